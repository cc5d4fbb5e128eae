//! Checkpoint/restart of the HHT integrator (bitwise-identical continuation), typed
//! failure causes (contact penetration through `check_step`, root cause of
//! `StepTooSmall`), and determinism of a slosh run across rayon thread counts.

use ancf_core::contact::{WallContact, WallContactLaw};
use ancf_core::mesh::box_mesh;
use ancf_core::tank::{TankGeometry, TankShape};
use ancf_core::{FluidBody, QuadratureOptions, Rheology};
use nalgebra::{Matrix3, Vector3};
use rail_mbs::defaults::{liquid, slosh_params};
use rail_mbs::integrator::{
    AdaptiveParams, Checkpoint, CheckpointFile, FailureCause, Hht, HhtParams, IntegratorError, Journal,
    MechanicalSystem, Predictor, SparsityPattern, StepControl, SystemError, read_journal,
};
use rail_mbs::mbs::rotation::axis_angle;
use rail_mbs::mbs::{JointKind, Multibody, RigidBody};
use rail_mbs::slosh::{PiecewiseAcceleration, PrescribedMotion, SloshFrame, SloshSystem};

use ancf_core::constants::GRAVITY as G;

/// Water in a small box tank hit by a lateral pulse (2×3×2 elements).
fn slosh_system() -> SloshSystem {
    let (lx, ly, d) = (0.416, 0.324, 0.132);
    let counts = [2, 3, 2];
    let mesh = box_mesh([-lx / 2.0, -ly / 2.0, 0.0], [lx, ly, d], counts).unwrap();
    let fluid = liquid(998.0, Rheology::Newtonian { viscosity: 1e-3 }, d, d / counts[2] as f64).unwrap();
    let geo =
        TankGeometry::new(TankShape::Box { min: [-lx / 2.0, -ly / 2.0, 0.0], max: [lx / 2.0, ly / 2.0, 0.3] }, vec![])
            .unwrap();
    let body = FluidBody::new(mesh, fluid, QuadratureOptions::default()).unwrap();
    let contact = WallContact::new(&body, geo, WallContactLaw::default_for(998.0, G, d)).unwrap();
    let mut motion = PrescribedMotion::at_rest([0.0; 3]);
    motion.translation[1] = PiecewiseAcceleration::pulse(0.5 * G, 0.0, 0.2, 0.01).unwrap();
    SloshSystem::new(body, contact, motion, [0.0, 0.0, -G], SloshFrame::Inertial).unwrap()
}

/// A rod pinned about the global Y axis (revolute joint: 5 constraints + normalization).
fn pendulum() -> (Multibody, Vec<f64>, Vec<f64>) {
    let (m, l) = (3.0, 1.2);
    let ic = m * l * l / 12.0;
    let mut mb = Multibody::new();
    let mut b = RigidBody::new("rod", m, [ic, ic, 1e-3], Vector3::zeros());
    b.orientation = axis_angle(&Vector3::y(), 0.6);
    b.position = b.orientation * Vector3::new(0.0, 0.0, -0.5 * l);
    let id = mb.add_body(b).unwrap();
    let axes = Matrix3::from_columns(&[Vector3::z(), Vector3::x(), Vector3::y()]);
    mb.add_joint("pin", JointKind::Revolute, Some(id), None, Vector3::zeros(), axes).unwrap();
    let (q0, v0) = mb.initial_coordinates();
    (mb, q0, v0)
}

fn bits(x: &[f64]) -> Vec<u64> {
    x.iter().map(|v| v.to_bits()).collect()
}

/// Full state and step sizes after each step, as bit patterns.
type Trace = Vec<(u64, Vec<u64>, Vec<u64>, Vec<u64>, Vec<u64>)>;

fn trace_steps<S: MechanicalSystem>(hht: &mut Hht<S>, steps: usize, h: f64) -> Trace {
    (0..steps)
        .map(|_| {
            let info = hht.step(h).unwrap();
            let s = hht.state();
            (info.h.to_bits() ^ s.t.to_bits().rotate_left(1), bits(s.q), bits(s.v), bits(s.a), bits(s.lambda))
        })
        .collect()
}

