//! The studies of the crude-oil paper (seed 000 §8.2–8.5) on the coupled car–oil model,
//! and their validation cases:
//!
//! | case | what |
//! |---|---|
//! | `ecp-braking-oils` | two cars, ECP braking 40 → 5 km/h: peak coupler force with heavy crude 15–45 % below light crude; coupler oscillation dies out sooner as viscosity rises |
//! | `conventional-braking` | front car only braking: coupler compressive, mean magnitude several times the ECP case; the oils differ little |
//! | `bulkhead-reduction` | light crude, ECP: two bulkheads (three compartments) cut the peak coupler force by 50–85 %, and the front/rear normal-force difference shrinks |
//! | `curve-outward-inertia` | one car on the Table 1 curve at 60 and 100 km/h: the oil's outward inertia force grows with density and exceeds the in-plane gravity component at 100 km/h only |
//! | `mesh-convergence` | one car braking with light crude, 32 / 48 / 64 elements: the oil centre-of-mass trajectories agree |
//!
//! # Choices (where the paper is silent)
//!
//! * **Brake torque.** "Nonlinear, designed to reduce the train velocity from 40 to 5 km/h in
//!   10 s": `T(t) = T₀ (1 − e^{−(t−t_s)/τ})` after a settling time `t_s` (the liquid settles
//!   under gravity from its flat reference shape), τ = 0.5 s, with `T₀` such that a rigid
//!   car of the same mass (wheelset spin inertia included) loses 35 km/h in 10 s.
//! * **ECP with identical cars.** Two identical cars braked identically still load their
//!   coupler: the coupler faces sit 1.5 m below the tank axes and 7 m from the car centres,
//!   and the cars pitch under braking and with the surging oil. A pitch θ of both cars
//!   (nose down) moves the faces apart vertically by about 14 θ, and a pinned coupler of
//!   length L and stiffness 300 MN/m turns that into a force k (14 θ)²/(2L) — a few kN at
//!   1 mrad. The peak coupler force therefore follows the oil's pitch dynamics, which is why
//!   it depends on the oil. `ecp-braking-oils` reports this paper-faithful configuration and
//!   a second one with a 10 % weaker rear-car brake (`rear_brake_factor` = 0.9: brake-force
//!   scatter between cars, an assumption), in which the coupler carries the brake difference
//!   and the slosh modulates it.
//! * Oils of seed 000 Table 2 with the Oldroyd model (the paper's choice), penalties
//!   `k_IC = 1000 ρ g H`, `c_TD = 0.2 √(k_IC ρ) h_el`; half-full tanks.

use std::sync::Arc;

use ancf_core::element::QuadratureOptions;
use ancf_core::error::{AncfError, Result, invalid};
use rail_mbs::mbs::SpeedProfile;
use rail_mbs::track::presets::{TABLE1_BODY_END, table1};
use rail_mbs::track::{GRAVITY, Track};
use rail_mbs::vehicle::equivalent::cylinder_lambda;
use rail_mbs::vehicle::fluid::{FluidCargo, FluidTrainRecord, run_fluid_train};
use rail_mbs::vehicle::{BrakeScope, TankCarParams, TrainScenario};

use crate::{Record, SCENE_WALL_ADHESION, SCENE_WALL_DAMPING};

pub use rail_mbs::defaults::{BRAKING_STEP, ECP_STEP, ECP_STEP_VISCOUS, Oil, SETTLE, brake_torque, braking_step};

