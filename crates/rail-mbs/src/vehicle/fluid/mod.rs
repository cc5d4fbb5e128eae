//! ANCF fluid bodies inside the tanks of a multibody vehicle, solved in one implicit
//! (monolithic) system with the rigid bodies ([`FluidVehicle`]).
//!
//! Coordinates: the rigid bodies of the [`Multibody`] first (`7` per body), then the
//! nodal coordinates of each fluid body (global frame). Each fluid touches its tank body
//! only through the penalty wall/bulkhead contact of seed 000 §5: the contact forces act
//! on the fluid, and the equal and opposite load (force, and moment about the tank body
//! origin) acts on the tank body (`Q_CB^t`). The tank frame of the fluid mesh and
//! contact geometry is the tank body frame (origin at the tank body's centre of mass,
//! which must be the tank's geometric centre; no rigid lading on fluid-carrying tanks).
//!
//! # Jacobians
//!
//! * fluid–fluid: exact element Jacobians and contact point Jacobians (as in
//!   [`crate::slosh::SloshSystem`]);
//! * tank rows × fluid columns: exact, from the point Jacobians, forces and arms:
//!   `∂Q_R/∂r_k = −K_k`, `∂M/∂r_k = F̃_k − d̃_k K_k`, `∂M/∂ṙ_k = −d̃_k C_k`, mapped to the
//!   Euler parameters by `2 Eᵀ`;
//! * fluid rows and the tank block × tank columns: forward finite differences over the
//!   tank's 14 coordinates and velocities (one contact pass each).
//!
//! The coupling blocks are what keeps Newton convergent when the tank is light compared
//! with its fluid (the added-mass instability of explicit coupling, seed 003).

use ancf_core::FluidBody;
use ancf_core::body::{ElementJacobian, ForceWorkspace};
use ancf_core::contact::{PointJacobian, TankKinematics, WallContact};
use ancf_core::error::AncfError;
use ancf_core::shape::N_SHAPE;
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;

use crate::fluid_blocks::FluidBlocks;
use crate::integrator::{KktIndex, LinearSolverKind, MechanicalSystem, SparsityPattern, SystemError};
use crate::invariants::{
    EnergySample, InvariantLimits, InvariantMonitor, Margins, Pending, check_state, stored_energy, wall_power,
};
use crate::mbs::{BodyId, BodyState, Multibody};

/// Finite-difference steps for the tank coordinates and velocities.
const FD_Q: f64 = 1e-7;
const FD_V: f64 = 1e-6;

/// One fluid body in one tank.
#[derive(Debug, Clone)]
pub struct TankFluid {
    /// The tank (car body) it is in.
    pub tank: BodyId,
    /// The fluid.
    pub body: FluidBody,
    /// Wall and bulkhead contact with the tank.
    pub contact: WallContact,
}

#[derive(Debug, Clone, Default)]
struct FluidLayout {
    /// First global coordinate of the fluid.
    offset: usize,
    /// The fluid's node-pair blocks.
    blocks: FluidBlocks,
    /// Pattern start of the 7 × n_f tank-rows block (row-major) and of the n_f × 7
    /// fluid-rows block (row-major).
    tank_rows: usize,
    fluid_rows: usize,
    /// (pattern index, value) of every fluid mass-matrix entry (constant).
    mass_entries: Vec<(usize, f64)>,
}

