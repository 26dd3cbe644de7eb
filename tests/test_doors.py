"""The doors: every verb with missing, empty, corrupt and truncated files and folders, bad options
and spec values just outside their ranges exits 2 with one line on stderr (or succeeds), never a
traceback or a signal. Nothing here starts a LAMMPS run: a door that would is given inputs that
fail first, or a finished run to resume (nothing left to run).

The CLI runs in-process (``ncf2lammps.cli.main``); a few cases run as subprocesses for the exit
code and the absence of a traceback. The tally (cases, refused, succeeded, crashed) is printed at
the end of the module and crashed must be 0.
"""

from __future__ import annotations

import dataclasses
import json
import os
import shutil
import subprocess
import sys
from collections import Counter
from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import ROOT, case_spec

from ncf2lammps import build_model, load_spec
from ncf2lammps.cli import main
from ncf2lammps.geometry.size import MAX_BEADS, model_size
from ncf2lammps.io.results import mark_complete, write_root, write_scene
from ncf2lammps.io.spectoml import _value, dumps_spec, write_spec
from ncf2lammps.orchestration.build import build
from ncf2lammps.spec import _TABLES, PlySpec, SpecError

TALLY: Counter = Counter()


@pytest.fixture(scope="module", autouse=True)
def tally(request):
    """Print the tally at the end of the module (under pytest-xdist, in the closing summary); no
    door may crash."""
    yield
    line = (
        f"doors: {sum(TALLY.values())} cases, {TALLY['refused']} refused, {TALLY['succeeded']}"
        f" succeeded, {TALLY['crashed']} crashed"
    )
    plugins = request.config.pluginmanager
    reporter, capture = plugins.get_plugin("terminalreporter"), plugins.get_plugin("capturemanager")
    if hasattr(request.config, "workeroutput"):  # a pytest-xdist worker: the controller prints it
        request.config.workeroutput.setdefault("summary_lines", []).append(line)
    elif reporter is not None and capture is not None:
        with capture.global_and_fixture_disabled():  # past the capture, like capsys.disabled()
            reporter.write_line("")
            reporter.write_line(line)
    assert TALLY["crashed"] == 0


def door(capsys, *argv, succeed=False):
    """Run the CLI in-process; record and return (outcome, stderr). Refused: exit 2 with exactly
    one line on stderr; succeeded: exit 0; anything else (a traceback, other codes) crashed."""
    argv = [str(a) for a in argv]
    try:
        code = main(argv)
    except SystemExit as stop:
        code = stop.code
    except BaseException as err:  # a crash is what this test looks for
        capsys.readouterr()
        TALLY["crashed"] += 1
        pytest.fail(f"{argv}: raised {type(err).__name__}: {err}")
    err = capsys.readouterr().err
    lines = err.splitlines()
    if code == 0:
        outcome = "succeeded"
    elif code == 2 and len(lines) == 1 and "Traceback" not in err:
        outcome = "refused"
    else:
        outcome = "crashed"
    TALLY[outcome] += 1
    expected = "succeeded" if succeed else "refused"
    assert outcome == expected, f"{argv}: exit {code}, stderr {err!r}"
    return outcome, err


# -- specs and folders ---------------------------------------------------------------------------


def fast_spec():
    """The mat-only case (3042 beads): small, no stitch; finished runs of it are faked."""
    return case_spec("mat-only")