/// A braking run of the studies.
#[derive(Debug, Clone)]
pub struct BrakingCase {
    /// Liquid.
    pub oil: Oil,
    /// Cars (1 or 2).
    pub cars: usize,
    /// ECP (all cars) or conventional (front car only).
    pub scope: BrakeScope,
    /// Two bulkheads dividing the tank into three equal compartments.
    pub bulkheads: bool,
    /// Fluid elements (length, width, height).
    pub counts: [usize; 3],
    /// Simulated time, s (the paper: 10 s of braking).
    pub t_end: f64,
    /// Rear-car brake factor (1 = identical brakes, the paper's ECP).
    pub rear_brake_factor: f64,
    /// Damping ratio of the liquid column on the tank walls ([`FluidCargo::wall_damping_ratio`];
    /// the library default [`ancf_core::contact::WALL_DAMPING_RATIO`], or 1 as the shipped ECP
    /// scenes use).
    pub wall_damping_ratio: f64,
    /// Suction the tank walls hold on the wetted liquid, × ρ g H ([`FluidCargo::wall_adhesion`];
    /// 0, or 4 as the shipped ECP scenes use).
    pub wall_adhesion: f64,
    /// How the coupled Newton matrix is solved ([`FluidCargo::linear_solver`]).
    pub linear_solver: rail_mbs::integrator::LinearSolverKind,
    /// The recommended shear stabilization ([`FluidCargo::shear_stabilization`]; false, or true as
    /// the shipped car scenes use).
    pub shear_stabilization: bool,
}

fn tangent() -> Result<Arc<Track>> {
    Track::straight(4000.0).map(Arc::new).map_err(|e| invalid("track", e, "valid"))
}

fn cargo(oil: Oil, counts: [usize; 3], bulkheads: bool, p: &TankCarParams) -> Result<FluidCargo> {
    let depth = p.tank_radius;
    let fluid = oil.fluid(depth, depth / counts[2] as f64)?;
    let third = (p.tank_length - 1.0) / 6.0;
    let bulkheads = if bulkheads { vec![(-third, 0.02), (third, 0.02)] } else { vec![] };
    Ok(FluidCargo::new(fluid, counts, 0.5, bulkheads))
}

fn finish(
    out: std::result::Result<FluidTrainRecord, Box<rail_mbs::vehicle::fluid::FluidTrainFailure>>,
) -> Result<FluidTrainRecord> {
    out.map_err(|f| {
        AncfError::Solver(format!("{} (at t = {:.3} s)", f.error, f.record.train.t.last().copied().unwrap_or(0.0)))
    })
}

/// Runs a braking case (largest step [`braking_step`]).
pub fn run_braking(case: &BrakingCase) -> Result<FluidTrainRecord> {
    run_braking_with(case, braking_step(case.scope, case.oil), TrainScenario::default_hht().rel_tol)
}

/// [`run_braking`] with a given largest time step `step` (s) and Newton relative
/// tolerance `rel_tol` (the work–precision sweeps vary them).
pub fn run_braking_with(case: &BrakingCase, step: f64, rel_tol: f64) -> Result<FluidTrainRecord> {
    run_braking_adjusted(case, step, rel_tol, |_| {})
}

/// [`run_braking_with`] with the cargo changed by `adjust` before the run (studies of a
/// setting `BrakingCase` does not carry, such as the shear stabilization's size).
pub fn run_braking_adjusted(
    case: &BrakingCase,
    step: f64,
    rel_tol: f64,
    adjust: impl FnOnce(&mut FluidCargo),
) -> Result<FluidTrainRecord> {
    let p = TankCarParams::standard()?;
    let mut cg = cargo(case.oil, case.counts, case.bulkheads, &p)?;
    cg.wall_damping_ratio = case.wall_damping_ratio;
    cg.wall_adhesion = case.wall_adhesion;
    cg.linear_solver = case.linear_solver;
    cg.shear_stabilization = case.shear_stabilization;
    adjust(&mut cg);
    let v0 = 40.0 / 3.6;
    let mut sc = TrainScenario::single(p.clone(), tangent()?, 300.0, v0, case.t_end);
    sc.cars = case.cars;
    sc.step = step;
    sc.record_every = 0.02;
    sc.hht = TrainScenario::fluid_hht();
    sc.hht.rel_tol = rel_tol;
    // Torque sized with the fluid mass of the mesh (total mass of one car).
    let fluid_mass = {
        let body = ancf_core::FluidBody::new(
            ancf_core::mesh::cylinder_tank(&p.tank_spec(0.5, [2, 2, 2]))?,
            cg.fluid,
            QuadratureOptions::default(),
        )?;
        body.total_mass()
    };
    let torque = brake_torque(&p, p.total_mass() + fluid_mass, v0, 5.0 / 3.6, 10.0)?;
    sc.brake = Some((torque, case.scope));
    sc.brake_factors = vec![1.0, case.rear_brake_factor];
    finish(run_fluid_train(&sc, &cg)?)
}

