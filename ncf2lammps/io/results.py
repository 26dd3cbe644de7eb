"""results.h5: one group per scene, 1-D float64 datasets of equal length, scalar attributes.

Names follow the contract in DESIGN.md section 4. A group carries ``complete = False`` until its
scene finishes; the file's root ``complete`` is set last, so a killed run never leaves a file
that looks complete.
"""

from __future__ import annotations

import os
from pathlib import Path

import h5py
import numpy as np

__all__ = ["mark_complete", "read_results", "update_root", "write_root", "write_scene"]


def write_root(path: str | os.PathLike, attrs: dict) -> None:
    """Create (or truncate) the file with its root attributes; ``complete`` starts False."""
    with h5py.File(path, "w") as fh:
        for key, value in attrs.items():
            fh.attrs[key] = value
        fh.attrs["complete"] = False


def write_scene(
    path: str | os.PathLike,
    scene: str,
    attrs: dict,
    datasets: dict[str, np.ndarray] | None = None,
    complete: bool = True,
) -> None:
    """Write one scene's group (replacing an older one); datasets must share one length."""
    datasets = datasets or {}
    lengths = {len(np.ravel(v)) for v in datasets.values()}
    if len(lengths) > 1:
        raise ValueError(f"/{scene}: datasets of unequal length {sorted(lengths)}")
    with h5py.File(path, "a") as fh:
        if scene in fh:
            del fh[scene]
        group = fh.create_group(scene)
        for name, values in datasets.items():
            group.create_dataset(name, data=np.asarray(values, dtype=np.float64).ravel())
        for key, value in attrs.items():
            group.attrs[key] = value
        group.attrs["complete"] = complete


def mark_complete(path: str | os.PathLike) -> None:
    """Set the root ``complete`` flag once every scene has been written."""
    with h5py.File(path, "a") as fh:
        fh.attrs["complete"] = True


def read_results(path: str | os.PathLike) -> dict:
    """{"attrs": {...}, scene: {"attrs": {...}, dataset: array}} of a results file."""
    out: dict = {}
    with h5py.File(Path(path), "r") as fh:
        out["attrs"] = dict(fh.attrs)
        for name, group in fh.items():
            out[name] = {"attrs": dict(group.attrs)}
            out[name].update({k: group[k][()] for k in group})
    return out


def update_root(path: str | os.PathLike, attrs: dict) -> None:
    """Set root attributes of an existing file and mark it incomplete (its groups are kept)."""
    with h5py.File(path, "a") as fh:
        for key, value in attrs.items():
            fh.attrs[key] = value
        fh.attrs["complete"] = False
