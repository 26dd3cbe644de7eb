"""Per-ply packing of a state file: where the bed's thickness goes in shear.

For each fibre ply of a LAMMPS data file written by ncf2lammps:
- z extent of its bead centres (0.5 / 50 / 99.5th percentiles, um);
- its layer thickness h = z99.5 - z0.5 + d (um) and the chains' packing in that layer,
  (also over the 5-95th percentile layer, holding 90 % of the chain),
  phi = (chain length x pi d^2 / 4) / (cell area x h): the share of the layer the bundles'
  contact cylinders fill (a random packing of parallel rods jams near 0.8);
- its fibre-fibre contacts (beads of different chains closer than their contact diameter):
  contacts per bead and the mapped internal Vf of the bundle, V_h d / r (V_h the law's onset).

    python contacts.py V_h FILE [FILE ...]
"""

import sys

import numpy as np
from MDAnalysis.lib.distances import self_capped_distance
from MDAnalysis.lib.mdamath import triclinic_box

from ncf2lammps.io.datafile import read_data


def contacts(data, chosen):
    """Pairs (i, j, r) of beads in ``chosen`` of different chains closer than their mean d:
    the cell periodic in x and y (its tilt included), open in z."""
    pos = data.positions[chosen]
    mol = data.mol_id[chosen]
    diam = data.diameter[chosen]
    h = data.box.matrix
    bottom = pos[:, 2].min() - diam.max()
    height = 10.0 * (np.ptp(pos[:, 2]) + 2.0 * diam.max())  # no z image within reach
    box = triclinic_box(h[:, 0], h[:, 1], np.array([0.0, 0.0, height]))
    pairs, r = self_capped_distance(pos - [0.0, 0.0, bottom], diam.max(), box=box)
    i, j = pairs.T
    keep = (mol[i] != mol[j]) & (r < 0.5 * (diam[i] + diam[j]))
    return i[keep], j[keep], r[keep], diam


def report(path, onset):
    data = read_data(path)
    lx, ly = data.box.lengths[:2]
    area = lx * ly
    print(f"{path}: cell area {area / 1e6:.3f} mm2")
    for t, label in enumerate(data.atom_labels):
        if label.startswith("stitch"):
            continue
        chosen = np.flatnonzero(data.type_id == t)
        z = data.positions[chosen, 2]
        z0, z50, z1 = np.percentile(z, [0.5, 50, 99.5])
        d = float(np.median(data.diameter[chosen]))
        in_ply = np.isin(data.bonds[:, 0], chosen) & np.isin(data.bonds[:, 1], chosen)
        bond = data.box.minimum_image(
            data.positions[data.bonds[in_ply, 1]] - data.positions[data.bonds[in_ply, 0]]
        )
        length = np.linalg.norm(bond, axis=1).sum()
        layer = z1 - z0 + d
        phi = length * np.pi * d**2 / 4 / (area * layer)
        z5, z95 = np.percentile(z, [5, 95])
        phi90 = 0.9 * length * np.pi * d**2 / 4 / (area * (z95 - z5 + d))
        i, j, r, diam = contacts(data, chosen)
        internal = onset * 0.5 * (diam[i] + diam[j]) / r
        q = np.percentile(internal, [50, 90, 99]) if len(r) else [np.nan] * 3
        print(
            f"  {label:12s} z {z0:7.0f} / {z50:7.0f} / {z1:7.0f} um  layer {layer:6.0f} um"
            f"  phi {phi:.3f} (5-95 %: {phi90:.3f})  contacts/bead {2 * len(r) / len(chosen):.2f}"
            f"  internal Vf p50/p90/p99 {q[0]:.3f} / {q[1]:.3f} / {q[2]:.3f}"
        )


if __name__ == "__main__":
    onset = float(sys.argv[1])
    for path in sys.argv[2:]:
        report(path, onset)