/// Names of the study cases.
pub const CASES: [&str; 6] = [
    "ecp-braking-oils",
    "conventional-braking",
    "bulkhead-reduction",
    "curve-outward-inertia",
    "mesh-convergence",
    "coupler-force-convergence",
];

/// Runs one study case (`quick`: coarse meshes and short runs for CI; the full forms take
/// tens of minutes).
pub fn run_case(name: &str, quick: bool) -> Result<Vec<Record>> {
    match name {
        "ecp-braking-oils" => ecp_braking_oils(quick),
        "conventional-braking" => conventional_braking(quick),
        "bulkhead-reduction" => bulkhead_reduction(quick),
        "curve-outward-inertia" => curve_outward_inertia(quick),
        "mesh-convergence" => mesh_convergence(quick),
        "coupler-force-convergence" => coupler_force_convergence(quick),
        other => Err(invalid("case", other, &format!("one of {CASES:?}"))),
    }
}

/// Mesh and duration of the braking studies.
fn braking_setup(quick: bool) -> ([usize; 3], f64) {
    if quick { ([2, 2, 2], 3.0) } else { ([6, 4, 2], SETTLE + 10.0) }
}

/// A study run to execute on its own thread.
type Job<'a, T> = Box<dyn FnOnce() -> Result<T> + Send + 'a>;

fn parallel<T: Send>(jobs: Vec<Job<'_, T>>) -> Result<Vec<T>> {
    std::thread::scope(|s| {
        let handles: Vec<_> = jobs.into_iter().map(|j| s.spawn(j)).collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|_| Err(AncfError::Solver("panic in a study run".into()))))
            .collect()
    })
}

fn coupler(rec: &FluidTrainRecord) -> Vec<(f64, f64)> {
    rec.train.t.iter().zip(&rec.train.coupler_force).map(|(t, c)| (*t, c.first().copied().unwrap_or(0.0))).collect()
}

fn peak_abs(x: &[(f64, f64)]) -> f64 {
    x.iter().map(|p| p.1.abs()).fold(0.0, f64::max)
}

