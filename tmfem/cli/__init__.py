"""The ``tmfem`` command line.

Every module of this package that defines ``NAME``, ``HELP``, ``configure(parser)`` and
``run(args) -> dict`` is a subcommand. ``run`` returns a JSON-serialisable result; with
``--json`` it is printed as one JSON document on stdout, otherwise the module's
``format_text(result) -> str`` (or a default rendering) is printed.

Exit codes (docs/guides/cli.md): a :class:`tmfem.errors.TmfemError` becomes one line on stderr
and its ``exit_code`` (1 the analysis says no, 2 bad input, 3 too large for this machine,
4 missing backend); a result whose ``ok`` is false or whose ``checks`` failed is printed
and exits 1 unless the command was given ``--allow-infeasible``; an output path that
cannot be written, or an output directory in use by another run (:mod:`tmfem.io.lock`), is
exit 2; Ctrl-C prints one line and exits 130, SIGTERM 143. Never a traceback for any of
these.
"""
from __future__ import annotations

import _thread
import argparse
import importlib
import json
import logging
import math
import os
import pkgutil
import signal
import sys
import threading
import time
import warnings

import numpy as np

from tmfem.errors import InputError, ResourceLimit, TmfemError


def subcommands() -> dict:
    """Every subcommand: its name and module, all of them imported."""
    mods = (command_module(info.name) for info in pkgutil.iter_modules(__path__))
    return dict(sorted((mod.NAME, mod) for mod in mods if mod is not None))


def command_module(name: str):
    """The module of subcommand ``name`` (imported), or None when no module of this package
    of that name defines ``NAME``, ``HELP``, ``configure`` and ``run``."""
    if name.startswith("_") or name == "common" or name not in _MODULE_NAMES:
        return None
    mod = importlib.import_module(f"{__name__}.{name}")
    return mod if all(hasattr(mod, a) for a in ("NAME", "HELP", "configure", "run")) else None


#: Names of the modules of this package (found without importing them).
_MODULE_NAMES = frozenset(info.name for info in pkgutil.iter_modules(__path__))


class _HelpWithDefaults(argparse.HelpFormatter):
    """Help text that states every option's default (unless its help already does)."""

    def _get_help_string(self, action):
        text = action.help or ""
        d = action.default
        if (action.option_strings and d not in (None, False, argparse.SUPPRESS, [], ())
                and "default" not in text):
            text += f" (default {d})"
        return text


def build_parser(command=None) -> argparse.ArgumentParser:
    """The parser of ``tmfem``: every subcommand, or only ``command`` (its module, from
    :func:`command_module`), which is all a command line of that command needs. Importing a
    command's module imports the library it runs, so a run imports only its own command's
    (``tmfem --help`` and an unknown command import them all, to list them)."""
    parser = argparse.ArgumentParser(prog="tmfem", description="Tensegrity-membrane systems: "
                                     "equilibrium, finite-element and control-oriented models, control.")
    sub = parser.add_subparsers(dest="command", metavar="<command>")
    sub.required = True
    commands = {command.NAME: command} if command is not None else subcommands()
    for name, mod in commands.items():
        p = sub.add_parser(name, help=mod.HELP, description=mod.HELP,
                           formatter_class=_HelpWithDefaults)
        p.add_argument("--json", action="store_true", help="print one JSON document on stdout")
        p.add_argument("--quiet", action="store_true",
                       help="no progress bars and no library progress lines (logging INFO) "
                            "on stderr; warnings and errors still")
        mod.configure(p)
        p.set_defaults(_module=mod)
    return parser


def _default_text(result) -> str:
    return json.dumps(result, indent=2, default=str)


def _one_line(text: str) -> str:
    """A message on one line (numpy arrays in messages print over several)."""
    return " ".join(str(text).split())


def failed_checks(result) -> list[str]:
    """Names of the failed checks of a command's result: ``result["failed_checks"]``, the
    entries of ``result["checks"]`` whose ``ok`` is false, or ``["ok"]`` when only
    ``result["ok"]`` is false."""
    if not isinstance(result, dict):
        return []
    names = list(result.get("failed_checks") or [])
    for c in result.get("checks") or []:
        if isinstance(c, dict) and c.get("ok") is False:
            n = c.get("name", c.get("check", "check"))
            if n not in names:
                names.append(n)
    if not names and result.get("ok") is False:
        names = ["ok"]
    return names


