//! Wheel and rail profiles: splines, analytic standard profiles and file import.
//!
//! # Profile conventions (used everywhere in this crate)
//!
//! A profile is a plane curve `z(y)` in its own 2-D frame, in **metres**:
//!
//! * `y` is the lateral coordinate, **positive towards the field side** (away from the
//!   track centre) for *both* wheels and rails and for both sides of the track. The
//!   same profile therefore serves the left and the right rail/wheel; the contact code
//!   mirrors it by the side sign (see [`crate::wheel_rail`]).
//! * `z` is **up** (towards the axle for a wheel, away from the rail foot for a rail).
//! * A **rail** profile has its crown near `z = 0`; the gauge face is at negative `y`.
//! * A **wheel** profile gives the height of the running surface above the nominal
//!   rolling circle: the local rolling radius is `r(y) = r0 − z(y)`. The flange is at
//!   negative `y` (gauge side) and has negative `z` (larger radius). The profile origin
//!   (`y = 0`) is the nominal tape-line point; for S1002 it lies 70 mm from the flange
//!   back.
//! * Rail profiles are given *uncanted* in their own frame; the inward cant is applied
//!   by the rail frame of the track ([`crate::track::Track::rail_frame`]). Profiles read
//!   from files keep whatever cant is in the data (the Manchester UIC60 file is already
//!   canted 1:40).
//!
//! File formats (SIMPACK `.prr`/`.prw`, CONTACT convention) use `z` **downwards** and
//! millimetres; [`io`] converts them (and applies the `mirror.y` flag of the header).

pub mod analytic;
pub mod io;
pub mod spline;

pub use analytic::{aar1b_wheel_approx, s1002_wheel, s1002_z, uic60_rail, uic60_z};
pub use io::{ProfileKind, SimpackProfile, parse_simpack, parse_two_column, read_simpack, read_two_column};
pub use spline::CubicSpline;

use thiserror::Error;

/// Errors raised when profiles are built or read.
#[derive(Debug, Error)]
pub enum ProfileError {
    /// The file could not be read.
    #[error("cannot read profile file {path}: {source}")]
    Io {
        /// File name.
        path: String,
        /// Underlying I/O error.
        source: std::io::Error,
    },
    /// A line could not be parsed.
    #[error("{file}:{line}: {message}")]
    Parse {
        /// File name (or a label for in-memory text).
        file: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// Not enough points for a profile.
    #[error("a profile needs at least 2 points, got {0}")]
    TooFewPoints(usize),
    /// Lateral coordinates are not strictly increasing after sorting (duplicates).
    #[error("profile lateral coordinates must be strictly increasing: point {index} at y = {y}")]
    NotIncreasing {
        /// Index of the offending point.
        index: usize,
        /// Its lateral coordinate.
        y: f64,
    },
    /// Any other invalid input.
    #[error("invalid profile: {0}")]
    Invalid(String),
}

/// A wheel or rail profile `z(y)` (conventions in the module docs), backed by a C²
/// cubic spline.
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    name: String,
    spline: CubicSpline,
}

impl Profile {
    /// Builds a profile from points in the crate convention (m, `y` to the field side,
    /// `z` up). Points are sorted by `y`; duplicated `y` values are an error.
    pub fn from_points(name: &str, points: &[(f64, f64)]) -> Result<Self, ProfileError> {
        if points.len() < 2 {
            return Err(ProfileError::TooFewPoints(points.len()));
        }
        let mut pts = points.to_vec();
        if pts.iter().any(|p| !p.0.is_finite() || !p.1.is_finite()) {
            return Err(ProfileError::Invalid(format!("profile {name}: non-finite coordinate")));
        }
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let y: Vec<f64> = pts.iter().map(|p| p.0).collect();
        let z: Vec<f64> = pts.iter().map(|p| p.1).collect();
        let spline = CubicSpline::new(&y, &z)?;
        Ok(Self { name: name.to_string(), spline })
    }

