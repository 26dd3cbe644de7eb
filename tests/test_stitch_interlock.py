"""Interlooped wales (stitch.interlock = "held"): the links that join each needle's loops on the
loop face, and a pretension that shortens only the legs and underlaps (docs/stitch.md)."""

from __future__ import annotations

import re

import numpy as np
import pytest
from conftest import case_spec, tiny_spec

from ncf2lammps import run
from ncf2lammps.analysis.stitch import bond_tensions, broken_bonds, yarn_holes
from ncf2lammps.geometry import SEGMENT_KINDS, stitch_path
from ncf2lammps.io.datafile import read_data
from ncf2lammps.io.results import read_results
from ncf2lammps.model import Box
from ncf2lammps.model.builder import build_model
from ncf2lammps.numerics import prepare
from ncf2lammps.scenes import render_deck
from ncf2lammps.scenes.stitch import segment_kind, stitch_yarns
from ncf2lammps.spec import SpecError

GAUGE, STITCH_LENGTH = 5080.0, 2800.0
LAPPINGS = {"tricot-chain": ((1, 0), (0, 1), (1, 2), (2, 1)), "chain": ((0, 1), (1, 0))}


def _kinds(model) -> list[str]:
    """The segment kind of each bond type (``""`` for fibre types)."""
    return [segment_kind(t.name) for t in model.bond_types]


@pytest.mark.parametrize("wales", [1, 2, 3])
@pytest.mark.parametrize("pattern", ["tricot-chain", "chain"])
def test_links_join_each_sinking_hole_to_the_next_course_on_its_needle(pattern, wales):
    # one link per hole where a yarn sinks; it starts at that top corner and ends, one stitch
    # length along x on the loop face (to 1e-9 um in the periodic cell), at the top corner where
    # the next course rises; every such corner is used once as a start and once as an end
    cell = (2 * len(LAPPINGS[pattern]) * STITCH_LENGTH, wales * GAUGE)
    path = stitch_path(LAPPINGS[pattern], GAUGE, STITCH_LENGTH, cell, -50.0, 700.0)
    vertices, n_vertices = path.yarn_vertices, path.yarn_vertices.shape[1]
    n_courses = n_vertices // 2
    assert len(path.link_corners) == wales * n_courses // 2
    (start_yarn, start_vertex), (end_yarn, end_vertex) = np.moveaxis(path.link_corners, 0, -1)
    start, end = vertices[start_yarn, start_vertex], vertices[end_yarn, end_vertex]
    assert np.all(start[:, 2] == 700.0) and np.all(end[:, 2] == 700.0)
    assert np.all(vertices[start_yarn, start_vertex + 1, 2] == -50.0)  # the yarn sinks there
    assert np.all(vertices[end_yarn, end_vertex - 1, 2] == -50.0)  # the next course rises
    gap = (start + path.link_vector - end)[:, :2]
    gap -= np.rint(gap / cell) * cell
    assert np.abs(gap).max() < 1e-9
    np.testing.assert_array_equal(path.link_vector, [STITCH_LENGTH, 0.0, 0.0])
    for corners in path.link_corners.transpose(1, 0, 2):
        assert len(np.unique(corners, axis=0)) == len(corners)


@pytest.fixture(scope="module", params=[1, 2], ids=["one wale", "two wales"])
def models(request):
    """{interlock: model} of the tiny tricot-chain cell one or two wales wide."""
    width = {"width_mm": 5.08 * request.param}
    return {
        interlock: build_model(tiny_spec(cell=width, stitch={"interlock": interlock}))
        for interlock in ("none", "held", "sliding")
    }


