"""The bundle transverse law: a chain is a bundle of filaments that packs tighter under load.

The law is the aligned fibre bed of Gutowski, Morigaki and Cai (J. Compos. Mater. 21, 1987,
172-188), the pressure a bed of wavy filaments carries at fibre volume fraction ``V``::

    P(V) = A_s (sqrt(V / V0) - 1) / (sqrt(Va / V) - 1)^4,    A_s = 3 pi E / beta^4,

``E`` the filaments' axial modulus, ``beta`` the span / amplitude ratio of their waviness, ``V0``
the Vf at which the bed starts to carry load and ``Va`` the largest Vf (packing limit).

Mapping onto the chains (docs/contact.md): two bundle chains pressed together to an overlap
``delta`` compress each other's filaments across the contact as a bed is compressed through its
thickness, ``V = V_h / (1 - delta / D)`` (a bed's Vf goes as one over its thickness), and the
contact carries the bed's pressure over its projected area ``D s`` (chain diameter ``D``, bead
spacing ``s``). A regular stack of such chains at pitch ``h = D - delta`` is then the bed
``P(V_h D / h)``. LAMMPS's granular pair styles carry Coulomb friction on their own normal force
and offer two normal laws, linear (hooke) and ``delta^3/2`` (Hertz): the bed law is mapped onto a
Hertz contact ``P = c (delta / D)^(3/2)`` whose two constants, the onset ``V_h`` (the bundle's
free internal Vf, so ``D = D_solid / sqrt(V_h)``) and ``c``, are fitted to the bed law by least
squares in ``log P`` over :data:`FIT_WINDOW_KPA`. The fit error over the window is part of the
result (:attr:`BundleLaw.max_error`): the Hertz exponent cannot follow the bed law's stiffening
towards ``Va``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .. import units

__all__ = ["FIT_WINDOW_KPA", "BundleLaw", "FibreBed", "bundle_law", "chain_fill", "spec_bundle_law"]

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


@dataclass(frozen=True)
class BundleLaw:
    """The bed law mapped onto a Hertz contact between bundle chains.

    Attributes:
        bed: the fibre bed law.
        onset_fvf: V_h, the bundle's internal Vf at first contact (the chain's fill).
        coefficient: c (kPa) of the stack pressure ``c (delta / D)^(3/2)``.
        max_error: largest |P_hertz / P_bed - 1| over :data:`FIT_WINDOW_KPA`.
    """

    bed: FibreBed
    onset_fvf: float
    coefficient: float
    max_error: float

    def stack_pressure(self, pitch_ratio):
        """Pressure (kPa) of the Hertz stack at pitch ``h / D`` (array, <= 1)."""
        overlap = np.maximum(1.0 - np.asarray(pitch_ratio, dtype=float), 0.0)
        return self.coefficient * overlap**1.5

    def effective_modulus(self, spacing_ratio: float) -> float:
        """E* (kPa) of the Hertz contact ``F = 4/3 E* sqrt(R* delta) delta`` between two beads of
        diameter D at spacing ``s = spacing_ratio D``: with R* = D / 4 and F = P D s, E* = 3/2 c
        s / D."""
        return 1.5 * self.coefficient * spacing_ratio

    def overlap_at(self, pressure: float) -> float:
        """Overlap delta / D of the Hertz stack at ``pressure`` (kPa)."""
        return float((pressure / self.coefficient) ** (2.0 / 3.0))


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
    """Fit the Hertz contact (onset V_h and coefficient c) to ``bed`` over the window.

    For each trial onset on a grid below the bed's Vf at the window's low end, ``log c`` is the
    mean of ``log P - 3/2 log(delta / D)`` with ``delta / D = 1 - V_h / V``; the onset of the
    smallest rms error in ``log P`` wins.
    """
    pressure = np.geomspace(*FIT_WINDOW_KPA, _FIT_POINTS)
    fvf = bed.fvf(pressure)
    onsets = np.linspace(0.5 * bed.free_fvf, fvf[0], 2001)[:-1]
    overlap = 1.0 - onsets[:, None] / fvf[None, :]
    log_c = np.mean(np.log(pressure)[None, :] - 1.5 * np.log(overlap), axis=1)
    residual = log_c[:, None] + 1.5 * np.log(overlap) - np.log(pressure)[None, :]
    best = int(np.argmin(np.sqrt(np.mean(residual**2, axis=1))))
    error = float(np.max(np.abs(np.expm1(residual[best]))))
    return BundleLaw(bed, float(onsets[best]), float(np.exp(log_c[best])), error)
