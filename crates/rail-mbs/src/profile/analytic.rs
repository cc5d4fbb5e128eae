//! Analytic standard profiles: S1002 wheel, UIC 60 rail head, approximate AAR-1B wheel.
//!
//! All functions return values in the crate convention (metres, `y` towards the field
//! side, `z` up; see [`super`]).

use super::{Profile, ProfileError};

/// S1002 wheel profile height `z(y)` in metres (crate convention), or `None` outside its
/// definition range `y ∈ [−70, 60]` mm.
///
/// Piecewise definition of the standard (EN 13715 / UIC 510-2) in eight sections —
/// straight lines, circular arcs and polynomials in the lateral coordinate — as
/// distributed by H. Netter (DLR) in the widely used `s1002(S)` routine. Section
/// boundaries and coefficients are the published constants of that definition; the
/// evaluation here is an independent implementation. The original returns the profile
/// depth positive downwards in mm with the flange at negative `S`; we return `−depth`
/// in metres.
pub fn s1002_z(y: f64) -> Option<f64> {
    let s = y * 1000.0;
    if !(-70.0..=60.0).contains(&s) {
        return None;
    }
    let circ = |a: f64, b: f64, c: f64, sign: f64| a + sign * (b * b - (s + c) * (s + c)).max(0.0).sqrt();
    let depth = if s >= 32.15796 {
        // A: tread cone towards the field side
        1.364_323_640 - 0.066_666_667 * s
    } else if s >= -26.0 {
        // B: tread, polynomial of degree 8
        let c = [
            0.0,
            -3.358_537_058e-2,
            1.565_681_624e-3,
            -2.810_427_944e-5,
            5.844_240_864e-8,
            -1.562_379_023e-8,
            5.309_217_349e-15,
            -5.957_839_843e-12,
            2.646_656_573e-13,
        ];
        horner(&c, s)
    } else if s >= -35.0 {
        // C: throat, polynomial of degree 7
        let c = [
            -4.320_221_063e3,
            -1.038_384_026e3,
            -1.065_501_873e2,
            -6.051_367_875,
            -2.054_332_446e-1,
            -4.169_739_389e-3,
            -4.687_195_829e-5,
            -2.252_755_540e-7,
        ];
        horner(&c, s)
    } else if s >= -38.426_669_071 {
        // D: arc R13
        circ(16.446, 13.0, 26.210_665, -1.0)
    } else if s >= -39.764_473_993 {
        // E: flange flank line
        -93.576_667_419 - 2.747_477_419 * s
    } else if s >= -49.662_510_381 {
        // F: arc R20
        circ(8.834_924_130, 20.0, 58.558_326_413, 1.0)
    } else if s >= -62.764_705_882 {
        // G: flange tip arc R12
        circ(16.0, 12.0, 55.0, 1.0)
    } else {
        // H: flange back arc R20.5
        circ(9.519_259_302, 20.5, 49.5, 1.0)
    };
    Some(-depth / 1000.0)
}

fn horner(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &ci| acc * x + ci)
}

/// S1002 wheel profile sampled every `spacing` metres (e.g. `2e-4`) over
/// `y ∈ [−69.5, 60]` mm (the last half millimetre of the vertical flange back is left
/// out), as a spline [`Profile`].
pub fn s1002_wheel(spacing: f64) -> Result<Profile, ProfileError> {
    sample_fn("S1002", -0.0695, 0.060, spacing, |y| s1002_z(y).unwrap_or(0.0))
}

fn sample_fn(name: &str, lo: f64, hi: f64, spacing: f64, f: impl Fn(f64) -> f64) -> Result<Profile, ProfileError> {
    if !(spacing > 0.0 && spacing < (hi - lo)) {
        return Err(ProfileError::Invalid(format!("{name}: bad sampling spacing {spacing}")));
    }
    let n = ((hi - lo) / spacing).ceil() as usize + 1;
    let pts: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let y = lo + (hi - lo) * i as f64 / (n - 1) as f64;
            (y, f(y))
        })
        .collect();
    Profile::from_points(name, &pts)
}

