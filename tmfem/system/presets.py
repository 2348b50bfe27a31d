"""Built-in systems of the dissertation, shipped as system files in ``presets/``.

Each preset carries the consistent values by default (corrected or reconstructed where the
dissertation's printed values contradict its own formulas, see ``docs/validation/errata.md``) and a
table ``[as_printed]`` with the values exactly as printed, merged in by
``load_preset(name, as_printed=True)``.
"""
from __future__ import annotations

import tomllib
from importlib import resources

from tmfem.errors import InputError
from tmfem.system.problem import deep_merge
from tmfem.system.spec import system_from_dict
from tmfem.system.system import System


def _preset_files() -> dict:
    root = resources.files("tmfem.system") / "presets"
    return {p.name[:-5]: p for p in root.iterdir() if p.name.endswith(".toml")}


def list_presets() -> list[str]:
    """Names of the built-in presets, sorted."""
    return sorted(_preset_files())


def preset_dict(name: str, as_printed: bool = False) -> dict:
    """The parsed system file of a preset, with ``[as_printed]`` merged in on request."""
    files = _preset_files()
    if name not in files:
        raise InputError(f"unknown preset {name!r}; expected one of {sorted(files)}")
    d = tomllib.loads(files[name].read_text())
    printed = d.pop("as_printed", {})
    return deep_merge(d, printed) if as_printed else d


def load_preset(name: str, as_printed: bool = False) -> System:
    """Load a built-in system; ``as_printed=True`` gives the dissertation's printed values."""
    suffix = " (as printed)" if as_printed else ""
    return system_from_dict(preset_dict(name, as_printed), where=f"preset {name}{suffix}")