fn mean_over(x: &[(f64, f64)], t0: f64, t1: f64) -> f64 {
    let v: Vec<f64> = x.iter().filter(|p| p.0 >= t0 && p.0 <= t1).map(|p| p.1).collect();
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// RMS deviation of `x` from its 1-s moving mean over `[t0, t1]`: the oscillation left.
fn oscillation(x: &[(f64, f64)], t0: f64, t1: f64) -> f64 {
    let pts: Vec<&(f64, f64)> = x.iter().filter(|p| p.0 >= t0 && p.0 <= t1).collect();
    let mut acc = 0.0;
    for p in &pts {
        let m = mean_over(x, p.0 - 0.5, p.0 + 0.5);
        acc += (p.1 - m) * (p.1 - m);
    }
    (acc / pts.len().max(1) as f64).sqrt()
}

fn braking(oil: Oil, cars: usize, scope: BrakeScope, bulkheads: bool, quick: bool, rear: f64) -> BrakingCase {
    let (counts, t_end) = braking_setup(quick);
    BrakingCase {
        oil,
        cars,
        scope,
        bulkheads,
        counts,
        t_end,
        rear_brake_factor: rear,
        wall_damping_ratio: ancf_core::contact::WALL_DAMPING_RATIO,
        wall_adhesion: 0.0,
        linear_solver: rail_mbs::integrator::LinearSolverKind::Condensed,
        shear_stabilization: false,
    }
}

fn ecp_braking_oils(quick: bool) -> Result<Vec<Record>> {
    let c = "ecp-braking-oils";
    // Identical brakes on both cars (the paper's ECP), and a 10 % weaker rear-car brake.
    let jobs: Vec<Job<'static, FluidTrainRecord>> = vec![
        Box::new(move || run_braking(&braking(Oil::Light, 2, BrakeScope::AllCars, false, quick, 1.0))),
        Box::new(move || run_braking(&braking(Oil::Heavy, 2, BrakeScope::AllCars, false, quick, 1.0))),
        Box::new(move || run_braking(&braking(Oil::Light, 2, BrakeScope::AllCars, false, quick, 0.9))),
        Box::new(move || run_braking(&braking(Oil::Heavy, 2, BrakeScope::AllCars, false, quick, 0.9))),
        // Conventional braking, for the paper's second ECP figure: the mean coupler force
        // under conventional braking is "nearly ten times" that under ECP braking (§8.3).
        Box::new(move || run_braking(&braking(Oil::Light, 2, BrakeScope::FrontCar, false, quick, 1.0))),
    ];
    let r = parallel(jobs)?;
    let mut out = Vec::new();
    let t0 = SETTLE + 1.0;
    let conventional = coupler(&r[4]);
    let mc = mean_over(&conventional, t0, r[4].train.t.last().copied().unwrap_or(0.0)).abs();
    for (k, label) in [(0, "identical brakes"), (2, "rear brake -10 %")] {
        let (light, heavy) = (coupler(&r[k]), coupler(&r[k + 1]));
        let (pl, ph) = (peak_abs(&light), peak_abs(&heavy));
        let t_end = r[k].train.t.last().copied().unwrap_or(0.0);
        let (ol, oh) = (oscillation(&light, 0.5 * t_end, t_end), oscillation(&heavy, 0.5 * t_end, t_end));
        if quick && k == 0 {
            // Coarse CI mesh: only the ordering is checked.
            out.push(Record::less_than(
                c,
                format!("{label}: peak coupler force heavy/light ({ph:.0} N vs {pl:.0} N), quick mesh"),
                ph / pl,
                1.0,
            ));
        } else if !quick {
            out.push(Record::abs(
                c,
                format!("{label}: peak coupler force, 1 - heavy/light ({ph:.0} N vs {pl:.0} N); paper ~30 %"),
                1.0 - ph / pl,
                0.30,
                0.15,
            ));
        }
        // No quick-mesh peak check with the brake spread: there the light crude's peak is a
        // single spike on top of the brake-difference force (which is larger for the denser
        // heavy crude), and on the coarse mesh it moved by 13 % (4385 -> 3829 N) when only
        // the Newton predictor changed, within the Newton tolerance, turning heavy/light from
        // 0.90 into 1.03. The oscillation check below is the robust quick-mesh ordering.
        out.push(Record::less_than(
            c,
            format!(
                "{label}: coupler oscillation (RMS about the 1-s mean, 2nd half), heavy/light ({oh:.0} N vs {ol:.0} N)"
            ),
            oh / ol.max(1e-300),
            1.0,
        ));
        // Mean |coupler| over the braking, light crude, against conventional braking: the
        // paper's "nearly ten times" (0.1). Quick form: ECP several times smaller.
        let me = mean_over(&light, t0, t_end).abs();
        let label = format!("{label}: mean |coupler| ECP / conventional, light crude ({me:.0} N vs {mc:.0} N)");
        out.push(if quick {
            Record::less_than(c, format!("{label}; quick mesh"), me / mc.max(1e-300), 1.0 / 3.0)
        } else {
            Record::abs(c, format!("{label}; paper ~1/10"), me / mc.max(1e-300), 0.10, 0.05)
        });
    }
    Ok(out)
}

