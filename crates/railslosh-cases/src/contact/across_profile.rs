//! Contact across the whole profile (issue 21): mirror symmetry, the search across the
//! contact-point jumps, friction that varies over the rail profile and quasi-static flange
//! climb. All on the analytic S1002 wheel and UIC 60 rail canted 1:40 (r0 = 0.46 m, profile
//! origin 0.75 m from the wheelset centre, gauge 1435 mm at 14 mm, steel, no shared data), the
//! wheel at the height that carries its load ([`solve_vertical`]).

use std::sync::Arc;

use nalgebra::Vector3;

use rail_mbs::profile::{s1002_wheel, uic60_rail};
use rail_mbs::track::Side;
use rail_mbs::wheel_rail::manchester::DataError;
use rail_mbs::wheel_rail::{
    ContactError, ContactMethod, ContactPoint, Creepages, FrictionMap, RailGeometry, RailPath, VerticalTarget,
    WheelGeometry, WheelPose, WheelRailContact, WheelState, mirror_pseudovector, mirror_vector, nadal_limit,
    solve_vertical,
};

use super::ValidationError;
use crate::Record;

const R0: f64 = 0.46;

/// One wheel of the S1002/UIC 60 pair (module docs) on `side`: S1002 wheel (r0 = 0.46 m) on
/// the analytic UIC 60 rail canted 1:40, gauge 1435 mm at 14 mm.
pub fn s1002_on_uic60(side: Side) -> Result<WheelRailContact, ValidationError> {
    let rail = uic60_rail(2e-4)?;
    let offset = RailGeometry::offset_for_gauge(&rail, 1.435, 0.014).ok_or_else(|| {
        ValidationError::from(DataError::BadData { file: "UIC60 (analytic)".into(), message: "no gauge point".into() })
    })?;
    Ok(WheelRailContact::new(
        WheelGeometry { profile: s1002_wheel(2e-4)?, nominal_radius: R0, profile_offset: 0.75, side },
        RailGeometry {
            profile: rail,
            side,
            profile_offset: offset,
            vertical_offset: 0.0,
            path: RailPath::Straight { inward_cant: 1.0 / 40.0 },
        },
    ))
}

/// The pose at which the wheel carries `load` (N): [`solve_vertical`]'s height; where the
/// vertical force jumps across the load (a contact-point jump: no height carries it), the
/// height of the jump.
fn pose_for_load(c: &mut WheelRailContact, state: &WheelState, load: f64) -> Result<WheelPose, ContactError> {
    match solve_vertical(c, state, VerticalTarget::Load(load)) {
        Ok(l) => Ok(l.pose),
        Err(ContactError::TargetNotMet { height, .. }) => Ok(state.pose(c.wheel.nominal_radius, height)),
        Err(e) => Err(e),
    }
}

/// A contact point that moves further than this (m, lateral) from one sweep shift to the next
/// has jumped. On S1002/UIC 60 at 1:40 the jumps are 5.8–11.5 mm (a second tread point, the
/// flange root, the flange), while the steepest continuous motion, near the flange root, is
/// 1.7 mm over a 0.5 mm shift step.
const JUMP: f64 = 3e-3;

/// Lateral positions (m, track frame) of the contact points.
fn point_ys(pts: &[ContactPoint]) -> Vec<f64> {
    pts.iter().map(|p| p.point().y).collect()
}

/// Shift intervals `[y_k, y_k+1]` (m) of a sweep `(shift, contact-point positions)` over which
/// the contact point jumps: a point of shift `k+1` lies more than [`JUMP`] from every point of
/// shift `k` (a second point appears away from the first, or the point leaps).
fn jumps(sweep: &[(f64, Vec<f64>)]) -> Vec<(f64, f64)> {
    sweep
        .windows(2)
        .filter(|w| w[1].1.iter().any(|b| w[0].1.iter().all(|a| (a - b).abs() > JUMP)))
        .map(|w| (w[0].0.min(w[1].0), w[0].0.max(w[1].0)))
        .collect()
}

// ---------------------------------------------------------------------------------------
// Mirror symmetry
// ---------------------------------------------------------------------------------------

