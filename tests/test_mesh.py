"""Meshes and mass matrices from Python, as numpy / scipy objects."""

import numpy as np
import pytest
import scipy.sparse as sp

import railslosh as rs


@pytest.mark.parametrize(("n_length", "coords"), [(4, 900), (6, 1260), (8, 1620)])
def test_paper_meshes_have_the_papers_coordinate_counts(n_length, coords):
    mesh = rs.mesh.cylinder_tank(n_length=n_length, n_width=4, n_height=2)
    assert mesh.n_elements == 8 * n_length
    assert mesh.n_coords == coords
    assert mesh.nodes.shape == (coords // 12, 12)
    assert mesh.nodes.dtype == np.float64
    assert mesh.connectivity.shape == (8 * n_length, 8)
    assert mesh.connectivity.dtype == np.int64
    # every node is used, indices in range
    assert set(np.unique(mesh.connectivity)) == set(range(mesh.n_nodes))


def test_shared_nodes_share_all_twelve_coordinates(tank_mesh):
    # neighbouring elements reference the same node index, so they share r and its gradients;
    # gradients at nodes come from the geometric map: r_x points along the tank axis
    nodes = tank_mesh.nodes
    rx = nodes[:, 3:6]
    assert np.all(rx[:, 0] > 0)
    conn = tank_mesh.connectivity
    # element 0 and element 1 share the face x = x_B of element 0
    assert set(conn[0][[1, 2, 5, 6]]) == set(conn[1][[0, 3, 4, 7]])


def test_mass_matrix_is_spd_and_sums_to_rho_v(tank_mesh):
    oil = rs.fluids.crude_oil("light")
    body = rs.FluidBody(tank_mesh, oil)
    m = rs.mass_matrix(body)
    assert isinstance(m, sp.csc_matrix)
    assert m.shape == (1260, 1260)
    assert abs(m - m.T).max() < 1e-9 * abs(m).max()
    ms = rs.mass_matrix(body, full=False).toarray()
    assert np.linalg.eigvalsh(ms).min() > 0.0
    # rigid translation velocity u: u^T M u = total mass |u|^2
    u = np.zeros(1260)
    u[0::12] = 1.0
    assert u @ (m @ u) == pytest.approx(body.total_mass, rel=1e-12)
    assert body.total_mass == pytest.approx(850.0 * body.reference_volume, rel=1e-12)
    assert body.total_mass == pytest.approx(850.0 * tank_mesh.exact_volume, rel=1e-2)


def test_box_mass_is_exact_and_gravity_sums_to_weight():
    mesh = rs.mesh.box((0.416, 0.324, 0.132), (3, 2, 2))
    body = rs.FluidBody(mesh, rs.fluids.water(depth=0.132))
    assert body.total_mass == pytest.approx(998.0 * 0.416 * 0.324 * 0.132, rel=1e-13)
    fg = body.gravity_force((0.0, 0.0, -9.81))
    assert fg[2::12].sum() == pytest.approx(-9.81 * body.total_mass, rel=1e-12)
    assert mesh.free_surface_z == pytest.approx(0.132)


def test_swri_tank_half_full_depth_and_volume():
    mesh = rs.mesh.elliptic_cylinder(n_length=2, n_width=4, n_height=2)
    a, b = rs.mesh.SWRI_SEMI_AXIS_Y, rs.mesh.SWRI_SEMI_AXIS_Z
    assert mesh.exact_volume == pytest.approx(0.5 * np.pi * a * b * 0.324, rel=1e-12)
    assert mesh.free_surface_z == pytest.approx(0.0, abs=1e-12)
    z = mesh.nodes[:, 2]
    assert z.min() == pytest.approx(-b, rel=1e-9)
    y = mesh.nodes[:, 1]
    assert np.all((y / a) ** 2 + (z / b) ** 2 <= 1 + 1e-9)


def test_boundary_faces_are_tagged(tank_mesh):
    kinds = {k for (_, _, k) in tank_mesh.boundary}
    assert kinds == {"Wall", "FreeSurface"}
    free = [b for b in tank_mesh.boundary if b[2] == "FreeSurface"]
    assert len(free) == 6 * 4  # top layer of a 6x4x2 mesh
