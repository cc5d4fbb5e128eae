//! Joints: holonomic constraints between two bodies (or a body and the ground), with
//! analytic constraint Jacobians.
//!
//! A joint stores, for each side, a point and a joint frame fixed in that body
//! (`point_i`, `frame_i` in body `i` coordinates; columns of `frame` are the joint axes
//! `x, y, z`). With `a_i = A_i f_i` the global axes:
//!
//! | kind | equations |
//! |---|---|
//! | spherical | `r_i + A_i s_i − r_j − A_j s_j = 0` (3) |
//! | revolute about joint `z` | spherical + `z_i·x_j = 0`, `z_i·y_j = 0` (5) |
//! | fixed | spherical + `x_i·y_j = 0`, `x_i·z_j = 0`, `y_i·z_j = 0` (6) |
//! | trajectory | `t(s*)·(r_i + A_i s_i − O(s*)) = 0`, `s* = s₀ + ∫ V dt` (1) |
//!
//! The dot-product ("dot-1", Haug 1989) equations hold for frames aligned at assembly.
//! The trajectory constraint drives a body along a [`Track`] at a prescribed speed: it
//! fixes the body point's position along the local tangent, leaving it free laterally
//! and vertically (the "trajectory coordinate" constraint of seed 000).

use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};

use super::body::{Attachment, BodyState};
use super::rotation::d_rotate;
use crate::track::Track;
use ancf_core::error::{AncfError, invalid};

/// Prescribed speed along the track.
#[derive(Debug, Clone, PartialEq)]
pub enum SpeedProfile {
    /// Constant speed, m/s.
    Constant(f64),
    /// Piecewise-linear speed (m/s) against time (s); held constant outside the table.
    Table {
        /// Times, s (strictly increasing).
        times: Vec<f64>,
        /// Speeds, m/s.
        speeds: Vec<f64>,
    },
}

impl SpeedProfile {
    /// Checks the table.
    pub fn validate(&self) -> Result<(), AncfError> {
        match self {
            Self::Constant(v) if !v.is_finite() => Err(invalid("speed", v, "finite, m/s")),
            Self::Constant(_) => Ok(()),
            Self::Table { times, speeds } => {
                if times.is_empty() || times.len() != speeds.len() {
                    return Err(invalid("speed table", times.len(), "non-empty, times and speeds of equal length"));
                }
                if times.windows(2).any(|w| w[1] <= w[0]) || times.iter().chain(speeds).any(|x| !x.is_finite()) {
                    return Err(invalid("speed table times", format!("{times:?}"), "finite, strictly increasing"));
                }
                Ok(())
            }
        }
    }

    /// Speed at time `t`, m/s.
    pub fn speed(&self, t: f64) -> f64 {
        match self {
            Self::Constant(v) => *v,
            Self::Table { times, speeds } => {
                if t <= times[0] {
                    return speeds[0];
                }
                let k = times.partition_point(|&x| x <= t);
                if k >= times.len() {
                    return speeds[speeds.len() - 1];
                }
                let w = (t - times[k - 1]) / (times[k] - times[k - 1]);
                speeds[k - 1] + w * (speeds[k] - speeds[k - 1])
            }
        }
    }

    /// Distance travelled from `t = 0` to `t`, m (exact integral of [`speed`](Self::speed)).
    pub fn distance(&self, t: f64) -> f64 {
        match self {
            Self::Constant(v) => v * t,
            Self::Table { times, .. } => {
                let seg = |a: f64, b: f64| 0.5 * (self.speed(a) + self.speed(b)) * (b - a);
                let (lo, hi, sign) = if t >= 0.0 { (0.0, t, 1.0) } else { (t, 0.0, -1.0) };
                let mut d = 0.0;
                let mut x = lo;
                for &tk in times.iter().filter(|&&tk| tk > lo && tk < hi) {
                    d += seg(x, tk);
                    x = tk;
                }
                sign * (d + seg(x, hi))
            }
        }
    }
}

/// Drives a body point along a track.
#[derive(Debug, Clone)]
pub struct TrajectoryDriver {
    /// Track.
    pub track: Arc<Track>,
    /// Arc length of the driven point at `t = 0`, m.
    pub s0: f64,
    /// Speed along the track.
    pub speed: SpeedProfile,
}

