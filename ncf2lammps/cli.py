"""Command line: ``ncf2lammps check|build|run|export|report|validate|study``; thin, it parses
the arguments and calls the package.

Exit codes: 0 success; 2 bad input (one line naming the field, file or folder and what is
allowed or what to do: spec values, spec files, run folders, results.h5, options); 1 a failed
run (with a diagnosis) or a system error (one line).
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable

from . import __version__, units
from .engine import EngineError
from .geometry.bundle import FIT_WINDOW_KPA, spec_bundle_law
from .geometry.direction import lattice_direction
from .io.results import ResultsFileError
from .numerics import STABLE_FRACTION, perturbation, prepare, stitch_mass_balance
from .orchestration.build import OutputExistsError, build, check_ranks
from .orchestration.export import export
from .orchestration.folder import RunFolderError, check_output
from .orchestration.report import write_report
from .orchestration.run import run
from .scenes import SCENES, applicable_scenes, render_deck
from .spec import SpecError, load_spec


def _check(args) -> int:
    spec = load_spec(args.spec)
    prepared = prepare(spec)
    model, step, law, simulated = (
        prepared.model,
        prepared.time_step,
        prepared.contact,
        prepared.simulated,
    )
    lx, ly, _ = model.box.lengths
    lines = [
        f"spec          {args.spec}: {spec.name}",
        f"cell          {lx / 1e3:.4g} x {ly / 1e3:.4g} mm (x machine/0 deg, y 90 deg), periodic in x, y",
        f"beads         {model.n_atoms} atoms, {model.n_bonds} bonds",
    ]
    plies = iter(spec.plies)
    for t in model.atom_types:
        chains, beads = model.count(t.name)
        lines.append(f"  {t.name:<14}{chains:>6} chains {beads:>9} beads  d = {t.diameter:.4g} um")
        if t.role == "fibre":
            direction = lattice_direction(t.lattice, (lx, ly))
            lines.append(
                f"    angle {next(plies).angle_deg:g} deg requested, {t.angle_deg:.4f} deg"
                f" realised: lattice {direction.lattice}, chain {direction.chain_length / 1e3:.4g}"
                f" mm, strip {direction.period / 1e3:.4g} mm"
            )
    fibre_aw = model.areal_weight("fibre")
    lines += [
        f"areal weight  fibre {fibre_aw:.4g} g/m2, stitch {model.areal_weight('stitch'):.4g} g/m2",
        f"mat           thickness {model.mat_thickness / 1e3:.4g} mm at Vf {spec.mat.initial_fvf:g}",
    ]
    if len(model.needle_points):
        lines.append(
            f"needles       {len(model.needle_points)} per cell, diameter {model.needle_diameter:.4g} um,"
            f" lapping {spec.stitch.notation}"
        )
    for bond_type in simulated.bond_types:
        lines.append(
            f"  bond {bond_type.name:<20} K = {bond_type.k:.4g} nN/um  r0 = {bond_type.r0:.5g} um"
            f"  EA = {units.from_micro(bond_type.axial_stiffness, 'N'):.4g} N"
        )
    mass = simulated.mass
    numerics = spec.numerics
    stitch_share = mass[model.role_mask("stitch")].sum() / mass.sum()
    lines += [
        f"bead mass     {mass.min():.4g} .. {mass.max():.4g} pg (mass scaling {numerics.mass_scaling:g},"
        f" fibre stiffness scaling {numerics.fibre_stiffness_scaling:g}, stitch mass scaling"
        f" {numerics.stitch_mass_scaling:g}: stitch {100 * stitch_share:.3g} % of the mass)",
        f"contact       {law.model}: k_n = {units.from_micro(law.stiffness, 'N_m'):.4g} N/m, mu = {law.friction:g}",
    ]
    if law.stitch is not None:
        lines.append(
            f"  fibre-stitch {law.stitch.model}: k_n ="
            f" {units.from_micro(law.stitch.stiffness, 'N_m'):.4g} N/m (rigid stitch contacts)"
        )
    bundle = spec_bundle_law(spec)
    if bundle is not None:
        lo, hi = FIT_WINDOW_KPA
        lines.append(
            f"bundle law    Gutowski bed A_s = {bundle.bed.stiffness * 1e3:.4g} Pa, V0"
            f" {bundle.bed.free_fvf:g}, Va {bundle.bed.max_fvf:g} on Hertz: onset Vf"
            f" {bundle.onset_fvf:.4f}, E* = {law.normal / 2:.4g} kPa,"
            f" largest deviation {100 * bundle.max_error:.3g} % over {lo:g}-{hi:g} kPa"
        )
    lines.append("stability     sqrt(m/k) per limit (us):")
    for name, limit in sorted(step.limits.items(), key=lambda kv: kv[1]):
        lines.append(f"  {name:<28} {limit:.4g}")
    lines += [
        f"time step     dt = {step.dt:.4g} us = {step.fraction:g} x {step.critical:.4g} us ({step.governing})",
        f"margin        {step.margin:.3g} (stable up to {STABLE_FRACTION} sqrt(m/k); > 1 is safe)",
    ]
    balance = stitch_mass_balance(step)
    if balance > 1.25:
        lines.append(
            f"stitch        sets the step: numerics.stitch_mass_scaling ="
            f" {balance * numerics.stitch_mass_scaling:.3g} lifts its limits to the fibres'"
            f" (docs/performance.md)"
        )
    every = spec.output.checkpoint_every_steps
    intervals = ", ".join(
        f"{scene} every {render_deck(prepared, scene).checkpoint_interval(every):,}"
        for scene in applicable_scenes(spec)
    )
    lines.append(
        f"checkpoints   {intervals} steps (output.checkpoint_every_steps = {every:,} rounded up"
        " to each deck's recording period, docs/hpc.md)"
        if every
        else "checkpoints   none (output.checkpoint_every_steps = 0)"
    )
    replica = perturbation(spec, model)
    if replica is not None:
        lines.append(
            f"replica       numerics.perturbation_seed = {replica.seed}: each scene starts by"
            f" moving every bead by up to {replica.amplitude:.3g} um per axis (docs/study.md)"
        )
    print("\n".join(lines))
    return 0


def _build(args) -> int:
    spec = load_spec(args.spec)
    check_output(args.output, force=args.force)  # before the model is built
    result = build(spec, args.output, force=args.force)
    print(
        f"wrote {result.directory}: model.data ({result.model.n_atoms} atoms, "
        f"{result.model.n_bonds} bonds), spec.resolved.toml, decks/"
        + ", decks/".join(p.name for p in result.decks.values())
    )
    return 0


def _run(args) -> int:
    spec = load_spec(args.spec)
    if not args.resume:
        check_output(args.output, force=args.force)
    results = run(
        spec, args.output, scenes=args.scene, force=args.force, ranks=args.np, resume=args.resume
    )
    print(f"wrote {results}")
    return 0


def _export(args) -> int:
    spec = load_spec(args.spec)
    check_output(args.output, force=args.force)
    folder = export(spec, args.output, args.np, args.time, args.module or (), force=args.force)
    print(f"wrote {folder}: run it with: mpirun -np {args.np} lmp -in in.run_all.lmp")
    return 0


def _report(args) -> int:
    for path in write_report(args.directory):
        print(f"wrote {path}")
    return 0


def _study(args) -> int:
    from .orchestration.run import scenes_to_run
    from .orchestration.study import parse_vary, study

    spec = load_spec(args.spec)
    if not 0.0 < args.tolerance < 1.0:
        raise SpecError("--tolerance", args.tolerance, "must be in (0, 1)")
    check_ranks(args.np)
    vary = [parse_vary(text) for text in args.vary or []]
    if not vary:
        raise SpecError("--vary", None, "give at least one KNOB=V1,V2,...")
    scenes_to_run(spec, args.scene)
    check_output(args.output, study=True)  # study() checks every point, then makes the folder
    for path in study(spec, args.output, vary, args.scene, args.zip, args.tolerance, args.np):
        print(f"wrote {path}")
    return 0


def _validate(args) -> int:
    from .scenes.validation import run_validation

    check_output(args.output, force=True, make=True)
    return run_validation(args.output, full=args.full, cases=args.case)


class _Parser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one line (exit 2), like every bad input."""

    def error(self, message: str):
        text = " ".join(f"{self.prog}: error: {message} (see {self.prog} --help)".split())
        self.exit(2, text + "\n")


