//! Wheel/rail contact validation cases, run by `railslosh validate` and the test suite.
//!
//! | case | shows |
//! |---|---|
//! | `manchester-contact-left` | Manchester contact benchmark, left wheel (S1002 on UIC 60 canted 1:40, 10 kN vertical load, lateral shifts 0–10 mm with yaw): contact position, normal force and creep forces vs CONTACT's reference output |
//! | `klingel-wavelength` | **kinematic** Klingel test: a free coned wheelset rolling slowly without slip oscillates laterally with wavelength `2π √(r0 b / λ)` |
//! | `contact-mirror-symmetry` | the right wheel at shift y, yaw ψ, roll φ is the mirror image of the left wheel at −y, −ψ, −φ ([`WheelPose::mirrored`](rail_mbs::wheel_rail::WheelPose::mirrored)) to 1e-9, 201 shifts −10…+10 mm across both contact-point jumps |
//! | `contact-sweep-refinement` | sweeping towards the flange in finer and finer steps with the search warm-started from step to step, the contact points are a fresh search's, and each jump's location is bracketed inside the coarser step's |
//! | `contact-variable-friction` | with μ = 0.1 on the gauge face and 0.4 on the top, each patch of a two-point contact saturates at the μ of its own location |
//! | `contact-nadal-climb` | quasi-static flange climb: a wheel sliding into flange contact holds Nadal's L/V at each contact angle, and climbs at Nadal's limit at the S1002 flange angle |
//!
//! # Data
//!
//! `manchester-contact-left` reads the CONTACT example files from the shared data directory
//! ([`rail_mbs::wheel_rail::manchester`]: where it is searched, the readers, the contact pair
//! and the frames). When the files are absent the case returns
//! `ValidationError::Data(DataError::DataNotFound)`; the CLI and the Python tests report it as *skipped: data
//! not found*, never as passed or failed.
//!
//! `quick` runs the integer shifts 0, 1, …, 10 mm (11 of the 21) with the
//! Shen–Hedrick–Elkins creep law and one cone for the Klingel case; the full forms run all 21
//! shifts, also with Polach and FASTSIM, and the Kik–Piotrowski patch (FASTSIM on its strips:
//! position, normal force, load balance and creep forces with the same tolerances), and a 1:20 and a 1:40 cone over five periods
//! (quick: the 1:20 cone over two periods with a coarser RK4 step). The quick and full forms
//! of the four cases across the profile (the analytic S1002/UIC 60 pair, no shared
//! data) are listed in docs/validation.md, "Wheel/rail contact".

use std::path::Path;

use nalgebra::{Matrix3, Vector3};
use thiserror::Error;

use rail_mbs::profile::{Profile, ProfileError, uic60_rail};
use rail_mbs::track::Side;
use rail_mbs::wheel_rail::manchester::{
    DataError, MANCHESTER_DIR, MANCHESTER_FILES, ManchesterReference, find_dataset, manchester_contact_pair,
    parse_manchester_reference,
};
use rail_mbs::wheel_rail::static_load::{VerticalTarget, solve_vertical};
use rail_mbs::wheel_rail::{
    ContactError, ContactGeometry, ContactPoint, CreepModel, PatchModel, RailGeometry, RailPath, WheelGeometry,
    WheelPose, WheelRailContact,
};

use crate::Record;

mod across_profile;
pub use across_profile::s1002_on_uic60;

/// Names of the contact cases.
pub const CASES: [&str; 6] = [
    "manchester-contact-left",
    "klingel-wavelength",
    "contact-mirror-symmetry",
    "contact-sweep-refinement",
    "contact-variable-friction",
    "contact-nadal-climb",
];

