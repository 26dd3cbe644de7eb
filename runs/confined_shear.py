"""Example experiment: the picture-frame shear of a manufactured cell between two frictionless
plates, to see whether the shear force is limited by the cell's loft; prints JSON.

    python runs/confined_shear.py prepare RUN OUT [--gap-um G] [--squeeze-speed-m-s V]
    cd OUT && mpiexec -n 2 lmp -in in.shear.lmp
    python runs/confined_shear.py report OUT RUN_FREE ... [--angles 10 20 30 40 44]

``prepare`` takes a finished manufacture (``RUN``: ``manufactured.restart`` and the rendered
decks ``decks/in.shear.lmp`` and ``decks/in.compaction.lmp`` of ``ncf2lammps run``) and writes
into ``OUT`` its shear deck with two plates added before the shear: planes at the manufactured
cell's lowest and highest bead surface, pressing with the compaction deck's plate laws
(``fix wall/gran/region``: the pairs' normal law; under the bundle law the fibre beads' and the
stitch beads' own, with the deck's groups for them) but with friction 0, so that they hold the
thickness without resisting the frame's in-plane motion. With ``--gap-um G`` the top plate first
descends at the squeeze speed to a gap of G um above the bottom plate and holds there for 20 %
of the descent's steps before the shear begins. The plates' pressures (kPa) and the cell's
thickness (um) are recorded with the shear's history in ``shear.plates.txt``.

``report`` reads shear folders (this experiment's, or the ``ncf2lammps run`` folder of a free
shear) and gives per angle the mean normalised force F_N (N/m) over the records within
+-0.5 deg, the force of the last record interval and, where plates are recorded, their mean
pressure over the same window.
"""

import argparse
import json
import math
import re
import sys
from pathlib import Path

import numpy as np

from ncf2lammps import units
from ncf2lammps.io.lammpslog import read_ave_time
from ncf2lammps.io.results import read_results

STAGE = "# stage: shear\n"
#: Share of the squeeze's steps the plates hold the gap before the shear.
HOLD_SHARE = 0.2


def _refuse(message: str) -> None:
    """Bad input: one line on stderr, exit 2."""
    print(f"confined_shear: {message}", file=sys.stderr)
    sys.exit(2)


#: A compaction plate: ``fix wall_top<suffix> <group> wall/gran/region <law> region plate_top``.
_PLATE = re.compile(
    r"^fix\s+wall_top(\S*)\s+(\S+)\s+wall/gran/region\s+(.+?)\s+region plate_top\b", re.M
)


def _wall_laws(compaction_deck: str) -> tuple[list[str], list[tuple[str, str, str]]]:
    """The compaction plates' group definitions and their (suffix, group, ``wall/gran/region``
    arguments) with the friction set to 0."""
    plates = _PLATE.findall(compaction_deck)
    if not plates:
        _refuse("no plate_top wall in decks/in.compaction.lmp")
    laws = []
    for suffix, group, law in plates:
        frictionless, count = re.subn(r"(tangential \S+ \S+ \S+) \S+", r"\1 0.0", law, count=1)
        if count != 1:
            _refuse("a plate law has no 'tangential MODEL kt xgammat mu' part")
        laws.append((suffix, group, frictionless))
    groups = {group for _, group, _ in laws} - {"all"}
    definitions = [
        line
        for line in compaction_deck.splitlines()
        if line.startswith("group ") and line.split()[1] in groups
    ]
    return definitions, laws


def _plates(
    walls: tuple[list[str], list[tuple[str, str, str]]],
    gap: float | None,
    thickness: float,
    speed: float,
    dt: float,
) -> str:
    """Deck lines: the two plates of :func:`_wall_laws` ``walls`` (and the squeeze from the
    manufactured ``thickness`` to ``gap`` um at ``speed`` um/us)."""
    definitions, laws = walls
    lines = [
        "# Confining plates: frictionless, the compaction deck's normal law.",
        "run             0",
        "variable        plate_lo equal $(c_bottom)",
        "variable        plate_hi equal $(c_top)",
    ]
    if gap is None:
        lines.append("variable        zshift equal 0.0")
    else:
        lines += [
            f"variable        travel equal $({gap!r}+v_plate_lo-v_plate_hi)",
            "variable        squeeze_start equal $(step)",
            f"variable        descent equal -{speed!r}*(step-v_squeeze_start)*dt",
            "variable        zshift equal ternary(v_descent<v_travel,v_travel,v_descent)",
        ]
    lines += [
        "region          plate_top plane 0.0 0.0 ${plate_hi} 0.0 0.0 -1.0"
        " move NULL NULL v_zshift units box",
        "region          plate_bottom plane 0.0 0.0 ${plate_lo} 0.0 0.0 1.0 units box",
    ]
    lines += definitions
    for name in ("top", "bottom"):
        for suffix, group, law in laws:
            wall = f"wall_{name}{suffix}"
            lines += [
                f"fix             {wall} {group} wall/gran/region {law} region plate_{name}"
                " contacts",
                f"compute         force_{name}{suffix} {group} reduce sum f_{wall}[4]",
            ]
    top = "+".join(f"c_force_top{suffix}" for suffix, _, _ in laws)
    bottom = "+".join(f"c_force_bottom{suffix}" for suffix, _, _ in laws)
    lines += [
        f"variable        ptop equal -({top})/(lx*ly)",
        f"variable        pbot equal ({bottom})/(lx*ly)",
        "variable        gap equal v_plate_hi+v_zshift-v_plate_lo",
    ]
    if gap is not None:
        lines += [
            "variable        load_rate_held equal $(v_load_rate)",
            "variable        load_rate internal 0.0",
            "thermo_style    custom step v_ptop v_pbot v_gap v_thickness ke pe",
            "thermo          10000",
        ]
        descent = math.ceil((thickness - gap) / speed / dt)
        lines += [
            "# The squeeze: the frame at rest while the top plate descends and holds.",
            f"run             {descent + math.ceil(HOLD_SHARE * descent)}",
            "variable        load_rate internal ${load_rate_held}",
        ]
    return "\n".join(lines) + "\n"


