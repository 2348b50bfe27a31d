"""Pictures (tmfem.post): off-screen pyvista renders and matplotlib plots are real images."""
import matplotlib.image as plt_image   # pyvista, matplotlib: declared dependencies
import numpy as np
import pytest
import pyvista  # noqa: F401  (pyproject.toml): a broken install must fail, not skip

from tmfem.errors import InputError
from tmfem.io import configuration_cells
from tmfem.system import load_preset


def _rgb(path):
    img = plt_image.imread(str(path))
    return img[..., :3].astype(float)


def _non_background(img):
    return np.any(np.abs(img - 1.0) > 0.02, axis=-1)     # white background


@pytest.fixture(scope="module")
def sys14():
    return load_preset("1-4")


def test_render_configuration_shows_bars_tendons_membrane(tmp_path, sys14):
    from tmfem.post.fields import membrane_design_field
    from tmfem.post.render import render_configuration

    s = sys14
    f = np.array([10.0, 20.0, 30.0, -1.0])                  # one slack tendon: red
    mf = membrane_design_field(s, n=4)
    p = render_configuration(tmp_path / "c.png", s, tendon_forces=f, membrane=mf,
                             title="1-4", window_size=(600, 450))
    img = _rgb(p)
    # the window less its empty margins: something is drawn within 13 px of every edge
    assert img.shape[0] <= 450 and img.shape[1] <= 600
    fg = _non_background(img)
    assert fg[:13].any() and fg[-13:].any() and fg[:, :13].any() and fg[:, -13:].any()
    assert 0.03 < fg.mean() < 0.9 and img.std() > 0.05
    dark = np.all(img < 0.1, axis=-1)                         # black bars
    blue = (img[..., 2] > img[..., 0] + 0.25) & (img[..., 2] > 0.3)
    red = (img[..., 0] > 0.5) & (img[..., 1] < 0.35) & (img[..., 2] < 0.35)
    assert dark.mean() > 0.002 and blue.mean() > 0.002 and red.sum() > 5
    # without a membrane mesh the polygon B_11..B_14 is drawn (tan surface)
    p2 = render_configuration(tmp_path / "g.png", s, window_size=(400, 300), labels=False)
    img2 = _rgb(p2)
    tan = (np.abs(img2[..., 0] - img2[..., 2]) > 0.15) & (img2[..., 0] > img2[..., 2])
    assert tan.mean() > 0.02


