//! [`Multibody`]: rigid bodies, joints, force elements and wheel/rail contacts
//! assembled into one [`MechanicalSystem`] for the HHT integrator.
//!
//! # Coordinates
//!
//! Body `b` owns coordinates `7b..7b+7` = `[x, y, z, e0, e1, e2, e3]`. Constraints are
//! ordered: one Euler-parameter normalization per body (`pᵀp − 1`), then the joint
//! equations in the order the joints were added.
//!
//! # Jacobians
//!
//! Constraint Jacobians are analytic ([`Joint::evaluate`]). Force Jacobians
//! `∂Q/∂q`, `∂Q/∂v` of bodies (gyroscopic terms) and force elements are computed by
//! central finite differences over the coordinates of the one or two bodies an element
//! touches (14 columns at most); wheel/rail contacts, whose evaluation includes a profile
//! scan, use forward differences. The constraint-force stiffness `∂(C_qᵀλ)/∂q` is
//! provided (central differences of the analytic `C_q` per joint; exact `2λI` for the
//! normalization), so Newton converges quadratically on joint-dominated problems.

use std::collections::HashMap;

use nalgebra::{Matrix3, Vector3};

use super::body::{Attachment, BodyId, BodyState, RigidBody};
use super::force::{ForceElement, Wrench};
use super::joint::{Joint, JointKind};
use super::wheelset::{WheelsetContact, WheelsetReport};
use crate::integrator::{KktIndex, MechanicalSystem, SparsityPattern, SystemError};
use crate::wheel_rail::ContactError;
use ancf_core::error::{AncfError, invalid};

/// Finite-difference step for coordinates (m, or Euler-parameter units).
const FD_Q: f64 = 1e-7;
/// Finite-difference step for velocities (m/s).
const FD_V: f64 = 1e-6;

/// A multibody system of rigid bodies.
#[derive(Debug, Default)]
pub struct Multibody {
    /// Gravitational acceleration, m/s² (global). Default `(0, 0, −9.80665)`.
    pub gravity: Vector3<f64>,
    bodies: Vec<RigidBody>,
    joints: Vec<Joint>,
    forces: Vec<Box<dyn ForceElement>>,
    wheelsets: Vec<WheelsetContact>,
    layout: Option<std::sync::Arc<Layout>>,
    /// Reusable buffers of the callbacks (no allocation per call once sized).
    scratch: Scratch,
}

/// Buffers reused by the [`MechanicalSystem`] callbacks of [`Multibody`].
#[derive(Debug, Default)]
struct Scratch {
    /// All zeros, length `n` (velocities of the constraint evaluations).
    zeros: Vec<f64>,
    /// Perturbed coordinates and velocities of the finite differences.
    q: Vec<f64>,
    v: Vec<f64>,
}

impl Scratch {
    /// `zeros` resized to `n` (stays all zeros: it is never written).
    fn zeros(&mut self, n: usize) {
        self.zeros.resize(n, 0.0);
    }

    /// Copies of `q` and `v` to perturb, taken out of the scratch (give them back with
    /// [`Self::put`]).
    fn take(&mut self, q: &[f64], v: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let (mut qq, mut vv) = (std::mem::take(&mut self.q), std::mem::take(&mut self.v));
        qq.clear();
        qq.extend_from_slice(q);
        vv.clear();
        vv.extend_from_slice(v);
        (qq, vv)
    }

    fn put(&mut self, (q, v): (Vec<f64>, Vec<f64>)) {
        self.q = q;
        self.v = v;
    }
}

#[derive(Debug, Clone)]
struct Layout {
    /// Pattern index of block (a, b) of bodies a, b (49 entries, row-major).
    blocks: HashMap<(usize, usize), usize>,
    /// First constraint-pattern index of each joint.
    joint_entries: Vec<usize>,
    /// First constraint row of each joint.
    joint_rows: Vec<usize>,
}

/// Coordinates of an attachment in the global vector, if it is a body.
fn coords(a: Attachment) -> Option<usize> {
    a.map(|b| 7 * b.0)
}

