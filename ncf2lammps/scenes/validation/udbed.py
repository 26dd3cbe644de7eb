"""Case 8: compaction of a random bed of unidirectional wavy chains, rigid against bundle chains.

Claim: a random bed of parallel wavy chains with rigid contacts and free pins LOCKS (its pressure
jumps by decades within a tiny change of Vf), while the same bed with the bundle transverse law
(docs/contact.md, :mod:`ncf2lammps.geometry.bundle`) and bending COMPACTS PROGRESSIVELY.

Law: the bundle bed follows ``Vf = a P^b`` (the compaction law of dry reinforcements, Robitaille
and Gauvin, Polym. Compos. 19, 1998, 198-216, whose exponents are of order 0.1) with ``b`` at
least that of a regular stack of the same bundle chains, ``b_stack = ln((1 - delta_1 / D) /
(1 - delta_18 / D)) / ln 18`` = 0.0344 between 1 and 18 kPa (``BundleLaw.stack_pressure``:
the compliance of the bundles' contacts alone; rearrangement and bending of the chains can
only add to it), and its pressure rises smoothly. The rigid bed locks where its pressure
rises threefold within 2 % of Vf (a local b below 0.018). Gutowski's bed law at the chain scale
(Gutowski, Morigaki and Cai 1987), ``P = A_s (sqrt(V/V0) - 1) / (sqrt(Va/V) - 1)^4`` with
``A_s = 3 pi E_eff / beta^4``, ``E_eff = EI / (pi D^4 / 64) = V_h E (d_f / D)^2`` = 0.27 GPa,
``beta`` = wavelength / amplitude = 26.7, V the chains' envelope Vf, V0 the envelope Vf where
the bed reaches 1 kPa and Va the hexagonal limit 0.907, is reported for comparison (info):
it does not describe the bed (below).

Configuration: 36 periodic closed chains along x (fast form: 24) of 32 beads, two waves per
cell (wavelength 1200 um, in-plane sinusoidal waviness :class:`~ncf2lammps.geometry.mat.Waviness`
of amplitude 0.3 D, random phase per chain), D = 150 um, s = D/2, carbon (E 240 GPa, rho 1.80);
axes and phases by random sequential placement without bead overlap in a square periodic cross
section at an envelope Vf of 0.25. The chains' fill (fibre Vf inside a chain) is the bundle
law's onset V_h = 0.508 of ``FibreBed(240 GPa, beta 350, V0 0.5, Va 0.785)`` in both beds, so
they carry the same fibre; Vf is the fibre Vf (fibre volume / box volume). (a) Rigid: hooke
k_n = 1e5 N/m, free pins. (b) Bundle: ``hertz/material`` with E = 2 E* of the bundle law,
harmonic bending angles EI = N_f E pi d_f^4 / 64 (d_f = 7 um, the builder's). Friction 0.3,
contact damping 0.3 of critical; ``fix viscous`` at 0.3 of critical for one contact (the
rigid one, the bundle one at its stiffness at 100 kPa). The fully periodic box is shrunk in z
(``fix deform z trate ... remap x``): a periodic box has no plate walls and no wall layer, and
the affine remap leaves the in-plane waves, and so the bonds, unstrained (out-of-plane waves
would be squeezed by the remap and load their bonds); Pzz is the virial pressure. An approach
at a fast rate stops once the bed carries 0.3 kPa; the loading then runs at a constant true
strain rate of inertial number ``I = rate D sqrt(rho_chain / 1 kPa)`` = 0.03 (fast form 0.06),
the rigid bed up to 100 kPa, the bundle bed up to 20 kPa. Fibre bonds are softened to
2 K = 1e6 N/m (10 x the rigid contacts, 3.4 % of carbon's EA / s;
``numerics.fibre_stiffness_scaling``, docs/performance.md), so that the steps are those of the
contacts and bending: the largest bond strain stays below 1e-4. Halving the speed changes the
bundle bed's pressure at the window's middle (4.24 kPa) by -12 %, its Vf there by ~2 % (at
b = 0.15): at this rate the bed is not quasi-static to 10 %; the half-speed run is reported,
not judged.

Measured (full form, ~4 min; fast form ~50 s): the bundle bed compacts smoothly with b = 0.147
(fast form ~0.22), successive records within 2 %. The rigid
bed locks in steps: its pressure rises threefold within 0.9 % of Vf (about 5 to 20 kPa at
Vf 0.21), then the free-pin chains yield and rearrange and the pressure falls back by up to
1.7 x (stick-slip) before the next step; it needs 13 % of Vf to rise tenfold and its b between
1 and 18 kPa is 0.066 (Vf 0.172 to 0.208), not below 0.02: a bed of floppy chains locks locally,
not once from 1 to 100 kPa, and its b is half the bundle bed's, not far below. The chain-scale
Gutowski estimate is two decades above the bundle bed's pressure (846 against 4.2 kPa at
Vf 0.348): with these constants its ``(sqrt(Va/V) - 1)^-4`` stiffening governs, while the bed's
compliance is that of its soft bundle contacts and its rearrangement.

Tolerance: bundle bed b in [b_stack, b_stack + 0.25]; ratio of successive records' pressures,
up or down, at most 1.25 between the first records at 1 and at 18 kPa; rigid bed: a threefold
rise within ``ln(Vf2/Vf1) <= 0.02``. The half-speed pressure, the tenfold rise, the fall after
a lock, the rigid bed's b and the Gutowski estimate are reported, not judged.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ... import units
from ...analysis.compaction import first_crossing
from ...geometry.bundle import FIT_WINDOW_KPA, FibreBed, bundle_law
from ...geometry.chains import sample_closed_polyline
from ...geometry.mat import Waviness
from ...model import AtomType, Box, Model, Part, join
from ...model.builder import angle_kinds, rest_angles, rest_length_types
from ...numerics import ContactLaw
from ...spec import HEXAGONAL_PACKING
from .common import (
    E_CARBON,
    MU,
    RHO_CARBON,
    CaseResult,
    Check,
    contact,
    hertz_contact,
    lammps_case,
)
from .plots import line_plot

__all__ = ["run"]

CASE = "8 random UD bed"

#: Chain (bundle envelope) diameter (um), filament diameter (um), waves per cell.
CHAIN_D = 150.0
FILAMENT_D = 7.0
WAVES = 2
#: Waviness amplitude (fraction of the chain diameter) and initial envelope Vf of the placement.
AMPLITUDE = 0.3
START_ENVELOPE_FVF = 0.25
#: The bundle's fibre bed: carbon's E (kPa), beta 350, V0 0.5, Va 0.785.
BED = FibreBed(E_CARBON, 350.0, 0.5, 0.785)
#: Rigid contacts of the bed without the bundle law (N/m); axial stiffness 2 K = EA / r0 of
#: every bond (N/m): 10 x the rigid contacts, 3.4 % of carbon's EA / s (the time step's limit).
RIGID_KN = 1.0e5
BOND_STIFFNESS = 1.0e6
#: Seed of the placement; the fast form's and the full form's chain counts.
SEED = 3
CHAINS = {False: 24, True: 36}
#: Inertial number of the loading at 1 kPa, ``I = rate D sqrt(rho / P)`` (fast, full form).
INERTIAL = {False: 0.06, True: 0.03}
#: Pressures (kPa): end of the approach, the window of the exponent, the top of the loading.
APPROACH_KPA = 0.3
WINDOW_KPA = (1.0, 18.0)
TOP_KPA = 20.0
#: The rigid bed is loaded on to this pressure (kPa); it locks where the pressure rises
#: LOCK_FACTOR-fold within a true strain of LOCK_STRAIN (2 % of Vf, a local b below 0.018).
RIGID_TOP_KPA = 100.0
LOCK_FACTOR = 3.0
LOCK_STRAIN = 0.02


def _template(length: float, spacing: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One closed wavy chain of phase 0 along x, waves in y (in the plane): (n, 3) beads, (n,) bond rest
    lengths (bond i joins bead i to i + 1), (n,) chain length per bead."""
    wave = Waviness(AMPLITUDE * CHAIN_D, WAVES, False, 1.0, 0)
    vertices = wave.vertices(length)
    chain = sample_closed_polyline(vertices, np.array([length, 0.0, 0.0]), spacing)
    return chain.positions, chain.bond_length, chain.length_per_bead


