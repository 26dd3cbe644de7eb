"""The loading rate of the test scenes (scenes/loading.py, templates/loading.lmp.j2).

The laws of the controller on real runs (the rate update and the coordinate as the integral of
the rate) are checked where those runs are made: tests/test_compaction.py, tests/test_shear.py.
"""

from __future__ import annotations

import math

import pytest
from conftest import case_spec

from ncf2lammps import prepare
from ncf2lammps.orchestration.study import parse_vary
from ncf2lammps.scenes import SCENES, render_deck
from ncf2lammps.scenes.loading import (
    SAMPLES,
    control_interval,
    kinetic_checks,
    loading_attrs,
    quasi_static,
)
from ncf2lammps.spec import SpecError


@pytest.mark.parametrize("multiple", [1, 10, 7])
def test_control_interval_resolves_the_fastest_rate(multiple):
    """An interval is a whole number of samples and of ``multiple`` steps, and at the fastest
    rate the coordinate moves by at most the resolution in it (by more than half of it unless
    one block of steps is already too long)."""
    dt, fastest, resolution = 0.004, 0.3, 1.0
    every = control_interval(resolution, fastest, dt, multiple)
    block = math.lcm(multiple, SAMPLES)
    assert every % block == 0
    assert every * fastest * dt <= resolution
    assert (every + block) * fastest * dt > resolution
    assert control_interval(1e-9, fastest, dt, multiple) == block


@pytest.mark.parametrize("scene, coordinate", [("compaction", "plate_drop"), ("shear", "g")])
def test_constant_loading_renders_no_controller(scene, coordinate):
    """Adaptive decks hold the rate controller, bounded at max_rate_factor times the
    inertial-number rate; constant decks only the integrator of the coordinate. Compaction is
    adaptive and shear constant by default."""
    default = prepare(case_spec("hpt310-coarse"))
    assert SCENES[scene].deck_values(default)["control"].adaptive is (scene == "compaction")
    adaptive, constant = (
        prepare(case_spec("hpt310-coarse").replace(**{scene: {"loading": kind}}))
        for kind in ("adaptive", "constant")
    )
    control = SCENES[scene].deck_values(adaptive)["control"]
    assert control.adaptive and control.rate_max == pytest.approx(16.0 * control.rate)
    integrator = f"fix             load_{coordinate} all controller 1 "
    for prepared, has_controller in ((adaptive, True), (constant, False)):
        text = render_deck(prepared, scene).text
        assert integrator in text
        assert ("fix             load_rate all controller" in text) is has_controller
    assert not SCENES[scene].deck_values(constant)["control"].adaptive


def test_vary_takes_numbers_and_words():
    assert parse_vary("compaction.inertial_number=0.05, 0.1") == (
        "compaction.inertial_number",
        [0.05, 0.1],
    )
    assert parse_vary("shear.loading=constant,adaptive") == (
        "shear.loading",
        ["constant", "adaptive"],
    )
    with pytest.raises(SpecError, match="numbers or words"):
        parse_vary("shear.loading=1..2")


def test_each_test_is_checked_on_the_error_of_its_own_output():
    """The shear's check is its kinetic stress ratio Q (its output is that stress); the
    compaction's is the thickness error Q b, so its Q alone carries no limit; both 1 %; a check
    is the largest over the measured records only."""
    spec = case_spec("hpt310-coarse")
    ratio = [0.5, 0.02, 0.004]
    measured = [False, True, True]
    shear = loading_attrs(spec.shear, ratio, measured)
    assert shear["max_kinetic_stress_ratio"] == 0.02 and shear["kinetic_stress_limit"] == 0.01
    assert not quasi_static(shear)
    compaction = loading_attrs(spec.compaction, ratio, measured, [5.0, 0.002, 0.0004])
    assert kinetic_checks(compaction) == [(0.002, 0.01)]
    assert quasi_static(compaction)
    assert not quasi_static(compaction | {"max_kinetic_thickness_error": 0.0101})
    # A compaction written before its thickness check is judged on Q, as it was.
    older = {"max_kinetic_stress_ratio": 0.02, "kinetic_stress_limit": 0.01}
    assert kinetic_checks(older) == [(0.02, 0.01)] and not quasi_static(older)
    assert kinetic_checks({"kinetic_ratio": 0.5}) == [] and quasi_static({"kinetic_ratio": 0.5})
