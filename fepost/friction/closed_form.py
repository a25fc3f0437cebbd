"""The paper's closed-form friction approximations (THEORY.md §4, paper 1.3, 1.7, 1.8).

With u = ω_z R (m/s) and v = |v| (m/s):

    F∥ = F0 v / √(v² + a u²)                   (N, along −v on the tire)
    M_C = M0 u / √(u² + m v²)                  (N·m, opposing ω_z)
    F⊥ = k_x (M0 / 2R) u / √(u² + (m/4) v²)    (N, lateral)

Magnitudes are returned; the signs of the components on the tire follow from
THEORY.md §3 and are applied by :func:`components`.
"""

from __future__ import annotations

import numpy as np


def f_parallel(v, u, F0: float, a: float) -> np.ndarray:
    """|F∥| in N for sliding speed ``v`` and spin speed ``u = ω_z R`` (both m/s)."""
    v = np.abs(np.asarray(v, float))
    u = np.asarray(u, float)
    den = np.sqrt(v**2 + a * u**2)
    return np.where(den > 0, F0 * v / np.where(den > 0, den, 1.0), 0.0)


def torque(v, u, M0: float, m: float) -> np.ndarray:
    """|M_C| in N·m."""
    v = np.asarray(v, float)
    u = np.abs(np.asarray(u, float))
    den = np.sqrt(u**2 + m * v**2)
    return np.where(den > 0, M0 * u / np.where(den > 0, den, 1.0), 0.0)


def f_perpendicular(v, u, M0: float, m: float, k_x: float, radius: float) -> np.ndarray:
    """|F⊥| in N (THEORY.md §4, with the 1/R the paper omits)."""
    v = np.asarray(v, float)
    u = np.abs(np.asarray(u, float))
    den = np.sqrt(u**2 + 0.25 * m * v**2)
    return np.where(den > 0, abs(k_x) * M0 / (2.0 * radius) * u / np.where(den > 0, den, 1.0), 0.0)


def f_parallel_ratio(psi, a: float) -> np.ndarray:
    """F∥/F0 = 1/√(1 + aψ²), ψ = u/v."""
    return 1.0 / np.sqrt(1.0 + a * np.asarray(psi, float) ** 2)


def torque_ratio(upsilon, m: float) -> np.ndarray:
    """M_C/M0 = 1/√(1 + mυ²), υ = v/u."""
    return 1.0 / np.sqrt(1.0 + m * np.asarray(upsilon, float) ** 2)


def f_perpendicular_ratio(upsilon, m: float) -> np.ndarray:
    """F⊥/(k_x M0/2R) = 1/√(1 + mυ²/4), υ = v/u."""
    return 1.0 / np.sqrt(1.0 + 0.25 * m * np.asarray(upsilon, float) ** 2)