class _MessageFormatter(logging.Formatter):
    """``tmfem: <message>``, and ``tmfem: WARNING: <message>`` from WARNING up."""

    def format(self, record):
        text = record.getMessage()
        if record.levelno >= logging.WARNING:
            text = f"{record.levelname}: {text}"
        return f"tmfem: {text}"


def _once(record) -> bool:
    """Handler filter: each WARNING text once per run (a command's warnings, the library's
    log lines and the Python warnings alike; :func:`_setup_logging` starts a run)."""
    if record.levelno != logging.WARNING:
        return True
    text = record.getMessage()
    if text in _SHOWN:
        return False
    _SHOWN.add(text)
    return True


_HANDLER = logging.StreamHandler(sys.stderr)
_HANDLER.setFormatter(_MessageFormatter())
_HANDLER.addFilter(_once)


def _setup_logging(*, quiet: bool = False) -> None:
    """Library progress (``logging`` INFO of the ``tmfem`` loggers, not with ``--quiet``)
    and warnings on stderr, one line each, prefixed ``tmfem:``. Python warnings (the
    library's and numpy's) go through the same channel: once per message, without the
    source path and line (:func:`_show_warning`)."""
    log = logging.getLogger("tmfem")
    if _HANDLER not in log.handlers:
        log.addHandler(_HANDLER)
        log.propagate = False
    _HANDLER.stream = sys.stderr          # this run's stderr (the old one may be closed)
    log.setLevel(logging.WARNING if quiet else logging.INFO)
    _SHOWN.clear()
    warnings.showwarning = _show_warning


_SHOWN: set = set()


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """``warnings.showwarning`` of the CLI: the warning as one ``tmfem: WARNING:`` line of
    the ``tmfem`` logger, each text once per run, without the source location."""
    text = _one_line(message)
    if (text, category) in _SHOWN:
        return
    _SHOWN.add((text, category))
    logging.getLogger("tmfem").warning("%s (%s)", text, category.__name__)


#: Exit codes of the signals the CLI ends on: 128 + the signal number, as a shell reports.
SIGNAL_EXITS = {signal.SIGINT: (130, "interrupted"), signal.SIGTERM: (143, "terminated")}
#: Seconds the main thread has to take SIGTERM before its own thread ends the process.
SIGTERM_GRACE_S = 5.0


def _install_interrupt_handler(command: str, cleanup=None, *, ranks=None):
    """Ctrl-C (SIGINT) and SIGTERM: one line (``interrupted`` / ``terminated``) and exit
    code 130 / 143, at once. A KeyboardInterrupt raised inside compiled callbacks (CasADi
    functions of the control-oriented model) is swallowed there and resurfaces as an
    unrelated error, so the handler ends the process itself, after ``cleanup()`` (removes
    temporary files and the output locks). What was written so far stays valid and marked:
    time series keep their ``.partial`` name and the ``.pvd`` its ``incomplete`` comment
    (docs/guides/cli.md, "Partial files").

    SIGTERM is blocked and taken by a thread of its own (``sigwait``): compiled libraries
    reset its disposition to the default (measured: the COM's free vibration does, after its
    first steps), which would end the process without a word. The thread hands it to the
    main thread (``_thread.interrupt_main``), so that nothing is written while the handler
    cleans up; when the main thread stays in a compiled call for :data:`SIGTERM_GRACE_S`,
    the thread ends the process itself.

    Under mpiexec (``ranks``, a :class:`_Ranks`) both signals are taken by that thread and
    end the rank at once: its main thread may wait in a collective call for a rank that has
    ended, and mpiexec kills the job about a second after a rank ends. The rank that
    receives the signal first passes it on to the other ranks of its host (mpiexec passes
    its own SIGINT and SIGTERM on to every rank), and only rank 0 prints the line, so that
    every rank exits with the same code and the job says it once. Returns a function that
    puts the previous handling back (None off the main thread)."""
    if threading.current_thread() is not threading.main_thread():
        return None
    ending = threading.Lock()

    def end(signum):
        if not ending.acquire(blocking=False):      # the other path is ending the process
            return
        code, what = SIGNAL_EXITS[signum]
        if ranks is not None:
            ranks.forward(signum)
        sys.stdout.flush()
        if cleanup is not None:
            cleanup()
        if ranks is None or ranks.rank == 0:
            # on a line of its own: a progress bar may be half drawn
            print(f"\ntmfem {command}: {what}", file=sys.stderr, flush=True)
        else:
            ranks.wait_for_root()
        os._exit(code)

    previous = {sig: signal.signal(sig, lambda signum, frame: end(signum)) for sig in SIGNAL_EXITS}
    waited = set(SIGNAL_EXITS) if ranks is not None else {signal.SIGTERM}
    signal.pthread_sigmask(signal.SIG_BLOCK, waited)
    state = {"stopping": False}

    def wait():
        signum = signal.sigwait(waited)
        if state["stopping"]:
            return
        if ranks is not None:
            end(signum)
            return
        _thread.interrupt_main(signal.SIGTERM)     # the handler runs on the main thread
        time.sleep(SIGTERM_GRACE_S)
        end(signal.SIGTERM)
    waiter = threading.Thread(target=wait, name="tmfem-sigterm", daemon=True)
    waiter.start()

    def restore():
        state["stopping"] = True
        signal.pthread_kill(waiter.ident, signal.SIGTERM)
        waiter.join()
        signal.pthread_sigmask(signal.SIG_UNBLOCK, waited)
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    return restore


