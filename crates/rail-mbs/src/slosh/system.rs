//! The fluid-in-a-tank system: one ANCF fluid body inside a rigid tank whose motion is
//! prescribed, as a [`MechanicalSystem`] for the HHT integrator.
//!
//! Two formulations of the same physics ([`SloshFrame`]):
//! - **Inertial**: fluid coordinates are global; the walls move with the tank
//!   (seed 000 §5: contact in the tank frame through R, A, Ṙ, ω).
//! - **Tank frame**: fluid coordinates are tank-frame coordinates; the walls are fixed and
//!   the motion enters as the pseudo-forces of seed 003 appendix C eq. (7.40):
//!   −ρ[a_lin + ω̇ × r + ω × (ω × r) + 2 ω × ṙ], with gravity rotated into the tank frame.
//!   Because the ANCF position field is linear in the coordinates, the generalized
//!   pseudo-forces are exact: −(∫ρN)⊗a_lin − M_s⊗(ω̃̇ + ω̃²) e − 2 M_s⊗ω̃ ė.
//!
//! Generalized forces: Q = −f_int(e, ė) + Q_gravity + Q_contact (+ pseudo-forces).

use ancf_core::FluidBody;
use ancf_core::body::{ElementJacobian, ForceWorkspace};
use ancf_core::constitutive::M3;
use ancf_core::contact::{ContactLoad, PointJacobian, TankKinematics, WallContact};
use ancf_core::error::AncfError;
use ancf_core::shape::N_SHAPE;
use nalgebra::Vector3;

use super::motion::{PrescribedMotion, TankFrameInput};
use crate::fluid_blocks::FluidBlocks;
use crate::integrator::{LinearSolverKind, MechanicalSystem, SparsityPattern, SystemError};

/// Which frame the fluid coordinates are written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SloshFrame {
    /// Global (inertial) coordinates, moving walls.
    Inertial,
    /// Tank-frame coordinates, pseudo-forces.
    Tank,
}

/// Fluid in a tank with prescribed motion.
#[derive(Debug, Clone)]
pub struct SloshSystem {
    /// The fluid body.
    pub body: FluidBody,
    /// Wall and bulkhead contact.
    pub contact: WallContact,
    /// The tank motion.
    pub motion: PrescribedMotion,
    /// Gravity (m/s², global).
    pub gravity: [f64; 3],
    /// Formulation.
    pub frame: SloshFrame,
    /// How the Newton matrix is solved; read when the integrator is built. Default
    /// sparse LU; [`LinearSolverKind::Iterative`] scales linearly to large meshes.
    pub linear_solver: LinearSolverKind,
    /// Largest admissible wall/bulkhead penetration (m), checked on every converged step
    /// ([`SystemError::Penetration`]), and the containment limit of the run-time
    /// invariants ([`crate::invariants::check_state`], also on every converged step).
    /// Default: [`PENETRATION_LIMIT_FACTOR`] × the smallest element edge.
    pub penetration_limit: f64,
    /// Admissible relative volume error of the fluid, checked on every converged step
    /// ([`SystemError::VolumeError`]). Default 0.01.
    pub volume_tolerance: f64,
    /// Volume of the reference configuration, m³.
    pub reference_volume: f64,
    /// Tank-frame formulation only: when set, the pseudo-forces and the tank-frame gravity
    /// come from these sampled inputs instead of [`motion`](Self::motion) (co-simulation,
    /// [`crate::cosim`]). `None` from [`SloshSystem::new`].
    pub tank_input: Option<TankFrameInput>,
    pattern: Vec<(usize, usize)>,
    layout: FluidBlocks,
    point_jac: Vec<PointJacobian>,
    /// Reused buffers: force evaluation and element Jacobians.
    workspace: ForceWorkspace,
    jacobians: Vec<ElementJacobian>,
    /// What the last passed step check measured (the run's monitor reuses it for the same
    /// state instead of measuring it again).
    pub(crate) last_state_check: Option<StateCheck>,
}

impl SloshSystem {
    /// Accounts the accepted state `(t, q)` in `monitor` (a run's invariant account, energy
    /// sample `energy`). When the last passed [`MechanicalSystem::check_step`] measured this
    /// very state (same time and coordinate bits) within the monitor's limits, only the
    /// energy balance is left to check; otherwise the full check runs and names any violation.
    pub(crate) fn account_state(
        &self,
        monitor: &mut crate::invariants::InvariantMonitor,
        t: f64,
        q: &[f64],
        energy: crate::invariants::EnergySample,
    ) -> Result<crate::invariants::Measured, SystemError> {
        let limits = monitor.limits;
        let cached = self.last_state_check.filter(|c| {
            c.t == t
                && c.q_bits == state_bits(q)
                && c.measured.0 <= limits.containment
                && c.measured.1 > limits.min_volume_ratio
        });
        match cached {
            Some(c) => monitor.check_energy(t, c.measured, energy),
            None => monitor.check(t, &self.body, &self.contact, &self.contact_kinematics(t), q, energy),
        }
    }