def test_render_modes_grid(tmp_path, sys14):
    from tmfem.post.render import render_modes

    s = sys14
    X = s.nodes()
    n = X.shape[1]
    S = np.zeros((3 * n, 4))
    S[2::3, 0] = 1.0                    # vertical translation
    S[0::3, 1] = X[1]                   # a shear
    S[1::3, 2] = np.sin(X[0])
    S[2::3, 3] = X[0] - X[0].mean()
    p = render_modes(tmp_path / "m.png", points=X, cells=configuration_cells(s), shapes=S,
                     freq_hz=[1.0, 2.0, 3.0, 4.0], k=4, window_size=(640, 480))
    img = _rgb(p)
    fg = _non_background(img)
    # the panels with caption and colour bar, nothing cut at an edge: a margin of background
    assert 480 <= img.shape[0] <= 480 + 140 and img.shape[1] <= 640 + 80    # titles may widen it
    assert not (fg[:5].any() or fg[-5:].any() or fg[:, :5].any() or fg[:, -5:].any())
    # 4 modes: 3 columns x 2 rows; each of the first three panels has something drawn
    h, w = img.shape[:2]
    for c in range(3):
        assert fg[: h // 2, c * w // 3:(c + 1) * w // 3].mean() > 0.005
    with pytest.raises(InputError, match=r"k: expected 1 <= k <= 4"):
        render_modes(tmp_path / "m.png", points=X, cells=configuration_cells(s), shapes=S,
                     freq_hz=[1.0, 2.0, 3.0, 4.0], k=5)
    S[0, 1] = np.nan                    # same checks as io.write_modes (io.meshes.check_modes)
    with pytest.raises(InputError, match="non-finite"):
        render_modes(tmp_path / "m.png", points=X, cells=configuration_cells(s), shapes=S,
                     freq_hz=[1.0, 2.0, 3.0, 4.0], k=4)
    with pytest.raises(InputError, match="expected 4 frequencies"):
        render_modes(tmp_path / "m.png", points=X, cells=configuration_cells(s), shapes=S,
                     freq_hz=[1.0, 2.0], k=2)


def test_render_errors(tmp_path, sys14):
    from tmfem.post.render import render_configuration

    with pytest.raises(InputError, match=r"suffix in \['.png'\]"):
        render_configuration(tmp_path / "c.jpg", sys14)
    with pytest.raises(InputError, match=r"tendon_forces: expected shape \(4,\)"):
        render_configuration(tmp_path / "c.png", sys14, tendon_forces=[1.0, 2.0])


def test_plots(tmp_path):
    from tmfem.post.plots import (fit_rates, plot_convergence, plot_histories,
                                  plot_table_comparison)

    t = np.linspace(0, 10, 201)
    p = plot_histories(tmp_path / "h.png", t, {"theta_11": np.sin(t), "psi_11": np.cos(t)},
                       ylabel="angle [rad]", title="free vibration")
    assert _non_background(_rgb(p)).mean() > 0.02
    p = plot_histories(tmp_path / "h2.png", t, {"a": t, "b": t**2}, ylabel="x", subplots=True)
    assert _rgb(p).shape[0] > _rgb(tmp_path / "h.png").shape[0]      # stacked axes are taller
    h = np.array([0.4, 0.2, 0.1, 0.05])
    v = np.column_stack([1.0 + 3 * h**2, 2.0 - h])   # closed form errors: rates 2 and 1
    np.testing.assert_allclose(fit_rates(h, v, [1.0, 2.0]), [2.0, 1.0], rtol=1e-12)
    p = plot_convergence(tmp_path / "c.png", h, v, labels=["f1", "f2"], reference=[1.0, 2.0])
    assert _non_background(_rgb(p)).mean() > 0.02
    p = plot_table_comparison(tmp_path / "t.png", ["S1", "V2"], [1.5, 2.0], [1.529, np.nan],
                              ylabel="rest length [m]")
    assert _non_background(_rgb(p)).mean() > 0.02
    with pytest.raises(InputError, match="expected a 1-D array of length 201"):
        plot_histories(tmp_path / "x.png", t, {"a": t[:-1]}, ylabel="x")
    with pytest.raises(InputError, match=r"labels: expected 2 labels, found 1"):
        plot_convergence(tmp_path / "x.png", h, v, labels=["f1"])


def test_membrane_colour_range_ignores_corner_peaks():
    from tmfem.post.render import _robust_range

    v = np.concatenate([np.linspace(1.0, 2.0, 200), [50.0, 60.0]])   # two singular corners
    lo, hi = _robust_range(v)
    assert lo == 1.0 and hi == pytest.approx(np.percentile(v, 98)) and hi < 3.0
    assert _robust_range(np.linspace(1.0, 2.0, 50)) == [1.0, 2.0]     # no outliers: full range


def test_the_legend_of_a_render_stays_inside_the_picture(tmp_path):
    """The legend's text (bar, membrane: the tendons have a colour bar) at the default window
    size is drawn whole: it starts at the left edge, where the picture has room for text longer
    than the legend's box, and nothing of it touches the right edge of the picture's top rows."""
    from tmfem.post.render import render_configuration
    from tmfem.system import load_system
    from tests.cli.test_own_system import SYSTEMS

    s = load_system(SYSTEMS / "pentagon-1-5.toml")
    p = render_configuration(tmp_path / "c.png", s, tendon_forces=np.full(len(s.tendons), 10.0), title="t")
    fg = _non_background(_rgb(p))
    top = fg[: fg.shape[0] // 8]
    assert top[:, : fg.shape[1] // 8].any()          # the legend, at the upper left
    assert not top[:, -3:].any()                     # no text cut by the right edge
