"""The main pipeline: FE export(s) → patch → polar map → moments → coefficients.

`analyse` is the documented entry point of the Python API::

    from fepost import analyse
    result = analyse("meshes/static.vtu", "meshes/rolling.vtu", friction=0.3)
    result.coefficients.M0, result.static_patch.circular, result.to_dict()
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from ._blas import one_blas_thread
from .coefficients import Coefficients, coefficients_from_moments
from .errors import ArgumentError, PatchWarning, ScaleError, ScaleWarning
from .field import ContactField
from .moments import Moments, moments
from .options import DEFAULT_FRICTION, AnalysisOptions, check_friction
from .patch import Patch, build_patch
from .polar import DEFAULT_NPHI, DEFAULT_NR, PolarGrid, PolarMap
from .reader import isolate, start_reading
from .reader.units import describe
from .refine import refined_map
from .resample import resample


@contextmanager
def float_range(source: object) -> Iterator[None]:
    """Turn an arithmetic overflow or a division by an underflowed zero inside the block into
    a `ScaleError` naming ``source``: a map whose loads or lengths reach the ends of the
    floating-point range (a load near 1.8e308 N, a radius near 1e-154 m) has no
    meaningful coefficients, and Python's own message names no file. numpy's
    RuntimeWarning is caught too where warnings are errors (``python -W error``)."""
    try:
        yield
    except (OverflowError, ZeroDivisionError, FloatingPointError, RuntimeWarning) as exc:
        raise ScaleError(
            f"{source}: values beyond the floating-point range in the analysis ({type(exc).__name__}: "
            f"{exc}); loads or lengths this large or small are no tire contact: check the file and --units"
        ) from None


@dataclass(frozen=True)
class Analysis:
    """Everything derived from a static (and optionally a rolling) FE map."""

    static_field: ContactField
    static_patch: Patch
    static_map: PolarMap
    static_moments: Moments
    coefficients: Coefficients
    rolling_field: ContactField | None = None
    rolling_patch: Patch | None = None
    rolling_map: PolarMap | None = None
    rolling_moments: Moments | None = None
    options: AnalysisOptions | None = None

    @property
    def load_mismatch_allowed(self) -> bool:
        """Whether the analysis was told to accept a rolling map of another load."""
        return self.options is not None and self.options.allow_load_mismatch

    def __repr__(self) -> str:
        c, p = self.coefficients, self.static_patch
        roll = (
            "" if self.rolling_field is None else f", rolling={self.rolling_field.source!r}, k_x={c.k_x:.6g}"
        )
        return (
            f"Analysis(static={self.static_field.source!r}, N={c.N:.6g} N, R={c.R:.6g} m, "
            f"M0={c.M0:.6g} N m, a={c.a:.6g}, m={c.m:.6g}, f={c.f:g}{roll}, "
            f"grid={self.grid.shape[0]}x{self.grid.shape[1]}, faces={len(p.triangles)})"
        )

    @property
    def grid(self) -> PolarGrid:
        return self.static_map.grid

    @cached_property
    def model_summary(self):
        """The generalised friction model of these maps (`fepost.friction.summary`)."""
        from .friction.law import FrictionLaw
        from .friction.summary import summarise

        c, p = self.coefficients, self.static_patch
        law = FrictionLaw(f=c.f)
        with float_range(self.static_field.source):
            return summarise(
                self.static_map, c, law, rolling_map=self.rolling_map, circular=p.circular, aspect=p.aspect
            )

    def to_dict(self, model: bool = True) -> dict:
        """The coefficients JSON (SI units, keys in docs/formats.md), with provenance.

        ``model``: include the generalised friction model (key ``model``; building
        it takes about a second: a table of many analyses may leave it out)."""
        d = self.coefficients.to_dict()
        d["N_fe"] = self.static_patch.N_fe
        d["patch"] = self.static_patch.to_dict()
        d["R_definition"] = (
            "r_max: smallest circle about the static centre of pressure holding every loaded point"
        )
        sf = self.static_field
        d["reaction_z"] = sf.reaction_z
        d["reactions"] = dict(sf.reactions)
        d["units"] = describe(sf.units)
        d["grid"] = {"rule": self.grid.rule, "nr": self.grid.shape[0], "nphi": self.grid.shape[1]}
        d["static"] = {
            "source": sf.source,
            "field": sf.field,
            "step": sf.step,
            "time": sf.time,
            "body": sf.body,
            "format": sf.format,
        }
        if self.rolling_patch is not None and self.rolling_field is not None and self.rolling_map is not None:
            rf = self.rolling_field
            d["rolling"] = {
                "source": rf.source,
                "field": rf.field,
                "step": rf.step,
                "N_fe": self.rolling_patch.N_fe,
                "reaction_z": rf.reaction_z,
                "centre_of_pressure": list(self.rolling_patch.centre_of_pressure),
                "grid_radius": self.rolling_map.radius,
                "load_ratio": self.rolling_patch.N_fe / self.static_patch.N_fe,
                "load_tolerance": LOAD_TOL,
                "load_mismatch_allowed": self.load_mismatch_allowed,
            }
        if model:  # generalised friction model (fepost.friction.summary)
            d["model"] = self.model_summary.to_dict()
        return d


#: Largest accepted |N/N_fe − 1| before a warning: the polar grid must carry the FE load.
RESAMPLE_TOL = 0.01
#: Largest accepted distance between N_fe and the solver's reaction before a warning.
REACTION_TOL = 0.10
#: Largest accepted |N_fe(rolling)/N_fe(static) − 1| of a static/rolling pair, unless the
#: caller allows a mismatch. The pair must be one tire at one load: the shipped pairs agree to
#: 0.4 % (aircraft, 100 %) and 1.5 % (small tire), a displacement-controlled rolling step moves
#: the load by a few tenths of a percent, while the nearest other load point of a sweep is
#: 25 % away; k_x = R x_c/<x^2> then mixes two patches (0.39 for 0.24 at 50 %/100 %).
LOAD_TOL = 0.03
_AXIS = re.compile(r"(?:^|[_\s.-])([xyz])$|([xyzXYZ])$")


def reaction_candidates(fld: ContactField, normal: np.ndarray) -> dict[str, float]:
    """The solver reactions of ``fld`` that act along the patch normal (N).

    The sidecar's ``reaction_z``, and the file's reaction/force globals whose
    name ends in the global axis the normal is closest to (``bot_react_y``) or
    names no axis at all; none when the normal is oblique to every axis.
    """
    out: dict[str, float] = {}
    if fld.reaction_z is not None:
        out["reaction_z (sidecar)"] = float(fld.reaction_z)
    k = int(np.argmax(np.abs(normal)))
    if abs(normal[k]) < 0.9:
        return out
    axis = "xyz"[k]
    for name, value in fld.reactions.items():
        m = _AXIS.search(name)
        named = (m.group(1) or m.group(2)).lower() if m else None
        if named is None or named == axis:
            out[name] = float(value)
    return out


def _check_reaction(fld: ContactField, patch: Patch) -> None:
    cands = reaction_candidates(fld, patch.frame.axes[2])
    if not cands:
        return
    errs = {n: abs(patch.N_fe) / abs(v) - 1.0 if v else np.inf for n, v in cands.items()}
    best = min(errs, key=lambda n: abs(errs[n]))
    if abs(errs[best]) <= REACTION_TOL:
        return
    listing = ", ".join(f"{n} = {v:.6g} N" for n, v in cands.items())
    ratio = abs(patch.N_fe / cands[best]) if cands[best] else np.inf
    hint = ""
    for f in (1e-3, 1e3, 1e-6, 1e6, 1e-9, 1e9):
        if np.isfinite(ratio) and abs(ratio / f - 1) < 0.05:
            hint = f" (a factor {f:g}: wrong --units?)"
    warnings.warn(
        f"{fld.source}: N_fe = {patch.N_fe:.6g} N differs from the solver's reaction by "
        f"{errs[best]:+.1%} ({listing}){hint}",
        ScaleWarning,
        stacklevel=3,
    )


def check_load_pair(static: Patch, rolling: Patch, *, allow: bool = False) -> float:
    """The ratio N_fe(rolling) / N_fe(static); refuse a pair further apart than `LOAD_TOL`.

    Raises
    ------
    ArgumentError
        The loads differ by more than `LOAD_TOL` and ``allow`` is false
        (one line naming both maps and both loads).
    """
    ratio = rolling.N_fe / static.N_fe
    if abs(ratio - 1.0) > LOAD_TOL and not allow:
        raise ArgumentError(
            f"{rolling.source}: the rolling map's load N_fe = {rolling.N_fe:.6g} N differs from the "
            f"static map's ({static.source}) N_fe = {static.N_fe:.6g} N by {ratio - 1.0:+.1%}, more "
            f"than the {LOAD_TOL:.0%} tolerance: k_x needs both maps at one load (pair maps of the "
            "same load, or allow the mismatch: --allow-load-mismatch)"
        )
    return ratio


def _check_resampling(patch: Patch, mom: Moments) -> None:
    err = mom.N / patch.N_fe - 1.0
    if abs(err) > RESAMPLE_TOL:
        warnings.warn(
            f"{patch.source}: the polar grid carries {err:+.1%} of the FE load (N = {mom.N:.6g} N, "
            f"N_fe = {patch.N_fe:.6g} N); refine it (--nr/--nphi) or check the mesh for holes",
            PatchWarning,
            stacklevel=3,
        )


def _default_grid(options: AnalysisOptions) -> bool:
    """Whether the analysis runs on the library's default polar grid, which `fepost.refine`
    refines where a map's pressure is when it misses the map's load or polar moment (a grid
    the caller chose is kept, with the warning of `_check_resampling`)."""
    return (options.nr, options.nphi, options.rule) == (DEFAULT_NR, DEFAULT_NPHI, "gauss")


def _warm_up() -> None:
    """Import, while the files are read, what the results need later: the generalised model
    (`Analysis.model_summary`, in `Analysis.to_dict` by default) with its error maps
    (`fepost.friction.sphere`), and what numpy imports on first use there: ``numpy.ma``
    (``np.unique``, in the model's exact integrals) and ``numpy.fft`` (the turned sums,
    `fepost.friction.turns`): 40-60 ms that would otherwise come after the read; and the
    BLAS controller the pipeline's `one_blas_thread` needs (5-10 ms)."""
    import numpy.fft
    import numpy.ma  # noqa: F401

    from . import _blas
    from .friction import sphere, summary  # noqa: F401

    _blas.warm()  # the BLAS controller of `one_blas_thread`, made once per process


