//! No heap allocation in the HHT step loop (issue 7): after a warm-up, Newton iterations
//! that reuse the factorization allocate nothing — residual (multibody forces with
//! wheel/rail contact, fluid internal forces), KKT right-hand side and the sparse solve —
//! for a rigid tank car and for a tank car carrying an ANCF fluid.
//!
//! A counting global allocator counts the allocations of the current thread; the
//! measured steps run inside a one-thread rayon pool, so every parallel loop of the step
//! runs (and allocates, if it did) on the counted thread. The model is wrapped in
//! [`Counted`], which attributes the allocations to the callbacks (forces, constraints,
//! Jacobians, step check); what is left is the integrator's own (KKT assembly, LU).
//!
//! Print the counts with `cargo test -p rail-mbs --release --test alloc_free -- --nocapture`.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::Arc;

use rail_mbs::defaults::Oil;
use rail_mbs::integrator::{Hht, KktIndex, MechanicalSystem, SparsityPattern, Stats, SystemError};
use rail_mbs::track::Track;
use rail_mbs::vehicle::{FluidCargo, FluidVehicle, TankCarParams, TrainScenario, build_fluid_train, build_train};

struct CountingAllocator;

thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

fn bump() {
    // `try_with`: the allocator can be called while the thread-local is being destroyed.
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

// SAFETY: every call is forwarded unchanged to the system allocator.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        bump();
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        bump();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        bump();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

/// Allocations of the current thread so far.
fn allocations() -> u64 {
    ALLOCATIONS.with(Cell::get)
}

/// Allocations of the current thread while `f` runs.
fn counting<R>(f: impl FnOnce() -> R) -> (R, u64) {
    let a0 = allocations();
    let r = f();
    (r, allocations() - a0)
}

/// Allocations per callback, accumulated.
#[derive(Debug, Clone, Copy, Default)]
struct Counts {
    forces: u64,
    /// Constraints, their Jacobian and the mass matrix.
    constraints: u64,
    jacobians: u64,
    check_step: u64,
}

/// A system whose callbacks count their allocations.
struct Counted<S> {
    inner: S,
    counts: Counts,
}

impl<S: MechanicalSystem> MechanicalSystem for Counted<S> {
    fn n_coords(&self) -> usize {
        self.inner.n_coords()
    }
    fn n_constraints(&self) -> usize {
        self.inner.n_constraints()
    }
    fn pattern(&self) -> SparsityPattern {
        self.inner.pattern()
    }
    fn mass_is_constant(&self) -> bool {
        self.inner.mass_is_constant()
    }
    fn mass_entries(&self) -> Option<Vec<usize>> {
        self.inner.mass_entries()
    }
    fn describe_unknown(&self, index: KktIndex) -> String {
        self.inner.describe_unknown(index)
    }
    fn mass(&mut self, q: &[f64], values: &mut [f64]) -> Result<(), SystemError> {
        let (r, n) = counting(|| self.inner.mass(q, values));
        self.counts.constraints += n;
        r
    }
    fn forces(&mut self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) -> Result<(), SystemError> {
        let (r, n) = counting(|| self.inner.forces(t, q, v, out));
        self.counts.forces += n;
        r
    }
    fn force_jacobians(
        &mut self,
        t: f64,
        q: &[f64],
        v: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
    ) -> Result<(), SystemError> {
        let (r, n) = counting(|| self.inner.force_jacobians(t, q, v, dq, dv));
        self.counts.jacobians += n;
        r
    }
    fn constraints(&mut self, t: f64, q: &[f64], out: &mut [f64]) -> Result<(), SystemError> {
        let (r, n) = counting(|| self.inner.constraints(t, q, out));
        self.counts.constraints += n;
        r
    }
    fn constraint_jacobian(&mut self, t: f64, q: &[f64], values: &mut [f64]) -> Result<(), SystemError> {
        let (r, n) = counting(|| self.inner.constraint_jacobian(t, q, values));
        self.counts.constraints += n;
        r
    }
    fn constraint_force_jacobian(
        &mut self,
        t: f64,
        q: &[f64],
        lambda: &[f64],
        dq: &mut [f64],
    ) -> Result<bool, SystemError> {
        let (r, n) = counting(|| self.inner.constraint_force_jacobian(t, q, lambda, dq));
        self.counts.jacobians += n;
        r
    }
    fn check_step(&mut self, t: f64, q: &[f64], v: &[f64]) -> Result<(), SystemError> {
        let (r, n) = counting(|| self.inner.check_step(t, q, v));
        self.counts.check_step += n;
        r
    }
}

/// One measured step: its allocations (total and per callback) and work counters.
#[derive(Debug, Clone, Copy)]
struct StepCount {
    total: u64,
    callbacks: Counts,
    /// Allocations inside `WallContact::forces` during the step (fluid case).
    wall_contact: u64,
    iterations: usize,
    residuals: usize,
    factorizations: usize,
    jacobians: usize,
    rejected: usize,
}

impl StepCount {
    /// Allocations outside the callbacks: the integrator's own (KKT, LU, solves).
    fn integrator(&self) -> u64 {
        let c = self.callbacks;
        self.total - c.forces - c.constraints - c.jacobians - c.check_step
    }
}

/// Runs `warmup` steps, then `measured` steps of `h`, one at a time, inside a
/// one-thread rayon pool. `wall_contact(sys)` returns the allocations of one
/// `WallContact::forces` pass over all fluids at the current state (0 for no fluid).
fn measure<S: MechanicalSystem + Send>(
    mut hht: Hht<Counted<S>>,
    h: f64,
    warmup: usize,
    measured: usize,
    wall_contact: impl Fn(&Hht<Counted<S>>) -> u64 + Sync,
) -> Vec<StepCount> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("rayon pool");
    pool.install(|| {
        for _ in 0..warmup {
            hht.step(h).expect("warm-up step");
        }
        let mut out = Vec::with_capacity(measured);
        for _ in 0..measured {
            let s0: Stats = *hht.stats();
            let c0 = hht.system().counts;
            // Contact passes per step without a Jacobian: one per residual evaluation and one
            // in the step check. The per-pass count is measured at the state of the step start.
            let per_pass = wall_contact(&hht);
            let (r, total) = counting(|| hht.step(h));
            r.expect("measured step");
            let s1 = *hht.stats();
            let c1 = hht.system().counts;
            let residuals = s1.residual_evaluations - s0.residual_evaluations;
            out.push(StepCount {
                total,
                callbacks: Counts {
                    forces: c1.forces - c0.forces,
                    constraints: c1.constraints - c0.constraints,
                    jacobians: c1.jacobians - c0.jacobians,
                    check_step: c1.check_step - c0.check_step,
                },
                wall_contact: per_pass * (residuals as u64 + 1),
                iterations: s1.newton_iterations - s0.newton_iterations,
                residuals,
                factorizations: s1.factorizations - s0.factorizations,
                jacobians: s1.jacobian_evaluations - s0.jacobian_evaluations,
                rejected: s1.rejected_steps - s0.rejected_steps,
            });
        }
        out
    })
}

