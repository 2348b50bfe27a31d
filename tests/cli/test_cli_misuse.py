"""CLI misuse battery: every bad option or input gives one line on stderr and the exit code
of the contract in docs/guides/cli.md (tmfem.errors), before any expensive step. Sources of the
numbers in the messages: the 1-4 preset (Table 6.2: |S_1| = 1.53111 m from eq. 3.29) and
the memory estimate of tmfem.cli.common.check_mesh_budget."""
import os
import signal
import subprocess
import sys
import time

import pytest

from tmfem.cli import main

BAD_INPUT, TOO_LARGE, REFUSED = 2, 3, 1


def run(argv, capsys):
    try:
        rc = main(argv)
    except SystemExit as exc:          # argparse usage errors
        rc = exc.code
    out, err = capsys.readouterr()
    return rc, out, err


def last_line(err):
    lines = [l for l in err.strip().splitlines() if l.strip()]
    assert lines, "expected a message on stderr"
    return lines[-1]


@pytest.fixture
def latin1(tmp_path):
    p = tmp_path / "latin1.toml"
    p.write_bytes('name = "caf\xe9"\nN = 4\n'.encode("latin-1"))
    return p


@pytest.fixture
def string_rest(tmp_path):
    from tmfem.system import dump_system, load_preset
    p = tmp_path / "s.toml"
    dump_system(load_preset("1-4"), p)
    p.write_text(p.read_text() + '\n[rest_lengths]\nS1 = "1.5"\n')
    return p


