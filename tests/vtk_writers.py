"""Write VTK XML files with VTK's own writers in every layout, and read a file both ways.

`xml_file` sets the data mode (ASCII, inline binary, appended raw or base64), the
compressor, the byte order, the header word and the block size; `both_ways` reads a
file with a path switched on and off (a module attribute patched to an empty tuple);
`same_fields` compares what the two ways gave, every field, types included.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from fepost.errors import FepostError


def xml_file(data, out: Path, mode: str, encode: bool, compressor: str, **extra) -> Path:
    """Write the pyvista/VTK data set ``data`` (unstructured grid or polydata) to ``out``."""
    from vtkmodules.vtkCommonDataModel import vtkPolyData
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter, vtkXMLUnstructuredGridWriter

    w = vtkXMLPolyDataWriter() if isinstance(data, vtkPolyData) else vtkXMLUnstructuredGridWriter()
    w.SetInputData(data)
    w.SetFileName(str(out))
    {"ascii": w.SetDataModeToAscii, "binary": w.SetDataModeToBinary, "appended": w.SetDataModeToAppended}[
        mode
    ]()
    w.SetEncodeAppendedData(encode)
    {
        "none": w.SetCompressorTypeToNone,
        "zlib": w.SetCompressorTypeToZLib,
        "lz4": w.SetCompressorTypeToLZ4,
        "lzma": w.SetCompressorTypeToLZMA,
    }[compressor]()
    if extra.get("big_endian"):
        w.SetByteOrderToBigEndian()
    if extra.get("uint64"):
        w.SetHeaderTypeToUInt64()
    if extra.get("block"):
        w.SetBlockSize(extra["block"])
    w.Write()
    return out


def both_ways(read, module, switch: str):
    """(with, without) the path ``module.switch`` enables: each ``read()``'s value, or the
    (type, message) of the fepost error it raised."""

    def one():
        try:
            return read()
        except FepostError as exc:
            return (type(exc), str(exc))

    first = one()
    saved = getattr(module, switch)
    setattr(module, switch, ())
    try:
        second = one()
    finally:
        setattr(module, switch, saved)
    return first, second


def same_fields(a, b) -> None:
    """Assert two contact fields (or two errors' (type, message)) are identical, every field."""
    assert type(a) is type(b)
    if isinstance(b, tuple):
        assert a == b
        return
    for f in dataclasses.fields(b):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(y, np.ndarray):
            assert x.dtype == y.dtype and np.array_equal(x, y), f.name
        elif isinstance(y, Mapping) and y and isinstance(next(iter(y.values())), np.ndarray):
            assert x.keys() == y.keys(), f.name
            assert all(x[k].dtype == y[k].dtype and np.array_equal(x[k], y[k]) for k in y), f.name
        else:
            assert x == y, f.name