def _placement(template, n_chains, length, width, height, rng) -> np.ndarray:
    """(C, n, 3) beads of ``n_chains`` translates of ``template`` at random phases and axes, by
    random sequential placement: a candidate whose beads come closer than one chain diameter to
    a placed chain's beads (periodic box) is drawn again."""
    cell = np.array([length, width, height])
    placed = np.empty((0, 3))
    chains = []
    for _ in range(n_chains):
        for _ in range(20000):
            shift = rng.uniform(0.0, 1.0, 3) * cell
            beads = template + shift
            if len(placed):
                gap = beads[:, None, :] - placed[None, :, :]
                gap -= np.rint(gap / cell) * cell
                if np.min(np.einsum("ijk,ijk->ij", gap, gap)) < CHAIN_D**2:
                    continue
            break
        else:
            raise RuntimeError("random placement found no free spot")
        chains.append(beads % cell)
        placed = np.vstack([placed, beads])
    return np.array(chains)


def _bed_model(n_chains: int, bending: bool) -> tuple[Model, float]:
    """The random bed; returns the model and the chains' bending stiffness EI (nN um^2, 0
    without bending)."""
    law = bundle_law(BED)
    spacing = CHAIN_D / 2
    length = WAVES * 16 * spacing
    template, r0, per_bead = _template(length, spacing)
    area = law.onset_fvf * np.pi * CHAIN_D**2 / 4  # fibre cross-section of a chain
    envelope = n_chains * np.pi * CHAIN_D**2 / 4 * r0.sum() / length
    width = math.sqrt(envelope / START_ENVELOPE_FVF)
    beads = _placement(template, n_chains, length, width, width, np.random.default_rng(SEED))
    n = beads.shape[1]
    # Fibre bonds softened to 2 K = EA / r0 = BOND_STIFFNESS (as numerics.fibre_stiffness_scaling)
    axial = units.to_micro(BOND_STIFFNESS, "N_m") * float(r0.mean())
    bond_types, bond_type = rest_length_types(r0, "fibre", axial, lambda j, i: f"chain_{j}")
    local = np.arange(n_chains * n).reshape(n_chains, n)
    density = RHO_CARBON * area * per_bead / (np.pi * CHAIN_D**3 / 6)
    part = Part(
        positions=beads.reshape(-1, 3),
        type_id=np.zeros(n_chains * n, dtype=np.int64),
        density=np.tile(density, n_chains),
        mol_id=np.repeat(np.arange(n_chains), n),
        bonds=np.stack([local, np.roll(local, -1, axis=1)], axis=-1).reshape(-1, 2),
        bond_type=np.tile(bond_type, n_chains),
        atom_types=(AtomType("chain", "fibre", CHAIN_D, RHO_CARBON, E_CARBON, 0.0, law.onset_fvf),),
        bond_types=bond_types,
        fibre_volume=float(area * r0.sum() * n_chains),
    )
    ei = 0.0
    if bending:
        ei = area * E_CARBON * FILAMENT_D**2 / 16.0  # N_f E pi d_f^4 / 64
        types, per = angle_kinds("harmonic", ei, rest_angles(template, length), per_bead, "chain")
        triples = np.stack([np.roll(local, 1, axis=1), local, np.roll(local, -1, axis=1)])
        part = Part(
            **{
                **part.__dict__,
                "angles": triples.reshape(3, -1).T,
                "angle_type": np.tile(per, n_chains),
                "angle_types": tuple(types),
            }
        )
    box = Box(np.zeros(3), np.array([length, width, width]), np.zeros(3))
    model = join(
        [part],
        box,
        mat_thickness=width,
        faces_z=(0.0, width),
        angle_style="harmonic" if bending else "none",
    )
    return model, ei