/// Rigid multibody vehicle plus fluids in its tanks.
#[derive(Debug)]
pub struct FluidVehicle {
    /// The rigid multibody system.
    pub mb: Multibody,
    /// The fluids.
    pub fluids: Vec<TankFluid>,
    /// How the Newton matrix is solved: [`LinearSolverKind::Condensed`] (default; each fluid
    /// factored on its own, the rest through the Schur complement) or
    /// [`LinearSolverKind::Direct`] (one LU of the whole matrix); read when the integrator is
    /// built. Both solve the same equations (docs/benchmarks.md).
    pub linear_solver: LinearSolverKind,
    layouts: Vec<FluidLayout>,
    mb_entries: usize,
    /// The rigid bodies' mass entries (row, column, pattern index), sorted by row and column.
    rigid_mass: Vec<(u32, u32, u32)>,
    n_rigid: usize,
    point_jac: Vec<PointJacobian>,
    /// Force buffers of each fluid (no allocation per force evaluation).
    workspaces: Vec<ForceWorkspace>,
    /// Element Jacobians (buffer reused by every fluid).
    jacobians: Vec<ElementJacobian>,
    /// Contact-force buffers of the step check and the finite differences (fluid length;
    /// zeroed before each use: the contact adds into them).
    scratch: [Vec<f64>; 2],
    /// The run-time invariants of each fluid: containment, element validity and energy
    /// balance (issue 16), accounted over the accepted steps.
    monitors: Vec<InvariantMonitor>,
    /// Each fluid's assessed state in the step being checked (committed once all pass).
    pending: Vec<Option<Pending>>,
}

/// Tank kinematics for the contact from a body state.
pub fn tank_kinematics(s: &BodyState) -> TankKinematics {
    TankKinematics {
        position: s.position.into(),
        rotation: s.rotation,
        velocity: s.velocity.into(),
        angular_velocity: s.angular_velocity.into(),
    }
}

impl FluidVehicle {
    /// Assembles the coupled system and its fixed sparsity pattern.
    pub fn new(mb: Multibody, fluids: Vec<TankFluid>) -> Result<Self, AncfError> {
        let n_rigid = mb.n_coords();
        for f in &fluids {
            if f.tank.0 >= mb.bodies().len() {
                return Err(ancf_core::error::invalid("fluid tank body", f.tank.0, "an existing body"));
            }
        }
        let mb_pattern = mb.pattern().dynamics;
        let mb_entries = mb_pattern.len();
        let mut rigid_mass: Vec<(u32, u32, u32)> = mb
            .mass_entries()
            .unwrap_or_else(|| (0..mb_entries).collect())
            .into_iter()
            .map(|k| (mb_pattern[k].0 as u32, mb_pattern[k].1 as u32, k as u32))
            .collect();
        rigid_mass.sort_unstable();
        rigid_mass.dedup();
        let workspaces = vec![ForceWorkspace::default(); fluids.len()];
        let mut s = Self {
            mb,
            fluids,
            linear_solver: LinearSolverKind::Condensed,
            layouts: Vec::new(),
            mb_entries,
            rigid_mass,
            n_rigid,
            point_jac: Vec::new(),
            workspaces,
            jacobians: Vec::new(),
            scratch: Default::default(),
            monitors: Vec::new(),
            pending: Vec::new(),
        };
        let g = s.mb.gravity.norm();
        s.monitors = (0..s.fluids.len())
            .map(|k| {
                let body = &s.fluids[k].body;
                let depth = body.mesh.liquid_depth();
                let limits = InvariantLimits::new(s.penetration_limit(k));
                InvariantMonitor::new(format!("fluid {k}"), limits, body.total_mass(), g, depth.max(0.0))
            })
            .collect();
        s.pending = vec![None; s.fluids.len()];
        let (_, layouts) = s.build_pattern();
        s.layouts = layouts;
        Ok(s)
    }

    /// Worst invariant margins over every fluid and accepted step so far.
    pub fn margins(&self) -> Margins {
        self.monitors.iter().map(|m| m.margins()).fold(Margins::default(), Margins::worst)
    }

    /// Largest admissible penetration of fluid `k` (m): [`PENETRATION_LIMIT_FACTOR`] × its
    /// smallest element edge, as in `SloshSystem`.
    ///
    /// [`PENETRATION_LIMIT_FACTOR`]: crate::fluid_blocks::PENETRATION_LIMIT_FACTOR
    fn penetration_limit(&self, k: usize) -> f64 {
        crate::fluid_blocks::default_penetration_limit(&self.fluids[k].body)
    }