    /// The run-time invariant monitor of this system ([`crate::invariants`]): containment
    /// within its penetration limit, default energy and volume-ratio limits.
    pub fn invariant_monitor(&self) -> crate::invariants::InvariantMonitor {
        let depth = self.body.mesh.liquid_depth();
        let g = Vector3::from(self.gravity).norm();
        crate::invariants::InvariantMonitor::new(
            "fluid",
            crate::invariants::InvariantLimits::new(self.penetration_limit),
            self.body.total_mass(),
            g,
            depth.max(0.0),
        )
    }
}

pub use crate::fluid_blocks::PENETRATION_LIMIT_FACTOR;

impl SloshSystem {
    /// Assemble the system and its fixed sparsity pattern (12×12 blocks for every pair of
    /// nodes that share an element).
    pub fn new(
        body: FluidBody,
        contact: WallContact,
        motion: PrescribedMotion,
        gravity: [f64; 3],
        frame: SloshFrame,
    ) -> Result<Self, AncfError> {
        motion.validate()?;
        let mut pattern = Vec::new();
        let layout = FluidBlocks::append(&body, 0, &mut pattern);
        let reference_volume = body.volume(&body.reference_coordinates());
        Ok(Self {
            penetration_limit: crate::fluid_blocks::default_penetration_limit(&body),
            volume_tolerance: 0.01,
            reference_volume,
            body,
            contact,
            motion,
            gravity,
            frame,
            tank_input: None,
            last_state_check: None,
            linear_solver: LinearSolverKind::Direct,
            pattern,
            layout,
            point_jac: Vec::new(),
            workspace: ForceWorkspace::default(),
            jacobians: Vec::new(),
        })
    }

    /// Tank kinematics seen by the contact at time t (identity in the tank frame).
    pub fn contact_kinematics(&self, t: f64) -> TankKinematics {
        match self.frame {
            SloshFrame::Inertial => self.motion.state(t).kinematics,
            SloshFrame::Tank => TankKinematics::identity(),
        }
    }

    /// Initial state: the reference mesh (tank frame) placed at the tank pose at `t0`,
    /// moving rigidly with the tank.
    pub fn initial_state(&self, t0: f64) -> (Vec<f64>, Vec<f64>) {
        let e0 = self.body.reference_coordinates();
        if self.frame == SloshFrame::Tank {
            return (e0.clone(), vec![0.0; e0.len()]);
        }
        let k = self.motion.state(t0).kinematics;
        let (a, rt, w, vt) =
            (k.rotation, Vector3::from(k.position), Vector3::from(k.angular_velocity), Vector3::from(k.velocity));
        let mut q = vec![0.0; e0.len()];
        let mut v = vec![0.0; e0.len()];
        for (s, x) in e0.chunks_exact(3).enumerate() {
            let y = a * Vector3::new(x[0], x[1], x[2]);
            let (p, vel) = if s % 4 == 0 { (y + rt, w.cross(&y) + vt) } else { (y, w.cross(&y)) };
            q[3 * s..3 * s + 3].copy_from_slice(p.as_slice());
            v[3 * s..3 * s + 3].copy_from_slice(vel.as_slice());
        }
        (q, v)
    }

    fn value_index(&self, row: usize, col: usize) -> usize {
        self.layout.value_index(row, col)
    }

