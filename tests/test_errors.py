"""Bad input gets a clear error naming the field; no Rust panic reaches Python."""

import numpy as np
import pytest

import railslosh as rs
from railslosh import _core


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        (dict(fill=1.5), "fill"),
        (dict(fill=0.0), "fill"),
        (dict(radius=-1.0), "radius"),
        (dict(n_length=0), "n_length"),
        (dict(n_height=0), "n_height"),
        (dict(grading=0.0), "grading"),
        (dict(head_depth=-0.1), "head_depth"),
    ],
)
def test_invalid_mesh_parameters_name_the_field(kwargs, field):
    with pytest.raises(ValueError, match=field) as info:
        rs.mesh.cylinder_tank(**kwargs)
    assert "allowed" in str(info.value)


@pytest.mark.parametrize(
    ("args", "kwargs", "field"),
    [
        ((-850.0, "newtonian"), dict(viscosity=1.0, bulk_penalty=1e6), "density"),
        ((850.0, "newtonian"), dict(viscosity=-1.0, bulk_penalty=1e6), "viscosity"),
        ((850.0, "bingham"), dict(viscosity=1.0, yield_stress=-3.0, bulk_penalty=1e6), "yield_stress"),
        ((850.0, "herschel-bulkley"), dict(consistency=1.0, power_index=-1.0, bulk_penalty=1e6), "power_index"),
        (
            (850.0, "oldroyd"),
            dict(viscosity=1.0, yield_stress=1.0, elastic_modulus=0.0, bulk_penalty=1e6),
            "elastic_modulus",
        ),
        ((850.0, "newtonian"), dict(viscosity=1.0, bulk_penalty=-1.0), "bulk_penalty"),
        ((850.0, "maxwell"), dict(bulk_penalty=1.0), "model"),
    ],
)
def test_invalid_fluid_parameters_name_the_field(args, kwargs, field):
    with pytest.raises(ValueError, match=field):
        rs.Fluid(*args, **kwargs)


def test_zero_elements_and_bad_quadrature_are_rejected():
    with pytest.raises(ValueError, match="n_x"):
        rs.mesh.box((1.0, 1.0, 1.0), (0, 1, 1))
    mesh = rs.mesh.box((1.0, 1.0, 1.0), (1, 1, 1))
    with pytest.raises(ValueError, match="quadrature.viscous"):
        rs.FluidBody(mesh, rs.fluids.water(), viscous_points=2)


def test_wrong_array_length_names_the_argument():
    body = rs.FluidBody(rs.mesh.box((1.0, 1.0, 1.0), (1, 1, 1)), rs.fluids.water())
    with pytest.raises(ValueError, match="`e`"):
        body.internal_forces(np.zeros(5), np.zeros(96))
    with pytest.raises(ValueError, match="index"):
        body.element_tangent(3, np.zeros(96), np.zeros(96))


def test_inverted_element_is_a_railslosh_error_naming_the_element():
    body = rs.FluidBody(rs.mesh.box((1.0, 1.0, 1.0), (2, 1, 1)), rs.fluids.water())
    e = body.reference_coordinates().reshape(-1, 3) * np.array([-1.0, 1.0, 1.0])
    with pytest.raises(rs.RailsloshError, match="element 0 inverted"):
        body.internal_forces(e.ravel(), np.zeros(e.size))


def test_a_rust_panic_becomes_a_railslosh_error():
    with pytest.raises(rs.RailsloshError, match="internal error"):
        _core._panic_for_test()