def _numerics(model: Model, ei: float, progressive: bool) -> tuple[ContactLaw, float, float]:
    """(contact law, time step us, viscous gamma pg/us) of a bed: the bundle's Hertz law at its
    stiffness at the top of the law's window, or rigid hooke; dt half the smallest of the
    bond, bending-zigzag and bead limits (ncf2lammps.numerics)."""
    mass = float(model.mass.min())
    bond_k = max(2.0 * t.k for t in model.bond_types)
    if progressive:
        law = bundle_law(BED)
        e_star = law.effective_modulus(0.5)
        k = 2.0 * e_star * math.sqrt(CHAIN_D / 4 * law.overlap_at(FIT_WINDOW_KPA[1]) * CHAIN_D)
        law_lmp = hertz_contact(2.0 * e_star, k, mass, MU)
    else:
        k = units.to_micro(RIGID_KN, "N_m")
        law_lmp = contact(k, mass, MU)
    zigzag = 16.0 * ei / (CHAIN_D / 2) ** 3
    limits = [
        math.sqrt(mass / bond_k),
        math.sqrt(2.0 * mass / (2.0 * bond_k + 6.0 * 9.0 / 7.0 * k + zigzag / 2.0)),
    ]
    if ei:
        limits.append(math.sqrt(4.0 * mass / zigzag))
    return law_lmp, 0.5 * min(limits), 0.3 * 2.0 * math.sqrt(k * mass)


