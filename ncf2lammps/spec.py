"""Fabric and model specification: frozen dataclasses read from a TOML file and validated.

A spec describes one fabric (plies, stitch) and its digital-chain model (discretisation, initial
mat, contact, numerics) in engineering units named in the keys. Every field is checked once, here:
a bad value raises :class:`SpecError` naming the field, the value and the allowed range. Unknown
keys are errors. Each field declares its range, unit and the source of its default in its
field metadata (:func:`_f`).
"""

from __future__ import annotations

import dataclasses
import math
import re
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

__all__ = [
    "HEXAGONAL_PACKING",
    "KINETIC_ERROR_LIMIT",
    "LOADINGS",
    "PATTERNS",
    "RANDOM_JAMMING",
    "SHEAR_SENSES",
    "CellSpec",
    "CompactionSpec",
    "ContactSpec",
    "DiscretisationSpec",
    "FabricSpec",
    "ManufactureSpec",
    "MatSpec",
    "NumericsSpec",
    "OutputSpec",
    "PlySpec",
    "ShearSpec",
    "SpecError",
    "StitchSpec",
    "load_spec",
    "parse_lapping",
    "shear_recipe",
    "spec_from_dict",
]


class SpecError(ValueError):
    """A spec value outside its allowed range; ``str()`` is one line naming field and range."""

    def __init__(self, field_path: str, value: Any, why: str):
        self.field = field_path
        self.value = value
        self.why = why
        message = f"{field_path} = {value!r}: {why}"
        super().__init__(_CONTROL.sub(lambda m: repr(m.group())[1:-1], message))


#: Densest packing of parallel cylinders, pi / (2 sqrt 3): the largest fibre Vf of solid chains.
HEXAGONAL_PACKING = math.pi / (2.0 * math.sqrt(3.0))

#: Characters that would break the one-line message (a key may hold any of them).
_CONTROL = re.compile("[\x00-\x1f\x7f-\x9f\u2028\u2029]")


#: Senses of a picture-frame shear (docs/shear.md): positive lengthens the frame diagonal
#: nearest the machine direction x, negative shortens it.
SHEAR_SENSES = ("positive", "negative")
#: How a test scene's loading rate is set (docs/loading.md).
LOADINGS = ("adaptive", "constant")
#: Largest error the beads' kinetic stress (2 K / 3 V) may cause on a quasi-static test's
#: output: 1 % (docs/design.md §8, docs/loading.md).
KINETIC_ERROR_LIMIT = 1e-2
#: Two frame directions (deg) closer than this are one (mirror images, the fibres of 0/90).
FRAME_TOLERANCE_DEG = 1e-6


def shear_recipe(frame: tuple[float, float]) -> str | None:
    """The picture-frame recipe of a frame of two fibre directions (deg), or None.

    ``"tilt"`` for 0/90 (edge a along x, edge b turns: the box tilts); ``"stretch"`` for two
    directions mirror images about x (+phi0, -phi0 with 0 < phi0 < 90: the box stays
    orthogonal and stretches along one axis while it shortens along the other).
    """
    low, high = sorted(frame)
    if abs(low) < FRAME_TOLERANCE_DEG and abs(high - 90.0) < FRAME_TOLERANCE_DEG:
        return "tilt"
    if (
        abs(low + high) < FRAME_TOLERANCE_DEG
        and FRAME_TOLERANCE_DEG < high < 90.0 - FRAME_TOLERANCE_DEG
    ):
        return "stretch"
    return None


#: Lapping notation of the named stitch patterns (guide-bar gap positions, one overlap per course).
#: See docs/stitch.md for the convention and the choice of the tricot-chain sequence.
PATTERNS: dict[str, str] = {
    "chain": "0-1/1-0",
    "pillar": "0-1/1-0",
    "tricot": "1-0/1-2",
    "tricot-chain": "1-0/0-1/1-2/2-1",
}

_LAP = re.compile(r"^\s*(\d+)\s*-\s*(\d+)\s*$")


def parse_lapping(notation: str, field_path: str = "stitch.lapping") -> tuple[tuple[int, int], ...]:
    """Parse warp-knitting lapping notation ``"1-0/1-2"`` into overlaps ``((1, 0), (1, 2))``.

    Each course is ``a-b``: the guide swings across one needle from gap ``a`` to gap ``b``
    (``|a - b| == 1``). Raises :class:`SpecError` on anything else.
    """
    courses = notation.split("/")
    overlaps = []
    for course in courses:
        match = _LAP.match(course)
        if match is None:
            raise SpecError(field_path, notation, "courses must read 'a-b' separated by '/'")
        a, b = int(match.group(1)), int(match.group(2))
        if abs(a - b) != 1:
            raise SpecError(
                field_path, notation, f"overlap '{course.strip()}' must span one needle (|a-b| = 1)"
            )
        overlaps.append((a, b))
    if not 1 <= len(overlaps) <= 64:
        raise SpecError(field_path, notation, "needs 1 to 64 courses")
    return tuple(overlaps)


#: Range texts of material fields (the ``source=`` of their declarations).
_FIBRE_DENSITIES = "engineering fibres span PP 0.91 and PE 0.97 to steel 7.9 g/cm3"
_STIFFEST = "diamond, the stiffest solid (E ~1.05-1.2 TPa)"
_FIBRE_MODULI = f"PP/PA fibres (~1-5 GPa) to pitch carbon (~900 GPa), below {_STIFFEST}"


