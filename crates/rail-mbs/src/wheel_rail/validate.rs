//! Wheel/rail contact validation cases, run by `railslosh validate` and the test suite.
//!
//! | case | shows |
//! |---|---|
//! | `manchester-contact-left` | Manchester contact benchmark, left wheel (S1002 on UIC 60 canted 1:40, 10 kN vertical load, lateral shifts 0–10 mm with yaw): contact position, normal force and creep forces vs CONTACT's reference output |
//! | `klingel-wavelength` | **kinematic** Klingel test: a free coned wheelset rolling slowly without slip oscillates laterally with wavelength `2π √(r0 b / λ)` |
//!
//! # Data
//!
//! `manchester-contact-left` reads the CONTACT example files (Apache-2.0) from the folder
//! `manchester-contact/` of the shared data directory, found as follows:
//!
//! 1. if the environment variable [`DATA_ENV`] (`RAILSLOSH_SHARED_DATA`) is set and not
//!    empty, it names the shared data directory and nothing else is searched;
//! 2. otherwise `../shared/data` next to the repository this crate was built from
//!    (`CARGO_MANIFEST_DIR/../../../shared/data`), then `shared/data` in the current
//!    directory and each of its parents.
//!
//! When the files are absent the case returns [`ValidationError::DataNotFound`], listing
//! the folders searched; the CLI and the Python tests report it as *skipped: data not
//! found*, never as passed or failed. The data are never copied into the repository.
//!
//! # Frames (Manchester case)
//!
//! CONTACT's track frame has x forward, y to the **right**, z **down**; ours has x forward,
//! y left, z up. Hence `y_ours = −y_C`, `roll_ours = roll_C`, `yaw_ours = −yaw_C`,
//! `ω_axle,ours = −VPITCH_C`. CONTACT reports forces on the rail, ours act on the wheel:
//! `FX_C = −Fx_wheel`, `FS_C = +Fy_wheel`.
//!
//! `quick` runs the integer shifts 0, 1, …, 10 mm (11 of the 21) with the
//! Shen–Hedrick–Elkins creep law and one cone for the Klingel case; the full forms run all 21
//! shifts, also with Polach and FASTSIM, and a 1:20 and a 1:40 cone over five periods
//! (quick: the 1:20 cone over two periods with a coarser RK4 step).

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

use ancf_core::validate::Record;
use nalgebra::{Matrix3, Vector3};
use thiserror::Error;

use super::static_load::{VerticalTarget, WheelState, solve_vertical};
use super::{
    ContactError, ContactGeometry, ContactPoint, CreepModel, Material, RailGeometry, RailPath, WheelGeometry,
    WheelPose, WheelRailContact,
};
use crate::profile::{Profile, ProfileError, read_simpack, uic60_rail};
use crate::track::Side;

/// Names of the contact cases.
pub const CASES: [&str; 2] = ["manchester-contact-left", "klingel-wavelength"];

/// Environment variable naming the shared data directory (the folder holding
/// `manchester-contact/`).
pub const DATA_ENV: &str = "RAILSLOSH_SHARED_DATA";

/// Folder of the Manchester benchmark inside the shared data directory.
pub const MANCHESTER_DIR: &str = "manchester-contact";
/// Files of the Manchester benchmark that the case reads.
pub const MANCHESTER_FILES: [&str; 3] = ["mbench_a22_left.ref_out", "MBench_UIC60_v3.prr", "MBench_S1002_v3.prw"];

