"""Time step and stability limits derived from the model's stiffnesses and masses.

Velocity Verlet on a spring of stiffness ``k`` between beads of mass ``m`` is stable for
``dt < sqrt(m / k)`` in a chain (highest mode ``2 sqrt(k/m)``). Measured here (docs/design.md §8): a pulled
chain stayed stable up to 1.0 sqrt(m/k), two crossing plies up to 0.8; so the stable fraction is
:data:`STABLE_FRACTION` and the default is ``dt_fraction = 0.5`` of the smallest limit, where
``k`` covers every bond type (``k = EA / r0 = 2 K``) and the contact law at its expected overlap.
A bead feels its two bonds and its contacts at once: for each bead type the Gershgorin bound on
the highest mode, ``omega^2 <= 2 (2 k_bond + Z (k_n + k_t)) / m`` with ``Z =``
:data:`COORDINATION` contacts, gives the limit ``sqrt(2 m / (2 k_bond + Z (k_n + k_t)))``
(``sqrt(m/k)`` for a bare chain). It governs when bond and contact limits are alike: the paper's
cell with its fibre bonds softened to the contacts' stiffness heated up at dt = 0.5 of the
single-spring limits, 1.03 x this one (kinetic / potential energy stuck at 0.7 under damping).
Two numerical scalings trade inertia and fibre stretch for larger steps (docs/performance.md):
``numerics.mass_scaling`` multiplies every bead mass (every limit grows by its square root; the
loading rates keep using the physical density, so the run is that much more dynamic) and
``numerics.fibre_stiffness_scaling`` multiplies the fibre bonds' axial stiffness (their limit
grows by its inverse square root; fibres stretch that much more). ``numerics.stitch_mass_scaling``
multiplies the stitch beads' mass only: where the light stitch yarn alone sets the step, as on
the coarse bundle cells, it lifts the stitch's limits (by its square root) to the fibres', as
explicit FE codes scale only the elements below a target step (:func:`stitch_mass_balance`
gives the factor that balances them); the heavier stitch moves the results of a stitched
cell, so it is off by default (docs/performance.md). :func:`simulated_model`
applies all three; every limit here is computed on it.

Bending angles (``discretisation.bending``, docs/fidelity.md) of stiffness EI at bead spacing s
add the transverse stencil ``EI / s^3 [1, -4, 6, -4, 1]``: its zigzag mode has
``omega^2 = 16 EI / (m s^3)``, so an angle type limits dt to ``sqrt(m / (4 EI / s^3))`` on its
own and adds ``8 EI / s^3`` to the bead bound's ``2 k_bond + Z (k_n + k_t)``. Bending is not
scaled by ``fibre_stiffness_scaling``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from . import units
from .geometry.bundle import FIT_WINDOW_KPA, spec_bundle_law
from .model import Model, build_model
from .spec import FabricSpec, SpecError

__all__ = [
    "COORDINATION",
    "GUARD_KINETIC_FLOOR_STEP_MOVE",
    "GUARD_MAX_BOND_STRETCH",
    "GUARD_MAX_KINETIC_JUMP",
    "GUARD_MAX_OVERLAP",
    "GUARD_MAX_STEP_MOVE",
    "PERTURBATION_AMPLITUDE",
    "STABLE_FRACTION",
    "ContactLaw",
    "Guards",
    "Perturbation",
    "Prepared",
    "TimeStep",
    "contact_law",
    "damped_law",
    "guards",
    "inertial_strain_rate",
    "perturbation",
    "prepare",
    "simulated_model",
    "stitch_mass_balance",
    "time_step",
]

#: Guard thresholds (docs/design.md §8): a bead moving this fraction of the smallest diameter in one step,
#: a bond this much longer than the longest rest length, a contact overlapping this fraction of
#: the smallest diameter (hooke estimate F / k_n) mean the integration has gone unstable. The
#: overlap limit is one whole small diameter (beads passing through each other): plates closing
#: on the coarse stitched cell press the thin stitch yarn into the chains by half its diameter
#: at Vf 0.55, a geometric squeeze of the model, not an instability (docs/contact.md). The
#: step-move limit is 0.1 d: at 0.02 d it stopped the coarse compaction near Vf 0.6, where a
#: squeezed stitch bead moved 0.023 d (1.9 um) in one step without any other sign of trouble.
GUARD_MAX_STEP_MOVE = 0.1
GUARD_MAX_BOND_STRETCH = 0.5
GUARD_MAX_OVERLAP = 1.0
#: Kinetic-energy jump guard: the kinetic energy may grow at most this factor between two
#: checks, above a floor: the kinetic energy 0.5 M (f d / dt)^2 of an rms bead move of f =
#: GUARD_KINETIC_FLOOR_STEP_MOVE smallest diameters per step. Quasi-static stages stay near
#: f = 1e-5; the needle stage is the fastest normal motion (f = 1.04e-3 at step 100 of the coarse
#: manufacture: 12 x the floor's energy); the shear box jumps of docs/numerics.md 2.6e-3 (78 x).
GUARD_MAX_KINETIC_JUMP = 50.0
GUARD_KINETIC_FLOOR_STEP_MOVE = 3.0e-4

#: Largest dt / sqrt(m/k) measured stable for crossing plies (docs/design.md §8).
STABLE_FRACTION = 0.8

#: Contacts a bead carries at once in the stability bound: the manufactured coarse cell has at
#: most 5 beads overlapping one bead and 7 within 1.02 d (measured on its manufactured.data).
COORDINATION = 6

#: Overlap (fraction of the smaller diameter) at which a Hertz contact's stiffness is evaluated.
HERTZ_REFERENCE_OVERLAP = 0.05

#: Largest displacement per axis of a replica's perturbation (``numerics.perturbation_seed``),
#: fraction of the smallest bead diameter: 1e-6 d is below 1 % of the contacts' overlaps (F / k_n
#: of 10^-3 to 10^-1 N at 10^6 N/m: 10^-3 to 10^-1 um against 2 x 10^-4 um at 200 um) and far
#: above the rounding of a coordinate (~10^-12 of the cell); the frictional contacts' chaos
#: amplifies it into an independent trajectory.
PERTURBATION_AMPLITUDE = 1e-6


def simulated_model(spec: FabricSpec, model: Model) -> Model:
    """The model LAMMPS integrates: bead densities x ``mass_scaling`` (stitch beads x
    ``stitch_mass_scaling`` on top) and fibre bond stiffness (K and EA) x
    ``fibre_stiffness_scaling``. Atom types keep their physical densities."""
    numerics = spec.numerics
    scalings = (
        numerics.mass_scaling,
        numerics.fibre_stiffness_scaling,
        numerics.stitch_mass_scaling,
    )
    if scalings == (1.0, 1.0, 1.0):
        return model
    stiffness = numerics.fibre_stiffness_scaling
    bond_types = tuple(
        replace(t, k=t.k * stiffness, axial_stiffness=t.axial_stiffness * stiffness)
        if t.role == "fibre"
        else t
        for t in model.bond_types
    )
    density = model.density * numerics.mass_scaling
    density = np.where(model.role_mask("stitch"), density * numerics.stitch_mass_scaling, density)
    return replace(model, density=density, bond_types=bond_types)


@dataclass(frozen=True)
class ContactLaw:
    """Contact parameters in LAMMPS units for ``pair_style granular``.

    Attributes: ``model`` ("hooke"/"hertz"); ``normal`` = k_n (nN/um, hooke) or E* scale
    (kPa, hertz/material: the Young's modulus given to LAMMPS); ``stiffness`` = the normal
    stiffness at the reference overlap (nN/um); ``damping`` = the normal law's damping
    argument: eta_n (1/us) for ``damping_model`` "mass_velocity", the coefficient of
    restitution e for "coeff_restitution" (:func:`damped_law`); ``tangential`` = k_t (nN/um);
    ``friction`` = mu.
    """

    model: str
    normal: float
    stiffness: float
    damping: float
    tangential: float
    friction: float
    stitch: ContactLaw | None = None
    damping_model: str = "mass_velocity"


def contact_law(spec: FabricSpec, model: Model) -> ContactLaw:
    """The contact law of ``spec`` evaluated for the lightest and smallest beads of ``model``
    (masses of the :func:`simulated_model`).

    Under the bundle law the fibre-stitch pairs keep the rigid hooke law of
    ``contact.normal_stiffness_N_m`` (attribute ``stitch``): the Hertz mapping holds over the
    bed law's window only, and a tensioned stitch presses its thin yarn into a bundle at
    megapascals, where the mapped contact would let it cut through (docs/contact.md)."""
    contact = spec.contact
    d_min = float(model.diameter.min())
    mass = simulated_model(spec, model).mass
    m_eff = float(mass.min()) / 2.0
    law = spec_bundle_law(spec)
    rigid = units.to_micro(contact.normal_stiffness_N_m, "N_m")
    if contact.normal_model == "hooke":
        return _law("hooke", rigid, rigid, m_eff, spec)
    if law is None:
        normal = units.to_micro(contact.contact_modulus_GPa, "GPa")
        overlap = HERTZ_REFERENCE_OVERLAP * d_min
    else:  # the bundle's E* at the fibre beads' mean spacing, stiffest at the window's top
        fibre = model.role_mask("fibre")
        d_min = float(model.diameter[fibre].min())
        normal = 2.0 * law.effective_modulus(_fibre_spacing_ratio(model))
        overlap = law.overlap_at(FIT_WINDOW_KPA[1]) * d_min
    e_star = normal / 2.0  # two equal bodies, Poisson ratio neglected
    stiffness = 2.0 * e_star * np.sqrt(d_min / 4.0 * overlap)
    hertz = _law("hertz", normal, stiffness, m_eff, spec)
    if law is None or not np.any(model.role_mask("stitch")):
        return hertz
    return replace(hertz, stitch=_law("hooke", rigid, rigid, m_eff, spec))


def _fibre_spacing_ratio(model: Model) -> float:
    """Mean bead spacing over mean diameter of the fibre chains (s / D of the bundle law)."""
    r0 = np.array([t.r0 for t in model.bond_types])[model.bond_type]
    fibre_bonds = np.array([t.role == "fibre" for t in model.bond_types])[model.bond_type]
    return float(r0[fibre_bonds].mean() / model.diameter[model.role_mask("fibre")].mean())


def _law(model: str, normal: float, stiffness: float, m_eff: float, spec: FabricSpec):
    """The :func:`damped_law` of ``spec``'s contact table."""
    contact = spec.contact
    return damped_law(
        model,
        normal,
        stiffness,
        contact.damping_ratio,
        m_eff,
        contact.tangential_stiffness_ratio,
        contact.friction,
    )


def damped_law(
    model: str,
    normal: float,
    stiffness: float,
    damping_ratio: float,
    m_eff: float,
    tangential_ratio: float,
    friction: float,
) -> ContactLaw:
    """A :class:`ContactLaw` of normal parameter ``normal``, reference ``stiffness`` (nN/um),
    k_t = ``tangential_ratio`` x stiffness and Coulomb ``friction``, damped at
    ``damping_ratio`` zeta of critical (docs/contact.md):

    - hooke: ``damping mass_velocity``, the force ``eta m_eff v_n`` with
      ``eta = 2 zeta sqrt(stiffness / m_eff)`` (1/us) for the effective mass ``m_eff`` (pg) of
      the lightest pair: zeta of critical for that pair, more for heavier ones;
    - hertz: ``damping coeff_restitution``, the force ``2 zeta sqrt(m_eff F_n / delta) v_n``
      of every pair's own effective mass and secant stiffness ``F_n / delta`` at its current
      overlap: zeta of critical on every contact at every load. LAMMPS forms that prefactor as
      ``sqrt(5) zeta_e sqrt(m_eff F_n / delta)`` from the coefficient of restitution e it is
      given, ``zeta_e = -ln e / sqrt(pi^2 + ln^2 e)`` (src/GRANULAR/gran_sub_mod_damping.cpp),
      so e is the one of ``zeta_e = 2 zeta / sqrt(5)``.
    """
    if model == "hooke":
        damping, damping_model = 2.0 * damping_ratio * np.sqrt(stiffness / m_eff), "mass_velocity"
    else:
        zeta_e = 2.0 * damping_ratio / np.sqrt(5.0)
        damping = np.exp(-np.pi * zeta_e / np.sqrt(1.0 - zeta_e**2))
        damping_model = "coeff_restitution"
    return ContactLaw(
        model=model,
        normal=float(normal),
        stiffness=float(stiffness),
        damping=float(damping),
        tangential=float(tangential_ratio * stiffness),
        friction=float(friction),
        damping_model=damping_model,
    )


@dataclass(frozen=True)
class TimeStep:
    """Stability limits and the chosen step (us).

    Attributes:
        limits: {name: sqrt(m/k)} for each bond type and for contacts (us).
        roles: {name: "fibre", "stitch" or "contact"}: whose beads each limit belongs to.
        governing: the name of the smallest limit.
        critical: the smallest limit sqrt(m/k) (us).
        dt: chosen time step (us).
        fraction: dt / critical.
        margin: STABLE_FRACTION / fraction (> 1 is inside the measured stable range).
    """

    limits: dict[str, float]
    roles: dict[str, str]
    governing: str
    critical: float
    dt: float
    fraction: float
    margin: float


def time_step(spec: FabricSpec, model: Model) -> TimeStep:
    """Critical and chosen time step of the :func:`simulated_model`; refuses a fraction above
    the stable one unless allowed."""
    simulated = simulated_model(spec, model)
    mass = simulated.mass
    limits: dict[str, float] = {}
    roles: dict[str, str] = {"contact": "contact"}
    for index, bond_type in enumerate(simulated.bond_types):
        in_type = model.bond_type == index
        if not np.any(in_type):
            continue
        m_min = float(mass[model.bonds[in_type].ravel()].min())
        limits[f"bond {bond_type.name}"] = float(np.sqrt(m_min / (2.0 * bond_type.k)))
        roles[f"bond {bond_type.name}"] = bond_type.role
    bending = np.zeros(len(simulated.atom_types))
    for index, angle_type in enumerate(simulated.angle_types):
        in_type = simulated.angle_type == index
        if not np.any(in_type):
            continue
        vertex = simulated.angles[in_type, 1]
        k_zigzag = 4.0 * angle_type.bending_stiffness / angle_type.spacing**3
        for t in np.unique(simulated.type_id[vertex]):
            m_min = float(mass[vertex[simulated.type_id[vertex] == t]].min())
            key = f"bending {simulated.atom_types[t].name}"
            limit = float(np.sqrt(m_min / k_zigzag))
            limits[key] = min(limits.get(key, limit), limit)
            roles[key] = simulated.atom_types[t].role
            bending[t] = max(bending[t], 2.0 * k_zigzag)
    law = contact_law(spec, model)
    stiffest = law if law.stitch is None else law.stitch
    limits["contact"] = float(np.sqrt(float(mass.min()) / stiffest.stiffness))
    contacts = COORDINATION * (stiffest.stiffness + stiffest.tangential)
    bond_k = np.array([2.0 * t.k for t in simulated.bond_types])
    degree = np.bincount(simulated.bonds.ravel(), minlength=len(mass))
    for index, atom_type in enumerate(simulated.atom_types):
        beads = simulated.type_id == index
        if not np.any(beads):
            continue
        ends = beads[simulated.bonds].any(axis=1)
        k_bond = float(bond_k[np.unique(simulated.bond_type[ends])].max()) if ends.any() else 0.0
        n_bonds = max(2, int(degree[beads].max()))  # a chain bead's two, a junction's more
        m_min = float(mass[beads].min())
        bend = " + bending" if bending[index] else ""
        key = f"bead {atom_type.name} ({n_bonds} bonds + {COORDINATION} contacts{bend})"
        limits[key] = float(np.sqrt(2.0 * m_min / (n_bonds * k_bond + contacts + bending[index])))
        roles[key] = atom_type.role
    governing = min(limits, key=limits.get)
    critical = limits[governing]
    fraction = spec.numerics.dt_fraction
    if fraction > STABLE_FRACTION and not spec.numerics.allow_unstable_dt:
        raise SpecError(
            "numerics.dt_fraction",
            fraction,
            f"above the stable {STABLE_FRACTION} sqrt(m/k) (dt {fraction * critical:.4g} us >"
            f" {STABLE_FRACTION * critical:.4g} us, {governing}); set"
            " numerics.allow_unstable_dt = true to run anyway",
        )
    return TimeStep(
        limits,
        roles,
        governing,
        critical,
        fraction * critical,
        fraction,
        STABLE_FRACTION / fraction,
    )


def stitch_mass_balance(step: TimeStep) -> float:
    """The ``stitch_mass_scaling`` factor (on top of the current one) that lifts the stitch's
    own limits (its beads and bonds, which grow as its square root) to the smallest limit of
    the fibres: ``(min fibre limit / min stitch limit)^2``, 1 where the stitch does not govern
    or the model has none. The global ``contact`` limit is left out: it follows the lightest
    bead, whichever that is."""
    stitch = [v for k, v in step.limits.items() if step.roles[k] == "stitch"]
    fibre = [v for k, v in step.limits.items() if step.roles[k] == "fibre"]
    if not stitch or not fibre:
        return 1.0
    return max(1.0, (min(fibre) / min(stitch)) ** 2)


@dataclass(frozen=True)
class Guards:
    """Stability guard settings rendered into every scene deck (``fix halt ... error hard``).

    Attributes: ``every`` (steps between checks); ``diameter`` = smallest bead diameter (um);
    ``contact_stiffness`` (nN/um) to turn the largest pair force into an overlap (hooke:
    ``F / k``); ``hertz_coefficient`` K (nN/um^1.5) for a Hertz law, ``(F / K)^(2/3)``, else
    None;
    ``max_step_move`` and ``max_overlap`` (fractions of ``diameter``); ``max_bond_length`` (um);
    ``max_kinetic_jump`` (growth factor of the kinetic energy between two checks) above
    ``kinetic_floor`` (pg um^2 / us^2, the kinetic energy of an rms move of
    :data:`GUARD_KINETIC_FLOOR_STEP_MOVE` diameters per step).
    """

    every: int
    diameter: float
    contact_stiffness: float
    hertz_coefficient: float | None
    max_step_move: float
    max_overlap: float
    max_bond_length: float
    max_kinetic_jump: float
    kinetic_floor: float


def guards(spec: FabricSpec, model: Model, dt: float) -> Guards:
    """The guards of a model run at time step ``dt`` (us): thresholds from
    :data:`GUARD_MAX_STEP_MOVE` and friends."""
    diameter = float(model.diameter.min())
    floor_speed = GUARD_KINETIC_FLOOR_STEP_MOVE * diameter / dt
    law = contact_law(spec, model)
    # F = 4/3 E* sqrt(R*) delta^1.5, E* = E / 2, R* = d / 4 (two smallest beads); with rigid
    # stitch contacts the largest pair force is read with their hooke stiffness.
    hertz = None
    if law.stitch is not None:
        law = law.stitch
    elif law.model == "hertz":
        hertz = 4.0 / 3.0 * law.normal / 2.0 * float(np.sqrt(diameter / 4.0))
    return Guards(
        every=spec.numerics.guard_every,
        diameter=diameter,
        contact_stiffness=law.stiffness,
        hertz_coefficient=hertz,
        max_step_move=GUARD_MAX_STEP_MOVE,
        max_overlap=GUARD_MAX_OVERLAP,
        max_bond_length=(1.0 + GUARD_MAX_BOND_STRETCH) * max(t.r0 for t in model.bond_types),
        max_kinetic_jump=GUARD_MAX_KINETIC_JUMP,
        kinetic_floor=0.5 * float(simulated_model(spec, model).mass.sum()) * floor_speed**2,
    )


@dataclass(frozen=True)
class Perturbation:
    """A replica's perturbation at the start of every scene: each bead displaced by a random
    vector, uniform in ``[-amplitude, amplitude]`` (um) per axis, drawn from ``seed`` (LAMMPS
    ``displace_atoms random``)."""

    amplitude: float
    seed: int


def perturbation(spec: FabricSpec, model: Model) -> Perturbation | None:
    """The replica's perturbation of ``numerics.perturbation_seed``, None when it is 0."""
    seed = spec.numerics.perturbation_seed
    if seed == 0:
        return None
    return Perturbation(PERTURBATION_AMPLITUDE * float(model.diameter.min()), seed)


def inertial_strain_rate(model: Model, inertial_number: float, pressure: float) -> float:
    """Strain rate (1/us) of a given inertial number ``I = gdot d sqrt(rho / P)``.

    ``d`` is the mean fibre bead diameter, ``rho`` the mean fibre density and ``P`` (kPa) the
    confining pressure: ``gdot = I sqrt(P / rho) / d``. The compaction and shear scenes derive
    their loading rates from it.
    """
    fibre = model.role_mask("fibre")
    rho = float(np.mean([t.density for t in model.atom_types if t.role == "fibre"]))
    d = float(model.diameter[fibre].mean())
    return inertial_number * float(np.sqrt(pressure / rho)) / d


@dataclass(frozen=True)
class Prepared:
    """One run's model and numerics, computed once and passed to every scene and writer.

    Attributes: ``spec``; ``model`` (physical masses and stiffnesses); ``simulated`` (the model
    LAMMPS integrates, :func:`simulated_model`); ``time_step``; ``contact`` (the contact law);
    ``guards`` (the stability guards at ``time_step.dt``).
    """

    spec: FabricSpec
    model: Model
    simulated: Model
    time_step: TimeStep
    contact: ContactLaw
    guards: Guards


def prepare(spec: FabricSpec, model: Model | None = None) -> Prepared:
    """The :class:`Prepared` run of ``spec`` (its model built unless given)."""
    model = build_model(spec) if model is None else model
    step = time_step(spec, model)
    return Prepared(
        spec=spec,
        model=model,
        simulated=simulated_model(spec, model),
        time_step=step,
        contact=contact_law(spec, model),
        guards=guards(spec, model, step.dt),
    )