    fn build_pattern(&self) -> (SparsityPattern, Vec<FluidLayout>) {
        let mut pat = self.mb.pattern();
        let mut layouts = Vec::new();
        let mut offset = self.n_rigid;
        for f in &self.fluids {
            let blocks = FluidBlocks::append(&f.body, offset, &mut pat.dynamics);
            let mut lay = FluidLayout { offset, blocks, ..Default::default() };
            let nf = f.body.n_coords();
            let t0 = 7 * f.tank.0;
            lay.tank_rows = pat.dynamics.len();
            for r in 0..7 {
                for c in 0..nf {
                    pat.dynamics.push((t0 + r, offset + c));
                }
            }
            lay.fluid_rows = pat.dynamics.len();
            for r in 0..nf {
                for c in 0..7 {
                    pat.dynamics.push((offset + r, t0 + c));
                }
            }
            let m = f.body.scalar_mass().as_ref();
            for j in 0..m.ncols() {
                for (i, val) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
                    for k in 0..3 {
                        let (r, c) = (3 * i + k, 3 * j + k);
                        lay.mass_entries.push((lay.blocks.value_index(r, c), *val));
                    }
                }
            }
            offset += nf;
            layouts.push(lay);
        }
        (pat, layouts)
    }

    /// Initial coordinates: the rigid bodies' and each fluid's reference mesh (tank frame)
    /// placed at its tank's initial pose, moving rigidly with it.
    pub fn initial_coordinates(&self) -> (Vec<f64>, Vec<f64>) {
        let (mut q, mut v) = self.mb.initial_coordinates();
        for f in &self.fluids {
            let s = self.mb.initial_state(Some(f.tank));
            let e0 = f.body.reference_coordinates();
            for (k, x) in e0.chunks_exact(3).enumerate() {
                let y = s.rotation * Vector3::new(x[0], x[1], x[2]);
                let (p, vel) = if k % 4 == 0 {
                    (y + s.position, s.angular_velocity.cross(&y) + s.velocity)
                } else {
                    (y, s.angular_velocity.cross(&y))
                };
                q.extend_from_slice(p.as_slice());
                v.extend_from_slice(vel.as_slice());
            }
        }
        (q, v)
    }

    /// Coordinates of fluid `k` within a global vector.
    pub fn fluid_slice<'a>(&self, k: usize, x: &'a [f64]) -> &'a [f64] {
        let o = self.layouts[k].offset;
        &x[o..o + self.fluids[k].body.n_coords()]
    }

    /// Fluid contact load on its tank (force, moment about the tank origin; global) at a state.
    pub fn fluid_load(&self, k: usize, q: &[f64], v: &[f64]) -> ancf_core::contact::ContactLoad {
        let f = &self.fluids[k];
        let s = self.mb.state(Some(f.tank), &q[..self.n_rigid], &v[..self.n_rigid]);
        let mut scratch = vec![0.0; f.body.n_coords()];
        f.contact.forces(
            &f.body,
            &tank_kinematics(&s),
            self.fluid_slice(k, q),
            self.fluid_slice(k, v),
            &mut scratch,
            None,
        )
    }
}

/// Fluid `f`'s generalized forces (internal, gravity `g`, wall contact) into `of`, its slice of
/// the system's forces (coordinates from `offset` in `q`, `v`), and its load on the tank body.
#[allow(clippy::too_many_arguments)]
fn fluid_forces(
    f: &TankFluid,
    offset: usize,
    ws: &mut ForceWorkspace,
    tank: &BodyState,
    q: &[f64],
    v: &[f64],
    g: Vector3<f64>,
    of: &mut [f64],
) -> Result<[f64; 7], SystemError> {
    let n = f.body.n_coords();
    let (e, ed) = (&q[offset..offset + n], &v[offset..offset + n]);
    f.body.internal_forces_with(ws, e, ed, of)?;
    of.iter_mut().for_each(|x| *x = -*x);
    for (s, o) in f.body.gravity_scale().iter().zip(of.chunks_exact_mut(3)) {
        for i in 0..3 {
            o[i] += s * g[i];
        }
    }
    Ok(contact_load(f, tank, e, ed, of))
}

