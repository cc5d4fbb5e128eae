//! Work–precision sweeps: run time against error (issue 7).
//!
//! Each sweep runs one case over a grid of discretization and solver settings (time step,
//! mesh, quadrature, Newton tolerance, linear solver) and measures, for every point, the
//! wall time and the errors against a converged reference run of the same case:
//!
//! | case | errors |
//! |---|---|
//! | `slosh-tank` | first-mode frequency vs the analytic 1.436 Hz and vs the reference run; lateral centre-of-mass history (max deviation / reference amplitude) |
//! | `ecp-braking` | peak coupler force; longitudinal oil centre-of-mass history of the front car (max deviation / reference amplitude) |
//! | `ecp-braking-spread` | the same, with the rear car's brake force 10 % lower (the configuration whose coupler force is first order, `docs/validation.md`) |
//!
//! The reference is the finest setting of the sweep, run with the same code. Points that
//! fail (Newton divergence, inverted element) are kept with their error message: a setting
//! that cannot run is part of the answer. `railslosh bench` writes the points as CSV/JSON
//! and plots error against wall time.

use std::time::Instant;

use ancf_core::FluidBody;
use ancf_core::constitutive::Rheology;
use ancf_core::contact::{WallContact, WallContactLaw};
use ancf_core::element::QuadratureOptions;
use ancf_core::error::{AncfError, Result};
use ancf_core::mesh::box_mesh;
use ancf_core::tank::{TankGeometry, TankShape};

use rail_mbs::defaults::{Oil, SETTLE};
use rail_mbs::defaults::{liquid, slosh_params};
use rail_mbs::integrator::{IterativeParams, LinearSolverKind};
use rail_mbs::slosh::analysis::dominant_frequency;
use rail_mbs::slosh::linear_theory::rect_tank_frequency;
use rail_mbs::slosh::{PiecewiseAcceleration, PrescribedMotion, SloshFrame, SloshRecord, SloshRun, SloshSystem};
use rail_mbs::vehicle::BrakeScope;

use crate::vehicle::studies::{BrakingCase, run_braking_with};

use ancf_core::constants::GRAVITY as G;

/// Names of the sweeps.
pub const CASES: [&str; 3] = ["slosh-tank", "ecp-braking", "ecp-braking-spread"];

/// Rear-car brake factor of the `ecp-braking-spread` sweep (the −10 % spread of the
/// `ecp-braking-oils` validation case).
pub const SPREAD_REAR_BRAKE_FACTOR: f64 = 0.9;

/// Braking time simulated by the full `ecp-braking-spread` sweep (s), after settling.
pub const SPREAD_BRAKING_S: f64 = 9.0;

/// One point of a sweep: its settings, cost and errors.
#[derive(Debug, Clone, PartialEq)]
pub struct WorkPoint {
    /// Sweep name.
    pub case: String,
    /// Whether this point is the reference run.
    pub reference: bool,
    /// Settings, e.g. `("h_max_s", 0.004)`, `("elements", 36.0)`.
    pub settings: Vec<(String, f64)>,
    /// Wall time of the run (s).
    pub wall_s: f64,
    /// Accepted steps, Newton iterations, Jacobian evaluations.
    pub steps: usize,
    /// Newton iterations.
    pub newton_iterations: usize,
    /// Jacobian evaluations.
    pub jacobians: usize,
    /// Errors against the reference, e.g. `("frequency_rel", 0.003)`.
    pub errors: Vec<(String, f64)>,
    /// Why the run failed, if it did.
    pub failure: Option<String>,
    /// The compared history (centre of mass, m), resampled on 201 points: (t, value).
    pub history: (Vec<f64>, Vec<f64>),
}

/// `x(t)` resampled on `n + 1` uniform points of [t0, t1] (linear interpolation).
fn resample(t: &[f64], x: &[f64], t0: f64, t1: f64, n: usize) -> (Vec<f64>, Vec<f64>) {
    if t.len() < 2 {
        return (Vec::new(), Vec::new());
    }
    let t1 = t1.min(t[t.len() - 1]);
    (0..=n)
        .map(|k| {
            let tq = t0 + (t1 - t0) * k as f64 / n as f64;
            (tq, interp(t, x, tq))
        })
        .unzip()
}

/// `x(tq)` by linear interpolation of the samples `(t, x)` (held at the ends); `t.len() >= 2`.
fn interp(t: &[f64], x: &[f64], tq: f64) -> f64 {
    let i = t.partition_point(|&v| v <= tq).clamp(1, t.len() - 1);
    let s = ((tq - t[i - 1]) / (t[i] - t[i - 1])).clamp(0.0, 1.0);
    x[i - 1] + s * (x[i] - x[i - 1])
}