    /// Profile name (file name or standard designation).
    pub fn name(&self) -> &str {
        &self.name
    }
    /// Underlying spline.
    pub fn spline(&self) -> &CubicSpline {
        &self.spline
    }
    /// Lateral range covered by the data, m.
    pub fn y_range(&self) -> (f64, f64) {
        self.spline.range()
    }
    /// `z(y)`, m.
    pub fn z(&self, y: f64) -> f64 {
        self.spline.value(y)
    }
    /// `z`, `dz/dy`, `d²z/dy²` at `y`.
    pub fn eval(&self, y: f64) -> (f64, f64, f64) {
        self.spline.eval(y)
    }
    /// Signed curvature `z'' / (1 + z'²)^{3/2}`, 1/m (positive = concave up).
    pub fn curvature(&self, y: f64) -> f64 {
        let (_, d, dd) = self.eval(y);
        dd / (1.0 + d * d).powf(1.5)
    }
    /// Highest point of the profile (`y`, `z`), found on the knots and refined with the
    /// spline derivative.
    pub fn highest_point(&self) -> (f64, f64) {
        let ys = self.spline.knots();
        let zs = self.spline.values();
        let mut k = 0;
        for i in 0..zs.len() {
            if zs[i] > zs[k] {
                k = i;
            }
        }
        let (lo, hi) = (ys[k.saturating_sub(1)], ys[(k + 1).min(ys.len() - 1)]);
        let mut y = ys[k];
        for _ in 0..30 {
            let (_, d, dd) = self.eval(y);
            if dd.abs() < 1e-12 {
                break;
            }
            let yn = (y - d / dd).clamp(lo, hi);
            if (yn - y).abs() < 1e-12 {
                y = yn;
                break;
            }
            y = yn;
        }
        (y, self.z(y))
    }

    /// Lateral position where the profile, on the side of `y_start` given by `direction`
    /// (`-1` towards negative `y`), first reaches `z_target` walking from `y_start`.
    /// Used for gauge points (e.g. 14 mm below the crown). `None` if never reached.
    pub fn crossing(&self, y_start: f64, direction: f64, z_target: f64) -> Option<f64> {
        let (lo, hi) = self.y_range();
        let step = 1e-4 * direction.signum();
        let mut y0 = y_start;
        let f = |y: f64| self.z(y) - z_target;
        let mut f0 = f(y0);
        loop {
            let y1 = y0 + step;
            if y1 < lo || y1 > hi {
                return None;
            }
            let f1 = f(y1);
            if f0 == 0.0 {
                return Some(y0);
            }
            if f0 * f1 <= 0.0 {
                let (mut a, mut b, mut fa) = (y0, y1, f0);
                for _ in 0..60 {
                    let m = 0.5 * (a + b);
                    let fm = f(m);
                    if fa * fm <= 0.0 {
                        b = m;
                    } else {
                        a = m;
                        fa = fm;
                    }
                }
                return Some(0.5 * (a + b));
            }
            y0 = y1;
            f0 = f1;
        }
    }

    /// Copy restricted to the longest run of knots where the chord slope stays below
    /// `max_slope` in magnitude (drops near-vertical ends such as a rail's gauge face
    /// below the corner or a flange back, which a `z(y)` spline cannot follow).
    pub fn trim_steep_ends(&self, max_slope: f64) -> Result<Self, ProfileError> {
        let ys = self.spline.knots();
        let zs = self.spline.values();
        let mut best = (0usize, 0usize);
        let mut start = 0usize;
        for i in 1..ys.len() {
            let slope = (zs[i] - zs[i - 1]) / (ys[i] - ys[i - 1]);
            if slope.abs() > max_slope {
                start = i;
            } else if i - start > best.1 - best.0 {
                best = (start, i);
            }
        }
        let pts: Vec<(f64, f64)> = (best.0..=best.1).map(|i| (ys[i], zs[i])).collect();
        Self::from_points(&self.name, &pts)
    }

    /// `n` evenly spaced samples `(y, z)` over the profile range.
    pub fn sample(&self, n: usize) -> Vec<(f64, f64)> {
        let (lo, hi) = self.y_range();
        let n = n.max(2);
        (0..n)
            .map(|i| {
                let y = lo + (hi - lo) * i as f64 / (n - 1) as f64;
                (y, self.z(y))
            })
            .collect()
    }
}