def _start(src, options: AnalysisOptions) -> isolate.Pending:
    """The reading of ``src`` under way (a `ContactField` or a started read is taken as it is)."""
    if isinstance(src, isolate.Pending):
        return src
    if isinstance(src, ContactField):
        return isolate.Pending(str(src.source), value=src)
    return start_reading(Path(src), **options.reading())


def friction_coefficient(friction) -> float:
    """f from a number or a `fepost.friction.law.FrictionLaw` (its ``f``), checked by
    `fepost.options.check_friction`."""
    return check_friction(getattr(friction, "f", friction))


def analyse(
    static,
    rolling=None,
    *,
    friction=DEFAULT_FRICTION,
    options: AnalysisOptions | None = None,
    **changes,
) -> Analysis:
    """Run the pipeline on a static map (path or `ContactField`) and an optional rolling map.

    The rolling map is placed in the static patch's frame; its polar grid is
    centred on the static centre of pressure with a radius large enough to
    hold its own loaded region. N_fe is checked against the solver's reaction
    where the export carries one (warning above `REACTION_TOL`). A rolling map
    whose load differs from the static map's by more than `LOAD_TOL` is refused
    (`ArgumentError`) unless ``allow_load_mismatch``, which the result records.

    Parameters
    ----------
    static, rolling : path, ContactField or a started read
        The maps. A map may be a read already under way (`fepost.reader.start_reading`,
        with its own reading options): a caller can start it before importing this module.
    friction : float or FrictionLaw
        The friction coefficient f (default `fepost.options.DEFAULT_FRICTION`), or a
        friction law whose ``f`` is taken.
    options : AnalysisOptions, optional
        How to read, resample and pair the maps (default: the defaults).
    **changes
        Single options changed on ``options`` by name (``field=``, ``step=``, ``grid=``,
        ``threshold=``, ``units=``, ... as in `AnalysisOptions.make`), for short calls.

    Returns
    -------
    Analysis
        The patches, polar maps, moments and coefficients.

    Examples
    --------
    >>> import fepost
    >>> res = fepost.analyse("meshes/static.vtu")   # the CalculiX sample of the repository
    >>> c = res.coefficients
    >>> round(c.N), round(c.R, 4)                    # normal load (N), R = r_max (m)
    (12900, 0.1202)
    >>> round(c.N / res.static_field.reaction_z, 3)  # against the solver's own reaction
    1.0
    >>> round(float(c.F0 / c.N), 6)                  # F0 = f N, default f = 0.3
    0.3
    >>> bool(res.static_patch.circular), round(res.static_patch.aspect, 2)
    (False, 1.16)
    """
    opts = AnalysisOptions.make(options, **changes)
    f = friction_coefficient(friction)
    # both files are read at once in their own children; the patch step's imports run meanwhile
    pending = [_start(static, opts)]
    try:
        if rolling is not None:
            pending.append(_start(rolling, opts))
        if any(p.running for p in pending):
            _warm_up()
        # one BLAS thread: the patch step's products are thin (n × 3, chunk-long dots), where
        # BLAS threads only spin, and on a busy machine they stall it (2-5x slower)
        with one_blas_thread(), float_range(pending[0].what):
            return _pipeline(pending, with_rolling=rolling is not None, friction=f, options=opts)
    finally:
        for p in pending:
            p.cancel()


