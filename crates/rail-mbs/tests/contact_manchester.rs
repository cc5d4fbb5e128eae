//! Manchester contact benchmark, case, left wheel (S1002 on UIC60 canted 1:40),
//! compared with CONTACT's reference output (`mbench_a22_left.ref_out`, Apache-2.0).
//!
//! The data are read from `../shared/data/manchester-contact` relative to the workspace
//! root; without them the tests fail under CI and are skipped visibly elsewhere
//! (`common::data_missing`).
//!
//! Frames: CONTACT's track frame has x forward, y to the **right**, z **down**; ours has
//! x forward, y left, z up. Hence `y_ours = −y_C`, `roll_ours = roll_C` (same physical
//! axis), `yaw_ours = −yaw_C`, `ω_axle,ours = −VPITCH_C`. CONTACT reports forces on the
//! rail; ours are on the wheel: `FX_C = −Fx_wheel`, `FS_C = +Fy_wheel` (our `e2` points
//! left, CONTACT's lateral axis right).

use std::path::PathBuf;

mod common;

use nalgebra::{Matrix3, Vector3};
use rail_mbs::wheel_rail::{ContactPoint, CreepModel, WheelPose, WheelRailContact};

fn data_dir() -> Option<PathBuf> {
    let p = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/manchester-contact"));
    if p.join("mbench_a22_left.ref_out").is_file() {
        Some(p)
    } else {
        common::data_missing(&format!("Manchester contact data at {}", p.display()));
        None
    }
}

/// One case of the reference output (CONTACT units: mm, N, rad, mm/s).
#[derive(Debug, Clone, Default)]
struct RefCase {
    y_ws: f64,
    roll: f64,
    yaw: f64,
    vx: f64,
    vpitch: f64,
    patches: usize,
    ycp_tr: f64,
    fx: f64,
    fs: f64,
    fn_: f64,
    fz_total: f64,
    /// CONTACT creepages (rail relative to wheel, CONTACT axes): ξ, η, φ (1/mm).
    creep: [f64; 3],
}

fn numbers(line: &str) -> Vec<f64> {
    line.split_whitespace().filter_map(|t| t.parse::<f64>().ok()).collect()
}

fn parse_ref(text: &str) -> Vec<RefCase> {
    let lines: Vec<&str> = text.lines().collect();
    let mut cases: Vec<RefCase> = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let l = lines[i].trim();
        if l.starts_with("Case ") {
            cases.push(RefCase::default());
        } else if let Some(c) = cases.last_mut() {
            if l.starts_with("WHEEL-RAIL CONTACT, LEFT WHEEL,") {
                c.patches = numbers(l.split(',').nth(2).unwrap_or("")).first().map(|v| *v as usize).unwrap_or(0);
            } else if l.starts_with("S_WS") {
                let v = numbers(lines[i + 1]);
                c.y_ws = v[1];
                c.roll = v[3];
                c.yaw = v[4];
            } else if l.starts_with("VX_WS") {
                let v = numbers(lines[i + 1]);
                c.vx = v[0];
                c.vpitch = v[5];
            } else if l.starts_with("FX(TR)") {
                let v = numbers(lines[i + 1]);
                c.fz_total = v[2];
            } else if l.starts_with("XCP(TR)") && c.ycp_tr == 0.0 {
                c.ycp_tr = numbers(lines[i + 1])[1];
            } else if l.starts_with("CHI ") && c.creep == [0.0; 3] {
                let v = numbers(lines[i + 1]);
                c.creep = [v[3], v[4], v[5]];
            } else if l.starts_with("FN ") && c.fn_ == 0.0 {
                let v = numbers(lines[i + 1]);
                c.fn_ = v[0];
                c.fx = v[1];
                c.fs = v[2];
            }
        }
        i += 1;
    }
    cases
}

/// The contact pair of the benchmark (the validation case's own construction).
fn setup(dir: &std::path::Path, model: CreepModel) -> WheelRailContact {
    rail_mbs::wheel_rail::manchester::manchester_contact_pair(dir, model).expect("Manchester contact pair")
}