impl Multibody {
    /// An empty system with standard gravity.
    pub fn new() -> Self {
        Self { gravity: Vector3::new(0.0, 0.0, -crate::track::GRAVITY), ..Default::default() }
    }

    /// Adds a body (checked) and returns its id.
    pub fn add_body(&mut self, body: RigidBody) -> Result<BodyId, AncfError> {
        body.validate()?;
        self.bodies.push(body);
        self.layout = None;
        Ok(BodyId(self.bodies.len() - 1))
    }

    fn check_attachment(&self, a: Attachment, what: &str) -> Result<(), AncfError> {
        match a {
            Some(b) if b.0 >= self.bodies.len() => {
                Err(invalid(what, b.0, &format!("a body id below {}", self.bodies.len())))
            }
            _ => Ok(()),
        }
    }

    /// Initial state of an attachment.
    pub fn initial_state(&self, a: Attachment) -> BodyState {
        match a {
            None => BodyState::ground(),
            Some(b) => {
                let (q, v) = self.bodies[b.0].initial_coordinates();
                BodyState::from_coordinates(&q, &v)
            }
        }
    }

    /// Adds a joint between `i` and `j` at the global point `at` with global joint axes
    /// `axes` (columns; for a revolute joint the pin is the third column), computing the
    /// body-fixed points and frames from the bodies' initial poses.
    pub fn add_joint(
        &mut self,
        name: &str,
        kind: JointKind,
        i: Attachment,
        j: Attachment,
        at: Vector3<f64>,
        axes: Matrix3<f64>,
    ) -> Result<usize, AncfError> {
        self.check_attachment(i, &format!("joint '{name}' body_i"))?;
        self.check_attachment(j, &format!("joint '{name}' body_j"))?;
        if i.is_none() && j.is_none() || i == j {
            return Err(invalid(&format!("joint '{name}' bodies"), format!("{i:?}, {j:?}"), "two different bodies"));
        }
        if matches!(kind, JointKind::Trajectory(_)) && (i.is_none() || j.is_some()) {
            return Err(invalid(
                &format!("joint '{name}' bodies"),
                format!("{i:?}, {j:?}"),
                "body_i a body, body_j ground",
            ));
        }
        let (si, sj) = (self.initial_state(i), self.initial_state(j));
        let joint = Joint {
            name: name.to_string(),
            body_i: i,
            body_j: j,
            point_i: si.rotation.transpose() * (at - si.position),
            point_j: sj.rotation.transpose() * (at - sj.position),
            frame_i: si.rotation.transpose() * axes,
            frame_j: sj.rotation.transpose() * axes,
            kind,
        };
        self.joints.push(joint);
        self.layout = None;
        Ok(self.joints.len() - 1)
    }

    /// Adds a force element.
    pub fn add_force(&mut self, element: Box<dyn ForceElement>) -> Result<usize, AncfError> {
        for (k, b) in element.bodies().iter().enumerate() {
            self.check_attachment(*b, &format!("force '{}' body {k}", element.name()))?;
        }
        self.forces.push(element);
        self.layout = None;
        Ok(self.forces.len() - 1)
    }

    /// Adds a wheelset's wheel/rail contact.
    pub fn add_wheelset_contact(&mut self, contact: WheelsetContact) -> Result<usize, AncfError> {
        self.check_attachment(Some(contact.body), &format!("wheelset contact '{}' body", contact.name))?;
        self.wheelsets.push(contact);
        Ok(self.wheelsets.len() - 1)
    }

    /// Moves a body's initial position by `delta` (m, global), e.g. to apply an initial
    /// disturbance. Joints and force elements added before keep their body-fixed points,
    /// so the move must respect the joints (bushings take it up as a deflection).
    pub fn displace_body(&mut self, id: BodyId, delta: Vector3<f64>) -> Result<(), AncfError> {
        let b = self.bodies.get_mut(id.0).ok_or_else(|| invalid("body id", id.0, "an existing body"))?;
        b.position += delta;
        Ok(())
    }