def _f(
    default,
    lo=None,
    hi=None,
    *,
    lo_open=False,
    hi_open=False,
    unit="",
    source="",
    choices=None,
    item=None,
):
    """Dataclass field with its allowed range, unit and the source of its default.

    A list field has a tuple default and ``item``, the default of one element: each element is
    checked against the range or ``choices`` like a field of that default."""
    meta = {
        "item": item,
        "lo": lo,
        "hi": hi,
        "lo_open": lo_open,
        "hi_open": hi_open,
        "unit": unit,
        "source": source,
        "choices": choices,
    }
    return field(default=default, metadata=meta)


@dataclass(frozen=True)
class PlySpec:
    """One unidirectional ply of fibre chains at an angle from x (0 deg along x, 90 deg along y)."""

    angle_deg: float = _f(
        0.0,
        -90.0,
        90.0,
        lo_open=True,
        unit="deg",
        source="fibre angle from the machine direction x; realised as the nearest closing"
        " direction within mat.angle_tolerance_deg (docs/manufacture.md)",
    )
    areal_weight_g_m2: float = _f(
        150.0,
        1.0,
        5000.0,
        unit="g/m2",
        source="HPT 310 datasheet-typical 2 x 150; NCF plies weigh some 50 to 2000 g/m2",
    )
    density_g_cm3: float = _f(
        1.80, 0.8, 8.0, unit="g/cm3", source=f"carbon, paper; range: {_FIBRE_DENSITIES}"
    )
    E_GPa: float = _f(
        240.0, 0.5, 1200.0, unit="GPa", source=f"carbon HT, typical; range: {_FIBRE_MODULI}"
    )
    filament_diameter_um: float = _f(
        7.0, 1.0, 50.0, unit="um", source="carbon HT filament (T700S, HTS40: 7 um); bending only"
    )


@dataclass(frozen=True)
class StitchSpec:
    """The stitch yarn: lapping, machine gauge and stitch length, yarn material."""

    pattern: str = _f("tricot-chain", choices=(*PATTERNS, "custom"), source="paper")
    lapping: str = _f("", source="empty: the pattern's notation (docs/stitch.md)")
    gauge_mm: float = _f(
        5.08,
        0.5,
        25.4,
        unit="mm",
        source="paper (E5); range: machine gauges E1 to E50 (25.4 / E mm needle spacing)",
    )
    stitch_length_mm: float = _f(2.8, 0.2, 20.0, unit="mm", source="paper")
    linear_density_dtex: float = _f(
        76.0,
        1.0,
        10000.0,
        unit="dtex",
        source="PES, typical NCF; range: one filament (1 dtex) to a 1 g/m heavy yarn",
    )
    density_g_cm3: float = _f(
        1.38, 0.8, 8.0, unit="g/cm3", source=f"PES; range: {_FIBRE_DENSITIES}"
    )
    E_GPa: float = _f(
        12.0,
        0.01,
        1200.0,
        unit="GPa",
        source="PES yarn 10-15 GPa, typical; the secant modulus to break of medium-tenacity"
        " polyester is 4.3 GPa (0.47 N/tex x 1.38 g/cm3 / 0.15, Morton & Hearle, Physical"
        " Properties of Textile Fibres, Table 13.2); a textured yarn's crimp extends first at"
        f" lower modulus (no source: study it); range: soft yarns (0.01 GPa) to {_STIFFEST}",
    )
    diameter_um: float | None = _f(
        None, 1.0, 2000.0, unit="um", source="None: from dtex, density and packing_fraction"
    )
    packing_fraction: float = _f(
        1.0, 0.3, 1.0, unit="-", source="1: solid yarn (paper); multifilament PES ~0.5-0.8"
    )
    contact_diameter_um: float | None = _f(
        None,
        1.0,
        2000.0,
        unit="um",
        source="None: the yarn's diameter (a round yarn, the paper); a multifilament yarn pressed"
        " between tows or plates flattens into a ribbon a few filaments thick, by an amount no"
        " source gives for this yarn: study it between a few filament diameters and the yarn's"
        " diameter (docs/fidelity.md)",
    )
    needle_diameter_mm: float = _f(
        1.0, 0.01, 10.0, unit="mm", source="E5 stitch-bonding compound needle, estimate"
    )
    interlock: str = _f(
        "none",
        choices=("none", "held", "sliding"),
        source="none: the paper's free idealised yarn; held: each needle's loops joined along"
        " the wale on the loop face, as a knitted loop is drawn through the loop of the course"
        " before (D. J. Spencer, Knitting Technology, 3rd ed., 2001: warp-knitted loops), and"
        " the pretension shortens only legs and underlaps; sliding: the same, each link ending"
        " in a ring the next course's yarn slips through with friction (docs/stitch.md)",
    )
    rupture: bool = _f(False, source="false: the paper's unbreakable stitch (docs/stitch.md)")
    rupture_criterion: str = _f(
        "force",
        choices=("force", "strain"),
        source="force: the yarn's breaking load, what a linear bond can match (docs/stitch.md)",
    )
    tenacity_cN_dtex: float = _f(
        4.7,
        0.01,
        50.0,
        unit="cN/dtex",
        source="medium-tenacity polyester, 0.47 N/tex (Morton & Hearle, Physical Properties of"
        " Textile Fibres, Table 13.2); high-tenacity 0.56 N/tex; range: soft yarns to UHMWPE"
        " (~40 cN/dtex)",
    )
    elongation_at_break: float = _f(
        0.15,
        0.001,
        10.0,
        unit="-",
        source="medium-tenacity polyester, 15 % (Morton & Hearle, Physical Properties of Textile"
        " Fibres, Table 13.2); high-tenacity 7 %; range: to elastane (~7)",
    )

    @property
    def overlaps(self) -> tuple[tuple[int, int], ...]:
        """Overlaps ``(a, b)`` of one repeat, parsed from :attr:`notation`."""
        return parse_lapping(self.notation)

    @property
    def courses_per_repeat(self) -> int:
        """Courses of the smallest cell: the lapping repeat, doubled if odd (the idealised yarn
        alternates faces at each hole and closes only after an even number of holes)."""
        n = len(self.overlaps)
        return n if n % 2 == 0 else 2 * n

    @property
    def notation(self) -> str:
        """The lapping notation in force: :attr:`lapping` if given, else the pattern's."""
        return self.lapping or PATTERNS[self.pattern]


