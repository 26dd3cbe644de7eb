"""Shared machinery of the validation cases: result rows, small bead models, decks and runs.

Every case builds a small :class:`~ncf2lammps.model.Model` from numpy arrays, writes it with
:func:`~ncf2lammps.io.datafile.write_data`, renders its deck from ``templates/validation/`` with
:func:`~ncf2lammps.io.deck.render` (typed values only), runs it in an
:class:`~ncf2lammps.engine.Engine` on one rank, and returns :class:`Check` rows. Units are LAMMPS
``micro`` (um, pg, us, nN, kPa) throughout.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ... import units
from ...engine import Engine
from ...io.datafile import write_data
from ...io.deck import render
from ...model import AtomType, BondType, Box, Model, Part, join
from ...numerics import ContactLaw, damped_law
from ..deck import base_context

__all__ = [
    "E_CARBON",
    "MU",
    "RHO_CARBON",
    "CaseResult",
    "ChainSet",
    "Check",
    "D",
    "contact",
    "hertz_contact",
    "lammps_case",
    "record",
]

#: Chain diameter of the paper (um).
D = 69.0
#: Carbon fibre density (pg/um^3) and axial modulus (kPa), docs/design.md §7.
RHO_CARBON = units.to_micro(1.80, "g_cm3")
E_CARBON = units.to_micro(240.0, "GPa")
#: Coulomb friction of the paper.
MU = 0.3


@dataclass(frozen=True)
class Check:
    """One row of the validation table.

    ``kind`` says how ``measured`` is judged against ``expected`` with ``tolerance``:
    ``"relative"``: ``|measured / expected - 1| <= tolerance``; ``"absolute"``:
    ``|measured - expected| <= tolerance``; ``"above"``: ``0 <= measured - expected <= tolerance``
    (a one-sided band such as F/(mu N) in [1.00, 1.05]); ``"info"``: reported, not judged.
    """

    case: str
    name: str
    law: str
    expected: float
    measured: float
    tolerance: float
    kind: str = "relative"

    @property
    def error(self) -> float:
        """Signed relative error (``"relative"``) or difference (other kinds)."""
        if self.kind == "relative":
            return self.measured / self.expected - 1.0
        return self.measured - self.expected

    @property
    def passed(self) -> bool:
        """Whether the measurement is inside the tolerance (always True for ``"info"``)."""
        if self.kind == "relative" or self.kind == "absolute":
            return bool(abs(self.error) <= self.tolerance)
        if self.kind == "above":
            return bool(0.0 <= self.error <= self.tolerance)
        return True

    def row(self) -> list[str]:
        """Table cells: case, law, expected, measured, error, tolerance, pass."""
        if self.kind == "relative":
            error, tolerance = f"{100 * self.error:+.3f} %", f"{100 * self.tolerance:.3g} %"
            expected = f"{self.expected:.6g}"
        elif self.kind == "absolute":
            error, tolerance = f"{self.error:+.3g}", f"{self.tolerance:.3g}"
            expected = f"{self.expected:.6g}"
        elif self.kind == "above":
            error, tolerance = f"{self.error:+.4f}", f"[0, {self.tolerance:.3g}]"
            expected = f"[{self.expected:.4g}, {self.expected + self.tolerance:.4g}]"
        else:
            error, tolerance, expected = f"{self.error:+.4g}", "-", f"{self.expected:.6g}"
        verdict = "info" if self.kind == "info" else ("pass" if self.passed else "FAIL")
        return [self.name, self.law, expected, f"{self.measured:.6g}", error, tolerance, verdict]


@dataclass
class CaseResult:
    """What one case returns: its rows, plots (paths) and a note for docs/validation.md."""

    case: str
    checks: list[Check]
    plots: list[Path] = field(default_factory=list)
    note: str = ""
    wall_s: float = 0.0


def fibre(
    name: str, diameter: float, spacing: float, modulus: float, rho: float
) -> tuple[AtomType, BondType, float]:
    """Atom type, bond type (``K = E A / (2 s)``) and bead density of a cylinder-equivalent chain.

    The bead density makes the mass per length ``rho pi d^2 / 4`` (docs/design.md §5).
    """
    area = np.pi * diameter**2 / 4.0
    atom = AtomType(name, "fibre", diameter, rho, modulus)
    bond = BondType(name, "fibre", modulus * area / (2.0 * spacing), spacing, modulus * area)
    return atom, bond, rho * area * spacing / (np.pi * diameter**3 / 6.0)


class ChainSet:
    """Collects bead chains (open or closed through the periodic box) into a :class:`Model`."""

    def __init__(self) -> None:
        self.atom_types: list[AtomType] = []
        self.bond_types: list[BondType] = []
        self._densities: list[float] = []
        self._chains: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []

    def add_type(self, atom: AtomType, bond: BondType, bead_density: float) -> int:
        """Register one bead/bond type pair; returns its index."""
        self.atom_types.append(atom)
        self.bond_types.append(bond)
        self._densities.append(bead_density)
        return len(self.atom_types) - 1

    def add(self, positions: np.ndarray, type_index, closed: bool = False) -> np.ndarray:
        """Add one chain of (n, 3) bead positions (um); returns the 0-based bead indices.

        ``type_index`` is one type for the chain or (n,) per bead; a bond takes the type of its
        first bead; ``closed`` bonds the last bead to the first (through the periodic box).
        """
        positions = np.asarray(positions, dtype=float).reshape(-1, 3)
        types = np.broadcast_to(np.asarray(type_index, dtype=np.int64), len(positions))
        indices = sum(len(c[0]) for c in self._chains) + np.arange(len(positions))
        ends = indices if closed else indices[:-1]
        bonds = np.stack([ends, np.roll(indices, -1)[: len(ends)]], axis=1)
        self._chains.append((positions, types, bonds))
        return indices

    def model(self, lo: Sequence[float], hi: Sequence[float], tilt=(0.0, 0.0, 0.0)) -> Model:
        """The collected chains in a box ``lo``..``hi`` (um) with tilt ``(xy, xz, yz)`` (um).

        One molecule per chain; the mat thickness and faces are the box's z extent, the fibre
        volume that of every bead's cylinder.
        """
        positions, type_id, bonds = (
            np.concatenate(arrays) for arrays in zip(*self._chains, strict=True)
        )
        mol_id = np.concatenate([np.full(len(c[0]), i) for i, c in enumerate(self._chains)])
        diameter = np.array([t.diameter for t in self.atom_types])[type_id]
        density = np.array(self._densities)[type_id]
        rho = np.array([t.density for t in self.atom_types])[type_id]
        part = Part(
            positions=positions,
            type_id=type_id,
            density=density,
            mol_id=mol_id,
            bonds=bonds,
            bond_type=type_id[bonds[:, 0]],
            atom_types=tuple(self.atom_types),
            bond_types=tuple(self.bond_types),
            fibre_volume=float(np.sum(density / rho * np.pi * diameter**3 / 6.0)),
        )
        lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
        box = Box(lo, hi, np.asarray(tilt, dtype=float))
        return join(
            [part], box, mat_thickness=float(hi[2] - lo[2]), faces_z=(float(lo[2]), float(hi[2]))
        )


def contact(kn: float, mass: float, mu: float, damping_ratio: float = 0.3) -> ContactLaw:
    """Hooke contact: stiffness ``kn`` (nN/um), damping ratio of a pair of beads of ``mass``
    (pg), tangential stiffness 2/7 kn (docs/design.md §6, spec default; numerics.damped_law)."""
    return damped_law("hooke", kn, kn, damping_ratio, mass / 2.0, 2.0 / 7.0, mu)


def hertz_contact(modulus: float, stiffness: float, mass: float, mu: float) -> ContactLaw:
    """hertz/material of Young's modulus ``modulus`` (kPa) and reference ``stiffness`` (nN/um),
    every pair damped at 0.3 of critical at its current stiffness (numerics.damped_law), beads of
    ``mass`` (pg)."""
    return damped_law("hertz", modulus, stiffness, 0.3, mass / 2.0, 2.0 / 7.0, mu)


def _base_values(model: Model, dt: float, law: ContactLaw, scene: str, data_file: str) -> dict:
    """The values ``base.lmp.j2`` needs (:func:`~ncf2lammps.scenes.deck.base_context`), sized to
    the model: skin d/10, a ghost cutoff two bonds past a bead, no guards, no output files;
    ``data_file`` is the absolute path of the case's data file."""
    return base_context(model, dt, law, scene, data_file=data_file, bond_reach=2.0)


