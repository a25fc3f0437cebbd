"""Refusals that name what is wrong: a --surface without pressure, an interface in tension,
several contact-pressure candidates."""

from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv
from test_reader_exodus import _two_bodies

from fepost.errors import PressureError
from fepost.reader import read_contact


def test_a_surface_without_pressure_names_where_the_pressure_is(tmp_path):
    path = _two_bodies(tmp_path)
    with pytest.raises(PressureError) as err:
        read_contact(path, surface="slab_top")
    assert str(err.value) == (
        f"{path}: surface 'slab_top' (side set 1 'slab_top') carries no positive 'contact_pressure'; "
        "the pressure is on side set 2 'cube_bottom', element block 2 (HEX8, 27 elements): "
        "choose one of them with --surface"
    )


def _quad(tmp_path, values, name="m.vtu"):
    pts = np.array([[0, 0, 0], [0.2, 0, 0], [0.2, 0.2, 0], [0, 0.2, 0]], float)
    grid = pv.UnstructuredGrid(np.r_[4, 0, 1, 2, 3], np.array([pv.CellType.QUAD]), pts)
    for k, v in values.items():
        grid.point_data[k] = np.asarray(v, float)
    grid.save(tmp_path / name)
    return tmp_path / name


def test_tension_only_interface_is_called_tension(tmp_path):
    path = _quad(tmp_path, {"CPRESS": [-1e5, -2e5, 0.0, -5e4]})
    with pytest.raises(PressureError) as err:
        read_contact(path)
    assert str(err.value) == (
        f"{path}: pressure array 'CPRESS' has no positive value and is negative at 3 nodes "
        "(down to -2e+05): the interface is in tension (a tied interface pulled apart), not pressed "
        "into contact; fepost reads compression as positive pressure"
    )


def test_contact_name_preferred_over_generic_pressure_with_a_note(tmp_path):
    path = _quad(tmp_path, {"CPRESS": [1e5] * 4, "pressure": [2e5] * 4})
    fld = read_contact(path)
    assert fld.field == "CPRESS"
    assert fld.notes == (
        "pressure taken from 'CPRESS', a contact-pressure name, preferred over the generic 'pressure'; "
        "choose another with --field",
    )
    assert read_contact(path, field="pressure").field == "pressure"
    assert np.all(read_contact(path, field="pressure").values == 2e5)


def test_two_contact_names_are_an_error_listing_them(tmp_path):
    from fepost.errors import FieldError

    path = _quad(tmp_path, {"CPRESS": [1e5] * 4, "contact_pressure": [2e5] * 4, "pressure": [3e5] * 4})
    with pytest.raises(FieldError) as err:
        read_contact(path)
    assert str(err.value) == (
        f"{path}: several candidate contact-pressure arrays: CPRESS (point), contact_pressure (point), "
        "pressure (point); choose one with --field"
    )


def test_a_block_that_is_a_directory_is_not_a_regular_file_not_missing(tmp_path):
    """A multi-block file naming a directory where a block file belongs: the refusal says what
    the path is, not that it is missing; the same file naming the real block reads."""
    from fepost.errors import InputFileError

    _quad(tmp_path, {"CPRESS": [1e5] * 4}, name="block.vtu")
    (tmp_path / "odd.vtu").mkdir()
    body = (
        '<?xml version="1.0"?>\n<VTKFile type="vtkMultiBlockDataSet" version="1.0">\n'
        '<vtkMultiBlockDataSet><DataSet index="0" file="{}"/></vtkMultiBlockDataSet>\n</VTKFile>\n'
    )
    good, odd = tmp_path / "good.vtm", tmp_path / "odd.vtm"
    good.write_text(body.format("block.vtu"))
    odd.write_text(body.format("odd.vtu"))
    assert np.all(read_contact(good).values == 1e5)
    with pytest.raises(InputFileError) as err:
        read_contact(odd)
    assert str(err.value) == (
        f"{odd}: refused .vtm file (multi-block piece 'odd.vtu' is not a regular file but a directory)"
    )
