//! Force elements: point-to-point spring–damper–actuators (linear or tabulated),
//! bushings (translational and rotational stiffness and damping in a body frame) and
//! brake torques on wheelsets.
//!
//! A force element acts between body `i` and body `j` (either may be the ground) and
//! returns the force and moment on each body about its origin, in global coordinates
//! ([`Wrench`]). The multibody system turns wrenches into generalized forces and gets
//! their Jacobians by finite differences (see [`Multibody`](super::Multibody)).

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use super::body::{Attachment, BodyState};
use ancf_core::error::{AncfError, invalid};

/// Force and moment on a body, about its origin (centre of mass), global frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Wrench {
    /// Force, N.
    pub force: Vector3<f64>,
    /// Moment about the body origin, N·m.
    pub moment: Vector3<f64>,
}

impl Wrench {
    /// Force `f` applied at the global offset `arm` from the body origin.
    pub fn at(f: Vector3<f64>, arm: Vector3<f64>) -> Self {
        Self { force: f, moment: arm.cross(&f) }
    }
}

/// A force element between two attachments.
pub trait ForceElement: Send + std::fmt::Debug {
    /// Name used in errors and results.
    fn name(&self) -> &str;
    /// The two bodies (ground = `None`).
    fn bodies(&self) -> [Attachment; 2];
    /// Wrenches on body `i` and body `j` at time `t`.
    fn wrenches(&self, t: f64, si: &BodyState, sj: &BodyState) -> [Wrench; 2];
    /// A scalar summary for results (e.g. the tension of a spring, the torque of a
    /// brake), SI units.
    fn output(&self, t: f64, si: &BodyState, sj: &BodyState) -> f64;
}

/// A piecewise-linear function `y(x)`, held constant outside its table.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// Abscissae (strictly increasing).
    pub x: Vec<f64>,
    /// Ordinates.
    pub y: Vec<f64>,
}

impl Table {
    /// Builds and checks a table; `field` names it in errors.
    pub fn new(field: &str, x: Vec<f64>, y: Vec<f64>) -> Result<Self, AncfError> {
        if x.is_empty() || x.len() != y.len() {
            return Err(invalid(field, x.len(), "non-empty, x and y of equal length"));
        }
        if x.windows(2).any(|w| w[1] <= w[0]) || x.iter().chain(&y).any(|v| !v.is_finite()) {
            return Err(invalid(field, format!("{x:?}"), "finite values, x strictly increasing"));
        }
        Ok(Self { x, y })
    }

    /// Value at `x`.
    pub fn eval(&self, x: f64) -> f64 {
        let k = self.x.partition_point(|&v| v <= x);
        if k == 0 {
            return self.y[0];
        }
        if k >= self.x.len() {
            return self.y[self.y.len() - 1];
        }
        let w = (x - self.x[k - 1]) / (self.x[k] - self.x[k - 1]);
        self.y[k - 1] + w * (self.y[k] - self.y[k - 1])
    }
}

/// Force law of a [`SpringDamper`]: tension as a function of extension `δ = l − l₀` and
/// its rate.
#[derive(Debug, Clone, PartialEq)]
pub enum SpringLaw {
    /// `f = k δ + c δ̇`.
    Linear {
        /// Stiffness, N/m.
        stiffness: f64,
        /// Damping, N·s/m.
        damping: f64,
    },
    /// `f = table(δ) + c δ̇` (nonlinear spring, e.g. draft gear).
    Table {
        /// Tension (N) against extension (m).
        force: Table,
        /// Damping, N·s/m.
        damping: f64,
    },
}

/// Point-to-point spring–damper–actuator. Tension is positive and pulls the two points
/// together: `f = law(l − l₀, l̇) + f_act(t)`.
#[derive(Debug, Clone)]
pub struct SpringDamper {
    /// Name.
    pub name: String,
    /// Bodies.
    pub bodies: [Attachment; 2],
    /// Attachment points in each body's frame, m.
    pub points: [Vector3<f64>; 2],
    /// Free length `l₀`, m (> 0).
    pub free_length: f64,
    /// Force law.
    pub law: SpringLaw,
    /// Actuator tension against time (N against s), if any.
    pub actuator: Option<Table>,
}

