"""The dissertation's printed numbers and the studies that reproduce them, on top of the library.

Nothing in the library below this package (system, fem, equilibrium, models, solvers,
simulation, control) imports it: printed tables, monitor choices and dissertation-specific
designs live here, the models know none of them.
"""
