"""Example post-processing script: what the stitch does in the shear of finished runs; prints
one JSON object.

    python runs/stitch_in_shear.py out/run-a out/run-b [--angles 0 1 3 5 10 22.5 45]

Each folder holds a ``results.h5`` with a ``/shear`` group, ``model.data`` and the dump
``shear.lammpstrj`` (``ncf2lammps run ... --scene shear``). Per run:

- the mean stitch-bond tension at each angle (the nearest record) and its fraction of the
  manufactured tension;
- at each dump frame, the stitch's path length (sum of its bond lengths) against its length at
  the start, beside the length the frame's own (affine) motion would give it: the start's bond
  vectors mapped in plane by the box's deformation since the start, ``F = H H0^-1`` (H: the
  in-plane box edges as columns; any recipe and sense), z unchanged; the tilt of the box's b
  edge from y (the shear angle of a 0/90 frame); the z extents (1st to 99th percentile of
  the bead centres, um) of the fibres and of the stitch; and, per bead type (each ply, the
  stitch), the 1st, 50th and 99th percentiles of the bead centres' z (um): where each ply goes
  (a ply that lofts past the stitch's loops, one that follows its underlaps);
- per ply and frame, its packing: the share of its layer (1st to 99th percentile of its bead
  centres' z, plus one chain diameter) that the chains' contact cylinders fill,
  ``0.98 sum(|bond| pi d^2 / 4) / (A h)`` (A the cell's area; 0.98: the chain inside the
  percentiles). A ply that thickens at a falling packing restacks; one that keeps its
  thickness while its area falls densifies in plane.

A stitch longer than its affine length is pushed out by the cell (a jammed cell that thickens);
one at its start length while its tension falls has let the cell yield around it.
"""

import argparse
import json
import sys
import warnings
from pathlib import Path

import MDAnalysis as mda
import numpy as np
from MDAnalysis.lib.distances import minimize_vectors
from MDAnalysis.lib.mdamath import triclinic_vectors

from ncf2lammps.analysis.trajectory import unique_frames
from ncf2lammps.io.datafile import read_data
from ncf2lammps.io.results import read_results

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("runs", type=Path, nargs="+", help="run folders with results.h5")
parser.add_argument(
    "--angles", type=float, nargs="+", default=[0, 1, 3, 5, 10, 22.5, 45], help="deg"
)
args = parser.parse_args()


def ply_packing(bottom: float, top: float, diameter: float, volume: float, area: float) -> float:
    """Share of a ply's layer its chains fill: ``bottom`` and ``top`` the 1st and 99th
    percentile of its bead heights (um), ``diameter`` its median contact diameter (um),
    ``volume`` its chains' contact cylinders (um3), ``area`` the cell's (um2)."""
    return float(0.98 * volume / (area * (top - bottom + diameter)))


def stitch_path(folder: Path) -> list[dict]:
    """Per dump frame: box tilt (deg), path and affine path change, fibre and stitch z extents."""
    data = read_data(folder / "model.data")
    stitch_type = data.atom_labels.index("stitch")
    stitch_bonds = np.all(data.type_id[data.bonds] == stitch_type, axis=1)
    fibre = data.type_id != stitch_type
    bond_sections = np.pi * data.diameter[data.bonds[:, 0]] ** 2 / 4  # (B,) um2
    plies = {  # label -> (its bonds, its median contact diameter, um)
        label: (
            np.all(data.type_id[data.bonds] == t, axis=1),
            float(np.median(data.diameter[data.type_id == t])),
        )
        for t, label in enumerate(data.atom_labels)
        if t != stitch_type
    }
    with warnings.catch_warnings():  # the dump has no masses and no time unit: not needed
        warnings.simplefilter("ignore", UserWarning)
        universe = mda.Universe(str(folder / "shear.lammpstrj"), format="LAMMPSDUMP")
        rows, start, edges0 = [], None, None
        for frame in universe.trajectory[unique_frames(universe)]:
            box = frame.dimensions
            x = universe.atoms.positions.astype(float)
            bond_vectors = minimize_vectors(x[data.bonds[:, 1]] - x[data.bonds[:, 0]], box)
            cylinders = np.linalg.norm(bond_vectors.astype(float), axis=1) * bond_sections
            vectors = bond_vectors[stitch_bonds].astype(float)
            edges = triclinic_vectors(box).astype(float)[:2, :2].T  # columns a, b (in plane)
            if start is None:
                start, edges0 = vectors, edges
                length0 = np.linalg.norm(start, axis=1).sum()
            frame_map = np.eye(3)
            frame_map[:2, :2] = edges @ np.linalg.inv(edges0)
            z_percentiles = {
                label: np.percentile(x[data.type_id == t, 2], [1, 50, 99]).tolist()
                for t, label in enumerate(data.atom_labels)
                if np.any(data.type_id == t)
            }
            area = abs(np.linalg.det(edges))
            rows.append(
                {
                    "step": int(frame.data.get("step", frame.frame)),
                    "box_tilt_deg": float(90.0 - box[5]),
                    "path_change": float(np.linalg.norm(vectors, axis=1).sum() / length0 - 1),
                    "affine_change": float(
                        np.linalg.norm(start @ frame_map.T, axis=1).sum() / length0 - 1
                    ),
                    "fibre_extent_um": float(np.ptp(np.percentile(x[fibre, 2], [1, 99]))),
                    "stitch_extent_um": float(np.ptp(np.percentile(x[~fibre, 2], [1, 99]))),
                    "z_percentiles_um": z_percentiles,
                    "ply_packing": {
                        label: ply_packing(
                            z_percentiles[label][0],
                            z_percentiles[label][2],
                            diameter,
                            cylinders[in_ply].sum(),
                            area,
                        )
                        for label, (in_ply, diameter) in plies.items()
                    },
                }
            )
    return rows


def refuse(folder: Path, what: str) -> None:
    """One line naming the folder and what it lacks; exit 2."""
    print(
        f"stitch_in_shear.py: error: {folder}: no {what}; give folders of stitched fabrics'"
        " finished shear runs",
        file=sys.stderr,
    )
    sys.exit(2)


for folder in args.runs:
    missing = [
        n for n in ("results.h5", "model.data", "shear.lammpstrj") if not (folder / n).is_file()
    ]
    if missing:
        refuse(folder, ", ".join(missing))

report = {}
for folder in args.runs:
    results = read_results(folder / "results.h5")
    if "stitch_angle_deg" not in results.get("shear", {}) or "manufacture" not in results:
        refuse(folder, "stitch records of a manufacture and a shear")
    shear = results["shear"]
    angle, tension = shear["stitch_angle_deg"], shear["stitch_tension_mean_N"]
    nearest = [int(np.argmin(np.abs(angle - a))) for a in args.angles]
    made = float(results["manufacture"]["attrs"]["stitch_tension_N"])
    report[str(folder)] = {
        "manufactured_tension_N": made,
        "tension_N": {f"{angle[i]:.2f}": float(tension[i]) for i in nearest},
        "retained": {f"{angle[i]:.2f}": float(tension[i] / made) for i in nearest},
        "path": stitch_path(folder),
    }
print(json.dumps(report, indent=1))
