"""Pictures and plots: pyvista renders (off screen) and matplotlib line plots (Agg)."""