fn conventional_braking(quick: bool) -> Result<Vec<Record>> {
    let c = "conventional-braking";
    let jobs: Vec<Job<'static, FluidTrainRecord>> = vec![
        Box::new(move || run_braking(&braking(Oil::Light, 2, BrakeScope::FrontCar, false, quick, 1.0))),
        Box::new(move || run_braking(&braking(Oil::Heavy, 2, BrakeScope::FrontCar, false, quick, 1.0))),
        Box::new(move || run_braking(&braking(Oil::Light, 2, BrakeScope::AllCars, false, quick, 1.0))),
    ];
    let r = parallel(jobs)?;
    let (light, heavy, ecp) = (coupler(&r[0]), coupler(&r[1]), coupler(&r[2]));
    let t_end = r[0].train.t.last().copied().unwrap_or(0.0);
    let t0 = SETTLE + 1.0;
    let (ml, mh, me) = (mean_over(&light, t0, t_end), mean_over(&heavy, t0, t_end), mean_over(&ecp, t0, t_end));
    let compressive = light.iter().chain(&heavy).filter(|p| p.0 >= t0).map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
    Ok(vec![
        Record::less_than(
            c,
            "largest coupler force after brake build-up, both oils (N): compressive",
            compressive,
            0.0,
        ),
        Record::less_than(
            c,
            format!(
                "mean |coupler| ECP / conventional, light crude ({:.0} N vs {:.0} N): several times smaller",
                me.abs(),
                ml.abs()
            ),
            me.abs() / ml.abs().max(1e-300),
            1.0 / 3.0,
        ),
        Record::at_most(
            c,
            format!("mean coupler force, heavy vs light: relative difference ({mh:.0} N vs {ml:.0} N)"),
            (mh - ml).abs() / ml.abs().max(1e-300),
            0.15,
        ),
    ])
}

fn front_rear_difference(rec: &FluidTrainRecord, t0: f64) -> f64 {
    // Max over time of |front bogie − rear bogie| normal load of the front car.
    rec.train
        .t
        .iter()
        .zip(&rec.train.wheel_vertical)
        .filter(|(t, _)| **t >= t0)
        .map(|(_, q)| ((q[0][0] + q[0][1] + q[1][0] + q[1][1]) - (q[2][0] + q[2][1] + q[3][0] + q[3][1])).abs())
        .fold(0.0, f64::max)
}

fn bulkhead_reduction(quick: bool) -> Result<Vec<Record>> {
    let c = "bulkhead-reduction";
    let jobs: Vec<Job<'static, FluidTrainRecord>> = vec![
        Box::new(move || run_braking(&braking(Oil::Light, 2, BrakeScope::AllCars, false, quick, 1.0))),
        Box::new(move || run_braking(&braking(Oil::Light, 2, BrakeScope::AllCars, true, quick, 1.0))),
    ];
    let r = parallel(jobs)?;
    let (open, bulk) = (peak_abs(&coupler(&r[0])), peak_abs(&coupler(&r[1])));
    let (dq_open, dq_bulk) = (front_rear_difference(&r[0], SETTLE), front_rear_difference(&r[1], SETTLE));
    let reduction = 1.0 - bulk / open.max(1e-300);
    let peak = if quick {
        Record::less_than(
            c,
            format!("peak coupler force bulkheads/open, light crude ECP ({bulk:.0} N vs {open:.0} N), quick mesh: < 1"),
            bulk / open.max(1e-300),
            1.0,
        )
    } else {
        Record::abs(
            c,
            format!(
                "peak coupler force reduction by two bulkheads, light crude ECP ({bulk:.0} N vs {open:.0} N); paper ~70 %"
            ),
            reduction,
            0.675,
            0.175,
        )
    };
    Ok(vec![
        peak,
        Record::less_than(
            c,
            format!(
                "max front-rear bogie normal-force difference, bulkheads / open ({dq_bulk:.0} N vs {dq_open:.0} N)"
            ),
            dq_bulk / dq_open.max(1e-300),
            1.0,
        ),
    ])
}

