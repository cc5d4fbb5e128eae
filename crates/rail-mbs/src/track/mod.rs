//! Track geometry built from a segment table.
//!
//! # Input
//!
//! A track is described, like Table 1 of the tank-car paper (seed 000), by a list of
//! [`TrackPoint`]s: distance along the track, signed curvature, signed super-elevation,
//! grade and the cant (inclination) of the right and left rails. Curvature,
//! super-elevation, grade and cant vary **linearly** in distance between two points, so
//! a change of curvature between two points is a clothoid spiral (linear curvature),
//! exactly as in the usual railway segment tables. Points may be given in SI units
//! ([`TrackPoint::new`]) or in US units ([`TrackPoint::from_us`]: feet, degrees of
//! curvature with the *arc* definition `R = 5729.58 / D` ft, inches, percent).
//!
//! # Frames and sign conventions
//!
//! * Global frame: `X`, `Y` horizontal, `Z` up. The track starts at the origin with
//!   heading along `+X` unless [`Track::with_origin`] says otherwise.
//! * Track frame at distance `s` ([`TrackFrame`]): `x` = unit tangent in the direction
//!   of increasing `s`, `y` = to the **left** (looking along `+x`), `z` = **up**,
//!   right-handed (`z = x × y`). The frame is pitched by the grade and rolled by the
//!   super-elevation.
//! * `s` is the true 3-D arc length of the centreline (the grade is included).
//! * **Curvature is positive for a curve to the left** (heading increases). Curvature is
//!   the rate of change of heading per unit arc length, `dψ/ds`.
//! * **Super-elevation is positive when the right rail is raised**; it is the height
//!   difference between the rails, measured over the base [`Track::cant_base`]. In a left
//!   curve (positive curvature) the outer rail is the right rail, so a normal
//!   (non-adverse) super-elevation has the same sign as the curvature. Table 1 of seed 000
//!   follows exactly that rule (+3°/+3 in, then −3°/−3 in).
//! * **Grade** is rise over horizontal run (a fraction, `0.01` = 1 %), positive climbing
//!   in the direction of increasing `s`.
//! * **Rail cant** (the 1:40 or 1:20 inward inclination of the rail seat) is stored as in
//!   Table 1, where the right rail has `+0.025` rad and the left rail `−0.025` rad, i.e.
//!   both rails inclined *inward* (towards the track centre). The inward angle of the right
//!   rail is therefore `cant_right` and that of the left rail `−cant_left`
//!   ([`Track::rail_inward_cant`]). In the track frame (x forward, y left, z up) the
//!   profile frame of a rail is rotated about `x` by `+inward` for the left rail and
//!   `−inward` for the right rail ([`Track::rail_frame`]).
//! * The centreline is the midpoint between the two rail gauge lines; the rail gauge lines
//!   lie at `±gauge/2` along the track-frame `y` axis ([`Track::rail_point`]).
//!
//! Outside the table the last (or first) curvature, super-elevation, grade and cant are
//! held constant.
//!
//! # Numerics
//!
//! The heading is integrated in closed form (piecewise quadratic). The position is the
//! integral of the unit tangent, evaluated with 5-point Gauss–Legendre quadrature on
//! sub-intervals no longer than [`Track::MAX_SUBINTERVAL`], tabulated once at
//! construction; a query integrates from the nearest tabulated node.

use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};
use thiserror::Error;

pub mod irregularity;
pub mod presets;
pub use irregularity::{Channel, Defect, Irregularity, IrregularityPsd, TrackSpectrum};

pub use ancf_core::constants::{FOOT, GRAVITY, INCH, MPH};
/// Radius, in feet, of a 1° curve with the arc definition (100 ft of arc per degree).
pub const ARC_DEGREE_RADIUS_FT: f64 = 5_729.577_951_308_232;

