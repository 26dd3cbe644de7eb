"""The homogeneous fibrous mat: straight periodic chains of each ply in sub-rows (pure numpy).

Each ply is a slab of thickness ``t = A / (Vf rho)`` (paper eq. 1). Its chain count ``N`` is the
fibre cross-section of the cell divided by the chain cross-section, rounded; the chain diameter is
then corrected so that ``N pi d^2 / 4`` equals the fibre cross-section exactly (the paper keeps the
fibre volume constant). Chains sit in ``floor(t / d)`` sub-rows spaced at least ``d`` apart; each
row holds ``N // rows`` or one more chains evenly spaced across the periodic width, so rows tile
the period exactly and no two chains overlap.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..spec import SpecError

__all__ = ["PlyLayout", "ply_chains", "ply_layout"]


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
    """

    n_chains: int
    diameter: float
    rows: np.ndarray
    row_z: np.ndarray
    beads_per_chain: int
    spacing: float


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
) -> PlyLayout:
    """Arrange one ply's chains (lengths um, areal weight pg/um^2, density pg/um^3).

    ``chain_length`` is the cell edge along the fibres, ``width`` the edge across them.
    """
    fibre_area = areal_weight / density * width  # fibre cross-section of the cell, um^2
    n_chains = max(1, round(fibre_area / (np.pi * diameter**2 / 4.0)))
    d = float(np.sqrt(4.0 * fibre_area / (np.pi * n_chains)))
    thickness = areal_weight / (fvf * density)
    if thickness < d * (1.0 - 1e-12):
        raise SpecError(
            "discretisation.chain_diameter_um",
            diameter,
            f"chains of {d:.4g} um do not fit the {thickness:.4g} um thick {field_prefix} of the"
            " homogeneous mat (use chains at most as thick as the ply, or a lower mat.initial_fvf)",
        )
    n_rows = int(min(n_chains, max(1, np.floor(thickness / d * (1.0 + 1e-12)))))
    rows = np.full(n_rows, n_chains // n_rows, dtype=np.int64)
    rows[: n_chains % n_rows] += 1
    if width / rows.max() < d * (1.0 - 1e-12):
        raise SpecError(
            "mat.initial_fvf",
            fvf,
            f"too dense for {d:.4g} um chains in {field_prefix}: a sub-row of {rows.max()} chains"
            f" needs {rows.max() * d:.4g} um across {width:.4g} um (lower mat.initial_fvf or"
            " discretisation.chain_diameter_um)",
        )
    row_z = z_bottom + (np.arange(n_rows) + 0.5) * thickness / n_rows
    beads = max(3, round(chain_length / (spacing_ratio * d)))
    return PlyLayout(n_chains, d, rows, row_z, beads, chain_length / beads)


def ply_chains(layout: PlyLayout, along_x: bool, width: float) -> np.ndarray:
    """Bead centres of a ply, shape (n_chains, beads_per_chain, 3), chain by chain.

    Chains run along x (``along_x``) or y; within a row they are evenly spaced across ``width``,
    odd rows shifted by half a pitch. Beads of chain ``c`` start at ``(c mod 2) s / 2`` so that
    neighbouring chains do not put beads side by side.
    """
    row_of_chain = np.repeat(np.arange(len(layout.rows)), layout.rows)
    first_in_row = np.concatenate([[0], np.cumsum(layout.rows)[:-1]])
    slot = np.arange(layout.n_chains) - first_in_row[row_of_chain]
    pitch = width / layout.rows[row_of_chain]
    across = (slot + 0.5 + 0.5 * (row_of_chain % 2)) * pitch % width
    along = (
        np.arange(layout.beads_per_chain)[None, :] + 0.5 * (np.arange(layout.n_chains) % 2)[:, None]
    ) * layout.spacing
    positions = np.empty((layout.n_chains, layout.beads_per_chain, 3))
    axis_along, axis_across = (0, 1) if along_x else (1, 0)
    positions[..., axis_along] = along
    positions[..., axis_across] = across[:, None]
    positions[..., 2] = layout.row_z[row_of_chain][:, None]
    return positions
