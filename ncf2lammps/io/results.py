"""results.h5: one group per scene, 1-D float64 datasets of equal length, scalar attributes.

Names follow the contract in docs/design.md section 4. A group carries ``complete = False``
until its scene finishes; the file's root ``complete`` is set last, so a killed run never leaves
a file that looks complete.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import h5py
import numpy as np

__all__ = [
    "ROOT_ATTRS",
    "ResultsFileError",
    "mark_complete",
    "read_results",
    "remove_groups",
    "update_root",
    "write_root",
    "write_scene",
]

#: Root attributes of a run's results.h5 (written first, by :func:`write_root`).
ROOT_ATTRS = ("ncf2lammps_version", "spec_toml", "n_atoms", "n_bonds", "complete")


class ResultsFileError(ValueError):
    """A results.h5 that cannot be read (missing, empty, not HDF5, truncated, corrupt) or is not
    a run's; ``str()`` is one line naming the file and the reason."""

    def __init__(self, path: str | os.PathLike, reason: str):
        self.path = Path(path)
        self.reason = reason
        super().__init__(f"{self.path}: {reason}")


def _h5_reason(err: BaseException) -> str:
    """The short cause inside an h5py message, e.g. ``truncated file: eof = 16000, ...``."""
    text = " ".join(str(err).split())
    inner = re.search(r"\(([^()]*)\)\s*$", text)
    return (inner.group(1) if inner else text)[:200] or type(err).__name__


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
    """{"attrs": {...}, scene: {"attrs": {...}, dataset: array}} of a results file.

    Raises :class:`ResultsFileError` if the file is missing, empty, not HDF5, truncated or
    corrupt, or breaks the layout the writers keep (:func:`_check_layout`; a run's file also
    carries :data:`ROOT_ATTRS`; scenes run on a bare built folder write only their groups).
    """
    path = Path(path)
    if path.is_dir():
        raise ResultsFileError(path, "is a folder, not a file")
    if not path.is_file():
        raise ResultsFileError(path, "no such file")
    if path.stat().st_size == 0:
        raise ResultsFileError(path, "empty file (a run stopped before writing it)")
    out: dict = {}
    try:
        with h5py.File(path, "r") as fh:
            out["attrs"] = dict(fh.attrs)
            for name, group in fh.items():
                if not isinstance(group, h5py.Group):
                    raise ResultsFileError(path, f"/{name} is not a scene group")
                out[name] = {"attrs": dict(group.attrs)}
                out[name].update({k: group[k][()] for k in group})
    except ResultsFileError:
        raise
    except (OSError, RuntimeError, KeyError, ValueError, TypeError) as err:
        raise ResultsFileError(path, f"unreadable HDF5 ({_h5_reason(err)})") from None
    _check_layout(path, out)
    return out


#: Root attributes and their types, where present.
_ROOT_TYPES = {
    "ncf2lammps_version": (str, bytes),
    "spec_toml": (str, bytes),
    "n_atoms": (int, np.integer),
    "n_bonds": (int, np.integer),
    "complete": (bool, np.bool_),
}


def _check_layout(path: Path, content: dict) -> None:
    """The layout :func:`write_root` and :func:`write_scene` keep: typed root attributes, a
    true/false ``complete`` in every group, 1-D float datasets of one length per group."""
    for key, kind in _ROOT_TYPES.items():
        if key in content["attrs"] and not isinstance(content["attrs"][key], kind):
            raise ResultsFileError(path, f"root attribute {key!r} is not a {_kind_name(kind)}")
    for name, group in content.items():
        if name == "attrs":
            continue
        if not isinstance(group["attrs"].get("complete", False), bool | np.bool_):
            raise ResultsFileError(path, f"/{name} attribute 'complete' is not true or false")
        lengths = set()
        for key, values in group.items():
            if key == "attrs":
                continue
            if np.ndim(values) != 1 or np.asarray(values).dtype.kind != "f":
                raise ResultsFileError(path, f"/{name}/{key} is not a 1-D float dataset")
            lengths.add(len(values))
        if len(lengths) > 1:
            raise ResultsFileError(path, f"/{name} holds datasets of unequal length")


def _kind_name(kind) -> str:
    first = kind[0] if isinstance(kind, tuple) else kind
    return {str: "text", int: "whole number", bool: "true or false"}[first]


def remove_groups(path: str | os.PathLike, names: list[str]) -> None:
    """Delete the groups ``names`` (those present) and mark the file incomplete."""
    with h5py.File(path, "a") as fh:
        for name in names:
            if name in fh:
                del fh[name]
        fh.attrs["complete"] = False


def update_root(path: str | os.PathLike, attrs: dict) -> None:
    """Set root attributes of an existing file and mark it incomplete (its groups are kept)."""
    with h5py.File(path, "a") as fh:
        for key, value in attrs.items():
            fh.attrs[key] = value
        fh.attrs["complete"] = False