/// Errors of the contact validation cases: the data errors of
/// [`rail_mbs::wheel_rail::manchester`] (a missing data set is
/// `Data(DataError::DataNotFound)`: a skip, not a failure), or an unknown case.
#[derive(Debug, Error)]
pub enum ValidationError {
    /// Reading the reference data, building the profiles or the contact failed.
    #[error(transparent)]
    Data(#[from] DataError),
    /// No case of that name.
    #[error("invalid `case` = {0:?}: expected one of {CASES:?}")]
    UnknownCase(String),
}

impl ValidationError {
    /// The reference data are absent: the case is skipped.
    pub fn is_data_not_found(&self) -> bool {
        matches!(self, Self::Data(DataError::DataNotFound { .. }))
    }
}

impl From<ProfileError> for ValidationError {
    fn from(e: ProfileError) -> Self {
        Self::Data(e.into())
    }
}

impl From<ContactError> for ValidationError {
    fn from(e: ContactError) -> Self {
        Self::Data(e.into())
    }
}

/// Run a contact case by name.
pub fn run_case(name: &str, quick: bool) -> Result<Vec<Record>, ValidationError> {
    match name {
        "manchester-contact-left" => manchester_contact_left(quick),
        "klingel-wavelength" => klingel_wavelength(quick),
        "contact-mirror-symmetry" => across_profile::mirror_symmetry(quick),
        "contact-sweep-refinement" => across_profile::sweep_refinement(quick),
        "contact-variable-friction" => across_profile::variable_friction(quick),
        "contact-nadal-climb" => across_profile::nadal_climb(quick),
        other => Err(ValidationError::UnknownCase(other.to_string())),
    }
}

// ---------------------------------------------------------------------------------------
// Manchester, left wheel
// ---------------------------------------------------------------------------------------

/// Our solution of one reference case: wheel at the height carrying CONTACT's total
/// vertical force.
fn manchester_solve(
    contact: &mut WheelRailContact,
    c: &ManchesterReference,
) -> Result<Vec<ContactPoint>, ContactError> {
    Ok(solve_vertical(contact, &c.wheel_state(), VerticalTarget::Load(c.fz_total))?.points)
}

/// Worst deviations of one creep law over the compared shifts.
#[derive(Debug, Default)]
struct Worst {
    single: usize,
    dy: f64,
    fn_rel: f64,
    fx_rel: f64,
    fs_rel: f64,
    fz_rel: f64,
    two_point: usize,
    dy_two: f64,
    fn_two_rel: f64,
}

fn manchester_compare(
    dir: &Path,
    cases: &[&ManchesterReference],
    model: CreepModel,
    patch: PatchModel,
) -> Result<Worst, ValidationError> {
    let mut contact = manchester_contact_pair(dir, model)?;
    contact.patch_model = patch;
    let mut w = Worst::default();
    for c in cases {
        let pts = manchester_solve(&mut contact, c)?;
        if pts.is_empty() {
            return Err(ValidationError::from(ContactError::InvalidInput(format!(
                "no loaded contact point at y_ws = {} mm",
                c.y_ws
            ))));
        }
        let fz: f64 = pts.iter().map(|p| p.force_on_wheel().z).sum();
        w.fz_rel = w.fz_rel.max((fz - c.fz_total).abs() / c.fz_total);
        let fn_total: f64 = pts.iter().map(|p| p.normal_force).sum();
        if pts.len() == 1 && c.patches == 1 {
            let p = &pts[0];
            w.single += 1;
            // |y| of our contact reference point (Hertz: the contact point; Kik–Piotrowski: the
            // patch's pressure centroid) vs CONTACT's reference point (y_C = −y_ours).
            w.dy = w.dy.max((p.reference_point().y * 1000.0 + c.ycp_tr).abs());
            w.fn_rel = w.fn_rel.max((p.normal_force - c.fn_).abs() / c.fn_.abs());
            w.fx_rel = w.fx_rel.max((-p.creep.longitudinal - c.fx).abs() / c.fx.abs());
            w.fs_rel = w.fs_rel.max((p.creep.lateral - c.fs).abs() / c.fs.abs());
        } else {
            // CONTACT finds one wide non-Hertzian patch where we find two Hertzian points:
            // compare the load-weighted position and the total normal force only.
            w.two_point += 1;
            let y = pts.iter().map(|p| p.normal_force * p.reference_point().y * 1000.0).sum::<f64>() / fn_total;
            w.dy_two = w.dy_two.max((y + c.ycp_tr).abs());
            w.fn_two_rel = w.fn_two_rel.max((fn_total - c.fn_).abs() / c.fn_.abs());
        }
    }
    Ok(w)
}

fn manchester_contact_left(quick: bool) -> Result<Vec<Record>, ValidationError> {
    let name = "manchester-contact-left";
    let dir = find_dataset(MANCHESTER_DIR, &MANCHESTER_FILES)?;
    let file = dir.join(MANCHESTER_FILES[0]);
    let text = std::fs::read_to_string(&file).map_err(|e| {
        ValidationError::from(DataError::BadData { file: file.display().to_string(), message: e.to_string() })
    })?;
    let all = parse_manchester_reference(&text, &file.display().to_string())?;
    // Quick: the integer shifts 0, 1, …, 10 mm.
    let cases: Vec<&ManchesterReference> =
        all.iter().filter(|c| !quick || (c.y_ws - c.y_ws.round()).abs() < 1e-9).collect();
    let n = cases.len();
    let mut out = Vec::new();
    let she = manchester_compare(&dir, &cases, CreepModel::ShenHedrickElkins, PatchModel::Hertz)?;
    out.push(Record::abs(
        name,
        format!("number of shifts (0-10 mm, of {n}) with a single contact point, as CONTACT's single patch"),
        she.single as f64,
        n as f64,
        2.0,
    ));
    out.push(Record::at_most(
        name,
        "single-point shifts: worst |y - y_CONTACT| of the contact point's lateral position on the rail (track frame, mm)",
        she.dy,
        1.0,
    ));
    out.push(Record::at_most(
        name,
        "all shifts: worst relative |sum Fz - Fz_applied| / Fz_applied (vertical load balance, 10 kN)",
        she.fz_rel,
        1e-6,
    ));
    out.push(Record::at_most(
        name,
        "single-point shifts: worst relative |FN - FN_CONTACT| / FN_CONTACT (normal force)",
        she.fn_rel,
        0.01,
    ));
    if she.two_point > 0 {
        out.push(Record::at_most(
            name,
            "two-point shifts (one CONTACT patch): worst |y - y_CONTACT| of the load-weighted lateral position (mm)",
            she.dy_two,
            1.0,
        ));
        out.push(Record::at_most(
            name,
            "two-point shifts: worst relative |sum FN - FN_CONTACT| / FN_CONTACT (total normal force)",
            she.fn_two_rel,
            0.01,
        ));
    }
    let mut laws = vec![("Shen-Hedrick-Elkins", she)];
    if !quick {
        let hertz = PatchModel::Hertz;
        laws.push((
            "Polach kA=kS=1",
            manchester_compare(&dir, &cases, CreepModel::Polach { k_a: 1.0, k_s: 1.0 }, hertz)?,
        ));
        laws.push(("FASTSIM 40x40", manchester_compare(&dir, &cases, CreepModel::Fastsim { nx: 40, ny: 40 }, hertz)?));
        // The Kik–Piotrowski patch (FASTSIM on its strips): its own position, normal-force and
        // load checks with the Hertz checks' tolerances, then its creep forces below.
        let label = "Kik-Piotrowski patch, FASTSIM 40x40";
        let kp =
            manchester_compare(&dir, &cases, CreepModel::Fastsim { nx: 40, ny: 40 }, PatchModel::kik_piotrowski())?;
        out.push(Record::abs(
            name,
            format!("number of shifts (of {n}) with a single contact point, as CONTACT's single patch ({label})"),
            kp.single as f64,
            n as f64,
            2.0,
        ));
        out.push(Record::at_most(
            name,
            format!(
                "single-point shifts: worst |y - y_CONTACT| of the contact reference point (pressure centroid) on \
                 the rail (track frame, mm; {label})"
            ),
            kp.dy,
            1.0,
        ));
        out.push(Record::at_most(
            name,
            format!("all shifts: worst relative |sum Fz - Fz_applied| / Fz_applied ({label})"),
            kp.fz_rel,
            1e-6,
        ));
        out.push(Record::at_most(
            name,
            format!("single-point shifts: worst relative |FN - FN_CONTACT| / FN_CONTACT ({label})"),
            kp.fn_rel,
            0.01,
        ));
        if kp.two_point > 0 {
            out.push(Record::at_most(
                name,
                format!("two-point shifts: worst |y - y_CONTACT| of the load-weighted reference point (mm; {label})"),
                kp.dy_two,
                1.0,
            ));
            out.push(Record::at_most(
                name,
                format!("two-point shifts: worst relative |sum FN - FN_CONTACT| / FN_CONTACT ({label})"),
                kp.fn_two_rel,
                0.01,
            ));
        }
        laws.push((label, kp));
    }
    for (label, w) in &laws {
        out.push(Record::at_most(
            name,
            format!("single-point shifts: worst relative |FX - FX_CONTACT| / |FX_CONTACT| (longitudinal creep force, {label})"),
            w.fx_rel,
            0.15,
        ));
        out.push(Record::at_most(
            name,
            format!(
                "single-point shifts: worst relative |FS - FS_CONTACT| / |FS_CONTACT| (lateral creep force, {label})"
            ),
            w.fs_rel,
            0.15,
        ));
    }
    Ok(out)
}

// ---------------------------------------------------------------------------------------
// Klingel (kinematic)
// ---------------------------------------------------------------------------------------

const KLINGEL_R0: f64 = 0.46;

/// One wheel of a pure-cone wheelset (`z = λ u`, radius growing towards the flange side)
/// on a UIC 60 rail (analytic head, no cant, gauge 1435 mm at 14 mm).
fn cone_wheel_rail(side: Side, conicity: f64) -> Result<WheelRailContact, ValidationError> {
    let cone: Vec<(f64, f64)> = (0..=100)
        .map(|i| {
            let u = -0.04 + 1e-3 * i as f64;
            (u, conicity * u)
        })
        .collect();
    let rail = uic60_rail(2e-4)?;
    let offset = RailGeometry::offset_for_gauge(&rail, 1.435, 0.014).ok_or_else(|| {
        ValidationError::from(DataError::BadData { file: "UIC60 (analytic)".into(), message: "no gauge point".into() })
    })?;
    let mut c = WheelRailContact::new(
        WheelGeometry {
            profile: Profile::from_points("cone", &cone)?,
            nominal_radius: KLINGEL_R0,
            profile_offset: 0.75,
            side,
        },
        RailGeometry {
            profile: rail,
            side,
            profile_offset: offset,
            vertical_offset: 0.0,
            path: RailPath::Straight { inward_cant: 0.0 },
        },
    );
    c.settings.scan_points = 200;
    Ok(c)
}

fn rot_z(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// Rolling radius and contact geometry of one wheel at wheelset state (x, y, ψ).
fn cone_contact(
    c: &mut WheelRailContact,
    conicity: f64,
    x: f64,
    y: f64,
    psi: f64,
) -> Result<(f64, ContactGeometry), ValidationError> {
    let pose = WheelPose::at_rest(Vector3::new(x, y, KLINGEL_R0 - 1e-4), rot_z(psi));
    let g = c.find_geometry(&pose)?;
    let g = *g.iter().max_by(|a, b| a.penetration.total_cmp(&b.penetration)).ok_or_else(|| {
        ValidationError::from(ContactError::InvalidInput(format!("no contact point at y = {y} m, yaw = {psi} rad")))
    })?;
    Ok((KLINGEL_R0 - conicity * g.params[2], g))
}

/// Kinematic wheelset: lateral displacement `y` and yaw `ψ` over the distance travelled,
/// `dy/dx = ψ`, `dψ/dx = −(r_L − r_R) / (2 b r0)` (rolling without slip, no inertia, no
/// creep forces), with `r_L`, `r_R` and the contact half-spacing `b` from the contact
/// search of each wheel at every RK4 stage. Returns (measured wavelength, Klingel
/// wavelength, max |y|, periods).
fn klingel_run(conicity: f64, h: f64, wavelengths: f64, y0: f64) -> Result<(f64, f64, f64, usize), ValidationError> {
    let mut left = cone_wheel_rail(Side::Left, conicity)?;
    let mut right = cone_wheel_rail(Side::Right, conicity)?;
    let (r_c, gl) = cone_contact(&mut left, conicity, 0.0, 0.0, 0.0)?;
    let (_, gr) = cone_contact(&mut right, conicity, 0.0, 0.0, 0.0)?;
    let b0 = 0.5 * (gl.point_rail.y - gr.point_rail.y);
    let expected = 2.0 * std::f64::consts::PI * (r_c * b0 / conicity).sqrt();
    let mut rhs = |x: f64, s: [f64; 2]| -> Result<[f64; 2], ValidationError> {
        let (rl, pl) = cone_contact(&mut left, conicity, x, s[0], s[1])?;
        let (rr, pr) = cone_contact(&mut right, conicity, x, s[0], s[1])?;
        let b = 0.5 * (pl.point_rail.y - pr.point_rail.y);
        Ok([s[1], -(rl - rr) / (2.0 * b * r_c)])
    };
    let mut x = 0.0;
    let mut s = [y0, 0.0];
    let mut crossings = Vec::new();
    let mut amp = 0.0f64;
    while x < wavelengths * expected {
        let k1 = rhs(x, s)?;
        let k2 = rhs(x + 0.5 * h, [s[0] + 0.5 * h * k1[0], s[1] + 0.5 * h * k1[1]])?;
        let k3 = rhs(x + 0.5 * h, [s[0] + 0.5 * h * k2[0], s[1] + 0.5 * h * k2[1]])?;
        let k4 = rhs(x + h, [s[0] + h * k3[0], s[1] + h * k3[1]])?;
        let next = [
            s[0] + h / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]),
            s[1] + h / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]),
        ];
        if s[0] > 0.0 && next[0] <= 0.0 {
            // Downward zero crossing, linear interpolation.
            crossings.push(x + h * s[0] / (s[0] - next[0]));
        }
        x += h;
        s = next;
        amp = amp.max(s[0].abs());
    }
    let periods = crossings.len().saturating_sub(1);
    let measured = if periods > 0 { (crossings[periods] - crossings[0]) / periods as f64 } else { f64::NAN };
    Ok((measured, expected, amp, periods))
}