    /// Tank-frame gravity, linear acceleration, ω and ω̇ (tank components) at t.
    fn tank_frame_terms(&self, t: f64) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>, Vector3<f64>) {
        if let Some(input) = &self.tank_input {
            let s = input.at(t);
            return (
                Vector3::from(s.gravity),
                Vector3::from(s.acceleration),
                Vector3::from(s.angular_velocity),
                Vector3::from(s.angular_acceleration),
            );
        }
        let s = self.motion.state(t);
        let at = s.kinematics.rotation.transpose();
        (
            at * Vector3::from(self.gravity),
            at * Vector3::from(s.acceleration),
            at * Vector3::from(s.kinematics.angular_velocity),
            at * Vector3::from(s.angular_acceleration),
        )
    }

    /// In the tank-frame formulation with a rotating tank, the matrices of the rotational
    /// pseudo-accelerations −(ω̃̇ + ω̃²) r − 2 ω̃ ṙ (tank components): (ω̃̇ + ω̃², 2 ω̃).
    fn rotation_terms(&self, t: f64) -> Option<(M3, M3)> {
        if self.frame != SloshFrame::Tank {
            return None;
        }
        let (_, _, w, wd) = self.tank_frame_terms(t);
        if w.norm() == 0.0 && wd.norm() == 0.0 {
            return None;
        }
        let wx = w.cross_matrix();
        Some((wd.cross_matrix() + wx * wx, 2.0 * wx))
    }

    /// Tank-frame formulation: the power of gravity and of the pseudo-forces on the
    /// liquid, (Q_gravity + Q_pseudo)·ė (W). The Coriolis term −2 M_s⊗ω̃ ė does no work
    /// (M_s symmetric, ω̃ skew), so only −(∫ρN)⊗(g − a) and −M_s⊗(ω̃̇ + ω̃²) e count.
    /// Zero in the inertial formulation, where the walls' work is the input instead.
    pub fn frame_power(&self, t: f64, q: &[f64], v: &[f64]) -> f64 {
        if self.frame != SloshFrame::Tank {
            return 0.0;
        }
        let (g, alin, _, _) = self.tank_frame_terms(t);
        let acc = g - alin;
        let mut p: f64 = self
            .body
            .gravity_scale()
            .iter()
            .zip(v.chunks_exact(3))
            .map(|(s, vs)| s * acc.dot(&Vector3::new(vs[0], vs[1], vs[2])))
            .sum();
        if let Some((b, _)) = self.rotation_terms(t) {
            let m = self.body.scalar_mass().as_ref();
            for j in 0..m.ncols() {
                let bj = b * Vector3::new(q[3 * j], q[3 * j + 1], q[3 * j + 2]);
                for (i, val) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
                    p -= val * Vector3::new(v[3 * i], v[3 * i + 1], v[3 * i + 2]).dot(&bj);
                }
            }
        }
        p
    }

    /// The energy account of a state in the tank-frame formulation, given its stored elastic
    /// energy `stored` ([`crate::invariants::stored_energy`]): the kinetic energy of the
    /// velocities relative to the tank, no gravitational term, and [`Self::frame_power`]
    /// (gravity and pseudo-forces) as the input power. Used by tank-frame slosh runs and the
    /// co-simulation participant.
    pub fn tank_frame_energy(&self, t: f64, q: &[f64], v: &[f64], stored: f64) -> crate::invariants::EnergySample {
        crate::invariants::EnergySample {
            kinetic: self.body.kinetic_energy(v),
            potential: 0.0,
            stored,
            input_power: self.frame_power(t, q, v),
        }
    }

    /// Contact load on the tank at a state (global components in the inertial formulation,
    /// tank components in the tank-frame formulation).
    pub fn contact_load(&self, t: f64, q: &[f64], v: &[f64]) -> ContactLoad {
        let mut scratch = vec![0.0; q.len()];
        self.contact.forces(&self.body, &self.contact_kinematics(t), q, v, &mut scratch, None)
    }
}

impl MechanicalSystem for SloshSystem {
    fn n_coords(&self) -> usize {
        self.body.n_coords()
    }

    fn linear_solver(&self) -> LinearSolverKind {
        self.linear_solver
    }

    fn pattern(&self) -> SparsityPattern {
        SparsityPattern { dynamics: self.pattern.clone(), constraints: Vec::new() }
    }

    fn mass_is_constant(&self) -> bool {
        true
    }

    fn mass_entries(&self) -> Option<Vec<usize>> {
        let m = self.body.scalar_mass().as_ref();
        let mut idx = Vec::with_capacity(3 * m.compute_nnz());
        for j in 0..m.ncols() {
            for i in m.row_idx_of_col(j) {
                idx.extend((0..3).map(|k| self.value_index(3 * i + k, 3 * j + k)));
            }
        }
        Some(idx)
    }