impl TrajectoryDriver {
    /// Arc length of the driven point at time `t`.
    pub fn station(&self, t: f64) -> f64 {
        self.s0 + self.speed.distance(t)
    }
}

/// Kind of joint.
#[derive(Debug, Clone)]
pub enum JointKind {
    /// All six relative motions fixed.
    Fixed,
    /// Rotation about the joint `z` axis free (pin).
    Revolute,
    /// All rotations free (ball joint).
    Spherical,
    /// A body point driven along a track (body `i` only; `j` must be the ground).
    Trajectory(TrajectoryDriver),
}

/// A joint between body `i` and body `j` (either may be the ground).
#[derive(Debug, Clone)]
pub struct Joint {
    /// Name used in errors and results.
    pub name: String,
    /// First body.
    pub body_i: Attachment,
    /// Second body.
    pub body_j: Attachment,
    /// Joint point in body `i` coordinates, m.
    pub point_i: Vector3<f64>,
    /// Joint point in body `j` coordinates, m.
    pub point_j: Vector3<f64>,
    /// Joint axes (columns) in body `i` coordinates.
    pub frame_i: Matrix3<f64>,
    /// Joint axes (columns) in body `j` coordinates.
    pub frame_j: Matrix3<f64>,
    /// Kind.
    pub kind: JointKind,
}

/// Pairs of axes `(axis of i, axis of j)` kept perpendicular.
fn dot_pairs(kind: &JointKind) -> &'static [(usize, usize)] {
    match kind {
        JointKind::Fixed => &[(0, 1), (0, 2), (1, 2)],
        JointKind::Revolute => &[(2, 0), (2, 1)],
        _ => &[],
    }
}

impl Joint {
    /// Number of constraint equations.
    pub fn n_equations(&self) -> usize {
        match self.kind {
            JointKind::Trajectory(_) => 1,
            _ => 3 + dot_pairs(&self.kind).len(),
        }
    }

