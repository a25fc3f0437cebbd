"""Types, ranges and lazily read defaults for the subcommands' options.

Every ``type=`` callable here takes the option's text and returns the value, or
raises `argparse.ArgumentTypeError` saying what is wrong with what was
given; the parser prefixes the option's name (``argument --seed: ...``) and the
CLI prints that one line and exits with status 2. Values that are valid but
implausible are accepted with an `OptionWarning`.

The ranges (documented in ``docs/cli-exit-codes.md`` and each option's help):

================  ======================================================
``--friction``    a number in [0.001, 10] (`fepost.options.FRICTION_RANGE`); above
                  `FRICTION_PLAUSIBLE` (1.5) accepted with a warning:
                  tire rubber on a road reaches about 1.2 (dry asphalt)
``--threshold``   a number strictly between 0 and 1 (fraction of the peak)
``--seed``        an integer >= 0 (numpy's generators take no negative seed)
``--inflation-pressure``  a pressure with an optional unit (``1.38e6``,
                  ``1380kPa``, ``1.38 MPa``, ``13.8bar``, ``200psi``; no
                  unit: Pa) in (0, 1 GPa]; outside [10 kPa, 10 MPa]
                  accepted with a warning (`pressure`)
``--nr``          an integer in [2, 4096]; ``--nphi`` in [4, 16384]; and
                  the grid must fit in memory (`check_grid`)
table1            ``--span`` in (0, 100], ``--k-x`` in [-10, 10],
                  ``--amplitude`` in [0, 2], ``--n-points`` in [2, 10^6]
================  ======================================================

The outer limits are where the computations stop being meaningful in floating
point (Table 1's curves overflow for ψ spans of 1000, a noise amplitude of 5 or
f = 1e-300), far outside any physical case.

This module is light on purpose (argparse and the standard library only): the
parser is built from it on every run, including ``fepost --help``, which must not
import numpy, scipy or VTK. Library defaults that live in heavy modules are given
as `LibraryDefault` and read only when the help shows them or the
command runs.
"""

from __future__ import annotations

import argparse
import math
import os
import warnings
from importlib import import_module

from ..errors import OptionWarning

#: Above this friction coefficient ``--friction`` warns (accepted: rubber on
#: glass or on a clean dry surface can reach 2-3, so it is not refused).
FRICTION_PLAUSIBLE = 1.5
#: Largest grid sizes accepted per option (a million-node FE patch is resolved
#: by 256 x 512; the default is 64 x 128).
NR_MAX = 4096
NPHI_MAX = 16384
#: Memory per polar-grid node budgeted for one run, bytes. Measured (tracemalloc
#: peak of ``analyse`` and of ``table1(source="exact")`` on a small FE map): per
#: node it falls to 140 and 220 bytes at 2-8 million nodes (2048 x 4096 peaked
#: at 2.1 GB resident); doubled for the report's extra maps and rounded.
BYTES_PER_GRID_NODE = 400


def _text(value: str) -> str:
    return repr(value) if isinstance(value, str) else repr(str(value))


def _number(text: str) -> float:
    try:
        return float(text)
    except (TypeError, ValueError):
        raise argparse.ArgumentTypeError(f"not a number: {_text(text)}") from None


def _integer(text: str) -> int:
    try:
        return int(str(text).strip(), 10)
    except (TypeError, ValueError):
        raise argparse.ArgumentTypeError(f"not an integer: {_text(text)}") from None


def friction(text: str) -> float:
    """Friction coefficient f by the one rule, `fepost.options.check_friction`; a warning
    above `FRICTION_PLAUSIBLE`."""
    from ..errors import ArgumentError
    from ..options import FRICTION_RANGE, check_friction

    f = _number(text)
    try:
        check_friction(f)
    except ArgumentError:
        lo, hi = FRICTION_RANGE
        raise argparse.ArgumentTypeError(
            f"must be a friction coefficient in [{lo:g}, {hi:g}], got {_text(text)}"
        ) from None
    if f > FRICTION_PLAUSIBLE:
        warnings.warn(
            f"--friction {f:g} is above {FRICTION_PLAUSIBLE:g}, implausible for a tire on a road "
            "(dry asphalt about 0.8-1.2); going on with it",
            OptionWarning,
            stacklevel=2,
        )
    return f


#: Units ``--inflation-pressure`` accepts, in Pa.
PRESSURE_UNITS = {"pa": 1.0, "kpa": 1e3, "mpa": 1e6, "gpa": 1e9, "bar": 1e5, "psi": 6894.757293168361}
#: Inflation pressures of real tires: a bicycle's 0.1 MPa ... an aircraft's 1.4-2 MPa.
PRESSURE_PLAUSIBLE = (1e4, 1e7)


