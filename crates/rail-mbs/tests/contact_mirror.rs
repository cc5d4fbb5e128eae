//! Mirror symmetry of the wheel/rail contact (issue 21): with the same (symmetric) profiles on
//! both sides, the right wheel at lateral shift y, yaw ψ and roll φ is the mirror image of the
//! left wheel at −y, −ψ, −φ. The mapping is written once, in the library
//! (`WheelPose::mirrored`, `mirror_vector`, `mirror_pseudovector`): the reflection
//! M = diag(1, −1, 1) of the track's lateral axis maps positions and forces as x → M x,
//! rotations as R → M R M, the angular velocity (a pseudovector) as ω → −M ω, and moments
//! (pseudovectors) as m → −M m. The validation case `contact-mirror-symmetry`
//! (`railslosh_cases::contact`) runs the same sweep.

use nalgebra::{Matrix3, Vector3};
use rail_mbs::profile::{s1002_wheel, uic60_rail};
use rail_mbs::track::Side;
mod common;
use common::contact::{height_for_load, s1002_on_uic60};
use rail_mbs::wheel_rail::{
    RailGeometry, RailPath, WheelGeometry, WheelPose, WheelRailContact, mirror_pseudovector, mirror_vector,
};

fn contact(side: Side) -> WheelRailContact {
    let mut c = s1002_on_uic60(side, RailPath::Straight { inward_cant: 1.0 / 40.0 });
    c.settings.always_scan = true; // no warm start: each pose is found from scratch
    c
}

fn rot(yaw: f64, roll: f64) -> Matrix3<f64> {
    let (sz, cz) = yaw.sin_cos();
    let (sx, cx) = roll.sin_cos();
    Matrix3::new(cz, -sz, 0.0, sz, cz, 0.0, 0.0, 0.0, 1.0) * Matrix3::new(1.0, 0.0, 0.0, 0.0, cx, -sx, 0.0, sx, cx)
}

/// Contact points that the search could only approximate (scan fall-backs).
static FALLBACKS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// Total force on the wheel and moment about the wheelset centre (global), and the normal
/// forces, sorted by contact-point lateral position.
/// The wheel of a wheelset at lateral shift `y` with `yaw` and `roll`, rolling at 20 m/s with
/// a little lateral and longitudinal creep, at the nominal height (r0 = 0.46 m).
fn rolling_pose(y: f64, yaw: f64, roll: f64) -> WheelPose {
    let (v, r0) = (20.0, 0.46);
    WheelPose {
        position: Vector3::new(5.0, y, r0),
        rotation: rot(yaw, roll),
        velocity: Vector3::new(v, 0.05, 0.0),
        angular_velocity: Vector3::new(0.0, v / r0 * 1.001, 0.0),
    }
}

fn resultant(c: &mut WheelRailContact, pose: &WheelPose) -> (Vector3<f64>, Vector3<f64>, Vec<f64>) {
    c.reset(); // a pure function of the pose: no previous solution as a starting guess
    let pts = c.evaluate(pose).unwrap();
    FALLBACKS.fetch_add(
        pts.iter().filter(|p| p.geometry.method != rail_mbs::wheel_rail::ContactMethod::Newton).count(),
        std::sync::atomic::Ordering::Relaxed,
    );
    let f = pts.iter().map(|p| p.force_on_wheel()).sum();
    let m = pts.iter().map(|p| p.moment_on_wheel(&pose.position)).sum();
    let mut n: Vec<(f64, f64)> = pts.iter().map(|p| (p.point().y.abs(), p.normal_force)).collect();
    n.sort_by(|a, b| a.0.total_cmp(&b.0));
    (f, m, n.into_iter().map(|x| x.1).collect())
}