    /// Pattern index of the first entry of body `id`'s own 7×7 block (row-major), for
    /// systems that embed this one with its pattern first.
    pub fn body_block_index(&mut self, id: BodyId) -> usize {
        self.layout().blocks[&(id.0, id.0)]
    }

    /// Bodies.
    pub fn bodies(&self) -> &[RigidBody] {
        &self.bodies
    }
    /// Joints.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }
    /// Force elements.
    pub fn forces(&self) -> &[Box<dyn ForceElement>] {
        &self.forces
    }
    /// Wheelset contacts.
    pub fn wheelsets(&self) -> &[WheelsetContact] {
        &self.wheelsets
    }

    /// Degrees of freedom: 6 per body minus the joint equations.
    pub fn dof(&self) -> isize {
        6 * self.bodies.len() as isize - self.joints.iter().map(|j| j.n_equations() as isize).sum::<isize>()
    }

    /// Initial coordinates and velocities of all bodies.
    pub fn initial_coordinates(&self) -> (Vec<f64>, Vec<f64>) {
        let mut q = Vec::with_capacity(7 * self.bodies.len());
        let mut v = Vec::with_capacity(7 * self.bodies.len());
        for b in &self.bodies {
            let (bq, bv) = b.initial_coordinates();
            q.extend_from_slice(&bq);
            v.extend_from_slice(&bv);
        }
        (q, v)
    }

    /// State of an attachment at `(q, v)`.
    pub fn state(&self, a: Attachment, q: &[f64], v: &[f64]) -> BodyState {
        match coords(a) {
            None => BodyState::ground(),
            Some(o) => BodyState::from_coordinates(&q[o..o + 7], &v[o..o + 7]),
        }
    }

    /// Scalar outputs of all force elements (see [`ForceElement::output`]).
    pub fn force_outputs(&self, t: f64, q: &[f64], v: &[f64]) -> Vec<f64> {
        self.forces
            .iter()
            .map(|f| {
                let [a, b] = f.bodies();
                f.output(t, &self.state(a, q, v), &self.state(b, q, v))
            })
            .collect()
    }

    /// Contact points of every wheelset at `(q, v)`; the contact searches' warm starts are
    /// left as they were ([`crate::mbs::WheelsetContact::evaluate`]).
    pub fn wheelset_reports(&mut self, q: &[f64], v: &[f64]) -> Result<Vec<WheelsetReport>, SystemError> {
        let mut out = Vec::with_capacity(self.wheelsets.len());
        for k in 0..self.wheelsets.len() {
            let s = self.state(Some(self.wheelsets[k].body), q, v);
            let w = &mut self.wheelsets[k];
            out.push(w.evaluate(&s).map_err(|e| SystemError::Other(format!("wheelset contact '{}': {e}", w.name)))?);
        }
        Ok(out)
    }

    fn build_layout(&self) -> (SparsityPattern, Layout) {
        let nb = self.bodies.len();
        let mut pat = SparsityPattern::default();
        let mut blocks = HashMap::new();
        let mut add_block = |pat: &mut SparsityPattern, a: usize, b: usize| {
            if let std::collections::hash_map::Entry::Vacant(e) = blocks.entry((a, b)) {
                e.insert(pat.dynamics.len());
                for r in 0..7 {
                    for c in 0..7 {
                        pat.dynamics.push((7 * a + r, 7 * b + c));
                    }
                }
            }
        };
        for b in 0..nb {
            add_block(&mut pat, b, b);
        }
        for f in &self.forces {
            if let [Some(a), Some(b)] = f.bodies()
                && a != b
            {
                add_block(&mut pat, a.0, b.0);
                add_block(&mut pat, b.0, a.0);
            }
        }
        // Joints couple their bodies through the constraint-force stiffness.
        for j in &self.joints {
            if let (Some(a), Some(b)) = (j.body_i, j.body_j) {
                add_block(&mut pat, a.0, b.0);
                add_block(&mut pat, b.0, a.0);
            }
        }
        for b in 0..nb {
            for k in 0..4 {
                pat.constraints.push((b, 7 * b + 3 + k));
            }
        }
        let mut joint_entries = Vec::new();
        let mut joint_rows = Vec::new();
        let mut row = nb;
        for j in &self.joints {
            joint_entries.push(pat.constraints.len());
            joint_rows.push(row);
            for e in 0..j.n_equations() {
                for o in [coords(j.body_i), coords(j.body_j)].into_iter().flatten() {
                    for c in 0..7 {
                        pat.constraints.push((row + e, o + c));
                    }
                }
            }
            row += j.n_equations();
        }
        (pat, Layout { blocks, joint_entries, joint_rows })
    }