/// Geometry of the UIC 60 (60E1) rail head used by [`uic60_z`], millimetres.
///
/// Published head geometry: crown radius R300, then R80, then the R13 gauge corner,
/// joined tangentially, and a 1:20 inclined side face; the head is 72 mm wide. The
/// R300/R80 tangent point (`y = ±10.25` mm) and the reference level of the 72 mm width
/// (14 mm below the crown, the gauge-measuring level) are *our* choices where the
/// drawings were not at hand; the remaining tangent points follow from tangency.
#[derive(Debug, Clone, Copy)]
struct Uic60Head {
    /// Centres (y, z) and radii of the three arcs, and their end angles (from +z
    /// towards +y).
    c1: (f64, f64),
    c2: (f64, f64),
    c3: (f64, f64),
    a1: f64,
    a2: f64,
    /// Tangent point between R13 and the side face.
    t3: (f64, f64),
}

const R1: f64 = 300.0;
const R2: f64 = 80.0;
const R3: f64 = 13.0;
const Y1: f64 = 10.25;
const HALF_WIDTH: f64 = 36.0;
const WIDTH_DEPTH: f64 = 14.0;

fn uic60_head_for(a2: f64) -> Uic60Head {
    let c1 = (0.0, -R1);
    let a1 = (Y1 / R1).asin();
    let c2 = (c1.0 + (R1 - R2) * a1.sin(), c1.1 + (R1 - R2) * a1.cos());
    let c3 = (c2.0 + (R2 - R3) * a2.sin(), c2.1 + (R2 - R3) * a2.cos());
    let a3 = std::f64::consts::FRAC_PI_2 - (1.0f64 / 20.0).atan();
    let t3 = (c3.0 + R3 * a3.sin(), c3.1 + R3 * a3.cos());
    Uic60Head { c1, c2, c3, a1, a2, t3 }
}

impl Uic60Head {
    /// Height (mm, up) at lateral `y ≥ 0` (mm).
    fn z(&self, y: f64) -> f64 {
        let arc = |c: (f64, f64), r: f64| c.1 + (r * r - (y - c.0) * (y - c.0)).max(0.0).sqrt();
        let y1 = self.c1.0 + R1 * self.a1.sin();
        let y2 = self.c2.0 + R2 * self.a2.sin();
        if y <= y1 {
            arc(self.c1, R1)
        } else if y <= y2 {
            arc(self.c2, R2)
        } else if y <= self.t3.0 {
            arc(self.c3, R3)
        } else {
            // 1:20 side face: z drops 20 mm per mm outward
            self.t3.1 - 20.0 * (y - self.t3.0)
        }
    }
    /// Lateral position (mm) where the head reaches depth `d` below the crown.
    fn y_at_depth(&self, d: f64) -> f64 {
        ancf_core::roots::bisect(0.0, 60.0, 80, |y| self.z(y) > -d)
    }
}

fn uic60_head() -> Uic60Head {
    // Solve for the R80/R13 tangent angle giving a 72 mm width at 14 mm depth.
    let a1 = (Y1 / R1).asin();
    let a3 = std::f64::consts::FRAC_PI_2 - (1.0f64 / 20.0).atan();
    uic60_head_for(ancf_core::roots::bisect(a1 + 1e-6, a3 - 1e-6, 80, |a| {
        uic60_head_for(a).y_at_depth(WIDTH_DEPTH) < HALF_WIDTH
    }))
}

/// UIC 60 rail head height `z(y)` in metres (crate convention, uncanted, symmetric, crown
/// at `z = 0`), defined for `|y| ≤ 37` mm (down to about 34 mm below the crown on the
/// 1:20 side face); `None` outside.
pub fn uic60_z(y: f64) -> Option<f64> {
    let ymm = (y * 1000.0).abs();
    if ymm > 37.0 {
        return None;
    }
    Some(uic60_head().z(ymm) / 1000.0)
}

/// UIC 60 rail head profile sampled every `spacing` metres over `|y| ≤ 36.5` mm.
pub fn uic60_rail(spacing: f64) -> Result<Profile, ProfileError> {
    let head = uic60_head();
    sample_fn("UIC60", -0.0365, 0.0365, spacing, |y| head.z((y * 1000.0).abs()) / 1000.0)
}