class _Ranks:
    """The rank of this process under mpiexec and the process ids of the ranks on its host
    (filled by :meth:`meet`, a collective call), to which a signal is passed on.

    A rank other than 0 that ends on a signal first waits for rank 0 to end (at most
    :data:`RANK_END_WAIT_S`): rank 0's main thread may be inside a compiled collective call
    that holds the interpreter lock and completes only while the other ranks still take
    part; once rank 0 has printed its line and removed its files, the others follow."""

    def __init__(self, rank: int):
        self.rank = rank
        self.peers: list[int] = []
        self.root: int | None = None

    def meet(self, comm) -> None:
        import socket
        here = (socket.gethostname(), os.getpid())
        everyone = comm.allgather(here)
        self.peers = [pid for host, pid in everyone if host == here[0] and pid != here[1]]
        if everyone[0][0] == here[0] and self.rank != 0:
            self.root = everyone[0][1]

    def forward(self, signum) -> None:
        for pid in self.peers:
            try:
                os.kill(pid, signum)
            except OSError:                        # that rank has ended already
                pass

    def wait_for_root(self) -> None:
        """Return when rank 0 has ended (or after :data:`RANK_END_WAIT_S`)."""
        t0 = time.monotonic()
        while self.root is not None and _running(self.root):
            if time.monotonic() - t0 > RANK_END_WAIT_S:
                return
            time.sleep(0.01)


#: Seconds a rank other than 0 waits for rank 0 to end after a signal (:class:`_Ranks`).
RANK_END_WAIT_S = 3.0


