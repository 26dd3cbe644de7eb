"""Model options beyond the paper (docs/fidelity.md): each off by default, each a law.

Laws checked here: fibre mass and volume conserved by every option (areal weight and Vf to
1e-9); chain internal Vf: ``n fill pi d^2 / 4`` = fibre cross-section and ``EA = E A_fibre``;
waviness: bonds at rest, no fibre overlap, displacement amplitude, closure across the cell;
bending: ``EI = N_f E pi d_f^4 / 64``, ``K = EI / s`` (cosine) or ``EI / (2 s)`` (harmonic),
LAMMPS angle energy ``3 EI y^2 / s^3`` for one bead moved by ``y``, the time step's zigzag bound;
stitch packing: ``d = sqrt(4 T / (pi rho phi))``, mass per length = dtex; fibre-stitch friction
only in the pair coefficients of the fibre-stitch type pairs.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import assert_model_invariants, tiny_spec

from ncf2lammps import build, build_model, units
from ncf2lammps.engine import Engine
from ncf2lammps.io.datafile import read_data, write_data
from ncf2lammps.numerics import time_step
from ncf2lammps.spec import SpecError

WAVY = {"waviness_amplitude_um": 100.0, "waviness_waves_per_cell": 2}


def fibre_cross_section(spec, ply_index, model):
    """Fibre cross-section (um^2) of one ply across the cell: areal weight / density x width."""
    ply = spec.plies[ply_index]
    width = model.box.lengths[1] if ply.angle_deg == 0.0 else model.box.lengths[0]
    rho = units.to_micro(ply.density_g_cm3, "g_cm3")
    return units.to_micro(ply.areal_weight_g_m2, "g_m2") / rho * width


# --- spec -------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("table", "key", "bad", "range_text"),
    [
        ("discretisation", "chain_internal_fvf", 0.4, "[0.5, 1]"),
        ("discretisation", "chain_internal_fvf", 1.1, "[0.5, 1]"),
        ("discretisation", "bending", "stiff", "none, harmonic, cosine"),
        ("mat", "waviness_amplitude_um", -1.0, "[0, 5000] um"),
        ("mat", "waviness_waves_per_cell", 1.5, "whole number"),
        ("mat", "waviness_plane", "diagonal", "in-plane, out-of-plane"),
        ("mat", "waviness_phase_spread_deg", 400.0, "[0, 360] deg"),
        ("stitch", "packing_fraction", 0.2, "[0.3, 1]"),
        ("contact", "fibre_stitch_friction", 3.0, "[0, 2]"),
    ],
)
def test_new_keys_refuse_values_outside_their_range(table, key, bad, range_text):
    with pytest.raises(
        SpecError, match=rf"^{table}\.{key} = .*{__import__('re').escape(range_text)}"
    ):
        tiny_spec(**{table: {key: bad}})


@pytest.mark.parametrize(
    ("tables", "field"),
    [
        ({"stitch": {"diameter_um": 30.0, "packing_fraction": 0.6}}, "stitch.packing_fraction"),
        (
            {"discretisation": {"bending": "cosine"}, "mat": {"waviness_amplitude_um": 10.0}},
            "discretisation.bending",
        ),
        (
            {
                "stitch": None,
                "cell": {"length_mm": 3, "width_mm": 3},
                "contact": {"fibre_stitch_friction": 0.2},
            },
            "contact.fibre_stitch_friction",
        ),
        ({"manufacture": {"creep_window_us": 500.0}}, "manufacture.creep_window_us"),
    ],
)
def test_inconsistent_options_are_refused_by_field(tables, field):
    with pytest.raises(SpecError) as err:
        tiny_spec(**tables)
    assert err.value.field == field


def test_defaults_are_the_papers_model():
    spec = tiny_spec()
    assert spec.discretisation.chain_internal_fvf == 1.0
    assert spec.discretisation.bending == "none"
    assert spec.mat.waviness_amplitude_um == 0.0
    assert spec.stitch.packing_fraction == 1.0
    assert spec.contact.fibre_stitch_friction is None
    assert spec.manufacture.stitch_creep_target_per_ms is None
    model = build_model(spec)
    assert model.n_angles == 0 and model.angle_style == "none"


# --- chain internal Vf ------------------------------------------------------------------------


@pytest.mark.parametrize("fill", [0.907, 0.6])
def test_chain_internal_fvf_keeps_fibre_mass_and_stiffness(fill):
    # Bundles of internal Vf 0.6 hold at most 0.6 pi / (2 sqrt 3) = 0.544 of fibre: the
    # compaction must stop below that (the default 0.67 is refused).
    spec = tiny_spec(discretisation={"chain_internal_fvf": fill}, compaction={"final_fvf": 0.5})
    model = build_model(spec)
    assert_model_invariants(spec, model)
    for index, t in enumerate(model.atom_types):
        if t.role != "fibre":
            continue
        chains, _ = model.count(t.name)
        fibre_area = fill * np.pi * t.diameter**2 / 4
        # n fill pi d^2 / 4 is the ply's fibre cross-section: the chains are 1/sqrt(fill) thicker.
        assert chains * fibre_area == pytest.approx(fibre_cross_section(spec, index, model), 1e-12)
        bond = model.bond_types[index]
        assert bond.axial_stiffness == pytest.approx(t.modulus * fibre_area, rel=1e-12)
        assert bond.k == pytest.approx(t.modulus * fibre_area / (2 * bond.r0), rel=1e-12)


# --- waviness ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "mat",
    [
        WAVY,
        {**WAVY, "waviness_phase_spread_deg": 0.0},
        {"waviness_amplitude_um": 40.0, "waviness_plane": "out-of-plane", "initial_fvf": 0.15},
    ],
)
def test_wavy_chains_conserve_fibre_stay_at_rest_and_apart(mat):
    spec = tiny_spec(mat=mat)
    model = build_model(spec)
    assert_model_invariants(spec, model)
    # The displacement of a 0 deg chain (along x) oscillates with the spec's amplitude.
    index = [t.angle_deg for t in model.atom_types].index(0.0)
    chain = model.mol_id == model.mol_id[model.type_id == index][0]
    axis = 2 if mat.get("waviness_plane") == "out-of-plane" else 1
    u = model.positions[chain, axis]
    assert np.ptp(u) / 2 == pytest.approx(mat["waviness_amplitude_um"], rel=0.02)


def test_waviness_is_seeded():
    a = build_model(tiny_spec(mat=WAVY))
    b = build_model(tiny_spec(mat=WAVY))
    c = build_model(tiny_spec(mat={**WAVY, "seed": 7}))
    assert np.array_equal(a.positions, b.positions)
    assert not np.array_equal(a.positions, c.positions)


@pytest.mark.parametrize(
    ("mat", "field"),
    [
        ({"waviness_amplitude_um": 800.0}, "mat.waviness_amplitude_um"),
        (
            {"waviness_amplitude_um": 40.0, "waviness_plane": "out-of-plane"},
            "mat.waviness_amplitude_um",
        ),
        (
            {"waviness_amplitude_um": 10.0, "waviness_waves_per_cell": 50},
            "mat.waviness_waves_per_cell",
        ),
    ],
)
def test_waviness_that_would_overlap_is_refused(mat, field):
    with pytest.raises(SpecError) as err:
        build_model(tiny_spec(mat=mat))
    assert err.value.field == field


# --- bending ----------------------------------------------------------------------------------


@pytest.mark.parametrize("style", ["cosine", "harmonic"])
def test_bending_coefficient_from_filament_count(style):
    spec = tiny_spec(discretisation={"bending": style, "chain_internal_fvf": 0.8})
    model = build_model(spec)
    fibre = model.role_mask("fibre")
    assert model.n_angles == fibre.sum()  # one angle per fibre bead, none on the stitch
    assert np.all(fibre[model.angles].all(axis=1))
    for t in model.angle_types:
        ply = spec.plies[int(t.name[3])]
        atom = model.atom_types[int(t.name[3])]
        d_f = ply.filament_diameter_um
        n_f = 0.8 * atom.diameter**2 / d_f**2  # filaments per chain
        ei = n_f * atom.modulus * np.pi * d_f**4 / 64
        assert t.bending_stiffness == pytest.approx(ei, rel=1e-12)
        expected_k = ei / t.spacing if style == "cosine" else ei / (2 * t.spacing)
        assert t.k == pytest.approx(expected_k, rel=1e-12)
        assert t.theta0 == 180.0


def test_without_bending_no_angle_anywhere(tmp_path):
    result = build(tiny_spec(), tmp_path / "run")
    assert "angle" not in (result.directory / "model.data").read_text().lower()
    for deck in result.decks.values():
        commands = [ln.split() for ln in deck.text.splitlines() if ln.strip()]
        assert not any(
            w[0].startswith("angle_")
            or (w[:3] == ["atom_style", "hybrid", "sphere"] and "angle" in w)
            for w in commands
        ), deck.name
    bent = build(tiny_spec(discretisation={"bending": "cosine"}), tmp_path / "bent")
    verify = bent.decks["verify"].text
    assert "atom_style      hybrid sphere angle" in verify and "angle_style     cosine" in verify


def test_angles_round_trip(tmp_path):
    model = build_model(tiny_spec(discretisation={"bending": "harmonic"}, mat=WAVY))
    data = read_data(write_data(tmp_path / "model.data", model))
    assert np.array_equal(data.angles, model.angles)
    assert np.array_equal(data.angle_type, model.angle_type)
    np.testing.assert_array_equal(data.angle_coeffs[:, 0], [t.k for t in model.angle_types])
    np.testing.assert_array_equal(data.angle_coeffs[:, 1], [t.theta0 for t in model.angle_types])
    assert data.angle_labels == tuple(t.name for t in model.angle_types)
    assert np.array_equal(data.bonds, model.bonds)


def test_time_step_includes_bending():
    """Softened bonds (fibre_stiffness_scaling 1e-3) leave bending (unscaled) to govern: the
    angle limit is sqrt(m / (4 EI / s^3)) (zigzag mode) and dt falls to fraction x that."""
    numerics = {"fibre_stiffness_scaling": 1e-3}
    plain_spec = tiny_spec(numerics=numerics, stitch=None, cell={"length_mm": 3, "width_mm": 3})
    bent_spec = plain_spec.replace(
        discretisation={"bending": "cosine"},
        ply=[{"angle_deg": 90.0, "filament_diameter_um": 50.0}, {"filament_diameter_um": 50.0}],
    )
    plain, bent = build_model(plain_spec), build_model(bent_spec)
    step_plain, step_bent = time_step(plain_spec, plain), time_step(bent_spec, bent)
    t = bent.angle_types[0]
    mass = bent.mass[bent.type_id == 0].min()
    expected = np.sqrt(mass / (4 * t.bending_stiffness / t.spacing**3))
    assert step_bent.limits[f"bending {bent.atom_types[0].name}"] == pytest.approx(expected, 1e-12)
    assert step_bent.critical == pytest.approx(min(step_bent.limits.values()), rel=1e-12)
    assert step_bent.dt < 0.9 * step_plain.dt
    assert step_bent.dt == pytest.approx(bent_spec.numerics.dt_fraction * step_bent.critical)


# --- stitch yarn ------------------------------------------------------------------------------


def _stitch_bonds(model):
    """[(bond type, count)] of the stitch's bond types."""
    return [
        (t, np.sum(model.bond_type == i))
        for i, t in enumerate(model.bond_types)
        if t.role == "stitch"
    ]


