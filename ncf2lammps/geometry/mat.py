"""The homogeneous fibrous mat: straight periodic chains of each ply in sub-rows (pure numpy).

Each ply is a slab of thickness ``t = A / (Vf rho)`` (paper eq. 1). Its chain count ``N`` is the
fibre cross-section of the cell divided by the chain cross-section, rounded; the chain diameter is
then corrected so that ``N pi d^2 / 4`` equals the fibre cross-section exactly (the paper keeps the
fibre volume constant). Chains sit in ``floor(t / d)`` sub-rows spaced at least ``d`` apart; each
row holds ``N // rows`` or one more chains evenly spaced across the periodic width, so rows tile
the period exactly and no two chains overlap.

A random bed (:class:`RandomBed`) keeps the chain count and the diameter (or draws per-chain
diameters of the same total cross-section) and places the chain axes at seeded random spots
of the ply's periodic cross-section, rejecting spots closer to a placed chain than
:data:`PLACEMENT_CLEARANCE` of their contact distance; the overlaps left are removed in LAMMPS
(the manufacture scene's push-off stage).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..spec import SpecError
from .chains import BeadChain, sample_closed_polyline
from .direction import PlyDirection

__all__ = [
    "PLACEMENT_CLEARANCE",
    "VERTICES_PER_WAVE",
    "PlyLayout",
    "RandomBed",
    "Waviness",
    "ply_chains",
    "ply_layout",
    "wavy_chains",
]

#: Polyline corners per wavelength of a wavy chain: a sine sampled at 16 points, every corner a
#: bead; its segments come in four lengths, so a ply gets a handful of bond and angle types.
VERTICES_PER_WAVE = 16

#: Closest approach of two chain axes of a random bed, fraction of their contact distance: the
#: initial overlap stays below half a contact distance, and no two chains start (nearly) on top
#: of each other, where their contact forces would have no direction to push them apart.
PLACEMENT_CLEARANCE = 0.5

#: Candidate spots drawn at once per chain, and the most drawn, of the random placement.
_BATCH, _MAX_CANDIDATES = 256, 256 * 400


@dataclass(frozen=True)
class Waviness:
    """Sinusoidal waviness of a ply's chains (docs/fidelity.md), all lengths in um.

    Chain ``c`` follows ``u(a) = amplitude sin(2 pi waves (a - a_c) / L)`` across its axis (in the
    plane, or in z if ``out_of_plane``), ``a`` the coordinate along the chain and ``L`` the cell
    edge along it, so the chain closes on itself. Phases ``a_c`` are uniform in
    ``[0, phase_spread L / waves)`` from ``seed`` (``phase_spread`` a fraction of a wave; 0: every
    chain in phase). The curve is a polyline through :data:`VERTICES_PER_WAVE` points per wave.
    """

    amplitude: float
    waves: int
    out_of_plane: bool
    phase_spread: float
    seed: int
    off_axis: bool = False

    def vertices(self, chain_length: float) -> np.ndarray:
        """(V, 3) polyline corners (along, displacement, 0) of one chain of phase 0."""
        j = np.arange(self.waves * VERTICES_PER_WAVE)
        along = j * chain_length / len(j)
        shape = self.amplitude * np.sin(2.0 * np.pi * j / VERTICES_PER_WAVE)
        return np.column_stack([along, shape, np.zeros(len(j))])

    def length_factor(self, chain_length: float) -> float:
        """Polyline length over the cell edge (>= 1): how much longer a wavy fibre is."""
        vertices = self.vertices(chain_length)
        ends = np.vstack([vertices[1:], vertices[:1] + np.array([chain_length, 0.0, 0.0])])
        return float(np.linalg.norm(ends - vertices, axis=1).sum() / chain_length)

    def slope(self, chain_length: float) -> float:
        """Largest slope (tan of the misalignment angle) of the polyline's segments."""
        vertices = self.vertices(chain_length)
        rise = np.diff(np.append(vertices[:, 1], vertices[0, 1]))
        return float(np.abs(rise).max() / (chain_length / len(vertices)))

    def relative_displacement(self, across_plies: bool) -> float:
        """Bound on the difference of two chains' displacements at the same place (um): chains
        of one ply differ by their phases (in phase: 0), chains of two plies by anything, and so
        do neighbours of an off-axis ply (``off_axis``: its chain's periodic image across the
        strip is shifted along, out of phase)."""
        chord_error = self.amplitude * (1.0 - np.cos(np.pi / VERTICES_PER_WAVE))
        if across_plies or self.off_axis:
            return 2.0 * (self.amplitude + chord_error)
        if self.phase_spread == 0.0:
            return 0.0
        half = min(np.pi, 2.0 * np.pi * self.phase_spread) / 2.0
        return 2.0 * (self.amplitude * np.sin(half) + chord_error)

    def phases(self, n_chains: int, chain_length: float, stream: int) -> np.ndarray:
        """(n_chains,) phase shifts ``a_c`` (um), reproducible from ``seed`` and ``stream``."""
        rng = np.random.default_rng([self.seed, stream])
        return rng.uniform(0.0, 1.0, n_chains) * self.phase_spread * chain_length / self.waves


