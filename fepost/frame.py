"""The patch frame: the least-squares plane of the loaded nodes, and its axes.

The plane's normal is the road normal z, oriented along the global axis it is
closest to (z-up and y-up models both come out with z up); x is the rolling
axis projected on the plane (default global x; when global x is normal to the
patch, the global axis closest to the plane, with a warning); y = z × x.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ._arrays import frozen
from ._chunks import map_chunks, slices
from .errors import ArgumentError, PatchWarning

#: Nodes per chunk of the plane fit's sums (their (chunk, 3) temporaries stay in the cache;
#: two threads share the chunks, `fepost._chunks`).
NODE_CHUNK = 1 << 15


@dataclass(frozen=True)
class Frame:
    """Patch frame: ``origin`` (3,) in global coordinates (m); ``axes`` rows are x, y, z."""

    origin: np.ndarray
    axes: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "origin", frozen(self.origin))
        object.__setattr__(self, "axes", frozen(self.axes))

    def to_local(self, points) -> np.ndarray:
        """Global (n, 3) points → patch coordinates (n, 3), m."""
        return (np.asarray(points, float) - self.origin) @ self.axes.T

    def to_global(self, local) -> np.ndarray:
        """Patch coordinates (n, 2 or 3) → global (n, 3), m."""
        local = np.asarray(local, float)
        if local.shape[-1] == 2:
            local = np.concatenate([local, np.zeros(local.shape[:-1] + (1,))], axis=-1)
        return local @ self.axes + self.origin


def _fmt(v) -> str:
    """A vector as plain numbers: (1, 0, 0)."""
    a = np.asarray(v, float).ravel()
    a = np.where(np.abs(a) < 1e-9 * max(1.0, float(np.abs(a).max(initial=0.0))), 0.0, a) + 0.0
    return "(" + ", ".join(f"{float(x):.3g}" for x in a) + ")"


def fit_plane(points: np.ndarray, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Weighted least-squares plane through ``points``.

    The first and second moments are accumulated about a node of the patch, so large
    global offsets cost no precision, in chunks of `NODE_CHUNK` nodes shared by two
    threads (a million-node patch: 4 ms instead of 16 ms column by column).

    Parameters
    ----------
    points : ndarray, shape (n, 3)
        The points (global coordinates).
    weights : ndarray, shape (n,)
        Non-negative weights (the patch uses the nodal loads); their sum must be positive.

    Returns
    -------
    centroid : ndarray, shape (3,)
        The weighted centroid.
    normal : ndarray, shape (3,)
        Unit normal of the plane, its largest component positive.
    variances : ndarray, shape (3,)
        Weighted variances, ascending: along the normal, then the two in-plane axes.
    """
    w = weights / weights.sum()
    ref = points[int(np.argmax(weights))]

    def chunk(sl: slice) -> tuple[np.ndarray, np.ndarray]:
        d = _rows_about(points, sl, ref)  # about a node of the patch: no precision lost to offsets
        wd = d * w[sl]
        return wd.sum(axis=1), wd @ d.T

    # the chunks' sums in their order: the same numbers on one thread or two
    c, m = np.zeros(3), np.zeros((3, 3))
    for first, second in map_chunks(chunk, slices(len(points), NODE_CHUNK)):
        c += first
        m += second
    cov = m - np.outer(c, c)
    evals, vecs = np.linalg.eigh(cov)
    n = vecs[:, 0]
    k = int(np.argmax(np.abs(n)))
    if n[k] < 0:
        n = -n
    return c + ref, n, evals


def frame_rows(points: np.ndarray, frame: Frame) -> np.ndarray:
    """The (n, 3) global ``points`` in ``frame``'s coordinates, as three rows x, y, z (m).

    ``rows[:2].T`` is an (n, 2) array whose columns are contiguous: the passes that gather x
    and y (`fepost.facesums`, `fepost.locate`) take them without a copy. Computed as
    (p − o)·e_k in chunks of `NODE_CHUNK` nodes shared by two threads.
    """
    rows = np.empty((3, len(points)))

    def chunk(sl: slice) -> None:
        rows[:, sl] = frame.axes @ _rows_about(points, sl, frame.origin)

    map_chunks(chunk, slices(len(points), NODE_CHUNK))
    return rows


def farthest_from_plane(points: np.ndarray, weights: np.ndarray, c: np.ndarray, normal: np.ndarray) -> float:
    """The largest distance from the plane through ``c`` of unit ``normal`` of the ``points`` of
    positive weight (0 without any), in chunks of `NODE_CHUNK` nodes shared by two threads."""

    def chunk(sl: slice) -> float:
        h = normal @ _rows_about(points, sl, c)
        np.abs(h, out=h)
        return float(h.max(where=weights[sl] > 0, initial=0.0))

    return max(map_chunks(chunk, slices(len(points), NODE_CHUNK)), default=0.0)


def _rows_about(points: np.ndarray, sl: slice, ref: np.ndarray) -> np.ndarray:
    """``points[sl] - ref`` as three rows (3, chunk): numpy's loops then run along the chunk,
    not along each node's three values."""
    d = np.empty((3, sl.stop - sl.start))
    np.subtract(points[sl].T, ref[:, None], out=d)
    return d


_AXIS_NAMES = ("x", "y", "z")


def patch_axes(normal: np.ndarray, rolling_axis, source: str = "") -> tuple[np.ndarray, str]:
    """The patch frame's axes for a plane of unit ``normal``.

    Parameters
    ----------
    normal : ndarray, shape (3,)
        Unit normal of the patch plane (the frame's z).
    rolling_axis : array_like of 3 floats or None
        The rolling direction (projected into the plane); None: global x, or
        the global axis closest to the plane when x is normal to it (then a
        `PatchWarning` is issued and returned as the note).
    source : str
        Names the map in the warning.

    Returns
    -------
    axes : ndarray, shape (3, 3)
        Rows x, y, z of the patch frame (right-handed, orthonormal).
    note : str
        Why the default axis was replaced ("" when it was not).

    Raises
    ------
    ArgumentError
        ``rolling_axis`` is not a non-zero finite 3-vector, or is (nearly) normal to the plane.
    """
    note = ""
    if rolling_axis is None:
        ax = np.array([1.0, 0.0, 0.0])
        if np.linalg.norm(ax - (ax @ normal) * normal) < 0.1:
            k = int(np.argmin(np.abs(normal[1:]))) + 1  # the global axis closest to the plane (y or z)
            ax = np.eye(3)[k]
            note = (
                f"rolling axis: global x is normal to the patch (normal {_fmt(normal)}); "
                f"global {_AXIS_NAMES[k]} is used as the rolling direction x (give --rolling-axis to choose)"
            )
            warnings.warn(f"{source}: {note}", PatchWarning, stacklevel=4)
    else:
        ax = np.asarray(rolling_axis, float)
        if ax.shape != (3,) or not np.all(np.isfinite(ax)) or np.linalg.norm(ax) == 0:
            raise ArgumentError(f"rolling_axis must be a non-zero 3-vector, got {rolling_axis!r}")
    ax = ax / np.linalg.norm(ax)
    x = ax - (ax @ normal) * normal
    if np.linalg.norm(x) < 0.1:
        raise ArgumentError(
            f"rolling axis {_fmt(ax)} is (nearly) normal to the patch plane "
            f"(normal {_fmt(normal)}); give an in-plane rolling axis"
        )
    x /= np.linalg.norm(x)
    y = np.cross(normal, x)
    return np.vstack([x, y, normal]), note
