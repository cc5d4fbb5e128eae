//! One wheel on its rail at the height that carries a prescribed vertical load (or reaches a
//! prescribed penetration): the set-up of CONTACT's "prescribed vertical force" mode and of
//! the Manchester contact benchmark, used by the validation cases and the Python helper
//! `railslosh.rail.contact`.
//!
//! # Pose
//!
//! The wheel body frame is the wheelset frame (x forward, y along the axle to the left,
//! z up). The wheelset centre is at `(0, lateral_shift, z)` in the global frame, which for a
//! [`RailPath::Straight`](super::RailPath::Straight) rail is the track frame (x along the
//! rail, y to the left, z up, origin on the centreline at the height of the rail profile
//! origins). The rotation is yaw `ψ` about z followed by roll `φ` about the rotated x:
//! `R = R_z(ψ) R_x(φ)`. The wheel(set) moves forward at `speed` along global x, with an
//! optional lateral velocity, and spins about its axle at `axle_rate` (rad/s, positive
//! for forward rolling; default `speed / nominal_radius`, i.e. pure rolling at the nominal
//! radius), plus a yaw rate about global z.
//!
//! With [`WheelState::creepages`] the creepages are prescribed (the same at every point,
//! as in CONTACT's "creepage prescribed" mode) instead of following from the velocities.
//!
//! # Height solve
//!
//! The height `z` is found by stepping down from 50 mm above the nominal height in 0.5 mm
//! steps until the target is exceeded, then by bisection to machine precision. The target
//! is either the total vertical force on the wheel, `Σ F_z` (normal and creep forces, as
//! CONTACT's `FZ`), or the largest penetration of the contact points.

use nalgebra::{Matrix3, Vector3};

use super::ContactError;
use super::contact::{ContactPoint, WheelPose, WheelRailContact};
use super::creep::{Creepages, creep_forces};

/// What the height solve aims for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum VerticalTarget {
    /// Total vertical force on the wheel, N (> 0).
    Load(f64),
    /// Largest penetration of the contact points, m (> 0).
    Penetration(f64),
}

/// Position and motion of the wheel(set) apart from its height (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WheelState {
    /// Lateral position of the wheelset centre, m (positive to the left).
    pub lateral_shift: f64,
    /// Yaw angle about z, rad (positive turns the nose to the left).
    pub yaw: f64,
    /// Roll angle about x, rad (positive lowers the right wheel).
    pub roll: f64,
    /// Forward speed, m/s (≥ 0).
    pub speed: f64,
    /// Lateral velocity of the wheelset centre, m/s.
    pub lateral_velocity: f64,
    /// Yaw rate about the global z axis, rad/s.
    pub yaw_rate: f64,
    /// Spin about the axle, rad/s (positive = rolling forward); `None` = `speed / r0`.
    pub axle_rate: Option<f64>,
    /// Prescribed creepages (the same at every contact point) replacing the kinematic ones
    /// (see [`apply_creepages`]); `None` = creepages from the rigid-body velocities.
    pub creepages: Option<Creepages>,
}

impl WheelState {
    /// Rotation body → global, `R_z(yaw) R_x(roll)`.
    pub fn rotation(&self) -> Matrix3<f64> {
        let (sy, cy) = self.yaw.sin_cos();
        let (sr, cr) = self.roll.sin_cos();
        let rz = Matrix3::new(cy, -sy, 0.0, sy, cy, 0.0, 0.0, 0.0, 1.0);
        let rx = Matrix3::new(1.0, 0.0, 0.0, 0.0, cr, -sr, 0.0, sr, cr);
        rz * rx
    }

    /// Pose of the wheel(set) at height `z` for a wheel of nominal radius `nominal_radius`.
    pub fn pose(&self, nominal_radius: f64, z: f64) -> WheelPose {
        let rotation = self.rotation();
        let omega = self.axle_rate.unwrap_or(self.speed / nominal_radius);
        WheelPose {
            position: Vector3::new(0.0, self.lateral_shift, z),
            rotation,
            velocity: Vector3::new(self.speed, self.lateral_velocity, 0.0),
            angular_velocity: rotation * Vector3::new(0.0, omega, 0.0) + Vector3::new(0.0, 0.0, self.yaw_rate),
        }
    }

    fn check(&self) -> Result<(), ContactError> {
        let fields = [
            ("lateral_shift", self.lateral_shift),
            ("yaw", self.yaw),
            ("roll", self.roll),
            ("speed", self.speed),
            ("lateral_velocity", self.lateral_velocity),
            ("yaw_rate", self.yaw_rate),
            ("axle_rate", self.axle_rate.unwrap_or(0.0)),
            ("creepages.longitudinal", self.creepages.map_or(0.0, |c| c.longitudinal)),
            ("creepages.lateral", self.creepages.map_or(0.0, |c| c.lateral)),
            ("creepages.spin", self.creepages.map_or(0.0, |c| c.spin)),
        ];
        for (name, v) in fields {
            if !v.is_finite() {
                return Err(ContactError::InvalidInput(format!("`{name}` = {v} must be finite")));
            }
        }
        if self.speed < 0.0 {
            return Err(ContactError::InvalidInput(format!("`speed` = {} must be >= 0", self.speed)));
        }
        Ok(())
    }
}