    fn mass(&mut self, _q: &[f64], values: &mut [f64]) -> Result<(), SystemError> {
        let m = self.body.scalar_mass().as_ref();
        for j in 0..m.ncols() {
            for (i, val) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
                for k in 0..3 {
                    let idx = self.value_index(3 * i + k, 3 * j + k);
                    values[idx] += val;
                }
            }
        }
        Ok(())
    }

    /// M_s ⊗ I₃ from the scalar mass ([`FluidBody::subtract_mass_product`]), the values
    /// [`Self::mass`] writes: bit for bit the integrator's product over the pattern entries.
    fn subtract_mass_product(&self, _values: &[f64], a: &[f64], scale: f64, out: &mut [f64]) -> bool {
        self.body.subtract_mass_product(a, scale, out);
        true
    }

    fn forces(&mut self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) -> Result<(), SystemError> {
        self.body.internal_forces_with(&mut self.workspace, q, v, out).map_err(SystemError::from)?;
        out.iter_mut().for_each(|x| *x = -*x);
        let gs = self.body.gravity_scale();
        let (g, alin) = match self.frame {
            SloshFrame::Inertial => (Vector3::from(self.gravity), Vector3::zeros()),
            SloshFrame::Tank => {
                let (g, alin, _, _) = self.tank_frame_terms(t);
                (g, alin)
            }
        };
        let acc = g - alin;
        for (s, o) in gs.iter().zip(out.chunks_exact_mut(3)) {
            for i in 0..3 {
                o[i] += s * acc[i];
            }
        }
        if let Some((b, wc)) = self.rotation_terms(t) {
            let m = self.body.scalar_mass().as_ref();
            for j in 0..m.ncols() {
                let ej = Vector3::new(q[3 * j], q[3 * j + 1], q[3 * j + 2]);
                let vj = Vector3::new(v[3 * j], v[3 * j + 1], v[3 * j + 2]);
                let fj = b * ej + wc * vj;
                for (i, val) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
                    for k in 0..3 {
                        out[3 * i + k] -= val * fj[k];
                    }
                }
            }
        }
        let kin = self.contact_kinematics(t);
        self.contact.forces(&self.body, &kin, q, v, out, None);
        if let Some(i) = out.iter().position(|x| !x.is_finite()) {
            return Err(SystemError::Other(format!("non-finite generalized force at coordinate {i}")));
        }
        Ok(())
    }

    fn check_step(&mut self, t: f64, q: &[f64], v: &[f64]) -> Result<(), SystemError> {
        let load = self.contact_load(t, q, v);
        if load.max_penetration > self.penetration_limit {
            return Err(SystemError::Penetration {
                contact: format!("fluid-wall contact ({} points active)", load.active),
                depth: load.max_penetration,
                limit: self.penetration_limit,
            });
        }
        let volume = self.body.volume(q);
        let error = (volume / self.reference_volume - 1.0).abs();
        if error.is_nan() || error > self.volume_tolerance {
            return Err(SystemError::VolumeError {
                what: "fluid".into(),
                volume,
                reference: self.reference_volume,
                limit: self.volume_tolerance,
            });
        }
        // the state invariants (containment of nodes, contact points and centre of mass;
        // element validity) for every run kind built on this system: slosh runs, the
        // co-simulation participant and the FMU
        let limits = crate::invariants::InvariantLimits::new(self.penetration_limit);
        let kin = self.contact_kinematics(t);
        let measured = crate::invariants::check_state(|| "fluid".into(), &self.body, &self.contact, &kin, q, &limits)
            .map_err(|(error, _, _)| error)?;
        self.last_state_check = Some(StateCheck { t, q_bits: state_bits(q), measured });
        Ok(())
    }

    fn force_jacobians(
        &mut self,
        t: f64,
        q: &[f64],
        v: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
    ) -> Result<(), SystemError> {
        self.layout.subtract_element_jacobians(&self.body, q, v, dq, dv, &mut self.jacobians)?;
        if let Some((b, wc)) = self.rotation_terms(t) {
            let m = self.body.scalar_mass().as_ref();
            for j in 0..m.ncols() {
                for (i, val) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
                    for r in 0..3 {
                        for c in 0..3 {
                            let idx = self.value_index(3 * i + r, 3 * j + c);
                            dq[idx] -= val * b[(r, c)];
                            dv[idx] -= val * wc[(r, c)];
                        }
                    }
                }
            }
        }
        let kin = self.contact_kinematics(t);
        let mut scratch = vec![0.0; q.len()];
        let mut pj = std::mem::take(&mut self.point_jac);
        self.contact.forces(&self.body, &kin, q, v, &mut scratch, Some(&mut pj));
        for p in &pj {
            let pt = &self.contact.points[p.point];
            let eb = &self.layout.element_blocks[pt.element];
            for a in 0..N_SHAPE {
                for b in 0..N_SHAPE {
                    let nn = pt.shape[a] * pt.shape[b];
                    if nn == 0.0 {
                        continue;
                    }
                    for i in 0..3 {
                        for k in 0..3 {
                            let idx = FluidBlocks::element_index(eb, a, i, b, k);
                            dq[idx] += nn * p.d_position[(i, k)];
                            dv[idx] += nn * p.d_velocity[(i, k)];
                        }
                    }
                }
            }
        }
        self.point_jac = pj;
        Ok(())
    }
}

/// The state invariants measured by the last passed [`SloshSystem::check_step`]: the time, a
/// fingerprint of the coordinates and (containment gap, smallest volume ratio).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct StateCheck {
    pub(crate) t: f64,
    pub(crate) q_bits: u64,
    pub(crate) measured: (f64, f64),
}

/// A fingerprint of the exact bits of `q` (FNV-1a over every value), so that a cached
/// measurement is used only for the very state it measured.
pub(crate) fn state_bits(q: &[f64]) -> u64 {
    q.iter().fold(0xcbf2_9ce4_8422_2325_u64, |h, x| (h ^ x.to_bits()).wrapping_mul(0x0100_0000_01b3))
}
