"""Read a small JSON file that must hold one object: the body files and the FE exports' sidecars.

One place for what both refuse, each in one line naming the file: a file over its size
limit, unreadable or malformed JSON, the non-standard ``NaN``/``Infinity`` literals
Python's json module would otherwise accept, nesting deep enough to exhaust the
recursion limit, and a document that is not an object. ``what`` names the kind of file
in the messages ("body JSON", "sidecar JSON").
"""

from __future__ import annotations

import json
from pathlib import Path

from .errors import InputFileError


def _no_constant(name: str):
    raise ValueError(f"non-finite number {name}: not a number JSON allows")


def read_json_object(path: Path, what: str, limit: int) -> dict:
    """The object in ``path`` (at most ``limit`` bytes); `InputFileError` otherwise.

    A missing file raises `FileNotFoundError`, for the caller to word."""
    try:
        size = path.stat().st_size
        if size > limit:
            raise InputFileError(f"{path}: {what} is {size} bytes (limit {limit})")
        data = json.loads(path.read_bytes(), parse_constant=_no_constant)
    except (InputFileError, FileNotFoundError):
        raise
    except (OSError, ValueError, RecursionError) as exc:
        text = str(exc).strip().splitlines()
        raise InputFileError(
            f"{path}: unreadable {what} ({text[0] if text else type(exc).__name__})"
        ) from None
    if not isinstance(data, dict):
        raise InputFileError(f"{path}: {what} must be an object, got {type(data).__name__}")
    return data