    /// The index layout (built once, shared cheaply with the callbacks).
    fn layout(&mut self) -> std::sync::Arc<Layout> {
        if self.layout.is_none() {
            self.layout = Some(std::sync::Arc::new(self.build_layout().1));
        }
        self.layout.clone().expect("layout just built")
    }

    /// Generalized forces of element `e` on the coordinates of its two bodies (14).
    fn element_forces(&self, e: usize, t: f64, q: &[f64], v: &[f64]) -> [f64; 14] {
        let f = &self.forces[e];
        let [a, b] = f.bodies();
        let (sa, sb) = (self.state(a, q, v), self.state(b, q, v));
        let [wa, wb] = f.wrenches(t, &sa, &sb);
        let ga = sa.generalized(&wa.force, &wa.moment);
        let gb = sb.generalized(&wb.force, &wb.moment);
        let mut out = [0.0; 14];
        out[..7].copy_from_slice(&ga);
        out[7..].copy_from_slice(&gb);
        out
    }

    fn wheelset_forces(&mut self, k: usize, q: &[f64], v: &[f64]) -> Result<[f64; 7], SystemError> {
        self.wheelset_forces_with(k, q, v, WheelsetContact::wrench)
    }

    /// [`Self::wheelset_forces`] with the contact evaluated by `wrench` (the full search, or
    /// the warm-started one of a Jacobian column, [`WheelsetContact::wrench_perturbed`]).
    fn wheelset_forces_with(
        &mut self,
        k: usize,
        q: &[f64],
        v: &[f64],
        wrench: fn(&mut WheelsetContact, &BodyState) -> Result<Wrench, ContactError>,
    ) -> Result<[f64; 7], SystemError> {
        let s = self.state(Some(self.wheelsets[k].body), q, v);
        let w = &mut self.wheelsets[k];
        let wr: Wrench =
            wrench(w, &s).map_err(|e| SystemError::Other(format!("wheelset contact '{}': {e}", w.name)))?;
        Ok(s.generalized(&wr.force, &wr.moment))
    }

    /// Forward-difference Jacobians of the wheel/rail contact wrenches (each evaluation
    /// scans the profiles), scattered into `dq`, `dv`. `qq`, `vv` hold copies of `q`, `v`.
    fn wheelset_jacobians(
        &mut self,
        q: &[f64],
        v: &[f64],
        (qq, vv): (&mut [f64], &mut [f64]),
        layout: &Layout,
        dq: &mut [f64],
        dv: &mut [f64],
    ) -> Result<(), SystemError> {
        let mut jq = [[0.0; 14]; 14];
        let mut jv = [[0.0; 14]; 14];
        for k in 0..self.wheelsets.len() {
            let b = self.wheelsets[k].body.0;
            // the full search at (q, v); the columns warm-start from its points
            let f0 = self.wheelset_forces(k, q, v)?;
            let perturbed = WheelsetContact::wrench_perturbed;
            for c in 0..7 {
                let g = 7 * b + c;
                qq[g] = q[g] + FD_Q;
                let fp = self.wheelset_forces_with(k, qq, vv, perturbed)?;
                qq[g] = q[g];
                vv[g] = v[g] + FD_V;
                let gp = self.wheelset_forces_with(k, qq, vv, perturbed)?;
                vv[g] = v[g];
                for r in 0..7 {
                    jq[r][c] = (fp[r] - f0[r]) / FD_Q;
                    jv[r][c] = (gp[r] - f0[r]) / FD_V;
                }
            }
            scatter(layout, [Some(b), None], &jq, dq);
            scatter(layout, [Some(b), None], &jv, dv);
        }
        Ok(())
    }
}

