//! Small-amplitude (linear) modes of a slosh system about a state at rest.
//!
//! About an equilibrium q₀ at rest (tank at rest, v = 0) the undamped linearized equations of
//! motion are M δq̈ + K δq = 0 with K = −∂Q/∂q at (q₀, v = 0): the penalty and contact
//! stiffness including the geometric (pre-stress) stiffness of the hydrostatic pressure;
//! gravity is a constant force and adds nothing. The viscous and bulk-damping forces vanish
//! with their q-derivatives at v = 0, so K does not depend on the viscosity. The free-surface
//! restoring force of sloshing enters through the pre-stress term, so the sloshing modes
//! are eigenpairs of
//!
//! K φ = ω² M φ,
//!
//! solved densely: M = L Lᵀ (Cholesky), (L⁻¹ K L⁻ᵀ) y = ω² y, φ = L⁻ᵀ y, so φᵀ M φ = 1.
//! K comes from conservative forces and is symmetric up to round-off (measured asymmetry
//! 1e-9 of its largest entry on the cylinder slices); its symmetric part is used.
//!
//! The effective mass of mode k along axis d is m_eff = (φₖᵀ M r_d)², with r_d the rigid
//! translation along d (1 on the position components d of every node, 0 on the gradients);
//! over all modes the effective masses sum to r_dᵀ M r_d = m, the liquid mass. A lateral
//! acceleration of the tank excites mode k in proportion to φₖᵀ M r_d, so the mode with the
//! largest lateral effective mass is the one a lateral pulse shows.
//!
//! A negative eigenvalue means that the state is not a stable equilibrium of the discrete
//! model: that mode grows as e^{σt}, σ = √(−ω²).
//!
//! Dense, O(n³): meant for slices of a few thousand coordinates.

use faer::{Mat, Par, Side};

use super::SloshSystem;
use crate::integrator::{MechanicalSystem, SystemError};

/// Linear modes, ascending in ω².
#[derive(Debug, Clone)]
pub struct LinearModes {
    /// ω² of each mode (rad²/s²), ascending; negative for unstable modes.
    pub omega_sq: Vec<f64>,
    /// Effective mass of each mode along the coordinate axes x, y, z (kg).
    pub effective_mass: Vec<[f64; 3]>,
    /// Mass-normalized mode shapes (columns), φᵀ M φ = 1.
    pub shapes: Mat<f64>,
}

impl LinearModes {
    /// Index of the mode with the largest effective mass along `axis` (0, 1, 2).
    pub fn dominant(&self, axis: usize) -> usize {
        (0..self.omega_sq.len())
            .max_by(|&a, &b| self.effective_mass[a][axis].total_cmp(&self.effective_mass[b][axis]))
            .unwrap_or(0)
    }
}

/// The eigenpairs of K_sym φ = ω² M φ for dense `m` (symmetric positive definite) and `k`
/// (its symmetric part is used), ascending in ω², with φᵀ M φ = 1 (module docs: M = L Lᵀ,
/// (L⁻¹ K L⁻ᵀ) y = ω² y, φ = L⁻ᵀ y).
pub fn mass_normalized_eigen(m: &Mat<f64>, k: &Mat<f64>) -> Result<(Vec<f64>, Mat<f64>), SystemError> {
    let n = m.nrows();
    let err = |what: &str| SystemError::Other(format!("linear modes: {what}"));
    let llt = m.llt(Side::Lower).map_err(|e| err(&format!("mass matrix not positive definite: {e:?}")))?;
    let l = llt.L().to_owned();
    // A = L⁻¹ K_sym L⁻ᵀ: B = L⁻¹ K_sym, then A = L⁻¹ Bᵀ (K_sym symmetric)
    let mut b = Mat::<f64>::from_fn(n, n, |i, j| 0.5 * (k[(i, j)] + k[(j, i)]));
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l.as_ref(), b.as_mut(), Par::Seq);
    let mut a = b.transpose().to_owned();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l.as_ref(), a.as_mut(), Par::Seq);
    let a = Mat::<f64>::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
    let eig = a.self_adjoint_eigen(Side::Lower).map_err(|e| err(&format!("eigensolver: {e:?}")))?;
    let omega_sq: Vec<f64> = (0..n).map(|c| eig.S()[c]).collect();
    let mut shapes = eig.U().to_owned();
    faer::linalg::triangular_solve::solve_upper_triangular_in_place(l.transpose(), shapes.as_mut(), Par::Seq);
    Ok((omega_sq, shapes))
}

