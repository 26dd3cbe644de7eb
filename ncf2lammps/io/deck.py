"""LAMMPS input decks rendered with Jinja2 from ``templates/`` (``StrictUndefined``).

Only typed, validated values reach a deck: numbers must be finite ints or floats, words must be
plain identifiers or paths without ``..`` (no spaces, quotes, ``$``, ``#`` or newlines), so nothing
read from a spec file can inject a LAMMPS command (LAMMPS has ``shell``). Scenes extend ``base.lmp.j2`` and
override only the blocks that differ.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import fields, is_dataclass
from pathlib import Path

import jinja2
import numpy as np

__all__ = ["DeckValueError", "render", "template_dir"]

_WORD = re.compile(r"^/?[A-Za-z0-9_][A-Za-z0-9_./+-]*$")


class DeckValueError(ValueError):
    """A value that may not be written into a LAMMPS deck."""


def template_dir() -> Path:
    """The templates folder: packaged copy when installed, the repository's otherwise."""
    here = Path(__file__).resolve().parent.parent
    for candidate in (here / "templates", here.parent / "templates"):
        if (candidate / "base.lmp.j2").is_file():
            return candidate
    raise FileNotFoundError("ncf2lammps templates not found (reinstall the package)")


def _num(value) -> str:
    """A finite number in full precision."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise DeckValueError(f"deck number expected, got {value!r}")
    if isinstance(value, int | np.integer):
        return str(int(value))
    if not math.isfinite(value):
        raise DeckValueError(f"deck number must be finite, got {value!r}")
    return repr(float(value))


def _word(value) -> str:
    """An identifier, or a relative or absolute path (the tool's own: a data file's folder)."""
    if not isinstance(value, str) or not _WORD.fullmatch(value) or ".." in value:
        raise DeckValueError(f"deck word must be an identifier or a plain path, got {value!r}")
    return value


def _check(value, where: str) -> None:
    """Reject anything that is not a number, a safe word, or a container of those."""
    if value is None or isinstance(value, bool):
        return
    if isinstance(value, int | float | np.integer | np.floating):
        _num(value)
    elif isinstance(value, str):
        _word(value)
    elif isinstance(value, Mapping):
        for key, item in value.items():
            _check(key, where)
            _check(item, f"{where}.{key}")
    elif isinstance(value, list | tuple):
        for i, item in enumerate(value):
            _check(item, f"{where}[{i}]")
    elif is_dataclass(value):
        for f in fields(value):
            _check(getattr(value, f.name), f"{where}.{f.name}")
    else:
        raise DeckValueError(f"{where}: type {type(value).__name__} cannot go into a deck")


def _environment() -> jinja2.Environment:
    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(template_dir())),
        undefined=jinja2.StrictUndefined,
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
        autoescape=False,
    )
    env.filters["num"] = _num
    env.filters["word"] = _word
    return env


def render(template: str, **values) -> str:
    """Render ``templates/<template>`` after checking every value (raises DeckValueError)."""
    for key, value in values.items():
        _check(value, key)
    return _environment().get_template(template).render(**values)