fn tangent() -> Arc<Track> {
    Arc::new(Track::straight(3000.0).expect("track"))
}

fn report(name: &str, steps: &[StepCount]) {
    println!(
        "{name}: allocations per step (total / forces / constraints / jacobians / check_step / integrator / wall contact)"
    );
    for s in steps {
        println!(
            "  {:>5} / {:>5} / {:>3} / {:>5} / {:>4} / {:>4} / {:>5}   iterations {} residuals {} factorizations {} jacobians {} rejected {}",
            s.total,
            s.callbacks.forces,
            s.callbacks.constraints,
            s.callbacks.jacobians,
            s.callbacks.check_step,
            s.integrator(),
            s.wall_contact,
            s.iterations,
            s.residuals,
            s.factorizations,
            s.jacobians,
            s.rejected
        );
    }
}

/// Steps that reuse the factorization and the Jacobians.
fn reuse_steps(steps: &[StepCount]) -> Vec<StepCount> {
    steps.iter().filter(|s| s.factorizations == 0 && s.jacobians == 0 && s.rejected == 0).copied().collect()
}

/// A braking tank car with rigid lading on tangent track: wheel/rail contact, suspension,
/// brake and the Euler-parameter constraints.
#[test]
fn rigid_tank_car_steps_do_not_allocate() {
    let mut p = TankCarParams::standard().expect("car");
    p.lading = Some((36_000.0, -0.5));
    let mut sc = TrainScenario::single(p, tangent(), 100.0, 10.0, 1.0);
    sc.hht.refresh_rate = 0.5;
    let (mb, _, _) = build_train(&sc).expect("train");
    let (q0, v0) = mb.initial_coordinates();
    let hht = Hht::new(Counted { inner: mb, counts: Counts::default() }, 0.0, q0, v0, sc.hht).expect("hht");
    let steps = measure(hht, 1e-3, 40, 30, |_| 0);
    report("rigid tank car", &steps);
    let reuse = reuse_steps(&steps);
    assert!(reuse.len() >= 5, "too few steps without refactorization to check: {steps:?}");
    for s in &reuse {
        assert_eq!(s.total, 0, "a step that reuses the factorization allocated: {s:?}");
    }
}

