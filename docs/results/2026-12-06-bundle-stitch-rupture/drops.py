"""Largest drops of F_N between consecutive shear records, with the stitch's mean tension.

Usage: python drops.py RUN/results.h5
"""

import sys

import h5py
import numpy as np

with h5py.File(sys.argv[1]) as f:
    g = f["shear"]
    angle, force = g["angle_deg"][:], g["force_N_per_m"][:]
    stitch_angle, stitch_mean = g["stitch_angle_deg"][:], g["stitch_tension_mean_N"][:]
change = np.diff(force) / force[:-1]
for i in sorted(np.argsort(change)[:6]):
    j = np.argmin(abs(stitch_angle - angle[i]))
    print(
        f"{angle[i]:5.2f} -> {angle[i + 1]:5.2f} deg  F_N {force[i]:6.1f} N/m"
        f"  {100 * change[i]:+5.1f} %  stitch {stitch_mean[j - 1]:.3f} -> {stitch_mean[j + 1]:.3f} N"
    )
