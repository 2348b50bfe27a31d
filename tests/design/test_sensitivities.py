"""Design sensitivities of the MTC model against central finite differences of the
re-solved static equilibrium (step h = 1e-4 m on rest lengths of about 1.5 m; the
equilibrium re-solved to a residual of 1e-12 of the member forces from the nominal state)."""
import dataclasses

import numpy as np
import pytest

from tmfem.design import design_sensitivities
from tmfem.design.sensitivities import variable_map
from tmfem.errors import InputError
from tmfem.models.mtc.model import MTCModel
from tmfem.system import load_preset
from tests.design.test_responses import richardson

H = 1e-4
NODE = "B_11"


def responses(model, eq, k):
    """The responses of :func:`design_sensitivities` recomputed from a solved state."""
    s = design_sensitivities(model, equilibrium=eq, k=k, node=NODE)
    return np.concatenate([s.omega2, [s.max_tendon_force, s.max_tendon_stress, s.position]])


def fd_check(system, variables, k=4):
    m = MTCModel(system, mesh_n=4)
    eq = m.equilibrium(tol=1e-12)
    s = design_sensitivities(m, equilibrium=eq, variables=variables, k=k, node=NODE)
    exact = np.vstack([s.d_omega2, s.d_max_tendon_force, s.d_max_tendon_stress, s.d_position])
    _, G = variable_map(m, variables)
    r0 = m.rest_lengths.copy()
    fd = np.zeros_like(exact)
    for j in range(G.shape[1]):
        vals = []
        for sgn in (1, -1):
            mj = MTCModel(system, mesh_n=4, rest_lengths=r0 + sgn * H * G[:, j])
            vals.append(responses(mj, mj.equilibrium(x0=eq.state, tol=1e-12), k))
        fd[:, j] = (vals[0] - vals[1]) / (2 * H)
    return s, exact, fd


def rel_err(exact, fd):
    return np.abs(exact - fd) / np.maximum(np.abs(fd), 1e-8 * np.abs(fd).max())


def test_group_gradients_of_1_4_match_finite_differences():
    # the symmetric group variable keeps the pair omega_2 = omega_3 repeated: both derivatives equal
    s, exact, fd = fd_check(load_preset("1-4"), "groups")
    assert [len(c) for c in s.clusters[:2]] == [1, 2]
    assert np.all(rel_err(exact, fd) < 1e-5), rel_err(exact, fd)


def test_tendon_gradients_of_1_4_pair_sum_matches_finite_differences():
    # one tendon at a time splits the repeated pair: only the pair's sum is smooth; the four
    # tendons carry equal forces, so the largest tendon force has a kink there (not compared)
    s, exact, fd = fd_check(load_preset("1-4"), "tendons")
    pair = s.clusters[1]
    assert len(pair) == 2
    simple = np.r_[0, 3, 6]
    assert np.all(rel_err(exact[simple], fd[simple]) < 1e-5), rel_err(exact[simple], fd[simple])
    assert np.all(rel_err(exact[pair].sum(0), fd[pair].sum(0)) < 1e-5)


def test_group_gradients_of_two_stage_2_3_match_finite_differences():
    # seven tendon groups (S1, S2, V2, D2, C2, P2, R2) of a two-stage system; the groups keep
    # its three-fold symmetry, so the repeated pair omega_2 = omega_3 stays repeated and smooth
    s, exact, fd = fd_check(load_preset("2-3"), "groups", k=3)
    assert [len(c) for c in s.clusters] == [1, 2] and exact.shape[1] == 7
    assert np.all(rel_err(exact, fd) < 1e-5), rel_err(exact, fd)


def test_membrane_thickness_gradients_of_1_4_match_finite_differences():
    # the rest lengths stay at the nominal design's while the membrane thickness h changes
    system = load_preset("1-4")
    m = MTCModel(system, mesh_n=4)
    r0 = m.rest_lengths.copy()
    eq = m.equilibrium(tol=1e-12)
    s = design_sensitivities(m, equilibrium=eq, k=4, node=NODE, thickness=True)
    assert s.names == ["S1", "h_membrane"]
    exact = np.r_[s.d_omega2[:, 1], s.d_max_tendon_force[1], s.d_max_tendon_stress[1], s.d_position[1]]
    # central differences at 1 % and 2 % of h, Richardson-extrapolated (error O(dh^4)). h
    # keeps the symmetry, so omega_2 = omega_3 stays repeated: its two exact derivatives are
    # equal, and the pair is compared by its mean (the split of a re-solved pair is the
    # equilibrium's round-off, 1e-10 of omega^2, which a 1 % step turns into 5e-6 of a
    # difference of either member)
    h0 = system.membrane.h

    def values(p):
        sj = system.replace(membrane=dataclasses.replace(system.membrane, h=p[0]))
        mj = MTCModel(sj, mesh_n=4, rest_lengths=r0)
        return responses(mj, mj.equilibrium(x0=eq.state, tol=1e-12), 4)

    fd = richardson(values, np.array([h0]), [0.01 * h0])[:, 0]
    pair = s.clusters[1]
    assert len(pair) == 2 and rel_err(exact[pair[0]], exact[pair[1]]) < 1e-6
    exact[pair], fd[pair] = exact[pair].mean(), fd[pair].mean()
    assert np.all(rel_err(exact, fd) < 1e-5), rel_err(exact, fd)


def test_options_that_do_not_apply_are_refused():
    m = MTCModel(load_preset("1-4"), mesh_n=2)
    for kwargs, text in (({"variables": "bars"}, "variables"), ({"k": 0}, "k:"), ({"axis": 3}, "axis"),
                         ({"node": "Q_99"}, "Q_99")):
        with pytest.raises(InputError, match=text):
            design_sensitivities(m, **kwargs)
    with pytest.raises(InputError, match="tendon_law"):
        design_sensitivities(MTCModel(load_preset("1-4"), mesh_n=2, tendon_law="fixed-rate"))