/// The same car carrying light crude as a 3×2×2 ANCF fluid mesh. The allocations of
/// `WallContact::forces` (ancf-core contact.rs, made allocation-free separately) are
/// measured on their own and subtracted.
#[test]
fn fluid_tank_car_steps_do_not_allocate() {
    let p = TankCarParams::standard().expect("car");
    let depth = p.tank_radius;
    let fluid = Oil::Light.fluid(depth, depth / 2.0).expect("fluid");
    let cargo = FluidCargo::new(fluid, [3, 2, 2], 0.5, vec![]);
    let mut sc = TrainScenario::single(p, tangent(), 300.0, 10.0, 1.0);
    sc.hht.refresh_rate = 0.5;
    let (sys, _, _) = build_fluid_train(&sc, &cargo).expect("fluid train");
    let (q0, v0) = sys.initial_coordinates();
    let hht = Hht::new(Counted { inner: sys, counts: Counts::default() }, 0.0, q0, v0, sc.hht).expect("hht");
    let wall_contact = |hht: &Hht<Counted<FluidVehicle>>| {
        let sys = &hht.system().inner;
        let (q, v) = (hht.q(), hht.v());
        let nr = sys.mb.n_coords();
        let mut n = 0;
        for (k, f) in sys.fluids.iter().enumerate() {
            let s = sys.mb.state(Some(f.tank), &q[..nr], &v[..nr]);
            let kin = rail_mbs::vehicle::fluid::tank_kinematics(&s);
            let (e, ed) = (sys.fluid_slice(k, q), sys.fluid_slice(k, v));
            let mut out = vec![0.0; e.len()];
            // Twice: the first call may grow buffers that later calls reuse.
            let _ = f.contact.forces(&f.body, &kin, e, ed, &mut out, None);
            n += counting(|| f.contact.forces(&f.body, &kin, e, ed, &mut out, None)).1;
        }
        n
    };
    let steps = measure(hht, 4e-3, 15, 15, wall_contact);
    report("fluid tank car (3x2x2)", &steps);
    // The residual path (forces, constraints, step check) allocates only inside the wall
    // contact, whatever the step does; the integrator's own work only when it refactorizes.
    for s in &steps {
        let c = s.callbacks;
        assert_eq!(c.forces + c.constraints + c.check_step, s.wall_contact, "residual evaluations allocated: {s:?}");
        if s.factorizations == 0 {
            assert_eq!(s.integrator(), 0, "a step without refactorization allocated in the integrator: {s:?}");
        }
    }
    assert!(steps.iter().map(|s| s.residuals).sum::<usize>() >= 20, "too few residual evaluations: {steps:?}");
    for s in reuse_steps(&steps) {
        assert_eq!(s.total, s.wall_contact, "a step that reuses the factorization allocated: {s:?}");
    }
    // and the wall-contact pass itself is allocation-free (ancf-core contact.rs)
    assert!(steps.iter().all(|s| s.wall_contact == 0), "the wall-contact pass allocated: {steps:?}");
}
