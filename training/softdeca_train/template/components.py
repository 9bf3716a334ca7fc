"""The vertex layout of the ICT head mesh: its components' vertex ranges and the skin S."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Component:
    """A contiguous vertex range of the ICT mesh [start, stop)."""

    name: str
    start: int
    stop: int

    @property
    def slice(self) -> slice:
        return slice(self.start, self.stop)


# Vertex ranges from ICT-FaceKit's README (stop exclusive).
COMPONENTS: tuple[Component, ...] = (
    Component("face", 0, 9409),
    Component("head_neck", 9409, 11248),
    Component("mouth_socket", 11248, 13294),
    Component("eye_socket_left", 13294, 13678),
    Component("eye_socket_right", 13678, 14062),
    Component("gums_tongue", 14062, 17039),
    Component("teeth_upper", 17039, 19247),
    Component("teeth_lower", 19247, 21451),
    Component("eyeball_left", 21451, 23021),
    Component("eyeball_right", 23021, 24591),
    Component("lacrimal_fluid", 24591, 24999),
    Component("eye_blend", 24999, 25047),
    Component("eye_occlusion", 25047, 25351),
    Component("eyelashes", 25351, 26719),
)
# S: face, head and neck, mouth socket and eye sockets. They are contiguous in ICT's order.
SKIN_COMPONENTS = ("face", "head_neck", "mouth_socket", "eye_socket_left", "eye_socket_right")
N_SKIN = 14062