def _assert_the_yarns_mass_and_stiffness(model, stitch):
    """The stitch's mass per yarn length is its dtex (total mass = tex x the yarns' polyline
    length, to 1e-9) and every stitch bond's EA = E x fibre area = E tex / rho (to 1e-12)."""
    rho = units.to_micro(stitch.density_g_cm3, "g_cm3")
    tex = units.to_micro(stitch.linear_density_dtex, "dtex")
    bonds = _stitch_bonds(model)
    length = sum(t.r0 * count for t, count in bonds)
    assert model.mass[model.role_mask("stitch")].sum() == pytest.approx(tex * length, rel=1e-9)
    ea = units.to_micro(stitch.E_GPa, "GPa") * tex / rho
    for t, _ in bonds:
        assert t.axial_stiffness == pytest.approx(ea, rel=1e-12)


def test_stitch_packing_fraction_sets_diameter_not_mass_or_stiffness():
    solid = build_model(tiny_spec())
    spec = tiny_spec(stitch={"packing_fraction": 0.6})
    loose = build_model(spec)
    stitch = spec.stitch
    rho = units.to_micro(stitch.density_g_cm3, "g_cm3")
    tex = units.to_micro(stitch.linear_density_dtex, "dtex")
    d = np.sqrt(4 * tex / (np.pi * rho * 0.6))
    assert loose.atom_types[-1].diameter == pytest.approx(d, rel=1e-12)
    for model in (solid, loose):  # whatever the packing
        _assert_the_yarns_mass_and_stiffness(model, stitch)
    assert_model_invariants(spec, loose)


