"""Compaction scene: plates close on the manufactured coarse cell."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import assert_loading_follows_its_law, case_spec, copy_run

from ncf2lammps import build, prepare, run, run_scenes
from ncf2lammps.analysis.compaction import CompactionCurve, first_crossings, smooth
from ncf2lammps.io.lammpslog import read_ave_time
from ncf2lammps.io.results import read_results
from ncf2lammps.scenes import SCENES

#: The default (adaptive) plates to Vf 0.55, past the default end: enough for the curve's shape
#: and the bookkeeping; the rate dependence is measured separately (docs/compaction.md).
FAST = {"final_fvf": 0.55, "end": "final_fvf"}


@pytest.fixture(scope="module")
def compacted(coarse_manufactured, tmp_path_factory):
    spec = case_spec("hpt310-coarse").replace(compaction=FAST)
    folder = copy_run(coarse_manufactured, tmp_path_factory.mktemp("compaction") / "run")
    results = run_scenes(spec, folder, ["compaction"])
    return spec, folder, read_results(results)["compaction"]


@pytest.mark.lammps
def test_contract_names_and_lengths(compacted):
    _, folder, group = compacted
    lengths = {len(group[k]) for k in ("gap_mm", "pressure_kPa", "fvf")}
    assert len(lengths) == 1 and lengths.pop() > 50
    for key in (
        "thickness_at_1kPa_mm",
        "thickness_at_18kPa_mm",
        "fvf_at_18kPa",
        "wall_s",
        "steps",
        "max_kinetic_ratio",
        "max_kinetic_thickness_error",
        "kinetic_thickness_error_limit",
    ):
        assert key in group["attrs"]
    # The check is the largest record error from the first record at the reference pressure
    # (1 kPa) on; the coarse cell passes it.
    measured = np.maximum.accumulate(group["pressure_smoothed_kPa"] >= 1.0)
    largest = np.max(group["kinetic_thickness_error"][measured])
    assert group["attrs"]["max_kinetic_thickness_error"] == largest
    assert 0.0 < largest <= group["attrs"]["kinetic_thickness_error_limit"] == 0.01
    assert group["attrs"]["stopped_by"] == "final_fvf"
    # With end = "final_fvf" the deck has no pressure stop.
    assert "final_pressure" not in (folder / "decks" / "in.compaction.lmp").read_text()


@pytest.mark.lammps
def test_plates_follow_the_adaptive_loading_law(compacted):
    """The default loading is adaptive: every record's plate speed follows the controller's law
    from the interval's plate pressure, the gap closes by the integral of the speed, and the
    speed rises above the inertial-number speed once the cell carries the plates' load."""
    spec, folder, group = compacted
    prepared = prepare(spec)
    control = SCENES["compaction"].deck_values(prepared)["control"]
    history = read_ave_time(folder / "compaction.history.txt")
    assert control.adaptive
    assert_loading_follows_its_law(history, "v_gap", control, prepared.time_step.dt, -1)
    # Vf 0.55 is well past 18 kPa: the speed has risen with the pressure.
    assert group["attrs"]["max_plate_speed_m_s"] > 2.0 * group["attrs"]["plate_speed_m_s"]


@pytest.mark.lammps
def test_pressure_rises_monotonically_after_smoothing(compacted):
    """Closing plates on a frictional granular layer: the pressure smoothed over 15 um of travel
    never drops by more than 10 % of the running maximum once it exceeds 1 kPa (dynamic ripple
    and rearrangements aside). The records are taken every control interval, whose travel
    grows with the plate speed: the curve is read on a 1 um grid of the gap first."""
    _, _, group = compacted
    gap = group["gap_mm"]
    grid = np.arange(gap[0], gap[-1], -1e-3)
    pressure = smooth(np.interp(-grid, -gap, group["pressure_kPa"]), 15)
    loaded = pressure > 1.0
    running_max = np.maximum.accumulate(pressure)
    assert np.all(pressure[loaded] >= 0.9 * running_max[loaded])
    assert pressure[-1] > 18.0  # Vf 0.55 is past the 18 kPa of the experiment


