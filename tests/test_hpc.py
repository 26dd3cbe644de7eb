"""HPC: the exported bundle under plain `mpiexec lmp`, 1 against 2 MPI ranks, and a run
killed mid-scene then resumed from its checkpoint, each against a Python-driven run on 1 rank.

The bundle runs on BUNDLE_RANKS = 1 rank: its decks differ from the Python-driven ones only by
their `restart` line, the same deck commands run on 2 ranks in `test_one_and_two_ranks_agree`,
and 2 bundle ranks beside the other pytest-xdist worker would oversubscribe a 2-core machine.

All on the coarse case with fast loading (inertial number 0.1 for compaction, 0.2 for shear,
compaction to Vf 0.35, shear to 20 deg) and checkpoints and dumps every 20,000 steps; the
manufacture settings are the case's, so the Python reference starts from the test run's shared
manufactured cell. Compaction stops at Vf 0.35, past 18 kPa (Vf 0.33) but well short of the
case's Vf 0.5: the plates move at a speed that does not depend on the final Vf, so t@1 kPa
(Vf 0.30) is that of the run to Vf 0.5, to the bit on one rank, in 45 % of the steps.
At 45 deg the shear rate trips the overlap guard, so the shear force compared is F_N averaged
over the last quarter of the angle range (15-20 deg): a single record interval at one angle
scatters by ~7 % between manufactured cells that differ only by round-off, the quarter mean by
~1 % (measured: bundle 6.40, Python 6.46, 2 ranks 6.38, 1 rank 6.48 N/m).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import case_spec, checkpoint_step, copy_run, kill_after_checkpoint

from ncf2lammps import run_scenes
from ncf2lammps.engine import Checkpoints
from ncf2lammps.io.results import read_results
from ncf2lammps.io.spectoml import write_spec
from ncf2lammps.orchestration.run import checkpoints, mpiexec
from ncf2lammps.scenes import Deck
from ncf2lammps.scenes.shear import SNAPSHOT_DEG

#: MPI ranks of the exported bundle's run (module docstring).
BUNDLE_RANKS = 1

FAST = {
    "compaction": {"inertial_number": 0.1, "final_fvf": 0.35},
    "shear": {"inertial_number": 0.2, "final_angle_deg": 20.0},
    "output": {"checkpoint_every_steps": 20_000, "dump_every_steps": 20_000},
}


def fast_spec():
    return case_spec("hpt310-coarse").replace(**FAST)


def last_quarter_force(shear: dict) -> float:
    """Mean F_N (N/m) over the last quarter of a shear group's angle range."""
    last = shear["angle_deg"] >= 0.75 * shear["attrs"]["final_angle_deg"]
    return float(shear["force_N_per_m"][last].mean())


def figures(results: dict) -> tuple[float, float]:
    """(thickness at 1 kPa in mm, mean F_N over the last quarter of the angle range in N/m)."""
    return (
        results["compaction"]["attrs"]["thickness_at_1kPa_mm"],
        last_quarter_force(results["shear"]),
    )


def cli(*args, **kwargs):
    return subprocess.run(
        [sys.executable, "-m", "ncf2lammps.cli", *args], capture_output=True, text=True, **kwargs
    )


@pytest.fixture(scope="module")
def reference(coarse_manufactured, tmp_path_factory):
    """Python-driven compaction and shear on one rank from the test run's shared manufactured cell."""
    folder = copy_run(coarse_manufactured, tmp_path_factory.mktemp("reference") / "run")
    return read_results(run_scenes(fast_spec(), folder, ["compaction", "shear"]))


