"""The bundle transverse law: a chain is a bundle of filaments that packs tighter under load.

The law is the aligned fibre bed of Gutowski, Morigaki and Cai (J. Compos. Mater. 21, 1987,
172-188), the pressure a bed of wavy filaments carries at fibre volume fraction ``V``::

    P(V) = A_s (sqrt(V / V0) - 1) / (sqrt(Va / V) - 1)^4,    A_s = 3 pi E / beta^4,

``E`` the filaments' axial modulus, ``beta`` the span / amplitude ratio of their waviness, ``V0``
the Vf at which the bed starts to carry load and ``Va`` the largest Vf (packing limit).

Mapping onto the chains (docs/contact.md): two bundle chains of contact diameter ``D`` pressed
together to an axis distance ``h`` compress each other's filaments across the contact as a bed
is compressed through its thickness: the internal Vf is ``V = V_h D / h`` (a bed's Vf goes as
one over its thickness), and the pair carries the bed's pressure over its projected width ``D``.
A regular stack of such chains at pitch ``h`` (``D`` apart across) is the bed ``P(V_h D / h)``.
LAMMPS's granular pair styles carry Coulomb friction on their own normal force and offer linear
(hooke) and Hertz normal laws between beads; the bed law is mapped onto the Hertz bead contact
``F = 4/3 E* sqrt(D / 4) delta^(3/2)``. Beads of two chains meet at every axial offset, so the
chains' law is the bead law averaged over the offset ``xi`` of the partner beads (spacing
``s``): per unit length and width the stack pressure is

    P(h) = (1 / (D s^2)) int F(D - r) h / r dxi,   r = sqrt(h^2 + xi^2),
         = 2/3 E* (D / s)^2 I(1 - h / D),   I(x) = int (1 - rho)_+^(3/2) (1 - x) / rho dzeta,

``rho = sqrt((1 - x)^2 + zeta^2)``, which starts as ``I = 3 pi sqrt(2) / 8 x^2``. Its two
constants, the onset ``V_h`` (the bundle's free internal Vf, so ``D = D_solid / sqrt(V_h)``)
and ``c = 2/3 E* (D / s)^2``, are fitted to the bed law by least squares in ``log P`` over
:data:`FIT_WINDOW_KPA`. The fit error over the window is part of the result
(:attr:`BundleLaw.max_error`): no fixed-exponent contact follows the bed law's stiffening
towards ``Va``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .. import units

__all__ = [
    "FIT_WINDOW_KPA",
    "BundleLaw",
    "FibreBed",
    "bundle_law",
    "chain_fill",
    "offset_average",
    "spec_bundle_law",
]

#: Pressures (kPa) over which the Hertz contact is fitted to the bed law: the validation's
#: stack range, which spans the compaction test's 1 to 18 kPa.
FIT_WINDOW_KPA = (1.0, 100.0)

#: Points of the fit, log-spaced in pressure over the window.
_FIT_POINTS = 200


@dataclass(frozen=True)
class FibreBed:
    """Gutowski's aligned fibre bed: ``modulus`` E (kPa), ``waviness_ratio`` beta, ``free_fvf``
    V0 and ``max_fvf`` Va."""

    modulus: float
    waviness_ratio: float
    free_fvf: float
    max_fvf: float

    @property
    def stiffness(self) -> float:
        """A_s = 3 pi E / beta^4 (kPa)."""
        return 3.0 * np.pi * self.modulus / self.waviness_ratio**4

    def pressure(self, fvf):
        """Bed pressure (kPa) at fibre volume fraction ``fvf`` (array, in (V0, Va)); 0 below V0."""
        fvf = np.asarray(fvf, dtype=float)
        rise = np.sqrt(np.maximum(fvf, self.free_fvf) / self.free_fvf) - 1.0
        return self.stiffness * rise / (np.sqrt(self.max_fvf / fvf) - 1.0) ** 4

    def fvf(self, pressure) -> np.ndarray:
        """Fibre volume fraction at ``pressure`` (kPa, array > 0): the inverse of
        :meth:`pressure`, by bisection (the law rises monotonically from V0 to Va)."""
        pressure = np.asarray(pressure, dtype=float)
        low = np.full(pressure.shape, self.free_fvf)
        high = np.full(pressure.shape, self.max_fvf)
        for _ in range(80):
            middle = 0.5 * (low + high)
            below = self.pressure(middle) < pressure
            low = np.where(below, middle, low)
            high = np.where(below, high, middle)
        return 0.5 * (low + high)


def offset_average(overlap):
    """I(x) of the offset-averaged Hertz bead contact (dimensionless, array ``x = 1 - h/D`` in
    [0, 1)), by 64-point Gauss-Legendre quadrature over the contact's axial extent."""
    x = np.clip(np.asarray(overlap, dtype=float), 0.0, 1.0 - 1e-12)
    h = 1.0 - x
    half = np.sqrt(np.maximum(1.0 - h**2, 0.0))
    nodes, weights = np.polynomial.legendre.leggauss(64)
    zeta = half[..., None] * nodes
    rho = np.sqrt(h[..., None] ** 2 + zeta**2)
    integrand = np.maximum(1.0 - rho, 0.0) ** 1.5 * h[..., None] / rho
    return half * np.sum(weights * integrand, axis=-1)