def test_stitch_contact_diameter_thins_the_beads_not_the_yarn():
    """A flattened yarn (``contact_diameter_um`` 40 um, the round yarn 83.7 um): the stitch
    beads have that diameter, are spaced by ``bead_spacing_ratio`` x it (mean bond within 5 %)
    and lie one bead radius plus 1 % of it below the fibres' lowest surface; the yarn's mass per
    length (its dtex) and axial stiffness E T / rho stay the round yarn's (to 1e-9). A contact
    diameter above the yarn's is refused, naming the field and the yarn's diameter."""
    spec = tiny_spec(stitch={"contact_diameter_um": 40.0})
    stitch = spec.stitch
    rho = units.to_micro(stitch.density_g_cm3, "g_cm3")
    tex = units.to_micro(stitch.linear_density_dtex, "dtex")
    for model, d in (
        (build_model(tiny_spec()), np.sqrt(4 * tex / (np.pi * rho))),
        (build_model(spec), 40.0),
    ):
        bonds = _stitch_bonds(model)
        length = sum(t.r0 * count for t, count in bonds)
        assert model.atom_types[-1].diameter == pytest.approx(d, rel=1e-12)
        assert length / sum(c for _, c in bonds) == pytest.approx(0.5 * d, rel=0.05)
        _assert_the_yarns_mass_and_stiffness(model, stitch)
        fibre = model.role_mask("fibre")
        bottom = np.min(model.positions[fibre, 2] - model.diameter[fibre] / 2)
        stitch_z = model.positions[model.role_mask("stitch"), 2]
        assert stitch_z.min() == pytest.approx(bottom - 0.51 * d, abs=1e-9)
    with pytest.raises(SpecError, match=r"stitch.contact_diameter_um.*83.74 um"):
        build_model(tiny_spec(stitch={"contact_diameter_um": 100.0}))


