"""Command-line interface: a thin shell over the Python API.

Each subcommand lives in its own module exposing ``add_parser(subparsers)``
and ``run(args) -> int``. Errors derived from :class:`fepost.errors.FepostError`
become a one-line message on stderr and exit status 2 (a traceback only with
``--debug``).
"""

from __future__ import annotations

import argparse
import sys
import warnings
from collections.abc import Sequence

from ..errors import FepostError, FepostWarning

_COMMANDS = ("coefficients", "table1", "report", "diagnose", "sweep")


def build_parser() -> argparse.ArgumentParser:
    from importlib import import_module

    parser = argparse.ArgumentParser(
        prog="fepost",
        description="FE tire-road contact results -> coupled dry-friction model coefficients.",
    )
    parser.add_argument("--debug", action="store_true", help="show tracebacks on errors")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in _COMMANDS:
        import_module(f"{__name__}.{name}").add_parser(sub)
    return parser


def _show_warning(message, category, filename, lineno, file=None, line=None):
    name = category.__name__
    print(f"fepost: warning ({name}): {message}", file=sys.stderr)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI with ``argv`` (default: ``sys.argv[1:]``); return the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    old = warnings.showwarning
    warnings.showwarning = _show_warning
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("always", FepostWarning)
            return int(args.func(args) or 0)
    except FepostError as exc:
        if args.debug:
            raise
        print(f"fepost: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("fepost: interrupted", file=sys.stderr)
        return 130
    finally:
        warnings.showwarning = old


def console_main() -> None:
    sys.exit(main())
