"""Shared fixtures: the committed cases and small factory specs."""

from __future__ import annotations

import fcntl
import functools
import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from MDAnalysis.lib.distances import self_capped_distance

import ncf2lammps.orchestration.run as orchestration_run
from ncf2lammps import load_spec, spec_from_dict
from ncf2lammps.engine import Checkpoints, Engine
from ncf2lammps.engine.journal import strip_comment

ROOT = Path(__file__).resolve().parent.parent

#: Whether the test being set up or run carries the ``lammps`` marker.
_MARKED = [True]


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_setup(item):
    """Before a test's fixtures are made: note whether it may start LAMMPS."""
    _MARKED[0] = item.get_closest_marker("lammps") is not None


def _needs_marker(start):
    """``start`` (a way of starting LAMMPS in this process or a scene's process) fails in a test
    without the ``lammps`` marker, so that every test that starts LAMMPS says so."""

    @functools.wraps(start)
    def guarded(*args, **kwargs):
        if not _MARKED[0]:
            raise AssertionError("this test starts LAMMPS: mark it @pytest.mark.lammps")
        return start(*args, **kwargs)

    return guarded


Engine.__enter__ = _needs_marker(Engine.__enter__)
orchestration_run._execute = _needs_marker(orchestration_run._execute)


#: Test files that go to the pytest-xdist workers first, in this order (``--dist loadfile``: one
#: worker runs a file's tests, in sequence; ``--no-loadscope-reorder``: files go out in
#: collection order): the longest chains of LAMMPS runs start at once and the many short tests
#: fill in around them.
FIRST_FILES = (
    "tests/test_hpc.py",  # first test: the bundle, which needs no shared manufactured cell
    "tests/test_compaction.py",  # first test: makes the shared manufactured cell
    "tests/test_study.py",
    "tests/test_stability.py",
    "tests/test_shear.py",
    "tests/validation/test_validation_cases.py",
    "tests/test_cli.py",
    "tests/test_stitch_rupture.py",
    "tests/test_stitch_interlock.py",
    "tests/test_io_engine.py",
    "tests/test_golden_decks.py",
    "tests/test_doors.py",
    "tests/test_multiaxial.py",
    "tests/test_contact_walls.py",
)


def pytest_collection_modifyitems(config, items):
    """Under pytest-xdist the tests of FIRST_FILES come first; alone, the order is the files'."""
    if os.environ.get("PYTEST_XDIST_WORKER"):
        rank = {name: i for i, name in enumerate(FIRST_FILES)}
        items.sort(key=lambda item: rank.get(item.nodeid.split("::")[0], len(FIRST_FILES)))


#: Lines the pytest-xdist workers left for the closing summary (``summary_lines`` of their
#: ``workeroutput``, e.g. the doors' tally), gathered by the controller.
_SUMMARY_LINES: list[str] = []


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error):
    """pytest-xdist controller: a worker finished; keep the lines it left for the summary."""
    _SUMMARY_LINES.extend(getattr(node, "workeroutput", {}).get("summary_lines", []))


def pytest_terminal_summary(terminalreporter):
    for line in _SUMMARY_LINES:
        terminalreporter.write_line(line)


CASES = (
    "hpt310",
    "hpt310-coarse",
    "mat-only",
    "hpt310-bundle",
    "hpt310-bundle-coarse",
    "pm45-cbx300",
    "pm45-cbx300-coarse",
    "quad-q400",
    "quad-q400-coarse",
)
GOLDEN = ROOT / "tests" / "golden"
UPDATE = os.environ.get("NCF2LAMMPS_UPDATE_GOLDEN") == "1"


def compare_or_update(produced: dict[str, str], folder: Path) -> None:
    """Assert that ``produced`` ({relative name: text}) equals the files under ``folder``
    (both ways: no file missing, none extra); with ``NCF2LAMMPS_UPDATE_GOLDEN=1`` write them."""
    if UPDATE:
        for name, text in produced.items():
            (folder / name).parent.mkdir(parents=True, exist_ok=True)
            (folder / name).write_text(text)
        return
    stored = {str(p.relative_to(folder)): p.read_text() for p in folder.rglob("*") if p.is_file()}
    assert sorted(produced) == sorted(stored), f"golden files of {folder.name} differ in names"
    for name, text in produced.items():
        assert text == stored[name], f"{folder.name}/{name} differs from its golden file"


def case_spec(name: str):
    """The committed spec of ``runs/<name>``."""
    return load_spec(ROOT / "runs" / name / "spec.toml")


