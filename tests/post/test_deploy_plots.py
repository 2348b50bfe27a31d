"""Deployment plots (tmfem.post.deploy_plots) on a synthetic run whose content is known."""
from types import SimpleNamespace

import matplotlib.image as plt_image
import numpy as np

from tmfem.post.deploy_plots import _deflections, plot_deployment
from tmfem.post.plots import new_figure


def _run(switch=5.0, peak_at=5.5):
    t = np.linspace(0.0, 10.0, 501)
    q_d = np.stack([1.5 - 0.2 * (1 - np.exp(-t)), 1.5 - 0.2 * (1 - np.exp(-t)),
                    np.full_like(t, 0.3), 0.1 * t], axis=1)
    z = q_d + 1e-3 * np.sin(t)[:, None]
    w = 1e-3 * np.exp(-((t - peak_at) ** 2) / 0.01)[:, None] * np.array([[1.0, 0.5]])
    return SimpleNamespace(t=t, z=z, q_d=q_d, w=w, u=np.ones((t.size, 2)), lengths=1.1 * np.ones((t.size, 2)),
                           switch_time=switch,
                           names={"q": ["theta_11", "theta_12", "psi_11", "x_21"], "w": ["w_1", "w_2"],
                                  "tendons": ["S_1", "V_1"]})


def test_one_panel_per_moving_family_and_one_for_the_tracking_error(tmp_path):
    # the moving references: theta (2 bars) and x; psi_11's reference is constant -> no panel.
    # panels: theta, x, tracking error, deflections, rest lengths = 5, each 2.4 in + 0.6 in, 120 dpi
    png = plot_deployment(tmp_path / "d.png", _run(), title="synthetic")
    h, w = plt_image.imread(str(png)).shape[:2]
    assert (h, w) == (round((2.4 * 5 + 0.6) * 120), 8 * 120)


def test_largest_deflection_is_marked_as_the_switch_transient_when_it_follows_the_switch():
    for peak_at, says in ((5.5, True), (2.0, False)):
        ax = new_figure().subplots()
        _deflections(ax, _run(peak_at=peak_at))
        text = " ".join(t.get_text() for t in ax.texts)
        assert "largest |w|: 1 mm (w_1)" in text
        assert ("after the switch" in text) is says


def test_membrane_frames_follow_the_model_field_and_its_floating_frame():
    # the deflected membrane of a state z with membrane modal coordinates eta: its w at the
    # model's output points equals the model's own output map W_out (eq. 5.1, another code
    # path), and the fitted normal is the z axis of O_f of the model's rotation (eq. 3.3)
    from tmfem.models.com.model import ControlOrientedModel
    from tmfem.post.deploy_plots import membrane_frames
    from tmfem.system.geometry import rotation_ef
    from tmfem.system.presets import load_preset
    model = ControlOrientedModel(load_preset("1-4"), membrane_modes=3, mesh_n=4)
    z = np.array(model.z0, dtype=float)
    z[:model.nq] += 1e-3 * np.arange(model.nq) / model.nq
    z[model.nq:] = [2e-3, -1e-3, 5e-4][:model.K]
    x, d, n = membrane_frames(model, SimpleNamespace(z=z[None, :]), [0])
    assert model.output_points                   # 1-4: the monitored points of eq. 5.36
    probe = model.membrane.probe(np.array(model.output_points).T)
    assert np.allclose(probe @ d[0, 2], model.membrane_w(z), atol=1e-12)
    zeta = model.zeta(z[:model.nq])
    assert np.allclose(n[0], rotation_ef(zeta[model.layout.n_delta:])[:, 2], atol=1e-9)
    assert x.shape == d.shape == (1, 3, model.membrane.mesh.p.shape[1])