#[test]
fn the_right_wheel_is_the_mirror_image_of_the_left_wheel_over_a_sweep_of_shifts() {
    let (mut left, mut right) = (contact(Side::Left), contact(Side::Right));
    let mut worst: f64 = 0.0;
    let mut cases = 0;
    let mut counts = std::collections::BTreeMap::new();
    for &(yaw, roll) in &[(0.0, 0.0), (0.004, 0.0), (-0.003, 0.0015)] {
        for k in 0..=200 {
            // wheelset shift −10 … +10 mm (both flange contacts and the jumps towards them)
            let y = -0.010 + 1e-4 * k as f64;
            let mut pose = rolling_pose(y, yaw, roll);
            // the left wheel carrying 60 kN (the mirrored right wheel is then at that height too)
            pose.position.z = height_for_load(&mut left, &pose, 6e4, 0.02);
            let (fl, ml, nl) = resultant(&mut left, &pose);
            let mp = pose.mirrored();
            let (fr, mr, nr) = resultant(&mut right, &mp);
            *counts.entry(nl.len()).or_insert(0) += 1;
            assert!(!nl.is_empty(), "the wheel touches the rail at y = {y}, yaw {yaw}, roll {roll}");
            assert_eq!(nl.len(), nr.len(), "contact-point count at y = {y}, yaw {yaw}, roll {roll}");
            let scale = fl.norm().max(1.0);
            let ef = (fr - mirror_vector(&fl)).norm() / scale;
            let em = (mr - mirror_pseudovector(&ml)).norm() / (ml.norm().max(1.0));
            let en = nl.iter().zip(&nr).map(|(a, b)| (a - b).abs() / scale).fold(0.0, f64::max);
            worst = worst.max(ef).max(em).max(en);
            assert!(
                ef < 1e-9 && em < 1e-9 && en < 1e-9,
                "y = {y}, yaw {yaw}, roll {roll}: force {ef:e}, moment {em:e}, normal {en:e}"
            );
            cases += 1;
        }
    }
    let fallbacks = FALLBACKS.load(std::sync::atomic::Ordering::Relaxed);
    println!(
        "{cases} mirrored poses, contact-point counts {counts:?}, worst relative difference {worst:.2e}, \
         {fallbacks} scan fall-back points (both wheels)"
    );
}

#[test]
fn the_contact_of_a_pose_does_not_depend_on_the_search_history() {
    // The search starts Newton from earlier solutions when they lie near a scan seed; the
    // points it returns must still be those of a fresh search (same method, same point).
    // Before cdf81e2 (the scan's gap along the rail normal) a fresh search at y = -7.1 mm
    // (flange root) missed the near-conformal Newton point the warm search found (Newton against
    // ScanFallback; docs/validation.md, "Mirror symmetry and the search history").
    let mut warm = contact(Side::Right);
    let mut fresh = contact(Side::Right);
    let (mut worst, mut fallbacks) = (0.0f64, 0);
    for k in 0..=200 {
        let y = 0.010 - 1e-4 * k as f64;
        let mut pose = rolling_pose(y, 0.0, 0.0);
        pose.position.z = height_for_load(&mut warm, &pose, 6e4, 0.02); // leaves a history in `warm`
        let a = warm.evaluate(&pose).unwrap();
        fresh.reset();
        let b = fresh.evaluate(&pose).unwrap();
        assert_eq!(a.len(), b.len(), "y = {y}");
        for (p, q) in a.iter().zip(&b) {
            assert_eq!(p.geometry.method, q.geometry.method, "y = {y}");
            fallbacks += usize::from(p.geometry.method != rail_mbs::wheel_rail::ContactMethod::Newton);
            worst = worst.max((p.normal_force - q.normal_force).abs() / q.normal_force.max(1.0));
            worst = worst.max((p.point() - q.point()).norm() / 1e-3);
        }
    }
    println!("history against fresh search: worst relative difference {worst:.2e}, {fallbacks} scan fall-backs");
    assert!(worst < 1e-9, "{worst}");
}

