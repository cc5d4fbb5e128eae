//! Timing of the sparse HHT-α integrator on a nonlinear mass–spring chain.
//!
//! Plain `harness = false` benchmark (no extra dependencies): run with
//! `cargo bench -p rail-mbs --bench integrator_chain`. Prints, per chain size and
//! Jacobian policy, the time per step and the assembly / factorization / solve split.

use rail_mbs::integrator::{Hht, HhtParams, JacobianPolicy, MechanicalSystem, SparsityPattern, SystemError};
use std::hint::black_box;
use std::time::Instant;

/// Chain of unit masses, springs `k δ + k3 δ³` and dampers; both ends pinned by
/// constraints.
struct Chain {
    n: usize,
    k: f64,
    k3: f64,
    c: f64,
}

impl MechanicalSystem for Chain {
    fn n_coords(&self) -> usize {
        self.n
    }
    fn n_constraints(&self) -> usize {
        2
    }
    fn pattern(&self) -> SparsityPattern {
        let mut dynamics: Vec<(usize, usize)> = (0..self.n).map(|i| (i, i)).collect();
        for i in 0..self.n - 1 {
            dynamics.push((i, i + 1));
            dynamics.push((i + 1, i));
        }
        SparsityPattern { dynamics, constraints: vec![(0, 0), (1, self.n - 1)] }
    }
    fn mass_is_constant(&self) -> bool {
        true
    }
    fn mass(&mut self, _q: &[f64], values: &mut [f64]) -> Result<(), SystemError> {
        values[..self.n].fill(1.0);
        Ok(())
    }
    fn forces(&mut self, _t: f64, q: &[f64], v: &[f64], out: &mut [f64]) -> Result<(), SystemError> {
        for i in 0..self.n - 1 {
            let d = q[i + 1] - q[i];
            let f = self.k * d + self.k3 * d.powi(3) + self.c * (v[i + 1] - v[i]);
            out[i] += f;
            out[i + 1] -= f;
        }
        Ok(())
    }
    fn force_jacobians(
        &mut self,
        _t: f64,
        q: &[f64],
        _v: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
    ) -> Result<(), SystemError> {
        let n = self.n;
        for i in 0..n - 1 {
            let d = q[i + 1] - q[i];
            let ks = self.k + 3.0 * self.k3 * d * d;
            for (vals, s) in [(&mut *dq, ks), (&mut *dv, self.c)] {
                vals[i] -= s;
                vals[i + 1] -= s;
                vals[n + 2 * i] += s;
                vals[n + 2 * i + 1] += s;
            }
        }
        Ok(())
    }
    fn constraints(&mut self, _t: f64, q: &[f64], out: &mut [f64]) -> Result<(), SystemError> {
        out[0] = q[0];
        out[1] = q[self.n - 1];
        Ok(())
    }
    fn constraint_jacobian(&mut self, _t: f64, _q: &[f64], values: &mut [f64]) -> Result<(), SystemError> {
        values.fill(1.0);
        Ok(())
    }
}

fn main() {
    faer::set_global_parallelism(faer::Par::Seq);
    let steps = 200;
    let h = 1e-3;
    for n in [2_000, 20_000] {
        for policy in [JacobianPolicy::EveryIteration, JacobianPolicy::EveryStep, JacobianPolicy::Automatic] {
            let sys = Chain { n, k: 1e4, k3: 1e9, c: 1.0 };
            let q0: Vec<f64> = (0..n)
                .map(|i| {
                    if i == 0 || i == n - 1 { 0.0 } else { 0.01 * (-((i as f64 - n as f64 / 5.0) / 5.0).powi(2)).exp() }
                })
                .collect();
            let params = HhtParams { alpha: -0.1, jacobian: policy, ..HhtParams::default() };
            let tic = Instant::now();
            let mut hht = Hht::new(sys, 0.0, q0, vec![0.0; n], params).expect("init");
            hht.integrate_to(steps as f64 * h, h).expect("integration");
            let wall = tic.elapsed();
            black_box(hht.q());
            let s = hht.stats();
            println!(
                "n = {n:6} {policy:?}: {:8.1} µs/step | iters {} factorizations {} jac evals {} | \
                 assembly {:?} factorization {:?} solve {:?} (wall {:?})",
                wall.as_secs_f64() * 1e6 / steps as f64,
                s.newton_iterations,
                s.factorizations,
                s.jacobian_evaluations,
                s.time_assembly,
                s.time_factorization,
                s.time_solve,
                wall
            );
        }
    }
}