def _compact(
    workdir: Path, progressive: bool, full: bool, slow: float = 1.0, stop_kpa: float = TOP_KPA
) -> tuple[np.ndarray, np.ndarray, float]:
    """Compact one bed; returns (fibre Vf, Pzz kPa) records of the loading and the largest
    bond strain. ``slow`` divides the loading rate; the loading stops above ``stop_kpa``."""
    model, ei = _bed_model(CHAINS[full], progressive)
    law, dt, gamma = _numerics(model, ei, progressive)
    rho = RHO_CARBON * bundle_law(BED).onset_fvf  # the chains' envelope density
    rate = INERTIAL[full] / slow * math.sqrt(WINDOW_KPA[0] / rho) / CHAIN_D
    chunk = 250 if not full else 500
    most = int(1.2 / (rate * dt * chunk))  # a true strain of 1.2 at most
    values = {"gamma": gamma, "approach_rate": 0.7 / (10000 * dt), "chunk": chunk}
    rows = []
    r0 = max(t.r0 for t in model.bond_types)
    with lammps_case(workdir, "validation/udbed.lmp.j2", model, dt, law, **values) as lmp:
        for _ in range(40):
            lmp.command(f"run {chunk}")
            if lmp.fix_vector("record", 3)[0] > APPROACH_KPA:
                break
        lmp.command("unfix approach")
        lmp.command(f"fix squeeze all deform 1 z trate {-rate:.8g} remap x")
        for _ in range(most):
            lmp.command(f"run {chunk}")
            rows.append(lmp.fix_vector("record", 3))
            if rows[-1][0] > stop_kpa:
                break
    rows = np.array(rows)
    np.savetxt(
        workdir / "records.txt", rows, header="Pzz (kPa), box volume (um^3), longest bond (um)"
    )
    return model.fibre_volume / rows[:, 1], rows[:, 0], float(rows[:, 2].max() / r0 - 1.0)


def _crossing(fvf: np.ndarray, pressure: np.ndarray, level: float) -> float:
    """Fibre Vf where the record first reaches ``level`` kPa (linear between records); the last
    Vf if it never does."""
    crossing = first_crossing(fvf, pressure, level)
    return float(fvf[-1]) if math.isnan(crossing) else crossing


def exponent(fvf: np.ndarray, pressure: np.ndarray, window=WINDOW_KPA) -> float:
    """b of ``Vf = a P^b`` between the ``window``'s two pressures (kPa), read at the records'
    first crossings of each: the Vf the loading needed to first carry that pressure."""
    low, high = (_crossing(fvf, pressure, p) for p in window)
    return math.log(high / low) / math.log(window[1] / window[0])


