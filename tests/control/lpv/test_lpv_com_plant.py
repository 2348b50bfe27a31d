"""The gridded LPV plant of the 2-3 system (8.3) from COM linearisations."""
import numpy as np
import pytest

from tmfem.control.lpv.plant import com_lpv_plant
from tmfem.control.lpv.generalized_plant import interconnection_8_1
from tmfem.equilibrium.symmetric_map import configuration_5_97, with_configuration
from tmfem.models.com.linearize import linearize
from tmfem.models.com.model import ControlOrientedModel
from tmfem.reference.tables import deployment_bases
from tmfem.system import load_preset


@pytest.mark.slow
def test_com_lpv_plant_point_coordinates_keep_the_frequencies_and_integrators_are_stabilizable():
    s = load_preset("2-3-lpv")
    th, ps = np.radians([63.0, 77.32]), np.radians([8.36])
    pl = com_lpv_plant(s, theta=th, psi=ps, bases=deployment_bases(s))
    assert pl.grid_shape == (2, 1) and pl.nx == 50 and pl.nu == 21 and pl.parameter_names == ["theta_13", "psi_13"]
    # independent formulation: the modal coordinates of eq. 5.14 give the same frequencies as
    # the point coordinates of eq. 5.17 at the same equilibrium (eq. 5.97 and the base rule)
    s1 = with_configuration(s, configuration_5_97(s, th[1], ps[0], **deployment_bases(s)(th[1], ps[0])))
    f_modal = linearize(ControlOrientedModel(s1, membrane_modes=4)).frequencies_hz()
    lam = np.sort(np.abs(np.linalg.eigvals(pl.A[1, 0]).imag))[::2] / (2 * np.pi)
    np.testing.assert_allclose(lam, np.sort(np.abs(f_modal)), rtol=1e-6, atol=1e-9)
    # eq. 5.98: the integrators of e_q are stabilisable iff [[A, B], [-T_qx, 0]] is nonsingular
    gp = interconnection_8_1(pl, tracked=s.q_names)
    T = pl.C[1, 0][:len(s.q_names)]
    M = np.block([[pl.A[1, 0], pl.B[1, 0]], [-T, np.zeros((len(s.q_names), pl.nu))]])
    assert np.linalg.matrix_rank(M) == M.shape[0]
    assert gp.sizes == {"n_x": 71, "n_w": 42, "n_u": 21, "n_p": 42}
