"""``tmfem modal``: natural frequencies and mode shapes about the prestressed state (6.4, eq. 5.32)."""
from __future__ import annotations

import sys

import numpy as np

from tmfem.cli.common import (add_model_args, add_system_args, check_com_modes, model_from_args,
                              model_options_from_args, with_backend)
from tmfem.cli.static import default_monitor
from tmfem.errors import InputError
from tmfem.models.mtc.design import describe_rule
from tmfem.models.mtc.spec import sequence_of

NAME = "modal"
HELP = "natural frequencies and mode shapes (MTC finite-element or control-oriented model)"


def configure(parser) -> None:
    add_system_args(parser)
    add_model_args(parser, NAME, default="mtc")
    parser.add_argument("--modes", type=int, default=12, help="number of modes (default 12)")
    parser.add_argument("--vtk", help="write the mode shapes (point data mode_k) to this .vtu "
                                      "[finite-element models]")
    parser.add_argument("--png", help="render the first six mode shapes to this PNG "
                                      "[finite-element models]")


def mtc_modes(model, *, k: int, start: str = "undeformed", sequence: int | None = None):
    """Static equilibrium of ``model`` and its ``k`` lowest modes (eq. 5.32)."""
    res = model.solve_static(start=start, monitor=default_monitor(model.system), sequence=sequence)
    modes = model.modes(res.x, k=k, tangent=res.tangent)
    return res, modes


def run(args) -> dict:
    if not (isinstance(args.modes, int) and args.modes >= 1):
        raise InputError(f"--modes: expected an integer >= 1, found {args.modes!r}")
    if args.model == "com":
        if args.vtk or args.png:
            raise InputError("modal --model com: option does not apply: --vtk/--png write "
                             "finite-element mode shapes (use --model mtc)")
        from tmfem.reference.com_modal import modal_summary
        system, options = model_options_from_args(args, NAME)
        K = check_com_modes(system, modes=args.modes, membrane_modes=options["membrane_modes"])
        return modal_summary(system, modes=args.modes, membrane_modes=K,
                             prestress_scale=options["prestress_scale"], mesh_n=options["mesh"],
                             membrane_law=options["membrane_law"])
    from tmfem.reference.tables import FREQUENCIES
    from tmfem.models.mtc.post import static_summary
    from tmfem.post.mtc import model_cells
    model, options = model_from_args(args, NAME)
    if args.modes >= model.ndof:                  # before the static solve
        raise InputError(f"--modes {args.modes}: expected fewer modes than the model's "
                         f"{model.ndof} free DOFs")
    if args.model == "sbc":
        return with_backend(sbc_modal(args, model, FREQUENCIES), model)
    system_name = model.system.name
    print(f"tmfem modal: {system_name} MTC, {model.ndof} free dofs", file=sys.stderr)
    res, modes = mtc_modes(model, k=args.modes, start=options["start"],
                           sequence=sequence_of(options["mesh"], options["sequence"]))
    st = static_summary(model, res.x, result=res)
    out = {"system": system_name, "model": "mtc", "dofs": model.ndof, "mesh_n": options["mesh"],
           "tendon_elements": options["tendon_elements"], "attachment": options["attachment"],
           "membrane_law": model.membrane_law, "rest_lengths_source": model.rest_lengths_source,
           "rest_lengths_note": describe_rule(model.rest_lengths_source),
           "rest_lengths": st["rest_lengths"], "static_iterations": res.iterations,
           "tendon_stress_max": st["tendon_stress_max"], "bar_load_max": st["bar_load_max"],
           "Delta_mean": float(np.mean(st["Delta"])),
           "freq_hz": modes.freq_hz.tolist()}
    ref = FREQUENCIES.get(system_name)
    if ref is not None:
        n = min(len(ref["MTC"]), args.modes)
        out["dissertation"] = {"source": ref["source"], "MTC": ref["MTC"][:n], "SBC": ref["SBC"][:n]}
        out["relative_difference_to_MTC"] = (modes.freq_hz[:n] / np.array(ref["MTC"][:n]) - 1).tolist()
    if args.vtk or args.png:
        shapes = model.topology.T @ modes.shapes
        cells = model_cells(model)
        if args.vtk:
            from tmfem.io.codes import kind_cell_data
            from tmfem.io.writer import write_modes
            out["vtk"] = str(write_modes(args.vtk, res.x, cells, shapes, modes.freq_hz,
                                         cell_data=kind_cell_data(cells)))
        if args.png:
            from tmfem.post.render import render_modes
            out["png"] = str(render_modes(args.png, points=res.x, cells=cells, shapes=shapes,
                                          freq_hz=modes.freq_hz, k=min(6, args.modes),
                                          title=f"{system_name} MTC modes"))
    return with_backend(out, model)


