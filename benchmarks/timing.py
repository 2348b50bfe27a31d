"""Shared timing functions of the benchmark scripts: best-of-n timing and where the time of a run
went, by timed call.

Run as ``python benchmarks/<script>.py``; the scripts import this module from their own
directory (it is on ``sys.path[0]`` when a script runs).
"""
from __future__ import annotations

import time


def best(fn, repeat: int = 3) -> float:
    """The shortest wall time of ``repeat`` calls of ``fn`` [s]."""
    t = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        t.append(time.perf_counter() - t0)
    return min(t)


def print_breakdown(times: dict, counts: dict, wall: float, rest: str) -> None:
    """One line per timed call (count, seconds, per call, share of ``wall``) and the rest,
    labelled ``rest``."""
    for k, t in times.items():
        if counts[k]:
            print(f"  {k:<14} {counts[k]:6d} calls {t:7.2f} s ({1e3 * t / counts[k]:7.3f} ms/call, "
                  f"{100 * t / wall:4.1f} %)")
    left = wall - sum(times.values())
    print(f"  {'rest (' + rest + ')':<14} {left:6.2f} s ({100 * left / wall:4.1f} %)")
