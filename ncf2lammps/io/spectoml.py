"""Write a resolved spec (every field, defaults filled in) back to TOML."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import Any

from ..spec import FabricSpec

__all__ = ["dumps_spec", "write_spec"]


def _value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ValueError(f"cannot write {value!r} to TOML")
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value)  # a JSON string is a valid TOML basic string
    if isinstance(value, tuple | list):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    raise TypeError(f"cannot write {type(value).__name__} to TOML")


def dumps_spec(spec: FabricSpec) -> str:
    """TOML text of the resolved spec; :func:`ncf2lammps.spec.load_spec` reads it back equal."""
    lines = ["# Resolved spec written by ncf2lammps: every field, defaults filled in.", ""]
    for key, table in spec.to_dict().items():
        rows = table if isinstance(table, list) else [table]
        for row in rows:
            lines.append(f"[[{key}]]" if isinstance(table, list) else f"[{key}]")
            lines += [f"{name} = {_value(v)}" for name, v in row.items()]
            lines.append("")
    return "\n".join(lines)


def write_spec(path: str | os.PathLike, spec: FabricSpec) -> Path:
    """Write :func:`dumps_spec` to ``path``."""
    path = Path(path)
    path.write_text(dumps_spec(spec))
    return path
