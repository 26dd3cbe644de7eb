"""LAMMPS data files for ``atom_style hybrid sphere bond`` (write a Model, read back arrays).

Atom lines are ``id type x y z diameter density mol`` (ids, types and molecules 1-based here and
only here); bonds ``id type atom1 atom2``. Bond coefficients (``bond_style harmonic``: K, r0) and
type labels travel in the file, so a deck needs nothing else to know the model. A model with
bending angles (docs/fidelity.md) adds ``Angles`` (``id type atom1 atom2 atom3``), their labels
and coefficients (``harmonic``: K, theta0; ``cosine``: K) and is read with ``atom_style hybrid
sphere angle`` (same atom columns); without angles the file has no angle line at all. Whole
arrays are formatted at once (no per-row Python loop); floats are written with 17 significant
digits, so a write-read round trip returns identical arrays.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..model import Box, Model

__all__ = ["LammpsData", "read_data", "write_data"]

_FLOAT = "%.17g"


def _format_rows(columns: list[np.ndarray], formats: list[str]) -> str:
    """Rows of whitespace-separated columns, formatted in one C-level operation."""
    n = len(columns[0])
    if n == 0:
        return ""
    row = " ".join(formats) + "\n"
    table = np.empty((n, len(columns)), dtype=object)
    for j, column in enumerate(columns):
        table[:, j] = column.tolist()
    return (row * n) % tuple(table.ravel().tolist())


def _type_mean_mass(model: Model) -> np.ndarray:
    """Mean bead mass of each atom type (pg), shape (n_types,); 1 for a type without beads."""
    n_types = len(model.atom_types)
    counts = np.bincount(model.type_id, minlength=n_types)
    totals = np.bincount(model.type_id, weights=model.mass, minlength=n_types)
    return np.divide(totals, counts, out=np.ones(n_types), where=counts > 0)


def _labels(title: str, types) -> list[str]:
    """A type-label section: ``id name`` per type, 1-based."""
    return [title, "", *(f"{i + 1} {t.name}" for i, t in enumerate(types)), ""]


def _angle_sections(model: Model) -> tuple[list[str], list[str], list[str]]:
    """(header counts, type labels, coefficients) of the angles; empty lists without angles."""
    if not model.n_angles:
        return [], [], []
    harmonic = model.angle_style == "harmonic"
    counts = [f"{model.n_angles} angles", f"{len(model.angle_types)} angle types"]
    coeffs = [
        f"Angle Coeffs # {model.angle_style}",
        "",
        *(
            f"{i + 1} {t.k:.17g} {t.theta0:.17g}" if harmonic else f"{i + 1} {t.k:.17g}"
            for i, t in enumerate(model.angle_types)
        ),
        "",
    ]
    return counts, _labels("Angle Type Labels", model.angle_types), coeffs


def _header(model: Model, title: str) -> list[str]:
    """Every line before the Atoms rows: counts, box, labels, masses, coefficients."""
    box = model.box
    angle_counts, angle_labels, angle_coeffs = _angle_sections(model)
    return [
        f"LAMMPS data file: {title}",
        "",
        f"{model.n_atoms} atoms",
        f"{model.n_bonds} bonds",
        f"{len(model.atom_types)} atom types",
        f"{len(model.bond_types)} bond types",
        *angle_counts,
        "",
        f"{box.lo[0]:.17g} {box.hi[0]:.17g} xlo xhi",
        f"{box.lo[1]:.17g} {box.hi[1]:.17g} ylo yhi",
        f"{box.lo[2]:.17g} {box.hi[2]:.17g} zlo zhi",
        f"{box.tilt[0]:.17g} {box.tilt[1]:.17g} {box.tilt[2]:.17g} xy xz yz",
        "",
        # LAMMPS wants every type label before the first coefficient.
        *_labels("Atom Type Labels", model.atom_types),
        *_labels("Bond Type Labels", model.bond_types),
        *angle_labels,
        # Unused by the run (per-atom masses govern), but LAMMPS writes them back with write_data
        # and refuses to read a data file whose type masses are 0.
        "Masses",
        "",
        *(f"{i + 1} {m:.17g}" for i, m in enumerate(_type_mean_mass(model))),
        "",
        "Bond Coeffs # harmonic",
        "",
        *(f"{i + 1} {t.k:.17g} {t.r0:.17g}" for i, t in enumerate(model.bond_types)),
        "",
        *angle_coeffs,
        "Atoms # hybrid",
        "",
    ]


def write_data(path: str | os.PathLike, model: Model, title: str = "ncf2lammps model") -> Path:
    """Write ``model`` as a LAMMPS data file (atom_style hybrid sphere bond, triclinic box)."""
    path = Path(path)
    atom_columns = [
        np.arange(1, model.n_atoms + 1),
        model.type_id + 1,
        *model.positions.T,
        model.diameter,
        model.density,
        model.mol_id + 1,
    ]
    bond_columns = [
        np.arange(1, model.n_bonds + 1),
        model.bond_type + 1,
        model.bonds[:, 0] + 1,
        model.bonds[:, 1] + 1,
    ]
    with open(path, "w") as fh:
        fh.write("\n".join(_header(model, title)) + "\n")
        fh.write(_format_rows(atom_columns, ["%d", "%d", *[_FLOAT] * 5, "%d"]))
        if model.n_bonds:
            fh.write("\nBonds\n\n")
            fh.write(_format_rows(bond_columns, ["%d"] * 4))
        if model.n_angles:
            angle_columns = [
                np.arange(1, model.n_angles + 1),
                model.angle_type + 1,
                *(model.angles.T + 1),
            ]
            fh.write("\nAngles\n\n")
            fh.write(_format_rows(angle_columns, ["%d"] * 5))
    return path


@dataclass(frozen=True)
class LammpsData:
    """Arrays of a data file, 0-based, ordered by atom id (see :class:`Model` for meanings).

    ``bond_coeffs`` is (B, 2) float (K, r0); ``atom_labels``/``bond_labels`` the type names;
    ``angles`` (A, 3), ``angle_type`` (A,), ``angle_coeffs`` (T, 1 or 2) and ``angle_labels``
    are empty without angles.
    """

    positions: np.ndarray
    diameter: np.ndarray
    density: np.ndarray
    type_id: np.ndarray
    mol_id: np.ndarray
    bonds: np.ndarray
    bond_type: np.ndarray
    box: Box
    bond_coeffs: np.ndarray
    atom_labels: tuple[str, ...]
    bond_labels: tuple[str, ...]
    angles: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), dtype=np.int64))
    angle_type: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    angle_coeffs: np.ndarray = field(default_factory=lambda: np.zeros((0, 1)))
    angle_labels: tuple[str, ...] = ()


_SECTIONS = (
    "Atom Type Labels",
    "Bond Type Labels",
    "Angle Type Labels",
    "Bond Coeffs",
    "Angle Coeffs",
    "Atoms",
    "Bonds",
    "Angles",
    "Velocities",
    "Masses",
)


class _Sections:
    """The header values and the named sections of a data file's lines."""

    def __init__(self, lines: list[str]):
        self.lines = lines
        self.counts: dict[str, int] = {}
        self.bounds: dict[str, tuple[float, float]] = {}
        self.tilt = np.zeros(3)
        self.starts: dict[str, int] = {}
        for i, line in enumerate(lines[1:], start=1):
            head = line.split("#")[0].strip()
            words = head.split()
            if head in _SECTIONS:
                self.starts[head] = i
            elif self.starts:
                continue
            elif len(words) == 2 and words[1] in ("atoms", "bonds", "angles"):
                self.counts[words[1]] = int(words[0])
            elif len(words) == 4 and words[2:] in (["xlo", "xhi"], ["ylo", "yhi"], ["zlo", "zhi"]):
                self.bounds[words[2][0]] = (float(words[0]), float(words[1]))
            elif len(words) == 6 and words[3:] == ["xy", "xz", "yz"]:
                self.tilt = np.array([float(w) for w in words[:3]])

    def body(self, name: str) -> str:
        """The section's lines without comments ("" if absent)."""
        if name not in self.starts:
            return ""
        begin = self.starts[name] + 1
        later = [s for s in sorted(self.starts.values()) if s > self.starts[name]]
        end = later[0] if later else len(self.lines)
        return "\n".join(re.sub(r"#.*", "", ln) for ln in self.lines[begin:end])

    def table(self, name: str) -> np.ndarray:
        """The section as a float table sorted by its first column (ids), (rows, columns)."""
        text = self.body(name)
        first = next((ln for ln in text.splitlines() if ln.strip()), "")
        values = np.array(text.split(), dtype=float).reshape(-1, max(1, len(first.split())))
        return values[np.argsort(values[:, 0])] if values.size else values

    def labels(self, name: str) -> tuple[str, ...]:
        """The names of a type-label section, by type id."""
        rows = [ln.split() for ln in self.body(name).splitlines() if ln.strip()]
        return tuple(r[1] for r in sorted(rows, key=lambda r: int(r[0])))