/// Worst deviations of the mirror sweep.
#[derive(Debug, Default)]
struct MirrorWorst {
    poses: usize,
    count_differs: usize,
    two_point: usize,
    force: f64,
    moment: f64,
    normal: f64,
    fallbacks: usize,
    jumps: usize,
}

/// Total force on the wheel, moment about the wheelset centre, and the normal forces sorted by
/// |lateral position|, of a search from scratch.
fn resultant(c: &mut WheelRailContact, pose: &WheelPose, fallbacks: &mut usize) -> Result<Resultant, ContactError> {
    c.reset(); // a pure function of the pose: no previous solution as a starting guess
    let pts = c.evaluate(pose)?;
    *fallbacks += pts.iter().filter(|p| p.geometry.method != ContactMethod::Newton).count();
    let f = pts.iter().map(|p| p.force_on_wheel()).sum();
    let m = pts.iter().map(|p| p.moment_on_wheel(&pose.position)).sum();
    let mut n: Vec<(f64, f64)> = pts.iter().map(|p| (p.point().y.abs(), p.normal_force)).collect();
    n.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(Resultant { force: f, moment: m, normal: n.into_iter().map(|x| x.1).collect(), ys: point_ys(&pts) })
}

struct Resultant {
    force: Vector3<f64>,
    moment: Vector3<f64>,
    normal: Vec<f64>,
    ys: Vec<f64>,
}

/// The left wheel at shift y, yaw ψ, roll φ (carrying 60 kN, 20 m/s, lateral velocity
/// 0.05 m/s, spin 0.1 % above rolling) against the right wheel at the mirrored pose
/// ([`WheelPose::mirrored`]), 201 shifts from −10 to +10 mm for each (ψ, φ) of `poses`.
fn mirror_sweep(poses: &[(f64, f64)], shifts: usize) -> Result<MirrorWorst, ValidationError> {
    let (mut left, mut right) = (s1002_on_uic60(Side::Left)?, s1002_on_uic60(Side::Right)?);
    let mut w = MirrorWorst::default();
    for &(yaw, roll) in poses {
        let mut sweep = Vec::with_capacity(shifts);
        for k in 0..shifts {
            let y = -0.010 + 0.020 * k as f64 / (shifts - 1) as f64;
            let state = WheelState {
                lateral_shift: y,
                yaw,
                roll,
                speed: 20.0,
                lateral_velocity: 0.05,
                axle_rate: Some(20.0 / R0 * 1.001),
                ..WheelState::default()
            };
            let pose = pose_for_load(&mut left, &state, 6e4)?;
            let l = resultant(&mut left, &pose, &mut w.fallbacks)?;
            let r = resultant(&mut right, &pose.mirrored(), &mut w.fallbacks)?;
            w.poses += 1;
            sweep.push((y, l.ys));
            if l.normal.len() != r.normal.len() {
                w.count_differs += 1;
                continue;
            }
            w.two_point += usize::from(l.normal.len() == 2);
            let scale = l.force.norm().max(1.0);
            w.force = w.force.max((r.force - mirror_vector(&l.force)).norm() / scale);
            w.moment = w.moment.max((r.moment - mirror_pseudovector(&l.moment)).norm() / l.moment.norm().max(1.0));
            let en = l.normal.iter().zip(&r.normal).map(|(a, b)| (a - b).abs() / scale).fold(0.0, f64::max);
            w.normal = w.normal.max(en);
        }
        w.jumps += jumps(&sweep).len();
    }
    Ok(w)
}