@pytest.fixture(scope="module")
def place(tmp_path_factory):
    """Spec files and run folders of every kind (no LAMMPS: results.h5 written by the same
    functions a run uses, with a compaction group of the real names)."""
    root = tmp_path_factory.mktemp("doors")
    spec = fast_spec()
    files = {"spec": write_spec(root / "spec.toml", spec)}
    other = spec.replace(discretisation={"chain_diameter_um": 120.0})
    files["other_spec"] = write_spec(root / "other.toml", other)
    (root / "empty.toml").write_text("")
    (root / "comments.toml").write_text("# nothing but a comment\n\n")
    (root / "random.toml").write_bytes(np.random.default_rng(1).bytes(2000))
    (root / "latin1.toml").write_bytes(b'[fabric]\nname = "caf\xe9"\n')
    (root / "not-toml.toml").write_text("this is not = = toml [\n")
    (root / "huge.toml").write_text("# " + "x" * 1_100_000 + "\n")
    (root / "deep.toml").write_text("x = " + "[" * 1000 + "]" * 1000 + "\n")  # 2 kB, too deep
    (root / "spec-dir").mkdir()
    shutil.copy(files["spec"], root / "spec-dir" / "spec.toml")
    files.update(
        {
            name: root / f"{name}.toml"
            for name in ("empty", "comments", "random", "latin1", "not-toml", "huge", "deep")
        }
    )
    files["spec_dir"] = root / "spec-dir"
    files["missing"] = root / "no-such.toml"

    built = build(spec, root / "built")
    folders = {"built": built.directory}

    def run_folder(name, scenes=("compaction",), complete=True):
        folder = root / name
        shutil.copytree(built.directory, folder)
        results = folder / "results.h5"
        write_root(
            results,
            {
                "ncf2lammps_version": "0",
                "lammps_version": "unknown",
                "spec_toml": dumps_spec(spec),
                "n_atoms": built.model.n_atoms,
                "n_bonds": built.model.n_bonds,
                "mpi_ranks": 1,
                "created": "2024-01-01T00:00:00+00:00",
                "dt_us": built.time_step.dt,
                "dt_critical_us": built.time_step.critical,
                "dt_governing": built.time_step.governing,
                "dt_margin": built.time_step.margin,
            },
        )
        gap = np.linspace(0.8, 0.4, 50)
        for scene in scenes:
            write_scene(
                results,
                scene,
                {
                    "thickness_at_1kPa_mm": 0.6,
                    "thickness_at_18kPa_mm": float("nan"),
                    "plate_speed_m_s": 2.0,
                    "steps": 1000,
                    "wall_s": 1.0,
                },
                {
                    "gap_mm": gap,
                    "pressure_kPa": 1.0 / gap**4,
                    "pressure_smoothed_kPa": 1.0 / gap**4,
                    "fvf": 0.3 * 0.8 / gap,
                    "time_us": np.arange(50.0),
                },
            )
        if complete:
            mark_complete(results)
        return folder

    folders["finished"] = run_folder("finished")  # like `run --scene compaction`
    folders["killed"] = run_folder("killed", scenes=("compaction",), complete=False)
    (folders["killed"] / "shear.lammpstrj").write_text("ITEM: TIMESTEP\n100\nITEM: NUMBER OF")
    folders["killed_early"] = run_folder("killed-early", scenes=(), complete=False)
    good = (folders["finished"] / "results.h5").read_bytes()
    for name, content in {
        "h5_empty": b"",
        "h5_random": np.random.default_rng(2).bytes(len(good)),
        "h5_truncated": good[: len(good) // 2],
        "h5_header": good[:512],
        "h5_tail_lost": good[:-100],
    }.items():
        folder = root / name
        shutil.copytree(folders["finished"], folder)
        (folder / "results.h5").write_bytes(content)
        folders[name] = folder
    folders["h5_foreign"] = root / "h5-foreign"
    shutil.copytree(folders["finished"], folders["h5_foreign"])
    with h5py.File(folders["h5_foreign"] / "results.h5", "w") as fh:
        fh["data"] = np.arange(3.0)
    folders["h5_dir"] = root / "h5-dir"
    shutil.copytree(built.directory, folders["h5_dir"])
    (folders["h5_dir"] / "results.h5").mkdir()
    folders.update(_damaged_folders(root, folders))
    folders["empty"] = root / "empty"
    folders["empty"].mkdir()
    folders["stranger"] = root / "stranger"
    folders["stranger"].mkdir()
    (folders["stranger"] / "notes.txt").write_text("not a run")
    folders["partial"] = root / "run.partial-12345"
    shutil.copytree(built.directory, folders["partial"])
    folders["study"] = root / "study"
    (folders["study"] / "points" / "p00").mkdir(parents=True)
    folders["no_model"] = root / "no-model"
    shutil.copytree(folders["killed"], folders["no_model"])
    (folders["no_model"] / "model.data").unlink()
    folders["missing"] = root / "no-such-folder"
    folders["a_file"] = root / "a-file"
    folders["a_file"].write_text("x")
    return root, files, folders


def _damaged_folders(root: Path, folders: dict) -> dict:
    """Run folders whose results.h5, checkpoint or layout a hand (or a disk) damaged."""
    made = {}

    def copy(name: str, of: str) -> Path:
        made[name] = root / name.replace("_", "-")
        shutil.copytree(folders[of], made[name])
        return made[name]

    with h5py.File(copy("h5_2d", "finished") / "results.h5", "a") as fh:
        del fh["compaction/gap_mm"]
        fh["compaction/gap_mm"] = np.ones((50, 2))
    with h5py.File(copy("h5_text_complete", "finished") / "results.h5", "a") as fh:
        fh.attrs["complete"] = "False"  # read as true, a killed run would look finished
    with h5py.File(copy("h5_no_gap", "finished") / "results.h5", "a") as fh:
        del fh["compaction/gap_mm"]
    (copy("figures_file", "finished") / "figures").write_text("x")
    (copy("checkpoint_damaged", "killed") / "compaction.checkpoint.json").write_text("{not json")
    record = {"step": 100, "restart": "compaction.checkpoint.100.restart", "line": 5}
    folder = copy("checkpoint_no_journal", "killed")
    (folder / "compaction.checkpoint.json").write_text(
        json.dumps({**record, "stage": "compaction", "internal": {}})
    )
    (folder / record["restart"]).write_text("")
    folder = copy("decks_file", "killed")
    shutil.rmtree(folder / "decks")
    (folder / "decks").write_text("x")
    return made


# -- spec files ----------------------------------------------------------------------------------

SPEC_FILES = (
    "missing",
    "spec_dir",
    "empty",
    "comments",
    "random",
    "latin1",
    "not-toml",
    "huge",
    "deep",
)


@pytest.mark.parametrize("name", SPEC_FILES)
@pytest.mark.parametrize("verb", ["check", "build", "run", "export", "study"])
def test_bad_spec_files_are_refused_by_every_verb(capsys, place, verb, name):
    root, files, _ = place
    argv = [verb, files[name]]
    if verb != "check":
        argv += ["-o", root / f"out-{verb}-{name}"]
    if verb == "study":
        argv += ["--vary", "numerics.dt_fraction=0.5,0.4"]
    _, err = door(capsys, *argv)
    assert str(files[name]) in err
    assert not (root / f"out-{verb}-{name}").exists()


def test_dev_null_is_not_a_spec(capsys):
    door(capsys, "check", os.devnull)


# -- spec values just outside their ranges -------------------------------------------------------


def _outside(f: dataclasses.Field) -> list:
    """Values just outside a field's declaration (or of the wrong kind)."""
    meta, default = f.metadata, f.default
    if isinstance(default, bool):
        return ["yes"]
    if isinstance(default, str):
        return ["no-such-choice"] if meta["choices"] else ["x" * 201]
    if meta["choices"] is not None:
        return [45.0]
    values = ["1.0"]  # a string where a number belongs
    integer = isinstance(default, int)
    for bound, sign, is_open in (
        (meta["lo"], -1, meta["lo_open"]),
        (meta["hi"], 1, meta["hi_open"]),
    ):
        if bound is None:
            continue
        if is_open:
            values.append(bound)
        elif integer:
            values.append(bound + sign)
        else:
            values.append(bound + sign * max(abs(bound), 1.0) * 1e-3)
    if integer:
        values.append(1.5)
    return values


def _toml(data: dict) -> str:
    lines = []
    for key, table in data.items():
        for row in table if isinstance(table, list) else [table]:
            lines.append(f"[[{key}]]" if isinstance(table, list) else f"[{key}]")
            lines += [f"{name} = {_value(v)}" for name, v in row.items()]
    return "\n".join(lines) + "\n"


def _value_cases():
    base = case_spec("hpt310-coarse").to_dict()
    cases = []
    tables = {"ply": PlySpec, **_TABLES}
    for table, cls in tables.items():
        for f in dataclasses.fields(cls):
            if f.name == "lapping":
                continue  # free text, checked by its notation (tests/test_spec.py)
            for value in _outside(f):
                path = f"ply[0].{f.name}" if table == "ply" else f"{table}.{f.name}"
                cases.append(pytest.param(table, f.name, value, id=f"{path}={value!r}"[:60]))
    return base, cases


BASE, VALUE_CASES = _value_cases()


@pytest.mark.parametrize(("table", "name", "value"), VALUE_CASES)
def test_values_just_outside_their_range_are_refused(capsys, tmp_path, table, name, value):
    data = {k: ([dict(r) for r in v] if isinstance(v, list) else dict(v)) for k, v in BASE.items()}
    if table == "ply":
        data["ply"][0][name] = value
    else:
        data[table][name] = value
    path = tmp_path / "spec.toml"
    path.write_text(_toml(data))
    _, err = door(capsys, "check", path)
    assert name in err


# -- run folders ---------------------------------------------------------------------------------

REFUSED_BY_REPORT = (
    "missing",
    "a_file",
    "empty",
    "stranger",
    "partial",
    "study",
    "built",
    "killed_early",
    "h5_empty",
    "h5_random",
    "h5_truncated",
    "h5_header",
    "h5_tail_lost",
    "h5_foreign",
    "h5_dir",
    "h5_2d",
    "h5_text_complete",
)


def test_a_final_fvf_reached_before_the_plates_move_is_refused(capsys, tmp_path):
    """A compaction.final_fvf at or below the Vf at which the plates start would give a
    compaction of no step: check and build refuse it, naming the Vf to exceed."""
    data = fast_spec().to_dict()
    data["compaction"].update(end="final_fvf", final_fvf=0.2)  # the mat starts at Vf 0.3
    spec_file = tmp_path / "spec.toml"
    spec_file.write_text(_toml(data))
    for argv in (["check", spec_file], ["build", spec_file, "-o", tmp_path / "out"]):
        _, err = door(capsys, *argv)
        assert err.startswith("ncf2lammps: error: compaction.final_fvf = 0.2") and "above" in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("name", REFUSED_BY_REPORT)
def test_report_refuses_what_is_not_a_reportable_run(capsys, place, name):
    _, _, folders = place
    _, err = door(capsys, "report", folders[name])
    assert str(folders[name]) in err
    assert not (folders[name] / "summary.md").exists()


@pytest.mark.parametrize("name", [*REFUSED_BY_REPORT, "no_model"])
def test_resume_refuses_what_cannot_be_resumed(capsys, place, name):
    _, files, folders = place
    if name == "killed_early":
        pytest.skip("resumable: it would start LAMMPS (tests/test_hpc.py resumes a killed run)")
    _, err = door(capsys, "run", files["spec"], "-o", folders[name], "--resume")
    assert "--resume" in err


@pytest.mark.parametrize("name", ["h5_no_gap", "figures_file"])
def test_report_refuses_a_run_missing_what_its_scenes_write(capsys, place, name):
    _, _, folders = place
    _, err = door(capsys, "report", folders[name])
    assert str(folders[name]) in err
    assert not (folders[name] / "summary.md").exists()


@pytest.mark.parametrize("name", ["checkpoint_damaged", "checkpoint_no_journal", "decks_file"])
def test_resume_refuses_a_damaged_checkpoint_or_layout(capsys, place, name):
    _, files, folders = place
    _, err = door(capsys, "run", files["spec"], "-o", folders[name], "--resume")
    assert "--resume" in err and "cannot be resumed" in err


def test_resume_refuses_another_spec(capsys, place):
    _, files, folders = place
    _, err = door(capsys, "run", files["other_spec"], "-o", folders["finished"], "--resume")
    assert "another spec" in err


def test_report_of_a_killed_run_reports_what_it_has(capsys, place):
    _, _, folders = place
    door(capsys, "report", folders["killed"], succeed=True)
    summary = (folders["killed"] / "summary.md").read_text()
    assert "complete: False" in summary and "**Incomplete run**" in summary
    assert "(compaction), not shear" in summary and "--resume" in summary


def test_report_and_resume_of_a_finished_run_succeed(capsys, place, tmp_path):
    _, files, folders = place
    door(capsys, "report", folders["finished"], succeed=True)
    assert "Incomplete" not in (folders["finished"] / "summary.md").read_text()
    folder = shutil.copytree(folders["killed"], tmp_path / "killed")
    # Everything asked for is finished: resume has nothing left to run, and completes the file.
    door(
        capsys,
        "run",
        files["spec"],
        "-o",
        folder,
        "--resume",
        "--scene",
        "compaction",
        succeed=True,
    )


@pytest.mark.parametrize("verb", ["build", "run", "export"])
@pytest.mark.parametrize("name", ["finished", "killed", "built", "stranger", "a_file"])
def test_writers_refuse_an_existing_output(capsys, place, verb, name):
    _, files, folders = place
    _, err = door(capsys, verb, files["spec"], "-o", folders[name])
    if name == "killed" and verb == "run":
        assert "--resume" in err


@pytest.mark.parametrize("verb", ["build", "run", "export"])
def test_force_does_not_replace_a_file(capsys, place, verb):
    _, files, folders = place
    door(capsys, verb, files["spec"], "-o", folders["a_file"], "--force")
    assert folders["a_file"].read_text() == "x"


@pytest.mark.parametrize("verb", ["build", "run", "export"])
def test_force_replaces_only_an_ncf2lammps_folder(capsys, place, verb):
    """--force replaces a run, build or export folder (one holding spec.resolved.toml), never a
    folder of other files: a mistyped -o does not delete it."""
    _, files, folders = place
    _, err = door(capsys, verb, files["spec"], "-o", folders["stranger"], "--force")
    assert "no ncf2lammps output" in err
    assert [p.name for p in folders["stranger"].iterdir()] == ["notes.txt"]


@pytest.mark.parametrize("verb", ["build", "run", "export"])
def test_the_current_folder_is_not_an_output(capsys, place, tmp_path, monkeypatch, verb):
    """A folder built elsewhere and renamed into place cannot be the current folder or one that
    holds it (the shell would be left in a deleted folder; --force would delete the parent)."""
    _, files, _ = place
    here = tmp_path / "here"
    here.mkdir()
    monkeypatch.chdir(here)
    for target, force in ((".", ()), ("./", ("--force",)), ("..", ("--force",))):
        _, err = door(capsys, verb, files["spec"], "-o", target, *force)
        assert "current folder" in err
    assert not any(here.iterdir()) and [p.name for p in tmp_path.iterdir()] == ["here"]


def test_a_relative_output_in_a_deleted_current_folder_is_refused(
    capsys, place, tmp_path, monkeypatch
):
    """The shell's folder deleted under it: a relative -o is refused in one line, an absolute
    one is built."""
    _, files, _ = place
    gone = tmp_path / "gone"
    gone.mkdir()
    monkeypatch.chdir(gone)
    gone.rmdir()
    _, err = door(capsys, "build", files["spec"], "-o", "out")
    assert "current folder that is gone" in err
    door(capsys, "build", files["spec"], "-o", tmp_path / "out", succeed=True)


def _unwritable(root: Path) -> list[Path]:
    """Places -o cannot be made in: below a file, in /sys; a read-only folder unless root."""
    places = [root / "a-file" / "sub"]
    if Path("/sys").is_dir():
        places.append(Path("/sys/ncf2lammps-doors/out"))
    if os.geteuid() != 0:
        locked = root / "locked"
        locked.mkdir(exist_ok=True)
        locked.chmod(0o500)
        places.append(locked / "out")
    return places


@pytest.mark.parametrize("verb", ["build", "run", "export", "study", "validate"])
def test_output_in_an_unwritable_place_is_refused(capsys, place, verb):
    root, files, _ = place
    for target in _unwritable(root):
        if verb == "validate":
            argv = ["validate", "-o", target, "--case", "hertz"]
        else:
            argv = [verb, files["spec"], "-o", target]
        if verb == "study":
            argv += ["--vary", "numerics.dt_fraction=0.5,0.4"]
        door(capsys, *argv)
        assert not target.exists()


def test_study_refuses_a_run_folder_and_a_file(capsys, place):
    _, files, folders = place
    for name in ("finished", "a_file"):
        door(
            capsys,
            "study",
            files["spec"],
            "-o",
            folders[name],
            "--vary",
            "numerics.dt_fraction=0.5",
        )


def test_validate_refuses_a_file_and_an_unknown_case(capsys, place, tmp_path):
    _, _, folders = place
    door(capsys, "validate", "-o", folders["a_file"])
    door(capsys, "validate", "-o", tmp_path / "v", "--case", "no-such-case")


# -- options -------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "args",
    [
        ["run", "{spec}", "-o", "{new}", "--np", "0"],
        ["run", "{spec}", "-o", "{new}", "--np", "-3"],
        ["run", "{spec}", "-o", "{new}", "--np", "abc"],
        ["run", "{spec}", "-o", "{new}", "--np", "100000"],
        ["run", "{spec}", "-o", "{new}", "--scene", "no-such-scene"],
        ["run", "{spec}", "-o", "{new}", "--scene", "manufacture"],  # no stitch in mat-only
        ["export", "{spec}", "-o", "{new}", "--np", "0"],
        ["export", "{spec}", "-o", "{new}", "--time", "1 day"],
        ["export", "{spec}", "-o", "{new}", "--time", "24:00"],
        ["export", "{spec}", "-o", "{new}", "--time", "24:00:00\n"],
        ["export", "{spec}", "-o", "{new}", "--time", "0:00:00"],
        ["export", "{spec}", "-o", "{new}", "--time", "366-00:00:00"],
        ["export", "{spec}", "-o", "{new}", "--time", "\uff11\uff12:00:00"],  # full-width 12
        ["export", "{spec}", "-o", "{new}", "--module", "m" * 101],
        ["export", "{spec}", "-o", "{new}", "--time", "1:60:00"],
        ["export", "{spec}", "-o", "{new}", "--time", ""],
        ["export", "{spec}", "-o", "{new}", "--module", "gcc\nrm -rf /"],
        ["export", "{spec}", "-o", "{new}", "--module", "../x"],
        ["study", "{spec}", "-o", "{new}"],
        ["study", "{spec}", "-o", "{new}", "--vary", ""],
        ["study", "{spec}", "-o", "{new}", "--vary", "="],
        ["study", "{spec}", "-o", "{new}", "--vary", "numerics.dt_fraction"],
        ["study", "{spec}", "-o", "{new}", "--vary", "no.such=1,2"],
        ["study", "{spec}", "-o", "{new}", "--vary", "numerics.dt_fraction="],
        ["study", "{spec}", "-o", "{new}", "--vary", "numerics.dt_fraction=abc"],
        ["study", "{spec}", "-o", "{new}", "--vary", "numerics.dt_fraction=[1]"],
        ["study", "{spec}", "-o", "{new}", "--vary", "numerics.dt_fraction=nan"],
        ["study", "{spec}", "-o", "{new}", "--vary", "numerics.dt_fraction=0.5,9"],
        ["study", "{spec}", "-o", "{new}", "--vary", "numerics.dt_fraction=1979-05-27"],
        ["study", "{spec}", "-o", "{new}", "--vary", "numerics.dt_fraction=0.5,,0.4"],
        # in range, but above the stable time step: refused by the point's build check
        ["study", "{spec}", "-o", "{new}", "--vary", "numerics.dt_fraction=0.5,1.5"],
        ["build", "{spec}", "-o", "{new}/" + "x" * 300],
        [
            "study",
            "{spec}",
            "-o",
            "{new}",
            "--vary",
            "mat.initial_fvf=0.3,0.2",
            "--vary",
            "mat.initial_fvf=0.25",
        ],
        [
            "study",
            "{spec}",
            "-o",
            "{new}",
            "--zip",
            "--vary",
            "mat.initial_fvf=0.3,0.2",
            "--vary",
            "numerics.dt_fraction=0.5",
        ],
        ["study", "{spec}", "-o", "{new}", "--vary", "numerics.dt_fraction=0.5", "--np", "0"],
        [
            "study",
            "{spec}",
            "-o",
            "{new}",
            "--vary",
            "numerics.dt_fraction=0.5",
            "--tolerance",
            "2",
        ],
        [
            "study",
            "{spec}",
            "-o",
            "{new}",
            "--vary",
            "numerics.dt_fraction=0.5",
            "--tolerance",
            "nan",
        ],
        ["study", "{spec}", "-o", "{new}", "--vary", "numerics.dt_fraction=0.5", "--scene", "x"],
        ["build", "{spec}"],
        ["report"],
        ["no-such-verb"],
        [],
        ["check", "{spec}", "--no-such-option"],
    ],
    ids=lambda a: " ".join(a)[:50],
)
def test_bad_options_are_refused_before_anything_is_written(capsys, place, tmp_path, args):
    _, files, _ = place
    new = tmp_path / "new"
    door(capsys, *[a.format(spec=files["spec"], new=new) for a in args])
    assert not new.exists()


