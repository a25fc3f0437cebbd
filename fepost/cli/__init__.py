"""Command-line interface: a thin shell over the Python API.

Each subcommand is a module of this package named in `COMMANDS`, exposing
``add_parser(subparsers)`` and ``run(args) -> int``. A subcommand module is light
at import (argparse, this package's helpers, `fepost.errors`): the whole
parser is built from them on every run, so ``fepost --help`` and usage errors
never import numpy, scipy, VTK or matplotlib; ``run`` imports what it needs.
Option types and ranges are in `fepost.cli._validate`.

`main` is the edge where exceptions become exit statuses
(`EXIT_STATUSES`, also in ``docs/cli-exit-codes.md``): every failure is
one line on stderr, a traceback only with ``--debug``; fepost's warnings are
printed as one line each, other libraries' warnings (numpy's RuntimeWarnings
among them) are not shown to users (``--debug`` shows them; the test suite
turns them into errors, so each one is a defect to fix where it arises).
"""

from __future__ import annotations

import argparse
import difflib
import functools
import os
import signal
import sys
import threading
import warnings
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from importlib import import_module

from .. import __version__
from ..errors import FepostError, FepostWarning

#: The subcommands, in the order ``fepost --help`` lists them; each is the module
#: ``fepost.cli.<name>``. Registering a new command is one line here.
COMMANDS = [
    "coefficients",
    "table1",
    "report",
    "diagnose",
    "predict",
    "sweep",
    "rig",
    "shimmy",
    "pushes",
    "map",
]

#: Exit statuses of ``fepost`` (the ``--help`` epilog and docs/cli-exit-codes.md).
EXIT_STATUSES = {
    0: "success",
    1: "finished, but some inputs failed (a table or report marks them)",
    2: "bad input or usage: a file or option refused, named in one line",
    3: "internal error: a bug in fepost or a library, or out of memory (--debug shows it)",
    130: "interrupted (Ctrl-C); nothing half-written is left",
    141: "the output pipe was closed (e.g. '| head'); stopped quietly",
    143: "terminated (SIGTERM; 129 for SIGHUP); nothing half-written is left",
}
OK, FAILED_INPUTS, BAD_INPUT, INTERNAL = 0, 1, 2, 3
BROKEN_PIPE = 141


class UsageError(Exception):
    """A command line the parser refuses (printed as one line, exit status 2)."""


class Terminated(BaseException):
    """SIGTERM or SIGHUP arrived: unwinds like Ctrl-C so temporary outputs are removed."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are one line (no usage block) and do not exit."""

    def error(self, message: str):  # type: ignore[override]
        raise UsageError(f"{message} (see '{self.prog} --help')")

    def _print_message(self, message: str, file=None) -> None:
        # argparse swallows OSError here; a closed pipe must reach main() (exit status 141)
        if message:
            (file or sys.stderr).write(message)


def _epilog() -> str:
    lines = ["exit status:"]
    lines += [f"  {code:>3}  {text}" for code, text in EXIT_STATUSES.items()]
    lines.append("Details: docs/cli-exit-codes.md.")
    return "\n".join(lines)


