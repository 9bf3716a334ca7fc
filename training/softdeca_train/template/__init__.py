"""The head template: ICT-FaceKit loaded once into a compact cache, in metres and ARKit's frame."""

from softdeca_train.template.arkit import ARKIT_BLENDSHAPES, arkit_to_ict_matrix
from softdeca_train.template.components import COMPONENTS, SKIN_COMPONENTS, Component
from softdeca_train.template.ict_source import load_ict
from softdeca_train.template.model import Template

__all__ = [
    "ARKIT_BLENDSHAPES",
    "COMPONENTS",
    "SKIN_COMPONENTS",
    "Component",
    "Template",
    "arkit_to_ict_matrix",
    "load_ict",
]