def largest_jump(pressure: np.ndarray) -> float:
    """Largest ratio, up or down, of successive records' pressures from the first record at
    the window's low end to the first at its high end."""
    above = np.flatnonzero(pressure >= WINDOW_KPA[0])
    top = np.flatnonzero(pressure >= WINDOW_KPA[1])
    if not len(above) or not len(top):
        return float("inf")
    segment = pressure[max(above[0] - 1, 0) : top[0] + 1]
    return float(np.exp(np.max(np.abs(np.diff(np.log(np.maximum(segment, 1e-9)))))))


def steepest_rise(fvf: np.ndarray, pressure: np.ndarray, factor: float = 10.0) -> float:
    """Smallest ``ln(Vf_j / Vf_i)`` over which the pressure rises ``factor``-fold, from any
    record ``i`` at or above the window's low end to the first record ``j`` after it at or
    above ``factor P_i``; inf if it never does."""
    best = math.inf
    for i in np.flatnonzero(pressure >= WINDOW_KPA[0]):
        later = np.flatnonzero(pressure[i:] >= factor * pressure[i])
        if len(later):
            best = min(best, math.log(fvf[i + later[0]] / fvf[i]))
    return best


def largest_drop(pressure: np.ndarray) -> float:
    """Largest ratio of the pressure reached so far to a later record's (1: never falls)."""
    return float(np.max(np.maximum.accumulate(pressure) / np.maximum(pressure, 1e-9)))


def stack_exponent() -> float:
    """b of the regular stack of bundle chains (:meth:`BundleLaw.stack_pressure`): the
    compaction the bundle's contacts alone give, Vf ~ 1 / (1 - delta / D)."""
    law = bundle_law(BED)
    low, high = (1.0 - law.overlap_at(p) for p in WINDOW_KPA)
    return math.log(low / high) / math.log(WINDOW_KPA[1] / WINDOW_KPA[0])


def gutowski_chain_scale(envelope_fvf: float, onset: float) -> float:
    """Gutowski's bed law at the chain scale (kPa) at envelope Vf ``envelope_fvf``: E_eff =
    EI / (pi D^4 / 64) = V_h E (d_f / D)^2, beta = wavelength / amplitude, V0 = ``onset``, Va
    = the hexagonal packing limit."""
    law = bundle_law(BED)
    modulus = law.onset_fvf * E_CARBON * (FILAMENT_D / CHAIN_D) ** 2
    beta = (WAVES * 16 * CHAIN_D / 2 / WAVES) / (AMPLITUDE * CHAIN_D)
    bed = FibreBed(modulus, beta, onset, HEXAGONAL_PACKING)
    return float(bed.pressure(envelope_fvf))


