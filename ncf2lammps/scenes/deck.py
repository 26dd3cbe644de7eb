"""A scene's deck: the base context every deck is rendered from, and the rendered deck itself.

:func:`base_context` is the one builder of the values ``templates/base.lmp.j2`` reads, for the
scenes (:func:`deck_context`, from a prepared run) and the validation decks alike (from a model,
a time step and a contact law): every value is always given, so no template asks whether one
is defined.

Each deck is rendered once from a :class:`~ncf2lammps.numerics.Prepared` run; its recording
period travels with it as a value (:attr:`Deck.period`), so nothing is parsed back out of text.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from .. import __version__
from ..io.deck import render
from ..model import Model
from ..numerics import ContactLaw, Guards, Perturbation, Prepared, perturbation
from ..spec import FabricSpec

__all__ = ["Deck", "base_context", "deck_context", "friction_pairs", "neighbor_skin", "render_deck"]


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
        return _rounded_up(every, self.period)


def _rounded_up(every: int, period: int) -> int:
    """``every`` rounded up to a multiple of ``period`` (0 stays 0)."""
    return period * math.ceil(every / period) if every else 0


def _default_skin(model: Model) -> float:
    """Neighbour skin (um) when none is given: d/10 of the largest bead, at least 1 um."""
    return max(1.0, 0.1 * float(model.diameter.max()))


def neighbor_skin(spec: FabricSpec, model: Model) -> float:
    """Neighbour skin (um): the spec's, else :func:`_default_skin`."""
    if spec.numerics.neighbor_skin_um is not None:
        return spec.numerics.neighbor_skin_um
    return _default_skin(model)


def friction_pairs(spec: FabricSpec, model: Model) -> list[tuple[int, int, float]]:
    """(type, stitch type, mu) 1-based, for a fibre-stitch friction of its own
    (``contact.fibre_stitch_friction``) or law of its own (the bundle law's rigid stitch
    contacts); empty when every pair shares the contact law and ``contact.friction``. A
    sliding interlock's rings hold on their yarn by stitch-stitch contact: under the bundle law
    that pair takes the rigid stitch law too, with ``contact.friction``."""
    mu = spec.contact.fibre_stitch_friction
    stitch = [i + 1 for i, t in enumerate(model.atom_types) if t.role == "stitch"]
    bundle = spec.contact.normal_model == "bundle"
    if mu is None and bundle:
        mu = spec.contact.friction  # the pairs of the rigid fibre-stitch law
    if mu is None or not stitch:
        return []
    fibre = [i + 1 for i, t in enumerate(model.atom_types) if t.role == "fibre"]
    pairs = [(i, stitch[0], float(mu)) for i in fibre]
    if bundle and spec.stitch.interlock == "sliding":
        pairs.append((stitch[0], stitch[0], float(spec.contact.friction)))
    return pairs


def base_context(
    model: Model,
    dt: float,
    contact: ContactLaw,
    scene: str,
    *,
    data_file: str = "model.data",
    skin: float | None = None,
    bond_reach: float = 1.5,
    thermo_every: int = 100000,
    friction_pairs: Sequence[tuple[int, int, float]] = (),
    guards: Guards | None = None,
    perturbation: Perturbation | None = None,
    dump_every: int = 0,
    restart_every: int = 0,
) -> dict:
    """The values of templates/base.lmp.j2 for ``model`` run at time step ``dt`` (us) with the
    contact law ``contact``; a scene's own values are added on top.

    ``skin`` (um): the neighbour skin, by default d/10 of the largest bead and at least 1 um;
    the ghost cutoff is the largest diameter plus the skin plus ``bond_reach`` longest bonds
    (a bead's diameter for a model without bonds). ``friction_pairs``: (type, type, mu)
    1-based, pairs with a friction of their own; ``guards``: the stability guards (None:
    none); ``perturbation``: a replica's displacement of every bead at the scene's start
    (None: none); ``dump_every``, ``restart_every``: steps between trajectory frames and restart
    files (0: none).
    """
    d_max = float(model.diameter.max())
    if skin is None:
        skin = _default_skin(model)
    longest_bond = max((t.r0 for t in model.bond_types), default=d_max)
    return {
        "version": __version__,
        "scene": scene,
        "data_file": data_file,
        "restart_file": None,
        "contact": contact,
        "friction_pairs": list(friction_pairs),
        "angle_style": None if model.angle_style == "none" else model.angle_style,
        "dt": float(dt),
        "skin": skin,
        "comm_cutoff": d_max + skin + bond_reach * longest_bond,
        "thermo_every": thermo_every,
        "guards": guards,
        "perturbation": perturbation,
        "dump_every": dump_every,
        "restart_every": restart_every,
    }


def deck_context(
    run: Prepared, scene: str, data_file: str = "model.data", restart_every: int = 0
) -> dict:
    """The typed values every scene deck is rendered from (:func:`base_context` of the run).

    ``restart_every`` (steps) writes LAMMPS restart files from the deck itself, for decks run
    by plain ``lmp`` (the Python driver writes its own checkpoints).
    """
    spec, model = run.spec, run.model
    return base_context(
        model,
        run.time_step.dt,
        run.contact,
        scene,
        data_file=data_file,
        skin=neighbor_skin(spec, model),
        thermo_every=spec.numerics.thermo_every,
        friction_pairs=friction_pairs(spec, model),
        guards=run.guards,
        perturbation=perturbation(spec, model) if scene != "verify" else None,
        dump_every=spec.output.dump_every_steps if scene != "verify" else 0,
        restart_every=restart_every,
    )


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
    if plain_lmp and name != "verify":
        values["restart_every"] = _rounded_up(run.spec.output.checkpoint_every_steps, period)
    template = "verify.lmp.j2" if name == "verify" else SCENES[name].template
    return Deck(name, render(template, **values), period)