def tiny_spec(**tables):
    """A small stitched 0/90 cell (chains 250 um, one stitch repeat) with table overrides."""
    data = {
        "fabric": {"name": "tiny"},
        "ply": [{"angle_deg": 90.0}, {"angle_deg": 0.0}],
        "stitch": {"pattern": "tricot-chain", "needle_diameter_mm": 0.8},
        "discretisation": {"chain_diameter_um": 250.0},
    }
    for key, value in tables.items():
        if value is None:
            data.pop(key, None)
        elif isinstance(value, dict) and isinstance(data.get(key), dict):
            data[key] = {**data[key], **value}
        else:
            data[key] = value
    return spec_from_dict(data)


def frictionless_mat_spec(final_angle_deg: float, **tables):
    """A 2 x 2 mm unstitched mat of frictionless chains pretensioned at 22 N/m, sheared in both
    senses at 0.2 deg/us to ``final_angle_deg``: the picture frame's zero-force identity."""
    shear = {
        "final_angle_deg": final_angle_deg,
        "fibre_pretension_N_m": 22.0,
        "shear_rate_deg_us": 0.2,
        "senses": ["positive", "negative"],
    }
    return tiny_spec(
        stitch=None,
        cell={"length_mm": 2.0, "width_mm": 2.0},
        contact={"friction": 0.0},
        shear=shear,
        **tables,
    )


def closest_pairs(positions: np.ndarray, box_lengths: np.ndarray, cutoff: float):
    """Pairs (i, j) and distances of beads closer than ``cutoff``, periodic in x and y only."""
    shifted = positions - positions.min(axis=0) * np.array([0, 0, 1])
    lz = 10.0 * (np.ptp(positions[:, 2]) + cutoff + 1.0)
    box = np.array([box_lengths[0], box_lengths[1], lz, 90.0, 90.0, 90.0], dtype=np.float32)
    pairs, distances = self_capped_distance(shifted.astype(np.float64), cutoff, box=box)
    return pairs, distances


def bond_lengths(model):
    """Minimum-image bond lengths (um), (n_bonds,) float."""
    delta = model.positions[model.bonds[:, 1]] - model.positions[model.bonds[:, 0]]
    lengths = model.box.lengths
    delta[:, :2] -= np.rint(delta[:, :2] / lengths[:2]) * lengths[:2]
    return np.linalg.norm(delta, axis=1)


def assert_model_invariants(spec, model):
    """The generation invariants of every valid spec: fibre areal weight and mat Vf equal the
    spec's (1e-9 relative: the chain diameter conserves fibre volume), every bond at its rest
    length (1e-9), two bonds per bead (closed chains), no two fibre beads of different chains
    closer than 0.99 of their contact distance (periodic images included)."""
    expected = sum(p.areal_weight_g_m2 for p in spec.plies)
    assert model.areal_weight("fibre") == pytest.approx(expected, rel=1e-9)
    assert model.fvf(model.mat_thickness) == pytest.approx(spec.mat.initial_fvf, rel=1e-9)
    r0 = np.array([t.r0 for t in model.bond_types])[model.bond_type]
    np.testing.assert_allclose(bond_lengths(model), r0, rtol=1e-9)
    counts = np.bincount(model.bonds.ravel(), minlength=model.n_atoms)
    assert np.array_equal(counts, np.full(model.n_atoms, 2))
    fibre = model.role_mask("fibre")
    pairs, distances = closest_pairs(model.positions, model.box.lengths, model.diameter.max())
    keep = (model.mol_id[pairs[:, 0]] != model.mol_id[pairs[:, 1]]) & fibre[pairs].all(axis=1)
    contact = 0.5 * model.diameter[pairs].sum(axis=1)
    assert np.all(distances[keep] >= 0.99 * contact[keep])


#: Values made once per test run and shared by the tests that ask for them.
_ONCE: dict[str, object] = {}


@pytest.fixture(scope="module")
def case_models():
    """{case: (spec, model)} of the three committed cases, built once per test run."""
    from ncf2lammps import build_model

    if "case_models" not in _ONCE:
        _ONCE["case_models"] = {n: (case_spec(n), build_model(case_spec(n))) for n in CASES}
    return _ONCE["case_models"]