@dataclass(frozen=True)
class RandomBed:
    """A random bed: chain axes at seeded random spots, diameters of relative spread ``spread``
    (lognormal, clipped at 2 standard deviations, rescaled to the ply's fibre cross-section)."""

    seed: int
    spread: float

    def rng(self, stream: int) -> np.random.Generator:
        """The bed's generator of ply ``stream`` (the third word keeps it apart from the
        waviness phases, drawn from ``[seed, stream]``)."""
        return np.random.default_rng([self.seed, stream, 1])

    def diameters(self, n_chains: int, d: float, rng: np.random.Generator) -> np.ndarray:
        """(n_chains,) chain diameters (um) with ``sum d_c^2 = n_chains d^2`` exactly."""
        if self.spread == 0.0:
            return np.full(n_chains, d)
        sigma = np.sqrt(np.log1p(self.spread**2))
        draws = np.exp(sigma * np.clip(rng.standard_normal(n_chains), -2.0, 2.0))
        return d * draws * np.sqrt(n_chains / np.sum(draws**2))


@dataclass(frozen=True)
class PlyLayout:
    """Chain arrangement of one ply in its cross-section (all lengths in um).

    Attributes:
        n_chains: chains in the ply.
        diameter: volume-conserving chain diameter.
        rows: (R,) int, chains in each sub-row, bottom to top.
        row_z: (R,) float, height of each sub-row's chain axes.
        beads_per_chain: beads on each chain (= bonds, chains are closed).
        spacing: bead spacing = bond rest length.
        axes: (n_chains, 2) position across and height of each chain axis of a random bed;
            None in rows.
        diameters: (n_chains,) chain diameters of a random bed with a spread (squares summing to
            ``n_chains diameter^2``); None: every chain ``diameter``.
    """

    n_chains: int
    diameter: float
    rows: np.ndarray
    row_z: np.ndarray
    beads_per_chain: int
    spacing: float
    axes: np.ndarray | None = None
    diameters: np.ndarray | None = None