def test_good_doors_succeed(capsys, place, tmp_path):
    _, files, _ = place
    door(capsys, "check", files["spec"], succeed=True)
    door(capsys, "build", files["spec"], "-o", tmp_path / "b", succeed=True)
    door(capsys, "export", files["spec"], "-o", tmp_path / "e", succeed=True)
    door(capsys, "build", files["spec"], "-o", tmp_path / "b", "--force", succeed=True)
    door(capsys, "build", files["spec"], "-o", tmp_path / "n" / "sub" / "..", succeed=True)
    assert (tmp_path / "n" / "model.data").is_file() and not (tmp_path / "n" / "sub").exists()


# -- the size of a model, known before it is built -----------------------------------------------

REAL_BEADS = {"hpt310": 73_834, "hpt310-coarse": 3_424, "mat-only": 3_042}


@pytest.mark.parametrize("case", REAL_BEADS)
def test_size_estimate_bounds_the_committed_cases(case):
    estimate = model_size(case_spec(case)).beads
    assert REAL_BEADS[case] <= estimate <= 1.15 * REAL_BEADS[case]


@pytest.mark.parametrize(
    ("tables", "factor"),
    [
        ({"discretisation": {"chain_diameter_um": 120.0, "bead_spacing_ratio": 0.2}}, 1.15),
        ({"discretisation": {"chain_diameter_um": 250.0, "bead_spacing_ratio": 1.0}}, 1.15),
        ({"mat": {"initial_fvf": 0.2}}, 1.15),
        ({"stitch": {"pattern": "tricot"}}, 1.15),
        ({"cell": {"length_mm": 22.4, "width_mm": 10.16}}, 1.15),
        (
            {
                "discretisation": {"chain_diameter_um": 150.0},
                "mat": {"waviness_amplitude_um": 20.0},
            },
            1.5,
        ),
        (
            {
                "discretisation": {"chain_diameter_um": 150.0},
                "mat": {"waviness_amplitude_um": 20.0, "waviness_waves_per_cell": 2},
            },
            1.5,
        ),
        (
            {
                "discretisation": {"chain_diameter_um": 150.0},
                "mat": {"waviness_amplitude_um": 30.0, "waviness_plane": "out-of-plane"},
            },
            1.5,
        ),
    ],
)
def test_size_estimate_bounds_variants(tables, factor):
    spec = case_spec("hpt310-coarse").replace(**tables)
    real = build_model(spec).n_atoms
    assert real <= model_size(spec).beads <= factor * real


