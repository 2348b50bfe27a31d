"""Upper bounds of the options that scale an LPV run's or a deployment's work, refused before
any work with the limit and why (docs/guides/cli.md, "Limits, locks, partial files and
signals"): ``control lpv --max-iter`` (exit 3), ``--certificate-rounds`` and ``--verify-rounds``
(exit 2), and the
ParaView frames of ``deploy --vtk`` (exit 3, as ``vibrate --vtk``)."""
import argparse
import time

import pytest

from tests.cli.test_cli_misuse import BAD_INPUT, TOO_LARGE, last_line, run
from tmfem.cli.common import MAX_FRAMES, check_frames
from tmfem.cli.lpv_options import MAX_ITER, check_iteration_limits
from tmfem.errors import InputError, ResourceLimit
from tmfem.reference.deployments import VTK_EVERY

# the default grid of 2-3-lpv: 6 x 3 of the printed grid, refined 4 times for the verification:
# (6 - 1) 4 + 1 = 21 by (3 - 1) 4 + 1 = 9 points
FINE, DESIGN = 21 * 9, 6 * 3


def limits(**given):
    args = argparse.Namespace(**{"max_iter": None, "certificate_rounds": None, **given})
    check_iteration_limits(args, fine_points=FINE, design_points=DESIGN)


def test_max_iter_bounded_at_scs_own_cap():
    limits(max_iter=100_000)                     # SCS's default max_iters (tmfem.control.lpv.synthesis)
    assert MAX_ITER == 100_000
    with pytest.raises(ResourceLimit, match="the limit is 100,000"):
        limits(max_iter=100_001)


def test_certificate_rounds_bounded_by_the_points_a_round_can_add():
    limits(certificate_rounds=FINE - DESIGN)     # every round imposes at least one new point
    with pytest.raises(InputError, match="expected at most 171 .* found 172"):
        limits(certificate_rounds=FINE - DESIGN + 1)


def test_deploy_frames_bounded_as_vibrate():
    steps = VTK_EVERY * (MAX_FRAMES - 1)         # frames at steps 0, 10, ..., the last one
    assert check_frames(steps=steps, every=VTK_EVERY, option=None) == MAX_FRAMES
    with pytest.raises(ResourceLimit, match="raise --dt or lower --t-end"):
        check_frames(steps=steps + VTK_EVERY, every=VTK_EVERY, option=None)


@pytest.mark.parametrize("argv, code, needle", [
    (["control", "lpv", "--preset", "2-3-lpv", "--max-iter", "1000000"], TOO_LARGE,
     "--max-iter 1,000,000: each iteration is one pass of the solver"),
    (["control", "lpv", "--preset", "2-3-lpv", "--output-feedback", "--rate-certificate",
      "--certificate-rounds", "1000"], BAD_INPUT,
     "--certificate-rounds: expected at most 171 (each round re-solves"),
    # the cutting-plane rounds of a design failing between its points: each imposes at least one
    # verification-grid point beyond the design grid's (189 - 18 = 171)
    (["control", "lpv", "--preset", "2-3-lpv", "--verify-rounds", "172"], BAD_INPUT,
     "--verify-rounds: expected 0 to 171 (each round imposes"),
    (["control", "lpv", "--preset", "2-3-lpv", "--verify-rounds", "-1"], BAD_INPUT,
     "--verify-rounds: expected 0 to 171"),
    (["control", "pbh", "--preset", "1-4D", "--verify-rounds", "2"], BAD_INPUT, "verify-rounds"),
    (["deploy", "--preset", "2-3-lpv", "--lpv-controller", "x.npz", "--verify-rounds", "2"], BAD_INPUT,
     "belong to a synthesis on the fly"),
    (["deploy", "--preset", "1-4D", "--verify-rounds", "2"], BAD_INPUT, "apply to --controller lpv only"),
    # 1000 s / 0.01 s = 100 000 steps, a frame every 10: 10 001 frames
    (["deploy", "--preset", "1-4D", "--t-end", "1000", "--vtk", "OUT"], TOO_LARGE,
     "100,000 steps give 10,001 ParaView frames; the limit is 10,000"),
    (["deploy", "--preset", "2-3-lpv", "--t-end", "1000", "--vtk", "OUT"], TOO_LARGE,
     "100,000 steps give 10,001 ParaView frames"),
])
def test_refused_before_any_work(argv, code, needle, tmp_path, capsys):
    argv = [str(tmp_path / "vtk") if a == "OUT" else a for a in argv]
    t0 = time.perf_counter()
    rc, _, err = run(argv, capsys)
    assert rc == code, err
    assert needle in last_line(err) and len(err.strip().splitlines()) == 1, err
    assert time.perf_counter() - t0 < 20         # refused up front, not after the work
    assert not (tmp_path / "vtk").exists() or not any((tmp_path / "vtk").iterdir())