/// Linear modes of `sys` about the state `q` at rest at time `t` (the tank must be at rest
/// there; `q` should be a settled equilibrium, otherwise K also holds the residual's terms).
pub fn linear_modes(sys: &mut SloshSystem, t: f64, q: &[f64]) -> Result<LinearModes, SystemError> {
    let n = sys.n_coords();
    let pattern = sys.pattern().dynamics;
    let zero = vec![0.0; n];
    let mut mv = vec![0.0; pattern.len()];
    sys.mass(q, &mut mv)?;
    let mut dq = vec![0.0; pattern.len()];
    let mut dv = vec![0.0; pattern.len()];
    sys.force_jacobians(t, q, &zero, &mut dq, &mut dv)?;
    let mut m = Mat::<f64>::zeros(n, n);
    let mut k = Mat::<f64>::zeros(n, n);
    for (idx, &(i, j)) in pattern.iter().enumerate() {
        m[(i, j)] += mv[idx];
        k[(i, j)] -= dq[idx];
    }
    let (omega_sq, shapes) = mass_normalized_eigen(&m, &k)?;
    // M r_d for the three rigid translations: column sums of M over the position components d
    let mut mr = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
    for (idx, &(i, j)) in pattern.iter().enumerate() {
        if j % 12 < 3 {
            mr[j % 12][i] += mv[idx];
        }
    }
    let effective_mass = (0..n)
        .map(|c| {
            let col = shapes.col(c);
            let p = |d: usize| -> f64 { (0..n).map(|i| col[i] * mr[d][i]).sum() };
            let (px, py, pz) = (p(0), p(1), p(2));
            [px * px, py * py, pz * pz]
        })
        .collect();
    Ok(LinearModes { omega_sq, effective_mass, shapes })
}

#[cfg(test)]
mod tests {
    use ancf_core::FluidBody;
    use ancf_core::constitutive::Rheology;
    use ancf_core::contact::{WallContact, WallContactLaw};
    use ancf_core::element::QuadratureOptions;
    use ancf_core::mesh::box_mesh;
    use ancf_core::tank::{TankGeometry, TankShape};

    use super::*;
    use crate::defaults::liquid;
    use crate::slosh::{PrescribedMotion, SloshFrame};
    use ancf_core::constants::GRAVITY as G;

    #[test]
    fn modes_are_mass_normalized_and_effective_masses_sum_to_the_mass() {
        let mesh = box_mesh([-0.2, -0.15, 0.0], [0.4, 0.3, 0.1], [2, 2, 1]).unwrap();
        let fluid = liquid(998.0, Rheology::Newtonian { viscosity: 1e-3 }, 0.1, 0.1).unwrap();
        let body = FluidBody::new(mesh, fluid, QuadratureOptions::default()).unwrap();
        let geo = TankGeometry::new(TankShape::Box { min: [-0.2, -0.15, 0.0], max: [0.2, 0.15, 0.3] }, vec![]).unwrap();
        let contact = WallContact::new(&body, geo, WallContactLaw::default_for(998.0, G, 0.1)).unwrap();
        let mass = body.total_mass();
        let q = body.reference_coordinates();
        let mut sys =
            SloshSystem::new(body, contact, PrescribedMotion::at_rest([0.0; 3]), [0.0, 0.0, -G], SloshFrame::Inertial)
                .unwrap();
        let modes = linear_modes(&mut sys, 0.0, &q).unwrap();
        let n = q.len();
        assert_eq!(modes.omega_sq.len(), n);
        assert!(modes.omega_sq.windows(2).all(|w| w[0] <= w[1]));
        for d in 0..3 {
            let total: f64 = modes.effective_mass.iter().map(|m| m[d]).sum();
            assert!((total / mass - 1.0).abs() < 1e-8, "axis {d}: {total} vs {mass}");
        }
        // φᵀ M φ = 1 for a few modes, with M = M_s ⊗ I₃
        let ms = sys.body.scalar_mass().as_ref();
        for c in [0, n / 2, n - 1] {
            let phi = modes.shapes.col(c);
            let mut norm = 0.0;
            for j in 0..ms.ncols() {
                for (i, v) in ms.row_idx_of_col(j).zip(ms.val_of_col(j)) {
                    for k in 0..3 {
                        norm += phi[3 * i + k] * v * phi[3 * j + k];
                    }
                }
            }
            assert!((norm - 1.0).abs() < 1e-8, "mode {c}: {norm}");
        }
    }
}