def _link_chains(model) -> np.ndarray:
    """(L, n) bead indices of each link from its start corner to its end bead (a corner, or
    a ring's bead 0): the model lays each link's bonds in order."""
    link = np.isin(model.bond_type, [i for i, k in enumerate(_kinds(model)) if k == "link"])
    bonds = model.bonds[link].reshape(len(model.needle_points) // 2, -1, 2)
    return np.column_stack([bonds[:, :, 0], bonds[:, -1, 1]])


def _distances(model, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(len(a), len(b)) minimum-image distances between beads ``a`` and ``b`` (um)."""
    delta = model.positions[a][:, None, :] - model.positions[b][None, :, :]
    return np.linalg.norm(model.box.minimum_image(delta.reshape(-1, 3)), axis=1).reshape(
        len(a), len(b)
    )


def _unwrapped_steps(model, chains: np.ndarray) -> np.ndarray:
    """(L, n - 1, 3) minimum-image steps along each chain (um)."""
    step = np.diff(model.positions[chains], axis=1)
    return model.box.minimum_image(step.reshape(-1, 3)).reshape(step.shape)


def test_held_model_adds_straight_links_of_the_yarns_material(models):
    # the held model is the free one (its beads first, unchanged) plus the links' inner beads:
    # straight chains of equal bonds along +x (1e-9 um) from a corner to a corner, two junction
    # beads of 3 bonds per link, the yarn's axial stiffness and mass per length (1e-12), loops in
    # types of their own
    free, held = models["none"], models["held"]
    n_free = free.n_atoms
    np.testing.assert_array_equal(held.positions[:n_free], free.positions)
    chains = _link_chains(held)
    (link_type,) = {_kinds(held).index("link")}
    r0 = held.bond_types[link_type].r0
    assert np.abs(_unwrapped_steps(held, chains) - [r0, 0.0, 0.0]).max() < 1e-9
    assert np.all(chains[:, [0, -1]] < n_free) and np.all(chains[:, 1:-1] >= n_free)
    degree = np.bincount(held.bonds.ravel(), minlength=held.n_atoms)
    assert np.count_nonzero(degree == 3) == chains.size - chains[:, 1:-1].size
    assert np.all(held.mol_id[n_free:] > free.mol_id.max())
    loop = held.bond_types[_kinds(held).index("loop")]
    assert held.bond_types[link_type].axial_stiffness == pytest.approx(loop.axial_stiffness, 1e-12)
    mass = held.density * np.pi * held.diameter**3 / 6.0
    loop_bead = held.bonds[held.bond_type == _kinds(held).index("loop")][1, 0]
    assert mass[n_free:] / r0 == pytest.approx(mass[loop_bead] / loop.r0, rel=1e-12)
    assert {k for k in _kinds(held) if k} == set(SEGMENT_KINDS) - {"ring"}


def test_sliding_links_end_in_rings_that_touch_the_leg(models):
    # a sliding link runs along +x on the loop face, drops by one yarn diameter d and ends on
    # bead 0 of a closed ring of radius d around the next course's leg, one d below its top
    # corner: the ring's beads touch the leg (the nearest yarn bead is d away in the ring's
    # plane, up to half a bead spacing s = d/2 above or below it), and no link bead overlaps
    # a ring bead it is not bonded to within two bonds
    held, sliding = models["held"], models["sliding"]
    d = sliding.diameter[-1]
    chains = _link_chains(sliding)
    steps = _unwrapped_steps(sliding, chains)
    assert np.all(steps[..., 0] >= 0.0) and np.all(steps[..., 1] == 0.0)
    assert np.all(steps[..., 2] <= 0.0)
    np.testing.assert_allclose(steps.sum(axis=1), [[2800.0 - d, 0.0, -d]] * len(chains))
    rings = np.isin(sliding.bond_type, [i for i, k in enumerate(_kinds(sliding)) if k == "ring"])
    ring_beads = np.unique(sliding.bonds[rings])
    assert set(chains[:, -1]) <= set(ring_beads)
    assert len(ring_beads) == np.count_nonzero(rings)  # closed rings: one bond per bead
    corner_ends = _link_chains(held)[:, -1]  # the same links' end corners
    centre = sliding.positions[chains[:, -1]] + [d, 0.0, 0.0]
    delta = centre - (sliding.positions[corner_ends] - [0.0, 0.0, d])
    delta[:, :2] -= np.rint(delta[:, :2] / sliding.box.lengths[:2]) * sliding.box.lengths[:2]
    assert np.abs(delta).max() < 1e-9
    yarns = np.concatenate(stitch_yarns(sliding))
    nearest_yarn = _distances(sliding, ring_beads, yarns).min()
    assert d * (1 - 1e-9) <= nearest_yarn < d * np.hypot(1.0, 0.25)  # a leg bead within s/2
    inner = chains[:, 1:-3].ravel()  # the link beads not within two bonds of a ring
    assert _distances(sliding, ring_beads, inner).min() >= d * (1 - 1e-9)


@pytest.mark.parametrize("interlock", ["held", "sliding"])
def test_yarns_and_holes_leave_the_interlock_out(models, interlock):
    # the yarns of an interlocked model are the free model's, so are their holes (exactly)
    free, linked = models["none"], models[interlock]
    for a, b in zip(stitch_yarns(free), stitch_yarns(linked), strict=True):
        np.testing.assert_array_equal(a, b)
        holes_free = yarn_holes(free.positions, free.box, a)
        holes_linked = yarn_holes(linked.positions, linked.box, b)
        np.testing.assert_array_equal(holes_free.fractional, holes_linked.fractional)


@pytest.mark.parametrize("interlock", ["held", "sliding"])
def test_the_pretension_shortens_and_measures_legs_and_underlaps_only(interlock):
    # the manufacture deck's pulled group is exactly the beads of leg and underlap bonds, fix
    # adapt shrinks only their types, the tension averages over them; the default deck pulls
    # every stitch type and has no such group
    prepared = prepare(tiny_spec(stitch={"interlock": interlock}))
    model, text = prepared.model, render_deck(prepared, "manufacture").text
    kinds = _kinds(model)
    pulled = [i for i, k in enumerate(kinds) if k in ("leg", "underlap")]
    ids = set()
    for line in re.findall(r"^group\s+stitch_pulled id (.*)$", text, re.M):
        for span in line.split():
            first, last = map(int, span.split(":"))
            ids.update(range(first, last + 1))
    expected = np.unique(model.bonds[np.isin(model.bond_type, pulled)]) + 1
    assert sorted(ids) == expected.tolist()
    adapt = re.search(r"^fix\s+pretension stitch adapt 1 (.*) reset no$", text, re.M).group(1)
    assert sorted(map(int, re.findall(r"r0 (\d+) v_r0", adapt))) == [i + 1 for i in pulled]
    assert "compute         stitch_bonds stitch_pulled bond/local force" in text
    free = render_deck(prepare(tiny_spec()), "manufacture").text
    assert "stitch_pulled" not in free
    n_stitch = sum(t.role == "stitch" for t in prepare(tiny_spec()).model.bond_types)
    assert free.count(" v_r0_") == n_stitch


def test_sliding_rings_hold_by_the_rigid_stitch_law_under_the_bundle_law():
    # under the bundle law the stitch-stitch pair takes the rigid law of the fibre-stitch pairs,
    # with the contact's friction, when the interlock slides (its rings hold by contact); the
    # held interlock keeps the pair on the bundle law of "* *"
    def pair_lines(interlock):
        spec = case_spec("hpt310-bundle-coarse").replace(stitch={"interlock": interlock})
        prepared = prepare(spec)
        t = next(i + 1 for i, a in enumerate(prepared.model.atom_types) if a.role == "stitch")
        text = render_deck(prepared, "manufacture").text
        return dict(re.findall(rf"^pair_coeff +(\d+) {t} (.*)$", text, re.M)), str(t)

    lines, stitch = pair_lines("sliding")
    fibre_stitch = {v for k, v in lines.items() if k != stitch}
    assert len(fibre_stitch) == 1 and lines[stitch] == fibre_stitch.pop()
    assert lines[stitch].startswith("hooke ")
    lines, stitch = pair_lines("held")
    assert stitch not in lines


def test_a_loop_of_one_bond_is_refused():
    # a 1.9 mm stitch bead spacing leaves the 2.8 mm loops one bond each: the tension's bead
    # group would count them as pulled
    spec = tiny_spec(
        stitch={"interlock": "held", "diameter_um": 1900.0, "needle_diameter_mm": 2.5},
        discretisation={"chain_diameter_um": 250.0, "bead_spacing_ratio": 1.0},
    )
    with pytest.raises(SpecError, match=r"stitch\.interlock.*two bonds"):
        build_model(spec)


@pytest.fixture(scope="module")
def interlocked(tmp_path_factory):
    """``interlocked(interlock)``: (spec, run folder, results) of the tiny cell with that
    interlock after manufacture, run once per module; the sliding one with a rupturing stitch
    of breaking load 0.38 N (0.5 cN/dtex x 76 dtex) and sheared on to 2 deg."""
    made = {}

    def make(interlock):
        if interlock not in made:
            if interlock == "held":
                spec, scenes = tiny_spec(stitch={"interlock": "held"}), ["manufacture"]
            else:
                stitch = {"interlock": "sliding", "rupture": True, "tenacity_cN_dtex": 0.5}
                spec = tiny_spec(stitch=stitch, shear={"final_angle_deg": 2.0})
                scenes = ["shear"]
            folder = tmp_path_factory.mktemp(interlock) / "run"
            made[interlock] = spec, folder, read_results(run(spec, folder, scenes=scenes))
        return made[interlock]

    return make


@pytest.mark.lammps
@pytest.mark.parametrize("interlock", ["held", "sliding"])
def test_held_loops_keep_their_length_while_the_legs_and_underlaps_pull(interlocked, interlock):
    """After manufacture the loops and links keep their generated rest length (to the data
    file's digits), the legs and underlaps have shrunk by one common strain, their mean tension
    is the target (5 %, the controller's tolerance plus the window), and the held loops carry
    the pull: their mean tension is positive (the underlaps pull on them through the
    junctions). A sliding link's ring still encircles its yarn: its centroid lies within half
    its radius d of a yarn bead (a ring slipped off would lie d or more away)."""
    spec, folder, results = interlocked(interlock)
    attrs = results["manufacture"]["attrs"]
    model = prepare(spec).model
    data = read_data(folder / "manufactured.data")
    kinds = _kinds(model)
    # strain of each stitch type's rest length; the data file keeps ~7 digits of r0
    strain = {
        kind: 1.0 - data.bond_coeffs[index, 1] / model.bond_types[index].r0
        for index, kind in enumerate(kinds)
        if kind
    }
    assert abs(strain["loop"]) < 1e-5 and abs(strain["link"]) < 1e-5
    assert strain["leg"] > 1e-3 and strain["leg"] == pytest.approx(strain["underlap"], abs=1e-5)
    positions, lengths = data.positions, data.box.lengths
    step = positions[data.bonds[:, 1]] - positions[data.bonds[:, 0]]
    step[:, :2] -= np.rint(step[:, :2] / lengths[:2]) * lengths[:2]
    k, r0 = data.bond_coeffs[data.bond_type].T
    tension = 2.0 * k * (np.linalg.norm(step, axis=1) - r0) * 1e-9  # N
    kind = np.array(kinds)[data.bond_type]
    on_pulled = np.isin(kind, ("leg", "underlap"))
    target = spec.manufacture.stitch_tension_N
    assert tension[on_pulled].mean() == pytest.approx(target, rel=0.05)
    assert tension[np.isin(kind, ("loop", "link"))].mean() > 0.0
    for name in set(kinds) - {""}:  # the recorded means per kind are these (1e-9)
        recorded = attrs[f"stitch_tension_{name}_N"]
        assert recorded == pytest.approx(tension[kind == name].mean(), rel=1e-9)
    if spec.stitch.interlock == "sliding":
        rings = np.unique(data.bonds[kind == "ring"]).reshape(len(model.needle_points) // 2, -1)
        yarns = np.concatenate(stitch_yarns(model))
        d = model.diameter[yarns[0]]
        for ring in rings:
            around = positions[ring] - positions[ring[0]]
            around[:, :2] -= np.rint(around[:, :2] / lengths[:2]) * lengths[:2]
            to_yarn = positions[yarns] - (positions[ring[0]] + around.mean(axis=0))
            to_yarn[:, :2] -= np.rint(to_yarn[:, :2] / lengths[:2]) * lengths[:2]
            assert np.linalg.norm(to_yarn, axis=1).min() < 0.5 * d


@pytest.mark.parametrize("interlock", ["held", "sliding"])
def test_rupture_breaks_the_yarn_not_the_interlock(interlock):
    # with rupture the loading decks break every stitch type but the links and rings (the
    # interlock holds); the manufacture writes the rest length of every type the decks read
    prepared = prepare(tiny_spec(stitch={"interlock": interlock, "rupture": True}))
    kinds = _kinds(prepared.model)
    shear = render_deck(prepared, "shear", plain_lmp=True).text
    broken = sorted(map(int, re.findall(r"bond/break \d+ (\d+) ", shear)))
    assert broken == [i + 1 for i, k in enumerate(kinds) if k in ("leg", "loop", "underlap")]
    manufacture = render_deck(prepared, "manufacture").text
    written = sorted(map(int, re.findall(r"variable +stitch_r0_(\d+) equal", manufacture)))
    assert written == [i + 1 for i, k in enumerate(kinds) if k]


@pytest.mark.lammps
def test_a_weak_stitch_breaks_in_its_yarn_and_stays_stable(interlocked):
    """The sliding cell's weak stitch sheared 2 deg: bonds break (the loops carry more than the
    0.1 N pretension), the recorded count equals the bonds missing from the final data file,
    none of them in a link or ring, and the run ends complete (no guard's stop)."""
    _, folder, results = interlocked("sliding")
    group = results["shear"]
    broken = int(group["attrs"]["stitch_bonds_broken"])
    assert broken > 0 and group["stitch_bonds_broken"][-1] == broken
    assert bool(results["attrs"]["complete"])
    before = read_data(folder / "manufactured.data")
    after = read_data(folder / "shear_2deg.data")
    gone = broken_bonds(before.bonds, after.bonds)
    assert len(gone) == broken
    kinds = {segment_kind(before.bond_labels[t]) for t in before.bond_type[gone]}
    assert kinds <= {"leg", "loop", "underlap"}
    # the path strain counts the unbroken bonds: after 2 deg (affine strain below 0.04 %) their
    # length has changed by a few per cent at most, where one broken bond counted would add its
    # gap of up to the cell
    assert abs(group["attrs"]["stitch_path_affine_strain"]) < 4e-4
    assert abs(group["attrs"]["stitch_path_strain"]) < 0.05


def test_bond_tensions_read_through_a_tilted_periodic_box():
    # a bond of rest length 10 um stretched to 12 um across the y boundary of a box tilted by
    # xy = 30 um reads 2 K (12 - 10) = 4 K; one compressed to 8 um reads -4 K (exact to 1e-12)
    box = Box(np.zeros(3), np.array([100.0, 50.0, 20.0]), np.array([30.0, 0.0, 0.0]))
    start = np.array([[20.0, 49.0, 5.0], [60.0, 20.0, 5.0]])
    # 12 um along y from the first bead crosses y = 50: its image sits at y = 11 (x - 30)
    end = np.array([[20.0 - 30.0 + 100.0, 11.0, 5.0], [68.0, 20.0, 5.0]])
    positions = np.vstack([start, end])
    tension = bond_tensions(
        positions, box, np.array([[0, 2], [1, 3]]), np.full(2, 3.0), np.full(2, 10.0)
    )
    np.testing.assert_allclose(tension, [12.0, -12.0], atol=1e-12)
