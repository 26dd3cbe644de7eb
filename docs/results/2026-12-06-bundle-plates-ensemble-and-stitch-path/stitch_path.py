"""Where the stitch's length goes in shear: its yarn path against the frame's map.

Usage: python stitch_path.py RUN SPEC STATE...

For the yarn bonds (legs, loops, underlaps; interlock links and rings left out) of
RUN/manufactured.data and of each STATE (e.g. shear_45deg.data) prints the total length, the
in-plane projected length, that length under the box's in-plane affine map of the manufactured
bonds, and the total z travel (um); then the yarns' holes: the path length between consecutive
holes, the in-plane hole-to-hole chords and the chords the box's map gives the manufactured holes
(where every yarn's holes can be matched to the manufactured ones).
"""

import sys
from pathlib import Path

import numpy as np

import ncf2lammps as n2l
from ncf2lammps.analysis.stitch import hole_alignment
from ncf2lammps.io.datafile import read_data
from ncf2lammps.scenes.stitch import segment_kind, stitch_holes

run, spec = Path(sys.argv[1]), n2l.load_spec(sys.argv[2])
model = n2l.prepare(spec).model
start = read_data(run / "manufactured.data")
kind = np.array([segment_kind(label) for label in start.bond_labels])[start.bond_type]
bonds = start.bonds[np.isin(kind, ("leg", "loop", "underlap"))]


def bond_vectors(state):
    positions = state.positions
    return state.box.minimum_image(positions[bonds[:, 1]] - positions[bonds[:, 0]])


def holes(state):
    return stitch_holes(model, state.positions[: model.n_atoms], state.box)


v0, holes0 = bond_vectors(start), holes(start)
for name in sys.argv[3:]:
    state = read_data(run / name)
    v = bond_vectors(state)
    deform = state.box.matrix[:2, :2] @ np.linalg.inv(start.box.matrix[:2, :2])
    affine = np.linalg.norm(v0[:, :2] @ deform.T, axis=1).sum()
    print(
        f"{name}: yarn {np.linalg.norm(v0, axis=1).sum():.0f} -> {np.linalg.norm(v, axis=1).sum():.0f}"
        f" um; in plane {np.linalg.norm(v0[:, :2], axis=1).sum():.0f} ->"
        f" {np.linalg.norm(v[:, :2], axis=1).sum():.0f} um (frame's map {affine:.0f});"
        f" z travel {np.abs(v0[:, 2]).sum():.0f} -> {np.abs(v[:, 2]).sum():.0f} um"
    )
    totals = np.zeros(5)
    for before, after in zip(holes0, holes(state), strict=True):
        shift = hole_alignment(before, after)
        if shift is None:
            print("  holes: a yarn's holes do not match the manufactured ones")
            break
        spans = np.roll(after.spans, -shift, axis=0)
        totals += [
            before.path_um.sum(),
            after.path_um.sum(),
            np.linalg.norm((before.spans @ start.box.matrix.T)[:, :2], axis=1).sum(),
            np.linalg.norm((spans @ state.box.matrix.T)[:, :2], axis=1).sum(),
            np.linalg.norm((before.spans @ state.box.matrix.T)[:, :2], axis=1).sum(),
        ]
    else:
        path0, path1, chord0, chord1, chord_map = totals
        print(
            f"  holes: path {path0:.0f} -> {path1:.0f} um; chords {chord0:.0f} -> {chord1:.0f} um"
            f" (frame's map {chord_map:.0f}); path beyond the chords {path0 - chord0:.0f} ->"
            f" {path1 - chord1:.0f} um"
        )