def prepare(run: Path, out: Path, gap: float | None, speed_m_s: float) -> dict:
    """Write ``out/in.shear.lmp`` and link the manufactured restart."""
    shear = run / "decks" / "in.shear.lmp"
    compaction = run / "decks" / "in.compaction.lmp"
    restart = run / "manufactured.restart"
    for path in (shear, compaction, restart, run / "results.h5"):
        if not path.is_file():
            _refuse(f"{path} not found (a finished `ncf2lammps run` folder)")
    deck = shear.read_text()
    if STAGE not in deck:
        _refuse(f"{shear} has no '{STAGE.strip()}' line")
    timestep = re.search(r"^timestep\s+(\S+)", deck, re.M)
    if timestep is None:
        _refuse(f"{shear} has no 'timestep' line")
    dt = float(timestep.group(1))
    speed = units.to_micro(speed_m_s, "m_s")
    attrs = read_results(run / "results.h5")["manufacture"]["attrs"]
    thickness = units.to_micro(float(attrs["thickness_mm"]), "mm")
    if gap is not None and gap >= thickness:
        _refuse(f"--gap-um {gap:g} is not below the cell's {thickness:.6g} um")
    block = _plates(_wall_laws(compaction.read_text()), gap, thickness, speed, dt)
    history = (
        f"fix             plates all ave/time 1 {_history_period(deck)} v_ptop v_pbot v_gap"
        ' v_thickness file shear.plates.txt format " %.15g"\n'
    )
    out.mkdir(parents=True, exist_ok=False)
    (out / "in.shear.lmp").write_text(deck.replace(STAGE, block + STAGE + history, 1))
    (out / "manufactured.restart").symlink_to(restart.resolve())
    return {"deck": str(out / "in.shear.lmp"), "thickness_um": thickness, "gap_um": gap}


def _history_period(deck: str) -> str:
    """``Nrepeat Nfreq`` of the shear's history fix, so the plate records align with it."""
    match = re.search(r"fix\s+history all ave/time 1 (\d+) (\d+)", deck)
    if match is None:
        _refuse("the shear deck has no 'fix history all ave/time 1 N N' line")
    return f"{match.group(1)} {match.group(2)}"


def _window_mean(angle: np.ndarray, value: np.ndarray, at: float) -> float | None:
    """Mean of ``value`` over the records within +-0.5 deg of ``at`` (None if none)."""
    inside = np.abs(angle - at) <= 0.5
    return float(value[inside].mean()) if inside.any() else None


def report(folder: Path, angles: list[float]) -> dict:
    """F_N (N/m) and plate pressures (kPa) around each angle of one shear folder."""
    history_file, box_file = folder / "shear.history.txt", folder / "shear.box.txt"
    if not history_file.is_file() or not box_file.is_file():
        _refuse(f"{folder} has no shear.history.txt and shear.box.txt")
    history, box = read_ave_time(history_file), read_ave_time(box_file)
    steps = np.intersect1d(history["TimeStep"], box["TimeStep"])
    fn = history["v_fn"][np.isin(history["TimeStep"], steps)] * 1e-3  # nN/um -> N/m
    angle = np.degrees(box["v_g"][np.isin(box["TimeStep"], steps)])
    result = {
        "folder": str(folder),
        "final_angle_deg": float(angle[-1]),
        "fn_last_interval_N_per_m": float(fn[-1]),
        "fn_window_mean_N_per_m": {f"{a:g}": _window_mean(angle, fn, a) for a in angles},
    }
    plates_file = folder / "shear.plates.txt"
    if plates_file.is_file():
        plates = read_ave_time(plates_file)
        rows = np.isin(plates["TimeStep"], steps)
        shared = np.isin(steps, plates["TimeStep"])
        pressure = 0.5 * (plates["v_ptop"][rows] + plates["v_pbot"][rows])
        result["plate_pressure_window_mean_kPa"] = {
            f"{a:g}": _window_mean(angle[shared], pressure, a) for a in angles
        }
        result["gap_um"] = float(plates["v_gap"][rows][-1])
        result["final_thickness_um"] = float(plates["v_thickness"][rows][-1])
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True)
    make = commands.add_parser("prepare", help="write the confined shear deck")
    make.add_argument("run", type=Path, help="finished ncf2lammps run folder")
    make.add_argument("out", type=Path, help="new folder for the deck")
    make.add_argument("--gap-um", type=float, default=None, help="squeeze to this gap (um)")
    make.add_argument("--squeeze-speed-m-s", type=float, default=0.17, help="m/s (default 0.17)")
    show = commands.add_parser("report", help="forces and plate pressures per angle")
    show.add_argument("folders", type=Path, nargs="+")
    show.add_argument("--angles", type=float, nargs="+", default=[10, 20, 30, 40, 44])
    args = parser.parse_args()
    if args.command == "prepare":
        if args.gap_um is not None and not args.gap_um > 0:
            _refuse("--gap-um must be > 0 (um)")
        if not args.squeeze_speed_m_s > 0:
            _refuse("--squeeze-speed-m-s must be > 0 (m/s)")
        if args.out.exists():
            _refuse(f"{args.out} exists; choose a new folder")
        print(json.dumps(prepare(args.run, args.out, args.gap_um, args.squeeze_speed_m_s)))
    else:
        print(json.dumps([report(f, args.angles) for f in args.folders], indent=1))


if __name__ == "__main__":
    main()
