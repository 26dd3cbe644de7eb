"""Granular walls follow the pairs' contact law, hooke and hertz alike.

``fix wall/gran/region granular hertz/material E ...`` (LAMMPS GRANULAR) presses a sphere of
radius R with ``F = 4/3 E / (2 (1 - nu^2)) sqrt(R delta) delta``: the effective modulus of two
bodies of modulus E, the pairs' own, on a flat (R* = R). The compaction plates take the pairs'
arguments (templates/contact_law.lmp.j2), and ``f_wall[4]`` of ``contacts`` is the z force on
each bead in contact.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from conftest import case_spec, tiny_spec

from ncf2lammps import build, run_scenes
from ncf2lammps.engine import Engine
from ncf2lammps.io.lammpslog import read_ave_time
from ncf2lammps.io.results import read_results
from ncf2lammps.numerics import prepare
from ncf2lammps.scenes import SCENES, render_deck
from ncf2lammps.scenes.stitch import deck_value

#: A quarter of the mat-only cell, closed fast to Vf 0.62: both plates carry the mat.
HERTZ_MAT = {
    "cell": {"length_mm": 1.4, "width_mm": 1.27},
    "contact": {"normal_model": "hertz"},
    "compaction": {
        "inertial_number": 0.5,
        "final_fvf": 0.62,
        "end": "final_fvf",
        "loading": "constant",
    },
}

_PLATE = re.compile(
    r"^fix\s+wall_(top|bottom)\s+all\s+wall/gran/region\s+granular\s+(.*?)\s+region\s", re.M
)
_PAIR = re.compile(r"^pair_coeff[ \t]+\* \*[ \t]+(\S.*)$", re.M)


#: The toy decks' box: micro units, spheres, a 1 x 1 mm box open in z.
_TOY_BOX = """units           micro
boundary        p p f
atom_style      sphere
atom_modify     map array
comm_modify     vel yes
region          box block -500 500 -500 500 -200 400"""


def _laws(deck: str) -> tuple[dict[str, str], str]:
    """({plate: wall law arguments}, pair law arguments) of a compaction deck."""
    return dict(_PLATE.findall(deck)), _PAIR.search(deck).group(1)


def test_plates_take_the_pair_law_hooke_and_hertz():
    """Rendered decks only: the plates' arguments are those of the pairs' ``pair_coeff * *``
    (pair_style granular: a hertz mat; a stitched hooke cell with a fibre-stitch friction of
    its own), for hertz a hertz/material law, not a hooke stiffness of the modulus."""
    for spec, law in (
        (case_spec("mat-only").replace(contact={"normal_model": "hertz"}), "hertz/material "),
        (tiny_spec(contact={"fibre_stitch_friction": 0.2}), "hooke "),
    ):
        run = prepare(spec)
        plates, pair = _laws(render_deck(run, "compaction").text)
        assert sorted(plates) == ["bottom", "top"]
        assert plates["top"] == plates["bottom"] == pair
        assert pair.startswith(law + f"{run.contact.normal!r} {run.contact.damping!r} ")


@pytest.mark.lammps
def test_one_bead_on_a_plate_feels_the_hertz_force(tmp_path):
    """One bead (d = 100 um) pressed 0.1 um into the bottom plate and one into the top plate
    (a plane region moving like the compaction's), and two beads overlapping by 0.1 um, with the
    hertz arguments of a compaction deck: the plate force is 4/3 E* sqrt(R delta) delta with the
    pairs' E* = E/2 (nu = 0), and f_wall[4] reads it (the pair force has R* = R/2)."""
    run = prepare(case_spec("mat-only").replace(contact={"normal_model": "hertz"}))
    plates, pair = _laws(render_deck(run, "compaction").text)
    radius, delta, modulus = 50.0, 0.1, run.contact.normal
    (tmp_path / "in.lmp").write_text(
        f"""
{_TOY_BOX}
create_box      1 box
create_atoms    1 single 0.0 0.0 {radius - delta}
create_atoms    1 single 200.0 0.0 {200.0 + delta - radius}
create_atoms    1 single -200.0 0.0 100.0
create_atoms    1 single {-200.0 + 2 * radius - delta} 0.0 100.0
set             group all diameter {2 * radius} density 1.8
group           low id 1
group           high id 2
pair_style      granular
pair_coeff      * * {pair}
region          plate_bottom plane 0.0 0.0 0.0 0.0 0.0 1.0 units box
variable        drop equal 0.0*time
region          plate_top plane 0.0 0.0 200.0 0.0 0.0 -1.0 move NULL NULL v_drop units box
fix             wall_bottom low wall/gran/region granular {plates["bottom"]} region plate_bottom contacts
fix             wall_top high wall/gran/region granular {plates["top"]} region plate_top contacts
compute         force_bottom all reduce sum f_wall_bottom[4]
compute         force_top all reduce sum f_wall_top[4]
compute         contacts all reduce sum f_wall_bottom[1] f_wall_top[1]
variable        force_bottom equal c_force_bottom
variable        force_top equal -c_force_top
variable        contacts equal c_contacts[1]+c_contacts[2]
variable        pair equal fx[3]
variable        fz1 equal fz[1]
thermo_style    custom step v_force_bottom v_force_top v_contacts v_pair v_fz1
run             0
"""
    )
    with Engine(log=None) as engine:
        engine.file(tmp_path / "in.lmp")
        value = engine.variable
        e_star = modulus / 2.0
        wall = 4.0 / 3.0 * e_star * math.sqrt(radius * delta) * delta
        pair_force = 4.0 / 3.0 * e_star * math.sqrt(radius / 2.0 * delta) * delta
        assert value("contacts") == 2.0
        assert value("force_bottom") == pytest.approx(wall, rel=1e-9)
        assert value("force_top") == pytest.approx(wall, rel=1e-9)
        assert value("fz1") == pytest.approx(wall, rel=1e-9)
        assert -value("pair") == pytest.approx(pair_force, rel=1e-9)


@pytest.mark.lammps
def test_hertz_compaction_loads_both_plates(tmp_path):
    """A hertz mat closed to Vf 0.62: the deck's plates use hertz/material with the pairs'
    arguments; the recorded plate forces are never negative, both plates carry the mat and
    agree once loaded (work-weighted mismatch < 10 %), and the pressure rises by more than
    tenfold from the first record that loads the bottom plate."""
    spec = case_spec("mat-only").replace(**HERTZ_MAT)
    folder = build(spec, tmp_path / "run").directory
    group = read_results(run_scenes(spec, folder, ["compaction"]))["compaction"]
    plates, pair = _laws((folder / "decks" / "in.compaction.lmp").read_text())
    assert plates["top"] == plates["bottom"] == pair and pair.startswith("hertz/material ")
    history = read_ave_time(folder / "compaction.history.txt")
    top, bottom, pressure = history["v_force_top"], history["v_force_bottom"], history["v_pressure"]
    assert np.all(top >= 0.0) and np.all(bottom >= 0.0)
    assert top.max() > 0.0 and bottom.max() > 0.0
    assert group["attrs"]["plate_force_imbalance"] < 0.1
    first = int(np.argmax(bottom > 0.0))
    assert pressure[-1] > 10.0 * pressure[first] > 0.0
    assert group["attrs"]["reached_fvf"] == pytest.approx(
        HERTZ_MAT["compaction"]["final_fvf"], rel=0.05
    )


@pytest.mark.lammps
def test_hertz_damping_is_the_same_fraction_of_critical_for_every_pair(tmp_path):
    """Hertz contacts are damped at ``contact.damping_ratio`` zeta of critical at their own
    stiffness and mass (numerics.damped_law): a pair closing at relative speed v with overlap
    delta feels ``F_n + 2 zeta sqrt(m_eff F_n / delta) v`` (F_n the elastic Hertz force,
    m_eff = m_i m_j / (m_i + m_j)), for beads ten times heavier as for light ones, and a bead
    moving into a plate the same with m_eff = m (to 1e-9)."""
    run = prepare(case_spec("mat-only").replace(contact={"normal_model": "hertz"}))
    plates, pair = _laws(render_deck(run, "compaction").text)
    radius, delta, speed, zeta = 50.0, 0.1, 0.02, run.spec.contact.damping_ratio
    (tmp_path / "in.lmp").write_text(
        f"""
{_TOY_BOX}
create_box      1 box
create_atoms    1 single -200.0 0.0 100.0
create_atoms    1 single {-200.0 + 2 * radius - delta} 0.0 100.0
create_atoms    1 single 200.0 0.0 100.0
create_atoms    1 single {200.0 + 2 * radius - delta} 0.0 100.0
create_atoms    1 single 0.0 0.0 {radius - delta}
set             group all diameter {2 * radius} density 1.8
set             atom 4 density 18.0
set             atom 1 vx {speed}
set             atom 3 vx {speed}
set             atom 5 vz {-speed}
group           low id 5
pair_style      granular
pair_coeff      * * {pair}
region          plate_bottom plane 0.0 0.0 0.0 0.0 0.0 1.0 units box
fix             wall_bottom low wall/gran/region granular {plates["bottom"]} region plate_bottom contacts
compute         force_bottom all reduce sum f_wall_bottom[4]
variable        light equal -fx[1]
variable        heavy equal -fx[3]
variable        wall equal c_force_bottom
variable        m1 equal mass[1]
variable        m4 equal mass[4]
thermo_style    custom step v_light v_heavy v_wall
run             0
"""
    )
    with Engine(log=None) as engine:
        engine.file(tmp_path / "in.lmp")
        value = engine.variable
        e_star = run.contact.normal / 2.0
        pair_force = 4.0 / 3.0 * e_star * math.sqrt(radius / 2.0 * delta) * delta
        wall_force = 4.0 / 3.0 * e_star * math.sqrt(radius * delta) * delta
        light, heavy = value("m1"), value("m4")

        def damped(force: float, m_eff: float) -> float:
            return force + 2.0 * zeta * math.sqrt(m_eff * force / delta) * speed

        assert value("light") == pytest.approx(damped(pair_force, light / 2.0), rel=1e-9)
        m_eff = light * heavy / (light + heavy)
        assert value("heavy") == pytest.approx(damped(pair_force, m_eff), rel=1e-9)
        assert value("wall") == pytest.approx(damped(wall_force, light), rel=1e-9)


#: A tiny stitched cell under the bundle law (fibre-stitch pairs: the rigid hooke law).
BUNDLE_CELL = {
    "contact": {"normal_model": "bundle", "normal_stiffness_N_m": 1e5},
    "mat": {"initial_fvf": 0.2},
}
_BUNDLE_PLATE = re.compile(
    r"^fix\s+wall_(top|bottom)(\S*)\s+(\S+)\s+wall/gran/region\s+granular\s+(.*?)\s+region\s",
    re.M,
)
#: The compaction deck's plate block: its groups, walls, force computes and force variables.
_PLATE_BLOCK = re.compile(
    r"^(group\s+(fibre|stitch)\s|fix\s+wall_|compute\s+force_|variable\s+force_).*$", re.M
)


def test_bundle_plates_press_fibres_by_the_bundle_law_and_the_stitch_rigidly():
    """Rendered deck only: under the bundle law each plate has two walls, the fibre beads'
    with the pairs' ``* *`` law (the compressible bed) and the stitch beads' with the
    fibre-stitch pairs' rigid hooke law (a solid yarn on steel), both with the plates'
    friction; the plate forces sum both walls."""
    run = prepare(tiny_spec(**BUNDLE_CELL))
    deck = render_deck(run, "compaction").text
    walls = {
        (plate, suffix, group): law for plate, suffix, group, law in _BUNDLE_PLATE.findall(deck)
    }
    pair = _PAIR.search(deck).group(1)
    stitch_type = deck_value(run, "compaction")["type"]
    fibre_stitch = re.search(rf"^pair_coeff\s+1 {stitch_type}\s+(\S.*)$", deck, re.M).group(1)
    assert sorted(walls) == [
        ("bottom", "", "fibre"),
        ("bottom", "_stitch", "stitch"),
        ("top", "", "fibre"),
        ("top", "_stitch", "stitch"),
    ]
    for plate in ("top", "bottom"):
        assert walls[(plate, "", "fibre")] == pair
        assert walls[(plate, "_stitch", "stitch")] == fibre_stitch
    assert pair.startswith("hertz/material ") and fibre_stitch.startswith("hooke ")
    assert f"group           stitch type {stitch_type}\n" in deck
    assert "variable        force_top equal -(c_force_top+c_force_top_stitch)\n" in deck
    history = re.search(r"^fix\s+history .*$", deck, re.M).group(0)
    assert " v_load_kinetic_ratio v_force_stitch file compaction.history.txt" in history


@pytest.mark.lammps
def test_a_stitch_bead_on_a_bundle_plate_feels_the_rigid_law(tmp_path):
    """The bundle compaction deck's own plate block on three beads: a fibre bead (d = 100 um)
    pressed 0.1 um into the bottom plate feels the Hertz force 4/3 E* sqrt(R delta) delta of
    the bundle law, a stitch bead pressed 0.01 um into each plate the hooke force k_n delta of
    the fibre-stitch law; the plate force variables sum both walls, and the stitch's own
    variable is the mean of its two walls (to 1e-9)."""
    run = prepare(tiny_spec(**BUNDLE_CELL))
    deck = render_deck(run, "compaction").text
    block = "\n".join(m.group(0) for m in _PLATE_BLOCK.finditer(deck))
    stitch_type = deck_value(run, "compaction")["type"]
    radius, delta, delta_stitch, stitch_radius = 50.0, 0.1, 0.01, 20.0
    (tmp_path / "in.lmp").write_text(
        f"""
{_TOY_BOX}
create_box      {len(run.model.atom_types)} box
create_atoms    1 single 0.0 0.0 {radius - delta}
create_atoms    {stitch_type} single 200.0 0.0 {stitch_radius - delta_stitch}
create_atoms    {stitch_type} single -200.0 0.0 {200.0 + delta_stitch - stitch_radius}
set             atom 1 diameter {2 * radius} density 1.8
set             atom 2*3 diameter {2 * stitch_radius} density 1.38
pair_style      granular
pair_coeff      * * {_PAIR.search(deck).group(1)}
region          plate_bottom plane 0.0 0.0 0.0 0.0 0.0 1.0 units box
region          plate_top plane 0.0 0.0 200.0 0.0 0.0 -1.0 units box
{block}
thermo_style    custom step v_force_top v_force_bottom
run             0
"""
    )
    with Engine(log=None) as engine:
        engine.file(tmp_path / "in.lmp")
        value = engine.variable
        hertz = 4.0 / 3.0 * run.contact.normal / 2.0 * math.sqrt(radius * delta) * delta
        rigid = run.contact.stitch.normal * delta_stitch
        assert value("force_top") == pytest.approx(rigid, rel=1e-9)
        assert value("force_bottom") == pytest.approx(hertz + rigid, rel=1e-9)
        assert value("force_stitch") == pytest.approx(rigid, rel=1e-9)


def test_bundle_compaction_reports_the_stitch_share_of_the_plate_load(tmp_path):
    """The compaction's collect on records in the bundle deck's formats: plates closing on a
    linear spring (1 kPa per 10 um of travel) whose stitch beads carry a quarter of the mean
    plate force report ``stitch_plate_share_at_1kPa`` and ``_18kPa`` of 1/4 (to 1e-12) and
    the stitch's plate force in N; the thickness attributes are read from the same records."""
    run = prepare(tiny_spec(**BUNDLE_CELL))
    area = run.model.cell_area
    gap = np.linspace(1200.0, 900.0, 301)
    steps = 1000 + 10 * np.arange(len(gap))
    pressure = 0.1 * (gap[0] - gap)
    force = pressure * area
    zero = np.zeros(len(gap))
    history = {
        "v_time": 1e-3 * steps, "v_gap": gap, "v_force_top": force, "v_force_bottom": force,
        "v_pressure": pressure, "v_kinetic": zero, "v_potential": zero, "v_load_rate": zero,
        "v_load_stress_mean": pressure, "v_load_kinetic_ratio": zero,
        "v_force_stitch": 0.25 * force,
    }  # fmt: skip
    stitch = {"v_gap": gap, "v_stitch_tension_mean": zero + 1e5, "v_stitch_tension_max": zero + 2e5}
    for name, columns in (("history", history), ("stitch", stitch)):
        table = np.column_stack([steps, *columns.values()])
        header = f"# Time-averaged data\n# TimeStep {' '.join(columns)}\n"
        np.savetxt(tmp_path / f"compaction.{name}.txt", table, header=header, comments="")
    (tmp_path / "compaction.final.txt").write_text(f"ncf2lammps compaction: step {steps[-1]}\n")
    attrs, datasets = SCENES["compaction"].collect(run, tmp_path)
    assert attrs["stitch_plate_share_at_1kPa"] == pytest.approx(0.25, rel=1e-12)
    assert attrs["stitch_plate_share_at_18kPa"] == pytest.approx(0.25, rel=1e-12)
    assert attrs["thickness_at_18kPa_mm"] == pytest.approx(1.2 - 0.18, rel=1e-9)
    assert datasets["stitch_plate_force_N"] == pytest.approx(0.25e-9 * force, rel=1e-12)
