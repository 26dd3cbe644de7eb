"""Stitch rupture (stitch.rupture, fix bond/break) and the stitch tension history of the loading
scenes (docs/stitch.md)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import case_spec, tiny_spec

from ncf2lammps import build, run
from ncf2lammps.io.results import read_results
from ncf2lammps.numerics import prepare
from ncf2lammps.scenes import render_deck
from ncf2lammps.spec import SpecError

#: Tenacity (cN/dtex) that breaks the tiny cell's most tensioned breakable stitch bonds at once:
#: 0.38 N, above the 0.1 N mean pretension, below the 0.87 N largest bond tension after
#: manufacture.
WEAK_TENACITY = 0.5


@pytest.mark.parametrize(
    ("stitch", "field", "words"),
    [
        ({"tenacity_cN_dtex": 3.0}, "stitch.tenacity_cN_dtex", "stitch.rupture = true"),
        ({"rupture": True, "tenacity_cN_dtex": 0.0}, "stitch.tenacity_cN_dtex", "out of range"),
        ({"rupture": True, "elongation_at_break": 0.3}, "stitch.elongation_at_break", "'strain'"),
        (
            {"rupture": True, "rupture_criterion": "strain", "tenacity_cN_dtex": 3.0},
            "stitch.tenacity_cN_dtex",
            "'force'",
        ),
        ({"rupture": "yes"}, "stitch.rupture", "true or false"),
        ({"rupture": True, "rupture_criterion": "energy"}, "stitch.rupture_criterion", "one of"),
    ],
)
def test_bad_rupture_keys_name_the_field(stitch, field, words):
    with pytest.raises(SpecError, match=field) as err:
        tiny_spec(stitch=stitch)
    assert words in str(err.value)


def test_a_stitch_weaker_than_its_pretension_is_refused(tmp_path):
    spec = tiny_spec(stitch={"rupture": True, "tenacity_cN_dtex": 0.1})  # 0.076 N < 0.1 N
    with pytest.raises(SpecError, match=r"stitch\.tenacity_cN_dtex.*pretension"):
        build(spec, tmp_path / "run")


def test_rupture_off_records_tension_without_bond_break():
    """Default: the loading decks record the stitch tension and break nothing; the mat-only case
    (no stitch) records no stitch at all."""
    prepared = prepare(case_spec("hpt310-coarse"))
    for name in ("compaction", "shear"):
        text = render_deck(prepared, name).text
        assert "bond/break" not in text and "stitch_history" in text
    assert "stitch" not in render_deck(prepare(case_spec("mat-only")), "shear").text


def test_rupture_decks_use_the_manufactured_rest_lengths():
    prepared = prepare(tiny_spec(stitch={"rupture": True}))
    assert "file manufactured.stitch.lmp" in render_deck(prepared, "manufacture").text
    shear = render_deck(prepared, "shear", plain_lmp=True).text
    assert "include         manufactured.stitch.lmp" in shear
    assert shear.count("stitch_breakable bond/break") == sum(
        t.role == "stitch" for t in prepared.model.bond_types
    )


@pytest.mark.lammps
def test_weak_stitch_breaks_and_reports_where(tmp_path):
    """A stitch of tenacity WEAK_TENACITY sheared 2 deg loses bonds: the recorded count, the
    count from the bond lists (manufactured.data against the final data file) and the listed
    positions agree; the run stays stable (the freed beads do not fire apart)."""
    spec = tiny_spec(
        stitch={"rupture": True, "tenacity_cN_dtex": WEAK_TENACITY},
        shear={"final_angle_deg": 2.0},
    )
    group = read_results(run(spec, tmp_path / "run", scenes=["shear"]))["shear"]
    attrs = group["attrs"]
    broken = int(attrs["stitch_bonds_broken"])
    assert broken > 0 and group["stitch_bonds_broken"][-1] == broken
    assert np.isfinite(attrs["stitch_first_break_angle_deg"])
    assert np.shape(attrs["stitch_broken_midpoints_mm"]) == (broken, 3)
    assert attrs["stitch_broken_bonds"].count(" mm") == min(broken, 12)
    assert np.all(group["stitch_tension_max_N"] >= group["stitch_tension_mean_N"])
