"""Deployment control (dissertation 7.2, 7.4, 7.6): reference trajectories (eq. 5.68),
partial feedback linearisation (eqs. 5.39-5.41), RBF adaptation (eqs. 5.44, 5.51-5.58),
rest-length limits, the switch to a linear controller (eq. 5.70), closed-loop runs and the
stress recovery of a run."""