#[test]
fn the_contact_does_not_depend_on_where_the_track_lies() {
    // The same wheel on the same straight track, once from the global origin and once moved
    // 3.7 m to the left and 0.4 m up (and started 250 m further along X): the contact forces
    // are equal up to the round-off of the larger coordinates.
    use rail_mbs::track::{Track, TrackPoint};
    use std::sync::Arc;
    let pts = || {
        vec![TrackPoint::new(0.0, 0.0, 0.0, 0.0, 0.025, -0.025), TrackPoint::new(500.0, 0.0, 0.0, 0.0, 0.025, -0.025)]
    };
    let shift = Vector3::new(250.0, 3.7, 0.4);
    let make = |origin: Vector3<f64>| {
        let track = Arc::new(Track::with_origin(pts(), origin, 0.0).unwrap());
        let rail = uic60_rail(2e-4).unwrap();
        let offset = RailGeometry::offset_for_gauge(&rail, 1.435, 0.014).unwrap();
        WheelRailContact::new(
            WheelGeometry {
                profile: s1002_wheel(2e-4).unwrap(),
                nominal_radius: 0.46,
                profile_offset: 0.75,
                side: Side::Left,
            },
            RailGeometry {
                profile: rail,
                side: Side::Left,
                profile_offset: offset,
                vertical_offset: 0.0,
                path: RailPath::Track(track),
            },
        )
    };
    let (mut here, mut there) = (make(Vector3::zeros()), make(shift));
    // Newton points agree to round-off (1e-9). A scan fall-back point is the minimum of a
    // gap that Newton could not solve: at 60 kN that happens only at 7.1 mm, in the conformal
    // stretch of the flange root (relative lateral curvature B ~ 0, docs/validation.md "The
    // scan's gap at the flange root"), where the gap is flat and its minimum is located only
    // to about sqrt(round-off of the coordinates / B) ~ sqrt(3e-14 m / 0.06 m^-1) ~ 1 um. Its
    // force takes Hertz's lateral curvature from the interpenetration region measured along
    // the normal at that point (`WheelRailContact::lateral_curvature`), and the normal turns
    // with the point's position by the rail's curvature (77 1/m x 1 um ~ 8e-5 rad): those
    // points are checked to 2 um in position and 1e-5 in force (measured 8.3e-8 with the local
    // curvature, 2.8e-6 with the region's), and there is at most one.
    let (mut worst, mut worst_flat, mut flat): (f64, f64, usize) = (0.0, 0.0, 0);
    for k in 0..=40 {
        let y = -0.004 + 3e-4 * k as f64;
        let mut pose = WheelPose {
            position: Vector3::new(100.0, y, 0.46),
            rotation: rot(0.002, 0.0),
            velocity: Vector3::new(20.0, 0.05, 0.0),
            angular_velocity: Vector3::new(0.0, 20.0 / 0.46 * 1.001, 0.0),
        };
        pose.position.z = height_for_load(&mut here, &pose, 6e4, 0.02);
        let moved = WheelPose { position: pose.position + shift, ..pose };
        // searches from scratch: the contact is a pure function of the pose
        here.reset();
        there.reset();
        let (pa, pb) = (here.evaluate(&pose).unwrap(), there.evaluate(&moved).unwrap());
        assert_eq!(pa.len(), pb.len(), "y = {y}");
        let total =
            |pts: &[rail_mbs::wheel_rail::ContactPoint]| pts.iter().map(|p| p.force_on_wheel()).sum::<Vector3<f64>>();
        let (fa, fb) = (total(&pa), total(&pb));
        let rel = (fa - fb).norm() / fa.norm();
        if pa.iter().chain(&pb).all(|p| p.geometry.method == rail_mbs::wheel_rail::ContactMethod::Newton) {
            worst = worst.max(rel);
        } else {
            flat += 1;
            worst_flat = worst_flat.max(rel);
            for (a, b) in pa.iter().zip(&pb) {
                assert!((a.point() + shift - b.point()).norm() < 2e-6, "y = {y}: fall-back point moved");
            }
        }
    }
    println!(
        "track moved by {shift:?}: worst relative force difference {worst:.2e} (Newton points); {flat} poses with \
         fall-back points, worst {worst_flat:.2e}"
    );
    assert!(worst < 1e-9, "{worst}");
    assert!(flat <= 1 && worst_flat < 1e-5, "{flat} poses with fall-back points, worst {worst_flat}");
}

