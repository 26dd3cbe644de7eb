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


def write_data(path: str | os.PathLike, model: Model, title: str = "ncf2lammps model") -> Path:
    """Write ``model`` as a LAMMPS data file (atom_style hybrid sphere bond, triclinic box)."""
    path = Path(path)
    box = model.box
    n_atoms, n_bonds = model.n_atoms, model.n_bonds
    angle_counts, angle_labels, angle_tables = [], [], []
    if model.n_angles:  # LAMMPS wants every type label before the first coefficient
        harmonic = model.angle_style == "harmonic"
        angle_counts = [f"{model.n_angles} angles", f"{len(model.angle_types)} angle types"]
        angle_labels = [
            "Angle Type Labels",
            "",
            *(f"{i + 1} {t.name}" for i, t in enumerate(model.angle_types)),
            "",
        ]
        angle_tables = [
            f"Angle Coeffs # {model.angle_style}",
            "",
            *(
                f"{i + 1} {t.k:.17g} {t.theta0:.17g}" if harmonic else f"{i + 1} {t.k:.17g}"
                for i, t in enumerate(model.angle_types)
            ),
            "",
        ]
    header = [
        f"LAMMPS data file: {title}",
        "",
        f"{n_atoms} atoms",
        f"{n_bonds} bonds",
        f"{len(model.atom_types)} atom types",
        f"{len(model.bond_types)} bond types",
        *angle_counts,
        "",
        f"{box.lo[0]:.17g} {box.hi[0]:.17g} xlo xhi",
        f"{box.lo[1]:.17g} {box.hi[1]:.17g} ylo yhi",
        f"{box.lo[2]:.17g} {box.hi[2]:.17g} zlo zhi",
        f"{box.tilt[0]:.17g} {box.tilt[1]:.17g} {box.tilt[2]:.17g} xy xz yz",
        "",
        "Atom Type Labels",
        "",
        *(f"{i + 1} {t.name}" for i, t in enumerate(model.atom_types)),
        "",
        "Bond Type Labels",
        "",
        *(f"{i + 1} {t.name}" for i, t in enumerate(model.bond_types)),
        "",
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
        *angle_tables,
        "Atoms # hybrid",
        "",
    ]
    ids = np.arange(1, n_atoms + 1)
    atoms = _format_rows(
        [
            ids,
            model.type_id + 1,
            *model.positions.T,
            model.diameter,
            model.density,
            model.mol_id + 1,
        ],
        ["%d", "%d", _FLOAT, _FLOAT, _FLOAT, _FLOAT, _FLOAT, "%d"],
    )
    bonds = _format_rows(
        [
            np.arange(1, n_bonds + 1),
            model.bond_type + 1,
            model.bonds[:, 0] + 1,
            model.bonds[:, 1] + 1,
        ],
        ["%d", "%d", "%d", "%d"],
    )
    with open(path, "w") as fh:
        fh.write("\n".join(header) + "\n")
        fh.write(atoms)
        if n_bonds:
            fh.write("\nBonds\n\n")
            fh.write(bonds)
        if model.n_angles:
            fh.write("\nAngles\n\n")
            fh.write(
                _format_rows(
                    [
                        np.arange(1, model.n_angles + 1),
                        model.angle_type + 1,
                        *(model.angles.T + 1),
                    ],
                    ["%d"] * 5,
                )
            )
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


def read_data(path: str | os.PathLike) -> LammpsData:
    """Read a data file written by :func:`write_data` or by LAMMPS ``write_data`` (same style)."""
    text = Path(path).read_text()
    lines = text.splitlines()
    counts = {}
    bounds = {}
    tilt = np.zeros(3)
    starts = {}
    for i, line in enumerate(lines[1:], start=1):
        words = line.split("#")[0].split()
        stripped = line.strip()
        head = stripped.split("#")[0].strip()
        if head in _SECTIONS:
            starts[head] = i
            continue
        if starts:
            continue
        if len(words) == 2 and words[1] in ("atoms", "bonds", "angles"):
            counts[words[1]] = int(words[0])
        elif len(words) == 4 and words[2:] in (["xlo", "xhi"], ["ylo", "yhi"], ["zlo", "zhi"]):
            bounds[words[2][0]] = (float(words[0]), float(words[1]))
        elif len(words) == 6 and words[3:] == ["xy", "xz", "yz"]:
            tilt = np.array([float(w) for w in words[:3]])
    order = sorted(starts.values())

    def body(name: str) -> str:
        if name not in starts:
            return ""
        begin = starts[name] + 1
        later = [s for s in order if s > starts[name]]
        end = later[0] if later else len(lines)
        return "\n".join(re.sub(r"#.*", "", ln) for ln in lines[begin:end])

    def table(name: str) -> np.ndarray:
        text = body(name)
        first = next((ln for ln in text.splitlines() if ln.strip()), "")
        values = np.array(text.split(), dtype=float)
        return values.reshape(-1, max(1, len(first.split())))

    def labels(name: str) -> tuple[str, ...]:
        rows = [ln.split() for ln in body(name).splitlines() if ln.strip()]
        return tuple(r[1] for r in sorted(rows, key=lambda r: int(r[0])))

    atoms = table("Atoms")  # 8 columns, or 11 with image flags
    if len(atoms) != counts.get("atoms", 0):
        raise ValueError(f"{path}: Atoms section has {len(atoms)} rows, header says {counts}")
    atoms = atoms[np.argsort(atoms[:, 0])]
    bonds = table("Bonds")
    bonds = bonds[np.argsort(bonds[:, 0])]
    coeffs = table("Bond Coeffs")
    coeffs = coeffs[np.argsort(coeffs[:, 0])][:, 1:]
    angles = table("Angles")
    angles = angles[np.argsort(angles[:, 0])] if angles.size else np.zeros((0, 5))
    angle_coeffs = table("Angle Coeffs")
    if angle_coeffs.size:
        angle_coeffs = angle_coeffs[np.argsort(angle_coeffs[:, 0])][:, 1:]
    box = Box(
        lo=np.array([bounds[a][0] for a in "xyz"]),
        hi=np.array([bounds[a][1] for a in "xyz"]),
        tilt=tilt,
    )
    return LammpsData(
        positions=atoms[:, 2:5],
        diameter=atoms[:, 5],
        density=atoms[:, 6],
        type_id=atoms[:, 1].astype(np.int64) - 1,
        mol_id=atoms[:, 7].astype(np.int64) - 1,
        bonds=bonds[:, 2:4].astype(np.int64) - 1,
        bond_type=bonds[:, 1].astype(np.int64) - 1,
        box=box,
        bond_coeffs=coeffs,
        atom_labels=labels("Atom Type Labels"),
        bond_labels=labels("Bond Type Labels"),
        angles=angles[:, 2:5].astype(np.int64) - 1,
        angle_type=angles[:, 1].astype(np.int64) - 1,
        angle_coeffs=angle_coeffs if angle_coeffs.size else np.zeros((0, 1)),
        angle_labels=labels("Angle Type Labels"),
    )