def ply_layout(
    areal_weight: float,
    density: float,
    chain_length: float,
    width: float,
    z_bottom: float,
    fvf: float,
    diameter: float,
    spacing_ratio: float,
    field_prefix: str = "ply",
    fill: float = 1.0,
    waviness: Waviness | None = None,
    bed: RandomBed | None = None,
    stream: int = 0,
) -> PlyLayout:
    """Arrange one ply's chains (lengths um, areal weight pg/um^2, density pg/um^3).

    ``chain_length`` is the cell edge along the fibres, ``width`` the edge across them. ``fill``
    is the chain's internal fibre volume fraction: a chain of diameter ``d`` carries the fibre
    cross-section ``fill pi d^2 / 4``. With ``waviness`` the chains are longer than the cell by
    its length factor (their diameter shrinks to keep the fibre volume) and their neighbours are
    spaced so that the wavy chains cannot touch (otherwise a SpecError). With ``bed`` the chains
    are placed at random (:func:`_random_axes`, generator stream ``stream``), overlaps allowed.
    """
    fibre_area = areal_weight / density * width  # fibre cross-section of the cell, um^2
    if waviness is not None:
        fibre_area = fibre_area / waviness.length_factor(chain_length)
    n_chains = max(1, round(fibre_area / (fill * np.pi * diameter**2 / 4.0)))
    d = float(np.sqrt(4.0 * fibre_area / (np.pi * n_chains * fill)))
    thickness = areal_weight / (fvf * density)
    beads = max(3, round(chain_length / (spacing_ratio * d)))
    row_pitch = across_pitch = d
    if waviness is not None and bed is None:
        row_pitch, across_pitch = _wavy_pitches(waviness, d, chain_length, spacing_ratio)
        if waviness.out_of_plane and thickness < row_pitch:
            raise SpecError(
                "mat.waviness_amplitude_um",
                waviness.amplitude,
                f"out-of-plane waviness needs rows {row_pitch:.4g} um apart, more than the"
                f" {thickness:.4g} um thick {field_prefix} (lower the amplitude or mat.initial_fvf)",
            )
    if thickness < d * (1.0 - 1e-12):
        raise SpecError(
            "discretisation.chain_diameter_um",
            diameter,
            f"chains of {d:.4g} um do not fit the {thickness:.4g} um thick {field_prefix} of the"
            " homogeneous mat (use chains at most as thick as the ply, or a lower mat.initial_fvf)",
        )
    if bed is not None:
        args = (n_chains, d, thickness, z_bottom, width, chain_length, spacing_ratio, beads)
        return _random_layout(*args, bed, stream, waviness, f"{field_prefix} at Vf {fvf:g}")
    n_rows = int(min(n_chains, max(1, np.floor(thickness / row_pitch * (1.0 + 1e-12)))))
    rows = np.full(n_rows, n_chains // n_rows, dtype=np.int64)
    rows[: n_chains % n_rows] += 1
    _check_rows_fit(rows.max(), width, d, across_pitch, fvf, waviness, field_prefix)
    row_z = z_bottom + (np.arange(n_rows) + 0.5) * thickness / n_rows
    return PlyLayout(n_chains, d, rows, row_z, beads, chain_length / beads)


def _check_rows_fit(
    per_row: int,
    width: float,
    d: float,
    across_pitch: float,
    fvf: float,
    waviness: Waviness | None,
    field_prefix: str,
) -> None:
    """SpecError unless ``per_row`` chains of diameter ``d`` (um), ``across_pitch`` apart when
    wavy, fit side by side across ``width`` (um)."""
    if waviness is not None and width / per_row < across_pitch:
        raise SpecError(
            "mat.waviness_amplitude_um",
            waviness.amplitude,
            f"in-plane waviness needs chains {across_pitch:.4g} um apart in a row, but"
            f" {field_prefix} packs {per_row} across {width:.4g} um (lower the amplitude,"
            " mat.waviness_phase_spread_deg or mat.initial_fvf)",
        )
    if width / per_row < d * (1.0 - 1e-12):
        raise SpecError(
            "mat.initial_fvf",
            fvf,
            f"too dense for {d:.4g} um chains in {field_prefix}: a sub-row of {per_row} chains"
            f" needs {per_row * d:.4g} um across {width:.4g} um (lower mat.initial_fvf or"
            " discretisation.chain_diameter_um)",
        )


def _random_layout(
    n_chains: int,
    d: float,
    thickness: float,
    z_bottom: float,
    width: float,
    chain_length: float,
    spacing_ratio: float,
    beads: int,
    bed: RandomBed,
    stream: int,
    waviness: Waviness | None,
    field_prefix: str,
) -> PlyLayout:
    """The random bed of a ply of ``n_chains`` chains of nominal diameter ``d`` in its slab
    (``thickness`` from ``z_bottom``, um): per-chain diameters, then axes kept a wave amplitude
    (out of the plane) and a radius inside the slab."""
    rise = 0.0
    if waviness is not None:
        _check_corners(waviness, d, chain_length, spacing_ratio)
        rise = waviness.amplitude if waviness.out_of_plane else 0.0
    rng = bed.rng(stream)
    diameters = bed.diameters(n_chains, d, rng)
    slab = (z_bottom + rise, z_bottom + thickness - rise)
    if diameters.max() > slab[1] - slab[0]:
        key, value = (
            ("mat.diameter_spread", bed.spread)
            if bed.spread > 0.0
            else ("mat.waviness_amplitude_um", rise)
        )
        raise SpecError(
            key,
            value,
            f"a {diameters.max():.4g} um chain does not fit the {slab[1] - slab[0]:.4g} um"
            f" of the {thickness:.4g} um thick {field_prefix} that its waves leave (lower"
            f" {key} or discretisation.chain_diameter_um, or mat.initial_fvf)",
        )
    axes = _random_axes(diameters, width, slab, rng, field_prefix)
    rows = np.array([n_chains])
    return PlyLayout(
        n_chains,
        d,
        rows,
        np.array([z_bottom + thickness / 2]),
        beads,
        chain_length / beads,
        axes,
        diameters if bed.spread > 0.0 else None,
    )


def _random_axes(
    diameters: np.ndarray,
    width: float,
    slab: tuple[float, float],
    rng: np.random.Generator,
    field_prefix: str,
) -> np.ndarray:
    """(C, 2) axes (across, height) of chains of ``diameters`` (um) by random sequential
    placement, thickest first: uniform across the periodic ``width``, heights keeping each chain
    inside ``slab`` (bottom, top, um); a spot closer to a placed axis than
    :data:`PLACEMENT_CLEARANCE` of their contact distance is drawn again."""
    axes = np.empty((len(diameters), 2))
    order = np.argsort(-diameters, kind="stable")
    for k, c in enumerate(order):
        lo, hi = slab[0] + diameters[c] / 2, slab[1] - diameters[c] / 2
        placed = order[:k]
        reach = PLACEMENT_CLEARANCE * (diameters[c] + diameters[placed]) / 2
        for _ in range(_MAX_CANDIDATES // _BATCH):
            spots = np.column_stack([rng.uniform(0.0, width, _BATCH), rng.uniform(lo, hi, _BATCH)])
            gap = spots[:, None, :] - axes[placed][None, :, :]
            gap[..., 0] -= np.rint(gap[..., 0] / width) * width
            free = np.all(np.hypot(gap[..., 0], gap[..., 1]) >= reach, axis=1)
            if free.any():
                axes[c] = spots[np.argmax(free)]
                break
        else:
            raise SpecError(
                "mat.arrangement",
                "random",
                f"no free spot for chain {c} of {field_prefix} in {_MAX_CANDIDATES} random draws"
                " (lower mat.initial_fvf or use mat.arrangement = 'rows')",
            )
    return axes


def _strip_coordinates(layout: PlyLayout, period: float) -> tuple[np.ndarray, np.ndarray]:
    """(n_chains,) position across the strip of width ``period`` and height (um) of each chain
    axis: evenly spaced within a row, odd rows shifted by half a pitch; a random bed's axes."""
    if layout.axes is not None:
        return layout.axes[:, 0], layout.axes[:, 1]
    row_of_chain = np.repeat(np.arange(len(layout.rows)), layout.rows)
    first_in_row = np.concatenate([[0], np.cumsum(layout.rows)[:-1]])
    slot = np.arange(layout.n_chains) - first_in_row[row_of_chain]
    pitch = period / layout.rows[row_of_chain]
    across = (slot + 0.5 + 0.5 * (row_of_chain % 2)) * pitch % period
    return across, layout.row_z[row_of_chain]


def ply_chains(layout: PlyLayout, direction: PlyDirection) -> np.ndarray:
    """Bead centres of a ply, shape (n_chains, beads_per_chain, 3), chain by chain, unwrapped.

    Chains run along ``direction`` (:class:`~.direction.PlyDirection`) at the strip coordinates
    of :func:`_strip_coordinates`. Beads of chain ``c`` start at ``(c mod 2) s / 2`` so that
    neighbouring chains do not put beads side by side.
    """
    across, height = _strip_coordinates(layout, direction.period)
    along = (
        np.arange(layout.beads_per_chain)[None, :] + 0.5 * (np.arange(layout.n_chains) % 2)[:, None]
    ) * layout.spacing
    positions = np.empty((layout.n_chains, layout.beads_per_chain, 3))
    positions[..., :2] = direction.place(along, np.broadcast_to(across[:, None], along.shape))
    positions[..., 2] = height[:, None]
    return positions


def _wavy_pitches(waviness: Waviness, d: float, chain_length: float, spacing_ratio: float):
    """(row pitch, pitch in a row) that keep wavy chains of diameter ``d`` apart (um).

    Two curves whose gap at equal position is at least ``G`` and whose slopes are at most
    ``tan a`` stay ``G / sqrt(1 + tan^2 a)`` apart (parallel chains) or ``G / sqrt(1 + 2 tan^2
    a)`` (crossing chains, each sloping); ``G`` is the pitch less the relative displacement.
    In-plane waviness needs room within a row, out-of-plane waviness between rows and plies.
    """
    _check_corners(waviness, d, chain_length, spacing_ratio)
    tan = waviness.slope(chain_length)
    if waviness.out_of_plane:
        row = d * np.sqrt(1.0 + 2.0 * tan**2) + waviness.relative_displacement(True)
        return float(row), d
    across = d * np.sqrt(1.0 + tan**2) + waviness.relative_displacement(False)
    return d, float(across)


def _check_corners(waviness: Waviness, d: float, chain_length: float, spacing_ratio: float):
    """SpecError unless the polyline's corners are at least a bead spacing apart (um)."""
    segment = chain_length / (waviness.waves * VERTICES_PER_WAVE)
    if segment < spacing_ratio * d:
        most = int(chain_length / (VERTICES_PER_WAVE * spacing_ratio * d))
        raise SpecError(
            "mat.waviness_waves_per_cell",
            waviness.waves,
            f"waves too short for beads {spacing_ratio * d:.4g} um apart: at most {most} per"
            f" cell edge of {chain_length:.4g} um ({VERTICES_PER_WAVE} corners per wave)",
        )


def wavy_chains(
    layout: PlyLayout, direction: PlyDirection, waviness: Waviness, stream: int
) -> tuple[np.ndarray, BeadChain]:
    """Bead centres of a wavy ply, (n_chains, beads per chain, 3), and the chain they all
    translate (its bonds, rest lengths and lengths per bead hold for every chain).

    Rows and positions across are those of :func:`ply_chains`; each chain is the sampled
    polyline of :meth:`Waviness.vertices` over ``direction.chain_length``, shifted along by its
    phase and displaced across (in the plane) or in z (out of the plane).
    """
    chain_length = direction.chain_length
    template = sample_closed_polyline(
        waviness.vertices(chain_length), np.array([chain_length, 0.0, 0.0]), layout.spacing
    )
    across, height = _strip_coordinates(layout, direction.period)
    phases = waviness.phases(layout.n_chains, chain_length, stream)
    along = template.positions[None, :, 0] + phases[:, None]
    shape = np.broadcast_to(template.positions[None, :, 1], along.shape)
    positions = np.empty((*along.shape, 3))
    positions[..., :2] = direction.place(along, np.broadcast_to(across[:, None], along.shape))
    positions[..., 2] = height[:, None]
    if waviness.out_of_plane:
        positions[..., 2] += shape
    else:
        positions[..., :2] += shape[..., None] * direction.across
    return positions, template
