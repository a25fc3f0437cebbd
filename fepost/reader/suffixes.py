"""The file suffixes of each format fepost reads (lower case).

Defined once, in a module that imports nothing: the package (`fepost.reader`, which
stays light to import) dispatches on them, and each format's reader takes its own.
"""

from __future__ import annotations

VTK_SUFFIXES = (".vtu", ".vtp", ".vtk", ".vtm", ".vts", ".vtr", ".pvtu", ".pvtp")
EXODUS_SUFFIXES = (".e", ".exo", ".ex2", ".exii")
XDMF_SUFFIXES = (".xdmf", ".xmf")
FRD_SUFFIXES = (".frd",)

__all__ = ["EXODUS_SUFFIXES", "FRD_SUFFIXES", "VTK_SUFFIXES", "XDMF_SUFFIXES"]
