"""Renders of the generated tiny cell: OVITO spheres when the extra works, matplotlib otherwise."""

from __future__ import annotations

import logging
import sys

import matplotlib.image
import numpy as np
import pytest
from conftest import tiny_spec

from ncf2lammps import build_model
from ncf2lammps.analysis import plots, render3d


@pytest.fixture(scope="module")
def tiny():
    """Generated tiny stitched cell and its stitch type id."""
    model = build_model(tiny_spec())
    return model, [t.role for t in model.atom_types].index("stitch")


def test_fallback_draws_the_faces_with_matplotlib(tiny, tmp_path, monkeypatch, caplog):
    model, stitch = tiny
    monkeypatch.setitem(sys.modules, "ovito", None)  # import ovito raises ImportError
    render3d._note.cache_clear()
    with caplog.at_level(logging.WARNING, logger=render3d.__name__):
        for _ in range(2):
            fig = render3d.views_figure(
                model.positions,
                model.diameter,
                model.type_id,
                model.box.lengths,
                "tiny",
                0.0,
                stitch,
            )
    fig.savefig(tmp_path / "views.png", dpi=render3d.DPI)
    image = matplotlib.image.imread(tmp_path / "views.png")
    assert image.shape[:2] == tuple(round(v * render3d.DPI) for v in fig.get_size_inches()[::-1])
    assert image[..., :3].std() > 0.05
    # Panels at the cell's aspect ratio fill the canvas but for their margins (inches): the
    # equal aspect of the axes shrinks none of them.
    width, height = fig.get_size_inches()
    left, right, top, bottom = plots._PANEL_MARGINS_IN
    boxes = [ax.get_position() for ax in fig.axes]  # after the draw: as drawn
    assert len(boxes) == 3
    assert all(box.width * width == pytest.approx(width - left - right, rel=1e-3) for box in boxes)
    assert sum(box.height for box in boxes) * height == pytest.approx(
        height - 3 * (top + bottom), rel=1e-3
    )
    assert len(caplog.records) == 1 and "matplotlib" in caplog.records[0].getMessage()


def test_ovito_renders_lit_spheres(tiny):
    pytest.importorskip("ovito")
    model, stitch = tiny
    args = (model.positions, model.diameter, model.type_id, model.box.lengths)
    front = render3d.render_view(*args, "front", stitch_type=stitch, width_px=400)
    lx, ly = model.box.lengths[:2]
    assert front.shape[1] == 400 and front.shape[0] == pytest.approx(
        400 * 2 * ly / (3 * lx), rel=0.1
    )
    assert front.std() > 20.0  # not blank
    orange = np.all(np.abs(front / 255.0 - render3d.STITCH_COLOUR) < 0.25, axis=-1)
    assert orange.any()  # the stitch loops lie on the front face
    side = render3d.render_view(*args, "side", stitch_type=stitch, width_px=400)
    assert side.shape == (40, 400, 3) and side.std() > 20.0