@pytest.mark.lammps
def test_interpolated_attributes_agree_with_curve(compacted):
    """t@1 kPa, t@18 kPa lie on the recorded (smoothed) curve; Vf = A / (rho t)."""
    _, _, group = compacted
    attrs = group["attrs"]
    gap, smoothed = group["gap_mm"], group["pressure_smoothed_kPa"]
    for key, pressure in (("thickness_at_1kPa_mm", 1.0), ("thickness_at_18kPa_mm", 18.0)):
        t = attrs[key]
        assert gap.min() <= t <= gap.max()
        i = np.searchsorted(-gap, -t)
        assert smoothed[i - 1] <= pressure <= smoothed[i] + 1e-12
    assert attrs["thickness_at_18kPa_mm"] < attrs["thickness_at_1kPa_mm"]
    fvf = np.interp(-attrs["thickness_at_18kPa_mm"], -gap, group["fvf"])
    assert attrs["fvf_at_18kPa"] == pytest.approx(fvf, rel=1e-3)
    np.testing.assert_allclose(group["fvf"] * gap, group["fvf"][0] * gap[0], rtol=1e-12)


@pytest.mark.lammps
def test_plates_stop_at_the_first_record_past_max_pressure(tmp_path):
    """With ``max_pressure_kPa`` the plates stop at the first record whose pressure exceeds it
    (the halt checks on the record cadence): every earlier record is below, the last above,
    and Vf stops short of final_fvf; t at 18 kPa is still on the curve. The same run to
    final_fvf passes through the same records (one rank: deterministic), so its results at 1
    and 18 kPa agree, and the kinetic ratio, checked from the reference pressure on, is taken
    over a subset of its records: never larger. Bookkeeping, the same for any cell: on the
    unstitched mat (no manufacture) with fast plates (inertial number 0.5, whose first impact
    on the mat's top beads reads ~3 MPa for a record), stopped at 10 MPa."""
    limit = 1e4
    groups = {}
    for end in ("final_fvf", "max_pressure"):
        spec = case_spec("mat-only").replace(
            compaction={"inertial_number": 0.5, **FAST, "end": end, "max_pressure_kPa": limit}
        )
        folder = build(spec, tmp_path / end).directory
        groups[end] = read_results(run_scenes(spec, folder, ["compaction"]))["compaction"]
    full, group = groups["final_fvf"]["attrs"], groups["max_pressure"]
    assert groups["final_fvf"]["pressure_kPa"][-1] > limit
    attrs, pressure = group["attrs"], group["pressure_kPa"]
    assert attrs["stopped_by"] == "max_pressure_kPa"
    assert pressure[-1] > limit and np.all(pressure[:-1] <= limit)
    assert attrs["reached_fvf"] == pytest.approx(group["fvf"][-1])
    assert attrs["reached_fvf"] < FAST["final_fvf"]
    assert np.isfinite(attrs["thickness_at_18kPa_mm"])
    assert "final_pressure" in (folder / "decks" / "in.compaction.lmp").read_text()
    for key in ("thickness_at_1kPa_mm", "thickness_at_18kPa_mm"):
        assert attrs[key] == pytest.approx(full[key], rel=1e-9)
    assert attrs["max_kinetic_ratio"] <= full["max_kinetic_ratio"] * (1 + 1e-12)


def _linear_curve(gap, stiffness=2.0, kinetic=0.5, imbalance=0.1, window=5):
    """CompactionCurve of plates closing on a linear spring from ``gap[0]`` (um), 0.01 kPa/um."""
    gap = np.asarray(gap, dtype=float)
    force = stiffness * (gap[0] - gap)
    work = 0.5 * stiffness * (gap[0] - gap) ** 2
    return CompactionCurve(
        gap,
        0.01 * (gap[0] - gap),
        300.0,
        force_top=force * (1 + imbalance / 2),
        force_bottom=force * (1 - imbalance / 2),
        kinetic=np.full(len(gap), kinetic),
        potential=work,  # all the work stored: nothing dissipated
        reference_pressure=1.0,
        window=window,
    ).compute()


