"""How many beads a spec's model has, known before anything is allocated (pure arithmetic).

:func:`ply_beads` and :func:`stitch_beads` bound the bead counts of :func:`~ncf2lammps.model.
build_model` from above, from plain numbers (micro units: um, pg/um^2, pg/um^3); they follow the
rounding of :mod:`~ncf2lammps.geometry.mat` and :mod:`~ncf2lammps.geometry.stitch` with every
``round(x)`` taken as ``x + 1/2`` (``x + 1`` where the result is at least 1):

* a ply: ``n <= max(1, F / a0 + 1/2)`` chains (``F`` the cell's fibre cross-section, ``a0`` the
  nominal chain's), each of ``<= max(3, L / (r d) + 1/2)`` beads with ``d`` the smallest
  volume-conserving diameter those chains can have (``L`` cell edge along, ``r`` spacing ratio);
  a wavy chain is at most ``1 + 4 A w / L`` times longer and has one more bead per corner;
* the stitch: per yarn and course one leg across the mat (at most its thickness
  ``sum A / (Vf rho)`` plus the stitch bead diameter and the waviness) and one face segment
  (at most ``sqrt(l^2 + (span g)^2)``), each of ``<= length / (r d) + 1`` bonds.

The bound is never below the real count; over it, straight chains by about
``(1 + 1/(2n))^1.5 (1 + 1/(2b))`` for ``n`` chains of ``b`` beads, the stitch by up to 1.4, wavy
chains by up to 1.5 (tests/test_doors.py: 1.011, 1.106 and 1.028 on the committed hpt310,
hpt310-coarse and mat-only cases; at most 1.15 on straight variants, 1.5 on wavy ones).
:func:`check_model_size` turns it into the one guard of every path: ``build_model`` calls it
first (``check``, ``build``, ``run``, ``export`` all build the model), and ``study`` checks
every point of its grid with it before any point runs.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from ..spec import SpecError
from .bundle import chain_fill
from .direction import spec_ply_direction

__all__ = ["MAX_BEADS", "ModelSize", "check_model_size", "model_size", "ply_beads", "stitch_beads"]

#: Largest model built (about 5 GB of arrays and data file): ten times the million beads that are
#: a normal input. A spec asking for more is refused before any array is allocated.
MAX_BEADS = 10_000_000

#: Polyline corners per wavelength of a wavy chain (:data:`ncf2lammps.geometry.mat.VERTICES_PER_WAVE`).
_CORNERS_PER_WAVE = 16


def ply_beads(
    areal_weight: float,
    density: float,
    chain_length: float,
    across: float,
    diameter: float,
    spacing_ratio: float,
    fill: float = 1.0,
    waviness_amplitude: float = 0.0,
    waves: int = 1,
) -> float:
    """Upper bound on one ply's beads (areal weight pg/um^2, density pg/um^3, lengths um).

    ``chain_length`` is the cell edge along the fibres, ``across`` the edge across them.
    """
    fibre_area = areal_weight / density * across
    nominal = fill * math.pi * diameter**2 / 4.0
    stretch, corners = 1.0, 0
    if waviness_amplitude > 0.0:
        stretch = 1.0 + 4.0 * waviness_amplitude * waves / chain_length
        corners = _CORNERS_PER_WAVE * waves
    chains = max(1.0, fibre_area / nominal + 0.5)
    least = fibre_area / stretch  # the least fibre cross-section the wavy chains carry
    d_low = math.sqrt(4.0 / (math.pi * fill) * least / max(1.0, least / nominal + 0.5))
    per_chain = max(3.0, chain_length / (spacing_ratio * d_low) + 0.5)
    return chains * (stretch * per_chain + corners)


def stitch_beads(
    overlaps: Sequence[tuple[int, int]],
    gauge: float,
    stitch_length: float,
    cell: tuple[float, float],
    mat_thickness: float,
    diameter: float,
    spacing_ratio: float,
) -> float:
    """Upper bound on the stitch yarns' beads (lengths um; ``mat_thickness`` the height the
    legs cross, before the yarn's own diameter is added)."""
    courses = max(1, round(cell[0] / stitch_length))
    wales = max(1, round(cell[1] / gauge))
    needles = [min(a, b) for a, b in overlaps]
    span = max(needles) - min(needles)
    spacing = spacing_ratio * diameter
    leg = mat_thickness + 1.02 * diameter
    face = math.hypot(stitch_length, span * gauge)
    return wales * courses * (leg / spacing + face / spacing + 2.0)


