"""Stiff and extreme cases: each either runs stably to the end with finite results or stops
with a guard's one-line diagnosis, and each asserts which of the two it does (measured on one
rank, which is deterministic); never a NaN in the results, never a silent blow-up."""

from __future__ import annotations

import re
import subprocess
import sys

import h5py
import numpy as np
import pytest
from conftest import case_spec, tiny_spec

from ncf2lammps import build, run
from ncf2lammps.engine import Engine, UnstableRunError, run_deck
from ncf2lammps.io.results import read_results
from ncf2lammps.io.spectoml import dumps_spec

#: Small and fast: the mat-only cell compacted quickly, at a constant plate speed, to Vf 0.5
#: (past the default end at 100 kPa, where the extreme cases show).
FAST = {"inertial_number": 0.5, "final_fvf": 0.5, "end": "final_fvf", "loading": "constant"}


def outcome(spec, folder, scene="compaction"):
    """('finished', results) with finite results, or (guard name, diagnosis) with a one-line
    diagnosis and an incomplete results.h5 (guard names: speed, bond, overlap, kinetic from the
    deck's ``fix halt``; lost-atoms and NaN from the driver)."""
    try:
        results = read_results(run(spec, folder, scenes=[scene]))
    except UnstableRunError as err:
        message = str(err)
        assert "\n" not in message and "step" in message
        with h5py.File(folder / "results.h5") as fh:
            assert not fh.attrs["complete"]
        named = re.match(r"guard '(\w+)'|(\S+) guard", message)
        return next(g for g in named.groups() if g), message
    for group in (g for name, g in results.items() if name != "attrs"):
        for name, values in group.items():
            if name != "attrs":
                assert np.all(np.isfinite(values)), name
    return "finished", results


@pytest.mark.parametrize(
    ("tables", "expected"),
    [
        ({"contact": {"friction": 0.0}}, "finished"),
        ({"contact": {"friction": 1.0}}, "finished"),
        (
            {"ply": [{"angle_deg": 0.0, "E_GPa": 1200.0}, {"angle_deg": 90.0, "E_GPa": 2.4}]},
            "finished",
        ),
        ({"numerics": {"dt_fraction": 1.2, "allow_unstable_dt": True}}, "lost-atoms"),
        (
            {
                "mat": {"initial_fvf": 0.6},
                "cell": {"length_mm": 1.0, "width_mm": 1.0},
                "discretisation": {"chain_diameter_um": 65.0},
                "compaction": {**FAST, "final_fvf": 0.75},
            },
            "finished",
        ),
        ({"compaction": {**FAST, "final_fvf": 0.8}}, "finished"),
        ({"discretisation": {"chain_diameter_um": 100.0, "bead_spacing_ratio": 1.0}}, "finished"),
        ({"discretisation": {"chain_diameter_um": 200.0, "bead_spacing_ratio": 0.25}}, "finished"),
        (
            {
                "cell": {"length_mm": 0.4, "width_mm": 0.4},
                "discretisation": {"chain_diameter_um": 190.0},
            },
            "finished",
        ),
    ],
    ids=[
        "mu0",
        "mu1",
        "fibre-E-x5-and-div100",
        "dt-1.5x-limit",
        "initial-fvf-0.6",
        "compaction-to-fvf-0.8",
        "bead-spacing-d",
        "bead-spacing-d/4",
        "one-chain-per-ply",
    ],
)
@pytest.mark.lammps
def test_extreme_cases_finish_or_stop_with_diagnosis(tables, expected, tmp_path):
    spec = case_spec("mat-only").replace(**{"compaction": FAST, **tables})
    kind, detail = outcome(spec, tmp_path / "run")
    assert kind == expected, detail


@pytest.mark.lammps
def test_shear_to_60_degrees_finishes_or_stops_with_diagnosis(tmp_path):
    spec = case_spec("mat-only").replace(shear={"final_angle_deg": 60.0, "inertial_number": 0.4})
    kind, result = outcome(spec, tmp_path / "run", scene="shear")
    assert kind == "finished", result
    assert result["shear"]["angle_deg"][-1] == pytest.approx(60.0, abs=0.5)


@pytest.mark.lammps
def test_stitch_modulus_x100_manufacture_finishes_or_stops_with_diagnosis(tmp_path):
    """PES stitch at 1200 GPa: the stitch bonds set the time step, 10 x smaller. Masses x 100
    bring the step count back to CI size; scaling every mass alike keeps the stiffness contrast
    (stitch 100 x stiffer than before against fibres and contacts) that makes the case stiff."""
    spec = tiny_spec(
        stitch={"E_GPa": 1200.0},
        numerics={"mass_scaling": 100.0},
        manufacture={"pretension_strain_rate_per_us": 0.02, "damping_time_us": 10.0},
    )
    kind, result = outcome(spec, tmp_path / "run", scene="manufacture")
    assert kind == "lost-atoms", result