def _spec_and_output(command, output_help: str = "output folder (new or empty)") -> None:
    command.add_argument("spec", help="spec TOML file")
    command.add_argument("-o", "--output", required=True, help=output_help)


def _force(command) -> None:
    command.add_argument(
        "--force", action="store_true", help="replace a folder of ncf2lammps output"
    )


def _ranks(command, default: int, help_text: str) -> None:
    command.add_argument("--np", type=int, default=default, metavar="N", help=help_text)


def _model_verbs(verbs) -> None:
    """check, build, run, export: the verbs that make a model from a spec."""
    check = verbs.add_parser(
        "check", help="validate a spec; print sizes, stiffnesses and the time step"
    )
    check.add_argument("spec", help="spec TOML file")
    check.set_defaults(func=_check)
    build_cmd = verbs.add_parser(
        "build", help="write model.data, spec.resolved.toml and decks into a folder"
    )
    _spec_and_output(build_cmd)
    _force(build_cmd)
    build_cmd.set_defaults(func=_build)
    run_cmd = verbs.add_parser("run", help="build, then run scenes in order; write results.h5")
    _spec_and_output(run_cmd)
    run_cmd.add_argument(
        "--scene",
        action="append",
        choices=list(SCENES),
        help="scene to run (repeat; default: all the spec supports)",
    )
    _force(run_cmd)
    _ranks(run_cmd, 1, "MPI ranks (mpiexec; default 1)")
    run_cmd.add_argument(
        "--resume", action="store_true", help="continue a killed run in -o from its checkpoints"
    )
    run_cmd.set_defaults(func=_run)
    export_cmd = verbs.add_parser(
        "export", help="HPC bundle for plain `mpirun -np N lmp -in in.run_all.lmp`"
    )
    _spec_and_output(export_cmd)
    _ranks(export_cmd, 2, "MPI ranks in job.slurm (default 2)")
    export_cmd.add_argument(
        "--time", default="24:00:00", help="Slurm wall time [D-]HH:MM:SS (default 24:00:00)"
    )
    export_cmd.add_argument(
        "--module", action="append", help="module to load in job.slurm (repeat)"
    )
    _force(export_cmd)
    export_cmd.set_defaults(func=_export)