/// Runs `total` steps, checkpointing (through bytes) after `k`; resumes the checkpoint
/// in a fresh integrator built by `fresh` and checks that every later step is
/// bitwise identical, including the statistics counters.
fn check_resume<S: MechanicalSystem>(
    mut hht: Hht<S>,
    fresh: impl Fn() -> S,
    params: HhtParams,
    k: usize,
    total: usize,
    h: f64,
) -> Checkpoint {
    trace_steps(&mut hht, k, h);
    let bytes = hht.checkpoint().to_bytes();
    let reference = trace_steps(&mut hht, total - k, h);
    let ck = Checkpoint::from_bytes(&bytes).unwrap();
    assert_eq!(ck.stats.steps, k);
    let mut resumed = Hht::restore(fresh(), &ck, params).unwrap();
    let resumed_trace = trace_steps(&mut resumed, total - k, h);
    assert_eq!(reference.len(), resumed_trace.len());
    for (i, (a, b)) in reference.iter().zip(&resumed_trace).enumerate() {
        assert!(a == b, "step {} after the checkpoint differs", i + 1);
    }
    let (s1, s2) = (hht.stats(), resumed.stats());
    assert_eq!(
        (s1.steps, s1.rejected_steps, s1.newton_iterations, s1.jacobian_evaluations, s1.linear_solves),
        (s2.steps, s2.rejected_steps, s2.newton_iterations, s2.jacobian_evaluations, s2.linear_solves)
    );
    ck
}

#[test]
fn slosh_run_resumed_from_a_checkpoint_is_bitwise_identical() {
    let params = slosh_params();
    let sys = slosh_system();
    let (q0, v0) = sys.initial_state(0.0);
    let hht = Hht::new(sys, 0.0, q0, v0, params).unwrap();
    // The pulse makes the adaptive controller and the Jacobian reuse work.
    let ck = check_resume(hht, slosh_system, params, 12, 40, 0.008);
    // The checkpoint carried a reusable factorization (otherwise reuse was not tested).
    assert!(ck.jac_valid && ck.factor_h.is_some(), "{:?} {:?}", ck.jac_valid, ck.factor_h);
}

#[test]
fn constrained_multibody_run_resumed_from_a_checkpoint_is_bitwise_identical() {
    for step_control in
        [StepControl::Fixed, StepControl::Adaptive(AdaptiveParams { h_min: 1e-8, ..Default::default() })]
    {
        for predictor in [Predictor::Hold, Predictor::Extrapolate] {
            let params = HhtParams {
                alpha: -0.1,
                rel_tol: 1e-8,
                max_iterations: 20,
                step_control,
                predictor,
                ..Default::default()
            };
            let (mb, q0, v0) = pendulum();
            let hht = Hht::new(mb, 0.0, q0, v0, params).unwrap();
            let ck = check_resume(hht, || pendulum().0, params, 37, 120, 5e-3);
            assert!(!ck.lambda.is_empty());
            assert!(ck.h_prev > 0.0 && ck.a_prev != ck.a, "the checkpoint carries the predictor's history");
        }
    }
}

#[test]
fn extrapolating_slosh_run_resumed_from_a_checkpoint_is_bitwise_identical() {
    let params = HhtParams { predictor: Predictor::Extrapolate, ..slosh_params() };
    let sys = slosh_system();
    let (q0, v0) = sys.initial_state(0.0);
    let hht = Hht::new(sys, 0.0, q0, v0, params).unwrap();
    check_resume(hht, slosh_system, params, 12, 40, 0.008);
}

