"""System files in TOML: read, validate and write (round trip).

A file describes either a symmetric system (table ``[symmetric]``, eqs. 3.19-3.20) or a
general one (table ``[general]`` with the base nodes A_1j, bar lengths and q of eqs.
3.1-3.2, optionally a custom ``[[tendon]]`` list). Angles are given in degrees and named
so (``theta_deg``). A preset may carry a table ``[as_printed]`` whose entries override
the rest of the file when the dissertation's printed values are requested; see
:func:`tmfem.system.presets.load_preset`. Example::

    name = "1-4"
    N = 4
    [symmetric]
    theta_deg = [60.0]
    psi_deg = [10.0]
    r = [0.4286]
    l = [2.015]
    [membrane]
    r_mb = 1.4142
    E = 165e6
    nu = 0.34
    rho = 1400.0
    h = 51e-6
    [bar]
    E = 200e9
    rho = 7800.0
    d = 0.03
    [tendons.S]
    E = 2e9
    d = 0.6e-3
"""
from __future__ import annotations

import math
import re
import tomllib
from pathlib import Path

import numpy as np
import tomli_w

from tmfem.errors import InputError
from tmfem.resources import check_membrane_modes
from tmfem.system.coordinates import q_stages
from tmfem.system.geometry import SymmetricConfig, membrane_corners_regular
from tmfem.system.materials import BarSection, MembraneMaterial, TendonSection
from tmfem.system.problem import problem_from_dict
from tmfem.system.system import System
from tmfem.system.topology import Tendon
from tmfem.system.validate import (check_bounds, check_keys_used, check_stage_lists,
                                   check_tendon_list, read_bounded, system_name)

_TOP_KEYS = {"name", "description", "N", "deployable", "k_H", "notes", "symmetric", "general",
             "membrane", "bar", "tendons", "tendon", "rest_lengths", "printed", "as_printed",
             "monitor", "models", "control", "deployment", "lpv", "report", "packaged", "design"}
# Keys accepted inside each sub-table ([printed] and [rest_lengths] are free-form;
# [as_printed] is merged in before validation, see tmfem.system.presets.preset_dict).
_TABLE_KEYS = {
    "symmetric": {"theta_deg", "psi_deg", "sigma_deg", "z", "r", "l"},
    "general": {"base", "l", "q"},
    "membrane": {"E", "nu", "rho", "h", "yield_stress", "r_mb", "corners"},
    "bar": {"E", "rho", "d"},
    "tendons.*": {"E", "d", "rho", "yield_stress"},
    "tendon": {"name", "family", "stage", "j", "ends"},
    "monitor": {"nodes", "points"},
    "models.com": {"membrane_modes"},
}


def _check_keys(t: dict, kind: str, where: str) -> None:
    """Reject keys of sub-table ``t`` (of kind ``kind``, see _TABLE_KEYS) that are not read."""
    unknown = set(t) - _TABLE_KEYS[kind]
    if unknown:
        raise InputError(f"{where}: unknown keys {sorted(unknown)}; "
                         f"expected some of {sorted(_TABLE_KEYS[kind])}")


def _table(d: dict, key: str, where: str) -> dict:
    if key not in d:
        raise InputError(f"{where}: missing table [{key}]")
    if not isinstance(d[key], dict):
        raise InputError(f"{where}: expected [{key}] to be a table, found {type(d[key]).__name__}")
    if key in _TABLE_KEYS:
        _check_keys(d[key], key, f"{where} [{key}]")
    return d[key]