# --- friction ---------------------------------------------------------------------------------


def test_fibre_stitch_friction_only_on_fibre_stitch_pairs(tmp_path):
    result = build(tiny_spec(contact={"fibre_stitch_friction": 0.15}), tmp_path / "run")
    deck = result.decks["verify"].text
    lines = [ln.split() for ln in deck.splitlines() if ln.startswith("pair_coeff")]
    mu = {(w[1], w[2]): float(w[w.index("linear_history") + 3]) for w in lines}
    assert mu == {("*", "*"): 0.3, ("1", "3"): 0.15, ("2", "3"): 0.15}
    default = build(tiny_spec(), tmp_path / "default").decks["verify"].text
    assert sum(ln.startswith("pair_coeff") for ln in default.splitlines()) == 1


# --- LAMMPS -----------------------------------------------------------------------------------


@pytest.mark.lammps
def test_lammps_runs_every_option_and_bends_by_the_law(tmp_path, monkeypatch):
    """All options on: LAMMPS reads the files, the wavy chains start with zero angle energy
    (rest angles from the geometry, < 1e-9 EI/s), 100 steps stay finite; then a straight chain
    (cosine) with one bead moved by y = 1e-3 s stores 3 EI y^2 / s^3 (to 1e-4)."""
    spec = tiny_spec(
        discretisation={"bending": "harmonic", "chain_internal_fvf": 0.85},
        mat={"waviness_amplitude_um": 60.0, "waviness_waves_per_cell": 1},
        stitch={"packing_fraction": 0.7, "contact_diameter_um": 60.0},
        contact={"fibre_stitch_friction": 0.2},
    )
    result = build(spec, tmp_path / "wavy")
    model = result.model
    scale = min(t.bending_stiffness / t.spacing for t in model.angle_types)
    monkeypatch.chdir(result.directory)
    with Engine(log="log.verify.lammps") as engine:
        engine.file("decks/in.verify.lmp")
        assert engine.nangles == model.n_angles
        engine.command("compute bend all pe angle")
        engine.command("run 0")
        assert abs(engine.compute_scalar("bend")) < 1e-9 * scale
        engine.command("run 100")
        assert np.isfinite(engine.thermo("pe")) and np.isfinite(engine.thermo("ke"))

    straight = build(tiny_spec(discretisation={"bending": "cosine"}), tmp_path / "straight")
    t = straight.model.angle_types[0]
    y = 1e-3 * t.spacing
    monkeypatch.chdir(straight.directory)
    with Engine(log=None) as engine:
        engine.file("decks/in.verify.lmp")
        engine.command("compute bend all pe angle")
        engine.command("group moved id 1")
        engine.command(f"displace_atoms moved move 0 0 {y!r}")
        engine.command("run 0")
        energy = engine.compute_scalar("bend")
    assert energy == pytest.approx(3 * t.bending_stiffness * y**2 / t.spacing**3, rel=1e-4)
