"""Landmarks for SparseSoftDECA: ARKit's reference face, ~150 contour landmarks defined on its
topology, their registration onto the template's skin surface S, and barycentric evaluation on
any mesh in template topology."""

from softdeca_train.landmarks.arkit_reference import ArkitFace, FaceLoops, canonical_shape_name
from softdeca_train.landmarks.definition import (
    LandmarkDefinition,
    generate_definition,
    load_definition,
    write_definition,
)
from softdeca_train.landmarks.pipeline import (
    LandmarkRegistration,
    face_target,
    register_arkit_to_template,
    template_landmarks,
)
from softdeca_train.landmarks.registration import RegistrationConfig, Similarity, umeyama
from softdeca_train.landmarks.surface import SurfaceLandmarks

__all__ = [
    "ArkitFace",
    "FaceLoops",
    "LandmarkDefinition",
    "LandmarkRegistration",
    "RegistrationConfig",
    "Similarity",
    "SurfaceLandmarks",
    "canonical_shape_name",
    "face_target",
    "generate_definition",
    "load_definition",
    "register_arkit_to_template",
    "template_landmarks",
    "umeyama",
    "write_definition",
]
