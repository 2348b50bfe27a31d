"""The memory estimate of a finite-element model before it is built (tmfem.resources.fe_bytes,
tmfem.cli.common.check_model_budget) follows the backend that will solve it.

Sources of the numbers: the peaks measured with the PETSc backend on one rank and two ranks
(benchmarks/bench_memory_ranks.py: the 1-4 MTC model, static + 12 modes) and of the SBC model
(`tmfem modal --model sbc --preset 1-4 --mesh n --backend petsc`, peak RSS), listed in
docs/validation/benchmarks.md; the estimate must bound each of them, and stay within twice
the measurement so that it does not refuse what fits."""
import pytest

from tmfem.cli.common import backend_plan, check_model_budget
from tmfem.errors import ResourceLimit
from tmfem.resources import fe_bytes, memory_limit, mesh_dofs
from tmfem.system import load_preset

MB = 2**20


@pytest.mark.parametrize("n, ranks, measured_mb", [
    (80, 1, 486), (160, 1, 1521), (320, 1, 5731),
    (160, 2, 959 + 931), (320, 2, 3389 + 3312),        # both ranks on this machine
])
def test_petsc_mtc_estimate_bounds_the_measured_peaks(n, ranks, measured_mb):
    dofs = mesh_dofs(N=4, n=n, extra_dofs=3 * 4 * 2)
    need = fe_bytes(dofs, backend="petsc", ranks=ranks)
    assert measured_mb * MB <= need <= 2 * measured_mb * MB


@pytest.mark.parametrize("n, measured_mb", [(30, 501), (60, 1483), (90, 3145)])
def test_petsc_sbc_estimate_bounds_the_measured_peaks(n, measured_mb):
    dofs = mesh_dofs(N=4, n=n, dofs_per_node=6)
    need = fe_bytes(dofs, backend="petsc", dofs_per_node=6)
    assert measured_mb * MB <= need <= 2 * measured_mb * MB


def test_the_petsc_backend_admits_the_million_dof_model_scipy_cannot_hold():
    # 4 x 320 x 320 (1.23 M DOFs): 5.7 GB with PETSc on one rank, over the limit with
    # scipy's 16 kB per DOF
    system = load_preset("1-4")
    if fe_bytes(1.3e6, backend="petsc") > memory_limit():
        pytest.skip("a machine too small for the 1.2 M DOF model")
    dofs = check_model_budget(system, mesh=320, tendon_elements=3, backend="petsc")
    assert dofs > 1.2e6
    if fe_bytes(dofs) > memory_limit():
        with pytest.raises(ResourceLimit, match="needs about"):
            check_model_budget(system, mesh=320, tendon_elements=3, backend="scipy")


def test_the_plan_follows_backend_auto_and_the_launchers_ranks(monkeypatch):
    for var in ("OMPI_COMM_WORLD_SIZE", "OMPI_COMM_WORLD_LOCAL_SIZE", "PMI_SIZE", "MPI_LOCALNRANKS"):
        monkeypatch.delenv(var, raising=False)
    assert backend_plan("scipy")(10**6) == ("scipy", 1, 1)
    assert backend_plan(None)(100) == ("scipy", 1, 1)          # below the crossover
    # under mpiexec: 8 ranks, 4 of them on this machine; auto takes PETSc whatever the size
    monkeypatch.setenv("OMPI_COMM_WORLD_SIZE", "8")
    monkeypatch.setenv("OMPI_COMM_WORLD_LOCAL_SIZE", "4")
    assert backend_plan("auto")(100) == ("petsc", 8, 4)
    # the ranks on this machine hold their start-up each and their share of the rest
    one = fe_bytes(10**6, backend="petsc", ranks=8, ranks_here=1)
    four = fe_bytes(10**6, backend="petsc", ranks=8, ranks_here=4)
    assert four == pytest.approx(4 * one)