def _running(pid: int) -> bool:
    """Whether process ``pid`` runs (neither gone nor a zombie)."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


#: Options that name an output: a file (``static --vtk s.vtu``, ``mesh OUT.msh``), whose
#: directory is locked, or a directory without a suffix (``study --out``, ``vibrate --vtk``),
#: locked itself.
OUTPUTS = ("out", "vtk", "png", "stress_plot", "wrinkle_plot", "csv", "plot", "save", "gif",
           "compare_csv", "compare_plot")


#: File in an output directory (``--out``) while its run has not ended: a run that fails or
#: is interrupted leaves it, since the directory may then hold files of an earlier run.
INCOMPLETE_MARK = "INCOMPLETE"


def _mark_incomplete(args):
    """Write :data:`INCOMPLETE_MARK` into the output directory ``--out`` (when there is
    one); returns its path, or None."""
    from pathlib import Path
    out = getattr(args, "out", None)
    if not isinstance(out, (str, os.PathLike)) or Path(out).suffix or not Path(out).is_dir():
        return None
    mark = Path(out) / INCOMPLETE_MARK
    mark.write_text(f"tmfem {args.command} (pid {os.getpid()}) has not finished writing this "
                    "directory; a run that stops leaves this file, and the directory may then "
                    "hold files of an earlier run\n")
    return mark


def output_directories(args) -> list:
    """The directories a command will write to (:data:`OUTPUTS`), each once; two options
    that name the same path (``--csv a.csv --compare-csv a.csv``) are refused."""
    from pathlib import Path
    dirs, seen = [], {}
    for dest in OUTPUTS:
        value = getattr(args, dest, None)
        if isinstance(value, (str, os.PathLike)) and str(value):
            p = Path(value)
            key = os.path.abspath(p)
            if key in seen:
                raise InputError(f"--{dest.replace('_', '-')} {str(value)!r}: expected its own "
                                 f"output path, found the one of --{seen[key].replace('_', '-')} "
                                 "(one would overwrite the other)")
            seen[key] = dest
            dirs.append(p.parent if p.suffix else p)
    return list(dict.fromkeys(dirs))


def main(argv=None) -> int:
    """Entry point of the ``tmfem`` console script; returns the exit code (docs/guides/cli.md)."""
    words = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(command_module(words[0]) if words else None)
    args = parser.parse_args(words)
    mod = args._module
    show_warning = warnings.showwarning          # put back when main returns
    _setup_logging(quiet=args.quiet)
    from tmfem.cli.common import QUIET
    QUIET["on"] = args.quiet
    if _mpi_size() > 1:
        return _main_mpi(args, mod)
    from tmfem.io.atomic import remove_pending
    from tmfem.io.lock import OutputLock
    lock = OutputLock()

    def cleanup():
        remove_pending()
        lock.release()
    restore = _install_interrupt_handler(args.command, cleanup)
    try:
        for d in output_directories(args):
            lock.acquire(d, label=f"tmfem {args.command}")
        mark = _mark_incomplete(args)
        result = mod.run(args)
        _warn_unused_petsc_options(args.command)
        print(render(args, mod, result))
        if mark is not None:
            mark.unlink(missing_ok=True)
    except TmfemError as exc:
        print(f"tmfem {args.command}: error: {_one_line(exc)}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        print(f"tmfem {args.command}: interrupted", file=sys.stderr)
        return 130
    except OSError as exc:                     # an output that cannot be written
        print(f"tmfem {args.command}: error: {_one_line(_unwritable(exc))}", file=sys.stderr)
        return 2
    except MemoryError:
        print(f"tmfem {args.command}: error: {_OUT_OF_MEMORY}", file=sys.stderr)
        return 3
    finally:
        cleanup()
        if restore is not None:
            restore()
        warnings.showwarning = show_warning
    return _checks_exit(args, result)


_OUT_OF_MEMORY = ("out of memory; the estimates of docs/guides/cli.md (Limits) did not foresee this "
                  "job: reduce the input that scales it (mesh, modes, steps, stages)")


def render(args, mod, result) -> str:
    """The text a command prints: one JSON document (``--json``, with the units) or the
    module's ``format_text``."""
    if args.json:
        from tmfem.io.units import with_units
        return json.dumps(_finite(with_units(result)), default=json_default, allow_nan=False)
    return getattr(mod, "format_text", _default_text)(result)


def _warn_unused_petsc_options(command: str) -> None:
    """Warn of the solver options of PETSC_OPTIONS that no solver of the run read
    (:func:`tmfem.solvers.petsc_options.unused_options`): a misspelt option, or one of a solver the
    command does not create, would otherwise change nothing without a word."""
    if "petsc4py.PETSc" not in sys.modules:
        return
    from tmfem.solvers.petsc_options import unused_options
    left = unused_options()
    if left:
        logging.getLogger("tmfem").warning(
            "PETSc options that no solver of this run read: %s (misspelt, or for a solver that "
            "tmfem %s does not create, or that the default direct solve ignores, such as "
            "-ksp_rtol)", " ".join(left), command)


def _unwritable(exc: OSError) -> str:
    """The message of an output that cannot be written."""
    where = f" {exc.filename}" if getattr(exc, "filename", None) else ""
    return f"cannot write{where}: {exc.strerror or exc}"


def _checks_exit(args, result, *, printing: bool = True) -> int:
    """Exit code of a finished command: 1 when checks failed (listed on stderr when
    ``printing``) unless ``--allow-infeasible``, else 0."""
    failed = failed_checks(result)
    if failed and not getattr(args, "allow_infeasible", False):
        if printing:
            print(f"tmfem {args.command}: failed checks: {', '.join(map(str, failed))} "
                  "(exit 1; see docs/guides/cli.md)", file=sys.stderr)
        return 1
    return 0


def _mpi_size() -> int:
    """Number of ranks when started by mpiexec, else 1."""
    from tmfem.solvers.petsc_loader import launched_ranks
    return launched_ranks()


