"""Membrane-truss-cable finite-element model (dissertation 4.4, 6.2-6.4); see docs/guides/mtc.md."""
