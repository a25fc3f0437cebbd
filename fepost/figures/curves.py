"""Figures 4–6: friction force and torque against the speed ratio.

Each figure shows one quantity (F∥ against ψ = u/v, M_C and F⊥ against
υ = v/u, with u = ω_z R) as plain arrays held in a `CurveData`:

* ``exact`` — the exact Coulomb integrals of the FE map,
* ``closed_form`` — the paper's square-root approximation with the map's
  coefficients,
* ``test_x``, ``test_y`` — the noisy "test" points of the identification
  experiment,
* ``fit`` with ``band_lo`` … ``band_hi`` — the curve fitted to those points and
  its 95 % prediction band;
* ``model`` — the generalised friction model built from the FE map
  (`fepost.identify.GeneralisedCurves.curves`).

Any of them but ``x`` and ``closed_form`` may be ``None``. The module computes
nothing physical: the report assembles the arrays.

Labels are plain text with subscripts written as ``M_C``, ``F_y``, ``ω_z``
(and ``F_{xy}`` for longer ones); `mathtext` turns them into matplotlib
mathtext, so they render as subscripts, not as literal underscores.

The figure states what its reader needs without the caption: under the ψ or υ
axis, u and v (`SPEED_DEFINITIONS`, as docs/theory.md defines them); in the
legend, that the test points are synthetic; and, where test points or the
prediction band of a non-negative curve fall below zero, that the paper's
additive noise takes them there (`BELOW_ZERO`): the band is drawn as computed,
never clipped.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np

from .._arrays import frozen
from ..errors import ArgumentError
from . import theme

_ARRAYS = ("x", "closed_form", "exact", "fit", "band_lo", "band_hi", "test_x", "test_y", "model")

#: Line colour of the generalised model (purple: apart from the theme's exact/closed/fit colours).
MODEL_COLOUR = "#7d3c98"
#: About this many open markers along the generalised model's line (it lies on the exact curve).
MODEL_MARKERS = 16
#: Unicode letters mathtext spells by name.
_TEX = {
    "α": r"\alpha", "β": r"\beta", "ε": r"\varepsilon", "θ": r"\theta", "μ": r"\mu",
    "ρ": r"\rho", "σ": r"\sigma", "τ": r"\tau", "υ": r"\upsilon", "φ": r"\varphi",
    "ψ": r"\psi", "ω": r"\omega", "∥": r"\parallel", "⊥": r"\perp",
}  # fmt: skip
#: The speeds of the ratios ψ = u/v and υ = v/u, written under their axis (docs/theory.md).
SPEED_DEFINITIONS = r"$u = \omega_z R$ (spin speed at radius R), $v = |\mathbf{v}|$ (sliding speed)"
#: Added to the legend entries of test points and band when they reach below a curve that is not.
BELOW_ZERO = "below 0 by the additive noise"
_SUBSCRIPT = re.compile(r"([A-Za-zα-ωΑ-Ω∥⊥]+)_(\{[^{}$]*\}|[A-Za-z0-9∥⊥]+)")


def mathtext(label: str) -> str:
    """``label`` with each ``base_sub`` turned into ``$base_{sub}$`` (mathtext).

    Greek letters and ∥, ⊥ inside the math are spelled as TeX commands; text
    already inside ``$…$`` is left alone. ``"M_C (N·m)"`` → ``"$M_{C}$ (N·m)"``.
    """

    def tex(text: str) -> str:
        return "".join(_TEX.get(ch, ch) + (" " if ch in _TEX else "") for ch in text).strip()

    def sub(m: re.Match) -> str:
        inner = m.group(2)[1:-1] if m.group(2).startswith("{") else m.group(2)
        return f"${tex(m.group(1))}_{{{tex(inner)}}}$"

    parts = label.split("$")
    # even parts are outside math
    return "$".join(_SUBSCRIPT.sub(sub, p) if i % 2 == 0 else p for i, p in enumerate(parts))


@dataclass(frozen=True)
class CurveData:
    """One of Figures 4–6 as arrays (see the module docstring).

    ``name`` is a short key (``F_parallel``, ``M_C``, ``F_perp``); ``x_name``
    the abscissa (``psi`` or ``upsilon``, dimensionless); ``unit`` the unit of the
    ordinates (``N`` or ``N m``). ``x``, ``closed_form``, ``exact``, ``fit``,
    ``band_lo``, ``band_hi`` share one length; ``test_x``, ``test_y`` another.
    """

    name: str
    title: str
    x_name: str
    x_label: str
    y_label: str
    unit: str
    x: np.ndarray
    closed_form: np.ndarray
    exact: np.ndarray | None = None
    fit: np.ndarray | None = None
    band_lo: np.ndarray | None = None
    band_hi: np.ndarray | None = None
    test_x: np.ndarray | None = None
    test_y: np.ndarray | None = None
    labels: dict = field(default_factory=dict)
    model: np.ndarray | None = None

    def __post_init__(self) -> None:
        for name in _ARRAYS:
            v = getattr(self, name)
            if v is not None:
                object.__setattr__(self, name, frozen(np.ravel(v)))
        n = self.x.size
        for name in ("closed_form", "exact", "fit", "band_lo", "band_hi", "model"):
            v = getattr(self, name)
            if v is not None and v.size != n:
                raise ArgumentError(f"{self.name}: {name} has {v.size} values, x has {n}")
        if (self.test_x is None) != (self.test_y is None):
            raise ArgumentError(f"{self.name}: give both test_x and test_y or neither")
        if self.test_x is not None and self.test_y is not None and self.test_x.size != self.test_y.size:
            raise ArgumentError(
                f"{self.name}: test_x has {self.test_x.size} values, test_y {self.test_y.size}"
            )
        if (self.band_lo is None) != (self.band_hi is None):
            raise ArgumentError(f"{self.name}: give both band_lo and band_hi or neither")

    def to_dict(self) -> dict:
        d = {k: getattr(self, k) for k in ("name", "title", "x_name", "unit")}
        for k in _ARRAYS:
            v = getattr(self, k)
            d[k] = None if v is None else v.tolist()
        return d


def plot_curve(data: CurveData, ax=None):
    """Plot one of Figures 4–6; return the figure. Series carry ``gid`` =
    their field name so tests can find them. Title, axis labels and legend
    entries go through `mathtext`."""
    import matplotlib.pyplot as plt

    lab = {
        "exact": "exact integral (FE map)",
        "closed_form": "closed form (1.8)",
        "model": "generalised model (FE map)",
        "test": "synthetic test points (the paper's 20 % noise)",
        "fit": "fitted (1.8)",
        "band": "95 % prediction band",
        **data.labels,
    }
    if _noise_below_zero(data):
        for key in ("test", "band"):
            lab[key] += f"; {BELOW_ZERO}"
    lab = {k: mathtext(v) for k, v in lab.items()}
    with theme.mpl_style():
        if ax is None:
            fig, ax = plt.subplots(figsize=(6.4, 6.2), layout="constrained")
        else:
            fig = ax.figure
        if data.band_lo is not None:
            ax.fill_between(
                data.x,
                data.band_lo,
                data.band_hi,
                color=theme.FIT_COLOUR,
                alpha=0.15,
                lw=0,
                label=lab["band"],
                gid="band",
            )
        if data.test_x is not None:
            ax.plot(
                data.test_x,
                data.test_y,
                "o",
                ms=3.0,
                color=theme.TEST_COLOUR,
                alpha=0.7,
                label=lab["test"],
                gid="test",
            )
        if data.exact is not None:
            ax.plot(
                data.x,
                data.exact,
                color=theme.EXACT_COLOUR,
                lw=2.0,
                label=lab["exact"],
                gid="exact",
            )
        ax.plot(
            data.x,
            data.closed_form,
            color=theme.CLOSED_COLOUR,
            lw=1.6,
            ls="--",
            label=lab["closed_form"],
            gid="closed_form",
        )
        if data.model is not None:
            # On top of the exact curve, which it follows closely: dotted with open markers.
            ax.plot(
                data.x,
                data.model,
                color=MODEL_COLOUR,
                lw=1.8,
                ls=":",
                marker="o",
                ms=4.5,
                mfc="none",
                markevery=max(1, data.x.size // MODEL_MARKERS),
                zorder=3,
                label=lab["model"],
                gid="model",
            )
        if data.fit is not None:
            ax.plot(
                data.x,
                data.fit,
                color=theme.FIT_COLOUR,
                lw=1.4,
                ls="-.",
                label=lab["fit"],
                gid="fit",
            )
        speeds = f"\n{SPEED_DEFINITIONS}" if data.x_name in ("psi", "upsilon") else ""
        ax.set_xlabel(mathtext(data.x_label) + speeds)
        ax.set_ylabel(mathtext(data.y_label))
        ax.set_title(mathtext(data.title), fontsize=10)
        ax.set_xlim(float(data.x[0]), float(data.x[-1]))
        ax.axhline(0.0, color="black", lw=0.6)
        # below the axes, outside them: a legend inside would cover test points or the band
        handles, labels = ax.get_legend_handles_labels()
        fig.legend(handles, labels, loc="outside lower center", ncol=1, fontsize=8.5)
    return fig


def _noise_below_zero(data: CurveData) -> bool:
    """Whether test points or the band reach below zero where the noise-free curves (exact,
    closed form) do not: only the additive noise of the synthetic points takes them there."""
    noisy = [v for v in (data.test_y, data.band_lo) if v is not None and v.size]
    clean = [v for v in (data.exact, data.closed_form) if v is not None and v.size]
    return bool(noisy and clean) and min(float(v.min()) for v in noisy) < 0.0 <= min(
        float(v.min()) for v in clean
    )


def curve_table(curves: Iterable[CurveData]) -> tuple[list[str], list[list]]:
    """The curves in long form for ``curves.csv``: header and rows
    (figure, x_name, series, x, value, unit)."""
    header = ["figure", "x_name", "series", "x", "value", "unit"]
    rows: list[list] = []
    for c in curves:
        for series in ("exact", "closed_form", "model", "fit", "band_lo", "band_hi"):
            y = getattr(c, series)
            if y is not None:
                rows += [
                    [c.name, c.x_name, series, float(x), float(v), c.unit]
                    for x, v in zip(c.x, y, strict=True)
                ]
        if c.test_x is not None and c.test_y is not None:
            rows += [
                [c.name, c.x_name, "test", float(x), float(v), c.unit]
                for x, v in zip(c.test_x, c.test_y, strict=True)
            ]
    return header, rows
