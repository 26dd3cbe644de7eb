"""The validation table and the ``validate`` command (one quick case through the CLI)."""

from __future__ import annotations

import pytest

from ncf2lammps.cli import main
from ncf2lammps.scenes.validation import Check
from ncf2lammps.scenes.validation.common import CaseResult
from ncf2lammps.scenes.validation.report import table_lines


def test_check_kinds_judge_their_tolerance():
    assert Check("c", "n", "law", 2.0, 2.009, 0.005).passed
    assert not Check("c", "n", "law", 2.0, 2.011, 0.005).passed
    assert Check("c", "n", "law", 0.0, -9e-4, 1e-3, "absolute").passed
    assert not Check("c", "n", "law", 0.0, 2e-3, 1e-3, "absolute").passed
    assert Check("c", "n", "law", 1.0, 1.02, 0.05, "above").passed
    assert not Check("c", "n", "law", 1.0, 0.99, 0.05, "above").passed
    assert not Check("c", "n", "law", 1.0, 1.06, 0.05, "above").passed


def test_table_has_every_column_and_verdict():
    result = CaseResult("x", [Check("x", "a", "F = mu N", 0.3, 0.4, 0.005)])
    header, row = table_lines([result])
    assert row.startswith("x: a")
    for word in ("case", "law", "expected", "measured", "error", "tolerance", "pass"):
        assert word in header
    assert "FAIL" in row and "+33.333 %" in row


@pytest.mark.lammps
def test_validate_command_writes_report(tmp_path, capsys):
    assert main(["validate", "-o", str(tmp_path), "--case", "hertz"]) == 0
    out = capsys.readouterr().out
    assert "F = 4/3 E* sqrt(R*) delta^1.5" in out
    report = (tmp_path / "validation.md").read_text()
    assert "| 2 Hertz:" in report and "![hertz](hertz/hertz.png)" in report


def test_validate_refuses_unknown_case(tmp_path, capsys):
    assert main(["validate", "-o", str(tmp_path), "--case", "nope"]) == 2
    assert "--case" in capsys.readouterr().err