def build_parser() -> argparse.ArgumentParser:
    """The ``fepost`` parser with every subcommand in `COMMANDS` (light imports only)."""
    parser = _Parser(
        prog="fepost",
        description="FE tire-road contact results -> coupled dry-friction model coefficients.",
        epilog=_epilog(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"fepost {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks and library warnings")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in COMMANDS:
        import_module(f"{__name__}.{name}").add_parser(sub)
    return parser


@functools.cache
def _parser() -> argparse.ArgumentParser:
    """`build_parser`, built once per process: parsing does not change a parser, and a process
    that runs many commands (a test session, a script calling `main`) saves 20 ms each."""
    return build_parser()


#: Longest message printed; longer ones (a 200 kB CSV cell quoted back) lose their middle.
MESSAGE_MAX = 1000


def _one_line(text: object) -> str:
    line = " ".join(str(text).split())
    if len(line) > MESSAGE_MAX:
        cut = len(line) - MESSAGE_MAX + 40
        half = (MESSAGE_MAX - 40) // 2
        line = f"{line[:half]} ...[{cut} characters]... {line[-half:]}"
    return line


class _Run:
    """State of one run: ``--debug``, and the signal that stopped it, if any.

    The signal is recorded before its exception is raised because a library may
    turn that exception into another one on its way up (an interrupted import
    inside VTK surfaces as ImportError and then as "cannot read the file"); the
    recorded signal decides the exit status.
    """

    def __init__(self) -> None:
        self.debug = False
        self.signum: int | None = None
        self.reported = False

    def show_warning(self, message, category, filename, lineno, file=None, line=None) -> None:
        """``warnings.showwarning``: fepost's warnings as one line, others only with --debug."""
        if issubclass(category, FepostWarning):
            print(f"fepost: warning ({category.__name__}): {_one_line(message)}", file=sys.stderr)
        elif self.debug:
            where = f"{os.path.basename(filename)}:{lineno}"
            print(f"fepost: debug: {category.__name__} at {where}: {_one_line(message)}", file=sys.stderr)

    def on_signal(self, signum, frame) -> None:
        """SIGINT/SIGTERM/SIGHUP: record it and raise, unless an import is running.

        An exception raised while VTK's extension modules initialise crashes the
        process (SIGSEGV, seen in testing); inside an import the raise waits for
        a SIGALRM 50 ms later that checks again (`on_alarm`).
        """
        self.signum = self.signum or signum
        # The exception unwinds through half-built objects (a renderer stopped in its
        # constructor); their finalisers then fail, and Python would print each such
        # failure as "Exception ignored in ..." after the one-line message. And when the
        # signal lands inside a finaliser, the stop itself is such an "ignored" exception.
        sys.unraisablehook = self.on_unraisable
        self.on_alarm(signal.SIGALRM, frame)

    def on_unraisable(self, unraisable) -> None:
        """``sys.unraisablehook`` after a stopping signal.

        A stop raised where Python cannot propagate it (a finaliser, a weakref
        callback) would be lost: it is raised again `_RECHECK` later, in whatever
        ordinary frame runs then. Finalisers' own errors stay quiet (shown with --debug).
        """
        if issubclass(unraisable.exc_type, KeyboardInterrupt | Terminated):
            signal.setitimer(signal.ITIMER_REAL, _RECHECK)
        elif self.debug:
            sys.__unraisablehook__(unraisable)

    def on_alarm(self, signum, frame) -> None:
        if self.signum is None:
            return
        if _importing(frame):
            signal.setitimer(signal.ITIMER_REAL, _RECHECK)
            return
        if self.signum == signal.SIGINT:
            raise KeyboardInterrupt
        raise Terminated(self.signum)

    def stopped(self) -> int:
        """Report the recorded signal; the exit status 128 + signal number (130 for Ctrl-C)."""
        assert self.signum is not None
        if not self.reported:  # once, whichever way the stop came up
            self.reported = True
            if self.signum == signal.SIGINT:
                _say("fepost: interrupted")
            else:
                _say(f"fepost: terminated by {signal.Signals(self.signum).name}")
        return 128 + self.signum


#: Delay (s) before a signal that arrived during an import is checked again.
_RECHECK = 0.05


def _importing(frame) -> bool:
    """Whether ``frame`` (a signal handler's) runs inside an import."""
    while frame is not None:
        if frame.f_code.co_filename.startswith("<frozen importlib._bootstrap"):
            return True
        frame = frame.f_back
    return False


@contextmanager
def _signals_unwind(run: _Run) -> Iterator[None]:
    """SIGINT, SIGTERM and SIGHUP raise (recorded in ``run``) while the command runs.

    Only in the main thread, and only for signals not set to be ignored (``nohup``).
    SIGALRM is used to defer a signal that arrives during an import.
    """
    if threading.current_thread() is not threading.main_thread() or not hasattr(signal, "setitimer"):
        yield
        return
    old = {signal.SIGALRM: signal.signal(signal.SIGALRM, run.on_alarm)}
    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        sig = getattr(signal, name, None)
        if sig is not None and signal.getsignal(sig) is not signal.SIG_IGN:
            old[sig] = signal.signal(sig, run.on_signal)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        for sig, handler in old.items():
            signal.signal(sig, handler)


def _silence_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's final flush cannot fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):
        pass


def _say(line: str) -> None:
    try:
        sys.stderr.write(line + "\n")  # one write: a signal handled between two cannot split the line
    except (OSError, ValueError):
        pass


def _error(message: object) -> None:
    _say(f"fepost: error: {_one_line(message)}")


def _internal(exc: BaseException) -> int:
    _error(f"internal error: {type(exc).__name__}: {exc} (rerun with --debug and report it)")
    return INTERNAL


def _subparser(parser: argparse.ArgumentParser, name: str | None) -> argparse.ArgumentParser | None:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction) and name in action.choices:
            return action.choices[name]
    return None


