"""Pictures and plots: pyvista renders (off screen) of configurations and modes, matplotlib
line plots (Agg) of histories, deployments, comparisons and convergence studies.
"""
from tmfem._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "render_configuration": "tmfem.post.render",
    "render_modes": "tmfem.post.render",
    "plot_histories": "tmfem.post.plots",
    "plot_free_vibration": "tmfem.post.plots",
    "plot_xy": "tmfem.post.plots",
    "plot_deployment": "tmfem.post.deploy_plots",
    "plot_lpv_deployment": "tmfem.post.deploy_plots",
    "animate_deployment": "tmfem.post.deploy_plots",
    "plot_plant_comparison": "tmfem.post.plant_compare_plot"
})
