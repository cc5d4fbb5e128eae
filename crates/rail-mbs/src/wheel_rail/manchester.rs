//! The Manchester contact benchmark's data (issue 21): finding the shared data directory,
//! reading CONTACT's reference output (`mbench_a22_left.ref_out`: forces, contact positions and
//! patch maps), the left-wheel contact pair from the benchmark's profile files, and our
//! solution of one case for a patch model. The validation case `manchester-contact-left`
//! (crate `railslosh-cases`), the Kik–Piotrowski and Manchester tests and the `patch_models`
//! example use it; it was split from the contact validation module when the cases left the
//! library (issue 18).
//!
//! # Data
//!
//! The CONTACT example files (Apache-2.0) are read from the folder `manchester-contact/` of
//! the shared data directory, found as follows:
//!
//! 1. if the environment variable [`DATA_ENV`] (`RAILSLOSH_SHARED_DATA`) is set and not
//!    empty, it names the shared data directory and nothing else is searched;
//! 2. otherwise `../shared/data` next to the repository this crate was built from
//!    (`CARGO_MANIFEST_DIR/../../../shared/data`), then `shared/data` in the current
//!    directory and each of its parents.
//!
//! When the files are absent the search returns [`DataError::DataNotFound`], listing the
//! folders searched; the CLI and the Python tests report a case that needs them as *skipped:
//! data not found*, never as passed or failed. The data are never copied into the repository.
//!
//! # Frames
//!
//! CONTACT's track frame has x forward, y to the **right**, z **down**; ours has x forward,
//! y left, z up. Hence `y_ours = −y_C`, `roll_ours = roll_C`, `yaw_ours = −yaw_C`,
//! `ω_axle,ours = −VPITCH_C`. CONTACT reports forces on the rail, ours act on the wheel:
//! `FX_C = −Fx_wheel`, `FS_C = +Fy_wheel`.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

use thiserror::Error;

use super::static_load::{VerticalTarget, WheelState, solve_vertical};
use super::{ContactError, CreepModel, Material, RailGeometry, RailPath, WheelGeometry, WheelPose, WheelRailContact};
use crate::profile::{Profile, ProfileError, read_simpack};
use crate::track::Side;

/// Environment variable naming the shared data directory (the folder holding
/// `manchester-contact/`).
pub const DATA_ENV: &str = "RAILSLOSH_SHARED_DATA";

/// Folder of the Manchester benchmark inside the shared data directory.
pub const MANCHESTER_DIR: &str = "manchester-contact";
/// Files of the Manchester benchmark that the case reads.
pub const MANCHESTER_FILES: [&str; 3] = ["mbench_a22_left.ref_out", "MBench_UIC60_v3.prr", "MBench_S1002_v3.prw"];

/// Errors of the shared-data search, the Manchester readers and the benchmark's contact setup.
#[derive(Debug, Error)]
pub enum DataError {
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
pub fn find_dataset_in(candidates: &[PathBuf], dataset: &str, required: &[&str]) -> Result<PathBuf, DataError> {
    for c in candidates {
        let dir = c.join(dataset);
        if required.iter().all(|f| dir.join(f).is_file()) {
            return Ok(dir);
        }
    }
    Err(DataError::DataNotFound {
        dataset: dataset.to_string(),
        required: required.iter().map(|s| s.to_string()).collect(),
        searched: candidates.to_vec(),
    })
}

/// Folder of a data set in the shared data directory (environment and current directory
/// as in the module docs).
pub fn find_dataset(dataset: &str, required: &[&str]) -> Result<PathBuf, DataError> {
    let env = std::env::var_os(DATA_ENV);
    let cwd = std::env::current_dir().ok();
    find_dataset_in(&shared_data_candidates(env.as_deref(), cwd.as_deref()), dataset, required)
}

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

impl ManchesterReference {
    /// The wheel state of this case in this crate's frames (CONTACT's y, yaw and pitch rate
    /// turned to ours; mm/s to m/s).
    pub fn wheel_state(&self) -> WheelState {
        WheelState {
            lateral_shift: -self.y_ws / 1000.0,
            yaw: -self.yaw,
            roll: self.roll,
            speed: self.vx / 1000.0,
            axle_rate: Some(-self.vpitch),
            ..Default::default()
        }
    }
}

fn numbers(line: &str) -> Vec<f64> {
    line.split_whitespace().filter_map(|t| t.parse::<f64>().ok()).collect()
}

/// Parses CONTACT's `mbench_a22_left.ref_out` (first patch of each case).
pub fn parse_manchester_reference(text: &str, file: &str) -> Result<Vec<ManchesterReference>, DataError> {
    let lines: Vec<&str> = text.lines().collect();
    let bad = |i: usize, what: &str| DataError::BadData {
        file: file.to_string(),
        message: format!("line {}: cannot read {what}", i + 2),
    };
    let next = |i: usize, min: usize, what: &str| -> Result<Vec<f64>, DataError> {
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
        return Err(DataError::BadData {
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
pub fn parse_manchester_patches(text: &str, file: &str) -> Result<Vec<ManchesterPatch>, DataError> {
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
                return Err(DataError::BadData {
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
        return Err(DataError::BadData {
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
pub fn manchester_patch_case(contact: &mut WheelRailContact, c: &ManchesterReference) -> Result<PatchCase, DataError> {
    let loaded = solve_vertical(contact, &c.wheel_state(), VerticalTarget::Load(c.fz_total))?;
    let pts = &loaded.points;
    let main = pts.iter().max_by(|a, b| a.normal_force.total_cmp(&b.normal_force)).ok_or_else(|| {
        DataError::Contact(ContactError::InvalidInput(format!("no loaded contact point at y_ws = {} mm", c.y_ws)))
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
pub fn manchester_contact_pair(dir: &Path, model: CreepModel) -> Result<WheelRailContact, DataError> {
    let rail_full = read_simpack(dir.join("MBench_UIC60_v3.prr"))?.to_profile()?;
    let wheel: Profile = read_simpack(dir.join("MBench_S1002_v3.prw"))?.to_profile()?;
    let offset = RailGeometry::offset_for_gauge(&rail_full, 1.435, 0.014).ok_or_else(|| DataError::BadData {
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
}