impl SpringDamper {
    /// Coupler defaults of seed 000 §8.2: k = 300 MN/m, c = 200 kN·s/m.
    pub const COUPLER_STIFFNESS: f64 = 300e6;
    /// See [`SpringDamper::COUPLER_STIFFNESS`].
    pub const COUPLER_DAMPING: f64 = 200e3;

    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), AncfError> {
        let f = |x: &str| format!("{} {x}", self.name);
        if !(self.free_length.is_finite() && self.free_length > 0.0) {
            return Err(invalid(&f("free_length"), self.free_length, "finite, > 0 m"));
        }
        let (k, c) = match &self.law {
            SpringLaw::Linear { stiffness, damping } => (*stiffness, *damping),
            SpringLaw::Table { damping, .. } => (0.0, *damping),
        };
        if !(k.is_finite() && k >= 0.0) {
            return Err(invalid(&f("stiffness"), k, "finite, >= 0 N/m"));
        }
        if !(c.is_finite() && c >= 0.0) {
            return Err(invalid(&f("damping"), c, "finite, >= 0 N s/m"));
        }
        Ok(())
    }

    fn geometry(&self, si: &BodyState, sj: &BodyState) -> (Vector3<f64>, f64, f64, [Vector3<f64>; 2]) {
        let ai = si.rotation * self.points[0];
        let aj = sj.rotation * self.points[1];
        let d = sj.position + aj - si.position - ai;
        let l = d.norm().max(1e-12);
        let u = d / l;
        let ld = u.dot(&(sj.point_velocity(&self.points[1]) - si.point_velocity(&self.points[0])));
        (u, l, ld, [ai, aj])
    }

    fn tension(&self, t: f64, l: f64, ld: f64) -> f64 {
        let ext = l - self.free_length;
        let f = match &self.law {
            SpringLaw::Linear { stiffness, damping } => stiffness * ext + damping * ld,
            SpringLaw::Table { force, damping } => force.eval(ext) + damping * ld,
        };
        f + self.actuator.as_ref().map_or(0.0, |a| a.eval(t))
    }
}

impl ForceElement for SpringDamper {
    fn name(&self) -> &str {
        &self.name
    }
    fn bodies(&self) -> [Attachment; 2] {
        self.bodies
    }
    fn wrenches(&self, t: f64, si: &BodyState, sj: &BodyState) -> [Wrench; 2] {
        let (u, l, ld, [ai, aj]) = self.geometry(si, sj);
        let f = self.tension(t, l, ld) * u;
        [Wrench::at(f, ai), Wrench::at(-f, aj)]
    }
    fn output(&self, t: f64, si: &BodyState, sj: &BodyState) -> f64 {
        let (_, l, ld, _) = self.geometry(si, sj);
        self.tension(t, l, ld)
    }
}

