"""The causes ``fepost diagnose`` can name, in the order it tries them.

A module of its own, without numpy, so that the command line builds its
``--cause`` choices and help without importing the diagnosis
(`fepost.diagnose.causes` defines what each cause does).
"""

CAUSES = (
    "none",
    "friction_level",
    "pressure_dependent_friction",
    "speed_dependent_friction",
    "elliptic_patch",
    "anisotropic_friction",
    "pressure_shift",
    "sensor_offset",
    "sensor_crosstalk",
    "load_transfer",
    "pressure_shape",
)