@dataclass(frozen=True)
class CellSpec:
    """Periodic cell size; with a stitch it defaults to the stitch repeat."""

    length_mm: float | None = _f(None, 0.05, 500.0, unit="mm", source="None: stitch repeat")
    width_mm: float | None = _f(None, 0.05, 500.0, unit="mm", source="None: stitch gauge")


@dataclass(frozen=True)
class DiscretisationSpec:
    """Chain diameter (before the volume-conserving correction per ply) and bead spacing."""

    chain_diameter_um: float = _f(69.0, 1.0, 5000.0, unit="um", source="paper reference model")
    bead_spacing_ratio: float = _f(
        0.5, 0.2, 1.0, unit="s/d", source="docs/design.md §5: roughness 0.134 R"
    )
    chain_internal_fvf: float = _f(
        1.0,
        0.5,
        1.0,
        unit="-",
        source="1: solid chains (paper); bundles <= 0.907 (docs/fidelity.md)",
    )
    bending: str = _f(
        "none", choices=("none", "harmonic", "cosine"), source="none: free pins (paper)"
    )


@dataclass(frozen=True)
class MatSpec:
    """The homogeneous fibrous mat before stitching."""

    initial_fvf: float = _f(0.30, 0.01, 0.785, unit="-", source="paper, eq. (1)")
    waviness_amplitude_um: float = _f(
        0.0, 0.0, 5000.0, unit="um", source="0: straight chains (paper); docs/fidelity.md"
    )
    waviness_waves_per_cell: int = _f(
        1, 1, 1000, unit="-", source="whole waves along each chain's cell edge (periodic)"
    )
    waviness_plane: str = _f(
        "in-plane", choices=("in-plane", "out-of-plane"), source="direction of the waviness"
    )
    waviness_phase_spread_deg: float = _f(
        360.0, 0.0, 360.0, unit="deg", source="chain phases uniform in [0, spread): 0 in phase"
    )
    seed: int = _f(
        1, 0, 2**31 - 1, unit="-", source="random phases of the waviness and the random bed"
    )
    arrangement: str = _f(
        "rows",
        choices=("rows", "random"),
        source="rows: aligned sub-rows (paper); random: seeded random bed (docs/fidelity.md)",
    )
    diameter_spread: float = _f(
        0.0,
        0.0,
        0.3,
        unit="-",
        source="0: one chain diameter per ply (paper); relative std of the chain diameters"
        " (random only)",
    )
    pushoff_overlap_tolerance: float = _f(
        0.02,
        1e-3,
        0.5,
        unit="d",
        source="largest fibre-fibre overlap after the push-off, fraction of the smallest chain"
        " diameter (random only); model choice, below the 0.05 d of the insertion check",
    )
    max_pushoff_steps: int = _f(
        200_000, 1, 10**10, unit="steps", source="safety cap of the push-off (random only)"
    )
    angle_tolerance_deg: float = _f(
        0.25,
        1e-3,
        5.0,
        unit="deg",
        source="largest |realised - requested| ply angle; model choice, below the ~1 deg"
        " scatter of fibre angles in NCF plies",
    )


@dataclass(frozen=True)
class ContactSpec:
    """Chain-chain contact: Coulomb friction and the normal law (``pair_style granular``)."""

    friction: float = _f(0.30, 0.0, 2.0, unit="-", source="paper")
    fibre_stitch_friction: float | None = _f(
        None, 0.0, 2.0, unit="-", source="None: friction; carbon-PES data in docs/fidelity.md"
    )
    normal_model: str = _f(
        "hooke",
        choices=("hooke", "hertz", "bundle"),
        source="model choice; bundle: the fibre-bed law on a Hertz contact (docs/contact.md)",
    )
    normal_stiffness_N_m: float = _f(
        1.0e6, 1.0, 1.0e9, unit="N/m", source="docs/contact.md: below the stitch bond's EA/s"
    )
    contact_modulus_GPa: float = _f(
        1.0,
        1e-4,
        200.0,
        unit="GPa",
        source="transverse bundle modulus, model choice (hertz); range: up to steel on steel,"
        " E* = E / (2 (1 - nu^2)) ~ 115 GPa (Johnson, Contact Mechanics, 1985)",
    )
    bundle_free_fvf: float = _f(
        0.50,
        0.2,
        0.75,
        unit="-",
        source="V0 of the bundle law: Gutowski et al., J. Compos. Mater. 21 (1987) 172, carbon",
    )
    bundle_max_fvf: float = _f(
        0.785,
        0.6,
        0.907,
        unit="-",
        source="Va of the bundle law: pi/4, square packing (Gutowski et al. 1987); 0.785-0.83"
        " reported, up to hexagonal 0.907",
    )
    bundle_waviness_ratio: float = _f(
        350.0,
        50.0,
        2000.0,
        unit="-",
        source="beta (filament span / amplitude) of the bundle law: Gutowski et al. 1987;"
        " 225-350 reported for carbon",
    )
    damping_ratio: float = _f(
        0.3,
        0.0,
        1.0,
        unit="-",
        source="fraction of critical, per contact, numerical (hooke: of the lightest"
        " pair at k_n, hertz and bundle: of every pair at its current stiffness)",
    )
    tangential_stiffness_ratio: float = _f(
        2.0 / 7.0, 0.01, 1.0, unit="kt/kn", source="LAMMPS gran/hooke/history default 2/7"
    )


