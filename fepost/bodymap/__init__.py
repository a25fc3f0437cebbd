"""A rigid body's contact-pressure map, written as an FE-style export (``fepost map``).

* `fepost.bodymap.maps` — point supports as loaded discs with the statics loads,
  a flat base as a uniform pressure (`body_map`, `BodyMap`);
* `fepost.bodymap.board` — the flat base pressed by its weight on an elastic board,
  solved by CalculiX (``fepost map --fe``);
* `fepost.bodymap.grid` — the polar grid that carries a map's load;
* `fepost.bodymap.write` — the ``.vtu`` and its sidecar, atomically;
* `fepost.bodymap.mesh` — the discs' and polygons' triangles and their exact load.

The map frame is the body frame moved to the body's ``reference_point``.
"""

from __future__ import annotations

from .maps import BodyMap, base_map, body_map, support_map
from .write import write_map

__all__ = ["BodyMap", "base_map", "body_map", "support_map", "write_map"]