#[test]
fn corrupted_or_mismatched_checkpoints_are_typed_errors() {
    let (mb, q0, v0) = pendulum();
    let params = HhtParams::default();
    let mut hht = Hht::new(mb, 0.0, q0, v0, params).unwrap();
    hht.integrate_to(0.05, 1e-2).unwrap();
    let ck = hht.checkpoint();
    let bytes = ck.to_bytes();
    assert_eq!(Checkpoint::from_bytes(&bytes).unwrap(), ck);
    let is_ck_err = |r: Result<Checkpoint, IntegratorError>, needle: &str| match r {
        Err(e @ IntegratorError::Checkpoint { .. }) => {
            assert!(e.to_string().contains(needle), "{e} should mention {needle}");
            assert_eq!(e.cause(), FailureCause::InvalidInput);
        }
        other => panic!("expected a checkpoint error, got {other:?}"),
    };
    is_ck_err(Checkpoint::from_bytes(&bytes[..bytes.len() - 3]), "truncated");
    is_ck_err(Checkpoint::from_bytes(b"not a checkpoint at all"), "magic");
    let mut extra = bytes.clone();
    extra.push(0);
    is_ck_err(Checkpoint::from_bytes(&extra), "trailing");
    let mut version = bytes.clone();
    version[8] = 99;
    is_ck_err(Checkpoint::from_bytes(&version), "version");
    // Every truncation is an error, never a panic.
    for cut in 0..bytes.len() {
        assert!(Checkpoint::from_bytes(&bytes[..cut]).is_err());
    }
    // A checkpoint of another system does not restore.
    match Hht::restore(slosh_system(), &ck, slosh_params()) {
        Err(IntegratorError::InvalidSystem { .. } | IntegratorError::Checkpoint { .. }) => {}
        Err(e) => panic!("unexpected error {e}"),
        Ok(_) => panic!("restored a pendulum checkpoint into a slosh system"),
    }
}

/// A unit mass falling onto a penalty floor `z < 0` of stiffness `k`; `check_step`
/// rejects penetrations beyond `limit`.
struct Bouncer {
    k: f64,
    limit: f64,
}

impl MechanicalSystem for Bouncer {
    fn n_coords(&self) -> usize {
        1
    }
    fn pattern(&self) -> SparsityPattern {
        SparsityPattern::diagonal(1)
    }
    fn mass_is_constant(&self) -> bool {
        true
    }
    fn mass(&mut self, _q: &[f64], m: &mut [f64]) -> Result<(), SystemError> {
        m[0] = 1.0;
        Ok(())
    }
    fn forces(&mut self, _t: f64, q: &[f64], _v: &[f64], f: &mut [f64]) -> Result<(), SystemError> {
        f[0] = -G + if q[0] < 0.0 { -self.k * q[0] } else { 0.0 };
        Ok(())
    }
    fn force_jacobians(
        &mut self,
        _t: f64,
        q: &[f64],
        _v: &[f64],
        dq: &mut [f64],
        _dv: &mut [f64],
    ) -> Result<(), SystemError> {
        dq[0] = if q[0] < 0.0 { -self.k } else { 0.0 };
        Ok(())
    }
    fn check_step(&mut self, _t: f64, q: &[f64], _v: &[f64]) -> Result<(), SystemError> {
        let depth = -q[0];
        if depth > self.limit {
            return Err(SystemError::Penetration { contact: "floor".into(), depth, limit: self.limit });
        }
        Ok(())
    }
}