/// Errors raised when a track is built or queried.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TrackError {
    /// Fewer than two points were given.
    #[error("a track needs at least two points, got {0}")]
    TooFewPoints(usize),
    /// Distances must be strictly increasing.
    #[error("track point {index}: distance {s} m is not greater than the previous one")]
    NotIncreasing {
        /// Index of the offending point.
        index: usize,
        /// Its distance, m.
        s: f64,
    },
    /// A value is NaN or infinite.
    #[error("track point {index}: non-finite value in field `{field}`")]
    NonFinite {
        /// Index of the offending point.
        index: usize,
        /// Field name.
        field: &'static str,
    },
    /// A super-elevation larger than the cant base.
    #[error("track point {index}: |super-elevation| {e} m is not smaller than the cant base {base} m")]
    SuperElevationTooLarge {
        /// Index of the offending point.
        index: usize,
        /// Super-elevation, m.
        e: f64,
        /// Cant base, m.
        base: f64,
    },
    /// A non-positive gauge or cant base.
    #[error("gauge and cant base must be positive (gauge {gauge} m, cant base {base} m)")]
    BadGauge {
        /// Gauge, m.
        gauge: f64,
        /// Cant base, m.
        base: f64,
    },
    /// Projection of a point onto the centreline did not converge.
    #[error("projection onto the track did not converge (last s = {s} m)")]
    ProjectionFailed {
        /// Last iterate, m.
        s: f64,
    },
}

/// One row of a track segment table, in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackPoint {
    /// Distance along the track, m.
    pub s: f64,
    /// Signed curvature, 1/m (positive = curve to the left).
    pub curvature: f64,
    /// Signed super-elevation, m (positive = right rail raised).
    pub superelevation: f64,
    /// Grade as a fraction (rise/run), positive climbing.
    pub grade: f64,
    /// Right rail cant, rad, Table 1 convention (positive = inward).
    pub cant_right: f64,
    /// Left rail cant, rad, Table 1 convention (negative = inward).
    pub cant_left: f64,
}

impl TrackPoint {
    /// A point in SI units (m, 1/m, m, fraction, rad, rad).
    pub fn new(s: f64, curvature: f64, superelevation: f64, grade: f64, cant_right: f64, cant_left: f64) -> Self {
        Self { s, curvature, superelevation, grade, cant_right, cant_left }
    }

    /// A point in US units: distance in feet, degree of curvature (arc definition,
    /// `R = 5729.58 / D` ft, sign = direction, positive left), super-elevation in
    /// inches, grade in percent, cant angles in radians (Table 1 convention).
    pub fn from_us(
        distance_ft: f64,
        degree_of_curvature: f64,
        superelevation_in: f64,
        grade_percent: f64,
        cant_right: f64,
        cant_left: f64,
    ) -> Self {
        Self {
            s: distance_ft * FOOT,
            curvature: curvature_from_degree(degree_of_curvature),
            superelevation: superelevation_in * INCH,
            grade: grade_percent / 100.0,
            cant_right,
            cant_left,
        }
    }
}

/// Signed curvature (1/m) of a curve of `degrees` degree of curvature, arc definition.
pub fn curvature_from_degree(degrees: f64) -> f64 {
    degrees / (ARC_DEGREE_RADIUS_FT * FOOT)
}

/// Which rail (or wheel) of a track (or wheelset).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Side {
    /// Left, looking in the direction of increasing `s` (positive track `y`).
    Left,
    /// Right (negative track `y`).
    Right,
}

impl Side {
    /// `+1` for the left side, `−1` for the right side.
    pub fn sign(self) -> f64 {
        match self {
            Side::Left => 1.0,
            Side::Right => -1.0,
        }
    }
}

/// Orthonormal track (or rail) frame at one position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackFrame {
    /// Origin, m (global frame).
    pub origin: Vector3<f64>,
    /// Columns are the frame axes `x` (tangent), `y` (left), `z` (up) in global
    /// coordinates; this is the rotation from frame to global coordinates.
    pub rotation: Matrix3<f64>,
}

impl TrackFrame {
    /// Unit tangent (direction of increasing `s`).
    pub fn tangent(&self) -> Vector3<f64> {
        self.rotation.column(0).into()
    }
    /// Unit lateral axis (to the left).
    pub fn lateral(&self) -> Vector3<f64> {
        self.rotation.column(1).into()
    }
    /// Unit up axis.
    pub fn up(&self) -> Vector3<f64> {
        self.rotation.column(2).into()
    }
    /// Global coordinates of a point given in this frame.
    pub fn to_global(&self, local: &Vector3<f64>) -> Vector3<f64> {
        self.origin + self.rotation * local
    }
    /// Coordinates in this frame of a global point.
    pub fn to_local(&self, global: &Vector3<f64>) -> Vector3<f64> {
        self.rotation.transpose() * (global - self.origin)
    }
}

