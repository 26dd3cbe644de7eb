"""A scene's deck: the base context every deck is rendered from, and the rendered deck itself.

Each deck is rendered once from a :class:`~ncf2lammps.numerics.Prepared` run; its recording
period travels with it as a value (:attr:`Deck.period`), so nothing is parsed back out of text.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .. import __version__
from ..io.deck import render
from ..model import Model
from ..numerics import Prepared
from ..spec import FabricSpec

__all__ = ["Deck", "deck_context", "friction_pairs", "neighbor_skin", "render_deck"]


@dataclass(frozen=True)
class Deck:
    """A rendered deck: ``name`` (``verify`` or a scene), ``text`` and ``period`` (steps, the
    least common multiple of its recording and checking periods)."""

    name: str
    text: str
    period: int

    def checkpoint_interval(self, every: int) -> int:
        """Steps between checkpoints for a wish of ``every`` steps (0: none), rounded up to a
        multiple of :attr:`period` so that no checkpoint splits a recording window."""
        return self.period * math.ceil(every / self.period) if every else 0


def neighbor_skin(spec: FabricSpec, model: Model) -> float:
    """Neighbour skin (um): the spec's, else d/10 of the largest bead and at least 1 um."""
    if spec.numerics.neighbor_skin_um is not None:
        return spec.numerics.neighbor_skin_um
    return max(1.0, 0.1 * float(model.diameter.max()))


def friction_pairs(spec: FabricSpec, model: Model) -> list[tuple[int, int, float]]:
    """(fibre type, stitch type, mu) 1-based, for a fibre-stitch friction of its own
    (``contact.fibre_stitch_friction``); empty when every pair shares ``contact.friction``."""
    mu = spec.contact.fibre_stitch_friction
    stitch = [i + 1 for i, t in enumerate(model.atom_types) if t.role == "stitch"]
    if mu is None or not stitch:
        return []
    fibre = [i + 1 for i, t in enumerate(model.atom_types) if t.role == "fibre"]
    return [(i, stitch[0], float(mu)) for i in fibre]


def deck_context(
    run: Prepared, scene: str, data_file: str = "model.data", restart_every: int = 0
) -> dict:
    """The typed values every deck is rendered from (see templates/base.lmp.j2).

    ``restart_every`` (steps) writes LAMMPS restart files from the deck itself, for decks run
    by plain ``lmp`` (the Python driver writes its own checkpoints).
    """
    spec, model = run.spec, run.model
    skin = neighbor_skin(spec, model)
    longest_bond = max(t.r0 for t in model.bond_types)
    return {
        "version": __version__,
        "scene": scene,
        "data_file": data_file,
        "restart_file": None,
        "contact": run.contact,
        "friction_pairs": friction_pairs(spec, model),
        "angle_style": None if model.angle_style == "none" else model.angle_style,
        "dt": run.time_step.dt,
        "skin": skin,
        "comm_cutoff": float(model.diameter.max()) + skin + 1.5 * longest_bond,
        "thermo_every": spec.numerics.thermo_every,
        "guards": run.guards,
        "dump_every": spec.output.dump_every_steps if scene != "verify" else 0,
        "restart_every": restart_every,
    }


def render_deck(run: Prepared, name: str, plain_lmp: bool = False) -> Deck:
    """The deck of scene ``name`` (or of ``verify``: load the model, run 0), rendered once.

    ``plain_lmp``: the deck writes its own restart files every
    ``output.checkpoint_every_steps`` (rounded to its period), for runs without the Python driver.
    """
    from . import SCENES  # the registry imports the scene modules, which import this one

    values = deck_context(run, name)
    periods: tuple[int, ...] = (run.guards.every,)
    if name != "verify":
        scene = SCENES[name]
        values.update(scene.deck_values(run))
        periods += scene.periods(values)
    period = math.lcm(*periods)
    deck = Deck(name, "", period)
    if plain_lmp and name != "verify":
        values["restart_every"] = deck.checkpoint_interval(run.spec.output.checkpoint_every_steps)
    template = "verify.lmp.j2" if name == "verify" else SCENES[name].template
    return Deck(name, render(template, **values), period)
