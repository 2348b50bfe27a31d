"""Gridded linear parameter-varying control (dissertation ch. 8).

The LPV plant on a grid (:class:`GriddedLPV`, :func:`com_lpv_plant`), the generalized plant
of Figure 8.1 (:func:`interconnection_8_1`), state-feedback synthesis with rate bounds
(:func:`synthesize_state_feedback`, :func:`bisect_gamma`), its pointwise lower bound, off-grid
verification (:mod:`tmfem.control.lpv.verify`), the observer-based output feedback and its
rate-bounded certificate, the gain-scheduled controllers and the LPV deployment of 8.4. The
design workflow of ``tmfem control lpv`` is :mod:`tmfem.control.lpv.workflow`
(:func:`design_plant`, :func:`synthesize_design`, :func:`refined_plant`, :func:`verify_design`, :func:`verified_design`,
:func:`output_feedback_design`). The general gridded synthesis on any plant, with basis
functions of one's choice for the parameter dependence, is :func:`lpvsyn`
(:mod:`tmfem.control.lpv.gridded_synthesis`, docs/guides/lpvsyn.md); it carries the 2-3
design too, on its EIGOPT route (:mod:`tmfem.control.lpv.eigopt_route`), which the workflow
calls.
"""
from tmfem._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "GriddedLPV": "tmfem.control.lpv.plant",
    "com_lpv_plant": "tmfem.control.lpv.plant",
    "GeneralizedLPV": "tmfem.control.lpv.generalized_plant",
    "interconnection_8_1": "tmfem.control.lpv.generalized_plant",
    "LPVStateFeedback": "tmfem.control.lpv.state_feedback",
    "synthesize_state_feedback": "tmfem.control.lpv.synthesis",
    "GammaBracket": "tmfem.control.lpv.bisect",
    "bisect_gamma": "tmfem.control.lpv.bisect",
    "PointwiseBound": "tmfem.control.lpv.bounds",
    "pointwise_state_feedback_bound": "tmfem.control.lpv.bounds",
    "Verification": "tmfem.control.lpv.verify",
    "LPVOutputController": "tmfem.control.lpv.output_feedback",
    "LPVOutputFeedback": "tmfem.control.lpv.output_feedback",
    "design_output_feedback": "tmfem.control.lpv.output_feedback",
    "verify_output_feedback": "tmfem.control.lpv.output_feedback",
    "RateBoundedCertificate": "tmfem.control.lpv.certificate",
    "rate_bounded_certificate": "tmfem.control.lpv.certificate",
    "refine_certificate": "tmfem.control.lpv.certificate",
    "LPVController": "tmfem.control.lpv.controller",
    "LPVDeployment": "tmfem.control.lpv.deployment",
    "lpv_deployment": "tmfem.control.lpv.deployment",
    "output_feedback_controller": "tmfem.control.lpv.deployment",
    "state_feedback_controller": "tmfem.control.lpv.deployment",
    "DesignPlant": "tmfem.control.lpv.workflow",
    "design_plant": "tmfem.control.lpv.workflow",
    "output_feedback_design": "tmfem.control.lpv.workflow",
    "refined_plant": "tmfem.control.lpv.workflow",
    "saved_design_plant": "tmfem.control.lpv.workflow",
    "synthesize_design": "tmfem.control.lpv.workflow",
    "verified_design": "tmfem.control.lpv.workflow",
    "refine_state_feedback": "tmfem.control.lpv.refinement",
    "verify_design": "tmfem.control.lpv.workflow",
    "Basis": "tmfem.control.lpv.basis",
    "lpvsyn": "tmfem.control.lpv.gridded_synthesis",
    "lpvsyn_cost": "tmfem.control.lpv.cost",
})