/// Errors of the contact validation cases.
#[derive(Debug, Error)]
pub enum ValidationError {
    /// The external reference data are not available: the case is skipped, not failed.
    #[error(
        "data not found: `{dataset}` with {files} in none of [{searched}]; set {DATA_ENV} to the shared data directory",
        files = required.join(", "),
        searched = searched.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
    )]
    DataNotFound {
        /// Folder name of the data set.
        dataset: String,
        /// Files it must hold.
        required: Vec<String>,
        /// Shared data directories searched.
        searched: Vec<PathBuf>,
    },
    /// No case of that name.
    #[error("invalid `case` = {0:?}: expected one of {CASES:?}")]
    UnknownCase(String),
    /// The reference data could not be read or parsed.
    #[error("{file}: {message}")]
    BadData {
        /// File name.
        file: String,
        /// What is wrong.
        message: String,
    },
    /// A profile could not be read or built.
    #[error(transparent)]
    Profile(#[from] ProfileError),
    /// The contact computation failed.
    #[error(transparent)]
    Contact(#[from] ContactError),
}

/// Run a contact case by name.
pub fn run_case(name: &str, quick: bool) -> Result<Vec<Record>, ValidationError> {
    match name {
        "manchester-contact-left" => manchester_contact_left(quick),
        "klingel-wavelength" => klingel_wavelength(quick),
        other => Err(ValidationError::UnknownCase(other.to_string())),
    }
}

/// Shared data directories to search, in order (see the module docs). `env` is the value of
/// [`DATA_ENV`], `cwd` the current directory.
pub fn shared_data_candidates(env: Option<&OsStr>, cwd: Option<&Path>) -> Vec<PathBuf> {
    if let Some(e) = env.filter(|e| !e.is_empty()) {
        return vec![PathBuf::from(e)];
    }
    let mut out = vec![Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data")];
    if let Some(cwd) = cwd {
        for dir in cwd.ancestors() {
            out.push(dir.join("shared/data"));
        }
    }
    let mut unique: Vec<PathBuf> = Vec::new();
    for p in out {
        let key = p.canonicalize().unwrap_or_else(|_| p.clone());
        if !unique.iter().any(|u| u.canonicalize().unwrap_or_else(|_| u.clone()) == key) {
            unique.push(p);
        }
    }
    unique
}

/// First folder `candidate/dataset` among `candidates` that holds every file of `required`.
pub fn find_dataset_in(candidates: &[PathBuf], dataset: &str, required: &[&str]) -> Result<PathBuf, ValidationError> {
    for c in candidates {
        let dir = c.join(dataset);
        if required.iter().all(|f| dir.join(f).is_file()) {
            return Ok(dir);
        }
    }
    Err(ValidationError::DataNotFound {
        dataset: dataset.to_string(),
        required: required.iter().map(|s| s.to_string()).collect(),
        searched: candidates.to_vec(),
    })
}

/// Folder of a data set in the shared data directory (environment and current directory
/// as in the module docs).
pub fn find_dataset(dataset: &str, required: &[&str]) -> Result<PathBuf, ValidationError> {
    let env = std::env::var_os(DATA_ENV);
    let cwd = std::env::current_dir().ok();
    find_dataset_in(&shared_data_candidates(env.as_deref(), cwd.as_deref()), dataset, required)
}

// ---------------------------------------------------------------------------------------
// Manchester, left wheel
// ---------------------------------------------------------------------------------------

/// One case of CONTACT's reference output (CONTACT units: mm, N, rad, mm/s).
#[derive(Debug, Clone, Default)]
pub struct ManchesterReference {
    /// Wheelset lateral shift, mm (CONTACT y, to the right).
    pub y_ws: f64,
    /// Roll, rad.
    pub roll: f64,
    /// Yaw, rad (CONTACT convention).
    pub yaw: f64,
    /// Forward speed, mm/s.
    pub vx: f64,
    /// Axle angular velocity, rad/s (CONTACT convention).
    pub vpitch: f64,
    /// Number of contact patches.
    pub patches: usize,
    /// Lateral position of the contact reference point, track frame, mm (CONTACT y).
    pub ycp_tr: f64,
    /// Normal force, N.
    pub fn_: f64,
    /// Longitudinal creep force on the rail, N.
    pub fx: f64,
    /// Lateral creep force on the rail (in the contact plane), N.
    pub fs: f64,
    /// Total vertical force, N.
    pub fz_total: f64,
}

fn numbers(line: &str) -> Vec<f64> {
    line.split_whitespace().filter_map(|t| t.parse::<f64>().ok()).collect()
}

/// Parses CONTACT's `mbench_a22_left.ref_out` (first patch of each case).
pub fn parse_manchester_reference(text: &str, file: &str) -> Result<Vec<ManchesterReference>, ValidationError> {
    let lines: Vec<&str> = text.lines().collect();
    let bad = |i: usize, what: &str| ValidationError::BadData {
        file: file.to_string(),
        message: format!("line {}: cannot read {what}", i + 2),
    };
    let next = |i: usize, min: usize, what: &str| -> Result<Vec<f64>, ValidationError> {
        let v = lines.get(i + 1).map(|l| numbers(l)).unwrap_or_default();
        if v.len() < min { Err(bad(i, what)) } else { Ok(v) }
    };
    let mut cases: Vec<ManchesterReference> = Vec::new();
    let mut seen_cp = false;
    let mut seen_fn = false;
    for (i, raw) in lines.iter().enumerate() {
        let l = raw.trim();
        if l.starts_with("Case ") {
            cases.push(ManchesterReference::default());
            seen_cp = false;
            seen_fn = false;
            continue;
        }
        let Some(c) = cases.last_mut() else { continue };
        if l.starts_with("WHEEL-RAIL CONTACT, LEFT WHEEL,") {
            c.patches = numbers(l.split(',').nth(2).unwrap_or("")).first().map(|v| *v as usize).unwrap_or(0);
        } else if l.starts_with("S_WS") {
            let v = next(i, 5, "S_WS")?;
            (c.y_ws, c.roll, c.yaw) = (v[1], v[3], v[4]);
        } else if l.starts_with("VX_WS") {
            let v = next(i, 6, "VX_WS")?;
            (c.vx, c.vpitch) = (v[0], v[5]);
        } else if l.starts_with("FX(TR)") {
            c.fz_total = next(i, 3, "FX(TR)")?[2];
        } else if l.starts_with("XCP(TR)") && !seen_cp {
            c.ycp_tr = next(i, 2, "XCP(TR)")?[1];
            seen_cp = true;
        } else if l.starts_with("FN ") && !seen_fn {
            let v = next(i, 3, "FN")?;
            (c.fn_, c.fx, c.fs) = (v[0], v[1], v[2]);
            seen_fn = true;
        }
    }
    if cases.len() != 21 {
        return Err(ValidationError::BadData {
            file: file.to_string(),
            message: format!("expected 21 cases (shifts 0:0.5:10 mm), found {}", cases.len()),
        });
    }
    Ok(cases)
}

/// CONTACT's contact patch of one reference case, read off its "FORM OF THE CONTACT"
/// map (one character per element of the 0.2 mm × 0.2 mm grid of the benchmark input;
/// `*` adhesion, `S` slip).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ManchesterPatch {
    /// Lateral extent (along the surface), mm: rows holding contact × 0.2 mm (±0.2 mm).
    pub lateral_extent: f64,
    /// Longest row (rolling direction), mm: its contact elements × 0.2 mm.
    pub length: f64,
    /// Area, mm²: contact elements × 0.04 mm² (equals CONTACT's NCON × DX × DS).
    pub area: f64,
}

/// Element size of the benchmark's CONTACT grid (DX = DS), mm.
pub const MANCHESTER_GRID_MM: f64 = 0.2;

/// Parses the first patch map of each case of `mbench_a22_left.ref_out`
/// ([`ManchesterPatch`]).
pub fn parse_manchester_patches(text: &str, file: &str) -> Result<Vec<ManchesterPatch>, ValidationError> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    let mut in_case = false;
    while i < lines.len() {
        let l = lines[i].trim();
        if l.starts_with("Case ") {
            in_case = true;
        } else if in_case && l.starts_with("FORM OF THE CONTACT") {
            let (mut rows, mut cells, mut longest) = (0usize, 0usize, 0usize);
            i += 1;
            while let Some(row) = lines.get(i) {
                let mut tok = row.split_whitespace();
                let is_row = tok.next().is_some_and(|t| t.parse::<usize>().is_ok())
                    && row.split_whitespace().nth(1).is_some_and(|t| matches!(t, "o" | "." | "*" | "S"));
                if !is_row {
                    break;
                }
                let n = tok.filter(|t| matches!(*t, "*" | "S")).count();
                if n > 0 {
                    rows += 1;
                    cells += n;
                    longest = longest.max(n);
                }
                i += 1;
            }
            if rows == 0 {
                return Err(ValidationError::BadData {
                    file: file.to_string(),
                    message: format!("line {}: empty contact map", i + 1),
                });
            }
            let h = MANCHESTER_GRID_MM;
            out.push(ManchesterPatch {
                lateral_extent: rows as f64 * h,
                length: longest as f64 * h,
                area: cells as f64 * h * h,
            });
            in_case = false;
            continue;
        }
        i += 1;
    }
    if out.len() != 21 {
        return Err(ValidationError::BadData {
            file: file.to_string(),
            message: format!("expected 21 contact maps, found {}", out.len()),
        });
    }
    Ok(out)
}