/// Runs a sweep. `quick`: a small grid for CI (seconds); the full grids take minutes
/// (`slosh-tank`) to about an hour (`ecp-braking`).
pub fn run_case(name: &str, quick: bool) -> Result<Vec<WorkPoint>> {
    run_case_with(name, quick, &mut |_| {})
}

/// [`run_case`], calling `progress` with each point as soon as it is measured (the
/// reference first), so that a long sweep reports as it goes.
pub fn run_case_with(name: &str, quick: bool, progress: &mut dyn FnMut(&WorkPoint)) -> Result<Vec<WorkPoint>> {
    match name {
        "slosh-tank" => {
            let points = slosh_tank(quick)?;
            points.iter().for_each(&mut *progress);
            Ok(points)
        }
        "ecp-braking" => ecp_braking(quick, 1.0, name, progress),
        "ecp-braking-spread" => ecp_braking(quick, SPREAD_REAR_BRAKE_FACTOR, name, progress),
        _ => Err(AncfError::InvalidParameter {
            field: "case".into(),
            value: name.into(),
            allowed: format!("one of {CASES:?}"),
        }),
    }
}

/// Settings of one slosh-tank point.
#[derive(Debug, Clone, Copy)]
struct SloshSetting {
    counts: [usize; 3],
    h: f64,
    penalty_points: usize,
    iterative: bool,
}

struct SloshOutcome {
    record: SloshRecord,
    wall: f64,
    stats: rail_mbs::integrator::Stats,
    failure: Option<String>,
}

fn run_slosh_setting(s: SloshSetting, t_end: f64) -> Result<SloshOutcome> {
    let (lx, ly, d) = (0.416, 0.324, 0.132);
    let mesh = box_mesh([-lx / 2.0, -ly / 2.0, 0.0], [lx, ly, d], s.counts)?;
    let fluid = liquid(998.0, Rheology::Newtonian { viscosity: 1e-3 }, d, d / s.counts[2] as f64)?;
    let geo =
        TankGeometry::new(TankShape::Box { min: [-lx / 2.0, -ly / 2.0, 0.0], max: [lx / 2.0, ly / 2.0, 0.3] }, vec![])?;
    let quad = QuadratureOptions { penalty: s.penalty_points, ..Default::default() };
    let body = FluidBody::new(mesh, fluid, quad)?;
    let contact = WallContact::new(&body, geo, WallContactLaw::default_for(998.0, G, d))?;
    let mut motion = PrescribedMotion::at_rest([0.0; 3]);
    motion.translation[1] = PiecewiseAcceleration::pulse(0.3 * G, 0.0, 0.5, 0.01)?;
    let mut sys = SloshSystem::new(body, contact, motion, [0.0, 0.0, -G], SloshFrame::Inertial)?;
    if s.iterative {
        sys.linear_solver = LinearSolverKind::Iterative(IterativeParams::default());
    }
    let tic = Instant::now();
    let fail = |e: String| AncfError::NonFinite { what: e, element: 0 };
    let mut run = SloshRun::new(sys, 0.0, slosh_params()).map_err(|e| fail(e.to_string()))?;
    let failure = run.run_to(t_end, s.h).err().map(|e| e.to_string());
    Ok(SloshOutcome { wall: tic.elapsed().as_secs_f64(), stats: *run.stats(), record: run.record, failure })
}

/// Max |x − x_ref| over a uniform grid on [t0, t1], over the reference's range.
fn history_error(t: &[f64], x: &[f64], t_ref: &[f64], x_ref: &[f64], t0: f64, t1: f64) -> f64 {
    if t.len() < 2 || t_ref.len() < 2 {
        return f64::NAN;
    }
    let t1 = t1.min(*t.last().unwrap_or(&t0)).min(*t_ref.last().unwrap_or(&t0));
    let n = 400;
    let (mut dev, mut lo, mut hi) = (0.0f64, f64::INFINITY, f64::NEG_INFINITY);
    for k in 0..=n {
        let tq = t0 + (t1 - t0) * k as f64 / n as f64;
        let r = interp(t_ref, x_ref, tq);
        dev = dev.max((interp(t, x, tq) - r).abs());
        lo = lo.min(r);
        hi = hi.max(r);
    }
    dev / (hi - lo).max(1e-300)
}