@pytest.mark.parametrize("argv, code, needle", [
    (["vibrate", "--preset", "1-4", "--t-end", "inf"], BAD_INPUT, "finite"),
    (["vibrate", "--preset", "1-4", "--t-end", "nan"], BAD_INPUT, "finite"),
    (["vibrate", "--preset", "1-4", "--t-end", "1e9"], TOO_LARGE, "steps; the limit is"),
    (["vibrate", "--preset", "1-4", "--dt", "1e-9"], TOO_LARGE, "steps; the limit is"),
    (["vibrate", "--preset", "1-4", "--dt", "100", "--t-end", "1"], BAD_INPUT, "at least one step"),
    (["vibrate", "--preset", "1-4", "--perturb", "theta_11=nan"], BAD_INPUT, "finite"),
    (["vibrate", "--preset", "1-4", "--perturb", "theta_11=0.1", "--perturb", "theta_11=0.2"],
     BAD_INPUT, "at most once"),
    (["modal", "--preset", "1-4", "--mesh", "2000"], TOO_LARGE, "GiB"),
    (["equilibrium", "--preset", "1-4", "--mesh", "5000"], TOO_LARGE, "GiB"),
    (["mesh", "--preset", "1-4", "--mesh", "20000", "OUT.msh"], TOO_LARGE, "GiB"),
    (["study", "--preset", "2-3", "--out", "OUT", "--map-grid", "1"], BAD_INPUT, "--map-grid"),
    (["study", "--preset", "1-4", "--out", "OUT", "--mesh", "3000"], TOO_LARGE, "GiB"),
    (["static", "--preset", "1-4", "--rest-lengths", "S1=2.0"], BAD_INPUT, "every tendon is slack"),
    (["static", "--preset", "1-4", "--vtk", "FILE/x.vtu"], BAD_INPUT, "not a directory"),
    (["vibrate", "--preset", "1-4", "--csv", "FILE/h.csv"], BAD_INPUT, "not a directory"),
    (["vibrate", "--preset", "1-4", "--vtk", "FILE"], BAD_INPUT, "is a file"),
    (["converge", "--preset", "1-4", "--plot", "FILE/c.png"], BAD_INPUT, "not a directory"),
    (["study", "--preset", "1-4", "--out", "FILE"], BAD_INPUT, "is a file"),
    (["report", "--preset", "1-4", "--out", "FILE"], BAD_INPUT, "is a file"),
    (["report", "--preset", "1-4", "--out", "OUT", "--dt", "0"], BAD_INPUT, "> 0"),
    (["equilibrium", "--preset", "1-4", "--attachment", "distributed", "--patch", "5"],
     BAD_INPUT, "half the shortest"),
    (["equilibrium", "--preset", "nope"], BAD_INPUT, "unknown preset"),
    # commands added after the first sweep (deploy, control, lpv, benchmark, --model sbc);
    # the limits: MAX_STEPS, control.MAX_STATES, control_lpv.MAX_VERIFY_POINTS, MAX_MEMBRANE_MODES
    (["deploy", "--preset", "1-4D", "--t-end", "nan"], BAD_INPUT, "finite"),
    (["deploy", "--preset", "1-4D", "--t-end", "abc"], BAD_INPUT, "expected a number"),
    (["deploy", "--preset", "1-4D", "--dt", "-1"], BAD_INPUT, "> 0"),
    (["deploy", "--preset", "1-4D", "--t-end", "1e9"], TOO_LARGE, "steps; the limit is"),
    (["deploy", "--preset", "1-4D", "--dt", "1", "--t-end", "0.5"], BAD_INPUT, "at least one step"),
    (["deploy", "--preset", "nope"], BAD_INPUT, "invalid choice"),
    (["deploy", "--preset", "1-4D", "--csv", "FILE/d.csv"], BAD_INPUT, "not a directory"),
    (["deploy", "--preset", "1-4D", "--plot", "OUT/d.txt"], BAD_INPUT, "suffix"),
    (["deploy", "--preset", "1-4D", "--gif", "OUT/d.png"], BAD_INPUT, "suffix"),
    (["deploy", "--preset", "1-4D", "--vtk", "FILE"], BAD_INPUT, "is a file"),
    (["control", "hinf", "--preset", "1-4D", "--membrane-modes", "0"], BAD_INPUT, "K >= 1"),
    (["control", "hinf", "--preset", "1-4D", "--membrane-modes", "1000"], TOO_LARGE, "states"),
    (["control", "hinf", "--preset", "1-4D", "--save", "FILE/k.npz"], BAD_INPUT, "not a directory"),
    (["control", "hinf", "--preset", "1-4D", "--save", "OUT/k.txt"], BAD_INPUT, "suffix"),
    (["control", "hinf", "--preset", "1-4D", "--plot", "OUT/k.txt"], BAD_INPUT, "suffix"),
    (["control", "hinf", "--preset", "1-4D", "--alpha", "abc"], BAD_INPUT, "invalid float"),
    (["control", "pbh", "--preset", "1-4D", "--alpha", "1"], BAD_INPUT, "hinf` only"),
    (["control", "hinf", "--preset", "1-4D", "--method", "central", "--solver", "CLARABEL"],
     BAD_INPUT, "--method lmi only"),
    (["control", "hinf", "--preset", "nope"], BAD_INPUT, "unknown preset"),
    (["control", "recheck", "FILE"], BAD_INPUT, "expected an .npz"),
    (["control", "recheck", "OUT/missing.npz"], BAD_INPUT, "expected an .npz"),
    (["control", "lpv", "--max-iter", "-5"], BAD_INPUT, "--max-iter"),
    (["control", "lpv", "--refine", "100000"], TOO_LARGE, "verification grid"),
    (["control", "lpv", "--grid", "abc"], BAD_INPUT, "AxB"),
    (["control", "lpv", "--rate-bound-deg", "nan"], BAD_INPUT, "--rate-bound-deg"),
    (["control", "lpv", "--save", "FILE/p.npz"], BAD_INPUT, "not a directory"),
    (["control", "lpv", "--preset", "1-4"], BAD_INPUT, "expected an [lpv] table"),
    (["benchmark", "nope"], BAD_INPUT, "expected one of"),
    (["benchmark", "truss-arch", "--plot", "OUT/b.txt"], BAD_INPUT, "suffix"),
    (["benchmark", "--list", "--csv", "OUT/b.csv"], BAD_INPUT, "--list"),
    (["static", "--model", "sbc", "--preset", "1-4", "--bar-elements", "100000"], TOO_LARGE, "GiB"),
    (["static", "--model", "sbc", "--preset", "1-4", "--tendon-elements", "100000"], TOO_LARGE, "GiB"),
    (["static", "--model", "sbc", "--preset", "1-4", "--wrinkle-plot", "OUT/w.png"], BAD_INPUT,
     "does not apply"),
    (["static", "--model", "sbc", "--preset", "1-4", "--patch", "0.1"], BAD_INPUT, "does not apply"),
    (["static", "--model", "sbc", "--preset", "1-4", "--rest-lengths", "S1=nan"], BAD_INPUT,
     "positive rest lengths"),
    (["static", "--model", "sbc", "--preset", "1-4", "--start", "design"], BAD_INPUT, "does not apply"),
    (["modal", "--model", "sbc", "--preset", "1-4", "--mesh", "3", "--modes", "100000"], BAD_INPUT,
     "free DOFs"),
    (["modal", "--model", "com", "--preset", "1-4", "--membrane-modes", "1000"], TOO_LARGE, "K <= 40"),
    (["modal", "--model", "com", "--preset", "1-4", "--modes", "100"], BAD_INPUT, "coordinates"),
    (["modal", "--preset", "1-4", "--mesh", "3", "--modes", "100000"], BAD_INPUT, "free DOFs"),
    (["vibrate", "--preset", "1-4", "--vtk-every", "5"], BAD_INPUT, "does not apply"),
    (["converge", "--preset", "1-4", "--mesh", "3", "--patch", "0.2"], BAD_INPUT, "does not apply"),
    (["converge", "--preset", "1-4", "--mesh", "3", "--attachment", "distributed", "--patch", "50"],
     BAD_INPUT, "half the shortest"),
    (["converge", "--preset", "1-4", "--mesh", "3", "--modes", "100000"], BAD_INPUT, "DOFs"),
    (["static", "--preset", "1-4", "--wrinkle-plot", "FILE/w.png"], BAD_INPUT, "not a directory"),
    (["report", "--preset", "2-3", "--out", "OUT", "--no-deploy"], BAD_INPUT, "does not apply"),
    (["report", "--preset", "1-4", "--out", "OUT", "--modes", "20"], BAD_INPUT, "coordinates"),
    # a pseudo-filesystem that refuses writes (os.access says yes to root): a real write
    (["vibrate", "--preset", "1-4", "--csv", "/proc/h.csv"], BAD_INPUT, "not writable"),
    (["static", "--preset", "1-4", "--vtk", "/sys/s.vtu"], BAD_INPUT, "not writable"),
    (["study", "--preset", "1-4", "--out", "/proc/study"], BAD_INPUT, "cannot create"),
    (["equilibrium", "/dev/zero"], BAD_INPUT, "at most 1,048,576 bytes"),
    (["static", "--preset", "1-4", "--png", "OUT/a.png", "--stress-plot", "OUT/a.png"], BAD_INPUT,
     "expected its own output path, found the one of --png"),
    (["export", "tests/data/systems/triangle-1-3.toml"], BAD_INPUT, "the output file comes after the system file"),
    (["mesh", "tests/data/systems/triangle-1-3.toml", "--mesh", "4"], BAD_INPUT, "found only"),
    (["compare", "--preset", "1-4", "--mesh", "2000"], TOO_LARGE, "GiB"),
    (["compare", "--preset", "1-4", "--vibrate", "--mesh", "2000"], TOO_LARGE, "GiB"),
    (["vibrate", "--preset", "1-4", "--t-end", "1000", "--vtk", "OUT/s", "--vtk-every", "1"],
     TOO_LARGE, "100,001 ParaView frames; the limit is 10,000"),
    # the eigen solver's basis beside the model (tmfem.cli.common.check_model_budget)
    (["modal", "--preset", "1-4", "--mesh", "150", "--modes", "50000"], TOO_LARGE,
     "basis of 2 x 50000 vectors needs about"),
])
def test_misuse_one_line_and_exit_code(argv, code, needle, tmp_path, capsys):
    f = tmp_path / "a_file"
    f.write_text("x")
    argv = [str(f) + a[4:] if a.startswith("FILE") else
            (str(tmp_path / "out") + a[3:] if a.startswith("OUT") else a) for a in argv]
    t0 = time.perf_counter()
    rc, out, err = run(argv, capsys)
    assert rc == code, err
    line = last_line(err)
    assert "Traceback" not in err and line.startswith(("tmfem", "usage")), err
    if needle:
        assert needle in line, line
    assert time.perf_counter() - t0 < 20       # refused up front, not after the work