def _main_mpi(args, mod) -> int:
    """Under ``mpiexec -n P`` (P > 1): the PETSc backend only; the command runs on every rank,
    rank 0 alone prints and writes the output files (docs/guides/backends.md#mpi), an error is
    printed once with a non-zero exit, never a hang. Rank 0 takes the output locks and the
    ``INCOMPLETE`` mark; a run refused there (a directory in use) is refused on every rank
    at once. SIGINT or SIGTERM to mpiexec or to any rank ends every rank with one line and
    exit 130 / 143 (:func:`_install_interrupt_handler`)."""
    rank = int(os.environ.get("OMPI_COMM_WORLD_RANK") or os.environ.get("PMI_RANK") or 0)

    def refuse(found: str) -> int:
        # before MPI starts: rank 0 prints and exits 2, the others end quietly with 0 (a
        # non-zero exit of another rank makes mpiexec kill rank 0, its line perhaps unwritten)
        if rank != 0:
            return 0
        print(f"tmfem {args.command}: error: under mpiexec with {_mpi_size()} ranks expected "
              f"{found}", file=sys.stderr, flush=True)
        return 2
    if not hasattr(args, "backend"):       # a command without --backend solves with scipy
        return refuse(f"a command with a distributed backend (--backend petsc), found "
                      f"`tmfem {args.command}`, which runs on one process: run it without mpiexec")
    if args.backend not in ("petsc", "auto", None):    # None: the default, auto
        return refuse(f"--backend petsc, found --backend {args.backend} (every rank would "
                      "solve the whole problem alone)")
    from tmfem.io.atomic import remove_pending
    from tmfem.io.lock import OutputLock
    lock, ranks = OutputLock(), _Ranks(rank)

    def cleanup():
        remove_pending()
        lock.release()
    # before MPI starts: the threads of MPI and PETSc inherit the blocked signals
    restore = _install_interrupt_handler(args.command, cleanup, ranks=ranks)
    try:
        return _run_ranks(args, mod, ranks, lock)
    finally:
        cleanup()
        if restore is not None:
            restore()


def _run_ranks(args, mod, ranks, lock) -> int:
    """The body of :func:`_main_mpi` on one rank; returns its exit code."""
    import contextlib
    import io

    from tmfem.cli.common import OUTPUT_SUFFIXES, check_outputs
    from tmfem.solvers.distributed import collective, comm_world, mpi_main
    rank = ranks.rank
    if rank != 0:
        # the other ranks compute the same result (and take part in every collective call)
        # but write nothing: no output files, no progress, no log lines
        for dest in OUTPUT_SUFFIXES:
            if getattr(args, dest, None) is not None:
                setattr(args, dest, None)
        logging.getLogger("tmfem").setLevel(logging.CRITICAL)
        logging.getLogger("py.warnings").setLevel(logging.CRITICAL)
    result, marks = {}, []

    def body():
        ranks.meet(comm_world())
        with collective(what=f"tmfem {args.command}"):
            # the output paths are checked and locked by rank 0 before any work: every rank
            # learns of a refused one at once instead of waiting for rank 0 in the first
            # collective call
            if rank == 0:
                for d in output_directories(args):
                    lock.acquire(d, label=f"tmfem {args.command}")
                marks.append(_mark_incomplete(args))
                check_outputs(args, args.command)
        with contextlib.redirect_stderr(sys.stderr if rank == 0 else io.StringIO()):
            try:
                result["value"] = mod.run(args)
                _warn_unused_petsc_options(args.command)
            except OSError as exc:             # rank 0's output that cannot be written
                raise InputError(_unwritable(exc)) from None
            except MemoryError:
                raise ResourceLimit(_OUT_OF_MEMORY) from None
        return render(args, mod, result["value"])
    code = mpi_main(body, report=rank_report(f"tmfem {args.command}: "))
    if code == 0:
        if marks and marks[0] is not None:
            marks[0].unlink(missing_ok=True)
        code = _checks_exit(args, result["value"], printing=rank == 0)
    return code


def rank_report(label: str = ""):
    """The ``report`` of :func:`tmfem.solvers.distributed.mpi_main` that prints: the text
    on stdout, an error as ``LABELerror: ...`` on stderr."""
    def report(text: str, *, error: bool) -> None:
        if error:
            print(f"{label}error: {text}", file=sys.stderr, flush=True)
        else:
            print(text, flush=True)
    return report


def _finite(obj):
    """``obj`` with non-finite floats replaced by None: JSON has no NaN or infinity
    (a tendon that would push has no rest length, a missing printed value is absent)."""
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_finite(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _finite(obj.tolist())
    if isinstance(obj, (float, np.floating)):
        return float(obj) if math.isfinite(obj) else None
    return obj


def json_default(obj):
    """``default`` of :func:`json.dumps` for numpy arrays and scalars."""
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
