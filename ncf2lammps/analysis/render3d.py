"""Lit 3D renders of a cell with OVITO (optional extra ``render``), matplotlib otherwise.

The same three views as :func:`~ncf2lammps.analysis.plots.render_views` (front = loop face seen
from +z, back = underlap face seen from -z, side seen from -y), the cell tiled 3 x 2 like the
paper's Fig. 4, beads as shaded spheres of their true diameter: fibre plies in muted colours,
the stitch yarn bright orange. OVITO's standard renderer (``OpenGLRenderer`` is its alias;
it rasterises on Vulkan) runs headless on Debian's ``libvulkan1`` and ``mesa-vulkan-drivers``:
0.6 s a view for 20k tiled beads. Its Tachyon ray tracer needs the same driver and took 35 s,
so it is no fallback. ``ovito`` is imported only when a render is asked for;
:func:`views_figure` falls back to the matplotlib discs, with one logged note, when ``ovito`` is
missing or cannot render.
"""

from __future__ import annotations

import functools
import logging

import numpy as np
from matplotlib.figure import Figure

from ..io.datafile import LammpsData
from .plots import CAPTIONS, VIEWS, render_views, tile_cell

__all__ = ["render_view", "views_figure"]

_log = logging.getLogger(__name__)

#: View name -> (camera direction, camera up); the camera looks along the direction.
CAMERAS = {
    "front": ((0.0, 0.0, -1.0), (0.0, 1.0, 0.0)),
    "back": ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
    "side": ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
}
#: RGB of fibre plies, by type id (cycled); the stitch type is drawn in :data:`STITCH_COLOUR`.
FIBRE_COLOURS = np.array([[0.32, 0.40, 0.52], [0.70, 0.70, 0.66], [0.45, 0.55, 0.40]])
STITCH_COLOUR = np.array([1.0, 0.55, 0.05])
#: Pixel height of the title band above each view; figure resolution (dots per inch).
TITLE_PX = 34
DPI = 110


def _colours(type_id: np.ndarray, stitch_type: int | None) -> np.ndarray:
    colours = FIBRE_COLOURS[type_id % len(FIBRE_COLOURS)]
    if stitch_type is not None:
        colours[type_id == stitch_type] = STITCH_COLOUR
    return colours


def render_view(
    positions: np.ndarray,
    diameter: np.ndarray,
    type_id: np.ndarray,
    box_lengths: np.ndarray,
    view: str = "front",
    repeat: tuple[int, int] = (3, 2),
    tilt_xy: float = 0.0,
    stitch_type: int | None = None,
    width_px: int = 1800,
) -> np.ndarray:
    """(H, width_px, 3) uint8 image of one view rendered by OVITO (raises if it cannot render).

    Args:
        positions: (N, 3) um; diameter: (N,) um; type_id: (N,) int, 0-based.
        box_lengths: (3,) um; tilt_xy: xy tilt of a sheared box (um).
        view: ``front``, ``back`` or ``side`` (:data:`CAMERAS`); the side view tiles x only.
        repeat: cells tiled along the two box edges in the plane.
        stitch_type: type id drawn in the stitch colour (None: no stitch).
        width_px: image width; the height follows the tiled extent (at least 40 px).

    Raises:
        ImportError: ``ovito`` (the ``render`` extra) is not installed.
        RuntimeError: OVITO found no working Vulkan driver.
    """
    h, v, _, _ = VIEWS[view]
    tiled, copies = tile_cell(
        positions, box_lengths, tilt_xy, repeat if view != "side" else (repeat[0], 1)
    )
    size = np.tile(diameter, copies)
    extent = (np.ptp(tiled, axis=0) + size.max()) * 1.02
    height_px = max(40, round(width_px * extent[v] / extent[h]))
    aspect = height_px / width_px
    # OVITO's orthographic fov is half the visible range along the image's shorter side.
    fov = 0.5 * (
        max(extent[v], extent[h] * aspect) if aspect <= 1 else max(extent[h], extent[v] / aspect)
    )
    colours = _colours(np.tile(type_id, copies), stitch_type)
    return _ovito_render(tiled, size, colours, view, extent.max(), fov, (width_px, height_px))


