"""Files for ParaView (meshio): one meshio.Mesh per result (:mod:`tmfem.io.meshes`), written
by :mod:`tmfem.io.writer`; codes of members and nodes (:mod:`tmfem.io.codes`), the membrane
as data (:mod:`tmfem.io.fields`), output paths (:mod:`tmfem.io.paths`), time series
(:mod:`tmfem.io.series`), gmsh meshes (:mod:`tmfem.io.msh`).
"""
from tmfem._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "FAMILY_CODES": "tmfem.io.codes",
    "KIND_CODES": "tmfem.io.codes",
    "configuration_cells": "tmfem.io.codes",
    "MembraneField": "tmfem.io.fields",
    "configuration_mesh": "tmfem.io.meshes",
    "modes_mesh": "tmfem.io.meshes",
    "check_dir": "tmfem.io.paths",
    "check_path": "tmfem.io.paths",
    "SeriesWriter": "tmfem.io.series",
    "read_pvd": "tmfem.io.series",
    "write_series": "tmfem.io.series",
    "write_configuration": "tmfem.io.writer",
    "write_mesh": "tmfem.io.writer",
    "write_modes": "tmfem.io.writer"
})