/// Our solution of one Manchester case for a patch model (CONTACT's conventions and units:
/// mm, N, forces on the rail): see [`manchester_patch_case`].
#[derive(Debug, Clone, PartialEq)]
pub struct PatchCase {
    /// Loaded contact points (patches).
    pub points: usize,
    /// Lateral extent of the patch(es) along the most loaded point's `e2`, mm (Hertz: `2b`;
    /// several points: the extent of their union).
    pub lateral_extent: f64,
    /// Total patch area, mm².
    pub area: f64,
    /// Lateral position of the contact reference point in CONTACT's track frame
    /// (`YCP(TR)`, y to the right), mm; the normal-force-weighted mean over the points.
    pub ycp: f64,
    /// Total normal force, N.
    pub fn_: f64,
    /// Total longitudinal creep force on the rail (`FX`), N.
    pub fx: f64,
    /// Total lateral creep force on the rail in the contact plane (`FS`), N.
    pub fs: f64,
    /// The wheel pose at the solved height.
    pub pose: WheelPose,
}

/// Solves case `c` with `contact` (its patch and creep models as set) at CONTACT's total
/// vertical force and reads off [`PatchCase`].
pub fn manchester_patch_case(
    contact: &mut WheelRailContact,
    c: &ManchesterReference,
) -> Result<PatchCase, ValidationError> {
    let state = WheelState {
        lateral_shift: -c.y_ws / 1000.0,
        yaw: -c.yaw,
        roll: c.roll,
        speed: c.vx / 1000.0,
        axle_rate: Some(-c.vpitch),
        ..Default::default()
    };
    let loaded = solve_vertical(contact, &state, VerticalTarget::Load(c.fz_total))?;
    let pts = &loaded.points;
    let main = pts.iter().max_by(|a, b| a.normal_force.total_cmp(&b.normal_force)).ok_or_else(|| {
        ValidationError::Contact(ContactError::InvalidInput(format!("no loaded contact point at y_ws = {} mm", c.y_ws)))
    })?;
    let (origin, e2) = (main.point(), main.geometry.e2);
    let (mut lo, mut hi, mut area) = (f64::INFINITY, f64::NEG_INFINITY, 0.0);
    for p in pts {
        let t = (p.point() - origin).dot(&e2);
        let (l, h, a) = match &p.patch {
            Some(s) => (s.lateral_extent.0, s.lateral_extent.1, s.area),
            None => (-p.semi_axes.1, p.semi_axes.1, std::f64::consts::PI * p.semi_axes.0 * p.semi_axes.1),
        };
        lo = lo.min(t + l);
        hi = hi.max(t + h);
        area += a;
    }
    let fn_: f64 = pts.iter().map(|p| p.normal_force).sum();
    Ok(PatchCase {
        points: pts.len(),
        lateral_extent: (hi - lo) * 1e3,
        area: area * 1e6,
        ycp: -pts.iter().map(|p| p.normal_force * p.reference_point().y).sum::<f64>() / fn_ * 1e3,
        fn_,
        fx: -pts.iter().map(|p| p.creep.longitudinal).sum::<f64>(),
        fs: pts.iter().map(|p| p.creep.lateral).sum(),
        pose: loaded.pose,
    })
}

