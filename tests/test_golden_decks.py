"""Golden files: the rendered decks of the committed cases and of every validation case.

A refactor must not change what LAMMPS is told. Each committed case is built (driver decks) and
exported (plain-``lmp`` bundle decks); every deck, and the SHA-256 of ``model.data``, must equal
the files under ``tests/golden/`` byte for byte. The validation decks are compared after the
fast validation forms have run (``tests/validation``). A deliberate change regenerates them with
``NCF2LAMMPS_UPDATE_GOLDEN=1 pytest tests/test_golden_decks.py tests/validation -m "not slow"``
and shows up in the diff for review.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest
from conftest import CASES, GOLDEN, case_spec, compare_or_update

from ncf2lammps import build
from ncf2lammps.scenes.export import export


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest() + "\n"


@pytest.mark.parametrize("case", CASES)
def test_committed_case_decks_match_golden_files(case, tmp_path):
    spec = case_spec(case)
    built = build(spec, tmp_path / "run").directory
    bundle = export(spec, tmp_path / "bundle")
    produced = {f"run/{p.name}": p.read_text() for p in (built / "decks").glob("*.lmp")}
    produced |= {f"bundle/{p.name}": p.read_text() for p in (bundle / "decks").glob("*.lmp")}
    produced["bundle/in.run_all.lmp"] = (bundle / "in.run_all.lmp").read_text()
    produced["model.data.sha256"] = _sha256(built / "model.data")
    compare_or_update(produced, GOLDEN / case)
