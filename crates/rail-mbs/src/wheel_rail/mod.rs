//! Three-dimensional wheel/rail contact (ECF-A elastic contact formulation).
//!
//! Following §7.2 of the tank-car paper (seed 000) the wheel keeps all six degrees of
//! freedom relative to the rail, the surfaces are parametrised by four surface
//! parameters `q = [s1r, s2r, s1w, s2w]` and a contact point satisfies
//!
//! ```text
//! C(q) = [ r_wr·t1r,  r_wr·t2r,  n_r·t1w,  n_r·t2w ] = 0,     r_wr = r_w − r_r,
//! ```
//!
//! with `t` the surface tangents and `n_r = t1r × t2r` the rail normal. `C = 0` is solved
//! by Newton–Raphson with the analytic Jacobian ([`WheelRailContact::constraint_jacobian`]).
//! Each solve is seeded from a 1-D scan over the wheel's lateral profile coordinate
//! (the signed distance from each wheel circle's lowest point to the rail profile, along the
//! rail normal at the foot of the perpendicular), whose
//! local minima give one seed per potential contact (tread and flange can touch at the
//! same time), and warm-started from the previous solution when one is near. The
//! penetration is `δ = −r_wr·n̂_r` (positive when the bodies overlap); a negative `δ`
//! means separation and gives no force.
//!
//! Normal force: Hertz `f_n = K_h δ^{3/2}(1 + d·δ̇)` (Hunt–Crossley damping with
//! coefficient `d` in s/m, clamped at zero), with `K_h` and the ellipse semi-axes from the
//! relative principal curvatures ([`hertz`]); or, with [`PatchModel::KikPiotrowski`] on
//! [`WheelRailContact::patch_model`], the non-elliptic Kik–Piotrowski patch from the profiles'
//! separation across the contact ([`kik_piotrowski`]). Tangential force: creepages from the rigid
//! body velocities and a creep law ([`creep`]; Shen–Hedrick–Elkins by default, Polach
//! and FASTSIM with three flexibilities optional).
//!
//! # Search strategy and limits
//!
//! * By default ([`ContactSettings::always_scan`]) every call scans the wheel profile
//!   (closed-form lowest point of each wheel circle in the rail frame, 400 samples),
//!   refines each scan minimum by Newton — starting from the previous solution when one
//!   lies within 2 mm, otherwise from the scan point — and accepts the result when it
//!   stays within the profile ranges, within 5 mm of the seed and has positive relative
//!   curvatures (a true minimum of the gap). Otherwise the scan minimum refined by a
//!   golden-section search is used ([`ContactMethod::ScanFallback`]).
//! * With `always_scan = false` only the previous solutions are re-converged, and the
//!   scan runs only when one of them fails; this is cheaper but cannot see a *new*
//!   contact point (e.g. the flange) appear while the old ones still converge.
//! * Newton uses the analytic Jacobian with step limits and backtracking on `|C|`. For
//!   nearly conformal pairs (S1002 tread on a 1:40 UIC 60 crown has almost equal
//!   lateral curvatures) its convergence radius in the lateral parameters is only a
//!   fraction of a millimetre, which is why it is always seeded from the scan.
//! * Near-conformal points whose relative curvature vanishes or turns negative are
//!   evaluated with Hertz at a curvature floor
//!   ([`ContactSettings::min_relative_curvature`]); a genuinely conformal contact (one
//!   wide patch, as CONTACT finds for S1002/UIC60 at zero lateral shift) is represented by
//!   two Hertzian points instead.
//! * One point per minimum of the gap: solutions within [`ContactSettings::merge_distance`]
//!   (1 mm in both lateral parameters) are one point found twice and are merged; distinct
//!   minima are not combined into one patch by default
//!   ([`ContactSettings::patch_combination`] = [`PatchCombination::Separate`]); with
//!   [`PatchCombination::Contact`] they are, by CONTACT's rule. CONTACT decides between one patch and two on
//!   the interpenetration regions instead: regions whose contact angles differ by at most
//!   A_SEP and whose facing ends lie within D_SEP are one patch (fully merged within D_COMB,
//!   between D_COMB and D_SEP one patch of two weakly coupled parts). On S1002/UIC 60 at 1:40
//!   every two-point contact we find is one patch by CONTACT's rule (docs/validation.md, "One
//!   patch or two: our rule and CONTACT's").
//! * Rails following a [`crate::track::Track`] get the first and second derivatives of
//!   their frame along `s` by central differences (2 cm), the track's irregularity
//!   ([`crate::track::Irregularity`], a translation of each rail's profile) included;
//!   rails are fixed (zero velocity).
//!
//! # Parametrisation and frames
//!
//! * **Rail** (`s1r = s`, `s2r = v`): `r_r = O(s) + M(s)·(0, σ v, z_r(v))`, where `O`, `M`
//!   are the rail profile frame (origin and rotation; track frame x forward, y left,
//!   z up, rotated by the inward cant), `σ = +1` for the left and `−1` for the right
//!   rail and `z_r(v)` the rail [`Profile`] (`v` towards the field side).
//! * **Wheel** (`s1w = u`, `s2w = θ`): in the wheel(set) body frame (x forward, y along
//!   the axle to the left, z up) `w = (ρ sin θ, σ (d_w + u), −ρ cos θ)`, `ρ(u) = r0 −
//!   z_w(u)`, with `r0` the nominal radius, `d_w` the lateral distance from the body
//!   origin to the wheel profile origin and `z_w(u)` the wheel [`Profile`]. `θ = 0` is
//!   the lowest point of the wheel circle.
//! * Contact frame: `n̂` the unit rail normal (out of the rail, into the wheel), `e1`
//!   the wheel's circumferential tangent projected on the tangent plane and oriented
//!   along the direction of travel, `e2 = n̂ × e1` (roughly to the left).
//!
//! [`Profile`]: crate::profile::Profile

