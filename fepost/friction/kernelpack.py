"""The generalised model's numbers packed for the compiled kernel (`fepost.friction.kernel`).

Kept apart from the kernel's compiled functions so that the kernel module holds
only what numba compiles into one cached whole (numba checks a cached kernel
against the time stamp of the file that defines it, not of the files it calls).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.polynomial import chebyshev

from .._arrays import frozen
from ..errors import ArgumentError

#: Correction blocks of up to this many numbers (the default 72) are summed by code
#: unrolled for their shape: their rows' partial sums stay in registers, 1.4 × the
#: speed of the general loops. numba compiles that once per shape, and the compile
#: time grows with the numbers (4 s for 72, 17 s for 204, then from its disk cache),
#: so larger blocks (the long patches' 156 and 204, 1.2 × faster unrolled) take the
#: general loops, compiled once for every shape.
UNROLL_MAX = 128

#: Order of the scalars in `KernelCoefficients.scalars`.
SCALARS = tuple(
    [
        "R",
        "F0",
        "U0",
        "U0^5",
        "U0^6",
        "Q00",
        "Q01",
        "Q11",
        "S00",
        "S01",
        "S11",
        "gx",
        "gy",
        "xcx",
        "xcy",
        "alpha",
        "g0",
        "g1x",
        "g1y",
    ]
)


@dataclass(frozen=True)
class KernelCoefficients:
    """The model's numbers as the kernel takes them: ``scalars`` (in the order of
    `SCALARS`), the potential correction ``C`` (2K + 1, L), the coefficients ``Cd`` of
    its derivative in t in the same basis, and the anisotropic-torque correction
    ``Cg`` (zeros when the model has none); columns zero-padded to a multiple of four."""

    scalars: np.ndarray
    C: np.ndarray
    Cd: np.ndarray
    Cg: np.ndarray

    @property
    def shape(self) -> tuple[tuple[int, ...], tuple[int, ...]]:
        """The shape of ``C`` as the compiled kernel's type sees it: tuples of
        ``rows`` and ``columns`` zeros (numba types a tuple with its length, so the kernel
        is compiled, and cached, once per shape with its sums unrolled for it), or two
        empty tuples beyond `UNROLL_MAX` numbers (general loops, one compilation)."""
        rows, cols = self.C.shape
        if rows * cols > UNROLL_MAX:
            return (), ()
        return (0,) * rows, (0,) * cols

    def __post_init__(self) -> None:
        for name in ("scalars", "C", "Cd", "Cg"):
            object.__setattr__(self, name, frozen(np.ascontiguousarray(getattr(self, name), float)))
        if self.C.shape != self.Cd.shape or self.C.shape[1] % 4 or self.Cg.shape[1] % 4:
            raise ArgumentError(
                f"C and Cd must have one shape with a multiple of 4 columns, got {self.C.shape}, "
                f"{self.Cd.shape} and Cg {self.Cg.shape}"
            )


def coefficients(model) -> KernelCoefficients:
    """Pack a `GeneralisedModel` for `fepost.friction.kernel.evaluate` (off-diagonals from the upper triangle,
    as the numpy path reads them)."""
    U0 = model.U0
    Q, S, g, xc, g1 = model.Q, model.S, model.g, model.xc, model.g1
    scalars = [model.R, model.F0, U0, U0**5, U0**6, Q[0, 0], Q[0, 1], Q[1, 1], S[0, 0], S[0, 1]]
    scalars += [S[1, 1], g[0], g[1], xc[0], xc[1], model.anisotropy, model.g0, g1[0], g1[1]]
    cg = np.zeros((1, 1)) if model.correction_g is None else model.correction_g
    C = model.correction
    # d/dt T_l(2t − 1) = 2 T_l'(x): chebder's scale 2
    Cd = chebyshev.chebder(C, scl=2.0, axis=1) if C.shape[1] > 1 else np.zeros_like(C)
    width = max(4, -(-C.shape[1] // 4) * 4)  # a multiple of four, ≥ 4
    gwidth = max(4, -(-cg.shape[1] // 4) * 4)
    return KernelCoefficients(
        np.array(scalars, float), _padded(C, width), _padded(Cd, width), _padded(cg, gwidth)
    )


def _padded(C: np.ndarray, width: int) -> np.ndarray:
    """C with zero columns up to ``width``."""
    out = np.zeros((C.shape[0], width))
    out[:, : C.shape[1]] = C
    return out