def test_curve_thickness_at_is_exact_on_a_line():
    curve = _linear_curve([1000.0, 900.0, 800.0, 700.0], window=1)
    assert curve.thickness_at(1.5) == pytest.approx(0.85)
    assert curve.fvf == pytest.approx(0.3 / curve.gap_mm)
    assert np.isnan(curve.thickness_at(10.0))


def test_force_share_of_a_part_carrying_a_fixed_fraction():
    """A part of the beads carrying 1/4 of the plates' mean force at every record has the
    share 1/4 wherever the smoothed plates carry load (NaN at the unsmoothed first record, at
    zero force), read at any pressure the curve reaches; ``value_at`` of the gap is
    ``thickness_at``. Tolerance 1e-12 (rounding)."""
    gap = np.linspace(1000.0, 500.0, 51)
    for window in (1, 5):
        curve = _linear_curve(gap, window=window)
        share = curve.force_share(0.25 * 0.5 * (curve.force_top + curve.force_bottom))
        assert share[1:] == pytest.approx(0.25, rel=1e-12)
        assert np.isnan(share[0]) == (window == 1)
    assert curve.value_at(share, 1.0) == pytest.approx(0.25, rel=1e-12)
    assert curve.value_at(curve.gap_mm, 1.5) == curve.thickness_at(1.5)
    assert np.isnan(curve.value_at(share, 1e3))


def test_curve_energetics_of_a_linear_spring():
    """F = k (h0 - h) on both plates, top (1 + e/2) F and bottom (1 - e/2) F, constant kinetic K,
    all work stored: the trapezoidal work is exact, ``W = k (h0 - h)^2 / 2``; the largest
    K / W is at the first record past the reference pressure (1 kPa at h0 - h = 100 um, in the
    unsmoothed interior); the imbalance is e; the residual 0. Tolerance 1e-12 (rounding)."""
    gap = np.linspace(1000.0, 500.0, 51)
    curve = _linear_curve(gap, stiffness=2.0, kinetic=0.5, imbalance=0.1)
    assert curve.work == pytest.approx((gap[0] - gap) ** 2, rel=1e-12)
    assert curve.loaded.tolist() == (gap <= 900.0).tolist()
    assert curve.max_kinetic_ratio == pytest.approx(0.5 / 100.0**2, rel=1e-12)
    assert curve.plate_force_imbalance == pytest.approx(0.1, rel=1e-12)
    assert curve.energy_balance_residual == pytest.approx(0.0, abs=1e-12)


@pytest.mark.lammps
def test_mat_only_compacts_without_manufacture(tmp_path):
    """All scenes of a mat without stitch: no manufacture; compaction and shear from the mat."""
    spec = case_spec("mat-only").replace(
        compaction={"inertial_number": 0.5, "final_fvf": 0.5},
        shear={"inertial_number": 0.5, "final_angle_deg": 5.0},
    )
    results = read_results(run(spec, tmp_path / "run"))
    assert "manufacture" not in results and "shear" in results
    assert results["compaction"]["attrs"]["thickness_at_1kPa_mm"] > 0.3


def test_stiffening_exponent_of_a_power_law_curve():
    """A curve with Vf = a P^b exactly (gap = A / Vf) returns b = ln(t1 / t18) / ln 18 to 1e-6."""
    b, a, per_area = 0.15, 0.25, 300.0
    pressure = np.geomspace(0.1, 100.0, 4000)
    curve = _loading_curve(per_area / (a * pressure**b), pressure, per_area)
    assert curve.stiffening_exponent(1.0, 18.0) == pytest.approx(b, rel=1e-6)