pub mod contact;
pub mod creep;
pub mod friction;
pub mod hertz;
pub mod kik_piotrowski;
pub mod manchester;
pub mod static_load;

pub use contact::{
    ContactGeometry, ContactMethod, ContactPoint, ContactSettings, InterpenetrationRegion, PatchCombination,
    RailGeometry, RailPath, WheelGeometry, WheelPose, WheelRailContact, mirror_pseudovector, mirror_vector,
};
pub use creep::{
    CreepForces, CreepModel, Creepages, KalkerCoefficients, PatchStrip, creep_forces, fastsim_flexibilities,
    fastsim_strips, kalker_coefficients, linear_coefficients,
};
pub use friction::{FrictionMap, GaugeFaceLubrication, nadal_limit};
pub use hertz::{HertzConstants, Material, combined_modulus, elliptic_ke};
pub use kik_piotrowski::{KpPatch, PatchModel, PatchSummary, QuadraticSeparation, SampledSeparation, SeparationFn};
pub use static_load::{LoadedContact, VerticalTarget, WheelState, apply_creepages, solve_vertical};

use thiserror::Error;

/// Errors of the contact computation.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ContactError {
    /// Relative curvatures are not both positive (conformal or concave contact), so the
    /// Hertz solution does not exist.
    #[error(
        "non-Hertzian contact: relative curvatures A = {curvature_x} 1/m, B = {curvature_y} 1/m must both be positive"
    )]
    NonHertzian {
        /// Curvature along the rolling direction.
        curvature_x: f64,
        /// Lateral curvature.
        curvature_y: f64,
    },
    /// Newton–Raphson did not converge.
    #[error("contact-point Newton iteration did not converge after {iterations} iterations (|C| = {residual:e})")]
    NoConvergence {
        /// Iterations done.
        iterations: usize,
        /// Last residual norm.
        residual: f64,
    },
    /// The Jacobian of the contact conditions is singular.
    #[error("singular contact Jacobian")]
    SingularJacobian,
    /// Bad input (non-finite pose, negative radius, …).
    #[error("invalid contact input: {0}")]
    InvalidInput(String),
    /// No wheel height meets a vertical target because the measured quantity jumps across
    /// it (the contact search finds a contact only from some depth on, typically at large
    /// yaw where the contact point leaves the profile's scanned range).
    #[error(
        "no wheel height meets the target {target} (the {quantity} jumps from {below:e} to {above:e} at height \
         {height} m; contact search discontinuous here)"
    )]
    TargetNotMet {
        /// What was solved for (e.g. "vertical force").
        quantity: &'static str,
        /// The target value.
        target: f64,
        /// The value just above the jump height (less loaded side).
        below: f64,
        /// The value just below the jump height.
        above: f64,
        /// The height of the jump, m.
        height: f64,
    },
    /// Track query failed.
    #[error("track error: {0}")]
    Track(#[from] crate::track::TrackError),
}
