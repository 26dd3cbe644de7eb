"""Analytical validation suite: small cells run in LAMMPS and compared with physical laws.

Cases (docs/design.md §9), one module each; every module's docstring states its law, configuration,
tolerance and source, and its ``run(workdir, full)`` returns a
:class:`~ncf2lammps.scenes.validation.common.CaseResult`. :func:`run_validation` runs a selection,
prints the table and writes ``<output>/validation.md`` with the plots.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Sequence
from pathlib import Path

from ...spec import SpecError
from . import bundle, capstan, crossover, hertz, packing, shear, sliding, udbed, waves
from .common import CaseResult, Check
from .report import table_lines, write_markdown

__all__ = ["CASES", "FAST", "CaseResult", "Check", "run_case", "run_validation"]

#: Case name -> module with ``run(workdir, full)``.
CASES = {
    "waves": waves,
    "hertz": hertz,
    "sliding": sliding,
    "capstan": capstan,
    "shear": shear,
    "crossover": crossover,
    "packing": packing,
    "bundle": bundle,
    "udbed": udbed,
}
#: Cases of the fast subset (``full=False`` runs each of them in its short form).
FAST = tuple(CASES)


def run_case(name: str, output: Path, full: bool = False) -> CaseResult:
    """Run one case in ``output/<name>``, timing it."""
    start = time.perf_counter()
    result = CASES[name].run(output / name, full=full)
    result.wall_s = time.perf_counter() - start
    return result


def run_validation(
    output_dir: str,
    full: bool = False,
    cases: Sequence[str] | None = None,
    docs_dir: str | None = None,
) -> int:
    """Run the cases (all with ``full``, else the fast forms), print and write the table.

    Writes ``<output_dir>/validation.md`` and the plots under ``<output_dir>/<case>/``; with
    ``docs_dir`` also ``<docs_dir>/validation.md`` with the plots copied to
    ``<docs_dir>/validation/`` (the committed copy). Returns 0 when every check passes, else 1.
    """
    names = list(cases) if cases else list(CASES if full else FAST)
    unknown = [n for n in names if n not in CASES]
    if unknown:
        raise SpecError("--case", unknown[0], f"must be one of {', '.join(CASES)}")
    output = Path(output_dir)
    output.mkdir(parents=True, exist_ok=True)
    results = []
    for name in names:
        print(f"running {name} ...", file=sys.stderr, flush=True)
        results.append(run_case(name, output, full))
    print("\n".join(table_lines(results)))
    docs = {r.case: CASES[n].__doc__ or "" for n, r in zip(names, results, strict=True)}
    report = write_markdown(results, docs, output / "validation.md")
    if docs_dir is not None:
        write_markdown(
            results, docs, Path(docs_dir) / "validation.md", Path(docs_dir) / "validation"
        )
    failed = sum(not c.passed for r in results for c in r.checks)
    print(f"{failed} of {sum(len(r.checks) for r in results)} checks failed; wrote {report}")
    return 1 if failed else 0
