"""Example measured data: a rig programme over a simulation with one documented cause hidden in it.

`make_example` runs the generator of `synthetic` on
an FE export and writes the measured-data CSV, with a header of ``#`` comment
lines that say what is hidden in it (cause, parameters, noise, outlier rows,
seed) and the command that made it. ``fepost diagnose --make-example CSV
--simulation SIM [--cause NAME] [--seed S]`` is its command line.

Effect sizes (`example_parameters`) are set relative to the simulation, so
that every cause is plain on any map: a 15 % lower friction level; c_p = 0.25;
c_v = −0.1 s/m; a patch stretched by 12 %; f_y/f_x = 1.15; the centre of
pressure moved by (4 %, −3 %) of R; offsets of (8 %, −6 %) of f·N and 5 % of
f·N·R; c_rim = 0.4 (more of the load towards the rim). The programme has
loads 0.8, 1.0 and 1.2 × N (pressure dependence then shows through the
load), 300 points, noise 1.5 % of each channel's range and
`EXAMPLE_OUTLIERS` gross errors (a sign flip, a 2.5× spike).

The example shipped as ``examples/measured_example.csv`` was made from
``meshes/static.vtu`` with the defaults: ``pressure_dependent_friction``,
c_p = 0.25, seed `EXAMPLE_SEED`.
"""

from __future__ import annotations

from pathlib import Path

from ..analysis import analyse
from ..errors import ArgumentError
from ..friction_coefficient import DEFAULT_FRICTION
from ..polar import PolarMap
from .causes import CAUSES
from .measured import write_csv
from .simulation import load_simulation
from .synthetic import SyntheticData, synthesize

#: The cause hidden in the example by default.
EXAMPLE_CAUSE = "pressure_dependent_friction"
#: Seed of the shipped example.
EXAMPLE_SEED = 1
#: Test points, load factors, noise (fraction of range) and gross errors of the example.
EXAMPLE_POINTS = 300
EXAMPLE_LOADS = (0.8, 1.0, 1.2)
EXAMPLE_NOISE = 0.015
EXAMPLE_OUTLIERS = 3


def example_parameters(cause: str, friction: float, load: float, radius: float) -> dict:
    """The hidden parameters of ``cause`` for a simulation with nominal f, load N (N) and R (m)."""
    fn = friction * load
    table = {
        "none": {},
        "friction_level": {"f": 0.85 * friction},
        "pressure_dependent_friction": {"c_p": 0.25},
        "speed_dependent_friction": {"c_v": -0.1},
        "elliptic_patch": {"s": 1.12},
        "anisotropic_friction": {"alpha": 1.15},
        "pressure_shift": {"dx": 0.04 * radius, "dy": -0.03 * radius},
        "sensor_offset": {"offset_Fx": 0.08 * fn, "offset_Fy": -0.06 * fn, "offset_Mz": 0.05 * fn * radius},
        "sensor_crosstalk": {
            "c_xy": 0.0,
            "c_xz": 0.0,
            "c_yx": 0.06,
            "c_yz": 0.0,
            "c_zx": 0.02 * radius,
            "c_zy": 0.0,
        },  # fmt: skip
        "load_transfer": {"h_x": 0.3 * radius, "h_y": 0.2 * radius},
        "pressure_shape": {"c_rim": 0.4},
    }
    if cause not in table:
        raise ArgumentError(f"--cause must be one of {', '.join(CAUSES)}, got {cause!r}")
    return table[cause]


def make_example(
    simulation,
    out,
    *,
    cause: str = EXAMPLE_CAUSE,
    seed: int = EXAMPLE_SEED,
    friction: float = DEFAULT_FRICTION,
    rolling=None,
    analyse_kwargs: dict | None = None,
) -> SyntheticData:
    """Write an example measured-data CSV over ``simulation`` to ``out``; returns the synthetic data.

    ``simulation``/``rolling``: FE exports (paths or ContactFields) or polar maps;
    the generator works on the analysis's polar maps (finer than diagnose's fit
    grid, as for measured data). With a rolling map the rows carry roll = −1, 0, +1.
    The file's header comments document the hidden cause, its parameters, the
    noise, the outlier rows and the seed.
    """
    if cause not in CAUSES:
        raise ArgumentError(f"--cause must be one of {', '.join(CAUSES)}, got {cause!r}")
    if isinstance(simulation, PolarMap):
        static, rolling_map = simulation, rolling
    else:  # the analysis's own polar maps, not the coarser fit grid of a Simulation
        result = analyse(simulation, rolling, friction=friction, **(analyse_kwargs or {}))
        static, rolling_map = result.static_map, result.rolling_map
    sim = load_simulation(static, rolling_map, friction=friction)
    params = example_parameters(cause, sim.friction, sim.load, sim.radius)
    syn = synthesize(
        static,
        cause,
        params,
        rolling=rolling_map,
        friction=sim.friction,
        n=EXAMPLE_POINTS,
        noise=EXAMPLE_NOISE,
        outliers=EXAMPLE_OUTLIERS,
        seed=seed,
        loads=EXAMPLE_LOADS,
    )
    shown = ", ".join(f"{k} = {v:.6g}" for k, v in params.items()) or "no effect"
    name = str(simulation) if isinstance(simulation, (str, Path)) else "a polar map"
    comment = "\n".join(
        [
            "Example measured friction data, made by fepost's generator (fepost.diagnose.synthetic),",
            f"not measured: {EXAMPLE_POINTS} rig points over {name}, nominal f = {sim.friction:g}.",
            f"Hidden cause: {cause} ({shown}).",
            f"Loads {', '.join(f'{x:g}' for x in EXAMPLE_LOADS)} x N = {syn.meta['N']:.6g} N; noise "
            f"{EXAMPLE_NOISE:.1%} of each channel's range;",
            f"gross errors (sign flip, 2.5x spike) in data rows {', '.join(map(str, syn.outliers))} "
            "(0-based, header excluded).",
            "Made with: fepost diagnose --make-example CSV "
            f"--simulation {name} --cause {cause} --seed {seed}",
            "Columns: vx, vy (m/s), wz (rad/s), Fx, Fy (N), Mz (N m), N (N), roll.",
        ]
    )
    write_csv(syn.data, out, comment=comment)
    return syn