@dataclass(frozen=True)
class NumericsSpec:
    """Time step, mass scaling and neighbour settings shared by every scene."""

    dt_fraction: float = _f(
        0.5, 0.0, 2.0, lo_open=True, unit="sqrt(m/k)", source="docs/design.md §8"
    )
    allow_unstable_dt: bool = _f(False, source="refuse dt above the stability limit")
    mass_scaling: float = _f(1.0, 1.0, 1e6, unit="-", source="docs/performance.md")
    fibre_stiffness_scaling: float = _f(1.0, 1e-4, 1.0, unit="-", source="docs/performance.md")
    stitch_mass_scaling: float = _f(
        1.0,
        1.0,
        1e4,
        unit="-",
        source="mass scaling of the beads below a target step (Abaqus/Explicit); docs/performance.md",
    )
    neighbor_skin_um: float | None = _f(None, 0.01, 1e4, unit="um", source="None: d/10, >= 1 um")
    thermo_every: int = _f(1000, 1, 10**9, unit="steps", source="output cadence")
    perturbation_seed: int = _f(
        0,
        0,
        2**31 - 1,
        unit="-",
        source="0: none (the paper's model). A replica of the same run: each scene starts by"
        " displacing every bead by a seeded random vector of 1e-6 bead diameters, so that"
        " replicas measure the trajectories' scatter (docs/study.md)",
    )
    guard_every: int = _f(100, 1, 10**9, unit="steps", source="stability guard cadence")


@dataclass(frozen=True)
class ManufactureSpec:
    """Manufacture scene: needle step, stitch insertion, pretension ramp, relaxation."""

    needle_speed_m_s: float = _f(10.0, 0.01, 100.0, unit="m/s", source="opening speed, model")
    stitch_tension_N: float = _f(0.10, 1e-4, 50.0, unit="N", source="docs/manufacture.md")
    pretension_strain_rate_per_us: float = _f(
        2e-3, 1e-8, 1e-1, unit="1/us", source="docs/manufacture.md"
    )
    control_time_us: float = _f(20.0, 0.01, 1e6, unit="us", source="tension controller, model")
    damping_time_us: float = _f(50.0, 0.01, 1e6, unit="us", source="docs/manufacture.md")
    relaxation_damping_time_us: float | None = _f(
        None, 0.01, 1e6, unit="us", source="None: damping_time_us; docs/manufacture.md"
    )
    stitch_damping_time_us: float | None = _f(
        None, 0.01, 1e6, unit="us", source="None: damping_time_us; docs/manufacture.md"
    )
    tension_tolerance: float = _f(
        0.01,
        1e-4,
        0.2,
        unit="-",
        source="convergence tolerance: the stitch tension within 1 % of its target",
    )
    kinetic_ratio_target: float = _f(
        1e-3,
        1e-9,
        0.5,
        unit="-",
        source="kinetic energy / pretension work; docs/manufacture.md: 1e-3 since the cell creeps",
    )
    stitch_creep_target_per_ms: float | None = _f(
        None,
        1e-6,
        1e3,
        unit="1/ms",
        source="None: no creep criterion (the paper's model). The relaxation also waits until the"
        " stitch's creep, the tension it would lose per ms with the controller off (EA x the"
        " controller's mean strain rate / tension), is below this; docs/manufacture.md",
    )
    creep_window_us: float = _f(
        1000.0,
        1.0,
        1e7,
        unit="us",
        source="averaging window of the creep rate, read only with stitch_creep_target_per_ms:"
        " 50 control times, long against the controller's response (docs/manufacture.md)",
    )
    needle_plane_hold: bool = _f(
        False,
        source="false: the paper's needle stage, free in z; true: the fibre beads keep their z"
        " while the needles part them (fix setforce), as the web lies on the machine's bed: model"
        " choice against the compressed chains' buckling (docs/manufacture.md)",
    )
    max_ramp_steps: int = _f(2_000_000, 1, 10**10, unit="steps", source="safety cap")
    max_relax_steps: int = _f(2_000_000, 1, 10**10, unit="steps", source="safety cap")
    insertion_overlap_tolerance: float = _f(
        0.05, 0.0, 0.5, unit="d", source="largest stitch-fibre overlap at insertion"
    )


def _max_rate_factor():
    """``max_rate_factor`` of a test scene's adaptive loading (compaction, shear)."""
    return _f(16.0, 1.0, 1e4, unit="x inertial-number rate", source="docs/loading.md: the fastest")


def _kinetic_stress_target():
    """``kinetic_stress_target`` of a test scene's adaptive loading (compaction, shear)."""
    return _f(
        KINETIC_ERROR_LIMIT / 4.0,
        1e-6,
        1.0,
        unit="-",
        source="kinetic stress ratio above which adaptive loading brakes: a quarter of the 1 %"
        " limit, so that a burst within one interval stays below it; 1 never brakes before the"
        " kinetic stress equals the stress (docs/loading.md)",
    )