def pressure(text: str) -> float:
    """An inflation pressure in Pa, from a number and an optional unit of `PRESSURE_UNITS`."""
    raw = str(text).strip()
    number = raw.rstrip("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ").strip()
    unit = raw[len(raw.rstrip("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ")) :].lower()
    if unit and unit not in PRESSURE_UNITS:
        names = ", ".join(k if k != "pa" else "Pa" for k in PRESSURE_UNITS)
        raise argparse.ArgumentTypeError(f"unknown pressure unit {unit!r} in {_text(text)} (use {names})")
    try:
        p = float(number) * PRESSURE_UNITS[unit or "pa"]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"not a pressure: {_text(text)} (e.g. 1.38e6, 1380kPa, 13.8bar)"
        ) from None
    from ..options import PRESSURE_MAX

    if not (math.isfinite(p) and 0.0 < p <= PRESSURE_MAX):
        raise argparse.ArgumentTypeError(f"must be a positive pressure up to 1 GPa, got {_text(text)}")
    lo, hi = PRESSURE_PLAUSIBLE
    if not lo <= p <= hi:
        warnings.warn(
            f"--inflation-pressure {p:g} Pa is outside {lo:g}-{hi:g} Pa, implausible for a tire "
            "(a unit missing? a bare number is Pa); going on with it",
            OptionWarning,
            stacklevel=2,
        )
    return p


def fraction(text: str) -> float:
    """A fraction strictly between 0 and 1 (e.g. ``--threshold``)."""
    x = _number(text)
    if not (0.0 < x < 1.0):
        raise argparse.ArgumentTypeError(f"must be a number between 0 and 1 (exclusive), got {_text(text)}")
    return x


def seed(text: str) -> int:
    """Random seed: an integer >= 0."""
    s = _integer(text)
    if s < 0:
        raise argparse.ArgumentTypeError(f"must be an integer >= 0, got {_text(text)}")
    return s


def integer_in(lo: int, hi: int | None = None, what: str = "an integer"):
    """Type for an integer in [lo, hi] (no upper bound when ``hi`` is None)."""

    def check(text: str) -> int:
        n = _integer(text)
        if n < lo or (hi is not None and n > hi):
            span = f">= {lo}" if hi is None else f"in [{lo}, {hi}]"
            raise argparse.ArgumentTypeError(f"must be {what} {span}, got {_text(text)}")
        return n

    check.__name__ = "integer"
    return check


def number_in(lo: float, hi: float):
    """Type for a number in [lo, hi]."""

    def check(text: str) -> float:
        x = _number(text)
        if not (lo <= x <= hi):
            raise argparse.ArgumentTypeError(f"must be a number in [{lo:g}, {hi:g}], got {_text(text)}")
        return x

    check.__name__ = "number"
    return check


def span(text: str) -> float:
    """Largest ψ and υ of Table 1's curves: in (0, 100]."""
    x = _number(text)
    if not (0.0 < x <= 100.0):
        raise argparse.ArgumentTypeError(f"must be a number in (0, 100], got {_text(text)}")
    return x


def check_strings(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """Refuse an empty string (``--json ''``) or one holding a NUL character (no file
    name can) given to any option or input, naming it.

    Raises `ArgumentError`.
    """
    actions = list(parser._actions)
    command = getattr(args, "command", None)
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction) and command in action.choices:
            actions += action.choices[command]._actions
    for action in actions:
        value = getattr(args, action.dest, None)
        for item in value if isinstance(value, list) else [value]:
            if isinstance(item, str) and (not item.strip() or "\x00" in item):
                from ..errors import ArgumentError

                name = "/".join(action.option_strings) or str(action.metavar or action.dest)
                problem = "must not be empty" if not item.strip() else "contains a NUL character"
                raise ArgumentError(f"argument {name}: {problem}")


#: Destinations of the options that name outputs, in every subcommand (``predict --model-json`` too).
OUTPUT_OPTIONS = ("out", "json", "model_json")