/// Adds a fluid's generalized load to its tank body's 7 rows of the rigid forces.
fn add_tank_load(rigid: &mut [f64], f: &TankFluid, load_gen: &[f64; 7]) {
    let o = 7 * f.tank.0;
    for i in 0..7 {
        rigid[o + i] += load_gen[i];
    }
}

/// Adds the wall-contact forces of fluid `f` in `tank` to `out` and returns its load on the tank
/// body as generalized forces on the body's 7 coordinates.
fn contact_load(f: &TankFluid, tank: &BodyState, e: &[f64], ed: &[f64], out: &mut [f64]) -> [f64; 7] {
    let load = f.contact.forces(&f.body, &tank_kinematics(tank), e, ed, out, None);
    tank.generalized(&Vector3::from(load.force), &Vector3::from(load.moment))
}

impl MechanicalSystem for FluidVehicle {
    fn n_coords(&self) -> usize {
        self.n_rigid + self.fluids.iter().map(|f| f.body.n_coords()).sum::<usize>()
    }

    fn n_constraints(&self) -> usize {
        self.mb.n_constraints()
    }

    fn describe_unknown(&self, index: KktIndex) -> String {
        let KktIndex::Coordinate(i) = index else { return self.mb.describe_unknown(index) };
        if i < self.n_rigid {
            return self.mb.describe_unknown(index);
        }
        const SLOTS: [&str; 4] = ["position", "gradient d/dX", "gradient d/dY", "gradient d/dZ"];
        for (k, (f, lay)) in self.fluids.iter().zip(&self.layouts).enumerate() {
            if (lay.offset..lay.offset + f.body.n_coords()).contains(&i) {
                let local = i - lay.offset;
                let (node, slot, c) = (local / 12, (local % 12) / 3, ["x", "y", "z"][local % 3]);
                let tank = &self.mb.bodies()[f.tank.0].name;
                return format!("coordinate {i} = {} {c} of node {node} of fluid {k} (tank '{tank}')", SLOTS[slot]);
            }
        }
        index.to_string()
    }

    fn pattern(&self) -> SparsityPattern {
        self.build_pattern().0
    }

    fn linear_solver(&self) -> LinearSolverKind {
        self.linear_solver
    }

    /// Each fluid's coordinates: they couple only to their tank body's.
    fn condensed_blocks(&self) -> Vec<std::ops::Range<usize>> {
        self.fluids.iter().zip(&self.layouts).map(|(f, lay)| lay.offset..lay.offset + f.body.n_coords()).collect()
    }

    fn mass_entries(&self) -> Option<Vec<usize>> {
        let mut idx = self.mb.mass_entries()?;
        for lay in &self.layouts {
            idx.extend(lay.mass_entries.iter().map(|&(i, _)| i));
        }
        Some(idx)
    }

    fn mass(&mut self, q: &[f64], values: &mut [f64]) -> Result<(), SystemError> {
        self.mass_varying(q, values)?;
        for lay in &self.layouts {
            for &(i, val) in &lay.mass_entries {
                values[i] += val;
            }
        }
        Ok(())
    }

    /// The rigid bodies' mass blocks change with their Euler parameters; the fluids' consistent
    /// mass (most of the entries) is constant, so the integrator keeps it between residuals.
    fn mass_varying_entries(&self) -> Option<Vec<usize>> {
        Some(self.mb.mass_entries().unwrap_or_else(|| (0..self.mb_entries).collect()))
    }

    fn mass_varying(&mut self, q: &[f64], values: &mut [f64]) -> Result<(), SystemError> {
        let nr = self.n_rigid;
        self.mb.mass(&q[..nr], &mut values[..self.mb_entries])
    }

