"""The main pipeline: FE export(s) → patch → polar map → moments → coefficients.

:func:`analyse` is the documented entry point of the Python API::

    from fepost import analyse
    result = analyse("meshes/static.vtu", "meshes/rolling.vtu", friction=0.3)
    result.coefficients.M0, result.static_patch.circular, result.to_dict()
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from .coefficients import Coefficients, coefficients_from_moments
from .errors import PatchWarning
from .field import ContactField
from .moments import Moments, moments
from .patch import DEFAULT_THRESHOLD, Patch, build_patch
from .polar import PolarGrid, PolarMap
from .reader import read_contact
from .resample import resample


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

    @property
    def grid(self) -> PolarGrid:
        return self.static_map.grid

    @cached_property
    def model_summary(self):
        """The generalised friction model of these maps (:mod:`fepost.friction.summary`)."""
        from .friction.summary import summarise

        return summarise(self)

    def to_dict(self) -> dict:
        """The coefficients JSON of INTERFACE.md (SI units), with provenance."""
        d = self.coefficients.to_dict()
        d["N_fe"] = self.static_patch.N_fe
        d["patch"] = self.static_patch.to_dict()
        d["R_definition"] = (
            "r_max: smallest circle about the static centre of pressure holding every loaded point"
        )
        d["reaction_z"] = self.static_field.reaction_z
        d["grid"] = {"rule": self.grid.rule, "nr": self.grid.shape[0], "nphi": self.grid.shape[1]}
        d["static"] = {
            "source": self.static_field.source,
            "field": self.static_field.field,
            "step": self.static_field.step,
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
            }
        d["model"] = self.model_summary.to_dict()  # generalised model (fepost.friction.summary)
        return d


#: Largest accepted |N/N_fe − 1| before a warning: the polar grid must carry the FE load.
RESAMPLE_TOL = 0.01


def _check_resampling(patch: Patch, mom: Moments) -> None:
    err = mom.N / patch.N_fe - 1.0
    if abs(err) > RESAMPLE_TOL:
        warnings.warn(
            f"{patch.source}: the polar grid carries {err:+.1%} of the FE load (N = {mom.N:.6g} N, "
            f"N_fe = {patch.N_fe:.6g} N); refine it (--nr/--nphi) or check the mesh for holes",
            PatchWarning,
            stacklevel=3,
        )


def _as_field(src, field, step, displacement) -> ContactField:
    if isinstance(src, ContactField):
        return src
    return read_contact(Path(src), field=field, step=step, displacement=displacement)


def analyse(
    static,
    rolling=None,
    *,
    friction: float = 0.3,
    field: str | None = None,
    step: int | None = None,
    displacement: str | None = "auto",
    grid: PolarGrid | None = None,
    threshold: float = DEFAULT_THRESHOLD,
    rolling_axis=None,
) -> Analysis:
    """Run the pipeline on a static map (path or :class:`ContactField`) and an optional rolling map.

    The rolling map is placed in the static patch's frame; its polar grid is
    centred on the static centre of pressure with a radius large enough to
    hold its own loaded region.
    """
    grid = grid or PolarGrid.make()
    sf = _as_field(static, field, step, displacement)
    sp = build_patch(sf, threshold=threshold, rolling_axis=rolling_axis)
    sm = resample(sp, grid, radius=sp.r_max)
    smo = moments(sm)
    _check_resampling(sp, smo)
    rf = rp = rm = rmo = None
    if rolling is not None:
        rf = _as_field(rolling, field, step, displacement)
        rp = build_patch(rf, threshold=threshold, frame=sp.frame)
        r_roll = float(np.max(np.hypot(rp.xy[:, 0], rp.xy[:, 1])))
        rm = resample(rp, grid, radius=max(sp.r_max, r_roll))
        rmo = moments(rm)
        _check_resampling(rp, rmo)
    coef = coefficients_from_moments(smo, rmo, friction=friction)
    return Analysis(sf, sp, sm, smo, coef, rf, rp, rm, rmo)