pub(super) fn mirror_symmetry(quick: bool) -> Result<Vec<Record>, ValidationError> {
    let name = "contact-mirror-symmetry";
    let all = [(0.0, 0.0), (0.004, 0.0), (-0.003, 0.0015)];
    let poses: &[(f64, f64)] = if quick { &all[2..] } else { &all };
    let w = mirror_sweep(poses, 201)?;
    let what =
        format!("S1002/UIC60 1:40, 60 kN, 20 m/s with creep, {} (yaw, roll) x 201 shifts -10..+10 mm", poses.len());
    Ok(vec![
        Record::abs(
            name,
            format!("{what}: poses where the right wheel has another contact-point count than the mirrored left"),
            w.count_differs as f64,
            0.0,
            0.0,
        ),
        Record::at_most(
            name,
            format!("{what}: worst relative |F_right - M F_left| / |F_left| (total contact force)"),
            w.force,
            1e-9,
        ),
        Record::at_most(
            name,
            format!("{what}: worst relative |m_right + M m_left| / |m_left| (moment about the wheelset centre)"),
            w.moment,
            1e-9,
        ),
        Record::at_most(
            name,
            format!("{what}: worst |N_right - N_left| / |F_left| over the contact points (normal forces)"),
            w.normal,
            1e-9,
        ),
        Record::at_least(
            name,
            format!(
                "{what}: contact-point jumps of the left wheel crossed per (yaw, roll) (a point appears > 3 mm from \
                 every point of the previous shift: tread to flange root, flange root to flange); {} two-point poses, \
                 {} scan fall-backs",
                w.two_point, w.fallbacks
            ),
            w.jumps as f64 / poses.len() as f64,
            2.0,
        ),
    ])
}

// ---------------------------------------------------------------------------------------
// Sweep refinement across the jumps
// ---------------------------------------------------------------------------------------

/// Worst point distance (m), shifts with another point count, jump brackets (m).
type SweepError = (f64, usize, Vec<(f64, f64)>);

/// One sweep of the wheelset from 0 to 10 mm towards `side`'s flange in steps of `step` m,
/// the search warm-started from step to step, the height for 60 kN from a separate contact
/// (the same at every step size). Returns the largest distance (m) between the warm-started
/// and a fresh search's points at the shared shifts 0, 0.5, …, 10 mm, the number of those
/// shifts whose point count differs, and the jumps along the sweep (shift brackets, m).
fn sweep_error(side: Side, step: f64) -> Result<SweepError, ValidationError> {
    let sign = if side == Side::Left { 1.0 } else { -1.0 };
    let mut warm = s1002_on_uic60(side)?;
    let mut fresh = s1002_on_uic60(side)?;
    let n = (0.010 / step).round() as usize;
    let every = (0.0005 / step).round() as usize;
    let (mut worst, mut count_differs) = (0.0f64, 0);
    let mut sweep = Vec::with_capacity(n + 1);
    for k in 0..=n {
        let y = sign * step * k as f64;
        let state = WheelState { lateral_shift: y, speed: 20.0, ..WheelState::default() };
        let pose = pose_for_load(&mut fresh, &state, 6e4)?;
        let a = warm.evaluate(&pose)?;
        sweep.push((y, point_ys(&a)));
        if k % every == 0 {
            fresh.reset();
            let b = fresh.evaluate(&pose)?;
            if a.len() != b.len() {
                count_differs += 1;
                continue;
            }
            for (p, q) in a.iter().zip(&b) {
                worst = worst.max((p.point() - q.point()).norm());
            }
        }
    }
    Ok((worst, count_differs, jumps(&sweep)))
}