/// Approximate AAR-1B wide-flange wheel profile (**not** the licensed AAR contour).
///
/// Built as a filleted polyline in mm: a 1:20 tread cone from the field side through
/// the tape line (`y = 0`) to a throat fillet (R 18 mm), a 75° flange face, a flange tip
/// (fillets R 8 mm) 25.4 mm (1 in) below the tape line, and an inclined flange back
/// ending 70 mm from the tape line. Only the 1:20 taper and the 75° flange angle are
/// taken from public AAR descriptions; every other dimension is an assumption. Sampled
/// every 0.25 mm.
pub fn aar1b_wheel_approx() -> Result<Profile, ProfileError> {
    let tan75 = 75f64.to_radians().tan();
    // Flange face passes through (-52, -25.4); throat corner where it meets z = y/20.
    let (yf, zf) = (-52.0, -25.4);
    let y2 = (zf - yf * tan75) / (0.05 - tan75);
    let verts = [(70.0, 3.5), (y2, y2 / 20.0), (yf, zf), (-60.0, -25.4), (-70.0, -8.0)];
    let radii = [18.0, 8.0, 8.0];
    let pts_mm = fillet_polyline(&verts, &radii, 0.25)?;
    let pts: Vec<(f64, f64)> = pts_mm.iter().map(|p| (p.0 / 1000.0, p.1 / 1000.0)).collect();
    Profile::from_points("AAR-1B (approximate)", &pts)
}

/// Samples a polyline whose interior corners are replaced by tangent circular arcs of
/// the given radii (one per interior vertex), with roughly `spacing` between points.
fn fillet_polyline(verts: &[(f64, f64)], radii: &[f64], spacing: f64) -> Result<Vec<(f64, f64)>, ProfileError> {
    if radii.len() + 2 != verts.len() {
        return Err(ProfileError::Invalid("fillet: one radius per interior vertex".into()));
    }
    let sub = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0, a.1 - b.1);
    let norm = |a: (f64, f64)| (a.0 * a.0 + a.1 * a.1).sqrt();
    let mut cursor = verts[0];
    let mut out = Vec::new();
    for i in 1..verts.len() - 1 {
        let p = verts[i];
        let d1 = sub(p, verts[i - 1]);
        let d2 = sub(verts[i + 1], p);
        let (l1, l2) = (norm(d1), norm(d2));
        let d1 = (d1.0 / l1, d1.1 / l1);
        let d2 = (d2.0 / l2, d2.1 / l2);
        let cosphi = (d1.0 * d2.0 + d1.1 * d2.1).clamp(-1.0, 1.0);
        let phi = cosphi.acos();
        let r = radii[i - 1];
        let t = r * (0.5 * phi).tan();
        if t > l1 || t > l2 {
            return Err(ProfileError::Invalid(format!("fillet radius {r} too large at vertex {i}")));
        }
        let a = (p.0 - t * d1.0, p.1 - t * d1.1);
        let b = (p.0 + t * d2.0, p.1 + t * d2.1);
        // line cursor -> a
        out.extend(sample_line(cursor, a, spacing));
        // arc a -> b, centre on the inner side of the turn
        let cross = d1.0 * d2.1 - d1.1 * d2.0;
        let nrm = if cross > 0.0 { (-d1.1, d1.0) } else { (d1.1, -d1.0) };
        let c = (a.0 + r * nrm.0, a.1 + r * nrm.1);
        let ang_a = (a.1 - c.1).atan2(a.0 - c.0);
        let mut ang_b = (b.1 - c.1).atan2(b.0 - c.0);
        let sweep_sign = cross.signum();
        while sweep_sign * (ang_b - ang_a) < 0.0 {
            ang_b += sweep_sign * std::f64::consts::TAU;
        }
        let n = ((r * (ang_b - ang_a).abs()) / spacing).ceil().max(2.0) as usize;
        let arc: Vec<(f64, f64)> = (0..n)
            .map(|k| {
                let th = ang_a + (ang_b - ang_a) * k as f64 / n as f64;
                (c.0 + r * th.cos(), c.1 + r * th.sin())
            })
            .collect();
        out.extend(arc);
        cursor = b;
    }
    out.extend(sample_line(cursor, verts[verts.len() - 1], spacing));
    out.push(verts[verts.len() - 1]);
    // Remove points that would break strict monotonicity in y.
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out.dedup_by(|a, b| (a.0 - b.0).abs() < 1e-6);
    Ok(out)
}

fn sample_line(a: (f64, f64), b: (f64, f64), spacing: f64) -> Vec<(f64, f64)> {
    let l = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
    let n = (l / spacing).ceil().max(1.0) as usize;
    (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1))
        })
        .collect()
}