    /// The rigid bodies' blocks from `values`, each fluid's M_s ⊗ I₃ from its scalar mass (the
    /// values `mass` writes there, unchanged): a third of the index traffic of the pattern's
    /// entries, the same sums in the same order.
    fn subtract_mass_product(&self, values: &[f64], a: &[f64], scale: f64, out: &mut [f64]) -> bool {
        for &(i, j, k) in &self.rigid_mass {
            out[i as usize] -= scale * values[k as usize] * a[j as usize];
        }
        for (f, lay) in self.fluids.iter().zip(&self.layouts) {
            let (o, n) = (lay.offset, f.body.n_coords());
            f.body.subtract_mass_product(&a[o..o + n], scale, &mut out[o..o + n]);
        }
        true
    }

    /// The rigid forces, then each fluid's internal, gravity and wall-contact forces and its
    /// load on the tank body. With several fluids and threads the fluids are evaluated in
    /// parallel (their coordinates are disjoint and follow the rigid ones in order); either
    /// way their loads are added to the tank rows in fluid order, so the result does not
    /// depend on the thread count. The sequential path does not allocate.
    fn forces(&mut self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) -> Result<(), SystemError> {
        let nr = self.n_rigid;
        out.fill(0.0);
        MechanicalSystem::forces(&mut self.mb, t, &q[..nr], &v[..nr], &mut out[..nr])?;
        let g = self.mb.gravity;
        let (rigid, fluid_out) = out.split_at_mut(nr);
        if self.fluids.len() > 1 && rayon::current_num_threads() > 1 {
            let tanks: Vec<BodyState> =
                self.fluids.iter().map(|f| self.mb.state(Some(f.tank), &q[..nr], &v[..nr])).collect();
            let mut slices = Vec::with_capacity(self.fluids.len());
            let mut rest = fluid_out;
            for f in &self.fluids {
                let (of, tail) = rest.split_at_mut(f.body.n_coords());
                slices.push(of);
                rest = tail;
            }
            let mut workspaces = std::mem::take(&mut self.workspaces);
            let (fluids, layouts) = (&self.fluids, &self.layouts);
            let loads: Vec<Result<[f64; 7], SystemError>> = slices
                .into_par_iter()
                .zip(workspaces.par_iter_mut())
                .enumerate()
                .map(|(k, (of, ws))| fluid_forces(&fluids[k], layouts[k].offset, ws, &tanks[k], q, v, g, of))
                .collect();
            self.workspaces = workspaces;
            for (f, load_gen) in self.fluids.iter().zip(loads) {
                add_tank_load(rigid, f, &load_gen?);
            }
        } else {
            for k in 0..self.fluids.len() {
                let (f, offset) = (&self.fluids[k], self.layouts[k].offset);
                let n = f.body.n_coords();
                let of = &mut fluid_out[offset - nr..offset - nr + n];
                let tank = self.mb.state(Some(f.tank), &q[..nr], &v[..nr]);
                let load_gen = fluid_forces(f, offset, &mut self.workspaces[k], &tank, q, v, g, of)?;
                add_tank_load(rigid, f, &load_gen);
            }
        }
        if let Some(i) = out.iter().position(|x| !x.is_finite()) {
            return Err(SystemError::Other(format!("non-finite generalized force at coordinate {i}")));
        }
        Ok(())
    }

    /// Rejects a step on which a fluid's volume error exceeds 1 % or a fluid penetrates
    /// its tank wall deeper than half its smallest element edge (as `SloshSystem`), or
    /// breaks a run-time invariant ([`crate::invariants`]): a node, contact point or the
    /// centre of mass beyond the wall by more than the same limit, a volume ratio at or
    /// below [`crate::invariants::MIN_VOLUME_RATIO`], or energy growth beyond what the
    /// tank walls put in (the liquid's energy in the global frame, the walls' work from
    /// the tank body's velocities). A step is accounted only when every fluid passes.
    /// The rigid system's warm starts, then each fluid's invariant account.
    fn save_internal_state(&self, out: &mut Vec<f64>) {
        self.mb.save_internal_state(out);
        for m in &self.monitors {
            m.save_account(out);
        }
    }