/// Result of projecting a point onto the track centreline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackProjection {
    /// Arc length of the foot point, m.
    pub s: f64,
    /// Lateral offset along the track-frame `y` (left positive), m.
    pub lateral: f64,
    /// Offset along the track-frame `z` (up positive), m.
    pub vertical: f64,
}

/// Nodes and weights of 5-point Gauss–Legendre quadrature on [-1, 1].
const GL5: [(f64, f64); 5] = [
    (0.0, 0.568_888_888_888_888_9),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

/// Track geometry: centreline, frames and rail curves from a segment table.
#[derive(Debug, Clone)]
pub struct Track {
    points: Vec<TrackPoint>,
    /// Heading at each table point, rad.
    heading_at_points: Vec<f64>,
    gauge: f64,
    cant_base: f64,
    origin: Vector3<f64>,
    heading0: f64,
    /// Tabulated nodes (s, position).
    nodes_s: Vec<f64>,
    nodes_r: Vec<Vector3<f64>>,
    /// Deviation of the rails from their design position ([`Track::with_irregularity`]).
    irregularity: Option<Arc<Irregularity>>,
}

impl Track {
    /// Longest quadrature sub-interval, m.
    pub const MAX_SUBINTERVAL: f64 = 5.0;
    /// Standard gauge, m.
    pub const STANDARD_GAUGE: f64 = 1.435;
    /// Default base over which super-elevation is measured (distance between the rail
    /// contact points), m.
    pub const DEFAULT_CANT_BASE: f64 = 1.5;

    /// Builds a track starting at the global origin, heading along `+X`, with standard
    /// gauge and a 1.5 m cant base.
    pub fn new(points: Vec<TrackPoint>) -> Result<Self, TrackError> {
        Self::with_options(points, Self::STANDARD_GAUGE, Self::DEFAULT_CANT_BASE, Vector3::zeros(), 0.0)
    }

    /// A straight, level track of `length` m from the global origin along `+X` (tangent
    /// track: no curvature, super-elevation, grade or rail cant).
    pub fn straight(length: f64) -> Result<Self, TrackError> {
        Self::new(vec![TrackPoint::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0), TrackPoint::new(length, 0.0, 0.0, 0.0, 0.0, 0.0)])
    }

    /// Builds a track with a given gauge and cant base (both m), start point and initial
    /// heading (rad, from `+X` towards `+Y`).
    pub fn with_options(
        points: Vec<TrackPoint>,
        gauge: f64,
        cant_base: f64,
        origin: Vector3<f64>,
        heading0: f64,
    ) -> Result<Self, TrackError> {
        if points.len() < 2 {
            return Err(TrackError::TooFewPoints(points.len()));
        }
        if !(gauge > 0.0 && cant_base > 0.0 && gauge.is_finite() && cant_base.is_finite()) {
            return Err(TrackError::BadGauge { gauge, base: cant_base });
        }
        for (i, p) in points.iter().enumerate() {
            let fields = [
                (p.s, "s"),
                (p.curvature, "curvature"),
                (p.superelevation, "superelevation"),
                (p.grade, "grade"),
                (p.cant_right, "cant_right"),
                (p.cant_left, "cant_left"),
            ];
            for (v, name) in fields {
                if !v.is_finite() {
                    return Err(TrackError::NonFinite { index: i, field: name });
                }
            }
            if i > 0 && p.s <= points[i - 1].s {
                return Err(TrackError::NotIncreasing { index: i, s: p.s });
            }
            if p.superelevation.abs() >= cant_base {
                return Err(TrackError::SuperElevationTooLarge { index: i, e: p.superelevation, base: cant_base });
            }
        }
        let mut heading_at_points = Vec::with_capacity(points.len());
        heading_at_points.push(heading0);
        for i in 1..points.len() {
            let (a, b) = (&points[i - 1], &points[i]);
            let l = b.s - a.s;
            heading_at_points.push(heading_at_points[i - 1] + 0.5 * (a.curvature + b.curvature) * l);
        }
        let mut track = Self {
            points,
            heading_at_points,
            gauge,
            cant_base,
            origin,
            heading0,
            nodes_s: Vec::new(),
            nodes_r: Vec::new(),
            irregularity: None,
        };
        track.tabulate();
        Ok(track)
    }

    /// Convenience: same as [`Track::with_options`] starting at `origin` with heading
    /// `heading0`, standard gauge and default cant base.
    pub fn with_origin(points: Vec<TrackPoint>, origin: Vector3<f64>, heading0: f64) -> Result<Self, TrackError> {
        Self::with_options(points, Self::STANDARD_GAUGE, Self::DEFAULT_CANT_BASE, origin, heading0)
    }

    fn tabulate(&mut self) {
        let s0 = self.points[0].s;
        let s_end = self.points.last().map(|p| p.s).unwrap_or(s0);
        let mut s = s0;
        let mut r = self.origin;
        self.nodes_s.push(s);
        self.nodes_r.push(r);
        // Sub-intervals never straddle a table point, so the integrand is smooth on each.
        for w in self.points.windows(2) {
            let (a, b) = (w[0].s, w[1].s);
            let n = ((b - a) / Self::MAX_SUBINTERVAL).ceil().max(1.0) as usize;
            let h = (b - a) / n as f64;
            for k in 0..n {
                let sa = a + h * k as f64;
                let sb = if k + 1 == n { b } else { sa + h };
                r += self.gauss_segment(sa, sb);
                s = sb;
                self.nodes_s.push(s);
                self.nodes_r.push(r);
            }
        }
        debug_assert!((s - s_end).abs() < 1e-9);
    }

    /// The table points.
    pub fn points(&self) -> &[TrackPoint] {
        &self.points
    }
    /// Track gauge, m.
    pub fn gauge(&self) -> f64 {
        self.gauge
    }
    /// Base over which super-elevation is measured, m.
    pub fn cant_base(&self) -> f64 {
        self.cant_base
    }
    /// First and last distance of the table, m.
    pub fn range(&self) -> (f64, f64) {
        (self.points[0].s, self.points[self.points.len() - 1].s)
    }

    /// Index `i` of the table interval containing `s` and the interpolation weight; outside
    /// the table returns the end interval with the weight clamped.
    fn locate(&self, s: f64) -> (usize, f64) {
        let n = self.points.len();
        if s <= self.points[0].s {
            return (0, 0.0);
        }
        if s >= self.points[n - 1].s {
            return (n - 2, 1.0);
        }
        let i = self.points.partition_point(|p| p.s <= s) - 1;
        let i = i.min(n - 2);
        let (a, b) = (&self.points[i], &self.points[i + 1]);
        (i, (s - a.s) / (b.s - a.s))
    }

    fn interp(&self, s: f64, f: impl Fn(&TrackPoint) -> f64) -> f64 {
        let (i, w) = self.locate(s);
        (1.0 - w) * f(&self.points[i]) + w * f(&self.points[i + 1])
    }

    /// Signed curvature at `s`, 1/m (positive = left).
    pub fn curvature(&self, s: f64) -> f64 {
        self.interp(s, |p| p.curvature)
    }
    /// Signed super-elevation at `s`, m (positive = right rail raised).
    pub fn superelevation(&self, s: f64) -> f64 {
        self.interp(s, |p| p.superelevation)
    }
    /// Grade at `s` (fraction, positive climbing).
    pub fn grade(&self, s: f64) -> f64 {
        self.interp(s, |p| p.grade)
    }
    /// Bank (roll) angle of the track frame about the tangent, rad: `−asin(e / base)`,
    /// negative when the right rail is raised.
    pub fn bank_angle(&self, s: f64) -> f64 {
        -(self.superelevation(s) / self.cant_base).asin()
    }
    /// Inward cant of one rail at `s`, rad (positive = rail head tilted towards the track
    /// centre), converted from the Table 1 convention.
    pub fn rail_inward_cant(&self, s: f64, side: Side) -> f64 {
        match side {
            Side::Right => self.interp(s, |p| p.cant_right),
            Side::Left => -self.interp(s, |p| p.cant_left),
        }
    }

    /// Heading (angle of the horizontal projection of the tangent from `+X`), rad.
    pub fn heading(&self, s: f64) -> f64 {
        let n = self.points.len();
        let p0 = &self.points[0];
        if s <= p0.s {
            return self.heading0 + p0.curvature * (s - p0.s);
        }
        let pl = &self.points[n - 1];
        if s >= pl.s {
            return self.heading_at_points[n - 1] + pl.curvature * (s - pl.s);
        }
        let (i, _) = self.locate(s);
        let (a, b) = (&self.points[i], &self.points[i + 1]);
        let l = b.s - a.s;
        let d = s - a.s;
        self.heading_at_points[i] + a.curvature * d + 0.5 * (b.curvature - a.curvature) / l * d * d
    }

    /// Unit tangent at `s` (global).
    pub fn tangent(&self, s: f64) -> Vector3<f64> {
        let psi = self.heading(s);
        let theta = self.grade(s).atan();
        Vector3::new(theta.cos() * psi.cos(), theta.cos() * psi.sin(), theta.sin())
    }

    /// Integral of the tangent over `[a, b]` with one Gauss–Legendre panel.
    fn gauss_segment(&self, a: f64, b: f64) -> Vector3<f64> {
        let half = 0.5 * (b - a);
        let mid = 0.5 * (a + b);
        let mut acc = Vector3::zeros();
        for (x, w) in GL5 {
            acc += self.tangent(mid + half * x) * w;
        }
        acc * half
    }

    /// Integral of the tangent over `[a, b]`, split at table points and into panels not
    /// longer than [`Track::MAX_SUBINTERVAL`].
    fn integrate(&self, a: f64, b: f64) -> Vector3<f64> {
        if a == b {
            return Vector3::zeros();
        }
        let (lo, hi, sign) = if a < b { (a, b, 1.0) } else { (b, a, -1.0) };
        let mut cuts = vec![lo];
        for p in &self.points {
            if p.s > lo && p.s < hi {
                cuts.push(p.s);
            }
        }
        cuts.push(hi);
        let mut acc = Vector3::zeros();
        for w in cuts.windows(2) {
            let n = ((w[1] - w[0]) / Self::MAX_SUBINTERVAL).ceil().max(1.0) as usize;
            let h = (w[1] - w[0]) / n as f64;
            for k in 0..n {
                let sa = w[0] + h * k as f64;
                acc += self.gauss_segment(sa, sa + h);
            }
        }
        acc * sign
    }

    /// Centreline position at arc length `s`, m (global).
    pub fn position(&self, s: f64) -> Vector3<f64> {
        let k = match self.nodes_s.binary_search_by(|x| x.partial_cmp(&s).unwrap_or(std::cmp::Ordering::Less)) {
            Ok(k) => return self.nodes_r[k],
            Err(0) => 0,
            Err(k) => k - 1,
        };
        self.nodes_r[k] + self.integrate(self.nodes_s[k], s)
    }

    /// Track frame at `s` (origin on the centreline, axes tangent/left/up, including
    /// grade and the roll from super-elevation).
    pub fn frame(&self, s: f64) -> TrackFrame {
        let psi = self.heading(s);
        let theta = self.grade(s).atan();
        let (sp, cp) = psi.sin_cos();
        let (st, ct) = theta.sin_cos();
        let t = Vector3::new(ct * cp, ct * sp, st);
        let l0 = Vector3::new(-sp, cp, 0.0);
        let u0 = Vector3::new(-st * cp, -st * sp, ct);
        let (sb, cb) = self.bank_angle(s).sin_cos();
        let l = l0 * cb + u0 * sb;
        let u = -l0 * sb + u0 * cb;
        TrackFrame { origin: self.position(s), rotation: Matrix3::from_columns(&[t, l, u]) }
    }

    /// The same track with the rails displaced by `irregularity` (module
    /// [`irregularity`]); the centreline and its frames stay the design ones.
    pub fn with_irregularity(mut self, irregularity: Irregularity) -> Self {
        self.irregularity = Some(Arc::new(irregularity));
        self
    }

    /// The rails' irregularity, if any.
    pub fn irregularity(&self) -> Option<&Irregularity> {
        self.irregularity.as_deref()
    }

    /// Offset of one rail from its design position at `s`, (lateral, vertical) in the
    /// track frame, m: zero on a perfect track ([`Irregularity::rail_offset`]).
    pub fn rail_offset(&self, s: f64, side: Side) -> (f64, f64) {
        self.irregularity.as_ref().map_or((0.0, 0.0), |irr| irr.rail_offset(s, side))
    }

    /// Point of the gauge line of one rail at `s` (centreline ± gauge/2 along the
    /// track-frame lateral axis, plus the rail's irregularity offset).
    pub fn rail_point(&self, s: f64, side: Side) -> Vector3<f64> {
        self.rail_point_in(&self.frame(s), s, side)
    }

    /// [`Track::rail_point`] in the already computed track frame `f` at `s`.
    fn rail_point_in(&self, f: &TrackFrame, s: f64, side: Side) -> Vector3<f64> {
        let (dy, dz) = self.rail_offset(s, side);
        f.origin + f.lateral() * (side.sign() * 0.5 * self.gauge + dy) + f.up() * dz
    }

    /// Rail profile frame at `s`: origin at the rail gauge line ([`Track::rail_point`],
    /// irregularity included) plus `offset` (given in the track frame), axes rotated about
    /// the tangent by the inward cant (`+inward` for the left rail, `−inward` for the right
    /// rail).
    pub fn rail_frame(&self, s: f64, side: Side, offset: Vector3<f64>) -> TrackFrame {
        let f = self.frame(s);
        let base = self.rail_point_in(&f, s, side) + f.rotation * offset;
        let ang = side.sign() * self.rail_inward_cant(s, side);
        let (sa, ca) = ang.sin_cos();
        let rx = Matrix3::new(1.0, 0.0, 0.0, 0.0, ca, -sa, 0.0, sa, ca);
        TrackFrame { origin: base, rotation: f.rotation * rx }
    }

    /// Projects a global point onto the centreline (trajectory coordinate). `hint` is an
    /// optional starting arc length (e.g. the previous result); without it the nearest
    /// tabulated node is used.
    pub fn project(&self, point: &Vector3<f64>, hint: Option<f64>) -> Result<TrackProjection, TrackError> {
        let mut s = match hint {
            Some(h) if h.is_finite() => h,
            _ => {
                let mut best = (f64::INFINITY, self.nodes_s[0]);
                for (si, ri) in self.nodes_s.iter().zip(&self.nodes_r) {
                    let d = (point - ri).norm_squared();
                    if d < best.0 {
                        best = (d, *si);
                    }
                }
                best.1
            }
        };
        for _ in 0..50 {
            let r = self.position(s);
            let t = self.tangent(s);
            let d = point - r;
            let f = d.dot(&t);
            // d/ds (d·t) = -t·t + d·t', t' ≈ curvature * horizontal normal.
            let h = 1e-3;
            let dt = (self.tangent(s + h) - self.tangent(s - h)) / (2.0 * h);
            let df = -1.0 + d.dot(&dt);
            let step = if df.abs() > 1e-6 { -f / df } else { f };
            let step = step.clamp(-50.0, 50.0);
            s += step;
            if step.abs() < 1e-10 {
                let fr = self.frame(s);
                let d = point - fr.origin;
                return Ok(TrackProjection { s, lateral: d.dot(&fr.lateral()), vertical: d.dot(&fr.up()) });
            }
        }
        Err(TrackError::ProjectionFailed { s })
    }

    /// Balance (equilibrium) speed at `s`, m/s: `v = sqrt(g R h / B)` with `R` the
    /// radius, `h` the super-elevation and `B` the cant base. `None` on tangent track
    /// (zero curvature) or where the super-elevation is adverse (opposite sign to the
    /// curvature); `Some(0)` on a curve without super-elevation.
    pub fn balance_speed(&self, s: f64) -> Option<f64> {
        let k = self.curvature(s);
        let e = self.superelevation(s);
        if k == 0.0 || e * k < 0.0 {
            return None;
        }
        Some((GRAVITY * e.abs() / (k.abs() * self.cant_base)).sqrt())
    }
}