def _loading_curve(gap, pressure, per_area):
    """CompactionCurve of a pressure record (kPa) against gap (um) alone: no plate forces or
    energies, reference pressure 1 kPa, no smoothing."""
    zeros = np.zeros(len(gap))
    return CompactionCurve(
        gap,
        pressure,
        per_area,
        force_top=zeros,
        force_bottom=zeros,
        kinetic=zeros,
        potential=zeros,
        reference_pressure=1.0,
        window=1,
    ).compute()


def test_first_crossings_match_the_record_by_record_search():
    """On a noisy, non-monotonic record the vectorised crossings equal the scalar definition:
    the first record at or above the level, linear from the record before it (exact)."""
    rng = np.random.default_rng(3)
    x = np.linspace(900.0, 400.0, 200)
    pressure = np.linspace(0.0, 30.0, 200) + rng.normal(0.0, 1.5, 200)
    levels = np.concatenate([rng.uniform(-2.0, 35.0, 300), [pressure[0], pressure.max()]])

    def by_record(level):
        above = np.flatnonzero(pressure >= level)
        if len(above) == 0:
            return np.nan
        i = above[0]
        if i == 0:
            return x[0]
        return x[i - 1] + (level - pressure[i - 1]) / (pressure[i] - pressure[i - 1]) * (
            x[i] - x[i - 1]
        )

    expected = [by_record(level) for level in levels]
    assert first_crossings(x, pressure, levels) == pytest.approx(
        expected, rel=0, abs=0, nan_ok=True
    )


def _two_slope_curve(low_b, high_b, knee, start):
    """(CompactionCurve, pressure (4000,) kPa) of ``Vf ~ P^low_b`` below ``knee`` kPa and
    ``P^high_b`` above, from ``start`` kPa to 100 kPa (:func:`_loading_curve`)."""
    pressure = np.geomspace(start, 100.0, 4000)
    exponent = np.where(pressure < knee, low_b, high_b)
    gap = 1000.0 * (pressure / knee) ** -exponent
    return _loading_curve(gap, pressure, 300.0), pressure


def test_local_stiffening_exponent_is_the_secant_over_a_factor_2():
    """Two power laws, b = 0.05 below 10 kPa and 0.3 above, from 0.8 kPa: the local exponent is
    0.05 at 3 kPa and 0.3 at 30 kPa (windows on one side), the mean 0.175 at the knee (the
    window sqrt 2 either side of it), 0.05 at 1 kPa with the window held at the first record
    (0.8 kPa, not 0.71) and 0.3 at 100 kPa with it held at the highest. The kinetic thickness
    error of each record is its own Q times b at its pressure floored at 1 kPa. Tolerance 1e-5
    (linear interpolation between records)."""
    curve, pressure = _two_slope_curve(0.05, 0.3, 10.0, 0.8)
    local = curve.local_stiffening_exponent([3.0, 30.0, 10.0, 1.0, 100.0])
    assert local == pytest.approx([0.05, 0.3, 0.175, 0.05, 0.3], rel=1e-5)
    assert curve.local_stiffening_exponent(30.0) == pytest.approx([0.3], rel=1e-5)
    ratio = np.random.default_rng(5).uniform(0.0, 0.05, len(pressure))
    stress = np.maximum(pressure, 1.0)
    expected = ratio * curve.local_stiffening_exponent(stress)
    assert curve.kinetic_thickness_error(ratio) == pytest.approx(expected, rel=1e-12)
    # What the estimate stands for: the thickness read at a pressure 1 % too high moves by
    # Q b to first order, |(1 + Q)^-b - 1| = Q b (1 - (1 + b) Q / 2 + ...): within 1 %.
    for level, exponent in ((3.0, 0.05), (30.0, 0.3)):
        shift = 1.0 - curve.thickness_at(level * 1.01) / curve.thickness_at(level)
        assert shift == pytest.approx(0.01 * exponent, rel=0.01)
    below = pressure < 1.0
    assert curve.kinetic_thickness_error(ratio)[below] == pytest.approx(
        0.05 * ratio[below], rel=1e-5
    )