def test_bad_system_files(latin1, string_rest, capsys):
    rc, _, err = run(["equilibrium", str(latin1)], capsys)
    assert rc == BAD_INPUT and "UTF-8" in last_line(err)
    for cmd in (["equilibrium"], ["static"], ["modal"]):      # same verdict in every command
        rc, _, err = run(cmd + [str(string_rest)], capsys)
        assert rc == BAD_INPUT and "'S1'" in last_line(err) and "'1.5'" in last_line(err)


def test_failed_check_exits_1_unless_allowed(capsys):
    # the initial 1-4(D) configuration (Table 7.3) is in equilibrium but its SU tendons are
    # above the 94.8 MPa yield of 7.4.1: a failed design check, which exited 0 before
    rc, out, err = run(["equilibrium", "--preset", "1-4D-initial", "--mesh", "4"], capsys)
    assert rc == REFUSED and "[FAIL] tendon yield" in out
    assert last_line(err) == "tmfem equilibrium: failed checks: tendon yield (exit 1; see docs/guides/cli.md)"
    rc, out, _ = run(["equilibrium", "--preset", "1-4D-initial", "--mesh", "4",
                      "--allow-infeasible"], capsys)
    assert rc == 0 and "[FAIL] tendon yield" in out
    # an infeasible design (2-3 as printed: its rest lengths do not belong to its geometry)
    rc, _, err = run(["equilibrium", "--preset", "2-3", "--as-printed", "--mesh", "4"], capsys)
    assert rc == REFUSED and "Traceback" not in err


@pytest.mark.parametrize("argv", [
    ["vibrate", "--preset", "1-4", "--t-end", "1000", "--dt", "0.01"],
    pytest.param(["deploy", "--preset", "1-4D", "--t-end", "1000"],   # in the controller design
                 marks=pytest.mark.slow),
])
def test_ctrl_c_is_one_line_exit_130(argv, tmp_path):
    """SIGINT at the command's first line on stderr (what it runs, or its first progress
    line): from then on it builds the model or designs the controller, inside compiled code
    (CasADi, the factorisations, the synthesis)."""
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    p = subprocess.Popen([sys.executable, "-m", "tmfem"] + argv,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, text=True)
    first = p.stderr.readline()
    assert first.startswith("tmfem"), first
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=60)
    err = first + err
    assert p.returncode == 130, err
    assert "Traceback" not in err and err.strip().splitlines()[-1] == f"tmfem {argv[0]}: interrupted"
