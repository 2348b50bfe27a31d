"""The dissertation's natural frequencies (Tables 6.6/6.7) beside a model's modal report."""
from __future__ import annotations

import numpy as np

from tmfem.reference.com_modal import add_dissertation_com
from tmfem.reference.tables import FREQUENCIES


def _fe_column(column: str, *, relative: bool):
    def add(out: dict, *, modes: int) -> dict:
        ref = FREQUENCIES.get(out["system"])
        if ref is None:
            return out
        n = min(len(ref[column]), modes)
        out["dissertation"] = {"source": ref["source"], "MTC": ref["MTC"][:n], "SBC": ref["SBC"][:n]}
        if relative:
            out[f"relative_difference_to_{column}"] = (
                np.asarray(out["freq_hz"][:n]) / np.array(ref[column][:n]) - 1).tolist()
        return out
    return add


#: model name -> ``add(out, modes=k)``: the printed columns beside a modal report ``out``
ADD_DISSERTATION = {"mtc": _fe_column("MTC", relative=True),
                    "sbc": _fe_column("SBC", relative=False),
                    "com": add_dissertation_com}


def with_dissertation(out: dict, *, modes: int) -> dict:
    """``out`` (a modal report of model ``out["model"]``) with the dissertation's frequencies
    of its system where Tables 6.6/6.7 print them."""
    add = ADD_DISSERTATION.get(out["model"])
    return out if add is None else add(out, modes=modes)