/// Scatters a dense local block (rows/cols of up to two bodies) into pattern values.
fn scatter(layout: &Layout, bodies: [Option<usize>; 2], local: &[[f64; 14]; 14], out: &mut [f64]) {
    for (sa, ba) in bodies.iter().enumerate() {
        let Some(ba) = ba else { continue };
        for (sb, bb) in bodies.iter().enumerate() {
            let Some(bb) = bb else { continue };
            let base = layout.blocks[&(*ba, *bb)];
            for r in 0..7 {
                for c in 0..7 {
                    out[base + 7 * r + c] += local[7 * sa + r][7 * sb + c];
                }
            }
        }
    }
}

impl MechanicalSystem for Multibody {
    fn n_coords(&self) -> usize {
        7 * self.bodies.len()
    }

    /// The wheel/rail searches' warm starts, wheelset by wheelset, left then right.
    fn save_internal_state(&self, out: &mut Vec<f64>) {
        for w in &self.wheelsets {
            for c in &w.wheels {
                c.save_warm_start(out);
            }
        }
    }

    fn restore_internal_state(&mut self, data: &mut &[f64]) -> Option<()> {
        for w in &mut self.wheelsets {
            for c in &mut w.wheels {
                c.restore_warm_start(data)?;
            }
        }
        Some(())
    }

    fn n_constraints(&self) -> usize {
        self.bodies.len() + self.joints.iter().map(|j| j.n_equations()).sum::<usize>()
    }

    fn describe_unknown(&self, index: KktIndex) -> String {
        const COMPONENTS: [&str; 7] = ["x", "y", "z", "e0", "e1", "e2", "e3"];
        match index {
            KktIndex::Coordinate(i) if i < 7 * self.bodies.len() => {
                format!("coordinate {i} = {} of body '{}'", COMPONENTS[i % 7], self.bodies[i / 7].name)
            }
            KktIndex::Constraint(k) if k < self.bodies.len() => {
                format!("constraint {k} = Euler-parameter normalization of body '{}'", self.bodies[k].name)
            }
            KktIndex::Constraint(k) => {
                // joint rows follow the normalization rows, in joint order (see `build_layout`)
                let mut row = self.bodies.len();
                for j in &self.joints {
                    if k < row + j.n_equations() {
                        return format!("constraint {k} = equation {} of joint '{}'", k - row, j.name);
                    }
                    row += j.n_equations();
                }
                index.to_string()
            }
            KktIndex::Coordinate(_) => index.to_string(),
        }
    }

    fn pattern(&self) -> SparsityPattern {
        self.build_layout().0
    }

    fn mass_entries(&self) -> Option<Vec<usize>> {
        let layout = self.layout.clone().unwrap_or_else(|| std::sync::Arc::new(self.build_layout().1));
        Some(
            (0..self.bodies.len())
                .flat_map(|b| (0..49).map(|k| layout.blocks[&(b, b)] + k).collect::<Vec<_>>())
                .collect(),
        )
    }

    fn mass(&mut self, q: &[f64], values: &mut [f64]) -> Result<(), SystemError> {
        let layout = self.layout();
        for (b, body) in self.bodies.iter().enumerate() {
            let m = body.mass_block(&q[7 * b..7 * b + 7]);
            let base = layout.blocks[&(b, b)];
            for r in 0..7 {
                for c in 0..7 {
                    values[base + 7 * r + c] = m[r][c];
                }
            }
        }
        Ok(())
    }

