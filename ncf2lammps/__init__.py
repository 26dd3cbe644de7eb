"""ncf2lammps: digital-chain models of stitched non-crimp fabrics, run on LAMMPS.

Public surface for generate-and-run scripts::

    import ncf2lammps as n2l
    spec = n2l.load_spec("runs/hpt310-coarse/spec.toml")
    spec = spec.replace(discretisation={"chain_diameter_um": 150.0})
    model = n2l.build_model(spec)
    prepared = n2l.prepare(spec, model)  # + simulated model, time step, contact law: once
    n2l.build(prepared, "out/d150")      # model.data, spec.resolved.toml, decks/
    n2l.run(spec, "out/run")             # build, run the scenes; returns results.h5
"""

__version__ = "0.1.0"

from .model import Model, build_model
from .numerics import Prepared, prepare, time_step
from .orchestration.build import build
from .orchestration.run import copy_manufactured, run, run_scenes
from .spec import FabricSpec, SpecError, load_spec, spec_from_dict

__all__ = [
    "FabricSpec",
    "Model",
    "Prepared",
    "SpecError",
    "__version__",
    "build",
    "build_model",
    "copy_manufactured",
    "load_spec",
    "prepare",
    "run",
    "run_scenes",
    "spec_from_dict",
    "time_step",
]
