"""Landing-gear shimmy with the tire's contact from the coupled dry-friction models.

The question the paper's coefficients serve: does a main landing gear shimmy
after touchdown, when the tire slides? This subpackage answers it for a simple
gear (docs/shimmy.md), by job:

* `.gear`: the gear's parameters and the gear file that holds them;
* `.contact`: fepost's friction models (closed forms, generalised, exact) as the
  tire's contact, with their derivatives; `.table`: a model tabulated over the
  sphere of kinematic directions for time integration;
* `.equations`: the equations of motion and the steady rolling with sliding;
* `.linear`: eigenvalues of the Jacobian, stability map, critical speeds;
* `.simulate`: nonlinear time histories and their verdicts;
* `.anchor`: a published simple nose-gear model (Somieski 1997) with its
  stretched-string tire, the outside check of the machinery;
* `.study`: the whole study on FE maps (`shimmy_study`); `.result`,
  `.figures`, `.writer`: its result, figures and output folder;
* `.brush`: the tire between sliding and gripping (tread elements over the FE
  patch); `.gripping`: the gear on it; `.touchdown`: the spin-up at touchdown
  (docs/touchdown.md);
* `.tire_string`: the exact stretched-string tire's yaw response;
  `.anchors_dynamics`: the outside anchors of the dynamics (docs/dynamics-anchors.md).
"""

from .gear import Gear, GearFileError, load_gear

__all__ = ["Gear", "GearFileError", "load_gear"]