/// Outward inertia force and in-plane gravity component of the oil (mean over the last
/// period of the first transverse slosh mode) for one car driven at `speed` through the Table 1 curve. The run starts with the
/// tank centre at 110 m, inside the body of the 3° curve (91.4–182.9 m), and ends at
/// `t_end` or when the leading wheelset reaches the end of the body, whichever is first, so
/// that the averaging window never reaches into the exit spiral (at 100 km/h a 3 s run
/// would: its last second spans 165–193 m).
pub fn curve_run(oil: Oil, speed: f64, counts: [usize; 3], t_end: f64) -> Result<(f64, f64, f64)> {
    let track = table1()?;
    let p = TankCarParams::standard()?;
    let cg = cargo(oil, counts, false, &p)?;
    let s0 = 110.0;
    let lead = 0.5 * (p.truck_centers + p.wheelbase); // leading wheelset ahead of the tank centre
    let radius = p.tank_radius;
    let t_end = t_end.min((TABLE1_BODY_END - lead - s0) / speed);
    if t_end < 1.5 {
        return Err(invalid(
            "curve run speed",
            speed,
            &format!("a speed that keeps the car in the curve body for at least 1.5 s ({t_end:.2} s here)"),
        ));
    }
    let mut sc = TrainScenario::single(p, track.clone(), s0, speed, t_end);
    sc.drive = Some(SpeedProfile::Constant(speed));
    sc.record_every = 0.02;
    sc.step = 4e-3;
    sc.hht = TrainScenario::fluid_hht();
    let rec = finish(run_fluid_train(&sc, &cg)?)?;
    let m = rec.fluid_mass;
    // CoM acceleration by central differences of the recorded global CoM.
    let (t, x) = (&rec.train.t, &rec.oil_com_global);
    // Averaging window: one period of the first transverse slosh mode of the half-full
    // cylinder (λ = ω²R/g = 1.3557, `equivalent::cylinder_lambda`; 2.1 s for R = 1.5 m), so that the sloshing
    // started by placing the car in the curve with a flat free surface averages out (the
    // light crude barely damps it), but no longer than the run minus 0.3 s.
    let period = 2.0 * std::f64::consts::PI / (cylinder_lambda(0.5)? * GRAVITY / radius).sqrt();
    let window = period.min(t_end - 0.3);
    let (mut fc, mut gc, mut n) = (0.0, 0.0, 0);
    for k in 1..t.len() - 1 {
        if t[k] < t_end - window {
            continue;
        }
        let h = t[k + 1] - t[k];
        let a = nalgebra::Vector3::from_fn(|i, _| (x[k + 1][0][i] - 2.0 * x[k][0][i] + x[k - 1][0][i]) / (h * h));
        let s = rec.train.tank_station[k][0];
        let f = track.frame(s);
        // F_c = m r̈_c · n with n the horizontal normal towards the centre of the (left)
        // curve: the magnitude of the outward d'Alembert force, m V²/R in steady curving.
        let lat = f.lateral();
        let inward = nalgebra::Vector3::new(lat.x, lat.y, 0.0).normalize();
        fc += m * a.dot(&inward);
        // In-plane gravity component along the track's (downhill) lateral axis.
        gc += m * GRAVITY * f.lateral().z.abs();
        n += 1;
    }
    Ok((fc / n.max(1) as f64, gc / n.max(1) as f64, m))
}

fn curve_outward_inertia(quick: bool) -> Result<Vec<Record>> {
    let c = "curve-outward-inertia";
    let (counts, t_end) = if quick { ([2, 2, 2], 2.0) } else { ([6, 4, 2], 3.0) };
    let oils = if quick { vec![Oil::Light, Oil::Heavy] } else { vec![Oil::Light, Oil::Medium, Oil::Heavy] };
    let mut jobs: Vec<Job<'static, (f64, f64, f64)>> = Vec::new();
    for &oil in &oils {
        for v in [60.0 / 3.6, 100.0 / 3.6] {
            jobs.push(Box::new(move || curve_run(oil, v, counts, t_end)));
        }
    }
    let r = parallel(jobs)?;
    let mut out = Vec::new();
    for (k, oil) in oils.iter().enumerate() {
        let (f60, g60, _) = r[2 * k];
        let (f100, g100, _) = r[2 * k + 1];
        out.push(Record::less_than(
            c,
            format!(
                "{} crude, 60 km/h: outward inertia / gravity component ({f60:.0} N vs {g60:.0} N) < 1",
                oil.name()
            ),
            f60 / g60,
            1.0,
        ));
        out.push(Record::less_than(
            c,
            format!(
                "{} crude, 100 km/h: gravity component / outward inertia ({g100:.0} N vs {f100:.0} N) < 1",
                oil.name()
            ),
            g100 / f100,
            1.0,
        ));
    }
    for k in 1..oils.len() {
        out.push(Record::less_than(
            c,
            format!("outward inertia at 100 km/h grows with density: {} / {}", oils[k - 1].name(), oils[k].name()),
            r[2 * (k - 1) + 1].0 / r[2 * k + 1].0,
            1.0,
        ));
    }
    Ok(out)
}

