"""Which array holds the contact pressure (and the displacement): names and components.

The pressure is found by name, case-insensitively and ignoring punctuation
(`PRESSURE_NAMES`), as a whole scalar array or as a **named component**
of a vector array: CalculiX results converted by ccx2paraview hold the contact
output in one 6-component array ``CONTACT`` whose components are named
``COPEN CSLIP1 CSLIP2 CPRESS CSHEAR1 CSHEAR2``. Legacy ``.vtk`` files cannot
store component names; there an unnamed 6-component ``CONTACT`` array is read
with that same ccx2paraview layout (`CCX_CONTACT`), and the result says
so.

When a file holds a contact-pressure name (``CPRESS``, ``contact_pressure``, ...)
and the generic ``pressure`` (often a fluid or inflation pressure), the contact
name is taken and the choice is stated in the result's notes; two contact names
are an error that lists them.

``--field NAME`` names an array, ``NAME:K`` its component K, and a component
name (``CPRESS``) is accepted too.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace

from ..errors import FepostError, FieldError

#: Normalised (lower-case, alphanumerics only) names taken as contact pressure.
PRESSURE_NAMES = (
    "cpress",
    "contactpressure",
    "contactpress",
    "contpress",
    "cpres",
    "pcontact",
    "pressurecontact",
    "normalcontactpressure",
    "contactnormalpressure",
    "pressure",
)
#: Normalised names that may mean another pressure (fluid, inflation): a contact-pressure name
#: (CPRESS, contact_pressure, ...) in the same file is preferred to them, with a note.
GENERIC_NAMES = ("pressure",)
#: Normalised names taken as nodal displacement (3 components).
DISPLACEMENT_NAMES = ("displacement", "displacements", "displ", "disp", "u")
#: Values that mean "no contact data" rather than a pressure (MOOSE writes −99999).
SENTINELS = (-99999.0, -999999.0, -9999.0, -1.0e30, -1.0e20)
#: ccx2paraview's component layout of CalculiX's ``CONTACT`` output (used when a file names none).
CCX_CONTACT = ("COPEN", "CSLIP1", "CSLIP2", "CPRESS", "CSHEAR1", "CSHEAR2")


def norm(name: str) -> str:
    """Lower-case alphanumerics of ``name``: ``Contact_Pressure`` → ``contactpressure``."""
    return re.sub(r"[^0-9a-z]", "", name.lower())


@dataclass(frozen=True)
class ArrayInfo:
    """An array offered by a file: where it lives and its components (names when known)."""

    name: str
    location: str  # "point" or "cell"
    ncomp: int
    components: tuple[str, ...] = ()


@dataclass(frozen=True)
class FieldChoice:
    """The array (and component) chosen as contact pressure."""

    name: str
    component: int | None
    location: str
    label: str
    note: str = ""


def _components(info: ArrayInfo) -> tuple[tuple[str, ...], bool]:
    """Component names of ``info``: the file's, or ccx2paraview's layout for an unnamed CONTACT."""
    if info.components and any(info.components):
        return info.components, False
    if norm(info.name) == "contact" and info.ncomp == len(CCX_CONTACT):
        return CCX_CONTACT, True
    return (), False


def _listing(catalogue: list[ArrayInfo]) -> str:
    parts = []
    for a in catalogue:
        comps, _ = _components(a)
        extra = (
            f", components {' '.join(comps)}" if comps else (f", {a.ncomp} components" if a.ncomp > 1 else "")
        )
        parts.append(f"{a.name} ({a.location}{extra})")
    return ", ".join(parts) or "none"


def pick_field(source: str, catalogue: list[ArrayInfo], field: str | None) -> FieldChoice:
    """Choose the contact-pressure array of ``catalogue`` (``field`` names it when given).

    Raises
    ------
    FieldError
        No candidate, several candidates, or ``field`` names nothing in the file.
    """
    by_name = {a.name: a for a in catalogue}
    if field is not None:
        return _named(source, catalogue, by_name, field)
    hits: list[FieldChoice] = []
    for a in catalogue:
        if norm(a.name) in PRESSURE_NAMES and a.ncomp == 1:
            hits.append(FieldChoice(a.name, None, a.location, a.name))
            continue
        comps, assumed = _components(a)
        for k, c in enumerate(comps):
            if norm(c) in PRESSURE_NAMES:
                note = (
                    f"pressure taken as component {k} ({c}) of {a.name}, by ccx2paraview's layout "
                    f"({' '.join(CCX_CONTACT)}): the file names no components"
                    if assumed
                    else ""
                )
                hits.append(FieldChoice(a.name, k, a.location, f"{a.name}:{c}", note))
    if not hits:
        raise FieldError(
            f"{source}: no contact-pressure array found (looked for CPRESS, contact_pressure, "
            f"pressure, ... and vector components with those names); arrays found: "
            f"{_listing(catalogue)}; name one with --field"
        )
    if len(hits) > 1:
        specific = [h for h in hits if norm(h.label.split(":")[-1]) not in GENERIC_NAMES]
        if len(specific) == 1:
            chosen = specific[0]
            generic = ", ".join(repr(h.label) for h in hits if h is not chosen)
            note = (
                f"pressure taken from {chosen.label!r}, a contact-pressure name, preferred over the "
                f"generic {generic}; choose another with --field"
            )
            return replace(chosen, note="; ".join(n for n in (chosen.note, note) if n))
        cand = ", ".join(f"{h.label} ({h.location})" for h in hits)
        raise FieldError(
            f"{source}: several candidate contact-pressure arrays: {cand}; choose one with --field"
        )
    return hits[0]


def _named(source: str, catalogue: list[ArrayInfo], by_name: dict[str, ArrayInfo], field: str) -> FieldChoice:
    name, comp = field, None
    m = re.fullmatch(r"(.+):(\d+)", field)
    if m and field not in by_name:
        name, comp = m.group(1), int(m.group(2))
    info = by_name.get(name)
    if info is None:
        lower = {n.lower(): a for n, a in by_name.items()}
        info = lower.get(name.lower())
    if info is None:
        # a component name (CPRESS inside CONTACT)
        for a in catalogue:
            comps, assumed = _components(a)
            for k, c in enumerate(comps):
                if c.lower() == name.lower() and comp is None:
                    note = f"component {k} ({c}) of {a.name} by ccx2paraview's layout" if assumed else ""
                    return FieldChoice(a.name, k, a.location, f"{a.name}:{c}", note)
        raise FieldError(f"{source}: no array named {name!r}; arrays found: {_listing(catalogue)}")
    if comp is None:
        if info.ncomp == 1:
            return FieldChoice(info.name, None, info.location, info.name)
        comps, _ = _components(info)
        hint = f" ({' '.join(f'{k}={c}' for k, c in enumerate(comps))})" if comps else ""
        raise FieldError(
            f"{source}: array {info.name!r} has {info.ncomp} components{hint}; "
            f"choose one with --field {info.name}:K"
        )
    if comp >= info.ncomp:
        if info.ncomp == 1:
            raise FieldError(f"{source}: array {info.name!r} is scalar; it has no component {comp}")
        raise FieldError(f"{source}: array {info.name!r} has no component {comp} (it has {info.ncomp})")
    if info.ncomp == 1:
        return FieldChoice(info.name, None, info.location, info.name)
    comps, _ = _components(info)
    label = f"{info.name}:{comps[comp]}" if comps and comps[comp] else f"{info.name}:{comp}"
    return FieldChoice(info.name, comp, info.location, label)


def pick_displacement(source: str, catalogue: list[ArrayInfo], displacement: str | None) -> str | None:
    """The nodal displacement array to add to the coordinates (None: none)."""
    if displacement is None or str(displacement).lower() == "none":
        return None
    points = [a for a in catalogue if a.location == "point"]
    if displacement == "auto":
        for a in points:
            if norm(a.name) in DISPLACEMENT_NAMES and a.ncomp >= 2:
                return a.name
        return None
    hit = next((a for a in points if a.name == displacement), None)
    if hit is None:
        names = ", ".join(a.name for a in points) or "none"
        raise FieldError(
            f"{source}: no nodal displacement array named {displacement!r}; point arrays: {names}"
        )
    if hit.ncomp < 2:
        raise FieldError(f"{source}: displacement array {displacement!r} is not a vector per node")
    return hit.name


def needed_point_arrays(
    source: str, catalogue: list[ArrayInfo], field: str | None, displacement: str | None
) -> set[str] | None:
    """The point arrays a contact field reads from ``catalogue``: the pressure (when it is
    nodal) and the displacement, chosen as `pick_field` and `pick_displacement` choose them;
    None when the choice fails (the reader then decodes every array and raises the same
    error on the same catalogue). Lets a reader leave the other arrays undecoded."""
    try:
        choice = pick_field(source, catalogue, field)
        disp = pick_displacement(source, catalogue, displacement)
    except FepostError:
        return None
    keep = {choice.name} if choice.location == "point" else set()
    if disp is not None:
        keep.add(disp)
    return keep