/// The left-wheel contact pair: rail file with its gauge point 14 mm below the crown
/// at 717.5 mm from the centreline (offset found on the full profile, then the near-vertical
/// canted side faces trimmed), S1002 wheel file with r0 = 460 mm and its profile origin
/// 750 mm from the wheelset centre, G = 82 GPa, ν = 0.28, μ = 0.3.
pub fn manchester_contact_pair(dir: &Path, model: CreepModel) -> Result<WheelRailContact, ValidationError> {
    let rail_full = read_simpack(dir.join("MBench_UIC60_v3.prr"))?.to_profile()?;
    let wheel: Profile = read_simpack(dir.join("MBench_S1002_v3.prw"))?.to_profile()?;
    let offset = RailGeometry::offset_for_gauge(&rail_full, 1.435, 0.014).ok_or_else(|| ValidationError::BadData {
        file: "MBench_UIC60_v3.prr".into(),
        message: "rail profile does not reach the gauge point 14 mm below the crown".into(),
    })?;
    let rail = rail_full.trim_steep_ends(10.0)?;
    let wheel_geo = WheelGeometry { profile: wheel, nominal_radius: 0.460, profile_offset: 0.750, side: Side::Left };
    let rail_geo = RailGeometry {
        profile: rail,
        side: Side::Left,
        profile_offset: offset,
        vertical_offset: 0.0,
        path: RailPath::Straight { inward_cant: 0.0 },
    };
    let mut contact = WheelRailContact::new(wheel_geo, rail_geo);
    let mat = Material::from_shear(82e9, 0.28);
    contact.wheel_material = mat;
    contact.rail_material = mat;
    contact.friction = 0.3;
    contact.creep_model = model;
    Ok(contact)
}