def _ovito_render(
    positions: np.ndarray,
    diameter: np.ndarray,
    colours: np.ndarray,
    view: str,
    distance: float,
    fov: float,
    size_px: tuple[int, int],
) -> np.ndarray:
    """(height, width, 3) uint8 OVITO render of spheres in an orthographic view.

    ``positions`` (N, 3) um, ``diameter`` (N,) um, ``colours`` (N, 3) RGB in [0, 1]; the camera
    looks along :data:`CAMERAS` ``[view]`` at the centre of the bounding box from ``distance``
    (um) away, ``fov`` (um) is half the visible range along the shorter image side,
    ``size_px`` is (width, height).
    """
    from ovito.data import DataCollection, Particles
    from ovito.pipeline import Pipeline, StaticSource
    from ovito.vis import StandardRenderer, Viewport

    particles = Particles(count=len(positions))
    particles.create_property("Position", data=positions)
    particles.create_property("Radius", data=diameter / 2.0)
    particles.create_property("Color", data=colours)
    data = DataCollection()
    data.objects.append(particles)
    pipeline = Pipeline(source=StaticSource(data=data))
    direction, up = CAMERAS[view]
    centre = 0.5 * (positions.min(axis=0) + positions.max(axis=0))
    viewport = Viewport(
        type=Viewport.Type.Ortho,
        camera_pos=centre - np.asarray(direction) * distance,
        camera_dir=direction,
        camera_up=up,
        fov=fov,
    )
    pipeline.add_to_scene()
    try:
        image = viewport.render_image(size=size_px, renderer=StandardRenderer())
    finally:
        pipeline.remove_from_scene()
    return _rgb_array(image)


def _rgb_array(image) -> np.ndarray:
    """(height, width, 3) uint8 copy of a ``QImage`` (its rows are padded to 4 bytes)."""
    from ovito.qt_compat import QtGui

    image = image.convertToFormat(QtGui.QImage.Format.Format_RGB888)
    rows = np.frombuffer(image.constBits(), np.uint8, image.bytesPerLine() * image.height())
    rows = rows.reshape(image.height(), -1)[:, : 3 * image.width()]
    return rows.reshape(image.height(), image.width(), 3).copy()  # the QImage owns the buffer


@functools.cache
def _note(reason: str) -> None:
    """Log the fallback once per distinct reason."""
    _log.warning(
        "3D renders unavailable (%s); drawing the faces with matplotlib. For lit 3D renders: "
        'apt-get install -y libvulkan1 mesa-vulkan-drivers && pip install "ncf2lammps[render]"',
        reason,
    )


def views_figure(
    positions: np.ndarray,
    diameter: np.ndarray,
    type_id: np.ndarray,
    box_lengths: np.ndarray,
    title: str,
    tilt_xy: float = 0.0,
    stitch_type: int | None = None,
):
    """Figure (save at :data:`DPI`) of the front, back and side views of a 3 x 2 tiling.

    OVITO spheres when the ``render`` extra works, else :func:`plots.render_views` discs.
    Arguments as in :func:`render_view`.
    """
    try:
        images = [
            render_view(
                positions,
                diameter,
                type_id,
                box_lengths,
                view,
                tilt_xy=tilt_xy,
                stitch_type=stitch_type,
            )
            for view in CAMERAS
        ]
    except (ImportError, OSError, RuntimeError) as err:
        _note(f"{type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''}")
        return render_views(positions, diameter, type_id, box_lengths, title, tilt_xy)
    width = images[0].shape[1]
    height = sum(image.shape[0] + TITLE_PX for image in images)
    fig = Figure(figsize=(width / DPI, height / DPI), dpi=DPI)
    top = height
    for view, image in zip(CAMERAS, images, strict=True):
        fig.text(0.01, (top - TITLE_PX / 2) / height, f"{title}: {CAPTIONS[view]}", va="center")
        top -= TITLE_PX + image.shape[0]
        ax = fig.add_axes((0.0, top / height, image.shape[1] / width, image.shape[0] / height))
        ax.imshow(image, interpolation="none")
        ax.set_axis_off()
    return fig


def state_views(state: LammpsData, title: str):
    """:func:`views_figure` of a state read from a data file (its box tilt and stitch label)."""
    labels = state.atom_labels
    return views_figure(
        state.positions,
        state.diameter,
        state.type_id,
        state.box.hi - state.box.lo,
        title,
        tilt_xy=float(state.box.tilt[0]),
        stitch_type=labels.index("stitch") if "stitch" in labels else None,
    )