@pytest.mark.lammps
def test_a_bead_through_a_needle_wall_stops_with_a_diagnosis(tmp_path):
    """The coarse case's manufacture at dt = 3.8 sqrt(m/k) (allowed explicitly): a bead crosses
    a needle's wall within one step, and LAMMPS's 'Particle outside surface of region' becomes
    the wall guard's one-line diagnosis with the step and what to lower."""
    spec = case_spec("hpt310-coarse").replace(
        numerics={"dt_fraction": 1.9, "allow_unstable_dt": True}
    )
    kind, message = outcome(spec, tmp_path / "run", scene="manufacture")
    assert kind == "wall", message
    assert "numerics.dt_fraction" in message and "needle_speed_m_s" in message


@pytest.mark.lammps
def test_far_too_large_time_step_trips_a_guard_and_cli_exits_1(tmp_path):
    """dt = 4 sqrt(m/k) (allowed explicitly) must not produce numbers: a guard stops it."""
    spec = case_spec("mat-only").replace(
        compaction=FAST, numerics={"dt_fraction": 2.0, "allow_unstable_dt": True}
    )
    path = tmp_path / "spec.toml"
    path.write_text(dumps_spec(spec))
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "ncf2lammps.cli",
            "run",
            str(path),
            "-o",
            str(tmp_path / "run"),
            "--scene",
            "compaction",
        ],
        capture_output=True,
        text=True,
    )
    assert out.returncode == 1, out.stderr
    assert "guard" in out.stderr and "step" in out.stderr
    assert "Traceback" not in out.stderr
    with h5py.File(tmp_path / "run" / "results.h5") as fh:
        assert not fh.attrs["complete"]


def _compaction_with(tmp_path, monkeypatch, extra) -> UnstableRunError:
    """The mat-only compaction deck with the lines ``extra(built)`` inserted before its last
    ``run``, run in its folder; the guard error it must raise."""
    spec = case_spec("mat-only").replace(compaction=FAST)
    built = build(spec, tmp_path / "run")
    deck = built.directory / "decks" / "in.compaction.lmp"
    lines = deck.read_text().splitlines()
    last_run = max(i for i, line in enumerate(lines) if line.startswith("run "))
    lines[last_run:last_run] = extra(built)
    deck.write_text("\n".join(lines) + "\n")
    monkeypatch.chdir(built.directory)
    with Engine(log=None) as engine, pytest.raises(UnstableRunError) as err:
        run_deck(engine, deck, chunk=10_000)
    return err.value


@pytest.mark.lammps
def test_kinetic_energy_jump_trips_the_kinetic_guard(tmp_path, monkeypatch):
    """A uniform kick along x of 0.01 d per step: a tenth of the step-move limit, no overlap, no
    stretched bond, yet the kinetic energy jumps ~1e4 x above the guard's floor (an rms move of
    1e-4 d per step) at the first check. The kinetic guard, and no other, must stop it: a box
    that jumped in one step (the shear deck's fix deform once did) looks just like this."""

    def kick(built) -> list[str]:
        speed = 0.01 * float(built.model.diameter.min()) / built.time_step.dt
        return [f"velocity        all set {speed!r} 0.0 0.0 sum yes units box"]

    err = _compaction_with(tmp_path, monkeypatch, kick)
    assert "guard 'kinetic' at step" in str(err)
    assert "kinetic energy grew" in str(err)


@pytest.mark.lammps
def test_a_bead_past_a_plate_trips_the_plate_guard(tmp_path, monkeypatch):
    """A granular plate skips a bead whose centre has passed it, silently. The mat's lowest
    layer of chains, moved down by 0.6 d before the compaction's run, lies past the bottom
    plate: the plate guard, and no other, stops the run at its first check with the count and
    what to change."""

    def sink(built) -> list[str]:
        diameter = float(built.model.diameter.max())
        return [
            "variable        lowest atom z<$(bound(all,zmin)+1.0)",
            "group           sunk variable lowest",
            f"displace_atoms  sunk move 0.0 0.0 {-0.6 * diameter!r} units box",
        ]

    err = _compaction_with(tmp_path, monkeypatch, sink)
    assert "guard 'plate' at step" in str(err)
    assert "passed through a compaction plate" in str(err)