/// Bushing: linear translational and rotational springs and dampers acting in a frame
/// fixed in body `i`.
///
/// With `R = A_i F_i` the bushing axes (global) and `d = Rᵀ(p_j − p_i) − d₀` the
/// deflection of point `j` from point `i` in those axes, the force on body `j` (at its
/// point) is `R (−K d − C ḋ + f₀)` and body `i` receives the opposite (at its point),
/// with `ḋ = Rᵀ(ṗ_j − ṗ_i)`. The rotational part uses the small relative rotation
/// `θ = ½ Σ_k a_ik × a_jk` of the aligned axes, or only the tilt `a_ik × a_jk` of axis
/// `k` when rotation about it is free (journal bearings and axle boxes of spinning
/// wheelsets). `f₀` is a preload (e.g. the static share of the car weight a suspension
/// spring carries at its reference length).
#[derive(Debug, Clone)]
pub struct Bushing {
    /// Name.
    pub name: String,
    /// Bodies.
    pub bodies: [Attachment; 2],
    /// Attachment points in each body's frame, m.
    pub points: [Vector3<f64>; 2],
    /// Bushing axes (columns) in body `i` coordinates.
    pub frame_i: Matrix3<f64>,
    /// The same axes in body `j` coordinates (aligned at assembly).
    pub frame_j: Matrix3<f64>,
    /// Reference deflection `d₀` (bushing axes), m.
    pub offset: Vector3<f64>,
    /// Translational stiffness along the bushing axes, N/m.
    pub stiffness: [f64; 3],
    /// Translational damping, N·s/m.
    pub damping: [f64; 3],
    /// Preload on body `j` along the bushing axes at zero deflection, N.
    pub preload: Vector3<f64>,
    /// Rotational stiffness about the bushing axes, N·m/rad.
    pub rotational_stiffness: [f64; 3],
    /// Rotational damping, N·m·s/rad.
    pub rotational_damping: [f64; 3],
    /// Axis (0, 1, 2) about which relative rotation is free, if any.
    pub free_axis: Option<usize>,
    /// Full 6×6 stiffness on `[d; θ]` → `[F; M]` (bushing axes), replacing the diagonal
    /// values when given (N/m, N, N·m/rad blocks).
    pub matrix_stiffness: Option<Matrix6<f64>>,
    /// Full 6×6 damping on `[ḋ; ω_rel]`, replacing the diagonal values when given.
    pub matrix_damping: Option<Matrix6<f64>>,
}

impl Bushing {
    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), AncfError> {
        let groups = [
            ("stiffness", self.stiffness),
            ("damping", self.damping),
            ("rotational_stiffness", self.rotational_stiffness),
            ("rotational_damping", self.rotational_damping),
        ];
        for (label, vals) in groups {
            if let Some(v) = vals.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
                return Err(invalid(&format!("{} {label}", self.name), v, "finite, >= 0"));
            }
        }
        for (label, m) in [("matrix_stiffness", &self.matrix_stiffness), ("matrix_damping", &self.matrix_damping)] {
            if let Some(m) = m
                && m.iter().any(|v| !v.is_finite())
            {
                return Err(invalid(&format!("{} {label}", self.name), "non-finite entry", "finite"));
            }
        }
        if let Some(k) = self.free_axis.filter(|&k| k > 2) {
            return Err(invalid(&format!("{} free_axis", self.name), k, "0, 1 or 2"));
        }
        Ok(())
    }

    /// Local force and moment on body `j` (bushing axes) and the global axes: with
    /// `u = [d; θ]`, `u̇ = [ḋ; ω_j − ω_i]` (bushing axes) the load is `−K u − C u̇ + [f₀; 0]`,
    /// where `K`, `C` are the full 6×6 matrices when given, else the diagonal values.
    fn local_load(&self, si: &BodyState, sj: &BodyState) -> (Vector3<f64>, Vector3<f64>, Matrix3<f64>) {
        let r = si.rotation * self.frame_i;
        let rj = sj.rotation * self.frame_j;
        let d = r.transpose() * (sj.point(&self.points[1]) - si.point(&self.points[0])) - self.offset;
        let dd = r.transpose() * (sj.point_velocity(&self.points[1]) - si.point_velocity(&self.points[0]));
        let theta = match self.free_axis {
            Some(k) => r.column(k).cross(&rj.column(k)),
            None => 0.5 * (0..3).map(|k| r.column(k).cross(&rj.column(k))).sum::<Vector3<f64>>(),
        };
        let mut th = r.transpose() * theta;
        let mut w = r.transpose() * (sj.angular_velocity - si.angular_velocity);
        if let Some(k) = self.free_axis {
            th[k] = 0.0;
            w[k] = 0.0;
        }
        let u = Vector6::new(d[0], d[1], d[2], th[0], th[1], th[2]);
        let ud = Vector6::new(dd[0], dd[1], dd[2], w[0], w[1], w[2]);
        let diag =
            |t: [f64; 3], rr: [f64; 3]| Matrix6::from_diagonal(&Vector6::new(t[0], t[1], t[2], rr[0], rr[1], rr[2]));
        let k = self.matrix_stiffness.unwrap_or_else(|| diag(self.stiffness, self.rotational_stiffness));
        let c = self.matrix_damping.unwrap_or_else(|| diag(self.damping, self.rotational_damping));
        let mut load = -(k * u) - c * ud;
        if let Some(a) = self.free_axis {
            load[3 + a] = 0.0;
        }
        let f = Vector3::new(load[0], load[1], load[2]) + self.preload;
        (f, Vector3::new(load[3], load[4], load[5]), r)
    }
}