@pytest.mark.lammps
def test_bundle_runs_under_mpiexec_lmp_and_its_report_matches_python(request, tmp_path):
    """t@1 kPa and F_N(15-20 deg) of the bundle (its own manufacture included) within 2 % of the
    Python-driven run (made once the bundle is done: under pytest-xdist the other worker makes
    the shared manufactured cell meanwhile)."""
    write_spec(tmp_path / "spec.toml", fast_spec())
    bundle = tmp_path / "bundle"
    out = cli("export", str(tmp_path / "spec.toml"), "-o", str(bundle), "--np", str(BUNDLE_RANKS))
    assert out.returncode == 0, out.stderr
    for name in ("in.run_all.lmp", "job.slurm", "README.md", "model.data", "decks/in.shear.lmp"):
        assert (bundle / name).is_file()
    assert "python" not in (bundle / "in.run_all.lmp").read_text()
    lmp = Path(mpiexec()).parent / "lmp"
    done = subprocess.run(
        [mpiexec(), "-n", str(BUNDLE_RANKS), str(lmp), "-in", "in.run_all.lmp"],
        cwd=bundle,
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stdout[-2000:]
    out = cli("report", str(bundle))
    assert out.returncode == 0, out.stderr
    results = read_results(bundle / "results.h5")
    assert bool(results["attrs"]["complete"]) and results["attrs"]["mpi_ranks"] == BUNDLE_RANKS
    reference = request.getfixturevalue("reference")
    for got, want in zip(figures(results), figures(reference), strict=True):
        assert got == pytest.approx(want, rel=0.02)
    assert (bundle / "figures" / "compaction_trajectory.png").is_file()
    assert len(results["compaction_trajectory"]["fvf_mean"]) >= 2
    assert list(bundle.glob("compaction.checkpoint.*.restart"))


@pytest.mark.lammps
def test_one_and_two_ranks_agree(reference, coarse_manufactured, tmp_path):
    """t@1 kPa and F_N(15-20 deg) of compaction and shear on 2 ranks (Python driver on every rank
    under mpiexec) within 2 % of 1 rank, from the same manufactured cell."""
    folder = copy_run(coarse_manufactured, tmp_path / "run")
    results = read_results(run_scenes(fast_spec(), folder, ["compaction", "shear"], ranks=2))
    for got, want in zip(figures(results), figures(reference), strict=True):
        assert got == pytest.approx(want, rel=0.02)


@pytest.fixture(scope="module")
def killed_and_resumed(tmp_path_factory):
    """Folder of a run killed (SIGKILL) in manufacture's relaxation stage, checked, resumed."""
    tmp_path = tmp_path_factory.mktemp("killed")
    spec_file = tmp_path / "spec.toml"
    write_spec(spec_file, fast_spec())
    folder = tmp_path / "run"
    command = [sys.executable, "-m", "ncf2lammps.cli", "run", str(spec_file), "-o", str(folder)]
    command += ["--scene", "compaction"]
    kill_after_checkpoint(command, tmp_path, folder.name, "manufacture", 100_000)
    with h5py.File(folder / "results.h5") as fh:
        killed = {"complete": bool(fh.attrs["complete"]), "manufacture": "manufacture" in fh}
    killed["summary"] = (folder / "summary.md").exists()
    killed["step"] = checkpoint_step(folder, "manufacture")
    killed["wall_s"] = Checkpoints("manufacture").wall_before(folder)
    out = cli("run", str(spec_file), "-o", str(folder), "--scene", "compaction", "--resume")
    return folder, killed, out


@pytest.mark.lammps
def test_killed_run_is_incomplete_and_resumes_to_a_complete_run(killed_and_resumed):
    """`run` killed in the relaxation stage of manufacture leaves results.h5 marked incomplete
    and no summary; `run --resume` continues from the checkpoint and completes the file, its
    wall time counting the steps run before the kill."""
    folder, killed, out = killed_and_resumed
    assert not killed["complete"] and not killed["manufacture"] and not killed["summary"]
    assert 100_000 <= killed["step"] < 200_000  # the relaxation stage, with its controller state
    assert out.returncode == 0, out.stderr
    results = read_results(folder / "results.h5")
    assert bool(results["attrs"]["complete"]) and (folder / "summary.md").is_file()
    attrs = results["manufacture"]["attrs"]
    assert attrs["resumed"]
    # The steps kept from before the kill count with the wall time their checkpoint recorded.
    assert attrs["wall_before_resume_s"] == killed["wall_s"] > 0
    assert attrs["wall_s"] > attrs["wall_before_resume_s"]


@pytest.mark.lammps
def test_resumed_run_ends_within_1_percent_of_an_unbroken_run(
    killed_and_resumed, reference, coarse_manufactured
):
    """Manufactured thickness and stitch tension, and t@1 kPa of the compaction that follows,
    within 1 % of unbroken runs."""
    folder, _, _ = killed_and_resumed
    results = read_results(folder / "results.h5")
    unbroken = read_results(coarse_manufactured / "results.h5")["manufacture"]["attrs"]
    for key in ("thickness_mm", "stitch_tension_N"):
        assert results["manufacture"]["attrs"][key] == pytest.approx(unbroken[key], rel=0.01)
    key = "thickness_at_1kPa_mm"
    assert results["compaction"]["attrs"][key] == pytest.approx(
        reference["compaction"]["attrs"][key], rel=0.01
    )


def _test_killed_and_resumed(tmp_path_factory, manufactured, spec, scene: str, first_step: int):
    """Folder of a test ``scene`` of ``spec`` (from a copy of the shared manufactured cell)
    killed (SIGKILL) at its first checkpoint at or past ``first_step``, then resumed; and
    whether it was still running when killed."""
    tmp_path = tmp_path_factory.mktemp(f"killed-{scene}")
    folder = copy_run(manufactured, tmp_path / "run")
    spec_file = tmp_path / "spec.toml"
    write_spec(spec_file, spec)
    script = (
        "from ncf2lammps import load_spec, run_scenes\n"
        f"run_scenes(load_spec({str(spec_file)!r}), {str(folder)!r}, [{scene!r}])\n"
    )
    command = [sys.executable, "-c", script]
    running = kill_after_checkpoint(command, tmp_path, folder.name, scene, first_step)
    run_scenes(spec, folder, [scene], resume=True)
    return folder, running


@pytest.fixture(scope="module")
def compaction_killed_and_resumed(tmp_path_factory, coarse_manufactured):
    start = read_results(coarse_manufactured / "results.h5")["manufacture"]["attrs"]["steps"]
    return _test_killed_and_resumed(
        tmp_path_factory, coarse_manufactured, fast_spec(), "compaction", start + 1
    )


def segmented_spec():
    """The fast spec sheared in two segments (to the 22.5 deg snapshot, then to 25 deg), so that
    a kill in the second resumes a deck that defined fix deform twice."""
    return fast_spec().replace(shear={**FAST["shear"], "final_angle_deg": 25.0})


@pytest.fixture(scope="module")
def segmented_shear(tmp_path_factory, coarse_manufactured):
    """Shear results of the two-segment fast shear, unbroken, from the shared manufactured
    cell."""
    folder = copy_run(coarse_manufactured, tmp_path_factory.mktemp("segmented") / "run")
    return read_results(run_scenes(segmented_spec(), folder, ["shear"]))["shear"]


@pytest.fixture(scope="module")
def shear_killed_and_resumed(tmp_path_factory, coarse_manufactured, reference):
    """The two-segment fast shear killed at its first checkpoint in the second segment (its
    steps scaled from the 20 deg run's at the same rate; the shear counts its steps from 0),
    then resumed."""
    steps_per_deg = reference["shear"]["attrs"]["steps"] / FAST["shear"]["final_angle_deg"]
    past_first_segment = int(steps_per_deg * SNAPSHOT_DEG[0]) + 1
    return _test_killed_and_resumed(
        tmp_path_factory,
        coarse_manufactured,
        segmented_spec(),
        "shear",
        past_first_segment,
    )


@pytest.mark.lammps
def test_a_compaction_resumed_mid_run_follows_the_unbroken_one(
    compaction_killed_and_resumed, reference
):
    """A compaction killed between checkpoints resumes with its plates' state (a granular
    wall's contact history and its moving region's last position come back only to walls
    defined before the first run after read_restart; lost, the top plate's first step read its
    whole travel as one step's motion and the cell blew up: kinetic stress ratio 8.4, t@18 kPa
    +10 %): LAMMPS reports no unused restart state, t@1 kPa and t@18 kPa within 1 % of the
    unbroken run, its largest kinetic stress ratio within 2 x the unbroken one's."""
    folder, running = compaction_killed_and_resumed
    assert running
    assert "Unused restart file" not in (folder / "log.compaction.lammps").read_text()
    resumed = read_results(folder / "results.h5")["compaction"]["attrs"]
    unbroken = reference["compaction"]["attrs"]
    assert resumed["resumed"]
    for key in ("thickness_at_1kPa_mm", "thickness_at_18kPa_mm"):
        assert resumed[key] == pytest.approx(unbroken[key], rel=0.01), key
    assert resumed["max_kinetic_stress_ratio"] <= 2.0 * unbroken["max_kinetic_stress_ratio"]


@pytest.mark.lammps
def test_a_shear_resumed_mid_run_follows_the_unbroken_one(
    shear_killed_and_resumed, segmented_shear
):
    """A shear killed in its second segment resumes from the box it had: fix deform keeps its
    start box in the restart file and hands it to every definition before the first run, so
    the deck's start angle g0 must be the journaled one (evaluated afresh, the box jumped back
    to the segment's start and F_N fell from 4.9 to 0.004 N/m). Every recorded box is the
    picture frame's of its angle g, xy = Lb sin g and ly = Lb cos g (docs/design.md), within
    1e-9 Lb; no unused restart state; the angles run on without a gap or a repeat; F_N over the
    last quarter of the angle range within 2 % of the unbroken run (runs that differ by
    round-off scatter by ~1 %, module docstring); the largest kinetic stress ratio within 2 x
    the unbroken one's."""
    folder, running = shear_killed_and_resumed
    assert running
    assert "Unused restart file" not in (folder / "log.shear.lammps").read_text()
    box = np.loadtxt(folder / "shear.box.txt")
    angle, xy, ly = box[:, 1], box[:, 2], box[:, 4]
    side = ly[0] / np.cos(angle[0])
    np.testing.assert_allclose(xy, side * np.sin(angle), rtol=0, atol=1e-9 * side)
    np.testing.assert_allclose(ly, side * np.cos(angle), rtol=0, atol=1e-9 * side)
    resumed = read_results(folder / "results.h5")["shear"]
    assert resumed["attrs"]["resumed"]
    steps = np.diff(resumed["angle_deg"])
    assert np.all(steps > 0) and steps.max() <= 1.5 * np.median(steps)
    assert resumed["angle_deg"][-1] == pytest.approx(segmented_shear["angle_deg"][-1], rel=1e-3)
    force = last_quarter_force(resumed)
    assert force == pytest.approx(last_quarter_force(segmented_shear), rel=0.02)
    ratio = resumed["attrs"]["max_kinetic_stress_ratio"]
    assert ratio <= 2.0 * segmented_shear["attrs"]["max_kinetic_stress_ratio"]


def test_resume_refuses_another_spec_and_bad_ranks(tmp_path):
    """Bad input exits 2 with one line naming the option."""
    spec = str(Path(__file__).parent.parent / "runs" / "mat-only" / "spec.toml")
    out = cli("run", spec, "-o", str(tmp_path / "none"), "--resume")
    assert out.returncode == 2 and "--resume" in out.stderr and out.stderr.count("\n") == 1
    for args in (
        ["run", spec, "-o", str(tmp_path / "a"), "--np", "0"],
        ["export", spec, "-o", str(tmp_path / "b"), "--time", "1 day"],
    ):
        out = cli(*args)
        assert out.returncode == 2 and out.stderr.count("\n") == 1, out.stderr
        assert "Traceback" not in out.stderr
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()


def test_a_checkpoint_interval_rounded_up_to_the_deck_period_is_announced(tmp_path, caplog):
    """A checkpoint interval is rounded up to a multiple of the deck's recording period, so
    that no checkpoint splits an averaging window; when that more than doubles what the spec
    asked for, one warning says which interval the scene uses and why; a smaller rounding, an
    interval already on the period's multiples, or none, passes silently."""
    deck = Deck("manufacture", "", 97_000)
    with caplog.at_level("WARNING"):
        assert checkpoints(tmp_path, deck, 20_000, resume=False).every == 97_000
        assert checkpoints(tmp_path, deck, 60_000, resume=False).every == 97_000
        assert checkpoints(tmp_path, deck, 194_000, resume=False).every == 194_000
        assert checkpoints(tmp_path, deck, 0, resume=False).every == 0
    assert len(caplog.records) == 1
    message = caplog.records[0].getMessage()
    assert "manufacture: checkpoints every 97000 steps, not the 20000 asked" in message
    assert "output.checkpoint_every_steps" in message


def test_a_checkpoint_record_whose_restart_is_gone_is_announced(tmp_path, caplog):
    """A resume whose checkpoint record names a deleted restart file cannot continue from it:
    the scene starts again from its beginning, and one warning names the record."""
    deck = Deck("shear", "", 1_000)
    record = tmp_path / "shear.checkpoint.json"
    restart = {"step": 9, "restart": "shear.checkpoint.9.restart", "line": 5}
    record.write_text(json.dumps({**restart, "stage": "shear", "internal": {}}))
    with caplog.at_level("WARNING"):
        assert not checkpoints(tmp_path, deck, 1_000, resume=True).resume
    assert len(caplog.records) == 1
    assert f"{record} names a restart file that is gone" in caplog.records[0].getMessage()
    (tmp_path / "shear.checkpoint.9.restart").write_text("")
    with caplog.at_level("WARNING"):
        assert checkpoints(tmp_path, deck, 1_000, resume=True).resume
        assert not checkpoints(tmp_path, deck, 1_000, resume=False).resume
    assert len(caplog.records) == 1