/// Result of [`solve_vertical`].
#[derive(Debug, Clone, PartialEq)]
pub struct LoadedContact {
    /// Height of the wheelset centre, m.
    pub height: f64,
    /// Pose at that height.
    pub pose: WheelPose,
    /// Loaded contact points (δ > 0), sorted by the wheel's lateral profile coordinate.
    pub points: Vec<ContactPoint>,
    /// Total vertical force on the wheel `Σ F_z`, N.
    pub vertical_force: f64,
    /// Largest penetration, m.
    pub max_penetration: f64,
}

/// Places the wheel at the height that meets `target` (see the module docs) and evaluates
/// the contact there. Fails with [`ContactError::InvalidInput`] on bad input and when no
/// height within 50 mm below the nominal one meets the target (e.g. the wheel is off its
/// rail), and with [`ContactError::TargetNotMet`] when the measure jumps across the target
/// (the force at the solved height is then not the target: it is never returned as such).
pub fn solve_vertical(
    contact: &mut WheelRailContact,
    state: &WheelState,
    target: VerticalTarget,
) -> Result<LoadedContact, ContactError> {
    state.check()?;
    let r0 = contact.wheel.nominal_radius;
    if !(r0 > 0.0 && r0.is_finite()) {
        return Err(ContactError::InvalidInput(format!("nominal radius {r0} m must be positive")));
    }
    let goal = match target {
        VerticalTarget::Load(f) | VerticalTarget::Penetration(f) if f > 0.0 && f.is_finite() => f,
        other => return Err(ContactError::InvalidInput(format!("target {other:?} must be positive and finite"))),
    };
    let loaded = |c: &mut WheelRailContact, pose: &WheelPose| -> Result<Vec<ContactPoint>, ContactError> {
        match &state.creepages {
            // the same as `evaluate` then `apply_creepages` for Hertz; the patch's own strips
            // for a Kik–Piotrowski patch
            Some(cr) => c.evaluate_with_creepages(pose, cr),
            None => c.evaluate(pose),
        }
    };
    let measure = |c: &mut WheelRailContact, z: f64| -> Result<f64, ContactError> {
        let pose = state.pose(r0, z);
        match target {
            VerticalTarget::Load(_) => Ok(loaded(c, &pose)?.iter().map(|p| p.force_on_wheel().z).sum()),
            VerticalTarget::Penetration(_) => {
                Ok(c.find_geometry(&pose)?.iter().map(|g| g.penetration).fold(f64::NEG_INFINITY, f64::max))
            }
        }
    };
    let z_nominal = r0 + contact.rail.vertical_offset;
    let mut hi = z_nominal + 0.05;
    if measure(contact, hi)? >= goal {
        return Err(ContactError::InvalidInput(format!(
            "the wheel already meets the target {target:?} 50 mm above its nominal height"
        )));
    }
    let step = 5e-4;
    let mut lo = hi;
    loop {
        lo -= step;
        if measure(contact, lo)? >= goal {
            break;
        }
        hi = lo;
        if lo < z_nominal - 0.05 {
            return Err(ContactError::InvalidInput(format!(
                "no wheel height within 50 mm of the nominal one meets the target {target:?} \
                 (is the wheel off its rail? `lateral_shift` = {} m)",
                state.lateral_shift
            )));
        }
    }
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if measure(contact, mid)? >= goal {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let height = 0.5 * (lo + hi);
    let pose = state.pose(r0, height);
    let points = loaded(contact, &pose)?;
    let vertical_force = points.iter().map(|p| p.force_on_wheel().z).sum();
    let max_penetration = points.iter().map(|p| p.geometry.penetration).fold(0.0, f64::max);
    // Bisection ends on a bracket narrower than the float spacing: a continuous measure meets
    // the goal there. A jump (a contact found only below some height) must not be returned
    // as if it were the solution.
    let reached = match target {
        VerticalTarget::Load(_) => vertical_force,
        VerticalTarget::Penetration(_) => max_penetration,
    };
    if (reached - goal).abs() > 1e-6 * goal {
        let quantity = match target {
            VerticalTarget::Load(_) => "vertical force (N)",
            VerticalTarget::Penetration(_) => "largest penetration (m)",
        };
        let (below, above) = (measure(contact, hi)?, measure(contact, lo)?);
        return Err(ContactError::TargetNotMet { quantity, target: goal, below, above, height });
    }
    Ok(LoadedContact { height, pose, points, vertical_force, max_penetration })
}

/// Replaces the creepages of `points` by `creepages` and recomputes their creep forces with
/// the creep law, friction and materials of `contact` (as [`WheelRailContact::evaluate`]
/// does for kinematic creepages) on each point's ellipse `semi_axes` (for a
/// Kik–Piotrowski patch its equivalent ellipse; [`WheelRailContact::evaluate_with_creepages`]
/// uses the patch itself).
pub fn apply_creepages(contact: &WheelRailContact, points: &mut [ContactPoint], creepages: &Creepages) {
    let (_, g_mod, nu) = contact.elastic_constants();
    for p in points {
        let (a, b) = p.semi_axes;
        p.creepages = *creepages;
        p.creep = creep_forces(
            contact.creep_model,
            creepages,
            a,
            b,
            p.normal_force,
            contact.friction_at(&p.geometry.params),
            g_mod,
            nu,
        );
    }
}
