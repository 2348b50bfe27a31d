"""The public API: the names re-exported by ``tmfem`` and by each subpackage resolve to
the objects of their modules, and ``import tmfem`` stays light (tmfem._lazy)."""
import importlib
import pkgutil
import subprocess
import sys
import types
from pathlib import Path

import pytest

import tmfem

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ["tmfem"] + sorted(m.name for m in pkgutil.walk_packages(tmfem.__path__, "tmfem.") if m.ispkg
                              and not m.name.startswith(("tmfem.cli", "tmfem.reference.benchmarks")))


@pytest.mark.parametrize("package", PACKAGES)
def test_every_exported_name_is_an_object_of_its_module(package):
    """Each name of ``__all__`` is a class, function or constant (not a module: a function of
    the same name as a submodule would be shadowed by it), listed by ``dir``."""
    pkg = importlib.import_module(package)
    assert pkg.__doc__ and pkg.__doc__.strip(), f"{package}: no docstring"
    for name in pkg.__all__:
        value = getattr(pkg, name)
        assert not isinstance(value, types.ModuleType), f"{package}.{name} is a module"
        assert getattr(value, "__module__", package).startswith("tmfem"), f"{package}.{name}"
        assert name in dir(pkg)
        assert importlib.util.find_spec(f"{package}.{name}") is None, \
            f"{package}.{name}: also the name of a submodule"


def test_the_names_a_user_types():
    from tmfem.control.lpv.synthesis import synthesize_state_feedback
    from tmfem.models.com.linearize import linearize
    from tmfem.system.presets import load_preset
    assert tmfem.load_preset is load_preset and tmfem.linearize is linearize
    assert tmfem.synthesize_state_feedback is synthesize_state_feedback
    assert tmfem.control.lpv.synthesize_state_feedback is synthesize_state_feedback
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        tmfem.nothing


def test_import_tmfem_loads_no_heavy_dependency():
    code = ("import sys, tmfem; tmfem.System; "
            "print(sorted(m for m in ('scipy', 'casadi', 'cvxpy', 'pyvista', 'petsc4py', 'matplotlib', "
            "'control', 'gmsh', 'meshio') if m in sys.modules))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "[]"