def sbc_modal(args, model, tables) -> dict:
    """``tmfem modal --model sbc``: equilibrium from the undeformed membrane, modes, and the
    printed SBC column of Tables 6.6/6.7 (``tables``) when the system has one."""
    from tmfem.models.sbc.post import modal_summary
    print(f"tmfem modal: {model.system.name} SBC, {model.ndof} free dofs", file=sys.stderr)
    res = model.solve_static(monitor=default_monitor(model.system))
    modes = model.modes(res.state, k=args.modes, tangent=res.tangent)
    out = modal_summary(model, res, modes)
    if args.vtk or args.png:
        from tmfem.post.sbc import mode_data, sbc_cells
        shapes, rotations = mode_data(model, res.state, modes)
        cells = sbc_cells(model)
        if args.vtk:
            from tmfem.io.codes import kind_cell_data
            from tmfem.io.writer import write_modes
            out["vtk"] = str(write_modes(args.vtk, res.state.x, cells, shapes, modes.freq_hz,
                                         point_data=rotations, cell_data=kind_cell_data(cells)))
        if args.png:
            from tmfem.post.render import render_modes
            out["png"] = str(render_modes(args.png, points=res.state.x, cells=cells, shapes=shapes,
                                          freq_hz=modes.freq_hz, k=min(6, args.modes),
                                          title=f"{model.system.name} SBC modes"))
    ref = tables.get(model.system.name)
    if ref is not None:
        n = min(len(ref["SBC"]), args.modes)
        out["dissertation"] = {"source": ref["source"], "MTC": ref["MTC"][:n], "SBC": ref["SBC"][:n]}
    return out


def format_text(r: dict) -> str:
    if r.get("model") == "sbc":
        from tmfem.models.sbc.post import format_static
        return format_static(r)
    if r.get("model") != "mtc":
        from tmfem.reference.com_modal import format_summary
        return format_summary(r)
    lines = [f"MTC modes of {r['system']}: mesh n={r['mesh_n']}, {r['tendon_elements']} "
             f"elements/tendon, {r['attachment']} attachment, {r.get('membrane_law', 'svk')} "
             f"membrane, {r['dofs']} free dofs",
             f"rest lengths {r['rest_lengths_source']}: {r['rest_lengths_note']}",
             "prestress: " + ", ".join(f"{k}={v:.5f} m" for k, v in list(r["rest_lengths"].items())[:4])
             + f"; max tendon stress {r['tendon_stress_max'] / 1e6:.2f} MPa, bar load "
               f"{r['bar_load_max']:.3f} N, Delta {r['Delta_mean'] * 1e3:.4f} mm"]
    d = r.get("dissertation")
    if d:
        lines.append(f"{'mode':>4s} {'ours [Hz]':>10s} {'MTC paper':>10s} {'SBC paper':>10s} {'diff':>8s}"
                     f"   ({d['source']})")
        for i, f in enumerate(r["freq_hz"]):
            if i < len(d["MTC"]):
                lines.append(f"{i + 1:4d} {f:10.4f} {d['MTC'][i]:10.4f} {d['SBC'][i]:10.4f} "
                             f"{100 * r['relative_difference_to_MTC'][i]:7.2f}%")
            else:
                lines.append(f"{i + 1:4d} {f:10.4f}")
    else:
        lines += [f"{i + 1:4d} {f:10.4f} Hz" for i, f in enumerate(r["freq_hz"])]
    for k in ("vtk", "png"):
        if k in r:
            lines.append(f"wrote {r[k]}")
    return "\n".join(lines)