#[test]
fn penetration_beyond_the_limit_stops_the_run_with_a_typed_error_and_keeps_the_state() {
    // Dropped from 1 m onto a soft floor: the static-free impact depth is
    // v/ω = √(2 g · 1 m / k) ≈ 0.44 m for k = 100 N/m; the limit is 0.1 m.
    let sys = Bouncer { k: 100.0, limit: 0.1 };
    let mut hht = Hht::new(sys, 0.0, vec![1.0], vec![0.0], HhtParams::default()).unwrap();
    let mut last_ok = (0.0, 1.0);
    let err = loop {
        match hht.step(1e-3) {
            Ok(_) => last_ok = (hht.t(), hht.q()[0]),
            Err(e) => break e,
        }
    };
    assert_eq!(err.cause(), FailureCause::ContactPenetration, "{err}");
    let t_fail = err.time().unwrap();
    // The state is the last accepted one, within the limit, just before the failure.
    assert_eq!(hht.t(), last_ok.0);
    assert!(hht.q()[0] >= -0.1 && hht.q()[0] < -0.09, "{}", hht.q()[0]);
    assert!((t_fail - (hht.t() + 1e-3)).abs() < 1e-12, "{t_fail}");
    // Free fall reaches the floor at √(2/g) ≈ 0.4515 s.
    assert!(hht.t() > (2.0 / G).sqrt());
    assert!(err.to_string().contains("penetration"), "{err}");

    // Adaptive mode cannot help a physical penetration: it reduces h to h_min and
    // reports StepTooSmall whose root cause is still the penetration.
    let params = HhtParams {
        step_control: StepControl::Adaptive(AdaptiveParams { h_min: 1e-5, ..Default::default() }),
        ..Default::default()
    };
    let mut hht = Hht::new(Bouncer { k: 100.0, limit: 0.1 }, 0.0, vec![1.0], vec![0.0], params).unwrap();
    let err = hht.integrate_to(2.0, 1e-3).unwrap_err();
    assert!(matches!(err, IntegratorError::StepTooSmall { .. }), "{err}");
    assert_eq!(err.cause(), FailureCause::ContactPenetration);
    assert!(matches!(err.root(), IntegratorError::System { source: SystemError::Penetration { .. }, .. }));
}

#[test]
fn slosh_penetration_limit_is_checked_on_accepted_steps() {
    // A limit of zero cannot hold against gravity: the first step that settles the
    // fluid onto the floor is rejected with a penetration error.
    let mut sys = slosh_system();
    assert!(sys.penetration_limit > 0.0 && sys.penetration_limit < 0.1);
    sys.penetration_limit = 0.0;
    let (q0, v0) = sys.initial_state(0.0);
    let params = HhtParams { step_control: StepControl::Fixed, ..slosh_params() };
    let mut hht = Hht::new(sys, 0.0, q0, v0, params).unwrap();
    let err = hht.integrate_to(0.1, 0.004).unwrap_err();
    assert_eq!(err.cause(), FailureCause::ContactPenetration, "{err}");
}

/// One slosh run inside a rayon pool with `threads` workers; returns the final state.
fn slosh_in_pool(threads: usize) -> Vec<u64> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| {
        let sys = slosh_system();
        let (q0, v0) = sys.initial_state(0.0);
        let mut hht = Hht::new(sys, 0.0, q0, v0, slosh_params()).unwrap();
        hht.integrate_to(0.12, 0.008).unwrap();
        let mut out = bits(hht.q());
        out.extend(bits(hht.v()));
        out.extend(bits(hht.a()));
        out.push(hht.t().to_bits());
        out
    })
}

#[test]
fn slosh_results_do_not_depend_on_the_thread_count() {
    let one = slosh_in_pool(1);
    for threads in [2, 4] {
        assert!(slosh_in_pool(threads) == one, "{threads} threads differ from 1 thread");
    }
}

fn temp_path(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("railslosh-{}-{name}", std::process::id()))
}

