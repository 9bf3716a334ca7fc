"""Sample avatars for tests, benchmarks and the demo: the ICT template or ARKit's reference face
moved into the conventions users' avatars come in (another topology, vertex order, unit, axes,
handedness, a whole body, separate eyes and teeth, some of the shapes under a rig's names), with
the ground truth that relates each avatar back to the template (`python -m softdeca_train
avatar`, docs/avatars.md)."""

from softdeca_train.sample_avatars.build import make_avatar
from softdeca_train.sample_avatars.config import (
    HELD_OUT_IDENTITIES,
    NAME_STYLES,
    UNITS,
    AvatarConfig,
)
from softdeca_train.sample_avatars.files import AvatarFiles, read_avatar, write_avatar
from softdeca_train.sample_avatars.mesh import PARTS, AvatarMesh, AvatarTruth
from softdeca_train.sample_avatars.names import rig_name

__all__ = [
    "HELD_OUT_IDENTITIES",
    "NAME_STYLES",
    "PARTS",
    "UNITS",
    "AvatarConfig",
    "AvatarFiles",
    "AvatarMesh",
    "AvatarTruth",
    "make_avatar",
    "read_avatar",
    "rig_name",
    "write_avatar",
]
