"""Each scene's deck holds only what that scene needs (issue 6), for the three committed cases."""

from __future__ import annotations

import re

import pytest
from conftest import CASES, case_spec

from ncf2lammps import build

#: Commands (regular expressions on deck lines) that only the named scene may contain.
ONLY_IN = {
    r"^fix\s+\S+\s+\S+\s+deform\b": "shear",
    r"^fix\s+\S+\s+\S+\s+wall/gran/region\b": "compaction",
    r"^fix\s+\S+\s+\S+\s+wall/region\b": "manufacture",
    r"^fix\s+\S+\s+\S+\s+adapt\b": "manufacture",
    r"^fix\s+\S+\s+\S+\s+controller\b": "manufacture",
    r"^region\s+needle": "manufacture",
    r"^region\s+plate_": "compaction",
}


@pytest.mark.parametrize("case", CASES)
def test_decks_hold_only_their_commands(case, tmp_path):
    result = build(case_spec(case), tmp_path / "run")
    stitch_types = [t.name for t in result.model.bond_types if t.role == "stitch"]
    for scene in result.decks:
        deck = (result.directory / "decks" / f"in.{scene}.lmp").read_text()
        lines = [ln.strip() for ln in deck.splitlines()]
        for pattern, owner in ONLY_IN.items():
            found = [ln for ln in lines if re.match(pattern, ln)]
            assert not found or scene == owner, (scene, found)
        assert not any(ln.startswith("shell") for ln in lines)
    if not stitch_types:  # mat-only: no stitch scene, no stitch bond type anywhere
        assert "manufacture" not in result.decks
        assert "stitch" not in (result.directory / "model.data").read_text()