def _suggest(word: str, choices: Sequence[str]) -> str:
    """`` (did you mean X?)`` for the closest of ``choices`` (difflib), or nothing."""
    close = difflib.get_close_matches(word, choices, n=1, cutoff=0.6)
    return f" (did you mean {close[0]}?)" if close else ""


def _options_of(parser: argparse.ArgumentParser | None) -> list[str]:
    return [] if parser is None else [o for a in parser._actions for o in a.option_strings]


def _known(name: str, options: Sequence[str]) -> bool:
    """``name`` is one of ``options`` or an abbreviation of exactly one (argparse's rule)."""
    return name in options or len([o for o in options if o.startswith(name)]) == 1


def _check_long_options(parser: argparse.ArgumentParser, argv: list[str]) -> None:
    """Refuse an unknown ``--option`` before argparse looks at the rest, naming the nearest
    known one; an option of ``fepost`` itself after the command (``--debug``, ``--version``)
    or a subcommand's option before it is told where it belongs."""
    at = next((i for i, a in enumerate(argv) if a in COMMANDS), None)
    top = _options_of(parser)
    cmd = None if at is None else argv[at]
    sub = _options_of(_subparser(parser, cmd)) if cmd else []
    for i, arg in enumerate(argv):
        if arg == "--":
            return
        if not arg.startswith("--"):
            continue
        name = arg.split("=", 1)[0]
        before = at is None or i < at
        if _known(name, top if before else sub):
            continue
        if not before and name in top:
            raise UsageError(
                f"{name} is an option of fepost itself, not of '{cmd}': put it before the command "
                f"('fepost {name} {cmd} ...')"
            )
        if before and cmd and name in sub:
            raise UsageError(
                f"{name} is an option of '{cmd}': put it after the command ('fepost {cmd} {name} ...')"
            )
        where = f"fepost {cmd}" if cmd and not before else "fepost"
        options = top if before else [*sub, *top]
        raise UsageError(f"unrecognized argument {arg!r}{_suggest(name, options)} (see '{where} --help')")


def _parse(parser: argparse.ArgumentParser, argv: list[str]) -> argparse.Namespace:
    """Parse ``argv``; an unknown option or command is a `UsageError` naming the nearest
    known one and the subcommand's help."""
    _check_long_options(parser, argv)
    command = next((a for a in argv if not a.startswith("-")), None)
    if command is not None and command not in COMMANDS:
        raise UsageError(f"unknown command {command!r}{_suggest(command, COMMANDS)} (see 'fepost --help')")
    args, extra = parser.parse_known_args(argv)
    if extra:
        sub = _subparser(parser, getattr(args, "command", None)) or parser
        unknown = next((a for a in extra if a.startswith("-")), extra[0])
        name = unknown.split("=", 1)[0]
        hint = _suggest(name, _options_of(sub)) if name.startswith("-") else ""
        raise UsageError(f"unrecognized argument {unknown!r}{hint} (see '{sub.prog} --help')")
    return args


