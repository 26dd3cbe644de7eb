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
import math
import re
from pathlib import Path

import pytest
from conftest import CASES, GOLDEN, case_spec, compare_or_update

from ncf2lammps import build
from ncf2lammps.numerics import prepare
from ncf2lammps.orchestration.export import export
from ncf2lammps.scenes import applicable_scenes, render_deck


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


#: The period N of every periodic fix in a deck: ``fix ave/time Nevery Nrepeat N``, ``halt N``,
#: ``print N``, ``controller N``.
PERIODIC = re.compile(
    r"^fix\s+\S+\s+\S+\s+(?:ave/time\s+\d+\s+\d+|halt|print|controller)\s+(\d+)\b", re.M
)


@pytest.mark.parametrize("case", CASES)
def test_deck_period_is_the_lcm_of_its_periodic_fixes(case):
    """A deck's declared period (a value, never parsed) equals the least common multiple of the
    periods of the periodic fixes in its text, so checkpoints split no recording window."""
    run = prepare(case_spec(case))
    for name in ("verify", *applicable_scenes(run.spec)):
        deck = render_deck(run, name, plain_lmp=True)
        assert deck.period == math.lcm(*map(int, PERIODIC.findall(deck.text))), name