def _num(d: dict, key: str, where: str, default=None):
    if key not in d:
        if default is not None:
            return default
        raise InputError(f"{where}: missing number '{key}'")
    v = d[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise InputError(f"{where}: expected '{key}' to be a finite number, found {v!r}")
    return float(v)


def _is_number(v) -> bool:
    """A TOML number (int or float, not a bool; strings such as "1.5" are not numbers)."""
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _floats(d: dict, key: str, where: str, n: int | None = None, default=None) -> np.ndarray:
    if key not in d:
        if default is not None:
            return np.asarray(default, dtype=float)
        raise InputError(f"{where}: missing list '{key}'")
    v = d[key]
    items = v if isinstance(v, list) else [v]
    flat = []
    for x in items:                               # one level of nesting: rows [x, y, z]
        flat += x if isinstance(x, list) else [x]
    if not all(_is_number(x) and math.isfinite(x) for x in flat):
        raise InputError(f"{where}: expected '{key}' to be a list of finite numbers, found {v!r}")
    try:
        a = np.asarray(v, dtype=float)
    except ValueError:                            # ragged rows
        raise InputError(f"{where}: expected '{key}' to be a list of numbers with rows of "
                         f"equal length, found {v!r}") from None
    a = np.atleast_1d(a)
    if n is not None and a.shape[0] != n:
        raise InputError(f"{where}: expected '{key}' to have {n} entries, found {a.shape[0]}")
    return a


def _optional_num(d: dict, key: str, where: str):
    """An optional finite number (None when absent)."""
    return _num(d, key, where) if key in d else None


def _string(d: dict, key: str, where: str, default: str = "") -> str:
    v = d.get(key, default)
    if not isinstance(v, str):
        raise InputError(f"{where}: expected '{key}' to be a string, found {v!r}")
    return v


# Entries of [printed] that commands compare with their results, hence numbers (others
# such as 'source' or 'k_H = "not printed"' are free-form notes).
_PRINTED_NUMBERS = re.compile(r"bar_critical_load|bar_load(_stage\d+)?|membrane_max_sigma_p1|"
                              r"membrane_max_von_mises|tendon_max_stress")


def _printed(d: dict, where: str) -> dict:
    """The optional [printed] table, its compared entries checked to be numbers."""
    p = d.get("printed", {})
    for k, v in p.items():
        if _PRINTED_NUMBERS.fullmatch(k) and not (_is_number(v) and math.isfinite(v)):
            raise InputError(f"{where} [printed]: expected '{k}' to be a finite number, found {v!r}")
    if "rest_lengths" in p:
        _rest_lengths(p, f"{where} [printed]")
    return dict(p)


def _rest_lengths(d: dict, where: str):
    """The optional [rest_lengths] table: group or tendon name -> finite positive number [m]."""
    rest = d.get("rest_lengths")
    if rest is None or rest == {}:
        return None
    if not isinstance(rest, dict):
        raise InputError(f"{where}: expected [rest_lengths] to be a table of numbers, found {rest!r}")
    for k, v in rest.items():
        if not (_is_number(v) and math.isfinite(v) and v > 0):
            raise InputError(f"{where} [rest_lengths]: expected '{k}' to be a positive rest "
                             f"length in m, found {v!r}")
    return rest


def _materials(d: dict, where: str):
    m = _table(d, "membrane", where)
    membrane = MembraneMaterial(E=_num(m, "E", f"{where} [membrane]"),
                                nu=_num(m, "nu", f"{where} [membrane]"),
                                rho=_num(m, "rho", f"{where} [membrane]"),
                                h=_num(m, "h", f"{where} [membrane]"),
                                yield_stress=_optional_num(m, "yield_stress", f"{where} [membrane]"))
    b = _table(d, "bar", where)
    bar = BarSection(E=_num(b, "E", f"{where} [bar]"), rho=_num(b, "rho", f"{where} [bar]"),
                     d=_num(b, "d", f"{where} [bar]"))
    sections = {}
    for key, t in _table(d, "tendons", where).items():
        w = f"{where} [tendons.{key}]"
        if not isinstance(t, dict):
            raise InputError(f"{w}: expected a table, found {t!r}")
        _check_keys(t, "tendons.*", w)
        sections[key] = TendonSection(E=_num(t, "E", w), d=_num(t, "d", w),
                                      rho=_optional_num(t, "rho", w),
                                      yield_stress=_optional_num(t, "yield_stress", w))
    return membrane, bar, sections


def _monitor(d: dict, where: str) -> dict:
    """``monitor_nodes`` and ``monitor_points`` of the optional table ``[monitor]``."""
    if "monitor" not in d:
        return {}
    t = _table(d, "monitor", where)
    nodes = t.get("nodes", [])
    if not (isinstance(nodes, list) and all(isinstance(n, str) for n in nodes)):
        raise InputError(f"{where} [monitor]: expected 'nodes' as a list of node labels, found {nodes!r}")
    pts = _floats(t, "points", f"{where} [monitor]", default=np.zeros(0))
    if pts.size % 2:
        raise InputError(f"{where} [monitor]: expected 'points' as rows [x_f, y_f], found {t['points']!r}")
    return {"monitor_nodes": tuple(nodes), "monitor_points": pts.reshape(-1, 2).T}


def _model_defaults(d: dict, where: str) -> dict:
    """Default model options of the optional tables ``[models.<name>]``."""
    t = d.get("models", {})
    if not isinstance(t, dict):
        raise InputError(f"{where}: expected [models] to be a table, found {type(t).__name__}")
    out = {}
    for name, opts in t.items():
        kind = f"models.{name}"
        if kind not in _TABLE_KEYS or not isinstance(opts, dict):
            known = sorted(k.split(".", 1)[1] for k in _TABLE_KEYS if k.startswith("models."))
            raise InputError(f"{where}: [models.{name}]: expected a table for one of the models "
                             f"{known}")
        _check_keys(opts, kind, f"{where} [models.{name}]")
        K = opts.get("membrane_modes")
        if K is not None and not (isinstance(K, int) and not isinstance(K, bool) and K >= 0):
            raise InputError(f"{where} [models.{name}]: expected membrane_modes as an integer >= 0, "
                             f"found {K!r}")
        if K is not None:
            check_membrane_modes(K, given=f"{where} [models.{name}] membrane_modes")
        out[name] = dict(opts)
    return out


def system_from_dict(d: dict, where: str = "system") -> System:
    """Build a :class:`System` from the parsed contents of a system file."""
    unknown = set(d) - _TOP_KEYS
    if unknown:
        raise InputError(f"{where}: unknown keys {sorted(unknown)}; expected some of {sorted(_TOP_KEYS)}")
    N = d.get("N")
    if not isinstance(N, int) or isinstance(N, bool) or N < 3:
        raise InputError(f"{where}: expected integer N >= 3 (bars per stage), found {N!r}")
    deployable = d.get("deployable", False)
    if not isinstance(deployable, bool):
        raise InputError(f"{where}: expected 'deployable' to be true or false, found {deployable!r}")
    k_H = _optional_num(d, "k_H", where)
    name = system_name(d, where)
    check_stage_lists(d, N, where)
    check_tendon_list(d.get("tendon"), where, symmetric="symmetric" in d)
    check_bounds(d, where)
    for key, kind in (("tendons", dict), ("printed", dict), ("notes", list), ("tendon", list)):
        if key in d and not isinstance(d[key], kind):
            raise InputError(f"{where}: expected '{key}' to be a "
                             f"{'table' if kind is dict else 'list'}, found {d[key]!r}")
    notes = d.get("notes", [])
    if not all(isinstance(n, str) for n in notes):
        raise InputError(f"{where}: expected 'notes' to be a list of strings, found {notes!r}")
    membrane, bar, sections = _materials(d, where)
    mtab = d["membrane"]
    rest = _rest_lengths(d, where)
    common = dict(name=name,
                  description=_string(d, "description", where),
                  notes=tuple(notes), printed=_printed(d, where),
                  **_monitor(d, where), model_defaults=_model_defaults(d, where),
                  problem=problem_from_dict(d, where, system_from_dict))
    for k, t in enumerate(d.get("tendon", ())):
        wt = f"{where} [[tendon]] entry {k + 1}"
        if not isinstance(t, dict):
            raise InputError(f"{wt}: expected a table, found {t!r}")
        _check_keys(t, "tendon", wt)
        missing = {"name", "family", "ends"} - set(t)
        if missing:
            raise InputError(f"{wt}: missing keys {sorted(missing)}")
        for key in ("name", "family"):
            _string(t, key, wt)
        ends = t["ends"]
        if not (isinstance(ends, list) and len(ends) == 2 and all(isinstance(e, str) for e in ends)):
            raise InputError(f"{wt}: expected 'ends' to be two node labels, found {ends!r}")
        for key in ("stage", "j"):
            v = t.get(key, 1)
            if not (isinstance(v, int) and not isinstance(v, bool) and v >= 1):
                raise InputError(f"{wt}: expected '{key}' to be an integer >= 1, found {v!r}")
    if ("symmetric" in d) == ("general" in d):
        raise InputError(f"{where}: expected exactly one of [symmetric] or [general]")
    if "symmetric" in d:
        s = _table(d, "symmetric", where)
        w = f"{where} [symmetric]"
        theta = np.radians(_floats(s, "theta_deg", w))
        M = theta.size
        cfg = SymmetricConfig(theta=theta, psi=np.radians(_floats(s, "psi_deg", w, M)),
                              sigma=np.radians(_floats(s, "sigma_deg", w, M, np.zeros(M))),
                              z=_floats(s, "z", w, M, np.zeros(M)), r=_floats(s, "r", w, M),
                              l=_floats(s, "l", w, M))
        r_mb = _num(mtab, "r_mb", f"{where} [membrane]")
        sys = System.symmetric_system(N=N, config=cfg, r_mb=r_mb, membrane=membrane, bar=bar,
                                      tendon_sections=sections, deployable=deployable, k_H=k_H,
                                      rest_lengths=rest, **common)
        check_keys_used(sys, d, where)
        return sys
    g = _table(d, "general", where)
    w = f"{where} [general]"
    base = _floats(g, "base", w) if g.get("base") not in (None, []) else None
    base = base.reshape(-1, 3).T if base is not None and base.size % 3 == 0 else None
    if base is None or base.shape != (3, N):
        raise InputError(f"{w}: expected 'base' as {N} rows [x, y, z], found {g.get('base')!r}")
    q = _floats(g, "q", w)
    M = q_stages(q.size, N)
    l = _floats(g, "l", w)
    l = np.broadcast_to(l.reshape(M, -1) if l.size == M * N else l.reshape(-1)[0], (M, N))
    if "corners" in mtab:
        corners = _floats(mtab, "corners", f"{where} [membrane]").reshape(-1, 2).T
        r_mb = None
    else:
        r_mb = _num(mtab, "r_mb", f"{where} [membrane]")
        corners = membrane_corners_regular(N, r_mb)
    tendons = tuple(Tendon(name=t["name"], family=t["family"], stage=int(t.get("stage", 1)),
                           j=int(t.get("j", 1)), ends=tuple(t["ends"])) for t in d.get("tendon", ()))
    sys = System(M=M, N=N, deployable=deployable, base=base, l=l, q=q, membrane=membrane,
                 membrane_corners=corners, bar=bar, tendon_sections=sections, k_H=k_H,
                 tendons=tendons, r_mb=r_mb, **common)
    check_keys_used(sys, d, where)
    return sys.with_rest_lengths(rest) if rest else sys


def load_system(path) -> System:
    """Read a system file (TOML); errors name the file and what is wrong."""
    path = Path(path)
    try:
        text = read_bounded(path).decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"{path}: expected UTF-8 text (TOML), found byte 0x{exc.object[exc.start]:02x} "
                         f"at offset {exc.start} that is not UTF-8") from None
    try:
        d = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: not valid TOML: {exc}") from None
    d.pop("as_printed", None)
    return system_from_dict(d, where=str(path))