fn mesh_convergence(quick: bool) -> Result<Vec<Record>> {
    let c = "mesh-convergence";
    let (meshes, t_end): (Vec<[usize; 3]>, f64) =
        if quick { (vec![[2, 2, 2], [3, 2, 2], [4, 2, 2]], 2.5) } else { (vec![[4, 4, 2], [6, 4, 2], [8, 4, 2]], 6.0) };
    let jobs: Vec<Job<'static, FluidTrainRecord>> = meshes
        .iter()
        .map(|&m| {
            Box::new(move || {
                run_braking(&BrakingCase {
                    oil: Oil::Light,
                    cars: 1,
                    scope: BrakeScope::AllCars,
                    bulkheads: false,
                    counts: m,
                    t_end,
                    rear_brake_factor: 1.0,
                    wall_damping_ratio: ancf_core::contact::WALL_DAMPING_RATIO,
                    wall_adhesion: 0.0,
                    linear_solver: rail_mbs::integrator::LinearSolverKind::Condensed,
                    shear_stabilization: false,
                })
            }) as Job<'static, FluidTrainRecord>
        })
        .collect();
    let r = parallel(jobs)?;
    let x = |k: usize| -> Vec<f64> { r[k].oil_com_tank.iter().map(|c| c[0][0]).collect() };
    let (a, b, fine) = (x(0), x(1), x(2));
    let range = fine.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-6);
    let diff = |u: &[f64]| u.iter().zip(&fine).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max) / range;
    let el = |k: usize| r[k].elements;
    Ok(vec![
        Record::at_most(
            c,
            format!("max |x_com({}) - x_com({})| / max |x_com|, light crude braking", el(1), el(2)),
            diff(&b),
            0.10,
        ),
        Record::at_most(
            c,
            format!("max |x_com({}) - x_com({})| / max |x_com|, light crude braking", el(0), el(2)),
            diff(&a),
            0.20,
        ),
    ])
}

/// Low-pass of a recorded series: centred moving average over `width` seconds (a boxcar:
/// −3 dB at 0.44/width, first zero at 1/width). The coupler statistics of
/// `coupler-force-convergence` use width 0.2 s (−3 dB at 2.2 Hz): the car–liquid motions of
/// the braking study are below 1 Hz (the liquid's longitudinal slosh 0.27 Hz), contact
/// chatter above 5 Hz.
fn low_pass(x: &[(f64, f64)], width: f64) -> Vec<(f64, f64)> {
    x.iter().map(|p| (p.0, mean_over(x, p.0 - 0.5 * width, p.0 + 0.5 * width))).collect()
}

/// Peak of the low-passed force, RMS of the raw force and steady mean (the mean over the
/// second half of the braking), all over [`SETTLE`] to the end.
fn coupler_statistics(rec: &FluidTrainRecord) -> [f64; 3] {
    let x = coupler(rec);
    let t_end = x.last().map_or(0.0, |p| p.0);
    let braking: Vec<(f64, f64)> = x.iter().copied().filter(|p| p.0 >= SETTLE).collect();
    let peak = peak_abs(&low_pass(&braking, 0.2));
    let rms = (braking.iter().map(|p| p.1 * p.1).sum::<f64>() / braking.len().max(1) as f64).sqrt();
    let mean = mean_over(&x, 0.5 * (SETTLE + t_end), t_end);
    [peak, rms, mean]
}