/// Our solution of one reference case: wheel at the height carrying CONTACT's total
/// vertical force.
fn manchester_solve(
    contact: &mut WheelRailContact,
    c: &ManchesterReference,
) -> Result<Vec<ContactPoint>, ContactError> {
    let state = WheelState {
        lateral_shift: -c.y_ws / 1000.0,
        yaw: -c.yaw,
        roll: c.roll,
        speed: c.vx / 1000.0,
        axle_rate: Some(-c.vpitch),
        ..Default::default()
    };
    Ok(solve_vertical(contact, &state, VerticalTarget::Load(c.fz_total))?.points)
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

fn manchester_compare(dir: &Path, cases: &[&ManchesterReference], model: CreepModel) -> Result<Worst, ValidationError> {
    let mut contact = manchester_contact_pair(dir, model)?;
    let mut w = Worst::default();
    for c in cases {
        let pts = manchester_solve(&mut contact, c)?;
        if pts.is_empty() {
            return Err(ValidationError::Contact(ContactError::InvalidInput(format!(
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
            // |y| of our contact point vs CONTACT's reference point (y_C = −y_ours).
            w.dy = w.dy.max((p.point().y * 1000.0 + c.ycp_tr).abs());
            w.fn_rel = w.fn_rel.max((p.normal_force - c.fn_).abs() / c.fn_.abs());
            w.fx_rel = w.fx_rel.max((-p.creep.longitudinal - c.fx).abs() / c.fx.abs());
            w.fs_rel = w.fs_rel.max((p.creep.lateral - c.fs).abs() / c.fs.abs());
        } else {
            // CONTACT finds one wide non-Hertzian patch where we find two Hertzian points:
            // compare the load-weighted position and the total normal force only.
            w.two_point += 1;
            let y = pts.iter().map(|p| p.normal_force * p.point().y * 1000.0).sum::<f64>() / fn_total;
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
    let text = std::fs::read_to_string(&file)
        .map_err(|e| ValidationError::BadData { file: file.display().to_string(), message: e.to_string() })?;
    let all = parse_manchester_reference(&text, &file.display().to_string())?;
    // Quick: the integer shifts 0, 1, …, 10 mm.
    let cases: Vec<&ManchesterReference> =
        all.iter().filter(|c| !quick || (c.y_ws - c.y_ws.round()).abs() < 1e-9).collect();
    let n = cases.len();
    let mut out = Vec::new();
    let she = manchester_compare(&dir, &cases, CreepModel::ShenHedrickElkins)?;
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
        laws.push(("Polach kA=kS=1", manchester_compare(&dir, &cases, CreepModel::Polach { k_a: 1.0, k_s: 1.0 })?));
        laws.push(("FASTSIM 40x40", manchester_compare(&dir, &cases, CreepModel::Fastsim { nx: 40, ny: 40 })?));
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
    let offset = RailGeometry::offset_for_gauge(&rail, 1.435, 0.014).ok_or_else(|| ValidationError::BadData {
        file: "UIC60 (analytic)".into(),
        message: "no gauge point".into(),
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
        ValidationError::Contact(ContactError::InvalidInput(format!("no contact point at y = {y} m, yaw = {psi} rad")))
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
    fn environment_variable_is_authoritative() {
        let c = shared_data_candidates(Some(OsStr::new("/nowhere/data")), Some(Path::new("/a/b")));
        assert_eq!(c, vec![PathBuf::from("/nowhere/data")]);
        let err = find_dataset_in(&c, MANCHESTER_DIR, &MANCHESTER_FILES).unwrap_err();
        let msg = err.to_string();
        assert!(msg.starts_with("data not found"), "{msg}");
        assert!(msg.contains("/nowhere/data") && msg.contains(DATA_ENV), "{msg}");
    }

    #[test]
    fn without_the_variable_repository_sibling_and_parents_are_searched() {
        let c = shared_data_candidates(Some(OsStr::new("")), Some(Path::new("/x/y/z")));
        assert!(c[0].ends_with("../../../shared/data"));
        for p in ["/x/y/z/shared/data", "/x/y/shared/data", "/x/shared/data", "/shared/data"] {
            assert!(c.contains(&PathBuf::from(p)), "{p} missing from {c:?}");
        }
    }

    #[test]
    fn unknown_case_names_the_field() {
        let e = run_case("nope", true).unwrap_err().to_string();
        assert!(e.contains("`case`") && e.contains("klingel-wavelength"), "{e}");
    }
}
