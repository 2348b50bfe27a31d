"""tmfem: modeling, analysis and deployment control of tensegrity-membrane systems.

The package follows the dissertation "Modeling and Control of Tensegrity-Membrane
Systems" (chapters 2-8). Every model is built from one :class:`System`::

    import tmfem
    system = tmfem.load_preset("1-4")            # or tmfem.load_system("my_system.toml")
    model = tmfem.ControlOrientedModel(system)   # or tmfem.MTCModel, tmfem.SBCModel
    lin = tmfem.linearize(model)                 # lin.ss: a python-control ss

The main names are re-exported here and from each subpackage, and imported on first use
(:mod:`tmfem._lazy`): ``import tmfem`` loads neither SciPy nor CasADi, cvxpy, pyvista or PETSc.
"""
from tmfem._lazy import lazy_exports

__version__ = "0.1.0"

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "System": "tmfem.system",
    "SymmetricConfig": "tmfem.system",
    "load_system": "tmfem.system",
    "load_preset": "tmfem.system",
    "list_presets": "tmfem.system",
    "MTCModel": "tmfem.models.mtc.model",
    "SBCModel": "tmfem.models.sbc.model",
    "ControlOrientedModel": "tmfem.models.com.model",
    "linearize": "tmfem.models.com.linearize",
    "simulate": "tmfem.simulation.driver",
    "ScipyBackend": "tmfem.solvers.backends",
    "get_backend": "tmfem.solvers.backends",
    "PetscBackend": "tmfem.solvers.petsc",
    "hinfsyn": "tmfem.control.linear.hinf_synthesis",
    "hinfsyn_state": "tmfem.control.linear.hinf_synthesis",
    "hinf_lmi": "tmfem.control.linear.hinf_lmi",
    "hinf_central": "tmfem.control.linear.hinf_central",
    "deployed_hinf": "tmfem.control.linear.deployed_design",
    "synthesize_state_feedback": "tmfem.control.lpv.synthesis",
    "design_output_feedback": "tmfem.control.lpv.output_feedback"
}, subpackages=("control", "design", "equilibrium", "errors", "fem", "io", "mesh", "models", "post", "reference",
                "simulation", "solvers", "system"))