def test_a_huge_model_is_refused_by_build_model_before_any_array():
    """Chains of 2 um: ~3e9 beads; a spec made without validation (density 1.8e-9, ~1e12 beads):
    both refused by build_model's size estimate before any array is allocated."""
    small_chains = case_spec("hpt310-coarse").replace(discretisation={"chain_diameter_um": 2.0})
    with pytest.raises(SpecError, match="chain_diameter_um 2") as err:
        build_model(small_chains)
    assert f"{MAX_BEADS:,}" in str(err.value) and "\n" not in str(err.value)
    spec = case_spec("hpt310-coarse")
    light = dataclasses.replace(spec.plies[0], density_g_cm3=1.8e-9)
    with pytest.raises(SpecError, match=r"density_g_cm3 1\.8e-09"):
        build_model(dataclasses.replace(spec, plies=(light, spec.plies[1])))


def test_committed_specs_still_validate():
    for path in [*ROOT.glob("runs/*/spec.toml"), *ROOT.glob("docs/**/*.toml")]:
        load_spec(path)


# -- a few doors through a real process ----------------------------------------------------------


def test_doors_through_a_process(place):
    """Exit code 2, one line on stderr, no traceback: as a user sees them."""
    root, files, folders = place
    light = root / "light.toml"
    light.write_text(
        (ROOT / "runs" / "hpt310-coarse" / "spec.toml")
        .read_text()
        .replace("density_g_cm3 = 1.80\n", "density_g_cm3 = 1.8e-9\n", 1)
    )
    cases = [
        ["report", folders["built"]],
        ["report", folders["missing"]],
        ["report", folders["h5_truncated"]],
        ["run", files["spec"], "-o", folders["h5_random"], "--resume"],
        ["check", light],
        ["build", files["spec"], "-o", folders["a_file"], "--force"],
        ["run", files["spec"], "-o", root / "x", "--np", "abc"],
    ]
    processes = [
        subprocess.Popen(
            [sys.executable, "-m", "ncf2lammps.cli", *map(str, argv)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for argv in cases
    ]
    for argv, process in zip(cases, processes, strict=True):
        _, err = process.communicate(timeout=120)
        ok = process.returncode == 2 and err.count("\n") == 1 and "Traceback" not in err
        TALLY["refused" if ok else "crashed"] += 1
        assert ok, f"{argv}: exit {process.returncode}, stderr {err!r}"


def test_example_scripts_refuse_bad_arguments(place, tmp_path):
    """The scripts of runs/ and benchmarks/ (through ``ncf2lammps.cli.script_main``): a wrong
    argument, a missing spec, a folder that is no run: exit 2, no traceback, the last line
    names what is wrong, nothing made. None of these starts LAMMPS."""
    _, files, folders = place
    runs, benchmarks = ROOT / "runs", ROOT / "benchmarks"
    out = tmp_path / "out"
    cases = [
        ([runs / "compaction_rate_check.py"], "required"),
        ([runs / "compaction_rate_check.py", tmp_path / "no.toml", out], "no.toml"),
        ([runs / "sweep_diameter.py", "--bogus"], "--bogus"),
        ([runs / "compare_runs.py", out / "o.png", "--study", tmp_path], "study.csv"),
        ([runs / "compare_runs.py", out / "o.png", f"A={folders['h5_random']}"], "results.h5"),
        (
            [runs / "test_from_manufactured.py", files["spec"], folders["stranger"], out, "shear"],
            "run folder",
        ),
        ([runs / "shear_senses.py", files["spec"], folders["stranger"], out], "run folder"),
        ([benchmarks / "engine_overhead.py", "--chunk", "0"], "--chunk"),
        ([benchmarks / "scaling.py", "--ranks", "0"], "--ranks"),
        ([benchmarks / "build_speed.py", "--repeat", "x"], "--repeat"),
        ([benchmarks / "time_to_solution.py", "--repeat", "0"], "--repeat"),
    ]
    processes = [
        subprocess.Popen(
            [sys.executable, *map(str, argv)],
            cwd=tmp_path,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for argv, _ in cases
    ]
    for (argv, named), process in zip(cases, processes, strict=True):
        _, err = process.communicate(timeout=120)
        last = err.strip().splitlines()[-1] if err.strip() else ""
        assert process.returncode == 2 and "Traceback" not in err, (argv, err)
        assert named in last, (argv, last)
    assert not out.exists()