#[test]
fn periodic_checkpoint_file_resumes_bitwise_and_journal_keeps_every_complete_row() {
    let params = HhtParams { alpha: -0.1, rel_tol: 1e-8, max_iterations: 20, ..Default::default() };
    let (mb, q0, v0) = pendulum();
    let mut hht = Hht::new(mb, 0.0, q0, v0, params).unwrap();
    let (ck_path, journal_path) = (temp_path("pendulum.ck"), temp_path("pendulum.journal"));
    let mut ck_file = CheckpointFile::new(&ck_path, 30).unwrap();
    let mut journal = Journal::create(&journal_path, &["t", "q0", "v0"], 1).unwrap();
    let mut written = Vec::new();
    for _ in 0..100 {
        hht.step(5e-3).unwrap();
        let row = [hht.t(), hht.q()[0], hht.v()[0]];
        journal.append(&row).unwrap();
        written.push(row.to_vec());
        ck_file.maybe_write(&hht).unwrap();
    }
    assert_eq!(ck_file.written(), 3);
    // An interruption now: the journal is flushed row by row, the checkpoint is the one of step 90.
    let (names, rows) = read_journal(&journal_path).unwrap();
    assert_eq!(names, ["t", "q0", "v0"]);
    assert!(rows == written);
    let ck = CheckpointFile::read(&ck_path).unwrap();
    assert_eq!(ck.stats.steps, 90);
    let mut resumed = Hht::restore(pendulum().0, &ck, params).unwrap();
    for _ in 0..10 {
        resumed.step(5e-3).unwrap();
    }
    assert_eq!(bits(resumed.q()), bits(hht.q()));
    assert_eq!(bits(resumed.lambda()), bits(hht.lambda()));
    // A torn last row (crash in the middle of a write) is dropped, the rest kept.
    drop(journal);
    let len = std::fs::metadata(&journal_path).unwrap().len();
    let f = std::fs::OpenOptions::new().write(true).open(&journal_path).unwrap();
    f.set_len(len - 5).unwrap();
    let (_, rows) = read_journal(&journal_path).unwrap();
    assert!(rows[..] == written[..99]);
    std::fs::write(&journal_path, b"garbage").unwrap();
    assert!(matches!(read_journal(&journal_path), Err(IntegratorError::Checkpoint { .. })));
    std::fs::remove_file(&journal_path).unwrap();
    std::fs::remove_file(&ck_path).unwrap();
}

#[test]
fn failure_causes_classify_every_error_and_messages_keep_the_words_python_matches() {
    let sys = |source| IntegratorError::System { t: 0.5, source };
    let inverted = sys(SystemError::InvertedElement { element: 3, point: 7, j: -0.02 });
    let penetration = sys(SystemError::Penetration { contact: "wall".into(), depth: 0.02, limit: 0.01 });
    let volume = sys(SystemError::VolumeError { what: "fluid".into(), volume: 0.98, reference: 1.0, limit: 0.01 });
    let newton = IntegratorError::NewtonDivergence {
        t: 0.2,
        h: 0.01,
        iterations: 6,
        correction: 3.0,
        rate: 1.5,
        largest: Some("coordinate 3 = z of body 'rod'".into()),
    };
    let singular = IntegratorError::SingularMatrix { t: 0.0, h: 0.0, pivot_step: Some(5), unknown: None };
    // The patterns of railslosh.slosh.FAILURE_CAUSES (Python) in the Display strings.
    for (e, cause, words, t) in [
        (&inverted, FailureCause::InvertedElement, "inverted: J =", 0.5),
        (&penetration, FailureCause::ContactPenetration, "beyond its limit", 0.5),
        (&volume, FailureCause::VolumeError, "deviates from its reference", 0.5),
        (&newton, FailureCause::NewtonDivergence, "Newton iteration did not converge", 0.2),
        (&singular, FailureCause::SingularConstraints, "singular KKT matrix", 0.0),
    ] {
        assert_eq!(e.cause(), cause, "{e}");
        assert!(e.to_string().contains(words), "{e}");
        assert_eq!(e.time(), Some(t));
        // Wrapped by the step controller, the root cause is kept.
        let wrapped = IntegratorError::StepTooSmall { t: 0.4, h: 1e-7, h_min: 1e-6, cause: Box::new((*e).clone()) };
        assert_eq!(wrapped.cause(), cause);
        assert!(wrapped.to_string().contains(words) && wrapped.to_string().contains("below h_min"));
    }
    assert!(volume.to_string().contains("-2.000%"), "{volume}");
    assert_eq!(FailureCause::VolumeError.name(), "volume_error");
    assert_eq!(
        IntegratorError::InvalidParameter { field: "h", value: -1.0, allowed: "> 0" }.cause(),
        FailureCause::InvalidInput
    );
}

