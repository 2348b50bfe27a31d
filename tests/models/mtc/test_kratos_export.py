"""The Kratos model that benchmarks/bench_kratos.py writes from an MTC model is the same model:
the same nodes, free dofs and elements, the membrane's reference geometry, the truss forces at
any length (against tmfem's truss kernel, eq. 4.7 on the rest length) and the total mass
(against tmfem's element mass matrices). Runs without Kratos."""
import importlib.util
from pathlib import Path

import numpy as np
import pytest

from tmfem.errors import InputError
from tmfem.fem.truss import TrussSet, truss_internal
from tmfem.models.mtc.model import MTCModel
from tmfem.system import load_preset

BENCH = Path(__file__).resolve().parents[3] / "benchmarks" / "bench_kratos.py"


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("bench_kratos", BENCH)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def model():
    return MTCModel(load_preset("1-4"), mesh_n=4)


@pytest.fixture(scope="module")
def export(bench, model):
    return bench.export_model(model)


def test_same_nodes_dofs_and_elements(model, export):
    topo = model.topology
    nn = export["coords"].shape[1]
    assert nn == int((topo.red_node >= 0).sum())
    assert 3 * nn - 3 * export["fixed"].size == model.ndof == int(export["ndof"])
    assert export["quads"].shape == topo.mesh.t.shape
    assert export["truss_conn"].shape[1] == model.bars.ne + model.tendons.ne
    assert export["quads"].min() == 1 and export["quads"].max() == topo.n_mesh     # 1-based ids
    # every bar top is its membrane corner's node
    tops = export["truss_conn"][1, :model.bars.ne]
    assert set(tops) == {int(n) + 1 for n in topo.mesh.corners}


def test_membrane_reference_is_the_mesh(model, export):
    """The Kratos membrane's reference geometry (its initial nodes) is tmfem's flat mesh moved
    rigidly: every element edge and diagonal has the mesh's length."""
    t, p = export["quads"] - 1, model.topology.mesh.p
    X = export["coords"]
    for a, b in ((0, 1), (1, 2), (2, 3), (3, 0), (0, 2), (1, 3)):
        np.testing.assert_allclose(np.linalg.norm(X[:, t[b]] - X[:, t[a]], axis=0),
                                   np.linalg.norm(p[:, t[b]] - p[:, t[a]], axis=0), rtol=1e-12)


def test_truss_forces_equal_tmfem_at_any_length(bench, export):
    """Kratos trusses measure strain from their initial node distance L0; with the exported
    properties their axial force equals tmfem's (strain on the rest length L) at every length."""
    X, conn = export["coords"], export["truss_conn"] - 1
    L0 = np.linalg.norm(X[:, conn[1]] - X[:, conn[0]], axis=0)
    L = export["truss_L"]
    assert np.max(np.abs(L0 / L - 1)) > 1e-3          # the start is not the rest state
    props = bench.kratos_truss_properties(L0, L, export["truss_EA"], export["truss_rhoA"])
    rng = np.random.default_rng(1)
    for l in (L0, L * (1 + 0.05 * rng.random(L.size)), L * (1 + 0.3 * rng.random(L.size))):
        ts = TrussSet(conn=np.array([np.zeros(L.size, int), np.arange(1, L.size + 1)]), L=L,
                      EA=export["truss_EA"], rhoA=export["truss_rhoA"], tension_only=np.zeros(L.size, bool))
        x = np.zeros((3, L.size + 1))
        x[0, 1:] = l
        N = truss_internal(x, ts, tangent=False).N
        np.testing.assert_allclose(bench.kratos_truss_force(l, L0, props), N, rtol=1e-10, atol=1e-9)


def test_total_mass_equals_tmfem(bench, model, export):
    X, t = export["coords"], export["quads"] - 1
    E, nu, rho, h = export["membrane"]
    d1, d2 = X[:, t[2]] - X[:, t[0]], X[:, t[3]] - X[:, t[1]]      # planar quads: |d1 x d2| / 2
    area = 0.5 * np.linalg.norm(np.cross(d1.T, d2.T), axis=1).sum()
    conn = export["truss_conn"] - 1
    L0 = np.linalg.norm(X[:, conn[1]] - X[:, conn[0]], axis=0)
    props = bench.kratos_truss_properties(L0, export["truss_L"], export["truss_EA"], export["truss_rhoA"])
    kratos_mass = rho * h * area + np.sum(props["rho"] * L0)          # CROSS_AREA 1
    tmfem_mass = sum(e.mass() for e in model.elements).sum() / 3.0
    assert kratos_mass == pytest.approx(tmfem_mass, rel=1e-12)


def test_distributed_attachment_refused(bench):
    m = MTCModel(load_preset("1-4"), mesh_n=4, attachment="distributed", patch=0.6)
    with pytest.raises(InputError, match="point attachment"):
        bench.export_model(m)