    fn restore_internal_state(&mut self, data: &mut &[f64]) -> Option<()> {
        self.mb.restore_internal_state(data)?;
        for m in &mut self.monitors {
            m.restore_account(data)?;
        }
        Some(())
    }

    fn check_step(&mut self, t: f64, q: &[f64], v: &[f64]) -> Result<(), SystemError> {
        let nr = self.n_rigid;
        let g = self.mb.gravity;
        for k in 0..self.fluids.len() {
            let f = &self.fluids[k];
            let o = self.layouts[k].offset;
            let (e, ed) = (&q[o..o + f.body.n_coords()], &v[o..o + f.body.n_coords()]);
            let (volume, reference) = (f.body.volume(e), f.body.reference_volume());
            let error = (volume / reference - 1.0).abs();
            if error.is_nan() || error > 0.01 {
                return Err(SystemError::VolumeError { what: format!("fluid {k}"), volume, reference, limit: 0.01 });
            }
            let tank = self.mb.state(Some(f.tank), &q[..nr], &v[..nr]);
            let kin = tank_kinematics(&tank);
            // The contact adds its forces into the buffer.
            let scratch = &mut self.scratch[0];
            scratch.clear();
            scratch.resize(e.len(), 0.0);
            let load = f.contact.forces(&f.body, &kin, e, ed, scratch, None);
            let limit = self.monitors[k].limits.containment;
            if load.max_penetration > limit {
                return Err(SystemError::Penetration {
                    contact: format!("fluid {k} - tank wall ({} points active)", load.active),
                    depth: load.max_penetration,
                    limit,
                });
            }
            let energy = EnergySample {
                kinetic: f.body.kinetic_energy(ed),
                potential: f.body.potential_energy(e, g.into()),
                stored: stored_energy(&f.body, &f.contact, &kin, e),
                input_power: wall_power(load.force, load.moment, &kin),
            };
            let assessed = self.monitors[k].assess(t, &f.body, &f.contact, &kin, e, energy);
            self.pending[k] = Some(assessed.map_err(|(error, _, _)| error)?);
        }
        // every fluid passed: the step is accepted
        for (m, p) in self.monitors.iter_mut().zip(self.pending.iter_mut()) {
            if let Some(p) = p.take() {
                m.commit(p);
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
        let nr = self.n_rigid;
        let me = self.mb_entries;
        self.mb.force_jacobians(t, &q[..nr], &v[..nr], &mut dq[..me], &mut dv[..me])?;
        let mut pj = std::mem::take(&mut self.point_jac);
        let [mut base, mut fp] = std::mem::take(&mut self.scratch);
        for k in 0..self.fluids.len() {
            let lay = &self.layouts[k];
            let f = &self.fluids[k];
            let n = f.body.n_coords();
            let (e, ed) = (&q[lay.offset..lay.offset + n], &v[lay.offset..lay.offset + n]);
            let idx = FluidBlocks::element_index;
            // Fluid–fluid: element Jacobians.
            lay.blocks.subtract_element_jacobians(&f.body, e, ed, dq, dv, &mut self.jacobians)?;
            // Contact: fluid–fluid point Jacobians and the exact tank rows.
            let tank = self.mb.state(Some(f.tank), &q[..nr], &v[..nr]);
            // The contact passes add their forces into `base` and `fp`: zero them first.
            base.clear();
            base.resize(n, 0.0);
            f.contact.forces(&f.body, &tank_kinematics(&tank), e, ed, &mut base, Some(&mut pj));
            let et2 = crate::mbs::rotation::e_matrix(&tank.params).transpose() * 2.0;
            for p in &pj {
                let pt = &f.contact.points[p.point];
                let eb = &lay.blocks.element_blocks[pt.element];
                let nodes = &f.body.mesh.elements[pt.element];
                let dm_dr: Matrix3<f64> = p.force.cross_matrix() - p.arm.cross_matrix() * p.d_position;
                let dm_dv: Matrix3<f64> = -(p.arm.cross_matrix() * p.d_velocity);
                let gp_dr = et2 * dm_dr;
                let gp_dv = et2 * dm_dv;
                for a in 0..N_SHAPE {
                    let na = pt.shape[a];
                    if na == 0.0 {
                        continue;
                    }
                    for b in 0..N_SHAPE {
                        let nn = na * pt.shape[b];
                        for i in 0..3 {
                            for c in 0..3 {
                                let x = idx(eb, a, i, b, c);
                                dq[x] += nn * p.d_position[(i, c)];
                                dv[x] += nn * p.d_velocity[(i, c)];
                            }
                        }
                    }
                    // Tank rows × fluid column (3 × node(a) + comp).
                    let col = 3 * (4 * nodes[a / 4] + a % 4);
                    for c in 0..3 {
                        for r in 0..3 {
                            let x = lay.tank_rows + r * n + col + c;
                            dq[x] -= na * p.d_position[(r, c)];
                            dv[x] -= na * p.d_velocity[(r, c)];
                        }
                        for r in 0..4 {
                            let x = lay.tank_rows + (3 + r) * n + col + c;
                            dq[x] += na * gp_dr[(r, c)];
                            dv[x] += na * gp_dv[(r, c)];
                        }
                    }
                }
            }
            // Tank columns: forward differences of the contact pass.
            let t0 = 7 * f.tank.0;
            base.fill(0.0);
            let gen0 = contact_load(&self.fluids[k], &tank, e, ed, &mut base);
            let mut qt = [0.0; 7];
            let mut vt = [0.0; 7];
            qt.copy_from_slice(&q[t0..t0 + 7]);
            vt.copy_from_slice(&v[t0..t0 + 7]);
            let mut tank_block_q = [[0.0; 7]; 7];
            let mut tank_block_v = [[0.0; 7]; 7];
            for c in 0..14 {
                let (mut qp, mut vp) = (qt, vt);
                let h = if c < 7 { FD_Q } else { FD_V };
                if c < 7 {
                    qp[c] += h;
                } else {
                    vp[c - 7] += h;
                }
                let st = BodyState::from_coordinates(&qp, &vp);
                fp.clear();
                fp.resize(n, 0.0);
                let load_gen = contact_load(&self.fluids[k], &st, e, ed, &mut fp);
                let (target, col) = if c < 7 { (&mut *dq, c) } else { (&mut *dv, c - 7) };
                for r in 0..n {
                    let d = (fp[r] - base[r]) / h;
                    if d != 0.0 {
                        target[lay.fluid_rows + r * 7 + col] += d;
                    }
                }
                let blk = if c < 7 { &mut tank_block_q } else { &mut tank_block_v };
                for r in 0..7 {
                    blk[r][col] = (load_gen[r] - gen0[r]) / h;
                }
            }
            // Tank–tank block lives in the multibody part (the body's own 7×7 block).
            let diag = self.mb.body_block_index(f.tank);
            for r in 0..7 {
                for c in 0..7 {
                    dq[diag + 7 * r + c] += tank_block_q[r][c];
                    dv[diag + 7 * r + c] += tank_block_v[r][c];
                }
            }
        }
        self.point_jac = pj;
        self.scratch = [base, fp];
        Ok(())
    }

    fn constraints(&mut self, t: f64, q: &[f64], out: &mut [f64]) -> Result<(), SystemError> {
        self.mb.constraints(t, &q[..self.n_rigid], out)
    }

    fn constraint_jacobian(&mut self, t: f64, q: &[f64], values: &mut [f64]) -> Result<(), SystemError> {
        self.mb.constraint_jacobian(t, &q[..self.n_rigid], values)
    }

    fn constraint_force_jacobian(
        &mut self,
        t: f64,
        q: &[f64],
        lambda: &[f64],
        dq: &mut [f64],
    ) -> Result<bool, SystemError> {
        let me = self.mb_entries;
        self.mb.constraint_force_jacobian(t, &q[..self.n_rigid], lambda, &mut dq[..me])
    }
}

mod train;
pub use train::*;