def run(workdir: Path, full: bool = False) -> CaseResult:
    """Run case 8 in ``workdir``; returns its rows and plot."""
    rigid_fvf, rigid_p, _ = _compact(workdir / "rigid", False, full, stop_kpa=RIGID_TOP_KPA)
    bundle_fvf, bundle_p, stretch = _compact(workdir / "bundle", True, full)
    b_rigid, b_bundle = exponent(rigid_fvf, rigid_p), exponent(bundle_fvf, bundle_p)
    b_stack = stack_exponent()
    fill = bundle_law(BED).onset_fvf
    middle = math.sqrt(WINDOW_KPA[0] * WINDOW_KPA[1])
    middle_fvf = _crossing(bundle_fvf, bundle_p, middle)
    onset = _crossing(bundle_fvf, bundle_p, WINDOW_KPA[0]) / fill
    window = f"{WINDOW_KPA[0]:g}-{WINDOW_KPA[1]:g} kPa"
    checks = [
        Check(
            CASE,
            f"bundle law + bending: b of Vf = a P^b, {window}",
            "b >= b of the bundle-chain stack",
            b_stack,
            b_bundle,
            0.25,
            "above",
        ),
        Check(
            CASE,
            f"bundle law + bending: largest P ratio of successive records, {window}",
            "P rises smoothly",
            1.0,
            largest_jump(bundle_p),
            0.25,
            "above",
        ),
        Check(
            CASE,
            f"rigid, free pins: b of Vf = a P^b, {window}",
            "locked: b < 0.02 (claim)",
            0.02,
            b_rigid,
            0.0,
            "info",
        ),
        Check(
            CASE,
            f"rigid, free pins: largest P ratio of successive records, {window}",
            "locked: a jump",
            1.0,
            largest_jump(rigid_p),
            0.0,
            "info",
        ),
        Check(
            CASE,
            "rigid, free pins: steepest threefold rise of P, ln(Vf2/Vf1)",
            "locks: P x 3 within 2 % of Vf",
            0.0,
            steepest_rise(rigid_fvf, rigid_p, LOCK_FACTOR),
            LOCK_STRAIN,
            "above",
        ),
        Check(
            CASE,
            "rigid, free pins: steepest tenfold rise of P, ln(Vf2/Vf1)",
            "locked from 1 to 100 kPa (claim): P x 10 within 2 % of Vf",
            0.0,
            steepest_rise(rigid_fvf, rigid_p),
            0.0,
            "info",
        ),
        Check(
            CASE,
            "rigid, free pins: largest fall of P after a lock (ratio)",
            "locked: P never falls",
            1.0,
            largest_drop(rigid_p),
            0.0,
            "info",
        ),
        Check(
            CASE,
            "bundle law + bending: steepest threefold rise of P, ln(Vf2/Vf1)",
            "progressive: ln 3 x b of the stack",
            math.log(LOCK_FACTOR) * b_stack,
            steepest_rise(bundle_fvf, bundle_p, LOCK_FACTOR),
            0.0,
            "info",
        ),
        Check(
            CASE,
            f"bundle bed: P (kPa) at Vf {middle_fvf:.3f} vs Gutowski at the chain scale",
            "P = A_s (sqrt(V/V0) - 1) / (sqrt(Va/V) - 1)^4",
            gutowski_chain_scale(middle_fvf / fill, onset),
            middle,
            0.0,
            "info",
        ),
        Check(CASE, "bundle bed: largest bond strain", "EA scaled", 0.0, stretch, 0.0, "info"),
    ]
    curves = [
        (rigid_fvf, rigid_p, f"rigid hooke, free pins: b = {b_rigid:.3f}"),
        (bundle_fvf, bundle_p, f"bundle law + bending: b = {b_bundle:.3f}"),
    ]
    if full:
        slow_fvf, slow_p, _ = _compact(workdir / "bundle_half_speed", True, full, 2.0, middle)
        slow_middle = float(np.interp(middle_fvf, slow_fvf, slow_p))
        checks.append(
            Check(
                CASE,
                f"bundle bed at half speed: P (kPa) at Vf {middle_fvf:.3f}",
                "quasi-static: rate-independent",
                middle,
                slow_middle,
                0.0,
                "info",
            )
        )
        curves.append((slow_fvf, slow_p, "bundle law + bending, half speed"))
    positive = [(v, np.maximum(p, 1e-3), label) for v, p, label in curves]
    plot = line_plot(
        workdir / "udbed.png",
        positive,
        "fibre volume fraction Vf",
        "compaction pressure Pzz (kPa)",
        f"Case 8: random bed of {CHAINS[full]} wavy UD chains",
        log_y=True,
    )
    note = (
        f"Bundle bed: Vf {_crossing(bundle_fvf, bundle_p, WINDOW_KPA[0]):.3f} at"
        f" {WINDOW_KPA[0]:g} kPa, {_crossing(bundle_fvf, bundle_p, WINDOW_KPA[1]):.3f} at"
        f" {WINDOW_KPA[1]:g} kPa; rigid bed: {_crossing(rigid_fvf, rigid_p, WINDOW_KPA[0]):.3f}"
        f" and {_crossing(rigid_fvf, rigid_p, WINDOW_KPA[1]):.3f}; stack exponent"
        f" {b_stack:.4f}."
    )
    return CaseResult(CASE, checks, [plot], note)