@contextmanager
def lammps_case(
    workdir: Path, template: str, model: Model, dt: float, law: ContactLaw, **values
) -> Iterator[Engine]:
    """Write ``model.data`` and ``in.lmp`` (rendered ``template``) in ``workdir``, run the deck.

    The deck reads the data file by its absolute path and LAMMPS logs to ``workdir/log.lammps``:
    the working directory is never changed. Yields the open :class:`Engine` after the deck has
    been read, so the case drives the runs.
    """
    workdir.mkdir(parents=True, exist_ok=True)
    folder = workdir.resolve()
    write_data(folder / "model.data", model, title=template)
    scene = Path(template).name.split(".")[0]
    base = _base_values(model, dt, law, scene, str(folder / "model.data"))
    (folder / "in.lmp").write_text(render(template, **base, **values))
    with Engine(log=folder / "log.lammps") as engine:
        engine.file(folder / "in.lmp")
        yield engine


def record(engine: Engine, fix_id: str, width: int, chunk: int, chunks: int) -> np.ndarray:
    """Run ``chunks`` runs of ``chunk`` steps; after each read a ``fix ave/time 1 chunk chunk``.

    Returns (chunks, width) float: the time averages of the fix's values over each chunk.
    """
    rows = np.empty((chunks, width))
    for i in range(chunks):
        engine.command(f"run {int(chunk)}")
        rows[i] = engine.fix_vector(fix_id, width)
    return rows