impl ForceElement for Bushing {
    fn name(&self) -> &str {
        &self.name
    }
    fn bodies(&self) -> [Attachment; 2] {
        self.bodies
    }
    fn wrenches(&self, _t: f64, si: &BodyState, sj: &BodyState) -> [Wrench; 2] {
        let (fl, ml, r) = self.local_load(si, sj);
        let (f, m) = (r * fl, r * ml);
        let mut wj = Wrench::at(f, sj.rotation * self.points[1]);
        let mut wi = Wrench::at(-f, si.rotation * self.points[0]);
        wj.moment += m;
        wi.moment -= m;
        [wi, wj]
    }
    fn output(&self, _t: f64, si: &BodyState, sj: &BodyState) -> f64 {
        self.local_load(si, sj).0.norm()
    }
}

/// Brake torque on a wheelset, opposing its spin relative to the body that carries the
/// brake rigging (the reaction acts on that body).
///
/// `M = −T(t) tanh(ω_rel / ω_s) a` with `a` the axle axis and `ω_rel` the relative
/// spin; `ω_s` smooths the sign change so that a stopped wheelset is not chattered.
#[derive(Debug, Clone)]
pub struct BrakeTorque {
    /// Name.
    pub name: String,
    /// The wheelset, and the body carrying the reaction (ground = none).
    pub bodies: [Attachment; 2],
    /// Axle axis in the wheelset frame (unit).
    pub axis: Vector3<f64>,
    /// Torque magnitude against time, N·m against s.
    pub torque: Table,
    /// Spin-rate scale `ω_s` of the sign smoothing, rad/s.
    pub smoothing: f64,
    /// Optional factor on the torque against the wheelset's forward speed (m/s), e.g.
    /// the speed dependence of the shoe friction coefficient; `T = T(t) · φ(V)`.
    pub speed_factor: Option<Table>,
}

impl BrakeTorque {
    fn moment_on_wheelset(&self, t: f64, si: &BodyState, sj: &BodyState) -> Vector3<f64> {
        let a = si.rotation * self.axis;
        let w_rel = (si.angular_velocity - sj.angular_velocity).dot(&a);
        let phi = self.speed_factor.as_ref().map_or(1.0, |f| f.eval(si.velocity.norm()));
        -self.torque.eval(t) * phi * (w_rel / self.smoothing).tanh() * a
    }
}