fn klingel_wavelength(quick: bool) -> Result<Vec<Record>, ValidationError> {
    let name = "klingel-wavelength";
    let y0 = 0.002;
    let runs: &[(f64, &str, f64, f64)] =
        if quick { &[(0.05, "1:20", 0.4, 2.5)] } else { &[(0.05, "1:20", 0.2, 5.5), (0.025, "1:40", 0.2, 5.5)] };
    let mut out = Vec::new();
    for &(conicity, label, h, wavelengths) in runs {
        let (measured, expected, amp, periods) = klingel_run(conicity, h, wavelengths, y0)?;
        out.push(Record::abs(
            name,
            format!(
                "kinematic (no-slip, no inertia) wavelength of a free {label} cone wheelset on UIC60, r0 = 0.46 m, \
                 mean over {periods} periods (m), reference 2 pi sqrt(r0 b / lambda), tolerance 3 %"
            ),
            measured,
            expected,
            0.03 * expected,
        ));
        out.push(Record::abs(
            name,
            format!("kinematic {label} cone: max |y| (m) equals the initial 2 mm shift (undamped motion)"),
            amp,
            y0,
            1e-4,
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_case_names_the_field() {
        let e = run_case("nope", true).unwrap_err().to_string();
        assert!(e.contains("`case`") && e.contains("klingel-wavelength"), "{e}");
    }
}