@dataclass(frozen=True)
class CompactionSpec:
    """Compaction scene: plates closing, at a speed the loading adapts to the cell by default
    (docs/loading.md), until the pressure first exceeds ``max_pressure_kPa`` (``end =
    "max_pressure"``) or down to the gap of ``final_fvf``."""

    end: str = _f(
        "max_pressure",
        choices=("max_pressure", "final_fvf"),
        source="max_pressure: past the experiment's 18 kPa; final_fvf: the paper's Fig. 5c end",
    )
    final_fvf: float = _f(0.67, 0.05, 0.9, unit="-", source="paper Fig. 5c")
    plate_speed_m_s: float | None = _f(
        None, 1e-6, 100.0, unit="m/s", source="None: from inertial_number"
    )
    inertial_number: float = _f(
        0.05,
        1e-5,
        1.0,
        unit="-",
        source="docs/compaction.md; adaptive loading holds it at the plate pressure",
    )
    max_pressure_kPa: float = _f(
        100.0,
        20.0,
        1e7,
        unit="kPa",
        source="5.6 x the 18 kPa reported: the smoothed curve and b see past it (docs/compaction.md)",
    )
    reference_pressure_kPa: float = _f(1.0, 1e-3, 1e4, unit="kPa", source="DIN ISO 5084")
    loading: str = _f(
        "adaptive", choices=LOADINGS, source="docs/loading.md: rate follows the measured stress"
    )
    max_rate_factor: float = _max_rate_factor()
    kinetic_stress_target: float = _kinetic_stress_target()
    record_every_um: float = _f(1.0, 1e-3, 1e3, unit="um", source="gap resolution of the curve")


@dataclass(frozen=True)
class ShearSpec:
    """Picture-frame shear scene by tilting the periodic box."""

    final_angle_deg: float = _f(45.0, 1.0, 60.0, unit="deg", source="paper Fig. 6")
    shear_rate_deg_us: float | None = _f(
        None, 1e-9, 1.0, unit="deg/us", source="None: from inertial_number"
    )
    inertial_number: float = _f(
        0.025,
        1e-5,
        1.0,
        unit="-",
        source="docs/shear.md; adaptive loading holds it at the shear stress |F_N| / thickness",
    )
    loading: str = _f(
        "constant",
        choices=LOADINGS,
        source="docs/loading.md: on the coarse HPT 310 cell adaptive shear moved F_N(45) by"
        " -15 to +14 %",
    )
    max_rate_factor: float = _max_rate_factor()
    kinetic_stress_target: float = _kinetic_stress_target()
    fibre_pretension_N_m: float = _f(
        0.0, 0.0, 1000.0, unit="N/m", source="per unit width of each ply; paper frame: 22"
    )
    frame_deg: tuple[float, ...] = _f(
        (),
        -90.0,
        90.0,
        lo_open=True,
        item=0.0,
        unit="deg",
        source="the frame's edges follow two ply directions (Boisse et al., Int. J. Mater."
        " Form. 10, 2017); empty: the first pair of ply angles with a recipe",
    )
    senses: tuple[str, ...] = _f(
        ("positive",),
        item="positive",
        choices=SHEAR_SENSES,
        source="positive: the frame diagonal nearest x lengthens (docs/shear.md)",
    )

    def frame(self, plies: tuple[PlySpec, ...]) -> tuple[float, float]:
        """The two fibre directions (deg, requested ply angles) the frame's edges follow:
        ``frame_deg``, else the first pair of distinct ply angles, in ply order, that has a
        recipe (:func:`shear_recipe`; 0/45/90/-45: 0 and 90), else the first two distinct ply
        angles, else (one direction) 0 and 90."""
        if self.frame_deg:
            return self.frame_deg[0], self.frame_deg[1]
        distinct = list(dict.fromkeys(p.angle_deg for p in plies))
        if len(distinct) < 2:
            return 0.0, 90.0
        pairs = [(a, b) for i, a in enumerate(distinct) for b in distinct[i + 1 :]]
        return next((pair for pair in pairs if shear_recipe(pair) is not None), pairs[0])


@dataclass(frozen=True)
class OutputSpec:
    """Checkpoints and trajectory dumps of every scene (docs/hpc.md); 0 turns one off."""

    checkpoint_every_steps: int = _f(
        100_000, 0, 10**10, unit="steps", source="docs/hpc.md: rounded up to the record cadence"
    )
    dump_every_steps: int = _f(50_000, 0, 10**10, unit="steps", source="docs/hpc.md")


_TABLES: dict[str, type] = {
    "stitch": StitchSpec,
    "cell": CellSpec,
    "discretisation": DiscretisationSpec,
    "mat": MatSpec,
    "contact": ContactSpec,
    "numerics": NumericsSpec,
    "manufacture": ManufactureSpec,
    "compaction": CompactionSpec,
    "shear": ShearSpec,
    "output": OutputSpec,
}


