//! The [`MechanicalSystem`] trait: what the integrator needs from a model.

use super::error::{KktIndex, SystemError};
use super::iterative::LinearSolverKind;

/// Fixed sparsity pattern of a [`MechanicalSystem`], declared once.
///
/// * `dynamics` lists `(row, col)` entries of the `n × n` matrices `M`, `∂Q/∂q` and
///   `∂Q/∂v` — one shared pattern, the union of the three. Mass and Jacobian values
///   are written **in this order**; entries a matrix does not use are written as 0.
/// * `constraints` lists `(row, col)` entries of the `m × n` constraint Jacobian
///   `C_q` (row = constraint index, col = coordinate index); its values are written
///   in this order.
///
/// Duplicate entries are allowed and summed. Entries that are sometimes zero (e.g.
/// wheel/rail contacts that switch on and off) **must stay in the pattern** as
/// explicit zeros: the symbolic LU factorization is computed once from it.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct SparsityPattern {
    /// `(row, col)` entries of `M`, `∂Q/∂q`, `∂Q/∂v` (union), each in `0..n`.
    pub dynamics: Vec<(usize, usize)>,
    /// `(constraint, coordinate)` entries of `C_q`, in `0..m × 0..n`.
    pub constraints: Vec<(usize, usize)>,
}

impl SparsityPattern {
    /// Dense-diagonal helper: the pattern `{(i, i)}` for `i in 0..n`, no constraints.
    pub fn diagonal(n: usize) -> Self {
        Self { dynamics: (0..n).map(|i| (i, i)).collect(), constraints: Vec::new() }
    }
}

/// A constrained mechanical system in index-3 form,
///
/// ```text
/// M(q) a = Q(t, q, v) + C_q(q, t)ᵀ λ,      v = q̇,  a = v̇,
/// C(q, t) = 0,
/// ```
///
/// with `n` generalized coordinates (`q`, `v`, `a` all have length `n`) and `m`
/// holonomic constraints. `Q` collects **applied minus internal** forces (gravity,
/// springs, contact, elastic forces of ANCF elements enter with a minus sign), and
/// `C_qᵀ λ` is the constraint force (so `λ` is a force for `C = x − x₀`).
///
/// Rigid bodies with Euler parameters use `ṗ` as velocities (so `q` and `v` have the
/// same length) and add the normalization `pᵀp − 1 = 0` as a constraint. ANCF bodies
/// have a constant mass matrix: return `true` from [`mass_is_constant`] and the
/// integrator evaluates [`mass`] once.
///
/// All matrix values are written into caller-provided slices in the order of
/// [`pattern`]; the slices are zeroed by the caller before each call. Callbacks return
/// a [`SystemError`] naming the failing element/constraint; the integrator adds the
/// time. Methods take `&mut self` so that models can cache (e.g. contact search
/// results between [`forces`] and [`force_jacobians`] at the same state).
///
/// [`mass_is_constant`]: MechanicalSystem::mass_is_constant
/// [`mass`]: MechanicalSystem::mass
/// [`pattern`]: MechanicalSystem::pattern
/// [`forces`]: MechanicalSystem::forces
/// [`force_jacobians`]: MechanicalSystem::force_jacobians
pub trait MechanicalSystem {
    /// Number of generalized coordinates `n` (= number of velocities).
    fn n_coords(&self) -> usize;

    /// Number of holonomic constraints `m`.
    fn n_constraints(&self) -> usize {
        0
    }

    /// The fixed sparsity pattern. Called once, when the integrator is built.
    fn pattern(&self) -> SparsityPattern;

    /// Whether `M` is independent of `q` (ANCF elements, point masses). If `true`,
    /// [`mass`](MechanicalSystem::mass) is called once and cached.
    fn mass_is_constant(&self) -> bool {
        false
    }

    /// How the integrator should solve this system's Newton matrix. Called once, when
    /// the integrator is built. Default: sparse LU ([`LinearSolverKind::Direct`]).
    /// Large unconstrained systems (a fluid mesh in a prescribed-motion tank) may
    /// return [`LinearSolverKind::Iterative`], whose cost grows linearly with size.
    fn linear_solver(&self) -> LinearSolverKind {
        LinearSolverKind::Direct
    }

    /// Coordinate ranges for [`LinearSolverKind::Condensed`]: each range couples (in the
    /// pattern) only to unknowns outside every range (other coordinates, constraints), never
    /// to another range. Called once, when the integrator is built. Default: none.
    fn condensed_blocks(&self) -> Vec<std::ops::Range<usize>> {
        Vec::new()
    }

    /// Optional: the indices into `pattern().dynamics` where [`mass`] can write a
    /// non-zero value (at any `q`). The integrator then forms `M a` over these entries
    /// only. Default `None`: every pattern entry.
    ///
    /// [`mass`]: MechanicalSystem::mass
    fn mass_entries(&self) -> Option<Vec<usize>> {
        None
    }

    /// Mass-matrix values at `q`, in `pattern().dynamics` order, kg (or kg·m² …).
    fn mass(&mut self, q: &[f64], values: &mut [f64]) -> Result<(), SystemError>;

