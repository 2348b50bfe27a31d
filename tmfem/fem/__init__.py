"""Total-Lagrangian finite elements (dissertation ch. 4): truss, membrane, assembly."""
