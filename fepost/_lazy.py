"""Names a package re-exports from its submodules, imported on first access (PEP 562).

``import fepost`` and ``import fepost.diagnose`` stay light this way: the command
line builds its parser and help without numpy, scipy or VTK.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from importlib import import_module
from typing import Any


def lazy_names(
    package: str, names: Mapping[str, str], namespace: dict[str, Any]
) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """The module ``__getattr__`` and ``__dir__`` of ``package``.

    ``names`` maps each re-exported name to the submodule (relative to ``package``)
    that defines it; ``namespace`` is the package's ``globals()``, where a name is
    kept once imported.
    """

    def __getattr__(name: str) -> Any:
        if name in names:
            value = getattr(import_module(f".{names[name]}", package), name)
            namespace[name] = value
            return value
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__() -> list[str]:
        return sorted(set(namespace) | set(names))

    return __getattr__, __dir__
