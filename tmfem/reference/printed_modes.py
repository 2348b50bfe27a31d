"""The printed natural frequencies of a system's file beside a model's modal report
(``[printed.frequencies_hz]``: Tables 6.6/6.7 for the presets 1-4 and 2-3)."""
from __future__ import annotations

import numpy as np

from tmfem.reference.com_modal import add_dissertation_com
from tmfem.reference.tables import printed_frequencies


def _fe_column(column: str, *, relative: bool):
    def add(out: dict, *, system, modes: int) -> dict:
        ref = printed_frequencies(system)
        if ref is None or column not in ref:
            return out
        n = min(len(ref[column]), modes)
        out["dissertation"] = {"source": ref.get("source", "printed"),
                               **{c: list(ref[c])[:n] for c in ("MTC", "SBC") if c in ref}}
        if relative:
            out[f"relative_difference_to_{column}"] = (
                np.asarray(out["freq_hz"][:n]) / np.array(ref[column][:n]) - 1).tolist()
        return out
    return add


#: model name -> ``add(out, system=, modes=k)``: the printed columns beside a modal report
ADD_PRINTED = {"mtc": _fe_column("MTC", relative=True),
               "sbc": _fe_column("SBC", relative=False),
               "com": add_dissertation_com}


def with_printed(out: dict, *, system, modes: int) -> dict:
    """``out`` (a modal report of model ``out["model"]``) with the frequencies printed in
    ``system``'s file, where it prints them; ``out`` unchanged otherwise."""
    add = ADD_PRINTED.get(out["model"])
    return out if add is None else add(out, system=system, modes=modes)
