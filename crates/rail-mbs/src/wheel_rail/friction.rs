//! Friction that varies over the rail profile and along the track (issue 21): a lubricated
//! gauge face, a dry top of rail, a wet stretch.
//!
//! μ at a contact point = `profile(v) × along_track(s)`, where `v` is the point's lateral
//! coordinate on the rail profile (m, towards the field side, the rail profile's own `y`;
//! crate convention of [`crate::profile`]) and `s` its distance along the track (m). Both are
//! piecewise-linear tables, held constant outside their range; an empty along-track table is 1.
//! Each contact point (patch) takes the μ of its own location ([`super::WheelRailContact`]).

use crate::profile::Profile;

use super::ContactError;

/// Friction coefficient over the rail profile and along the track (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct FrictionMap {
    /// `(v, μ)`: rail profile lateral coordinate (m, increasing) and friction coefficient.
    pub profile: Vec<(f64, f64)>,
    /// `(s, factor)`: distance along the track (m, increasing) and the factor on μ.
    pub along_track: Vec<(f64, f64)>,
}

fn table(x: &[(f64, f64)], at: f64) -> f64 {
    let k = x.partition_point(|p| p.0 < at);
    if k == 0 {
        return x[0].1;
    }
    if k == x.len() {
        return x[x.len() - 1].1;
    }
    let (a, b) = (x[k - 1], x[k]);
    a.1 + (b.1 - a.1) * (at - a.0) / (b.0 - a.0)
}

/// The project's one "invalid `field` = value: expected …" message, as a contact error.
fn invalid(field: &str, value: impl std::fmt::Display, allowed: &str) -> ContactError {
    ContactError::InvalidInput(ancf_core::error::invalid(field, value, allowed).to_string())
}

/// The parameters of [`FrictionMap::lubricated_gauge_face`]; [`Self::DEFAULT`] is the one
/// home of their defaults (the contact API, vehicle runs and scenes read them from here).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaugeFaceLubrication {
    /// Friction on the top of the rail.
    pub mu_top: f64,
    /// Friction on the lubricated gauge face.
    pub mu_gauge: f64,
    /// The gauge face starts this far below the rail's highest point, m.
    pub depth: f64,
    /// Width of the blend from `mu_gauge` to `mu_top`, m.
    pub width: f64,
}

impl GaugeFaceLubrication {
    /// A dry top of rail (0.4), a greased gauge face (0.1) from 2 mm below the top, blended
    /// over 2 mm.
    pub const DEFAULT: Self = Self { mu_top: 0.4, mu_gauge: 0.1, depth: 0.002, width: 0.002 };
}

impl FrictionMap {
    /// The same μ everywhere.
    pub fn uniform(mu: f64) -> Result<Self, ContactError> {
        let m = Self { profile: vec![(0.0, mu)], along_track: Vec::new() };
        m.validate()?;
        Ok(m)
    }

    /// A lubricated gauge face: `mu_gauge` on the gauge side of the rail up to the point
    /// `depth` below the rail's highest point (2 mm: on UIC 60 about 25 mm to the gauge side
    /// of the top), `mu_top` on the rest of the head, changing linearly over `width` (m)
    /// towards the top.
    pub fn lubricated_gauge_face(
        rail: &Profile,
        mu_top: f64,
        mu_gauge: f64,
        depth: f64,
        width: f64,
    ) -> Result<Self, ContactError> {
        if !(depth.is_finite() && depth > 0.0) {
            return Err(invalid("depth", depth, "a depth > 0 m below the rail top"));
        }
        if !(width.is_finite() && width > 0.0) {
            return Err(invalid("width", width, "a transition width > 0 m"));
        }
        let (y_top, z_top) = rail.highest_point();
        let v = rail
            .crossing(y_top, -1.0, z_top - depth)
            .ok_or_else(|| invalid("depth", depth, "a depth within the rail profile"))?;
        let m = Self { profile: vec![(v, mu_gauge), (v + width, mu_top)], along_track: Vec::new() };
        m.validate()?;
        Ok(m)
    }

    /// Checks the tables: non-empty profile, increasing abscissae, μ and factors finite ≥ 0,
    /// μ ≤ 1.
    pub fn validate(&self) -> Result<(), ContactError> {
        if self.profile.is_empty() {
            return Err(invalid("friction.profile", "[]", "at least one (v, μ) pair"));
        }
        for (name, t, hi) in
            [("friction.profile", &self.profile, 1.0), ("friction.along_track", &self.along_track, 10.0)]
        {
            for (i, &(x, y)) in t.iter().enumerate() {
                if !x.is_finite() || (i > 0 && x <= t[i - 1].0) {
                    return Err(invalid(&format!("{name}[{i}]"), x, "finite, strictly increasing positions (m)"));
                }
                if !(y.is_finite() && (0.0..=hi).contains(&y)) {
                    return Err(invalid(&format!("{name}[{i}]"), y, &format!("a value from 0 to {hi}")));
                }
            }
        }
        Ok(())
    }

    /// μ at rail profile coordinate `v` (m) and distance `s` (m).
    pub fn mu(&self, s: f64, v: f64) -> f64 {
        let f = if self.along_track.is_empty() { 1.0 } else { table(&self.along_track, s) };
        table(&self.profile, v) * f
    }
}

/// Nadal's flange-climb limit `Y/Q = (tan δ − μ) / (1 + μ tan δ)` (M. J. Nadal, 1908): the
/// single-wheel L/V at which a wheel in contact at angle `contact_angle` δ (rad) with friction
/// `friction` μ starts to climb the rail (saturated creep pointing down the flange). The one
/// implementation: the derailment indicators (Python `railslosh.indicators.nadal_limit`) and the
/// flange-climb validation case call it.
pub fn nadal_limit(contact_angle: f64, friction: f64) -> f64 {
    let t = contact_angle.tan();
    (t - friction) / (1.0 + friction * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_interpolate_and_hold_their_ends() {
        let m =
            FrictionMap { profile: vec![(-0.02, 0.1), (-0.01, 0.4)], along_track: vec![(100.0, 1.0), (110.0, 0.5)] };
        assert_eq!(m.mu(0.0, -0.05), 0.1);
        assert_eq!(m.mu(0.0, 0.0), 0.4);
        assert!((m.mu(0.0, -0.015) - 0.25).abs() < 1e-15);
        assert!((m.mu(105.0, 0.0) - 0.4 * 0.75).abs() < 1e-15);
        assert!((m.mu(200.0, 0.0) - 0.2).abs() < 1e-15);
        let bad = FrictionMap { profile: vec![(0.0, 0.2), (0.0, 0.3)], along_track: vec![] };
        assert!(bad.validate().unwrap_err().to_string().contains("`friction.profile[1]`"));
        let bad = FrictionMap { profile: vec![(0.0, 1.5)], along_track: vec![] };
        assert!(bad.validate().unwrap_err().to_string().contains("from 0 to 1"));
    }
}