/// `coupler-force-convergence` (issue 16 §3): the ECP (identical brakes, and a 10 % weaker
/// rear brake), and conventional coupler-force
/// statistics (peak of the low-passed force, RMS, steady mean; [`coupler_statistics`]) of
/// the two-car light-crude braking study change by at most 5 % between the two finest of
/// three meshes and between the runs' largest step ([`braking_step`]: 2 ms for ECP, 4 ms for
/// conventional braking, as the shipped scenes) and half of it on the middle mesh. Relative changes
/// are taken against the finer run's value; for the ECP steady mean, whose reference is
/// near zero (identical brakes), against the conventional steady mean (the scale of the
/// coupler force in this study). Quick: meshes 2×2×2, 3×2×2, 4×2×2, 3 s; full: 4×4×2,
/// 6×4×2 (the paper's), 8×4×2, the paper's 10.5 s. Walls critically damped and adhesive
/// (`wall_damping_ratio` = 1, `wall_adhesion` = 4) and the liquid's rest state stabilized
/// (`shear_stabilization`), as the shipped ECP scenes: docs/validation.md "Wall damping",
/// "Wall peeling", "A stable rest state").
fn coupler_force_convergence(quick: bool) -> Result<Vec<Record>> {
    let c = "coupler-force-convergence";
    let (meshes, t_end): ([[usize; 3]; 3], f64) =
        if quick { ([[2, 2, 2], [3, 2, 2], [4, 2, 2]], 3.0) } else { ([[4, 4, 2], [6, 4, 2], [8, 4, 2]], 10.5) };
    let mut jobs: Vec<Job<'static, FluidTrainRecord>> = Vec::new();
    // ECP with identical brakes, ECP with a 10 % weaker rear brake (the brake spread that
    // reproduces the paper's ECP figures, `ecp-braking-oils`) and conventional braking
    let groups = [
        (BrakeScope::AllCars, 1.0, "ECP"),
        (BrakeScope::AllCars, 0.9, "ECP, rear brake -10 %"),
        (BrakeScope::FrontCar, 1.0, "conventional"),
    ];
    for (scope, rear_brake_factor, _) in groups {
        let case = move |counts| BrakingCase {
            oil: Oil::Light,
            cars: 2,
            scope,
            bulkheads: false,
            counts,
            t_end,
            rear_brake_factor,
            wall_damping_ratio: SCENE_WALL_DAMPING,
            wall_adhesion: SCENE_WALL_ADHESION,
            linear_solver: rail_mbs::integrator::LinearSolverKind::Condensed,
            shear_stabilization: true,
        };
        for m in meshes {
            jobs.push(Box::new(move || run_braking(&case(m))));
        }
        let half = 0.5 * braking_step(scope, Oil::Light);
        jobs.push(Box::new(move || run_braking_with(&case(meshes[1]), half, TrainScenario::default_hht().rel_tol)));
    }
    let r = parallel(jobs)?;
    let stats: Vec<[f64; 3]> = r.iter().map(coupler_statistics).collect();
    // the identical-brake ECP mean is ~0: its change is measured against the conventional mean
    let scale = stats[8..12].iter().map(|s| s[2].abs()).fold(0.0, f64::max).max(1.0);
    let names = ["peak of the 0.2-s low-passed coupler force", "coupler-force RMS", "steady mean coupler force"];
    let mut out = Vec::new();
    for (g, &(scope, _, label)) in groups.iter().enumerate() {
        let base = 4 * g;
        let s = &stats[base..base + 4];
        for (q, name) in names.iter().enumerate() {
            let reference = |fine: f64| if base == 0 && q == 2 { scale } else { fine.abs().max(1e-9) };
            let mesh_change = (s[1][q] - s[2][q]).abs() / reference(s[2][q]);
            let step_change = (s[1][q] - s[3][q]).abs() / reference(s[3][q]);
            let m = |k: usize| format!("{:?}", meshes[k]);
            out.push(Record::at_most(
                c,
                format!(
                    "{label}, {name}: change {} -> {} mesh ({:.0} N -> {:.0} N; coarsest {} {:.0} N)",
                    m(1),
                    m(2),
                    s[1][q],
                    s[2][q],
                    m(0),
                    s[0][q]
                ),
                mesh_change,
                0.05,
            ));
            let h = 1e3 * braking_step(scope, Oil::Light);
            out.push(Record::at_most(
                c,
                format!(
                    "{label}, {name}: change {h} -> {} ms step on {} ({:.0} N -> {:.0} N)",
                    0.5 * h,
                    m(1),
                    s[1][q],
                    s[3][q]
                ),
                step_change,
                0.05,
            ));
        }
    }
    Ok(out)
}