fn slosh_tank(quick: bool) -> Result<Vec<WorkPoint>> {
    let t_end = if quick { 2.0 } else { 5.0 };
    let (reference, grid): (SloshSetting, Vec<SloshSetting>) = if quick {
        // reference at 1 ms: the adaptive step of this run stays below 2 ms (Newton failures
        // set it), so a 2 ms cap and the 8 ms one took the same steps once the controller
        // grew its step after 20 easy steps (docs/benchmarks.md, "Growing the step less often")
        let r = SloshSetting { counts: [3, 6, 2], h: 0.001, penalty_points: 3, iterative: false };
        let g = vec![
            SloshSetting { counts: [3, 6, 2], h: 0.008, penalty_points: 3, iterative: false },
            SloshSetting { counts: [2, 4, 2], h: 0.004, penalty_points: 3, iterative: false },
        ];
        (r, g)
    } else {
        let r = SloshSetting { counts: [6, 12, 4], h: 0.001, penalty_points: 3, iterative: false };
        let mut g = Vec::new();
        for counts in [[2, 4, 2], [3, 6, 2], [4, 8, 3]] {
            for h in [0.008, 0.004, 0.002] {
                for penalty_points in [2, 3] {
                    g.push(SloshSetting { counts, h, penalty_points, iterative: false });
                }
            }
        }
        g.push(SloshSetting { counts: [3, 6, 2], h: 0.004, penalty_points: 3, iterative: true });
        (r, g)
    };
    let fa = rect_tank_frequency(0.324, 0.132);
    let ref_out = run_slosh_setting(reference, t_end)?;
    let series = |r: &SloshRecord| -> (Vec<f64>, Vec<f64>) {
        (r.force_tank.iter().map(|f| f[1]).collect(), r.com_tank.iter().map(|c| c[1]).collect())
    };
    let (fy_ref, cy_ref) = series(&ref_out.record);
    let f_ref = dominant_frequency(&ref_out.record.t, &fy_ref, 0.6, 0.3, 4.0);
    let point = |s: SloshSetting, out: &SloshOutcome, is_ref: bool| -> WorkPoint {
        let (fy, cy) = series(&out.record);
        let f = dominant_frequency(&out.record.t, &fy, 0.6, 0.3, 4.0);
        let com = history_error(&out.record.t, &cy, &ref_out.record.t, &cy_ref, 0.0, t_end);
        let ok = out.failure.is_none();
        let or_nan = |v: f64| if ok { v } else { f64::NAN };
        WorkPoint {
            case: "slosh-tank".into(),
            reference: is_ref,
            settings: vec![
                ("h_max_s".into(), s.h),
                ("elements".into(), (s.counts[0] * s.counts[1] * s.counts[2]) as f64),
                ("penalty_points".into(), s.penalty_points as f64),
                ("iterative".into(), if s.iterative { 1.0 } else { 0.0 }),
                ("t_end_s".into(), t_end),
            ],
            wall_s: out.wall,
            steps: out.stats.steps,
            newton_iterations: out.stats.newton_iterations,
            jacobians: out.stats.jacobian_evaluations,
            errors: vec![
                ("frequency_vs_analytic_rel".into(), or_nan((f - fa).abs() / fa)),
                ("frequency_vs_reference_rel".into(), or_nan((f - f_ref).abs() / f_ref)),
                ("com_history_rel".into(), or_nan(com)),
            ],
            failure: out.failure.clone(),
            history: resample(&out.record.t, &cy, 0.0, t_end, 200),
        }
    };
    let mut points = vec![point(reference, &ref_out, true)];
    for s in grid {
        let out = run_slosh_setting(s, t_end)?;
        points.push(point(s, &out, false));
    }
    Ok(points)
}

/// Settings of one ECP braking point.
#[derive(Debug, Clone, Copy)]
struct EcpSetting {
    counts: [usize; 3],
    step: f64,
    rel_tol: f64,
}