def _run(argv: list[str], run: _Run) -> int:
    from ._validate import check_grid, check_outputs, check_strings, resolve_defaults

    run.debug = "--debug" in argv[: next((i for i, a in enumerate(argv) if a in COMMANDS), len(argv))]
    try:
        parser = _parser()
        if not [a for a in argv if a != "--debug"]:  # a bare `fepost`: the help, as a usage error
            parser.print_help(sys.stderr)
            return BAD_INPUT
        args = _parse(parser, argv)
        resolve_defaults(args)
        check_strings(parser, args)
        check_grid(args)
        check_outputs(args)
        status = int(args.func(args) or 0)
        sys.stdout.flush()
        return status
    except SystemExit as exc:  # --help, --version
        sys.stdout.flush()
        return exc.code if isinstance(exc.code, int) else (OK if exc.code is None else BAD_INPUT)
    except UsageError as exc:
        _error(exc)
        return BAD_INPUT
    except (KeyboardInterrupt, Terminated, BrokenPipeError):
        raise
    except Exception as exc:
        if run.signum is not None:  # a signal's exception, changed on its way up
            return run.stopped()
        if run.debug:
            raise
        if isinstance(exc, FepostError):
            _error(exc)
            return BAD_INPUT
        if isinstance(exc, OSError) and exc.filename is not None:  # names the file
            _error(f"{exc.filename}: {exc.strerror or exc}")
            return BAD_INPUT
        if isinstance(exc, MemoryError):
            _error("out of memory (a smaller grid, --nr/--nphi, or a smaller model may fit)")
            return INTERNAL
        return _internal(exc)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI with ``argv`` (default: ``sys.argv[1:]``); return the exit status.

    Never raises (except with ``--debug``) and never exits: the status follows
    `EXIT_STATUSES`.
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    run = _Run()
    with warnings.catch_warnings():
        warnings.simplefilter("always", FepostWarning)
        warnings.showwarning = run.show_warning
        try:
            with _signals_unwind(run):
                status = _run(argv, run)
            # a stop whose exception was swallowed on its way up (e.g. by a library's
            # `except BaseException`) still ends the run as a stop
            return status if run.signum is None else run.stopped()
        except KeyboardInterrupt:
            run.signum = run.signum or signal.SIGINT
            return run.stopped()
        except Terminated as exc:
            run.signum = exc.signum
            return run.stopped()
        except BrokenPipeError:
            _silence_stdout()
            return BROKEN_PIPE


#: Whether this process is the ``fepost`` command (`console_main`) rather than a program calling
#: `main`: a command may then tune the process for its one run
#: (`fepost.cli.coefficients.warm_heap`).
WHOLE_PROCESS = False

#: Environment variable OpenBLAS (numpy's and scipy's BLAS) reads its thread count from, once,
#: when it loads.
BLAS_THREADS_ENV = "OPENBLAS_NUM_THREADS"


def console_main() -> None:
    """Entry point of the ``fepost`` script.

    BLAS runs on one thread unless the user's environment says otherwise (`BLAS_THREADS_ENV`,
    set here before any command imports numpy). fepost's products are thin (n x 3, a polar
    grid against a few columns): more BLAS threads never finish sooner, and after each call
    they spin, taking the cores from fepost's own threads and the reading child. On the
    1.08 M-node surface map they took about 0.15 s of the process's CPU time
    (benchmarks/bench_read.py)."""
    os.environ.setdefault(BLAS_THREADS_ENV, "1")
    global WHOLE_PROCESS
    WHOLE_PROCESS = True
    status = main()
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        _silence_stdout()
        status = status or BROKEN_PIPE
    if _command(sys.argv[1:]) in QUICK_EXIT and threading.active_count() == 1:
        _quick_exit(status)
    sys.exit(status)


#: Commands whose process ends with ``os._exit`` once its work is done (`_quick_exit`): each has
#: closed and renamed its outputs before `main` returns, and starts no thread or process that
#: outlives it. Freeing a million-node map's arrays and the imported libraries' modules at the
#: interpreter's teardown took about 35 ms of the 1.08 M-node surface map's run
#: (benchmarks/bench_read.py).
QUICK_EXIT = frozenset({"coefficients"})


def _command(argv: Sequence[str]) -> str | None:
    """The subcommand of a ``fepost`` command line: its first word that is not an option
    (``fepost`` itself takes no option with a value)."""
    return next((a for a in argv if not a.startswith("-")), None)


def _quick_exit(status: int) -> None:
    """End the process with ``status`` and no interpreter teardown: the standard streams are
    flushed and the exit functions registered with `atexit` run first (a library's clean-up
    is kept); only the freeing of memory the operating system takes back anyway is skipped.
    Called only when no other thread runs (none would be joined)."""
    import atexit

    try:
        sys.stdout.flush()
    except (OSError, ValueError):
        _silence_stdout()
        status = status or BROKEN_PIPE
    atexit._run_exitfuncs()
    try:
        sys.stderr.flush()
    except (OSError, ValueError):
        pass
    os._exit(status)