def read_data(path: str | os.PathLike) -> LammpsData:
    """Read a data file written by :func:`write_data` or by LAMMPS ``write_data`` (same style)."""
    sections = _Sections(Path(path).read_text().splitlines())
    atoms = sections.table("Atoms")  # 8 columns, or 11 with image flags
    if len(atoms) != sections.counts.get("atoms", 0):
        raise ValueError(
            f"{path}: Atoms section has {len(atoms)} rows, header says {sections.counts}"
        )
    bonds = sections.table("Bonds")
    angles = sections.table("Angles")
    angles = angles if angles.size else np.zeros((0, 5))
    angle_coeffs = sections.table("Angle Coeffs")
    bounds = sections.bounds
    return LammpsData(
        positions=atoms[:, 2:5],
        diameter=atoms[:, 5],
        density=atoms[:, 6],
        type_id=atoms[:, 1].astype(np.int64) - 1,
        mol_id=atoms[:, 7].astype(np.int64) - 1,
        bonds=bonds[:, 2:4].astype(np.int64) - 1,
        bond_type=bonds[:, 1].astype(np.int64) - 1,
        box=Box(
            lo=np.array([bounds[a][0] for a in "xyz"]),
            hi=np.array([bounds[a][1] for a in "xyz"]),
            tilt=sections.tilt,
        ),
        bond_coeffs=sections.table("Bond Coeffs")[:, 1:],
        atom_labels=sections.labels("Atom Type Labels"),
        bond_labels=sections.labels("Bond Type Labels"),
        angles=angles[:, 2:5].astype(np.int64) - 1,
        angle_type=angles[:, 1].astype(np.int64) - 1,
        angle_coeffs=angle_coeffs[:, 1:] if angle_coeffs.size else np.zeros((0, 1)),
        angle_labels=sections.labels("Angle Type Labels"),
    )
