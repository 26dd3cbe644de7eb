"""Plot functions: each draws on a given axes; importing the package keeps matplotlib's backend."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
from matplotlib.figure import Figure

from ncf2lammps.analysis.plots import plot_compaction, plot_shear, plot_study


def _results() -> dict:
    """Synthetic results.h5 contents: a compaction and a shear group."""
    gap = np.linspace(1.0, 0.3, 50)
    pressure = 0.01 * np.exp(12 * (1.0 - gap))
    angle = np.linspace(0.5, 45.0, 40)
    return {
        "compaction": {
            "attrs": {
                "thickness_at_1kPa_mm": 0.62,
                "thickness_at_18kPa_mm": float("nan"),
                "plate_speed_m_s": 0.5,
            },
            "gap_mm": gap,
            "pressure_kPa": pressure,
            "pressure_smoothed_kPa": pressure,
        },
        "shear": {
            "attrs": {"shear_rate_deg_us": 0.01},
            "angle_deg": angle,
            "force_N_per_m": 0.02 * angle,
            "force_work_N_per_m": 0.021 * angle,
        },
    }


def test_curve_plots_draw_on_the_given_axes_with_the_paper_marks_once():
    results = _results()
    fig = Figure()
    left, right = fig.subplots(1, 2)
    assert plot_compaction(results, left) is left
    assert plot_shear(results, right) is right
    # The run's own figure: raw, smoothed, one circled thickness, experiment, paper model.
    assert len(left.get_lines()) == 5 and left.get_yscale() == "log"
    assert len(right.get_lines()) == 4 and right.get_yscale() == "symlog"
    for label in ("a", "b"):  # comparing runs: one curve each, the paper's marks stay single
        plot_compaction(results, left, label=label)
        plot_shear(results, right, label=label)
    assert len(left.get_lines()) == 7 and len(right.get_lines()) == 6
    assert sum(line.get_gid() == "paper" for line in left.get_lines()) == 2
    assert [t.get_text() for t in right.get_legend().get_texts()][-2:] == ["a", "b"]


def test_without_axes_a_new_figure_is_made():
    results = _results()
    assert isinstance(plot_compaction(results).figure, Figure)
    assert isinstance(plot_shear(results).figure, Figure)
    ax = Figure().subplots()
    wall, error = np.array([1.0, 2.0, 4.0]), np.array([0.0, 0.1, 0.01])
    front = np.array([True, False, True])
    assert plot_study(wall, error, front, ["p0", "p1", "p2"], 0.05, 0, ax=ax) is ax.figure
    assert len(ax.get_lines()) == 4


def test_importing_the_package_keeps_the_backend():
    """A non-Agg backend chosen before the import (as Jupyter's inline one) stays chosen."""
    code = (
        "import matplotlib; matplotlib.use('svg'); b = matplotlib.get_backend();"
        " import ncf2lammps, ncf2lammps.cli, ncf2lammps.orchestration.run;"
        " import ncf2lammps.scenes.compaction, ncf2lammps.scenes.shear, ncf2lammps.analysis.render3d;"
        " import ncf2lammps.scenes.validation.plots;"
        " assert matplotlib.get_backend() == b, matplotlib.get_backend()"
    )
    env = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}
    subprocess.run([sys.executable, "-c", code], env=env, check=True)


def test_paper_marks_only_for_the_papers_fabric():
    """The paper's marks belong to a 0/90 fabric; a +-45 one gets its curves alone."""
    from ncf2lammps.analysis.plots import paper_comparable

    assert paper_comparable([0.0, 90.0]) and paper_comparable([])
    assert not paper_comparable([45.0617, -45.0617])
    ax = plot_shear(_results(), paper_marks=False)
    assert not any(line.get_gid() == "paper" for line in ax.get_lines())


def test_stitch_tension_plot_draws_each_sense_and_the_first_break():
    from ncf2lammps.analysis.plots import plot_stitch_tension

    results = _results()
    angle = results["shear"]["angle_deg"]
    broken = (angle > 30.0).astype(float)
    for group, scale in (("shear", 0.0), ("shear_negative", 1.0)):
        results.setdefault(group, {"attrs": {}})
        results[group] |= {
            "stitch_angle_deg": angle,
            "stitch_tension_mean_N": 0.1 + scale * 0.05 * angle,
            "stitch_tension_max_N": 0.2 + scale * 0.06 * angle,
            "stitch_bonds_broken": broken * scale,
        }
    ax = plot_stitch_tension(results)
    labels = [line.get_label() for line in ax.get_lines()]
    assert labels == [
        "mean, positive",
        "largest, positive",
        "mean, negative",
        "largest, negative",
        "first break, negative",
    ]
    assert ax.get_lines()[-1].get_xdata()[0] == angle[np.argmax(angle > 30.0)]
