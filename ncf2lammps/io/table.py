"""Column tables as CSV (study.csv)."""

from __future__ import annotations

import csv
import os
from collections.abc import Sequence

__all__ = ["write_csv"]


def write_csv(path: str | os.PathLike, columns: dict[str, Sequence]) -> None:
    """Write equal-length columns with a header row; floats in 7 significant digits."""
    lengths = {len(v) for v in columns.values()}
    if len(lengths) > 1:
        raise ValueError(f"{path}: columns of unequal length {sorted(lengths)}")
    rows = zip(*columns.values(), strict=True)
    with open(path, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(columns)
        for row in rows:
            writer.writerow(f"{v:.7g}" if isinstance(v, float) else v for v in row)
