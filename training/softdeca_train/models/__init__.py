"""SoftDECA and SparseSoftDECA as the runtime runs them: the model bundle contract (networks,
manifest, ONNX export), the deformation transfer, and the reference forward pass."""

from softdeca_train.models.bundle import (
    FORMAT,
    FORMAT_VERSION,
    BundleInfo,
    OnnxNetworks,
    as_stored,
    export_bundle,
    pack_bundle,
    read_definition,
    read_manifest,
)
from softdeca_train.models.dt import DtSystem, deformation_transfer, dt_system
from softdeca_train.models.networks import (
    FULL_SIZES,
    TEST_SIZES,
    BundleNetworks,
    NetworkSizes,
    build_random,
)
from softdeca_train.models.parameters import ParameterState, load_parameter_specs
from softdeca_train.models.reference import ReferenceAvatar, TorchNetworks
from softdeca_train.models.topology import LandmarkSet, TemplateDefinition

__all__ = [
    "FORMAT",
    "FORMAT_VERSION",
    "FULL_SIZES",
    "TEST_SIZES",
    "BundleInfo",
    "BundleNetworks",
    "DtSystem",
    "LandmarkSet",
    "NetworkSizes",
    "OnnxNetworks",
    "ParameterState",
    "ReferenceAvatar",
    "TemplateDefinition",
    "TorchNetworks",
    "as_stored",
    "build_random",
    "deformation_transfer",
    "dt_system",
    "export_bundle",
    "load_parameter_specs",
    "pack_bundle",
    "read_definition",
    "read_manifest",
]