@dataclass(frozen=True)
class FabricSpec:
    """A fabric and its model. Build with :func:`load_spec` or :func:`spec_from_dict`."""

    name: str
    plies: tuple[PlySpec, ...]
    stitch: StitchSpec | None
    cell: CellSpec = CellSpec()
    discretisation: DiscretisationSpec = DiscretisationSpec()
    mat: MatSpec = MatSpec()
    contact: ContactSpec = ContactSpec()
    numerics: NumericsSpec = NumericsSpec()
    manufacture: ManufactureSpec = ManufactureSpec()
    compaction: CompactionSpec = CompactionSpec()
    shear: ShearSpec = ShearSpec()
    output: OutputSpec = OutputSpec()

    @property
    def cell_mm(self) -> tuple[float, float]:
        """Cell length (x, machine direction) and width (y) in mm."""
        length, width = self.cell.length_mm, self.cell.width_mm
        if self.stitch is not None:
            repeat_x = self.stitch.courses_per_repeat * self.stitch.stitch_length_mm
            repeat_y = self.stitch.gauge_mm
            length = repeat_x if length is None else length
            width = repeat_y if width is None else width
        return float(length), float(width)

    def replace(self, **changes) -> FabricSpec:
        """A copy with some top-level tables replaced, validated again.

        ``spec.replace(discretisation={"chain_diameter_um": 120})`` merges dicts into tables.
        """
        data = self.to_dict()
        for key, value in changes.items():
            if isinstance(value, dict) and isinstance(data.get(key), dict):
                data[key] = {**data[key], **value}
            else:
                data[key] = value
        return spec_from_dict(data)

    def to_dict(self) -> dict[str, Any]:
        """Plain dict (TOML layout) of every field, with ``None`` values left out."""
        out: dict[str, Any] = {"fabric": {"name": self.name}}
        out["ply"] = [_table_dict(p) for p in self.plies]
        if self.stitch is not None:
            out["stitch"] = _table_dict(self.stitch)
        for key in _TABLES:
            if key != "stitch":
                out[key] = _table_dict(getattr(self, key))
        return out


def _table_dict(obj) -> dict[str, Any]:
    return {f.name: getattr(obj, f.name) for f in fields(obj) if getattr(obj, f.name) is not None}


def _check_value(path: str, f: dataclasses.Field, value: Any) -> Any:
    if isinstance(f.default, tuple):
        if not isinstance(value, list | tuple) or len(value) > 8:
            raise SpecError(path, value, "must be a list of at most 8 items")
        item = f.metadata["item"]
        return tuple(
            _check_scalar(f"{path}[{i}]", f.metadata, item, v) for i, v in enumerate(value)
        )
    return _check_scalar(path, f.metadata, f.default, value)


def _check_scalar(path: str, meta, default, value: Any) -> Any:
    if value is None:
        if default is None:
            return None
        raise SpecError(path, value, "must be given")
    if isinstance(default, bool):
        if not isinstance(value, bool):
            raise SpecError(path, value, "must be true or false")
        return value
    if isinstance(default, str):
        choices = f"one of {', '.join(meta['choices'])}" if meta["choices"] else ""
        if not isinstance(value, str):
            raise SpecError(path, value, "must be a string" + (f": {choices}" if choices else ""))
        if choices and value not in meta["choices"]:
            raise SpecError(path, value, f"must be {choices}")
        if len(value) > 200:
            raise SpecError(path, value, "must be at most 200 characters")
        return value
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise SpecError(path, value, f"must be a number{_range_text(meta)}")
    if isinstance(default, int) and not isinstance(value, int):
        if not float(value).is_integer():
            raise SpecError(path, value, f"must be a whole number{_range_text(meta)}")
    number = int(value) if isinstance(default, int) else float(value)
    if not math.isfinite(number):
        raise SpecError(path, value, f"must be finite{_range_text(meta)}")
    if meta["choices"] is not None:
        if number not in meta["choices"]:
            allowed = " or ".join(f"{c:g}" for c in meta["choices"])
            raise SpecError(path, value, f"must be {allowed} {meta['unit']}".rstrip())
        return number
    lo, hi = meta["lo"], meta["hi"]
    too_low = lo is not None and (number <= lo if meta["lo_open"] else number < lo)
    too_high = hi is not None and (number >= hi if meta["hi_open"] else number > hi)
    if too_low or too_high:
        raise SpecError(path, value, f"out of range: allowed{_range_text(meta)}")
    return number


def _range_text(meta) -> str:
    lo, hi = meta["lo"], meta["hi"]
    if lo is None and hi is None:
        return ""
    left = "(" if meta["lo_open"] else "["
    right = ")" if meta["hi_open"] else "]"
    unit = f" {meta['unit']}" if meta["unit"] not in (None, "", "-") else ""
    return f" {left}{_bound_text(lo)}, {_bound_text(hi)}{right}{unit}"


def _bound_text(bound: float) -> str:
    """A range bound as written: whole numbers to every digit, others in ``%g``."""
    return str(bound) if isinstance(bound, int) else f"{bound:g}"


def _build(cls: type, table: Any, path: str):
    if not isinstance(table, dict):
        raise SpecError(path, table, "must be a table")
    known = {f.name: f for f in fields(cls)}
    for key in table:
        if key not in known:
            raise SpecError(f"{path}.{key}", table[key], f"unknown key (known: {', '.join(known)})")
    values = {}
    for name, f in known.items():
        if name in table:
            values[name] = _check_value(f"{path}.{name}", f, table[name])
    return cls(**values)


def spec_from_dict(data: dict[str, Any]) -> FabricSpec:
    """Validate a TOML-layout dict and build a :class:`FabricSpec` (raises :class:`SpecError`)."""
    if not isinstance(data, dict):
        raise SpecError("<spec>", type(data).__name__, "must be a TOML table")
    allowed = {"fabric", "ply", *_TABLES}
    for key in data:
        if key not in allowed:
            raise SpecError(key, "...", f"unknown table (known: {', '.join(sorted(allowed))})")
    fabric = data.get("fabric", {})
    if not isinstance(fabric, dict) or set(fabric) - {"name"}:
        raise SpecError("fabric", fabric, "must be a table with only the key 'name'")
    name = fabric.get("name", "fabric")
    if not isinstance(name, str) or not 0 < len(name) <= 200:
        raise SpecError("fabric.name", name, "must be a string of 1 to 200 characters")
    plies_data = data.get("ply")
    if not isinstance(plies_data, list) or not 1 <= len(plies_data) <= 8:
        raise SpecError("ply", plies_data, "needs 1 to 8 [[ply]] tables")
    plies = tuple(_build(PlySpec, p, f"ply[{i}]") for i, p in enumerate(plies_data))
    tables = {k: _build(cls, data[k], k) for k, cls in _TABLES.items() if k in data}
    stitch = tables.pop("stitch", None)
    spec = FabricSpec(name=name, plies=plies, stitch=stitch, **tables)
    _check_consistency(spec)
    return spec