    fn forces(&mut self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) -> Result<(), SystemError> {
        out.fill(0.0);
        for (b, body) in self.bodies.iter().enumerate() {
            let o = 7 * b;
            let f = body.inertial_forces(&q[o..o + 7], &v[o..o + 7], &self.gravity);
            for k in 0..7 {
                out[o + k] += f[k];
            }
        }
        for e in 0..self.forces.len() {
            let g = self.element_forces(e, t, q, v);
            for (side, a) in self.forces[e].bodies().iter().enumerate() {
                if let Some(o) = coords(*a) {
                    for k in 0..7 {
                        out[o + k] += g[7 * side + k];
                    }
                }
            }
        }
        for k in 0..self.wheelsets.len() {
            let g = self.wheelset_forces(k, q, v)?;
            let o = 7 * self.wheelsets[k].body.0;
            for i in 0..7 {
                out[o + i] += g[i];
            }
        }
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
        let layout = self.layout();
        let mut jq = [[0.0; 14]; 14];
        let mut jv = [[0.0; 14]; 14];
        let clear = |j: &mut [[f64; 14]; 14]| j.iter_mut().for_each(|r| r.fill(0.0));
        // Bodies: gravity and gyroscopic terms (central differences).
        for (b, body) in self.bodies.iter().enumerate() {
            let o = 7 * b;
            let (mut qb, mut vb) = ([0.0; 7], [0.0; 7]);
            qb.copy_from_slice(&q[o..o + 7]);
            vb.copy_from_slice(&v[o..o + 7]);
            clear(&mut jq);
            clear(&mut jv);
            for c in 0..7 {
                let x0 = qb[c];
                qb[c] = x0 + FD_Q;
                let fp = body.inertial_forces(&qb, &vb, &self.gravity);
                qb[c] = x0 - FD_Q;
                let fm = body.inertial_forces(&qb, &vb, &self.gravity);
                qb[c] = x0;
                let x0 = vb[c];
                vb[c] = x0 + FD_V;
                let gp = body.inertial_forces(&qb, &vb, &self.gravity);
                vb[c] = x0 - FD_V;
                let gm = body.inertial_forces(&qb, &vb, &self.gravity);
                vb[c] = x0;
                for r in 0..7 {
                    jq[r][c] = (fp[r] - fm[r]) / (2.0 * FD_Q);
                    jv[r][c] = (gp[r] - gm[r]) / (2.0 * FD_V);
                }
            }
            scatter(&layout, [Some(b), None], &jq, dq);
            scatter(&layout, [Some(b), None], &jv, dv);
        }
        // Force elements (central differences over the coordinates of their bodies).
        let (mut qq, mut vv) = self.scratch.take(q, v);
        for e in 0..self.forces.len() {
            let bodies = self.forces[e].bodies().map(|a| a.map(|b| b.0));
            clear(&mut jq);
            clear(&mut jv);
            for (side, b) in bodies.iter().enumerate() {
                let Some(b) = b else { continue };
                for c in 0..7 {
                    let g = 7 * b + c;
                    let col = 7 * side + c;
                    qq[g] = q[g] + FD_Q;
                    let fp = self.element_forces(e, t, &qq, &vv);
                    qq[g] = q[g] - FD_Q;
                    let fm = self.element_forces(e, t, &qq, &vv);
                    qq[g] = q[g];
                    vv[g] = v[g] + FD_V;
                    let gp = self.element_forces(e, t, &qq, &vv);
                    vv[g] = v[g] - FD_V;
                    let gm = self.element_forces(e, t, &qq, &vv);
                    vv[g] = v[g];
                    for r in 0..14 {
                        jq[r][col] = (fp[r] - fm[r]) / (2.0 * FD_Q);
                        jv[r][col] = (gp[r] - gm[r]) / (2.0 * FD_V);
                    }
                }
            }
            scatter(&layout, bodies, &jq, dq);
            scatter(&layout, bodies, &jv, dv);
        }
        // Wheel/rail contacts (forward differences: each evaluation scans the profiles).
        let result = self.wheelset_jacobians(q, v, (&mut qq, &mut vv), &layout, dq, dv);
        self.scratch.put((qq, vv));
        result
    }

