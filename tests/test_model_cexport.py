"""The C evaluator generated from the model JSON (fepost.friction.cexport), compiled with
the system's C compiler and run on many kinematic points, against the Python model.

Tolerance: 1e-12 relative (to each value, with F0 or M0 as the floor near zero):
the C code does the formulas of the numpy path in the same order with the
model's numbers as exact hexadecimal literals; only libm and the compiler's
contraction choices differ (measured ≤ 1e-15).
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess

import numpy as np
import pytest

from fepost.errors import ArgumentError, DataError, OutputError
from fepost.friction.build import build_model
from fepost.friction.cexport import c_source, export_c
from fepost.friction.law import FrictionLaw
from fepost.friction.model import GeneralisedModel
from fepost.friction.reference_maps import asymmetric, ellipse_quad, tire_like

REL = 1e-12
CC = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
needs_cc = pytest.mark.skipif(CC is None, reason="no C compiler (cc, gcc, clang) on PATH")


@pytest.fixture(scope="module")
def models() -> dict[str, GeneralisedModel]:
    return {
        "asymmetric 72": build_model(asymmetric(2.0), FrictionLaw(f=0.3), order=(4, 8), check=False),
        "tire-like 204": build_model(tire_like(2.5), FrictionLaw(f=0.5), order=(8, 12), check=False),
        "anisotropic": build_model(
            asymmetric(1.5), FrictionLaw(f=0.3, anisotropy=0.7), order=(4, 8), check=False
        ),
        "base only": build_model(
            ellipse_quad("hertz", 1.0), FrictionLaw(f=0.3), order=(2, 3)
        ).without_correction(),
    }


def kinematics() -> np.ndarray:
    """Random points over many magnitudes and the singular ones: zero velocity, pure
    spin (both signs), pure sliding, and their neighbourhoods."""
    rng = np.random.default_rng(7)
    n = 3000
    vx, vy = rng.normal(size=(2, n)) * np.exp(rng.uniform(-5, 5, n))
    wz = rng.normal(size=n) * np.exp(rng.uniform(-3, 5, n))
    rows = [(0.0, 0.0, 0.0), (0.0, 0.0, 4.0), (0.0, 0.0, -4.0), (1.0, 0.0, 0.0), (0.0, -2.0, 0.0)]
    for eps in (1e-12, 1e-8, 1e-4):
        rows += [(eps, -eps, 10.0), (eps, 0.0, -10.0), (1.0, 0.5, eps), (-1.0, 0.0, -eps)]
    return np.vstack([np.column_stack([vx, vy, wz]), np.array(rows)])


def run_c(tmp_path, model_json: dict, points: np.ndarray) -> np.ndarray:
    src = export_c(model_json, tmp_path / "friction.c")
    exe = tmp_path / "friction"
    subprocess.run(
        [
            CC,
            "-std=c99",
            "-O2",
            "-Wall",
            "-Werror",
            "-DFEPOST_FRICTION_MAIN",
            str(src),
            "-o",
            str(exe),
            "-lm",
        ],
        check=True,
        capture_output=True,
        timeout=120,
    )
    text = "\n".join(" ".join(repr(float(x)) for x in row) for row in points) + "\n"
    out = subprocess.run([str(exe)], input=text, capture_output=True, text=True, check=True, timeout=60)
    return np.array([[float(x) for x in line.split()] for line in out.stdout.splitlines()])


@needs_cc
@pytest.mark.parametrize("name", ["asymmetric 72", "tire-like 204", "anisotropic", "base only"])
def test_compiled_c_equals_the_python_model(models, name, tmp_path):
    model = models[name]
    data = json.loads(model.to_json())  # generated from the model JSON, as a user would
    pts = kinematics()
    got = run_c(tmp_path, data, pts)
    assert got.shape == pts.shape
    for backend in ("numpy", "numba") if _has_numba() else ("numpy",):
        ref = model.evaluate(pts[:, 0], pts[:, 1], pts[:, 2], backend=backend)
        for col, (label, scale) in enumerate((("Fx", model.F0), ("Fy", model.F0), ("Mz", model.M0))):
            err = np.abs(got[:, col] - ref[col]) / np.maximum(np.abs(ref[col]), scale)
            assert np.max(err) <= REL, f"{label} ({backend}): {np.max(err):.3g}"


def _has_numba() -> bool:
    from fepost.friction import kernel

    return kernel.AVAILABLE


def test_source_is_self_contained_and_exact(models):
    model = models["asymmetric 72"]
    text = c_source(model, name="tire_friction")
    assert "void tire_friction(double vx, double vy, double wz, double *Fx, double *Fy, double *Mz)" in text
    includes = set(re.findall(r"#include <([^>]+)>", text))
    assert includes == {"math.h", "stdio.h"}  # stdio only in the harness
    # every correction number appears as its exact hexadecimal literal
    for x in model.correction.ravel()[:10]:
        assert float(x).hex() in text
    assert c_source(model.to_dict(), name="tire_friction") == text


def test_bad_arguments_and_paths(models, tmp_path):
    model = models["base only"]
    with pytest.raises(ArgumentError, match=re.escape("name must be a C identifier, got '2x'")):
        c_source(model, name="2x")
    with pytest.raises(ArgumentError, match="model must be a GeneralisedModel or its JSON data, got list"):
        c_source([1, 2])
    with pytest.raises(DataError, match="model format must be"):
        c_source({"format": "other"})
    missing = tmp_path / "no" / "such" / "friction.c"
    with pytest.raises(
        OutputError, match=re.escape(f"{missing}: the folder {missing.parent} does not exist")
    ):
        export_c(model, missing)
    assert list(tmp_path.iterdir()) == []
