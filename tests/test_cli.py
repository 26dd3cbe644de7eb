"""The command line: output, exit codes, one-line errors, no silent overwrite."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT

COARSE = str(ROOT / "runs" / "hpt310-coarse" / "spec.toml")


def cli(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "ncf2lammps.cli", *args], capture_output=True, text=True, cwd=cwd
    )


def test_check_prints_sizes_and_time_step():
    out = cli("check", COARSE)
    assert out.returncode == 0, out.stderr
    for words in (
        "cell          11.2 x 5.08 mm",
        "atoms",
        "areal weight  fibre 300",
        "time step",
        "margin",
    ):
        assert words in out.stdout
    assert "replica" not in out.stdout


def test_check_prints_each_scenes_checkpoint_interval(tmp_path):
    """The interval each scene checkpoints at: the spec's 100,000 rounded up to the deck's
    recording period (the coarse compaction deck guards every 100 steps and records every 150:
    100,200), or none."""
    out = cli("check", COARSE)
    assert out.returncode == 0, out.stderr
    assert "checkpoints   manufacture every 100,000, compaction every 100,200, shear every" in (
        out.stdout
    )
    assert "(output.checkpoint_every_steps = 100,000 rounded up" in out.stdout
    spec = tmp_path / "none.toml"
    spec.write_text(Path(COARSE).read_text() + "\n[output]\ncheckpoint_every_steps = 0\n")
    out = cli("check", spec)
    assert "checkpoints   none (output.checkpoint_every_steps = 0)" in out.stdout


def test_check_names_a_replica_and_its_perturbation(tmp_path):
    """A spec with numerics.perturbation_seed: `check` says that every scene moves the beads."""
    spec = tmp_path / "replica.toml"
    spec.write_text(Path(COARSE).read_text() + "\n[numerics]\nperturbation_seed = 7\n")
    out = cli("check", spec)
    assert out.returncode == 0, out.stderr
    assert "numerics.perturbation_seed = 7: each scene starts by moving every bead" in out.stdout


def test_check_piped_into_a_reader_that_stops_leaves_no_traceback():
    """`ncf2lammps check SPEC | head -1`: a closed pipe is not worth a traceback (exit 1)."""
    read_end, write_end = os.pipe()
    os.close(read_end)  # the reader has gone: every write gets EPIPE
    try:
        out = subprocess.run(
            [sys.executable, "-m", "ncf2lammps.cli", "check", COARSE],
            stdout=write_end,
            stderr=subprocess.PIPE,
            text=True,
        )
    finally:
        os.close(write_end)
    assert out.returncode == 1 and out.stderr == "", out.stderr


@pytest.mark.parametrize(
    ("text", "field"),
    [
        ("[[ply]]\nangle_deg = 120\n[cell]\nlength_mm = 2\nwidth_mm = 2\n", "ply[0].angle_deg"),
        (
            "[[ply]]\n[cell]\nlength_mm = 2\nwidth_mm = 2\n[mat]\ninitial_fvf = 0.9\n",
            "mat.initial_fvf",
        ),
        (
            "[[ply]]\n[cell]\nlength_mm = 2\nwidth_mm = 2\n[numerics]\ndt_fraction = 1.5\n",
            "numerics.dt_fraction",
        ),
        ("[[ply]\n", "<file>"),
    ],
)
def test_bad_input_exits_2_with_one_line(tmp_path, text, field):
    spec = tmp_path / "spec.toml"
    spec.write_text(text)
    for verb in (["check", str(spec)], ["build", str(spec), "-o", str(tmp_path / "out")]):
        out = cli(*verb)
        assert out.returncode == 2
        assert out.stderr.count("\n") == 1 and field in out.stderr, out.stderr
        assert "Traceback" not in out.stderr
    assert not (tmp_path / "out").exists()


def test_build_writes_folder_and_refuses_to_overwrite(tmp_path):
    out = cli("build", COARSE, "-o", str(tmp_path / "run"))
    assert out.returncode == 0, out.stderr
    for name in ("model.data", "spec.resolved.toml", "decks/in.verify.lmp"):
        assert (tmp_path / "run" / name).is_file()
    again = cli("build", COARSE, "-o", str(tmp_path / "run"))
    assert again.returncode == 2 and "not empty" in again.stderr
    forced = cli("build", COARSE, "-o", str(tmp_path / "run"), "--force")
    assert forced.returncode == 0
    assert not list(tmp_path.glob("run.partial-*"))


def test_every_verb_has_help():
    for verb in ("check", "build", "run", "export", "report"):
        assert cli(verb, "--help").returncode == 0


@pytest.mark.lammps
def test_run_with_relative_output_folder(tmp_path):
    """The README runs with a relative -o: the whole chain must resolve it once."""
    spec = tmp_path / "spec.toml"
    spec.write_text(
        (ROOT / "runs" / "mat-only" / "spec.toml").read_text()
        + "\n[compaction]\ninertial_number = 0.5\nfinal_fvf = 0.4\n"
    )
    out = cli("run", "spec.toml", "-o", "out", "--scene", "compaction", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert (tmp_path / "out" / "summary.md").is_file()
    assert (tmp_path / "out" / "figures" / "compaction.png").is_file()
