"""Where the stitch passes through the mat: hole positions, the underlaps' width across the
wales and the holes' slip through the mat (analysis/stitch.py, scenes/stitch.py)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import tiny_spec

from ncf2lammps.analysis.stitch import yarn_holes
from ncf2lammps.io.datafile import write_data
from ncf2lammps.model import Box
from ncf2lammps.model.builder import build_model
from ncf2lammps.scenes.stitch import hole_attrs, path_attrs, stitch_yarns


def _state(model, positions, box, path):
    """A data file of ``model`` moved to ``positions`` in ``box`` (wrapped in x and y)."""
    fractional = box.fractional(positions)
    fractional[:, :2] -= np.floor(fractional[:, :2])
    moved = dataclasses.replace(model, positions=box.lo + fractional @ box.matrix.T, box=box)
    write_data(path, moved)
    return path


@pytest.fixture(scope="module", params=[1, 2], ids=["one wale", "two wales"])
def model(request):
    """The tiny tricot-chain cell, one or two wales wide (one yarn per wale)."""
    return build_model(tiny_spec(cell={"width_mm": 5.08 * request.param}))


def test_generated_holes_lie_on_the_needle_points(model):
    # tricot-chain 1-0/0-1/1-2/2-1: four holes per yarn and repeat, alternately leaving on the
    # top (loop) and the bottom (underlap) face; every hole at a needle point (to 1e-6 um)
    lengths = model.box.lengths
    needles = model.needle_points
    for yarn in stitch_yarns(model):
        holes = yarn_holes(model.positions, model.box, yarn)
        assert len(holes.face) == 4 and set(np.abs(np.diff(holes.face))) == {2}
        xy = np.mod(holes.fractional[:, :2], 1.0) * lengths[:2]
        delta = xy[:, None, :] - needles[None, :, :]
        delta -= np.rint(delta / lengths[:2]) * lengths[:2]
        assert np.sqrt((delta**2).sum(axis=-1)).min(axis=1).max() < 1e-6
        # the path between holes adds up to the yarn's length, and the spans to its period
        steps = np.diff(model.positions[np.append(yarn, yarn[0])], axis=0)
        steps[:, :2] -= np.rint(steps[:, :2] / lengths[:2]) * lengths[:2]
        assert holes.path_um.sum() == pytest.approx(np.linalg.norm(steps, axis=1).sum(), 1e-12)
        np.testing.assert_allclose(holes.spans.sum(axis=0), holes.period, atol=1e-12)


def test_an_affine_shear_and_a_rigid_drift_move_no_hole(model, tmp_path):
    # fractional coordinates are the cell's material coordinates: the shear's box (tilt xy =
    # ly tan 40 deg) carrying every bead, plus a common translation, leaves the width 1 and the
    # slip 0 (1e-9 relative, 1e-6 um)
    lo, (lx, ly, lz) = model.box.lo, model.box.lengths
    tilt = ly * np.tan(np.radians(40.0))
    sheared = Box(lo, lo + np.array([lx, ly, lz]), np.array([tilt, 0.0, 0.0]))
    moved = (model.positions - lo) / np.array([lx, ly, lz]) @ sheared.matrix.T + lo
    state = _state(model, moved + np.array([123.0, -321.0, 7.0]), sheared, tmp_path / "s.data")
    attrs = hole_attrs(model, None, state)
    assert attrs["stitch_shog_width_ratio"] == pytest.approx(1.0, rel=1e-9)
    assert attrs["stitch_hole_slip_mm"] < 1e-9


def _stitch_length(model, positions, box, skip=0) -> float:
    """Total length (um) of the stitch bonds but the first ``skip``, each bond's shortest
    periodic copy found by trying every in-plane image -2..2 (independent of
    Box.minimum_image)."""
    bonds = model.bonds[model.role_mask("stitch")[model.bonds[:, 0]]][skip:]
    delta = positions[bonds[:, 1]] - positions[bonds[:, 0]]
    shifts = np.array([[i, j, 0] for i in range(-2, 3) for j in range(-2, 3)]) @ box.matrix.T
    return np.linalg.norm(delta[:, None, :] + shifts[None], axis=2).min(axis=1).sum()


def test_the_stitch_path_strain_against_the_frames_affine_map(model, tmp_path):
    # Carried by the picture frame's map at 30 deg (edge a along x, edge b of constant length
    # turned by 30 deg) the stitch lengthens exactly as the affine strain says; thickened about
    # its mid-plane by 1.25 in the same box, the affine strain stays 0 and the actual strain is
    # the length ratio of an independent sum over the bonds' nearest images (1e-9)
    lo, (lx, ly, lz) = model.box.lo, model.box.lengths
    g = np.radians(30.0)
    frame = Box(lo, lo + np.array([lx, ly * np.cos(g), lz]), np.array([ly * np.sin(g), 0, 0]))
    carried = (model.positions - lo) / np.array([lx, ly, lz]) @ frame.matrix.T + lo
    reference = _state(model, model.positions, model.box, tmp_path / "m.data")
    sheared = path_attrs(model, reference, _state(model, carried, frame, tmp_path / "s.data"))
    expected = _stitch_length(model, carried, frame) / _stitch_length(
        model, model.positions, model.box
    )
    assert sheared["stitch_path_strain"] == pytest.approx(expected - 1.0, abs=1e-9)
    assert sheared["stitch_path_affine_strain"] == pytest.approx(expected - 1.0, abs=1e-9)
    middle = 0.5 * (model.positions[:, 2].max() + model.positions[:, 2].min())
    thick = np.array(model.positions)
    thick[:, 2] = middle + 1.25 * (thick[:, 2] - middle)
    thickened = path_attrs(model, reference, _state(model, thick, model.box, tmp_path / "t.data"))
    expected = _stitch_length(model, thick, model.box) / _stitch_length(
        model, model.positions, model.box
    )
    assert thickened["stitch_path_affine_strain"] == pytest.approx(0.0, abs=1e-12)
    assert thickened["stitch_path_strain"] == pytest.approx(expected - 1.0, abs=1e-9)
    assert thickened["stitch_path_strain"] > 0.01
    # a state whose first three stitch bonds broke: the strain of the bonds it still has
    stitch_bond = np.flatnonzero(model.role_mask("stitch")[model.bonds[:, 0]])
    keep = np.setdiff1d(np.arange(model.n_bonds), stitch_bond[:3])
    broken = dataclasses.replace(model, bonds=model.bonds[keep], bond_type=model.bond_type[keep])
    after = path_attrs(model, reference, _state(broken, thick, model.box, tmp_path / "b.data"))
    expected = _stitch_length(model, thick, model.box, 3) / _stitch_length(
        model, model.positions, model.box, 3
    )
    assert after["stitch_path_strain"] == pytest.approx(expected - 1.0, abs=1e-9)


def test_underlaps_pulled_straight_narrow_by_the_pull(model, tmp_path):
    # every yarn's beads drawn towards its own mean y by a factor lam (fibres in place): each
    # hole moves across the wales by (1 - lam) (y - mean), so the width ratio is lam and the
    # slip the RMS of those moves (1e-9 relative)
    lam = 0.4
    positions = np.array(model.positions)
    ly = model.box.lengths[1]
    expected = []
    for yarn in stitch_yarns(model):
        y = positions[yarn, 1]
        steps = np.diff(np.append(y, y[0]))
        y_unwrapped = y[0] + np.concatenate([[0.0], np.cumsum(steps - np.rint(steps / ly) * ly)])
        mean = y_unwrapped[:-1].mean()
        positions[yarn, 1] = mean + lam * (y_unwrapped[:-1] - mean)
        holes = yarn_holes(model.positions, model.box, yarn)
        hole_y = holes.fractional[:, 1] * ly + model.box.lo[1]
        hole_y -= np.rint((hole_y - mean) / ly) * ly
        expected.append((1.0 - lam) * (hole_y - mean))
    state = _state(model, positions, model.box, tmp_path / "narrow.data")
    attrs = hole_attrs(model, None, state)
    assert attrs["stitch_shog_width_ratio"] == pytest.approx(lam, rel=1e-9)
    rms = np.sqrt(np.mean(np.concatenate(expected) ** 2))
    assert attrs["stitch_hole_slip_mm"] * 1e3 == pytest.approx(rms, rel=1e-9)
    assert rms > 100.0  # the zigzag of a 5.08 mm gauge: holes moved by ~1 mm


def test_a_chain_stitch_has_no_width_and_a_flattened_yarn_no_matching_holes(tmp_path):
    chain = build_model(tiny_spec(stitch={"pattern": "chain"}))
    attrs = hole_attrs(chain, None, _state(chain, chain.positions, chain.box, tmp_path / "c.data"))
    assert np.isnan(attrs["stitch_shog_width_ratio"]) and attrs["stitch_hole_slip_mm"] == 0.0
    model = build_model(tiny_spec())
    flat = np.array(model.positions)
    flat[model.role_mask("stitch"), 2] = flat[model.role_mask("stitch"), 2].mean()
    attrs = hole_attrs(model, None, _state(model, flat, model.box, tmp_path / "flat.data"))
    assert np.isnan(attrs["stitch_shog_width_ratio"]) and np.isnan(attrs["stitch_hole_slip_mm"])
    assert hole_attrs(model, None, tmp_path / "missing.data") == {}
    # a state of another model (fewer beads) is not read; beads a deck adds after the model's
    # (a hand-edited experiment) are left out
    assert hole_attrs(model, tmp_path / "c.data", tmp_path / "flat.data") == {}
    more = dataclasses.replace(
        model,
        positions=np.vstack([model.positions, model.positions[:3]]),
        diameter=np.concatenate([model.diameter, model.diameter[:3]]),
        density=np.concatenate([model.density, model.density[:3]]),
        type_id=np.concatenate([model.type_id, model.type_id[:3]]),
        mol_id=np.concatenate([model.mol_id, model.mol_id[:3]]),
    )
    write_data(tmp_path / "more.data", more)
    attrs = hole_attrs(model, None, tmp_path / "more.data")
    assert attrs["stitch_shog_width_ratio"] == pytest.approx(1.0, rel=1e-12)