fn ecp_braking(
    quick: bool,
    rear_brake_factor: f64,
    name: &str,
    progress: &mut dyn FnMut(&WorkPoint),
) -> Result<Vec<WorkPoint>> {
    // quick: 2 s after settling on 12-element tanks; full: the paper's 10 s on 48 elements
    let (t_end, reference, grid) = if quick {
        let r = EcpSetting { counts: [3, 2, 2], step: 1e-3, rel_tol: 1e-6 };
        let g = vec![
            EcpSetting { counts: [3, 2, 2], step: 4e-3, rel_tol: 1e-4 },
            EcpSetting { counts: [3, 2, 2], step: 2e-3, rel_tol: 1e-4 },
        ];
        (SETTLE + 2.0, r, g)
    } else {
        let r = EcpSetting { counts: [6, 4, 2], step: 1e-3, rel_tol: 1e-6 };
        let mut g = Vec::new();
        for step in [8e-3, 4e-3, 2e-3] {
            for rel_tol in [1e-3, 1e-4] {
                g.push(EcpSetting { counts: [6, 4, 2], step, rel_tol });
            }
        }
        g.push(EcpSetting { counts: [4, 3, 2], step: 4e-3, rel_tol: 1e-4 });
        // The spread case stops at 9 s of braking: its 1 ms, 1e-6 reference diverged at
        // t = 9.82 s (a free-surface element of the rear tank near inversion, where the
        // viscous stress ~ 1/J makes Newton fail at any step), and a sweep needs a reference.
        let braking = if rear_brake_factor == 1.0 { 10.0 } else { SPREAD_BRAKING_S };
        (SETTLE + braking, r, g)
    };
    let run = |s: EcpSetting| {
        let case = BrakingCase {
            oil: Oil::Light,
            cars: 2,
            scope: BrakeScope::AllCars,
            bulkheads: false,
            counts: s.counts,
            t_end,
            rear_brake_factor,
            wall_damping_ratio: ancf_core::contact::WALL_DAMPING_RATIO,
            wall_adhesion: 0.0,
            linear_solver: rail_mbs::integrator::LinearSolverKind::Condensed,
            shear_stabilization: false,
        };
        let tic = Instant::now();
        let out = run_braking_with(&case, s.step, s.rel_tol);
        (out, tic.elapsed().as_secs_f64())
    };
    let peak = |r: &rail_mbs::vehicle::FluidTrainRecord| -> f64 {
        r.train.coupler_force.iter().map(|c| c.first().map_or(0.0, |f| f.abs())).fold(0.0, f64::max)
    };
    let com_x =
        |r: &rail_mbs::vehicle::FluidTrainRecord| -> Vec<f64> { r.oil_com_tank.iter().map(|c| c[0][0]).collect() };
    let (ref_out, ref_wall) = run(reference);
    let ref_rec = ref_out?;
    let (p_ref, c_ref) = (peak(&ref_rec), com_x(&ref_rec));
    let mut points = Vec::new();
    for (k, s) in std::iter::once(reference).chain(grid).enumerate() {
        let (out, wall) = if k == 0 { (Ok(ref_rec.clone()), ref_wall) } else { run(s) };
        let (errors, failure, steps, newton, jac) = match &out {
            Ok(r) => (
                vec![
                    ("peak_coupler_rel".into(), (peak(r) - p_ref).abs() / p_ref.max(1e-300)),
                    ("peak_coupler_n".into(), peak(r)),
                    (
                        "oil_com_history_rel".into(),
                        history_error(&r.train.t, &com_x(r), &ref_rec.train.t, &c_ref, SETTLE, t_end),
                    ),
                ],
                None,
                r.train.steps,
                r.train.newton_iterations,
                r.train.jacobian_evaluations,
            ),
            Err(e) => (
                vec![
                    ("peak_coupler_rel".into(), f64::NAN),
                    ("peak_coupler_n".into(), f64::NAN),
                    ("oil_com_history_rel".into(), f64::NAN),
                ],
                Some(e.to_string()),
                0,
                0,
                0,
            ),
        };
        points.push(WorkPoint {
            case: name.into(),
            reference: k == 0,
            settings: vec![
                ("h_max_s".into(), s.step),
                ("rel_tol".into(), s.rel_tol),
                ("elements_per_tank".into(), (s.counts[0] * s.counts[1] * s.counts[2]) as f64),
                ("t_end_s".into(), t_end),
                ("rear_brake_factor".into(), rear_brake_factor),
            ],
            wall_s: wall,
            steps,
            newton_iterations: newton,
            jacobians: jac,
            history: match &out {
                Ok(r) => resample(&r.train.t, &com_x(r), 0.0, t_end, 200),
                Err(_) => (Vec::new(), Vec::new()),
            },
            errors,
            failure,
        });
        progress(points.last().expect("just pushed"));
    }
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn history_error_of_shifted_signal() {
        let t: Vec<f64> = (0..=100).map(|i| i as f64 * 0.01).collect();
        let x: Vec<f64> = t.iter().map(|&s| (6.0 * s).sin()).collect();
        let y: Vec<f64> = x.iter().map(|v| v + 0.02).collect();
        let e = history_error(&t, &y, &t, &x, 0.0, 1.0);
        // sin(6 t) on [0, 1] reaches +1 (t = pi/12) and -1 (t = pi/4): range 2
        assert!((e - 0.02 / 2.0).abs() < 1e-4, "{e}");
        assert_eq!(history_error(&t, &x, &t, &x, 0.0, 1.0), 0.0);
        assert!(run_case("nope", true).is_err());
    }
}
