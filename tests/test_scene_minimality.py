"""Each scene's deck holds only what that scene needs, for every committed case: the one place
where deck minimality is checked."""

from __future__ import annotations

import re

import pytest
from conftest import CASES, case_spec

from ncf2lammps import build

SHEAR = ("shear", "shear_negative")
#: Commands (regular expressions on deck lines) that only the named scenes may contain.
ONLY_IN = {
    r"^fix\s+\S+\s+\S+\s+deform\b": SHEAR,
    r"^fix\s+\S+\s+\S+\s+wall/gran/region\b": ("compaction",),
    r"^fix\s+\S+\s+\S+\s+wall/region\b": ("manufacture",),
    r"^fix\s+\S+\s+\S+\s+adapt\b": ("manufacture",),
    r"^fix\s+(?!load_)\S+\s+\S+\s+controller\b": ("manufacture",),
    r"^fix\s+load_\S+\s+\S+\s+controller\b": ("compaction", *SHEAR),
    r"^fix\s+load_plate_drop\b": ("compaction",),
    r"^fix\s+load_g\b": SHEAR,
    r"^region\s+needle": ("manufacture",),
    r"^region\s+plate_": ("compaction",),
    r"^fix\s+\S+\s+\S+\s+(?:langevin|viscous)\b": ("manufacture",),
    r"^fix\s+\S+\s+\S+\s+bond/break\b": ("compaction", *SHEAR),
}


@pytest.mark.parametrize("case", CASES)
def test_decks_hold_only_their_commands(case, tmp_path):
    result = build(case_spec(case), tmp_path / "run")
    stitch_types = [t.name for t in result.model.bond_types if t.role == "stitch"]
    for scene, deck in result.decks.items():
        lines = [ln.strip() for ln in deck.text.splitlines()]
        for pattern, owner in ONLY_IN.items():
            found = [ln for ln in lines if re.match(pattern, ln)]
            assert not found or scene in owner, (scene, found)
        assert not any(ln.startswith("shell") for ln in lines)
    if not stitch_types:  # mat-only: no stitch scene, no stitch bond type anywhere
        assert "manufacture" not in result.decks
        assert "stitch" not in (result.directory / "model.data").read_text()
