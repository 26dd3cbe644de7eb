"""Stiff and extreme cases (issue 6): each runs stably to the end or stops with a guard's
diagnosis; never a NaN in the results, never a silent blow-up."""

from __future__ import annotations

import subprocess
import sys

import h5py
import numpy as np
import pytest
from conftest import case_spec

from ncf2lammps import run
from ncf2lammps.engine import UnstableRunError
from ncf2lammps.io.results import read_results
from ncf2lammps.io.spectoml import dumps_spec

#: Small and fast: the mat-only cell compacted quickly to Vf 0.5.
FAST = {"inertial_number": 0.5, "final_fvf": 0.5}


def outcome(spec, folder):
    """'finished' with finite results, or 'guard' with a diagnosis and an incomplete file."""
    try:
        results = read_results(run(spec, folder, scenes=["compaction"]))
    except UnstableRunError as err:
        message = str(err)
        assert "\n" not in message and "step" in message
        with h5py.File(folder / "results.h5") as fh:
            assert not fh.attrs["complete"]
        return "guard", message
    for group in (g for name, g in results.items() if name != "attrs"):
        for name, values in group.items():
            if name != "attrs":
                assert np.all(np.isfinite(values)), name
    return "finished", results


@pytest.mark.parametrize(
    "tables",
    [
        {"contact": {"friction": 0.0}},
        {"contact": {"friction": 1.0}},
        {"ply": [{"angle_deg": 0.0, "E_GPa": 2400.0}, {"angle_deg": 90.0, "E_GPa": 2.4}]},
        {"numerics": {"dt_fraction": 1.2, "allow_unstable_dt": True}},
    ],
    ids=["mu0", "mu1", "fibre-E-x10-and-div100", "dt-1.5x-limit"],
)
def test_extreme_cases_finish_or_stop_with_diagnosis(tables, tmp_path):
    spec = case_spec("mat-only").replace(compaction=FAST, **tables)
    kind, _ = outcome(spec, tmp_path / "run")
    assert kind in ("finished", "guard")


def test_far_too_large_time_step_trips_a_guard_and_cli_exits_1(tmp_path):
    """dt = 4 sqrt(m/k) (allowed explicitly) must not produce numbers: a guard stops it."""
    spec = case_spec("mat-only").replace(
        compaction=FAST, numerics={"dt_fraction": 2.0, "allow_unstable_dt": True}
    )
    path = tmp_path / "spec.toml"
    path.write_text(dumps_spec(spec).replace("dt_fraction = 2.0", "dt_fraction = 2.0"))
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