#[test]
fn journaled_slosh_run_streams_every_recorded_sample_exactly() {
    use rail_mbs::slosh::{SloshRecord, SloshRun};
    let path = temp_path("slosh.journal");
    let mut run = SloshRun::new(slosh_system(), 0.0, slosh_params()).unwrap();
    let mut journal = Journal::create(&path, &SloshRecord::COLUMNS, 1).unwrap();
    run.run_to_journaled(0.05, 0.01, &mut |_| true, &mut journal).unwrap();
    let (names, rows) = read_journal(&path).unwrap();
    assert_eq!(names, SloshRecord::COLUMNS);
    assert_eq!(rows.len(), run.record.t.len());
    for (i, row) in rows.iter().enumerate() {
        assert_eq!(bits(row), bits(&run.record.row(i)), "sample {i}");
    }
    // Same samples as the plain run.
    let mut plain = SloshRun::new(slosh_system(), 0.0, slosh_params()).unwrap();
    plain.run_to(0.05, 0.01).unwrap();
    assert!(plain.record == run.record);
    std::fs::remove_file(&path).unwrap();
}

/// Issue 18: a slosh run's checkpoint file carries the invariants' account, so a resumed run
/// (implicit or explicit) records every column of the uninterrupted run bit for bit, energy error
/// and input work included, and ends with the same worst margins; a bare stepper checkpoint still
/// resumes, with its energy account restarted at the checkpoint.
#[test]
fn a_resumed_slosh_run_goes_on_with_the_same_energy_account() {
    use rail_mbs::integrator::ExplicitParams;
    use rail_mbs::slosh::{SloshCheckpoint, SloshRecord, SloshRun};
    let column = |name: &str| SloshRecord::COLUMNS.iter().position(|c| *c == name).unwrap();
    for explicit in [false, true] {
        let start = || {
            if explicit {
                SloshRun::new_explicit(slosh_system(), 0.0, ExplicitParams::default()).unwrap()
            } else {
                SloshRun::new(slosh_system(), 0.0, slosh_params()).unwrap()
            }
        };
        let path = temp_path(&format!("slosh-account-{explicit}.ck"));
        // checkpoints every 40 % of the run's steps (an explicit run counts its sub-steps)
        let mut probe = start();
        probe.run_to(0.3, 0.01).unwrap();
        let every = probe.stepper.stats().steps * 2 / 5;
        let mut full = start();
        full.checkpoints = Some(CheckpointFile::new(&path, every).unwrap());
        full.run_to(0.3, 0.01).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let ck = SloshCheckpoint::from_bytes(&bytes).unwrap();
        assert!(!ck.account.is_empty());
        let resume =
            |b: &[u8]| SloshRun::resume_from_bytes(slosh_system(), b, slosh_params(), ExplicitParams::default());
        let mut rest = resume(&bytes).unwrap();
        rest.run_to(0.3, 0.01).unwrap();
        let k = full.record.t.iter().position(|&t| t == rest.record.t[0]).unwrap();
        assert!(k > 0 && k + 1 < full.record.t.len(), "explicit {explicit}: checkpoint at sample {k}");
        assert_eq!(rest.record.t.len(), full.record.t.len() - k);
        for i in 0..rest.record.t.len() {
            let (a, b) = (rest.record.row(i), full.record.row(k + i));
            if i == 0 {
                // the resumed first sample reports no Newton iterations; everything else is equal
                let it = column("newton_iterations");
                let drop_it =
                    |r: Vec<f64>| r.into_iter().enumerate().filter(|&(j, _)| j != it).map(|x| x.1).collect::<Vec<_>>();
                assert_eq!(bits(&drop_it(a)), bits(&drop_it(b)), "explicit {explicit}: first resumed sample");
            } else {
                assert_eq!(bits(&a), bits(&b), "explicit {explicit}: sample {}", k + i);
            }
        }
        assert!(rest.record.input_work[0] != 0.0, "the account went on, not restarted");
        assert_eq!(rest.invariants.margins(), full.invariants.margins());
        // A bare stepper checkpoint (the format before the account was saved): the run resumes
        // with the same loads, and an energy account that starts again at the checkpoint.
        let mut bare = resume(&ck.stepper).unwrap();
        bare.run_to(0.3, 0.01).unwrap();
        assert_eq!(bits(&bare.record.volume), bits(&full.record.volume[k..]));
        assert_eq!(bare.record.input_work[0], 0.0);
        // an account of the wrong length is refused with a typed error
        let short = SloshCheckpoint { stepper: ck.stepper.clone(), account: ck.account[1..].to_vec() };
        assert!(matches!(resume(&short.to_bytes()), Err(IntegratorError::Checkpoint { .. })));
        std::fs::remove_file(&path).unwrap();
    }
}