/// Largest distance (m) between the warm-started and the fresh contact points at the target
/// shifts 0, 0.5, …, 10 mm of the left wheel (60 kN), the wheelset swept there in steps of
/// `step` m with the search warm-started from step to step; and the number of targets whose
/// point count differs.
fn sweep_error(step: f64) -> (f64, usize) {
    let mut warm = s1002_on_uic60(Side::Left, RailPath::Straight { inward_cant: 1.0 / 40.0 });
    warm.settings.always_scan = true;
    let mut fresh = contact(Side::Left);
    let base = WheelPose {
        position: Vector3::new(5.0, 0.0, 0.46),
        rotation: Matrix3::identity(),
        velocity: Vector3::new(20.0, 0.0, 0.0),
        angular_velocity: Vector3::new(0.0, 20.0 / 0.46, 0.0),
    };
    let n = (0.010 / step).round() as usize;
    let every = (0.0005 / step).round() as usize;
    let (mut worst, mut count_differs) = (0.0f64, 0);
    let mut z = 0.46;
    for k in 0..=n {
        let y = step * k as f64;
        let mut pose = WheelPose { position: Vector3::new(5.0, y, z), ..base };
        // the height for 60 kN from a fresh search (the same at every step size)
        pose.position.z = height_for_load(&mut fresh, &pose, 6e4, 0.02);
        z = pose.position.z;
        let a = warm.evaluate(&pose).unwrap();
        if k % every == 0 {
            fresh.reset();
            let b = fresh.evaluate(&pose).unwrap();
            if a.len() != b.len() {
                count_differs += 1;
                continue;
            }
            for (p, q) in a.iter().zip(&b) {
                worst = worst.max((p.point() - q.point()).norm());
            }
        }
    }
    (worst, count_differs)
}

#[test]
fn the_warm_started_contact_point_converges_with_the_sweep_step() {
    // Issue 21: sweeping the wheelset towards flange contact in finer and finer steps, the
    // warm-started search must land on the fresh search's points at the shared shifts.
    let mut rows = Vec::new();
    for step in [5e-4, 2.5e-4, 1e-4, 5e-5] {
        let (worst, differs) = sweep_error(step);
        println!(
            "step {:.3} mm: worst point distance {:.3e} m, {differs} of 21 shifts with another point count",
            step * 1e3,
            worst
        );
        rows.push((step, worst, differs));
    }
    for (step, worst, differs) in &rows {
        assert_eq!(*differs, 0, "step {step}");
        assert!(*worst < 1e-9, "step {step}: {worst}");
    }
}

/// The mirror images hold with CONTACT's patch rule too (`PatchCombination::contact()`: A_SEP = π,
/// D_SEP = 8 mm, D_COMB = 4 mm; every two-point contact of this pair is one combined patch):
/// (ψ, φ) = (−3 mrad, 1.5 mrad), 201 shifts −10 … +10 mm, the left wheel at 60 kN with the rule.
#[test]
fn the_mirror_images_hold_with_combined_patches() {
    use rail_mbs::wheel_rail::PatchCombination;
    let (mut left, mut right) = (contact(Side::Left), contact(Side::Right));
    left.settings.patch_combination = PatchCombination::contact();
    right.settings.patch_combination = PatchCombination::contact();
    let (yaw, roll) = (-0.003, 0.0015);
    let (mut worst, mut combined): (f64, usize) = (0.0, 0);
    for k in 0..=200 {
        let y = -0.010 + 1e-4 * k as f64;
        let mut pose = rolling_pose(y, yaw, roll);
        pose.position.z = height_for_load(&mut left, &pose, 6e4, 0.02);
        let (fl, ml, nl) = resultant(&mut left, &pose);
        let (fr, mr, nr) = resultant(&mut right, &pose.mirrored());
        left.reset();
        combined += usize::from(left.evaluate(&pose).unwrap().iter().any(|p| p.patch.is_some()));
        assert_eq!(nl.len(), nr.len(), "contact-point count at y = {y}");
        let scale = fl.norm().max(1.0);
        let ef = (fr - mirror_vector(&fl)).norm() / scale;
        let em = (mr - mirror_pseudovector(&ml)).norm() / (ml.norm().max(1.0));
        let en = nl.iter().zip(&nr).map(|(a, b)| (a - b).abs() / scale).fold(0.0, f64::max);
        worst = worst.max(ef).max(em).max(en);
        assert!(ef < 1e-9 && em < 1e-9 && en < 1e-9, "y = {y}: force {ef:e}, moment {em:e}, normal {en:e}");
    }
    println!(
        "combined patches: 201 mirrored poses, {combined} with a combined patch, worst relative difference {worst:.2e}"
    );
    assert!(combined >= 10, "the sweep meets combined patches: {combined}");
}