impl ForceElement for BrakeTorque {
    fn name(&self) -> &str {
        &self.name
    }
    fn bodies(&self) -> [Attachment; 2] {
        self.bodies
    }
    fn wrenches(&self, t: f64, si: &BodyState, sj: &BodyState) -> [Wrench; 2] {
        let m = self.moment_on_wheelset(t, si, sj);
        [Wrench { force: Vector3::zeros(), moment: m }, Wrench { force: Vector3::zeros(), moment: -m }]
    }
    fn output(&self, t: f64, si: &BodyState, sj: &BodyState) -> f64 {
        self.moment_on_wheelset(t, si, sj).norm()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mbs::rotation::{axis_angle, from_rotation};

    fn st(r: Vector3<f64>, a: Matrix3<f64>, v: Vector3<f64>, w: Vector3<f64>) -> BodyState {
        BodyState { position: r, params: from_rotation(&a), rotation: a, velocity: v, angular_velocity: w }
    }

    /// Internal force elements obey action = reaction: total force and total moment
    /// about the origin vanish (the bushing up to the moment of the pair of forces over
    /// the deflection, which is exact here since the points coincide).
    fn check_balance(e: &dyn ForceElement, si: &BodyState, sj: &BodyState) {
        let [wi, wj] = e.wrenches(0.5, si, sj);
        assert!((wi.force + wj.force).norm() < 1e-9 * (1.0 + wi.force.norm()));
        let m = wi.moment + si.position.cross(&wi.force) + wj.moment + sj.position.cross(&wj.force);
        assert!(m.norm() < 1e-9 * (1.0 + wi.force.norm() + wi.moment.norm()), "{m}");
    }

    #[test]
    fn spring_damper_tension_and_balance() {
        let s = SpringDamper {
            name: "coupler".into(),
            bodies: [None, None],
            points: [Vector3::new(1.0, 0.0, 0.0), Vector3::new(-1.0, 0.0, 0.0)],
            free_length: 1.0,
            law: SpringLaw::Linear { stiffness: 100.0, damping: 10.0 },
            actuator: Some(Table::new("actuator", vec![0.0, 1.0], vec![0.0, 20.0]).unwrap()),
        };
        let si = st(Vector3::zeros(), Matrix3::identity(), Vector3::zeros(), Vector3::zeros());
        let sj = st(Vector3::new(3.5, 0.0, 0.0), Matrix3::identity(), Vector3::new(0.2, 0.0, 0.0), Vector3::zeros());
        // l = 1.5, extension 0.5, rate 0.2, actuator 10 → 50 + 2 + 10.
        assert!((s.output(0.5, &si, &sj) - 62.0).abs() < 1e-12);
        let [wi, _] = s.wrenches(0.5, &si, &sj);
        assert!((wi.force.x - 62.0).abs() < 1e-12, "tension pulls body i forward");
        let sj = st(
            Vector3::new(2.0, 0.5, -0.3),
            axis_angle(&Vector3::new(0.1, 0.2, 1.0), 0.4),
            Vector3::new(0.1, 0.3, 0.0),
            Vector3::new(0.0, 0.5, 0.2),
        );
        check_balance(&s, &si, &sj);
    }

    #[test]
    fn bushing_restores_and_balances() {
        let b = Bushing {
            name: "primary".into(),
            bodies: [None, None],
            points: [Vector3::new(0.0, 1.0, 0.0), Vector3::new(0.0, 1.0, 0.0)],
            frame_i: Matrix3::identity(),
            frame_j: Matrix3::identity(),
            offset: Vector3::zeros(),
            stiffness: [1e6, 2e6, 3e6],
            damping: [1e3, 1e3, 1e3],
            preload: Vector3::new(0.0, 0.0, 5e3),
            rotational_stiffness: [1e4, 2e4, 3e4],
            rotational_damping: [0.0; 3],
            free_axis: None,
            matrix_stiffness: None,
            matrix_damping: None,
        };
        let si = st(Vector3::zeros(), Matrix3::identity(), Vector3::zeros(), Vector3::zeros());
        let sj = st(Vector3::new(0.0, 0.0, 1e-3), Matrix3::identity(), Vector3::zeros(), Vector3::zeros());
        let [_, wj] = b.wrenches(0.0, &si, &sj);
        assert!((wj.force.z - (5e3 - 3e3)).abs() < 1e-9);
        // A small rotation about z of body j is resisted by k_z θ.
        let sj = st(Vector3::zeros(), axis_angle(&Vector3::z(), 1e-4), Vector3::zeros(), Vector3::zeros());
        let [_, wj] = b.wrenches(0.0, &si, &sj);
        let f = wj.force; // the point moved by θ × (0, 1, 0) = (−1e-4, 0, 0)
        assert!((f.x - 1e6 * 1e-4).abs() < 1e-3);
        let m_rot = wj.moment - (sj.rotation * b.points[1]).cross(&f);
        assert!((m_rot.z + 3e4 * 1e-4).abs() < 1e-6, "{m_rot}");
        let mut free = b.clone();
        free.free_axis = Some(2);
        let [_, wj] = free.wrenches(0.0, &si, &sj);
        assert!((wj.moment - (sj.rotation * b.points[1]).cross(&wj.force)).norm() < 1e-12);
        let sj = st(
            Vector3::new(1e-3, -2e-3, 5e-4),
            axis_angle(&Vector3::new(1.0, 1.0, 0.2), 3e-3),
            Vector3::new(0.1, 0.0, 0.0),
            Vector3::new(0.0, 0.1, 0.0),
        );
        let [wi, wj] = b.wrenches(0.0, &si, &sj);
        assert!((wi.force + wj.force).norm() < 1e-9);
        // A full 6×6 stiffness couples directions: K[1][2] = 5e5 gives a lateral force from a
        // vertical deflection, and equals the diagonal form when diagonal.
        let mut full = b.clone();
        let mut k6 = Matrix6::from_diagonal(&Vector6::new(1e6, 2e6, 3e6, 1e4, 2e4, 3e4));
        let c6 = Matrix6::from_diagonal(&Vector6::new(1e3, 1e3, 1e3, 0.0, 0.0, 0.0));
        full.matrix_stiffness = Some(k6);
        full.matrix_damping = Some(c6);
        let [a, bb] = full.wrenches(0.0, &si, &sj);
        assert!((a.force - wi.force).norm() < 1e-9 && (bb.moment - wj.moment).norm() < 1e-9);
        k6[(1, 2)] = 5e5;
        full.matrix_stiffness = Some(k6);
        let sz = st(Vector3::new(0.0, 0.0, 1e-3), Matrix3::identity(), Vector3::zeros(), Vector3::zeros());
        let [_, wz] = full.wrenches(0.0, &si, &sz);
        assert!((wz.force.y + 5e5 * 1e-3).abs() < 1e-9, "{}", wz.force);
        // Total moment about the global origin: the couple of the force pair over the deflection.
        let total = wi.moment + si.position.cross(&wi.force) + wj.moment + sj.position.cross(&wj.force);
        let couple = (sj.point(&b.points[1]) - si.point(&b.points[0])).cross(&wj.force);
        assert!((total - couple).norm() < 1e-9 * wj.force.norm(), "{total} vs {couple}");
    }

    #[test]
    fn brake_opposes_spin_and_table_interpolates() {
        let t = Table::new("torque", vec![0.0, 2.0], vec![0.0, 1000.0]).unwrap();
        assert_eq!(t.eval(1.0), 500.0);
        assert_eq!(t.eval(5.0), 1000.0);
        assert!(Table::new("torque", vec![1.0, 0.0], vec![0.0, 0.0]).is_err());
        let mut b = BrakeTorque {
            name: "brake".into(),
            bodies: [None, None],
            axis: Vector3::y(),
            torque: t,
            smoothing: 0.1,
            speed_factor: None,
        };
        let si = st(Vector3::zeros(), Matrix3::identity(), Vector3::zeros(), Vector3::new(0.0, 20.0, 0.0));
        let sj = st(Vector3::zeros(), Matrix3::identity(), Vector3::zeros(), Vector3::zeros());
        let [wi, wj] = b.wrenches(2.0, &si, &sj);
        assert!((wi.moment.y + 1000.0).abs() < 1e-6 && (wj.moment.y - 1000.0).abs() < 1e-6);
        // A speed factor scales it: half the torque at 10 m/s.
        b.speed_factor = Some(Table::new("speed_factor", vec![0.0, 20.0], vec![1.0, 0.0]).unwrap());
        let si = st(Vector3::zeros(), Matrix3::identity(), Vector3::new(10.0, 0.0, 0.0), Vector3::new(0.0, 20.0, 0.0));
        let [wi, _] = b.wrenches(2.0, &si, &sj);
        assert!((wi.moment.y + 500.0).abs() < 1e-6);
    }
}
