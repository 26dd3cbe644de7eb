"""The one table of unit conversions between engineering units and LAMMPS ``units micro``.

LAMMPS ``micro``: length um, mass pg, time us, force nN, pressure kPa, density pg/um^3 (= g/cm^3),
velocity um/us (= m/s), energy pg um^2/us^2 (= 1e-15 J). Spec files are written in engineering
units named in their keys (``gauge_mm``, ``E_GPa``); nothing else in the package converts units.
"""

from __future__ import annotations

import numpy as np

#: Value of one engineering unit expressed in the matching LAMMPS ``micro`` unit.
MICRO_PER_UNIT: dict[str, float] = {
    # length -> um
    "m": 1e6,
    "mm": 1e3,
    "um": 1.0,
    # mass -> pg
    "kg": 1e15,
    "g": 1e12,
    "pg": 1.0,
    # time -> us
    "s": 1e6,
    "ms": 1e3,
    "us": 1.0,
    # force -> nN
    "N": 1e9,
    "nN": 1.0,
    # pressure / modulus -> kPa
    "Pa": 1e-3,
    "kPa": 1.0,
    "MPa": 1e3,
    "GPa": 1e6,
    # density -> pg/um^3
    "g_cm3": 1.0,
    "kg_m3": 1e-3,
    # areal weight -> pg/um^2
    "g_m2": 1.0,
    # linear density -> pg/um (1 dtex = 1 g / 10 km)
    "dtex": 100.0,
    "tex": 1000.0,
    # stiffness, membrane force -> nN/um (= kPa um)
    "N_m": 1e3,
    # velocity -> um/us
    "m_s": 1.0,
    "um_s": 1e-6,
    "mm_min": 1e-3 / 60.0,
    # angular rate -> rad/us
    "deg_s": np.pi / 180.0 * 1e-6,
    # energy -> pg um^2/us^2
    "J": 1e15,
}


def to_micro(value, unit: str):
    """Convert ``value`` (scalar or array) from the engineering ``unit`` to LAMMPS ``micro``."""
    return value * MICRO_PER_UNIT[unit]


def from_micro(value, unit: str):
    """Convert ``value`` (scalar or array) from LAMMPS ``micro`` to the engineering ``unit``."""
    return value / MICRO_PER_UNIT[unit]