def _check_consistency(spec: FabricSpec) -> None:
    """Checks across fields that a single range cannot express."""
    stitch = spec.stitch
    if stitch is not None:
        if stitch.pattern == "custom" and not stitch.lapping:
            raise SpecError("stitch.lapping", "", "must be given when stitch.pattern = 'custom'")
        if stitch.lapping and stitch.pattern != "custom":
            raise SpecError(
                "stitch.lapping", stitch.lapping, "is only read with stitch.pattern = 'custom'"
            )
        stitch.overlaps  # noqa: B018 - parses and validates the notation
        if stitch.diameter_um is not None and stitch.packing_fraction != 1.0:
            raise SpecError(
                "stitch.packing_fraction",
                stitch.packing_fraction,
                "is only read with stitch.diameter_um unset (the diameter follows from it)",
            )
        _check_rupture(stitch)
        repeat = (stitch.courses_per_repeat * stitch.stitch_length_mm, stitch.gauge_mm)
        for key, size, unit_len in zip(
            ("cell.length_mm", "cell.width_mm"),
            (spec.cell.length_mm, spec.cell.width_mm),
            repeat,
            strict=True,
        ):
            if size is not None and abs(size / unit_len - round(size / unit_len)) > 1e-6:
                raise SpecError(
                    key, size, f"must be a whole multiple of the repeat {unit_len:g} mm"
                )
            if size is not None and round(size / unit_len) < 1:
                raise SpecError(key, size, f"must be at least the repeat {unit_len:g} mm")
    elif spec.cell.length_mm is None or spec.cell.width_mm is None:
        raise SpecError("cell", "missing", "length_mm and width_mm are required without [stitch]")
    if stitch is None and spec.contact.fibre_stitch_friction is not None:
        raise SpecError(
            "contact.fibre_stitch_friction",
            spec.contact.fibre_stitch_friction,
            "is only read with a [stitch] table",
        )
    if spec.discretisation.bending == "cosine" and spec.mat.waviness_amplitude_um > 0.0:
        raise SpecError(
            "discretisation.bending",
            "cosine",
            "rests at 180 deg only: use 'harmonic' with mat.waviness_amplitude_um > 0",
        )
    manufacture = spec.manufacture
    if manufacture.stitch_creep_target_per_ms is None:
        _only_read_with(
            "manufacture",
            manufacture,
            ("creep_window_us",),
            "manufacture.stitch_creep_target_per_ms set",
        )
    for table in ("compaction", "shear"):
        settings = getattr(spec, table)
        if settings.loading == "constant":
            _only_read_with(
                table,
                settings,
                ("max_rate_factor", "kinetic_stress_target"),
                f"{table}.loading = 'adaptive'",
            )
    _check_bundle(spec)
    _check_random_bed(spec)
    _check_shear(spec)
    internal, source = spec.discretisation.chain_internal_fvf, "discretisation.chain_internal_fvf"
    if spec.contact.normal_model == "bundle":
        internal, source = spec.contact.bundle_max_fvf, "contact.bundle_max_fvf"
    densest = internal * HEXAGONAL_PACKING
    if spec.compaction.final_fvf > densest:
        raise SpecError(
            "compaction.final_fvf",
            spec.compaction.final_fvf,
            f"out of range: chains of internal Vf {internal:g} ({source}) reach at most"
            f" {densest:.3f} (hexagonal packing); allowed [0.05, {densest:.3f}]",
        )
    length, width = spec.cell_mm
    d_mm = spec.discretisation.chain_diameter_um * 1e-3
    if min(length, width) < 2.0 * d_mm:
        raise SpecError(
            "discretisation.chain_diameter_um",
            spec.discretisation.chain_diameter_um,
            f"must be at most half the cell edge ({min(length, width) * 500:g} um)",
        )


#: The rupture keys and the criterion (None: any) under which each is read.
_RUPTURE_KEYS = {
    "rupture_criterion": None,
    "tenacity_cN_dtex": "force",
    "elongation_at_break": "strain",
}


def _only_read_with(table: str, settings, keys: tuple[str, ...], condition: str) -> None:
    """SpecError on the first of ``keys`` that ``settings`` (the ``[table]`` dataclass) sets
    away from its default: that key is only read with ``condition``."""
    defaults = type(settings)()
    for key in keys:
        value = getattr(settings, key)
        if value != getattr(defaults, key):
            raise SpecError(f"{table}.{key}", value, f"is only read with {condition}")


def _check_rupture(stitch: StitchSpec) -> None:
    """The rupture keys are read only with ``stitch.rupture = true``, each under its criterion."""
    for key, criterion in _RUPTURE_KEYS.items():
        if not stitch.rupture:
            condition = "stitch.rupture = true"
        elif criterion not in (None, stitch.rupture_criterion):
            condition = f"stitch.rupture_criterion = '{criterion}'"
        else:
            continue
        _only_read_with("stitch", stitch, (key,), condition)