pub(super) fn sweep_refinement(quick: bool) -> Result<Vec<Record>, ValidationError> {
    let name = "contact-sweep-refinement";
    let steps: &[f64] = if quick { &[5e-4, 2.5e-4] } else { &[5e-4, 2.5e-4, 1e-4, 5e-5] };
    let sides: &[(Side, &str)] =
        if quick { &[(Side::Left, "left")] } else { &[(Side::Left, "left"), (Side::Right, "right")] };
    let mut out = Vec::new();
    for &(side, label) in sides {
        let mut brackets: Vec<Vec<(f64, f64)>> = Vec::new();
        for &step in steps {
            let (worst, differs, j) = sweep_error(side, step)?;
            let what = format!(
                "{label} wheel (S1002/UIC60 1:40, 60 kN) swept 0-10 mm towards its flange in {:.3} mm steps, search \
                 warm-started from step to step",
                step * 1e3
            );
            out.push(Record::abs(
                name,
                format!(
                    "{what}: of the 21 shifts 0, 0.5, .., 10 mm, those with another point count than a fresh search"
                ),
                differs as f64,
                0.0,
                0.0,
            ));
            out.push(Record::at_most(
                name,
                format!("{what}: worst distance (m) of the warm-started contact points from a fresh search's"),
                worst,
                1e-9,
            ));
            out.push(Record::at_least(
                name,
                format!(
                    "{what}: contact-point jumps crossed (brackets, mm: {})",
                    j.iter().map(|(a, b)| format!("[{:.3}, {:.3}]", a * 1e3, b * 1e3)).collect::<Vec<_>>().join(" ")
                ),
                j.len() as f64,
                2.0,
            ));
            brackets.push(j);
        }
        // Refining the step, each jump's bracket must lie inside the coarser step's bracket.
        for (i, pair) in brackets.windows(2).enumerate() {
            let (coarse, fine) = (&pair[0], &pair[1]);
            let nested = coarse.len() == fine.len()
                && coarse.iter().zip(fine).all(|(c, f)| f.0 >= c.0 - 1e-12 && f.1 <= c.1 + 1e-12);
            out.push(Record::abs(
                name,
                format!(
                    "{label} wheel: the jumps located at step {:.3} mm lie inside those at step {:.3} mm (1 = nested, \
                     same number)",
                    steps[i + 1] * 1e3,
                    steps[i] * 1e3
                ),
                f64::from(u8::from(nested)),
                1.0,
                0.0,
            ));
        }
    }
    Ok(out)
}

// ---------------------------------------------------------------------------------------
// Friction over the rail profile
// ---------------------------------------------------------------------------------------

const MU_TOP: f64 = 0.4;
const MU_GAUGE: f64 = 0.1;

/// The right wheel (50 kN, 20 m/s) pressed against its rail's gauge face with a
/// lubricated-gauge-face map (μ = 0.1 on the gauge side to 2 mm below the top, 0.4 on the
/// top, 2 mm transition), at the lateral velocity `v_lat`.
fn friction_pose(
    c: &mut WheelRailContact,
    shift: f64,
    v_lat: f64,
) -> Result<Option<(WheelPose, Vec<ContactPoint>)>, ContactError> {
    let state = WheelState { lateral_shift: shift, speed: 20.0, lateral_velocity: v_lat, ..WheelState::default() };
    match solve_vertical(c, &state, VerticalTarget::Load(5e4)) {
        Ok(l) => Ok(Some((l.pose, l.points))),
        Err(ContactError::TargetNotMet { .. }) => Ok(None),
        Err(e) => Err(e),
    }
}

fn tangential_ratio(p: &ContactPoint) -> f64 {
    p.creep.longitudinal.hypot(p.creep.lateral) / p.normal_force
}

