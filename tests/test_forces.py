"""Forces and Jacobians from Python: invariants and property-based finite-difference checks."""

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import railslosh as rs

MODELS = {
    "newtonian": dict(viscosity=0.8),
    "bingham": dict(viscosity=0.5, yield_stress=3.0),
    "herschel-bulkley": dict(consistency=0.7, power_index=0.6, yield_stress=2.0),
    "oldroyd": dict(viscosity=0.5, yield_stress=20.0, elastic_modulus=500.0),
    "casson": dict(viscosity=0.4, yield_stress=2.5),
}


def make_body(model, mesh=None):
    mesh = mesh or rs.mesh.box((0.5, 0.3, 0.2), (1, 1, 1))
    fluid = rs.Fluid(900.0, model, bulk_penalty=2.0e5, bulk_damping=20.0, **MODELS[model])
    return rs.FluidBody(mesh, fluid)


def rotation(axis, angle):
    axis = np.asarray(axis, float)
    axis /= np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def rigid(e, r, t, w, v):
    blocks = e.reshape(-1, 3)
    out = blocks @ r.T
    out[0::4] += t
    vel = np.cross(w, out)
    vel[0::4] += v
    return out.ravel(), vel.ravel()


@pytest.mark.parametrize("model", list(MODELS))
def test_rigid_motion_gives_zero_force_and_forces_rotate(model, rng):
    body = make_body(model, rs.mesh.box((0.6, 0.4, 0.3), (2, 2, 1)))
    e0 = body.reference_coordinates()
    r = rotation(rng.normal(size=3), 1.1)
    e, v = rigid(e0, r, rng.normal(size=3), rng.normal(size=3), rng.normal(size=3))
    f_def = body.internal_forces(e, v + 0.3 * rng.normal(size=v.size))
    f = body.internal_forces(e, v)
    assert np.abs(f).max() < 1e-10 * np.abs(f_def).max()
    ed = e0 + 0.01 * rng.normal(size=e0.size)
    vd = 0.3 * rng.normal(size=e0.size)
    f1 = body.internal_forces(ed, vd)
    f2 = body.internal_forces((ed.reshape(-1, 3) @ r.T).ravel(), (vd.reshape(-1, 3) @ r.T).ravel())
    np.testing.assert_allclose((f1.reshape(-1, 3) @ r.T).ravel(), f2, atol=1e-10 * np.abs(f1).max())


@settings(max_examples=6, deadline=None)
@given(model=st.sampled_from(sorted(MODELS)), seed=st.integers(0, 2**31), amp=st.floats(0.0, 0.04))
@example(model="bingham", seed=189, amp=1.192092896e-07)  # found by hypothesis on 2026-11-26
def test_element_jacobians_match_central_differences(model, seed, amp):
    body = make_body(model)
    rng = np.random.default_rng(seed)
    e = body.reference_coordinates() + amp * rng.uniform(-1, 1, 96)
    v = 0.5 * rng.uniform(-1, 1, 96)
    dofs = body.element_dofs(0)
    f, k, c = body.element_tangent(0, e, v)
    # The two paths sum the same terms in a different order. Near the reference state the penalty
    # terms, of order k V = 2e5 Pa * 0.03 m^3 = 6 kN, cancel to forces of order 1 N, so the paths
    # agree to round-off of k V, not of |f| (seed 189, amp 1.2e-7: 2.1e-12 N, 1.6 ulps of k V, on
    # forces up to 2.2 N): the tolerance is 64 ulps of k V.
    atol = 64 * np.finfo(float).eps * 2.0e5 * 0.5 * 0.3 * 0.2
    np.testing.assert_allclose(f, body.internal_forces(e, v)[dofs], rtol=1e-12, atol=atol)
    h = 1e-6
    for jac, wrt in ((k, "e"), (c, "v")):
        fd = np.empty((96, 96))
        for j, d in enumerate(dofs):
            xp = (e if wrt == "e" else v).copy()
            xm = xp.copy()
            xp[d] += h
            xm[d] -= h
            fp = body.internal_forces(xp, v) if wrt == "e" else body.internal_forces(e, xp)
            fm = body.internal_forces(xm, v) if wrt == "e" else body.internal_forces(e, xm)
            fd[:, j] = (fp[dofs] - fm[dofs]) / (2 * h)
        err = np.abs(fd - jac).max() / np.abs(jac).max()
        assert err <= 1e-6, f"{model} d/d{wrt}: {err:.2e}"


def test_limits_bingham_zero_yield_equals_newtonian(rng):
    mesh = rs.mesh.box((0.5, 0.4, 0.3), (2, 1, 1))
    new = rs.FluidBody(mesh, rs.fluids.newtonian(900.0, 0.7, bulk_penalty=1e5))
    bing = rs.FluidBody(mesh, rs.fluids.bingham(900.0, 0.7, 0.0, bulk_penalty=1e5))
    hb = rs.FluidBody(mesh, rs.fluids.herschel_bulkley(900.0, 0.7, 1.0, 0.0, bulk_penalty=1e5))
    cas = rs.FluidBody(mesh, rs.fluids.casson(900.0, 0.7, 0.0, bulk_penalty=1e5))
    old = rs.FluidBody(mesh, rs.fluids.oldroyd(900.0, 0.7, 0.0, bulk_penalty=1e5))
    e = new.reference_coordinates() + 0.01 * rng.normal(size=new.n_coords)
    v = 0.4 * rng.normal(size=new.n_coords)
    ref = new.internal_forces(e, v)
    for b in (bing, hb, cas, old):
        np.testing.assert_allclose(b.internal_forces(e, v), ref, rtol=0, atol=1e-13 * np.abs(ref).max())


def test_volume_is_invariant_under_isochoric_shear():
    body = make_body("newtonian", rs.mesh.box((0.6, 0.4, 0.3), (2, 2, 2)))
    e0 = body.reference_coordinates()
    s = np.array([[1.0, 0.25, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    e = (e0.reshape(-1, 3) @ s.T).ravel()
    assert body.volume(e) == pytest.approx(body.volume(e0), rel=1e-13)
    assert body.volume(2.0 * e0) == pytest.approx(8.0 * body.volume(e0), rel=1e-13)