#: Tabulated I(x) on a log grid, for the fit and its inverse.
_X_TABLE = np.geomspace(1e-6, 0.95, 4000)
_LOG_I_TABLE = np.log(offset_average(_X_TABLE))


def _log_i(overlap: np.ndarray) -> np.ndarray:
    return np.interp(np.log(overlap), np.log(_X_TABLE), _LOG_I_TABLE)


@dataclass(frozen=True)
class BundleLaw:
    """The bed law mapped onto the offset-averaged Hertz contact between bundle chains.

    Attributes:
        bed: the fibre bed law.
        onset_fvf: V_h, the bundle's internal Vf at first contact (the chain's fill).
        coefficient: c (kPa) of the stack pressure ``c I(1 - h / D)``.
        max_error: largest |P_chains / P_bed - 1| over :data:`FIT_WINDOW_KPA`.
    """

    bed: FibreBed
    onset_fvf: float
    coefficient: float
    max_error: float

    def stack_pressure(self, pitch_ratio):
        """Pressure (kPa) of the stack at pitch ``h / D`` (array)."""
        overlap = np.maximum(1.0 - np.asarray(pitch_ratio, dtype=float), 0.0)
        return self.coefficient * offset_average(overlap)

    def effective_modulus(self, spacing_ratio: float) -> float:
        """E* (kPa) of the bead contact ``F = 4/3 E* sqrt(R* delta) delta`` (R* = D / 4) at bead
        spacing ``s = spacing_ratio D``: E* = 3/2 c (s / D)^2."""
        return 1.5 * self.coefficient * spacing_ratio**2

    def overlap_at(self, pressure: float) -> float:
        """Overlap ``1 - h / D`` of the stack at ``pressure`` (kPa)."""
        target = np.log(pressure / self.coefficient)
        return float(np.exp(np.interp(target, _LOG_I_TABLE, np.log(_X_TABLE))))


def spec_bundle_law(spec) -> BundleLaw | None:
    """The bundle law of a :class:`~ncf2lammps.spec.FabricSpec` (None unless
    ``contact.normal_model = "bundle"``): the bed of its plies' fibre at the contact's constants."""
    contact = spec.contact
    if contact.normal_model != "bundle":
        return None
    modulus = units.to_micro(spec.plies[0].E_GPa, "GPa")
    bed = FibreBed(
        modulus, contact.bundle_waviness_ratio, contact.bundle_free_fvf, contact.bundle_max_fvf
    )
    return bundle_law(bed)


def chain_fill(spec) -> float:
    """Internal fibre Vf of the chains: the bundle law's onset, else
    ``discretisation.chain_internal_fvf``."""
    law = spec_bundle_law(spec)
    return spec.discretisation.chain_internal_fvf if law is None else law.onset_fvf


@lru_cache(maxsize=64)
def bundle_law(bed: FibreBed) -> BundleLaw:
    """Fit the chains' contact (onset V_h and coefficient c) to ``bed`` over the window.

    For each trial onset on a grid below the bed's Vf at the window's low end, ``log c`` is the
    mean of ``log P - log I(x)`` with ``x = 1 - V_h / V``; the onset of the smallest rms error
    in ``log P`` wins.
    """
    pressure = np.geomspace(*FIT_WINDOW_KPA, _FIT_POINTS)
    fvf = bed.fvf(pressure)
    onsets = np.linspace(0.5 * bed.free_fvf, fvf[0], 2001)[:-1]
    log_i = _log_i(1.0 - onsets[:, None] / fvf[None, :])
    log_c = np.mean(np.log(pressure)[None, :] - log_i, axis=1)
    residual = log_c[:, None] + log_i - np.log(pressure)[None, :]
    best = int(np.argmin(np.sqrt(np.mean(residual**2, axis=1))))
    error = float(np.max(np.abs(np.expm1(residual[best]))))
    return BundleLaw(bed, float(onsets[best]), float(np.exp(log_c[best])), error)