def shared_folder(tmp_path_factory, name: str, make: Callable[[Path], object]) -> Path:
    """Folder ``name`` of this test run, made once by ``make(folder)`` and shared by every test
    and every pytest-xdist worker that asks for it.

    The first process to ask makes it while it holds a lock; the others wait for it and then
    reuse it (read it, or copy it with :func:`copy_run`; never write into it). A folder whose
    making failed is not made again: later askers fail with the first error's message.
    """
    root = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        root = root.parent  # the workers' base folders sit side by side in the run's own one
    root = root / "shared"
    root.mkdir(exist_ok=True)
    folder, done, failed = (root / name, root / f"{name}.done", root / f"{name}.failed")
    with open(root / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if failed.exists():
            raise RuntimeError(f"{name}: making it failed before: {failed.read_text()}")
        if not done.exists():
            shutil.rmtree(folder, ignore_errors=True)
            try:
                make(folder)
            except BaseException as err:
                failed.write_text(f"{type(err).__name__}: {err}")
                raise
            done.touch()
    return folder


@pytest.fixture(scope="module")
def coarse_manufactured(tmp_path_factory):
    """Folder of the coarse case after ``run --scene manufacture`` (run once per test run).

    Tests that run further scenes copy it (:func:`copy_run`) so that each starts from the same
    manufactured state.
    """
    from ncf2lammps import run

    def manufacture(folder):
        run(case_spec("hpt310-coarse"), folder, scenes=["manufacture"])

    return shared_folder(tmp_path_factory, "coarse-manufactured", manufacture)


def checkpoint_step(folder: Path, deck: str) -> int:
    """Step of the last checkpoint of ``deck`` in ``folder``; -1 before the first."""
    state = Checkpoints(deck).state(folder)
    return -1 if state is None else state["step"]


def kill_after_checkpoint(
    command: list[str], root: Path, pattern: str, deck: str, step: int = 1
) -> bool:
    """Start ``command`` and SIGKILL it once ``deck`` has a checkpoint at or past ``step`` in a
    folder matching ``pattern`` under ``root`` (at most 600 s); returns whether it was still
    running when killed."""
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 600
    while process.poll() is None and not any(
        checkpoint_step(path, deck) >= step for path in root.glob(pattern)
    ):
        assert time.monotonic() < deadline
        time.sleep(0.1)
    running = process.poll() is None
    process.send_signal(signal.SIGKILL)
    process.wait()
    return running


def run_lammps_file(folder: Path, deck: str) -> None:
    """Run the LAMMPS input ``deck`` in ``folder`` in a fresh process, as the orchestration runs
    each scene: a second LAMMPS instance in one process can follow another trajectory from the
    same restart file (measured on the coarse compaction deck, first records onwards)."""
    script = "from ncf2lammps.engine import Engine\nwith Engine(log=None) as e:\n    e.file({!r})\n"
    subprocess.run(
        [sys.executable, "-c", script.format(deck)], cwd=folder, check=True, capture_output=True
    )


def deck_commands(path: Path) -> list[str]:
    """The commands of the LAMMPS deck at ``path``: comments cut as the driver cuts them, blank
    lines and trajectory dumps left out."""
    commands = (strip_comment(line) for line in path.read_text().splitlines())
    return [line for line in commands if line and not line.startswith("dump")]


def copy_run(folder: Path, destination: Path) -> Path:
    """A copy of a run folder to run more scenes in."""
    shutil.copytree(folder, destination)
    return destination


def assert_loading_follows_its_law(records: dict, coordinate: str, control, dt: float, sign: int):
    """The recorded loading of a test scene follows templates/loading.lmp.j2.

    ``records`` (read_ave_time of the scene's records at the end of each control interval) hold
    the loaded ``coordinate`` column, the rate ``v_load_rate``, the interval's mean stress S
    ``v_load_stress_mean`` (floored at the reference pressure) and kinetic stress ratio Q
    ``v_load_kinetic_ratio``; ``control`` is the scene's LoadingControl, ``dt`` (us), ``sign``
    the direction the rate moves the coordinate. Laws, to rounding:
    - adaptive: the rate after each interval is ``clamp(r clamp(min(r_I sqrt(S / S_ref) / r,
      sqrt(Q* / Q)), down, up), r_I, r_max)`` of the rate r before it; constant: it stays r_I;
    - the coordinate advances every step by the rate of that step: an interval of ``every``
      steps moves it by ``dt ((every - 1) r_before + r_after)`` (the rate changes at the
      interval's last step, before that step's advance).
    """
    rate = records["v_load_rate"]
    stress, ratio = records["v_load_stress_mean"][1:], records["v_load_kinetic_ratio"][1:]
    before, after = rate[:-1], rate[1:]
    if control.adaptive:
        hold = control.rate * np.sqrt(stress / control.floor) / before
        brake = np.sqrt(control.kinetic_target / (ratio + 1e-30))
        gain = np.clip(np.minimum(hold, brake), control.down, control.up)
        expected = np.clip(before * gain, control.rate, control.rate_max)
    else:
        expected = np.full_like(before, control.rate)
    np.testing.assert_allclose(after, expected, rtol=1e-9)
    travel = sign * np.diff(records[coordinate])
    np.testing.assert_allclose(
        travel,
        dt * ((control.every - 1) * before + after),
        rtol=1e-6,
        atol=1e-12 * np.abs(records[coordinate]).max(),
    )
