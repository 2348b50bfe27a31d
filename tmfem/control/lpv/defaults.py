"""The defaults of the LPV design workflow (8.3), in a module without dependencies so that a
command line can state them in its help without loading the synthesis."""

#: EIGOPT defaults: relative bracket width of the gamma bisection, its time budget [s]
GAMMA_RTOL, TIME_BUDGET = 0.05, 300.0
#: cutting-plane rounds of the rate-bounded certificate on the finer grid, points added per round
CERTIFICATE_ROUNDS, CERTIFICATE_PER_ROUND = 8, 4
#: cutting-plane rounds of a state feedback that fails its verification between its grid points
#: (:func:`tmfem.control.lpv.refinement.refine_state_feedback`), points added per round
DESIGN_ROUNDS, DESIGN_PER_ROUND = 8, 4
#: the weights of the interconnection of Figure 8.1 (8.3): W_e = 0.5 I, W_u = 0.05 I
W_E, W_U = 0.5, 0.05