def _pipeline(pending, *, with_rolling: bool, friction: float, options: AnalysisOptions) -> Analysis:
    grid = options.grid
    sf = pending[0].result()
    sp = build_patch(sf, threshold=options.threshold, rolling_axis=options.rolling_axis)
    _check_reaction(sf, sp)
    sm = resample(sp, grid, radius=sp.r_max)
    smo = moments(sm)
    refine = _default_grid(options)  # a map the default grid misses: refined where its pressure is
    if refine:
        sm, smo = refined_map(sp, sm, smo)
    _check_resampling(sp, smo)
    rf = rp = rm = rmo = None
    if with_rolling:
        rf = pending[1].result()
        rp = build_patch(rf, threshold=options.threshold, frame=sp.frame)
        check_load_pair(sp, rp, allow=options.allow_load_mismatch)
        r_roll = float(np.max(np.hypot(rp.xy[:, 0], rp.xy[:, 1])))
        rm = resample(rp, grid, radius=max(sp.r_max, r_roll))
        rmo = moments(rm)
        if refine:
            rm, rmo = refined_map(rp, rm, rmo)
        _check_resampling(rp, rmo)
    coef = coefficients_from_moments(smo, rmo, friction=friction)
    return Analysis(sf, sp, sm, smo, coef, rf, rp, rm, rmo, options=options)