pub(super) fn variable_friction(quick: bool) -> Result<Vec<Record>, ValidationError> {
    let name = "contact-variable-friction";
    let mut c = s1002_on_uic60(Side::Right)?;
    let map = FrictionMap::lubricated_gauge_face(&c.rail.profile, MU_TOP, MU_GAUGE, 0.002, 0.002)?;
    let v_edge = map.profile[0].0;
    c.friction_map = Some(Arc::new(map));
    // Two-point contacts (tread and flange root, both > 500 N) between 5.5 and 8.5 mm towards
    // the right rail at a lateral velocity of 1 m/s (η ≈ 0.05: full sliding).
    let shifts = if quick { 31 } else { 61 };
    let mut found = Vec::new();
    for i in 0..shifts {
        let y = -0.0055 - 0.003 * i as f64 / (shifts - 1) as f64;
        if let Some((pose, pts)) = friction_pose(&mut c, y, 1.0)?
            && pts.len() == 2
            && pts.iter().all(|p| p.normal_force > 500.0)
        {
            found.push((y, pose, pts));
            if quick {
                break;
            }
        }
    }
    let mut out = vec![Record::at_least(
        name,
        "two-point contacts (tread and flange root, both N > 500 N) found between 5.5 and 8.5 mm towards the right rail \
         (right S1002 wheel on UIC60 1:40, 50 kN)",
        found.len() as f64,
        1.0,
    )];
    let (mut worst_sat, mut zones_wrong, mut worst_flange, mut worst_tread) = (0.0f64, 0usize, 0.0f64, 0.0f64);
    for (_, _, pts) in &found {
        let mut mus: Vec<f64> = Vec::new();
        for p in pts {
            let mu = c.friction_at(&p.geometry.params);
            worst_sat = worst_sat.max((tangential_ratio(p) - mu).abs() / mu);
            if p.geometry.params[1] < v_edge {
                worst_flange = worst_flange.max((tangential_ratio(p) - MU_GAUGE).abs() / MU_GAUGE);
            } else if p.geometry.params[1] > v_edge + 0.002 {
                worst_tread = worst_tread.max((tangential_ratio(p) - MU_TOP).abs() / MU_TOP);
            }
            mus.push(mu);
        }
        mus.sort_by(f64::total_cmp);
        zones_wrong += usize::from(mus != [MU_GAUGE, MU_TOP]);
    }
    let what = format!(
        "{} two-point contact(s), lateral velocity 1 m/s at 20 m/s (full sliding), mu = {MU_GAUGE} on the gauge face \
         to 2 mm below the top, {MU_TOP} on the top",
        found.len()
    );
    out.push(Record::abs(
        name,
        format!("{what}: contacts whose two points do not lie one on the gauge face (mu {MU_GAUGE}), one on the top"),
        zones_wrong as f64,
        0.0,
        0.0,
    ));
    out.push(Record::at_most(
        name,
        format!("{what}: worst relative | |F_t|/N - mu(own location) | / mu over every point (saturation)"),
        worst_sat,
        1e-9,
    ));
    out.push(Record::at_most(
        name,
        format!("{what}: flange-root points: worst relative | |F_t|/N - {MU_GAUGE} | / {MU_GAUGE}"),
        worst_flange,
        1e-9,
    ));
    out.push(Record::at_most(
        name,
        format!("{what}: tread points: worst relative | |F_t|/N - {MU_TOP} | / {MU_TOP}"),
        worst_tread,
        1e-9,
    ));
    let Some((shift, pose, _)) = found.first() else { return Ok(out) };
    // The uniform map is the scalar friction, bit for bit.
    let mut uni = s1002_on_uic60(Side::Right)?;
    uni.friction_map = Some(Arc::new(FrictionMap::uniform(0.3)?));
    let a = uni.evaluate(pose)?;
    let mut scalar = s1002_on_uic60(Side::Right)?;
    scalar.friction = 0.3;
    let b = scalar.evaluate(pose)?;
    let diff = a
        .iter()
        .zip(&b)
        .map(|(p, q)| {
            (p.creep.longitudinal - q.creep.longitudinal).abs().max((p.creep.lateral - q.creep.lateral).abs())
        })
        .fold(if a.len() == b.len() { 0.0 } else { f64::INFINITY }, f64::max);
    out.push(Record::at_most(
        name,
        format!("shift {:.2} mm: a uniform map mu = 0.3 against the scalar friction 0.3: largest creep-force difference (N)", shift * 1e3),
        diff,
        0.0,
    ));
    if !quick {
        // Below saturation: at small lateral slip each point's force ratio stays below its own
        // μ and grows with the slip towards it.
        let mut below = 0usize;
        let mut not_growing = 0usize;
        let mut last: Option<Vec<f64>> = None;
        let slips = [0.01, 0.03, 0.1, 0.3, 1.0];
        for &v in &slips {
            let Some((_, pts)) = friction_pose(&mut c, *shift, v)? else { continue };
            let ratios: Vec<f64> = pts.iter().map(tangential_ratio).collect();
            below +=
                pts.iter().filter(|p| tangential_ratio(p) <= c.friction_at(&p.geometry.params) * (1.0 + 1e-9)).count();
            if let Some(prev) = &last
                && (prev.len() != ratios.len() || prev.iter().zip(&ratios).any(|(a, b)| *b < a - 1e-12))
            {
                not_growing += 1;
            }
            last = Some(ratios);
        }
        out.push(Record::abs(
            name,
            format!(
                "shift {:.2} mm, lateral velocity 0.01-1 m/s: points (of 2 x {}) whose |F_t|/N stays <= the mu of \
                 their own location",
                shift * 1e3,
                slips.len()
            ),
            below as f64,
            (2 * slips.len()) as f64,
            0.0,
        ));
        out.push(Record::abs(
            name,
            format!(
                "shift {:.2} mm: slip steps at which a point's |F_t|/N falls as the lateral velocity grows",
                shift * 1e3
            ),
            not_growing as f64,
            0.0,
            0.0,
        ));
    }
    Ok(out)
}