def check_outputs(args: argparse.Namespace) -> None:
    """Refuse an output (``--out``, ``--json``) that is or contains one of the run's
    inputs, or whose folder does not exist, before any work is done.

    The inputs are every other path given on the command line that exists; the
    current and home folders are guarded too (`fepost.output.check_replaceable`).
    Raises `OutputError`.
    """
    values = []
    for key, value in vars(args).items():
        if key in OUTPUT_OPTIONS or key in ("func", "command"):
            continue
        for item in value if isinstance(value, list) else [value]:
            if isinstance(item, str) and os.path.exists(item):
                values.append(item)
    outputs = {key: getattr(args, key) for key in OUTPUT_OPTIONS if isinstance(getattr(args, key, None), str)}
    if outputs:
        from ..errors import OutputError
        from ..output import check_replaceable

        for key, out in outputs.items():
            check_replaceable(out, values)
            parent = os.path.dirname(out) or "."
            if not os.path.isdir(parent):  # fail now, not after the computation
                where = "parent folder" if key == "out" else "folder"
                raise OutputError(f"{out}: {where} {parent} does not exist")


radial_nodes = integer_in(2, NR_MAX)
angular_nodes = integer_in(4, NPHI_MAX)


class LibraryDefault:
    """A default kept in a (heavy) library module, read only when it is needed.

    ``default=LibraryDefault("fepost.table1", "DEFAULT_SEED")`` with a help text
    containing ``%(default)s`` shows the value in ``--help``; `resolve_defaults`
    replaces it by the module's attribute after parsing (the command imports that
    module anyway). For the help text the constant is read from the module's
    source, where it is a literal assignment, without importing it (importing
    ``fepost.table1`` takes a second); otherwise the module is imported.
    """

    def __init__(self, module: str, name: str) -> None:
        self.module, self.name = module, name

    @property
    def value(self):
        return getattr(import_module(self.module), self.name)

    def literal(self):
        """The value as written in the module's source (no import), or the imported value."""
        import ast

        try:
            origin = _source_file(self.module)
            tree = ast.parse(open(origin, encoding="utf-8").read()) if origin else None
        except (ImportError, OSError, SyntaxError, ValueError):
            tree = None
        for node in tree.body if tree is not None else ():
            target = node.target if isinstance(node, ast.AnnAssign) else None
            if isinstance(node, ast.Assign) and len(node.targets) == 1:
                target = node.targets[0]
            if isinstance(target, ast.Name) and target.id == self.name and node.value is not None:
                try:
                    return ast.literal_eval(node.value)
                except ValueError:
                    break
        return self.value

    def __str__(self) -> str:
        return str(self.literal())

    def __repr__(self) -> str:
        return f"LibraryDefault({self.module!r}, {self.name!r})"


def _source_file(module: str) -> str | None:
    """Source file of ``module`` found without importing it or its parent packages
    (``importlib.util.find_spec`` imports the parents, e.g. all of ``fepost.diagnose``)."""
    import sys
    from importlib.machinery import PathFinder

    parts = module.split(".")
    k = next(i for i in range(len(parts), -1, -1) if i == 0 or ".".join(parts[:i]) in sys.modules)
    if k == len(parts):
        return getattr(sys.modules[module], "__file__", None)
    path = getattr(sys.modules[".".join(parts[:k])], "__path__", None) if k else None
    origin = None
    for part in parts[k:]:
        spec = PathFinder.find_spec(part, path)
        if spec is None:
            return None
        origin, path = spec.origin, spec.submodule_search_locations
    return origin


def resolve_defaults(args: argparse.Namespace) -> None:
    """Replace every `LibraryDefault` left in ``args`` by its value."""
    for key, value in vars(args).items():
        if isinstance(value, LibraryDefault):
            setattr(args, key, value.value)


def _physical_memory() -> int | None:
    try:
        return int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, OSError, ValueError):
        return None


def check_grid(args: argparse.Namespace) -> None:
    """Refuse ``--nr`` x ``--nphi`` grids that cannot fit in this machine's memory.

    Raises `ArgumentError` with the estimate.
    """
    nr, nphi = getattr(args, "nr", None), getattr(args, "nphi", None)
    if not (isinstance(nr, int) and isinstance(nphi, int)):
        return
    need = nr * nphi * BYTES_PER_GRID_NODE
    have = _physical_memory()
    if have is not None and need > have // 2:
        from ..errors import ArgumentError

        raise ArgumentError(
            f"--nr {nr} x --nphi {nphi} = {nr * nphi:,} grid nodes need about {_size(need)} of memory "
            f"(~{BYTES_PER_GRID_NODE} bytes per node); this machine has {_size(have)}: use a smaller grid"
        )


def _size(n: float) -> str:
    for unit in ("bytes", "kB", "MB", "GB", "TB"):
        if n < 1000 or unit == "TB":
            return f"{n:.0f} {unit}" if unit == "bytes" else f"{n:.1f} {unit}"
        n /= 1000
    return f"{n:.1f} TB"
