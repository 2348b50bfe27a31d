"""Files for ParaView (meshio): configurations, mode shapes, time series."""
from tmfem.io.vtk import (FAMILY_CODES, KIND_CODES, MembraneField, SeriesWriter,
                          configuration_cells, membrane_on_configuration, read_pvd,
                          write_configuration, write_modes, write_series)

__all__ = ["FAMILY_CODES", "KIND_CODES", "MembraneField", "SeriesWriter", "configuration_cells",
           "membrane_on_configuration", "read_pvd", "write_configuration", "write_modes",
           "write_series"]