def _check_bundle(spec: FabricSpec) -> None:
    """The bundle law's keys against the rest: one fibre, free below packed, chains not filled."""
    contact = spec.contact
    if contact.normal_model != "bundle":
        return
    if contact.bundle_free_fvf >= contact.bundle_max_fvf:
        raise SpecError(
            "contact.bundle_free_fvf",
            contact.bundle_free_fvf,
            f"must be below contact.bundle_max_fvf = {contact.bundle_max_fvf:g}",
        )
    if spec.discretisation.chain_internal_fvf != 1.0:
        raise SpecError(
            "discretisation.chain_internal_fvf",
            spec.discretisation.chain_internal_fvf,
            "is not read with contact.normal_model = 'bundle' (the bundle law sets the chains'"
            " internal Vf): leave it at 1",
        )
    moduli = {p.E_GPa for p in spec.plies}
    if len(moduli) > 1:
        raise SpecError(
            "ply.E_GPa",
            sorted(moduli),
            "must be one value for contact.normal_model = 'bundle' (one law for every contact)",
        )


def _check_shear(spec: FabricSpec) -> None:
    """The picture frame: two ply directions of a recipe; each sense once."""
    shear = spec.shear
    angles = {p.angle_deg for p in spec.plies}
    if shear.frame_deg:
        if len(shear.frame_deg) != 2:
            raise SpecError("shear.frame_deg", list(shear.frame_deg), "must name two ply angles")
        for angle in shear.frame_deg:
            if angle not in angles:
                raise SpecError(
                    "shear.frame_deg",
                    list(shear.frame_deg),
                    f"{angle:g} is no ply's angle_deg (the plies: {', '.join(f'{a:g}' for a in sorted(angles))})",
                )
    frame = shear.frame(spec.plies)
    if shear_recipe(frame) is None:
        raise SpecError(
            "shear.frame_deg",
            list(frame),
            "must be 0 and 90 (the box tilts) or two angles +phi0 and -phi0 (the box stretches)",
        )
    if not shear.senses or len(set(shear.senses)) != len(shear.senses):
        raise SpecError(
            "shear.senses",
            list(shear.senses),
            f"must hold each of {', '.join(SHEAR_SENSES)} at most once, at least one",
        )


#: Area fraction at which random sequential addition of equal discs jams (Feder, J. Theor.
#: Biol. 87, 1980: 0.547): the densest random bed of chains, whose cross-sections are discs.
RANDOM_JAMMING = 0.547


def _check_random_bed(spec: FabricSpec) -> None:
    """The random-bed keys: read only with ``mat.arrangement = 'random'``, which needs a stitch
    (its push-off runs in the manufacture scene) and a Vf its random bed can reach."""
    mat = spec.mat
    if mat.arrangement == "rows":
        _only_read_with(
            "mat",
            mat,
            ("diameter_spread", "pushoff_overlap_tolerance", "max_pushoff_steps"),
            "mat.arrangement = 'random'",
        )
        return
    if spec.stitch is None:
        raise SpecError(
            "mat.arrangement",
            "random",
            "needs a [stitch] table: its push-off runs in the manufacture scene (use 'rows')",
        )
    fill = spec.discretisation.chain_internal_fvf
    if spec.contact.normal_model == "bundle":
        fill = spec.contact.bundle_free_fvf  # the law's onset lies at or just above V0
    densest = RANDOM_JAMMING * fill
    if mat.initial_fvf > densest:
        raise SpecError(
            "mat.initial_fvf",
            mat.initial_fvf,
            f"out of range for mat.arrangement = 'random': chains of internal Vf {fill:g} jam at"
            f" {densest:.3f} (random packing of discs, area fraction {RANDOM_JAMMING});"
            f" allowed [0.01, {densest:.3f}], or use 'rows'",
        )


#: Largest spec file read (a spec is a few kB of TOML).
MAX_SPEC_BYTES = 1_000_000


def load_spec(path: str | Path) -> FabricSpec:
    """Read and validate a spec TOML file (raises :class:`SpecError`, one line, on bad input).

    The file must exist, be a regular file of at most :data:`MAX_SPEC_BYTES`, readable, UTF-8,
    TOML and not empty; every failure names the path and what to give instead.
    """
    path = Path(path)
    shown = str(path)
    try:
        status = path.stat()
    except OSError as err:
        why = "no such file" if isinstance(err, FileNotFoundError) else err.strerror
        raise SpecError("<file>", shown, f"cannot be read ({why}): give a spec TOML file") from None
    if path.is_dir():
        inside = [p.name for p in (path / "spec.resolved.toml", path / "spec.toml") if p.is_file()]
        hint = f" (it holds {inside[0]})" if inside else ""
        raise SpecError("<file>", shown, f"is a folder, not a spec TOML file{hint}")
    if not path.is_file():
        raise SpecError("<file>", shown, "is not a regular file: give a spec TOML file")
    if status.st_size > MAX_SPEC_BYTES:
        raise SpecError(
            "<file>", shown, f"is {status.st_size:,} bytes, more than a spec ({MAX_SPEC_BYTES:,})"
        )
    try:
        raw = path.read_bytes()
    except OSError as err:
        raise SpecError("<file>", shown, f"cannot be read ({err.strerror})") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as err:
        raise SpecError(
            "<file>", shown, f"is not UTF-8 text (byte {err.start}): a spec is a TOML text file"
        ) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise SpecError("<file>", shown, f"is not valid TOML ({err})") from None
    except RecursionError:
        raise SpecError(
            "<file>",
            shown,
            "nests arrays or tables too deeply to read: a spec is a few flat tables",
        ) from None
    if not data:
        raise SpecError(
            "<file>", shown, "is empty: a spec needs [[ply]] tables (see runs/*/spec.toml)"
        )
    return spec_from_dict(data)