    /// Constraint residuals and, when `jac` is given, their Jacobian rows with respect
    /// to `[r_i, p_i, r_j, p_j]` (14 columns; the columns of a ground side are ignored).
    pub fn evaluate(&self, t: f64, si: &BodyState, sj: &BodyState, c: &mut [f64], mut jac: Option<&mut [[f64; 14]]>) {
        if let JointKind::Trajectory(drv) = &self.kind {
            let st = drv.station(t);
            let frame = drv.track.frame(st);
            let tan = frame.tangent();
            c[0] = tan.dot(&(si.point(&self.point_i) - frame.origin));
            if let Some(j) = jac.as_deref_mut() {
                let dp = tan.transpose() * d_rotate(&si.params, &self.point_i);
                j[0] = [0.0; 14];
                for k in 0..3 {
                    j[0][k] = tan[k];
                }
                for k in 0..4 {
                    j[0][3 + k] = dp[k];
                }
            }
            return;
        }
        let d = si.point(&self.point_i) - sj.point(&self.point_j);
        c[..3].copy_from_slice(d.as_slice());
        if let Some(j) = jac.as_deref_mut() {
            let bi = d_rotate(&si.params, &self.point_i);
            let bj = d_rotate(&sj.params, &self.point_j);
            for r in 0..3 {
                j[r] = [0.0; 14];
                j[r][r] = 1.0;
                j[r][7 + r] = -1.0;
                for k in 0..4 {
                    j[r][3 + k] = bi[(r, k)];
                    j[r][10 + k] = -bj[(r, k)];
                }
            }
        }
        for (e, &(ai, aj)) in dot_pairs(&self.kind).iter().enumerate() {
            let fi: Vector3<f64> = self.frame_i.column(ai).into();
            let fj: Vector3<f64> = self.frame_j.column(aj).into();
            let (gi, gj) = (si.rotation * fi, sj.rotation * fj);
            c[3 + e] = gi.dot(&gj);
            if let Some(j) = jac.as_deref_mut() {
                let di = gj.transpose() * d_rotate(&si.params, &fi);
                let dj = gi.transpose() * d_rotate(&sj.params, &fj);
                let row = &mut j[3 + e];
                *row = [0.0; 14];
                for k in 0..4 {
                    row[3 + k] = di[k];
                    row[10 + k] = dj[k];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mbs::rotation::{axis_angle, from_rotation, rotation};
    use crate::track::TrackPoint;
    use nalgebra::Vector4;

    fn state(r: Vector3<f64>, p: Vector4<f64>) -> BodyState {
        BodyState {
            position: r,
            params: p,
            rotation: rotation(&p),
            velocity: Vector3::zeros(),
            angular_velocity: Vector3::zeros(),
        }
    }

    fn joints() -> Vec<Joint> {
        let track = Arc::new(
            Track::new(vec![
                TrackPoint::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
                TrackPoint::new(100.0, 0.01, 0.05, 0.0, 0.0, 0.0),
            ])
            .unwrap(),
        );
        let kinds = [
            JointKind::Fixed,
            JointKind::Revolute,
            JointKind::Spherical,
            JointKind::Trajectory(TrajectoryDriver { track, s0: 20.0, speed: SpeedProfile::Constant(10.0) }),
        ];
        kinds
            .into_iter()
            .map(|kind| Joint {
                name: "j".into(),
                body_i: None,
                body_j: None,
                point_i: Vector3::new(0.3, -0.2, 0.5),
                point_j: Vector3::new(-0.4, 0.1, 0.2),
                frame_i: axis_angle(&Vector3::new(1.0, 0.3, 0.2), 0.4),
                frame_j: axis_angle(&Vector3::new(-0.2, 1.0, 0.5), 0.9),
                kind,
            })
            .collect()
    }

    #[test]
    fn constraint_jacobians_match_finite_differences() {
        let qi = [1.0, 2.0, 0.5, 0.0, 0.0, 0.0, 0.0];
        let mut q = [0.0; 14];
        let pi = from_rotation(&axis_angle(&Vector3::new(0.2, 0.5, 1.0), 0.6)) * 1.01; // off the unit sphere
        let pj = from_rotation(&axis_angle(&Vector3::new(1.0, -0.5, 0.3), -0.8));
        q[..3].copy_from_slice(&qi[..3]);
        q[3..7].copy_from_slice(pi.as_slice());
        q[7..10].copy_from_slice(&[1.3, 1.9, 0.1]);
        q[10..14].copy_from_slice(pj.as_slice());
        let states = |q: &[f64; 14]| {
            (
                state(Vector3::new(q[0], q[1], q[2]), Vector4::new(q[3], q[4], q[5], q[6])),
                state(Vector3::new(q[7], q[8], q[9]), Vector4::new(q[10], q[11], q[12], q[13])),
            )
        };
        for joint in joints() {
            let n = joint.n_equations();
            let (si, sj) = states(&q);
            let mut c = vec![0.0; n];
            let mut jac = vec![[0.0; 14]; n];
            joint.evaluate(1.3, &si, &sj, &mut c, Some(&mut jac));
            let traj = matches!(joint.kind, JointKind::Trajectory(_));
            for k in 0..if traj { 7 } else { 14 } {
                let h = 1e-6;
                let (mut qp, mut qm) = (q, q);
                qp[k] += h;
                qm[k] -= h;
                let (mut cp, mut cm) = (vec![0.0; n], vec![0.0; n]);
                let (a, b) = states(&qp);
                joint.evaluate(1.3, &a, &b, &mut cp, None);
                let (a, b) = states(&qm);
                joint.evaluate(1.3, &a, &b, &mut cm, None);
                for r in 0..n {
                    let fd = (cp[r] - cm[r]) / (2.0 * h);
                    assert!((fd - jac[r][k]).abs() < 1e-8, "{:?} row {r} col {k}: {fd} vs {}", joint.kind, jac[r][k]);
                }
            }
        }
    }

    #[test]
    fn speed_table_distance_is_the_exact_integral() {
        let p = SpeedProfile::Table { times: vec![0.0, 10.0], speeds: vec![40.0 / 3.6, 5.0 / 3.6] };
        let d = p.distance(10.0);
        assert!((d - 0.5 * (45.0 / 3.6) * 10.0).abs() < 1e-12);
        assert!((p.distance(12.0) - d - 2.0 * 5.0 / 3.6).abs() < 1e-12);
        assert!((p.speed(5.0) - 22.5 / 3.6).abs() < 1e-12);
        assert!(SpeedProfile::Table { times: vec![0.0, 0.0], speeds: vec![1.0, 2.0] }.validate().is_err());
    }
}