// ---------------------------------------------------------------------------------------
// Nadal flange climb, quasi-static
// ---------------------------------------------------------------------------------------

/// The flange angle of S1002, rad.
const S1002_FLANGE_ANGLE: f64 = 70.0 * std::f64::consts::PI / 180.0;

pub(super) fn nadal_climb(quick: bool) -> Result<Vec<Record>, ValidationError> {
    let name = "contact-nadal-climb";
    let (mus, shifts): (&[f64], usize) = if quick { (&[0.3], 21) } else { (&[0.3, 0.5], 81) };
    let mut out = Vec::new();
    for &mu in mus {
        let mut c = s1002_on_uic60(Side::Left)?;
        c.friction = mu;
        let (mut worst, mut flange_points, mut jumps) = (0.0f64, 0usize, 0usize);
        let mut peak = (f64::NEG_INFINITY, 0.0);
        for k in 0..shifts {
            let y = 0.007 + 0.004 * k as f64 / (shifts - 1) as f64;
            // saturated lateral creepage in the climbing direction, no longitudinal creep
            let state = WheelState {
                lateral_shift: y,
                speed: 5.0,
                creepages: Some(Creepages { longitudinal: 0.0, lateral: -0.05, spin: 0.0 }),
                ..WheelState::default()
            };
            let l = match solve_vertical(&mut c, &state, VerticalTarget::Load(5e4)) {
                Ok(l) => l,
                // between the flange root and the flange no height carries 50 kN
                Err(ContactError::TargetNotMet { .. }) => {
                    jumps += 1;
                    continue;
                }
                Err(e) => return Err(e.into()),
            };
            if l.points.len() != 1 {
                continue;
            }
            let delta = l.points[0].geometry.normal.z.clamp(-1.0, 1.0).acos();
            let lv = -l.points.iter().map(|p| p.force_on_wheel().y).sum::<f64>() / l.vertical_force;
            if delta > 45f64.to_radians() {
                flange_points += 1;
                worst = worst.max((lv - nadal_limit(delta, mu)).abs() / nadal_limit(delta, mu));
            }
            if lv > peak.0 {
                peak = (lv, delta);
            }
        }
        let what = format!(
            "left S1002 on UIC60 1:40, 50 kN, lateral creepage -0.05 (climbing, saturated), mu = {mu}, {shifts} shifts \
             7-11 mm"
        );
        out.push(Record::at_least(
            name,
            format!("{what}: single-point flange contacts (contact angle > 45 deg); {jumps} shifts in the jump"),
            flange_points as f64,
            (shifts / 2) as f64,
        ));
        out.push(Record::at_most(
            name,
            format!("{what}: worst relative |L/V - Nadal(delta, mu)| / Nadal at each point's own contact angle delta"),
            worst,
            1e-9,
        ));
        out.push(Record::abs(
            name,
            format!(
                "{what}: steepest contact angle (deg) where L/V peaks (the wheel starts to climb), S1002 flange 70 deg"
            ),
            peak.1.to_degrees(),
            S1002_FLANGE_ANGLE.to_degrees(),
            0.15,
        ));
        let reference = nadal_limit(S1002_FLANGE_ANGLE, mu);
        out.push(Record::abs(
            name,
            format!("{what}: largest L/V (climb) vs Nadal's limit at 70 deg, tolerance 0.2 % relative"),
            peak.0,
            reference,
            2e-3 * reference,
        ));
    }
    Ok(out)
}
