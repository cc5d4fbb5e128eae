//! Where our search finds two contact points, what CONTACT's patch rule (A_SEP, D_SEP,
//! D_COMB; docs/validation.md, "One patch or two") would make of them:
//! `cargo run --release -p railslosh-cases --example patch_separation`.
//!
//! For each of the two points, the rigid interpenetration region across the contact is where the
//! undeformed separation `h(y)` (`WheelRailContact::separation`, along the contact's lateral
//! axis) stays below the point's penetration δ; its ends are placed in the track's y–z plane. As
//! in CONTACT (`combine_cpatches`, module `m_wr_locatecp` of its open-source release), `dist` is
//! the distance between the facing ends of the two regions and `dangle` the angle between the
//! two contact normals: kept apart when `dangle > A_SEP` or `dist > D_SEP`, one patch when
//! `dist ≤ D_COMB`, and in between one patch whose two parts interact with the weight
//! `((D_SEP − dist)/(D_SEP − D_COMB))^0.8`. The Manchester benchmark's values: A_SEP = 90°,
//! D_SEP = 8 mm, D_COMB = 4 mm.
use rail_mbs::track::Side;
use rail_mbs::wheel_rail::manchester::{
    MANCHESTER_DIR, MANCHESTER_FILES, find_dataset, manchester_contact_pair, parse_manchester_reference,
};
use rail_mbs::wheel_rail::{
    ContactError, ContactPoint, CreepModel, PatchCombination, VerticalTarget, WheelPose, WheelRailContact, WheelState,
    solve_vertical,
};

/// CONTACT's decision for two points: (dist mm, dangle deg, decision), from the library's
/// interpenetration regions (`WheelRailContact::interpenetration_region`) and rule
/// (`PatchCombination::coupling`). Where the two regions overlap, the rigid interpenetration is
/// one region, which CONTACT's scan finds as one.
fn decide(c: &WheelRailContact, pose: &WheelPose, pts: &[ContactPoint]) -> Result<(f64, f64, String), ContactError> {
    let ra = c.interpenetration_region(pose, &pts[0].geometry)?;
    let rb = c.interpenetration_region(pose, &pts[1].geometry)?;
    let dist = ra.distance(&rb);
    let dangle = pts[0].geometry.normal.dot(&pts[1].geometry.normal).clamp(-1.0, 1.0).acos();
    let rule = PatchCombination::manchester();
    let PatchCombination::Contact { d_comb, .. } = rule else { unreachable!() };
    let weight = rule.coupling(dist, dangle);
    let decision = if dist == 0.0 {
        // CONTACT's scan finds one interpenetration region: one patch before any combining
        "one interpenetration region: one patch".to_string()
    } else if weight == 0.0 {
        "two patches".to_string()
    } else if dist <= d_comb {
        "one patch".to_string()
    } else {
        format!("one patch, parts weighted {weight:.2}")
    };
    Ok((dist * 1e3, dangle.to_degrees(), decision))
}

fn row(c: &WheelRailContact, label: &str, pose: &WheelPose, pts: &[ContactPoint]) {
    if pts.len() != 2 {
        return;
    }
    match decide(c, pose, pts) {
        Ok((dist, dangle, decision)) => println!(
            "{label}: points {:.2} mm apart (N = {:.0} / {:.0} N); region gap {dist:.2} mm, normals {dangle:.1} deg \
             apart -> CONTACT: {decision}",
            (pts[0].point() - pts[1].point()).norm() * 1e3,
            pts[0].normal_force,
            pts[1].normal_force
        ),
        Err(e) => println!("{label}: {e}"),
    }
}

fn main() {
    // Manchester, left wheel, 10 kN (CONTACT's own patch count printed beside ours).
    match find_dataset(MANCHESTER_DIR, &MANCHESTER_FILES) {
        Ok(dir) => {
            let file = dir.join(MANCHESTER_FILES[0]);
            let text = std::fs::read_to_string(&file).expect("reference output");
            let cases = parse_manchester_reference(&text, &file.display().to_string()).expect("reference output");
            let mut c = manchester_contact_pair(&dir, CreepModel::ShenHedrickElkins).expect("contact pair");
            println!("Manchester A-2.2 left wheel, 10 kN (shifts where we find two points):");
            for r in &cases {
                let l = solve_vertical(&mut c, &r.wheel_state(), VerticalTarget::Load(r.fz_total)).expect("solve");
                let label = format!("  y_ws {:>4.1} mm, CONTACT {} patch(es)", r.y_ws, r.patches);
                row(&c, &label, &l.pose, &l.points);
            }
        }
        Err(e) => println!("Manchester case skipped: {e}"),
    }
    // The analytic S1002/UIC 60 pair at 1:40, 60 kN, shifts 0-10 mm towards the left flange.
    let mut c = railslosh_cases::contact::s1002_on_uic60(Side::Left).expect("S1002 on UIC 60");
    println!("S1002 on UIC 60 1:40 (analytic), left wheel, 60 kN, 20 m/s (shifts where we find two points):");
    for k in 0..=100 {
        let y = 1e-4 * k as f64;
        let state = WheelState { lateral_shift: y, speed: 20.0, ..WheelState::default() };
        match solve_vertical(&mut c, &state, VerticalTarget::Load(6e4)) {
            Ok(l) => row(&c, &format!("  y {:>4.1} mm", y * 1e3), &l.pose, &l.points),
            Err(ContactError::TargetNotMet { .. }) => println!("  y {:>4.1} mm: in the jump", y * 1e3),
            Err(e) => println!("  y {:>4.1} mm: {e}", y * 1e3),
        }
    }
}
