"""Local thickness of a dump (analysis/trajectory.py): the model's beads are the dump's first."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import tiny_spec

from ncf2lammps.analysis.trajectory import local_thickness
from ncf2lammps.model.builder import build_model


def _dump(path, positions, radius, box):
    """One frame of ``dump custom ... id mol type x y z radius`` in an orthogonal box."""
    lo, hi = box.lo, box.hi
    rows = "\n".join(
        f"{i + 1} 1 1 {x:.9g} {y:.9g} {z:.9g} {r:.9g}"
        for i, ((x, y, z), r) in enumerate(zip(positions, radius, strict=True))
    )
    path.write_text(
        f"ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n{len(positions)}\n"
        "ITEM: BOX BOUNDS pp pp ff\n"
        + "".join(f"{lo[k]:.9g} {hi[k]:.9g}\n" for k in range(3))
        + f"ITEM: ATOMS id mol type x y z radius\n{rows}\n"
    )
    return path


def test_atoms_a_deck_adds_after_the_model_are_left_out(tmp_path):
    # three extra beads 10 mm above the cell would make every grid cell they fall in 10 mm
    # thick; the thickness and Vf read from the model's beads only are those without them
    model = build_model(tiny_spec())
    radius = model.diameter / 2
    plain = _dump(tmp_path / "plain.lammpstrj", model.positions, radius, model.box)
    extra = model.positions[:3] + np.array([0.0, 0.0, 1e4])
    more = _dump(
        tmp_path / "more.lammpstrj",
        np.vstack([model.positions, extra]),
        np.concatenate([radius, radius[:3]]),
        model.box,
    )
    expected = local_thickness(plain, model).results
    got = local_thickness(more, model).results
    np.testing.assert_array_equal(got.thickness, expected.thickness)
    np.testing.assert_array_equal(got.fvf, expected.fvf)
    assert np.nanmax(expected.thickness) < 5e3
    fewer = _dump(tmp_path / "fewer.lammpstrj", model.positions[:-1], radius[:-1], model.box)
    with pytest.raises(ValueError, match="fewer than the model's"):
        local_thickness(fewer, model)