@dataclass(frozen=True)
class ModelSize:
    """The bound and its parts: ``parts`` maps ``"ply[i]"`` / ``"stitch"`` to beads, ``drivers``
    each part to the text of the fields that set it."""

    beads: float
    parts: dict[str, float]
    drivers: dict[str, str]
    mat_thickness: float


def model_size(spec) -> ModelSize:
    """The bead bound of a :class:`~ncf2lammps.spec.FabricSpec` (fields only, no arrays)."""
    length_mm, width_mm = spec.cell_mm
    length, width = length_mm * 1e3, width_mm * 1e3
    disc, mat = spec.discretisation, spec.mat
    waviness = mat.waviness_amplitude_um
    parts: dict[str, float] = {}
    drivers: dict[str, str] = {}
    thickness = 0.0
    cell = f"cell {length_mm:.4g} x {width_mm:.4g} mm"
    for index, ply in enumerate(spec.plies):
        direction = spec_ply_direction(spec, index)
        along, across = direction.chain_length, direction.period
        name = f"ply[{index}]"
        parts[name] = ply_beads(
            ply.areal_weight_g_m2,
            ply.density_g_cm3,
            along,
            across,
            disc.chain_diameter_um,
            disc.bead_spacing_ratio,
            chain_fill(spec),
            waviness,
            mat.waviness_waves_per_cell * direction.edges_crossed,
        )
        drivers[name] = (
            f"areal_weight_g_m2 {ply.areal_weight_g_m2:g}, density_g_cm3 {ply.density_g_cm3:g},"
            f" {cell}, discretisation.chain_diameter_um {disc.chain_diameter_um:g},"
            f" bead_spacing_ratio {disc.bead_spacing_ratio:g}"
        )
        thickness += ply.areal_weight_g_m2 / (mat.initial_fvf * ply.density_g_cm3)
    stitch = spec.stitch
    if stitch is not None:
        rho = stitch.density_g_cm3 * stitch.packing_fraction
        linear = stitch.linear_density_dtex * 100.0  # pg/um
        yarn = stitch.diameter_um or math.sqrt(4.0 * linear / (math.pi * rho))
        d = stitch.contact_diameter_um or yarn  # the beads' diameter (a flattened yarn's)
        parts["stitch"] = stitch_beads(
            stitch.overlaps,
            stitch.gauge_mm * 1e3,
            stitch.stitch_length_mm * 1e3,
            (length, width),
            thickness + 2.0 * waviness,
            d,
            disc.bead_spacing_ratio,
        )
        drivers["stitch"] = (
            f"legs across the {thickness / 1e3:.3g} mm thick mat (sum of areal_weight_g_m2 /"
            f" (mat.initial_fvf {mat.initial_fvf:g} x density_g_cm3)),"
            f" stitch bead diameter {d:.4g} um, stitch_length_mm {stitch.stitch_length_mm:g}, {cell}"
        )
    return ModelSize(sum(parts.values()), parts, drivers, thickness)


def _short(number: float) -> str:
    """``1.4e9`` style: two significant digits."""
    if number < 1e4:
        return f"{number:.0f}"
    mantissa, exponent = f"{number:.1e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def check_model_size(spec, limit: int = MAX_BEADS) -> ModelSize:
    """The :class:`ModelSize` of ``spec``; a one-line SpecError when it exceeds ``limit``."""
    size = model_size(spec)
    if size.beads > limit:
        part = max(size.parts, key=size.parts.__getitem__)
        if part == "stitch" and size.mat_thickness > 1e5:
            advice = "lower ply areal_weight_g_m2 or raise density_g_cm3 / mat.initial_fvf"
        else:
            advice = (
                "raise discretisation.chain_diameter_um or bead_spacing_ratio, or shrink the cell"
            )
        raise SpecError(
            "<model>",
            f"~{_short(size.beads)} beads",
            f"too large ({part} ~{_short(size.parts[part])}: {size.drivers[part]});"
            f" the limit is {limit:,} ({advice})",
        )
    return size