    fn constraints(&mut self, t: f64, q: &[f64], out: &mut [f64]) -> Result<(), SystemError> {
        let layout = self.layout();
        self.scratch.zeros(q.len());
        let zeros = &self.scratch.zeros;
        for b in 0..self.bodies.len() {
            let p = &q[7 * b + 3..7 * b + 7];
            out[b] = p.iter().map(|x| x * x).sum::<f64>() - 1.0;
        }
        for (k, j) in self.joints.iter().enumerate() {
            let (si, sj) = (self.state(j.body_i, q, zeros), self.state(j.body_j, q, zeros));
            let r = layout.joint_rows[k];
            j.evaluate(t, &si, &sj, &mut out[r..r + j.n_equations()], None);
        }
        Ok(())
    }

    fn constraint_jacobian(&mut self, t: f64, q: &[f64], values: &mut [f64]) -> Result<(), SystemError> {
        let layout = self.layout();
        self.scratch.zeros(q.len());
        let zeros = &self.scratch.zeros;
        for b in 0..self.bodies.len() {
            for k in 0..4 {
                values[4 * b + k] = 2.0 * q[7 * b + 3 + k];
            }
        }
        let mut c = [0.0; 6];
        let mut jac = [[0.0; 14]; 6];
        for (k, j) in self.joints.iter().enumerate() {
            let (si, sj) = (self.state(j.body_i, q, zeros), self.state(j.body_j, q, zeros));
            let n = j.n_equations();
            j.evaluate(t, &si, &sj, &mut c[..n], Some(&mut jac[..n]));
            let mut idx = layout.joint_entries[k];
            for row in jac.iter().take(n) {
                for (side, a) in [j.body_i, j.body_j].iter().enumerate() {
                    if a.is_some() {
                        values[idx..idx + 7].copy_from_slice(&row[7 * side..7 * side + 7]);
                        idx += 7;
                    }
                }
            }
        }
        Ok(())
    }

    fn constraint_force_jacobian(
        &mut self,
        t: f64,
        q: &[f64],
        lambda: &[f64],
        dq: &mut [f64],
    ) -> Result<bool, SystemError> {
        let layout = self.layout();
        self.scratch.zeros(q.len());
        // Normalization: ∂(2 p λ)/∂p = 2 λ I.
        for (b, lam) in lambda.iter().enumerate().take(self.bodies.len()) {
            let base = layout.blocks[&(b, b)];
            for k in 3..7 {
                dq[base + 7 * k + k] += 2.0 * lam;
            }
        }
        let (mut qq, vv) = self.scratch.take(q, &[]);
        let zeros = &self.scratch.zeros;
        let mut c = [0.0; 6];
        let mut jp = [[0.0; 14]; 6];
        let mut jm = [[0.0; 14]; 6];
        let mut local = [[0.0; 14]; 14];
        for (k, j) in self.joints.iter().enumerate() {
            let n = j.n_equations();
            let lam = &lambda[layout.joint_rows[k]..layout.joint_rows[k] + n];
            let bodies = [j.body_i.map(|b| b.0), j.body_j.map(|b| b.0)];
            local.iter_mut().for_each(|r| r.fill(0.0));
            for (side, b) in bodies.iter().enumerate() {
                let Some(b) = b else { continue };
                for cc in 0..7 {
                    let g = 7 * b + cc;
                    qq[g] = q[g] + FD_Q;
                    j.evaluate(
                        t,
                        &self.state(j.body_i, &qq, zeros),
                        &self.state(j.body_j, &qq, zeros),
                        &mut c,
                        Some(&mut jp[..n]),
                    );
                    qq[g] = q[g] - FD_Q;
                    j.evaluate(
                        t,
                        &self.state(j.body_i, &qq, zeros),
                        &self.state(j.body_j, &qq, zeros),
                        &mut c,
                        Some(&mut jm[..n]),
                    );
                    qq[g] = q[g];
                    for r in 0..14 {
                        let d: f64 = (0..n).map(|e| (jp[e][r] - jm[e][r]) * lam[e]).sum();
                        local[r][7 * side + cc] = d / (2.0 * FD_Q);
                    }
                }
            }
            scatter(&layout, bodies, &local, dq);
        }
        self.scratch.put((qq, vv));
        Ok(true)
    }
}