def system_to_dict(system: System) -> dict:
    """The system-file contents of ``system`` (inverse of :func:`system_from_dict`)."""
    d: dict = {"name": system.name, "N": system.N}
    if system.description:
        d["description"] = system.description
    if system.notes:
        d["notes"] = list(system.notes)
    if system.deployable:
        d["deployable"] = True
        d["k_H"] = float(system.k_H)
    if system.symmetric is not None:
        c = system.symmetric
        d["symmetric"] = {"theta_deg": np.degrees(c.theta).tolist(), "psi_deg": np.degrees(c.psi).tolist(),
                          "sigma_deg": np.degrees(c.sigma).tolist(), "z": c.z.tolist(),
                          "r": c.r.tolist(), "l": c.l.tolist()}
    else:
        d["general"] = {"base": system.base.T.tolist(), "l": system.l.tolist(), "q": system.q.tolist()}
    m = system.membrane
    mem = {"E": m.E, "nu": m.nu, "rho": m.rho, "h": m.h}
    if m.yield_stress is not None:
        mem["yield_stress"] = m.yield_stress
    if system.r_mb is not None:
        mem["r_mb"] = system.r_mb
    else:
        mem["corners"] = system.membrane_corners.T.tolist()
    d["membrane"] = mem
    d["bar"] = {"E": system.bar.E, "rho": system.bar.rho, "d": system.bar.d}
    d["tendons"] = {k: {kk: vv for kk, vv in vars(s).items() if vv is not None}
                    for k, s in system.tendon_sections.items()}
    if system.symmetric is None and system.tendons:
        d["tendon"] = [{"name": t.name, "family": t.family, "stage": t.stage, "j": t.j,
                        "ends": list(t.ends)} for t in system.tendons]
    if system.rest_lengths is not None:
        d["rest_lengths"] = dict(zip(system.tendon_names(), system.rest_lengths.tolist()))
    if system.printed:
        d["printed"] = system.printed
    if system.model_defaults:
        d["models"] = {k: dict(v) for k, v in system.model_defaults.items()}
    d.update(system.problem.raw)
    if system.monitor_nodes or system.monitor_points.size:
        d["monitor"] = {k: v for k, v in (("nodes", list(system.monitor_nodes)),
                                          ("points", system.monitor_points.T.tolist())) if v}
    return d


def dump_system(system: System, path) -> None:
    """Write ``system`` as a system file."""
    Path(path).write_bytes(tomli_w.dumps(system_to_dict(system)).encode())