    /// Optional, for a mass matrix of which only a part depends on `q` (rigid bodies beside a
    /// fluid's constant consistent mass): the indices into `pattern().dynamics` of the entries
    /// that can change with `q`. With `Some`, the integrator evaluates the whole mass once with
    /// [`mass`](MechanicalSystem::mass), keeps the other entries, and at each residual zeroes
    /// only these and calls [`mass_varying`](MechanicalSystem::mass_varying), which must then
    /// be implemented. Ignored when [`mass_is_constant`](MechanicalSystem::mass_is_constant).
    /// Default `None`: the whole mass at every residual.
    fn mass_varying_entries(&self) -> Option<Vec<usize>> {
        None
    }

    /// The entries of [`mass_varying_entries`](MechanicalSystem::mass_varying_entries) at `q`,
    /// written as [`mass`](MechanicalSystem::mass) writes them (into entries the integrator
    /// has zeroed); every other entry must be left as it is. Default: [`mass`](MechanicalSystem::mass),
    /// right only for a system that declares no such entries.
    fn mass_varying(&mut self, q: &[f64], values: &mut [f64]) -> Result<(), SystemError> {
        self.mass(q, values)
    }

    /// Optional, faster than the integrator's product over the pattern entries for a mass with
    /// structure (a fluid's consistent mass is M_s ⊗ I₃): `out[i] −= (scale · M_ij) · a[j]` for
    /// every entry of M, with `M` the values `values` (`pattern().dynamics` order, as
    /// [`mass`](MechanicalSystem::mass) wrote them), taking each row's entries by increasing
    /// column, so that the result is bit for bit the integrator's own. Returns whether it did;
    /// default `false`.
    fn subtract_mass_product(&self, values: &[f64], a: &[f64], scale: f64, out: &mut [f64]) -> bool {
        let _ = (values, a, scale, out);
        false
    }

    /// Generalized forces `Q(t, q, v)` (applied minus internal), length `n`.
    fn forces(&mut self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) -> Result<(), SystemError>;

    /// Force Jacobians `∂Q/∂q` (into `dq`) and `∂Q/∂v` (into `dv`), both in
    /// `pattern().dynamics` order. For a linear spring `Q = −k x` write `−k`.
    fn force_jacobians(
        &mut self,
        t: f64,
        q: &[f64],
        v: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
    ) -> Result<(), SystemError>;

    /// Constraint residuals `C(q, t)`, length `m`. Default: no constraints.
    fn constraints(&mut self, t: f64, q: &[f64], out: &mut [f64]) -> Result<(), SystemError> {
        let _ = (t, q, out);
        Ok(())
    }

    /// Constraint Jacobian `C_q` values in `pattern().constraints` order.
    fn constraint_jacobian(&mut self, t: f64, q: &[f64], values: &mut [f64]) -> Result<(), SystemError> {
        let _ = (t, q, values);
        Ok(())
    }

    /// Optional geometric stiffness of the constraint forces: **add**
    /// `∂(C_qᵀ λ)/∂q` into `dq` (pattern order) and return `Ok(true)`.
    ///
    /// The default returns `Ok(false)`: the term is neglected in the Newton matrix,
    /// which then converges linearly instead of quadratically (the converged
    /// solution is unchanged).
    fn constraint_force_jacobian(
        &mut self,
        t: f64,
        q: &[f64],
        lambda: &[f64],
        dq: &mut [f64],
    ) -> Result<bool, SystemError> {
        let _ = (t, q, lambda, dq);
        Ok(false)
    }

    /// Optional exact right-hand side of the acceleration-level constraints,
    /// `γ = −(C_q v)_q v − 2 C_qt v − C_tt`, so that `C_q a = γ`. Return `Ok(true)` if
    /// written. Used only for the consistent initial acceleration.
    ///
    /// The default returns `Ok(false)`; the integrator then uses the central second
    /// difference of `s ↦ C(q + s v, t + s)` at `s = 0`, which is exactly `−γ`.
    fn constraint_acceleration_rhs(
        &mut self,
        t: f64,
        q: &[f64],
        v: &[f64],
        out: &mut [f64],
    ) -> Result<bool, SystemError> {
        let _ = (t, q, v, out);
        Ok(false)
    }

    /// Describes a KKT unknown (a coordinate's acceleration or a constraint's multiplier) for
    /// error messages: which body, node or joint it belongs to. Default: its index.
    fn describe_unknown(&self, index: KktIndex) -> String {
        index.to_string()
    }

    /// Appends what the system carries from step to step beyond `(q, v)` and changes as it
    /// runs (warm starts of a contact search, the run-time invariants' energy account) to
    /// `out`, for a checkpoint of a whole run; [`Self::restore_internal_state`] reads it back
    /// into a freshly built system so that the run continues bit for bit. Default: nothing.
    fn save_internal_state(&self, out: &mut Vec<f64>) {
        let _ = out;
    }

    /// Reads the state [`Self::save_internal_state`] wrote from the front of `data`, advancing
    /// it; `None` when it does not fit this system. Default: reads nothing.
    fn restore_internal_state(&mut self, data: &mut &[f64]) -> Option<()> {
        let _ = data;
        Some(())
    }

    /// Optional acceptance check of a converged step at `(t, q, v)`, before it is
    /// committed (e.g. contact penetration beyond a limit, see
    /// [`SystemError::Penetration`]). An error rejects the step: in adaptive mode it is
    /// retried with a smaller `h`, otherwise the run stops with this error. Default:
    /// accept.
    fn check_step(&mut self, t: f64, q: &[f64], v: &[f64]) -> Result<(), SystemError> {
        let _ = (t, q, v);
        Ok(())
    }
}
