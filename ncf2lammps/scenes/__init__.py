"""Scenes: one virtual process or test each, with its own deck (:mod:`.base` for the protocol).

:data:`SCENES` is the registry, in run order; each entry is its module's ``SCENE``.
"""

from . import compaction, manufacture, shear
from .base import Scene, execute
from .deck import Deck, deck_context, render_deck
from .loading import kinetic_checks, quasi_static

__all__ = [
    "SCENES",
    "Deck",
    "Scene",
    "applicable_scenes",
    "deck_context",
    "execute",
    "kinetic_checks",
    "quasi_static",
    "render_deck",
]

#: The scenes in the order a run executes them.
SCENES: dict[str, Scene] = {
    s.name: s for s in (manufacture.SCENE, compaction.SCENE, shear.SCENE, shear.NEGATIVE)
}


def applicable_scenes(spec) -> tuple[str, ...]:
    """The scenes a spec supports, in run order (manufacture needs a stitch, each shear scene
    its sense in ``shear.senses``)."""
    return tuple(name for name, scene in SCENES.items() if scene.applies(spec))
