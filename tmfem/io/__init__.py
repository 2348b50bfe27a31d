"""Files for ParaView (meshio): one meshio.Mesh per result (:mod:`tmfem.io.meshes`), written
by :mod:`tmfem.io.writer`; codes of members and nodes (:mod:`tmfem.io.codes`), the membrane
as data (:mod:`tmfem.io.fields`), output paths (:mod:`tmfem.io.paths`), time series
(:mod:`tmfem.io.series`), gmsh meshes (:mod:`tmfem.io.msh`)."""
from tmfem.io.codes import FAMILY_CODES, KIND_CODES, configuration_cells
from tmfem.io.fields import MembraneField
from tmfem.io.meshes import configuration_mesh, modes_mesh
from tmfem.io.paths import check_dir, check_path
from tmfem.io.series import SeriesWriter, read_pvd, write_series
from tmfem.io.writer import write_configuration, write_mesh, write_modes

__all__ = ["FAMILY_CODES", "KIND_CODES", "MembraneField", "SeriesWriter", "check_dir",
           "check_path", "configuration_cells", "configuration_mesh", "modes_mesh", "read_pvd",
           "write_configuration", "write_mesh", "write_modes", "write_series"]