#[test]
fn adaptive_steps_stretch_to_the_requested_step_instead_of_leaving_a_sliver() {
    // A caller landing on output times asks for the remainder to the next one; when the
    // controller's step falls just short of it, the step is stretched (≤ 1 %) so that no
    // sliver step follows: one Newton failure on a sliver ends the run, since halving it
    // falls below h_min at once (the 100 km/h curve runs of the crude-oil study stopped so,
    // at t = 1.44 s - 9.3e-12 s).
    let (mb, q0, v0) = pendulum();
    let params = HhtParams { step_control: StepControl::Adaptive(AdaptiveParams::default()), ..HhtParams::default() };
    let mut hht = Hht::new(mb, 0.0, q0, v0, params).unwrap();
    for _ in 0..20 {
        hht.step(4e-3).unwrap();
    }
    let t0 = hht.t();
    let info = hht.step(4e-3 * 1.005).unwrap();
    assert_eq!(info.h, 4e-3 * 1.005, "the step was not stretched: h = {}", info.h);
    assert!((hht.t() - (t0 + 4e-3 * 1.005)).abs() < 1e-15);
    // a request 2 % longer than the controller's step is not stretched
    let info = hht.step(4e-3 * 1.02).unwrap();
    assert!(info.h < 4e-3 * 1.02, "h = {}", info.h);
    // nor is a request that would leave a remainder below h_min (a sliver whose first
    // Newton failure would end the run: halving it falls below h_min at once)
    let h_min = AdaptiveParams::default().h_min;
    let t1 = hht.t();
    let info = hht.step(4e-3 + 0.5 * h_min).unwrap();
    assert_eq!(info.h, 4e-3 + 0.5 * h_min);
    assert!((hht.t() - (t1 + 4e-3 + 0.5 * h_min)).abs() < 1e-15);
}

#[test]
fn constraint_unknowns_are_described_by_joint_equation() {
    use rail_mbs::integrator::KktIndex;
    let (mb, _, _) = pendulum();
    // one normalization row, then the revolute joint's five equations
    assert_eq!(
        mb.describe_unknown(KktIndex::Constraint(0)),
        "constraint 0 = Euler-parameter normalization of body 'rod'"
    );
    assert_eq!(mb.describe_unknown(KktIndex::Constraint(1)), "constraint 1 = equation 0 of joint 'pin'");
    assert_eq!(mb.describe_unknown(KktIndex::Constraint(5)), "constraint 5 = equation 4 of joint 'pin'");
    assert_eq!(mb.describe_unknown(KktIndex::Constraint(6)), "constraint 6");
    assert_eq!(mb.describe_unknown(KktIndex::Coordinate(2)), "coordinate 2 = z of body 'rod'");
}

#[test]
fn a_newton_divergence_names_the_unknown_with_the_largest_correction() {
    // A fixed step far too long for one Newton iteration to converge: the error names the
    // unknown through the system's description (here the swinging rod's coordinates).
    let (mb, q0, v0) = pendulum();
    let params =
        HhtParams { step_control: StepControl::Fixed, max_iterations: 1, rel_tol: 1e-12, ..HhtParams::default() };
    let mut hht = Hht::new(mb, 0.0, q0, v0, params).unwrap();
    let err = hht.step(0.2).unwrap_err();
    let IntegratorError::NewtonDivergence { largest: Some(w), .. } = &err else {
        panic!("expected a Newton divergence naming an unknown: {err}");
    };
    assert!(w.contains("of body 'rod'") || w.contains("of joint 'pin'"), "{w}");
    assert!(err.to_string().contains(&format!("largest correction: {w}")), "{err}");
}