def _folder_verbs(verbs) -> None:
    """report, study, validate: the verbs that read or fill folders of runs."""
    report = verbs.add_parser("report", help="figures/ and summary.md from a run's results.h5")
    report.add_argument("directory", help="run folder with results.h5")
    report.set_defaults(func=_report)
    study_cmd = verbs.add_parser(
        "study", help="run scenes over a grid of numerical knobs; error against wall time"
    )
    _spec_and_output(study_cmd, "study folder (new or a study's)")
    study_cmd.add_argument(
        "--vary",
        action="append",
        metavar="KNOB=V1,V2,...",
        help="a knob and its values (repeat; e.g. shear.inertial_number=0.025,0.05)",
    )
    study_cmd.add_argument(
        "--zip", action="store_true", help="pair the --vary lists by position (default: product)"
    )
    study_cmd.add_argument(
        "--scene", action="append", choices=list(SCENES), help="scene to run (repeat; default: all)"
    )
    study_cmd.add_argument(
        "--tolerance", type=float, default=0.03, help="error tolerance (default 0.03)"
    )
    _ranks(study_cmd, 1, "MPI ranks per point (default 1)")
    study_cmd.set_defaults(func=_study)
    validate = verbs.add_parser(
        "validate", help="run the analytical validation cases; print and write the table"
    )
    validate.add_argument("-o", "--output", default="validation", help="folder for logs and plots")
    validate.add_argument(
        "--full", action="store_true", help="full forms (default: the fast form of every case)"
    )
    validate.add_argument("--case", action="append", help="run only this case (repeat)")
    validate.set_defaults(func=_validate)


def parser() -> argparse.ArgumentParser:
    """The argument parser (one sub-command per verb)."""
    top = _Parser(
        prog="ncf2lammps",
        description="Digital-chain models of stitched non-crimp fabrics on LAMMPS.",
    )
    top.add_argument("--version", action="version", version=f"ncf2lammps {__version__}")
    verbs = top.add_subparsers(dest="verb", required=True, metavar="VERB")
    _model_verbs(verbs)
    _folder_verbs(verbs)
    return top


def at_least_one(text: str) -> int:
    """An argparse type: a whole number >= 1 (repeats, chunks, ranks of a script)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: not a whole number") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value}: must be at least 1")
    return value


#: Errors of bad input: one line on stderr, exit 2.
INPUT_ERRORS = (SpecError, OutputExistsError, RunFolderError, ResultsFileError)


def _exit_code(prog: str, call: Callable[[], int | None]) -> int:
    """``call()``'s exit code (None: 0), or that of what it raised, printed on one line as
    ``<prog>: error: ...``: bad input (:data:`INPUT_ERRORS`) 2, a failed run or a system
    error 1."""
    try:
        return call() or 0
    except INPUT_ERRORS as err:
        print(f"{prog}: error: {err}", file=sys.stderr)
        return 2
    except EngineError as err:
        print(f"{prog}: run failed: {err}", file=sys.stderr)
        return 1
    except BrokenPipeError:
        # The reader of our output stopped (`ncf2lammps check SPEC | head`): no traceback, and
        # no second error when Python flushes stdout at exit.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    except OSError as err:  # the system refused (disk full, permissions): one line, not input
        where = f"{err.filename}: " if err.filename else ""
        print(" ".join(f"{prog}: error: {where}{err.strerror or err}".split()), file=sys.stderr)
        return 1


def script_main(main_function: Callable[[], None]) -> None:
    """Run a script's ``main_function`` and exit with the command line's codes and one-line
    messages (for the example scripts of runs/ and benchmarks/)."""
    sys.exit(_exit_code(os.path.basename(sys.argv[0]), main_function))


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``ncf2lammps`` console script."""
    args = parser().parse_args(argv)
    return _exit_code("ncf2lammps", lambda: args.func(args))


if __name__ == "__main__":
    sys.exit(main())
