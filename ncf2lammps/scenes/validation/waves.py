"""Case 1: axial waves in a free bead chain.

Law: a chain of beads of mass ``m = rho A s`` joined by springs ``k = E A / s`` carries long axial
waves at ``c = s sqrt(k / m) = sqrt(E / rho)``; a free-free chain of N beads has the modes
``omega_n = 2 sqrt(k / m) sin(n pi / (2 N))`` (standing waves of the discrete lattice; e.g.
Brillouin, *Wave Propagation in Periodic Structures*, 1946, ch. 1). Without damping velocity
Verlet conserves energy: no drift, only a bounded fluctuation of order ``(omega dt)^2``.

Configuration: carbon chain (E 240 GPa, rho 1.80 g/cm3), d = 69 um, s = d/2, dt = 0.5 sqrt(m/k),
``fix nve``, no contacts (neighbours closer than 1-4 are excluded, 1-4 beads sit 1.5 d apart).
(a) Time of flight: 300 beads; a right-going compressive Gaussian pulse (width 10 beads,
velocity ``c eps g`` with the matching strain) starts at bead 60; the momentum centroid
``sum(x v) / sum(v)`` is fitted against time while the pulse is inside the chain. Lattice
dispersion slows it by ``1 / (16 w^2)`` = 0.06 % for w = 10 beads.
(b) Modes: 20 beads displaced in the sum of modes 1, 2, 3; each modal coordinate is a cosine,
its period is measured from zero crossings over 4 periods. Velocity Verlet raises the frequency
by ``(omega dt)^2 / 24``: +0.03, +0.10, +0.23 % for modes 1-3 at this dt (what is measured).
(c) Energy: the pulse chain runs 40 000 steps (pulse reflected ~40 times at the free ends);
drift = |mean E of the last 1000 steps - mean E of the first 1000| / E.

Tolerance: 0.5 % on c and on each omega_n; energy drift 1e-4.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ...engine import Engine
from .common import (
    E_CARBON,
    RHO_CARBON,
    CaseResult,
    ChainSet,
    Check,
    D,
    contact,
    fibre,
    lammps_case,
    record,
)
from .plots import line_plot

__all__ = ["run"]

CASE = "1 waves"
SPEED_TOLERANCE = 0.005
MODE_TOLERANCE = 0.005
DRIFT_TOLERANCE = 1e-4


def _chain(n: int, displacement: np.ndarray) -> tuple:
    """Model of a straight free chain of ``n`` beads along x, displaced by (n,) um."""
    spacing = D / 2.0
    atom, bond, density = fibre("carbon", D, spacing, E_CARBON, RHO_CARBON)
    chains = ChainSet()
    chains.add_type(atom, bond, density)
    x = np.arange(n) * spacing + displacement
    chains.add(np.column_stack([x, np.zeros(n), np.zeros(n)]), 0)
    model = chains.model([-20 * spacing, -4 * D, -4 * D], [(n + 20) * spacing, 4 * D, 4 * D])
    k = 2.0 * bond.k
    mass = float(model.mass[0])
    return model, k, mass, spacing


def _pulse(n: int, start: float, width: float, strain: float) -> np.ndarray:
    """(n,) um displacement of a compressive Gaussian pulse of peak ``strain``, centred on bead
    ``start``, ``width`` beads wide (the integral of the strain ``-eps g``)."""
    spacing = D / 2.0
    j = np.arange(n)
    erf = np.vectorize(math.erf)
    # right-going wave u = f(x - c t): strain u' = -eps g, velocity -c u' = c eps g
    displacement = -strain * spacing * width * math.sqrt(math.pi / 2.0)
    return displacement * (1.0 + erf((j - start) / (width * math.sqrt(2.0))))


def _track(
    lmp: Engine, rest: np.ndarray, dt: float, steps: int, every: int
) -> tuple[list[float], list[float]]:
    """Run ``steps`` steps, every ``every`` steps reading the momentum centroid
    ``sum(x v) / sum(v)`` (um) over the (n,) rest positions ``rest`` (um); returns the times
    (us) and the centroids."""
    times, centroid = [], []
    for step in range(0, steps, every):
        velocity = lmp.gather("v", 3)[:, 0]
        times.append(step * dt)
        centroid.append(float(np.sum(rest * velocity) / np.sum(velocity)))
        lmp.command(f"run {every} pre no post no")
    return times, centroid


def _flight_plot(
    workdir: Path, times: np.ndarray, centroid: np.ndarray, origin: float, speed: float
) -> Path:
    """Plot the centroid (um) against time (us), each (samples,), with ``origin + c t`` (um)."""
    return line_plot(
        workdir / "waves_flight.png",
        [
            (times * 1e3, centroid / 1e3, "momentum centroid"),
            (
                times * 1e3,
                (origin + speed * times) / 1e3,
                f"c = sqrt(E/rho) = {speed:.0f} m/s",
            ),
        ],
        "time (ns)",
        "position (mm)",
        "Case 1a: axial pulse time of flight",
    )


def _time_of_flight(workdir: Path, full: bool) -> tuple[list[Check], Path]:
    """Pulse speed and energy drift (sub-cases a and c)."""
    n, start, width, strain = 300, 60.0, 10.0, 1e-4
    speed = math.sqrt(E_CARBON / RHO_CARBON)
    spacing = D / 2.0
    model, k, mass, _ = _chain(n, _pulse(n, start, width, strain))
    dt = 0.5 * math.sqrt(mass / k)
    law = contact(k / 10.0, mass, 0.0)
    every, chunk = 4, 1000
    values = {
        "pulse_amplitude": speed * strain,
        "pulse_centre": start * spacing,
        "pulse_width": width * spacing,
        "chunk": chunk,
    }
    rest = np.arange(n) * spacing
    with lammps_case(
        workdir / "flight", "validation/waves.lmp.j2", model, dt, law, **values
    ) as lmp:
        travel_steps = int((n - start - 5 * width) * spacing / speed / dt)
        times, centroid = _track(lmp, rest, dt, travel_steps, every)
        # energy: align with the averaging chunks, run on with the pulse bouncing at the ends
        lmp.command(f"run {chunk - lmp.step % chunk}")
        energy = record(lmp, "energy", 2, chunk, 40 if full else 20)[:, 0]
    times, centroid = np.array(times), np.array(centroid)
    inside = (centroid > (start + 2 * width) * spacing) & (centroid < (n - 1 - 4 * width) * spacing)
    measured = float(np.polyfit(times[inside], centroid[inside], 1)[0])
    drift = float(abs(energy[-1] - energy[0]) / energy[0])
    plot = _flight_plot(workdir, times, centroid, start * spacing, speed)
    checks = [
        Check(CASE, "wave speed c (m/s)", "c = sqrt(E/rho)", speed, measured, SPEED_TOLERANCE),
        Check(
            CASE,
            f"energy drift, {len(energy) * chunk} steps",
            "dE/E = 0 (no damping)",
            0.0,
            drift,
            DRIFT_TOLERANCE,
            "absolute",
        ),
    ]
    return checks, plot


def _modes(workdir: Path) -> tuple[list[Check], Path]:
    """Lowest modes of a free-free chain of 20 beads (sub-case b)."""
    n, modes, amplitude = 20, np.array([1, 2, 3]), 1e-3 * D
    shapes = np.cos(np.pi * np.outer(modes, np.arange(n) + 0.5) / n)  # (3, n)
    model, k, mass, spacing = _chain(n, amplitude * shapes.sum(axis=0))
    dt = 0.5 * math.sqrt(mass / k)
    law = contact(k / 10.0, mass, 0.0)
    omega = 2.0 * math.sqrt(k / mass) * np.sin(modes * np.pi / (2 * n))
    steps = int(4 * 2 * math.pi / omega[0] / dt) + 2
    rest = np.arange(n) * spacing
    history = np.empty((steps, len(modes)))
    values = {"pulse_amplitude": 0.0, "pulse_centre": 0.0, "pulse_width": 1.0, "chunk": 1}
    with lammps_case(workdir / "modes", "validation/waves.lmp.j2", model, dt, law, **values) as lmp:
        for step in range(steps):
            u = lmp.gather("x", 3)[:, 0] - rest
            history[step] = shapes @ u / np.sum(shapes**2, axis=1)
            lmp.command("run 1 pre no post no")
    time = np.arange(steps) * dt
    measured = np.array([_frequency(time, history[:, i]) for i in range(len(modes))])
    plot = line_plot(
        workdir / "waves_modes.png",
        [(time * 1e3, history[:, i] / amplitude, f"mode {m}") for i, m in enumerate(modes)],
        "time (ns)",
        "modal amplitude / initial",
        "Case 1b: free-free chain of 20 beads, modes 1-3",
    )
    checks = [
        Check(
            CASE,
            f"mode {m} omega (rad/us)",
            "omega_n = 2 sqrt(k/m) sin(n pi/2N)",
            float(w),
            float(mw),
            MODE_TOLERANCE,
        )
        for m, w, mw in zip(modes, omega, measured, strict=True)
    ]
    return checks, plot


def _frequency(time: np.ndarray, signal: np.ndarray) -> float:
    """Angular frequency from the linearly interpolated zero crossings of a cosine, rad/us."""
    sign = np.signbit(signal)
    i = np.nonzero(sign[1:] != sign[:-1])[0]
    crossings = time[i] - signal[i] * (time[i + 1] - time[i]) / (signal[i + 1] - signal[i])
    half_periods = np.diff(crossings)
    return float(np.pi / half_periods.mean())


def run(workdir: Path, full: bool = False) -> CaseResult:
    """Run case 1 in ``workdir``; returns its rows and plots."""
    flight, flight_plot = _time_of_flight(workdir, full)
    modes, modes_plot = _modes(workdir)
    return CaseResult(CASE, [flight[0], *modes, flight[1]], [flight_plot, modes_plot])