fn rot_z(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}
fn rot_x(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

/// Solves the wheelset height for a total vertical force `fz` on the wheel and returns
/// the contacts.
fn solve_case(contact: &mut WheelRailContact, c: &RefCase, fz: f64) -> (f64, Vec<ContactPoint>) {
    let rotation = rot_z(-c.yaw) * rot_x(c.roll);
    let v = c.vx / 1000.0;
    let omega_axle = -c.vpitch;
    let pose_at = |z: f64| WheelPose {
        position: Vector3::new(0.0, -c.y_ws / 1000.0, z),
        rotation,
        velocity: Vector3::new(v, 0.0, 0.0),
        angular_velocity: rotation * Vector3::new(0.0, omega_axle, 0.0),
    };
    let vertical = |contact: &mut WheelRailContact, z: f64| -> f64 {
        contact.evaluate(&pose_at(z)).expect("contact evaluation").iter().map(|p| p.force_on_wheel().z).sum()
    };
    // Bracket: at z = 0.47 m the wheel is clear; go down until the force exceeds fz.
    let mut hi = 0.470;
    let mut lo = 0.460;
    while vertical(contact, lo) < fz {
        hi = lo;
        lo -= 0.002;
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if vertical(contact, mid) > fz {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let z = 0.5 * (lo + hi);
    let pts = contact.evaluate(&pose_at(z)).expect("contact evaluation");
    (z, pts)
}

fn pct(ours: f64, reference: f64) -> f64 {
    100.0 * (ours - reference) / reference.abs()
}

/// One compared case: reference, our |y| of the most loaded contact (mm), its FN, FX,
/// FS (CONTACT convention, N), our number of contact points, and the normal-force
/// weighted mean |y| (mm) and total FN over all our points.
struct Row {
    c: RefCase,
    y_cp: f64,
    fn_: f64,
    fx: f64,
    fs: f64,
    n: usize,
    y_weighted: f64,
    fn_total: f64,
    /// Our creepages of the most loaded point in CONTACT's convention (φ in 1/mm).
    creep_c: [f64; 3],
}

fn run(model: CreepModel, label: &str) -> Option<Vec<Row>> {
    let dir = data_dir()?;
    let text = std::fs::read_to_string(dir.join("mbench_a22_left.ref_out")).expect("ref_out");
    let cases = parse_ref(&text);
    assert_eq!(cases.len(), 21, "expected 21 cases in the reference output");
    let mut contact = setup(&dir, model);
    println!("Manchester A-2.2 left wheel, creep law {label}");
    println!(
        "{:>5} {:>4} | {:>9} {:>9} {:>6} | {:>8} {:>8} {:>6} | {:>8} {:>8} {:>6} | {:>8} {:>8} {:>6}",
        "y_ws", "np", "|y|cp", "ref", "d(mm)", "FN", "ref", "%", "FX", "ref", "%", "FS", "ref", "%"
    );
    let mut out = Vec::new();
    for c in cases.iter() {
        let (_z, pts) = solve_case(&mut contact, c, c.fz_total);
        let n_ours = pts.len();
        // Report the most loaded contact.
        let p = pts.iter().max_by(|a, b| a.normal_force.total_cmp(&b.normal_force)).expect("at least one contact");
        let y_cp = p.point().y * 1000.0;
        let fx_c = -p.creep.longitudinal;
        let fs_c = p.creep.lateral;
        let fn_ = p.normal_force;
        println!(
            "{:>5.1} {:>2}/{} | {:>9.3} {:>9.3} {:>6.2} | {:>8.1} {:>8.1} {:>6.2} | {:>8.1} {:>8.1} {:>6.1} | {:>8.1} {:>8.1} {:>6.1}",
            c.y_ws,
            n_ours,
            c.patches,
            y_cp,
            -c.ycp_tr,
            y_cp + c.ycp_tr,
            fn_,
            c.fn_,
            pct(fn_, c.fn_),
            fx_c,
            c.fx,
            pct(fx_c, c.fx),
            fs_c,
            c.fs,
            pct(fs_c, c.fs)
        );
        // Creepages: ours are wheel-relative-to-rail along (e1 forward, e2 left, n up);
        // CONTACT's are rail-relative-to-wheel in axes (x forward, y right, z down), so
        // CKSI = −ξ, CETA = +η and CPHI = +φ (two sign flips each for η and φ).
        println!(
            "        creepages ours xi {:+.4e} eta {:+.4e} phi {:+.4e} 1/mm | CONTACT CKSI {:+.4e} CETA {:+.4e} CPHI {:+.4e}",
            p.creepages.longitudinal,
            p.creepages.lateral,
            p.creepages.spin / 1000.0,
            c.creep[0],
            c.creep[1],
            c.creep[2]
        );
        if n_ours > 1 {
            for q in &pts {
                println!(
                    "        point at |y| = {:.3} mm: FN {:.1} N, FX {:.1} N, FS {:.1} N, contact angle {:.4} rad",
                    q.point().y * 1000.0,
                    q.normal_force,
                    -q.creep.longitudinal,
                    q.creep.lateral,
                    q.geometry.normal.z.acos()
                );
            }
        }
        let fn_total: f64 = pts.iter().map(|q| q.normal_force).sum();
        let y_weighted = pts.iter().map(|q| q.normal_force * q.point().y * 1000.0).sum::<f64>() / fn_total;
        let creep_c = [-p.creepages.longitudinal, p.creepages.lateral, p.creepages.spin / 1000.0];
        out.push(Row { c: c.clone(), y_cp, fn_, fx: fx_c, fs: fs_c, n: n_ours, y_weighted, fn_total, creep_c });
    }
    Some(out)
}

/// Checks one creep law against the reference: contact position within 1 mm, normal
/// force within 1 %, creep forces within `creep_tol_pct` (single-point cases only).
fn check(model: CreepModel, label: &str, creep_tol_pct: f64) {
    let Some(rows) = run(model, label) else {
        return;
    };
    let mut compared = 0;
    let mut worst = [0.0f64; 4];
    for Row { c, y_cp, fn_, fx, fs, n, y_weighted, fn_total, creep_c } in rows {
        assert_eq!(c.patches, 1, "reference case y = {} mm has one patch", c.y_ws);
        if c.y_ws > 10.0 + 1e-9 || n != 1 {
            // CONTACT finds one wide non-Hertzian patch where we find two Hertzian points:
            // compare only the load-weighted position and the total normal force.
            let dy = y_weighted + c.ycp_tr;
            println!(
                "y_ws = {} mm: {} contact points; load-weighted |y| {:.3} mm (ref {:.3}, d {:.2} mm), total FN {:.1} N (ref {:.1}); creep not compared",
                c.y_ws, n, y_weighted, -c.ycp_tr, dy, fn_total, c.fn_
            );
            assert!(dy.abs() < 1.0, "load-weighted contact position off by {dy} mm");
            assert!(pct(fn_total, c.fn_).abs() < 1.0);
            continue;
        }
        compared += 1;
        // Creepages from our rigid-body kinematics at our contact point vs CONTACT's at
        // its reference point.
        let rel = |k: usize| ((creep_c[k] - c.creep[k]) / c.creep[k]).abs();
        assert!(rel(0) < 0.12, "y_ws {}: xi {:?} vs {:?}", c.y_ws, creep_c, c.creep);
        assert!(rel(1) < 0.02, "y_ws {}: eta {:?} vs {:?}", c.y_ws, creep_c, c.creep);
        assert!(rel(2) < 0.08, "y_ws {}: phi {:?} vs {:?}", c.y_ws, creep_c, c.creep);
        let dy = (y_cp + c.ycp_tr).abs();
        worst[0] = worst[0].max(dy);
        worst[1] = worst[1].max(pct(fn_, c.fn_).abs());
        worst[2] = worst[2].max(pct(fx, c.fx).abs());
        worst[3] = worst[3].max(pct(fs, c.fs).abs());
        assert!(dy < 1.0, "y_ws {}: contact position off by {dy:.3} mm", c.y_ws);
        assert!(pct(fn_, c.fn_).abs() < 1.0, "y_ws {}: FN {fn_:.1} vs {:.1}", c.y_ws, c.fn_);
        assert!(pct(fx, c.fx).abs() < creep_tol_pct, "y_ws {}: FX {fx:.1} vs {:.1}", c.y_ws, c.fx);
        assert!(pct(fs, c.fs).abs() < creep_tol_pct, "y_ws {}: FS {fs:.1} vs {:.1}", c.y_ws, c.fs);
    }
    println!(
        "{label}: {compared} single-point cases compared; worst |dy| = {:.3} mm, FN {:.2} %, FX {:.1} %, FS {:.1} %",
        worst[0], worst[1], worst[2], worst[3]
    );
    assert!(compared >= 19, "too few single-point cases compared: {compared}");
}

/// The vertical contact force equals the applied load after the height solve, and the
/// normal force is consistent with the Hertz law at the solved penetration.
#[test]
fn manchester_load_balance() {
    let Some(dir) = data_dir() else {
        return;
    };
    let text = std::fs::read_to_string(dir.join("mbench_a22_left.ref_out")).expect("ref_out");
    let cases = parse_ref(&text);
    let mut contact = setup(&dir, CreepModel::ShenHedrickElkins);
    for c in cases.iter().step_by(4) {
        let (_z, pts) = solve_case(&mut contact, c, 10_000.0);
        let fz: f64 = pts.iter().map(|p| p.force_on_wheel().z).sum();
        assert!((fz - 10_000.0).abs() < 1e-3, "vertical force {fz} N");
        for p in &pts {
            let fe = p.hertz.stiffness * p.geometry.penetration.powf(1.5);
            assert!((fe - p.normal_force).abs() < 1e-9 * fe.max(1.0));
            assert!(p.geometry.penetration > 0.0 && p.geometry.penetration < 2e-4);
        }
    }
}

#[test]
fn manchester_a22_left_she() {
    check(CreepModel::ShenHedrickElkins, "Shen-Hedrick-Elkins", 15.0);
}

#[test]
fn manchester_a22_left_polach() {
    check(CreepModel::Polach { k_a: 1.0, k_s: 1.0 }, "Polach (kA = kS = 1)", 15.0);
}

#[test]
fn manchester_a22_left_fastsim() {
    check(CreepModel::Fastsim { nx: 40, ny: 40 }, "FASTSIM (40 x 40)", 15.0);
}
