//! Checkpoint and restart of [`Hht`] with bitwise-identical continuation.
//!
//! A [`Checkpoint`] holds everything that determines the following steps: the state
//! `(t, q, v, a, λ)`, the previous step's `a`, `λ` and `h` (for the extrapolating
//! predictor), the step-size controller (`h_current`, count of easy steps),
//! the Jacobian-reuse state (whether stored Jacobians are valid, their values, and the
//! step size of the current factorization) and the statistics. Restoring re-assembles
//! the KKT matrix from the stored Jacobian values with the same coefficients and
//! refactorizes it, so the resumed run reuses exactly the matrix the uninterrupted run
//! reuses, and continues bit for bit. Taking a checkpoint does not change the run.
//!
//! The byte format ([`Checkpoint::to_bytes`]) is little-endian: the magic
//! `RSLHHTCK`, a format version (u32), then the fields in declaration order; `f64` as
//! [`f64::to_le_bytes`] (exact), lengths and counters as u64, durations as u64
//! nanoseconds, flags as one byte. The model itself (mesh, fluid, motion …) is not in
//! the checkpoint: the caller rebuilds the same system and passes it to
//! [`Hht::restore`]; `n`, `m` and the pattern sizes are checked.

use std::time::{Duration, Instant};

use super::{Hht, IntegratorError, MechanicalSystem, Stats, linear_error};
use crate::integrator::params::HhtParams;

const MAGIC: &[u8; 8] = b"RSLHHTCK";
const VERSION: u32 = 2;

/// Complete integrator state at an accepted step (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Checkpoint {
    /// Time, s.
    pub t: f64,
    /// Positions.
    pub q: Vec<f64>,
    /// Velocities.
    pub v: Vec<f64>,
    /// Accelerations.
    pub a: Vec<f64>,
    /// Lagrange multipliers.
    pub lambda: Vec<f64>,
    /// Accelerations at the previous accepted step (for [`Predictor::Extrapolate`](crate::integrator::Predictor::Extrapolate)).
    pub a_prev: Vec<f64>,
    /// Lagrange multipliers at the previous accepted step.
    pub lambda_prev: Vec<f64>,
    /// Length of the last accepted step, s (0: none; the predictor then holds).
    pub h_prev: f64,
    /// Step-size controller: current step (adaptive mode; +inf before the first step).
    pub h_current: f64,
    /// Step-size controller: consecutive easy steps.
    pub easy_count: usize,
    /// Whether the stored Jacobians are valid (reusable).
    pub jac_valid: bool,
    /// Step size of the current factorization (`None`: none usable).
    pub factor_h: Option<f64>,
    /// Stored mass-matrix values used in the Newton matrix.
    pub mass_jac: Vec<f64>,
    /// Stored `∂Q/∂q` values.
    pub dq: Vec<f64>,
    /// Stored `∂Q/∂v` values.
    pub dv: Vec<f64>,
    /// Stored `C_q` values of the Newton matrix.
    pub cq: Vec<f64>,
    /// Statistics at the checkpoint.
    pub stats: Stats,
}

pub(crate) struct Writer(pub(crate) Vec<u8>);

impl Writer {
    /// The magic of a format and its version (read back by [`Reader::header`]).
    pub(crate) fn header(&mut self, magic: &[u8; 8], version: u32) {
        self.0.extend_from_slice(magic);
        self.0.extend_from_slice(&version.to_le_bytes());
    }
    /// Bytes of a nested format, length first (read back by [`Reader::bytes`]).
    pub(crate) fn bytes(&mut self, x: &[u8]) {
        self.u64(x.len() as u64);
        self.0.extend_from_slice(x);
    }
    pub(crate) fn u64(&mut self, x: u64) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    pub(crate) fn f64(&mut self, x: f64) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    pub(crate) fn vec(&mut self, x: &[f64]) {
        self.u64(x.len() as u64);
        for &v in x {
            self.f64(v);
        }
    }
    pub(crate) fn dur(&mut self, d: Duration) {
        self.u64(u64::try_from(d.as_nanos()).unwrap_or(u64::MAX));
    }
    /// The counters, then the durations, in [`Stats`] declaration order.
    pub(crate) fn stats(&mut self, s: &Stats) {
        for c in [
            s.steps,
            s.rejected_steps,
            s.newton_iterations,
            s.factorizations,
            s.jacobian_evaluations,
            s.residual_evaluations,
            s.linear_solves,
        ] {
            self.u64(c as u64);
        }
        for d in [s.time_assembly, s.time_factorization, s.time_solve, s.time_total] {
            self.dur(d);
        }
    }
}

pub(crate) struct Reader<'a> {
    pub(crate) bytes: &'a [u8],
    pub(crate) pos: usize,
}

pub(crate) fn bad(what: impl Into<String>) -> IntegratorError {
    IntegratorError::Checkpoint { what: what.into() }
}

impl Reader<'_> {
    pub(crate) fn take(&mut self, k: usize, field: &str) -> Result<&[u8], IntegratorError> {
        let end = self.pos.checked_add(k).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            return Err(bad(format!("truncated at byte {} while reading `{field}`", self.pos)));
        };
        let s = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(s)
    }
    /// Checks the magic at the start of the bytes (`what`: the kind of checkpoint, in the
    /// error) and returns the format version that follows it.
    pub(crate) fn header(&mut self, magic: &[u8; 8], what: &str) -> Result<u32, IntegratorError> {
        if self.take(8, "magic")? != magic {
            return Err(bad(format!("not a railslosh {what} checkpoint (bad magic)")));
        }
        Ok(u32::from_le_bytes(self.take(4, "version")?.try_into().expect("4 bytes")))
    }
    /// [`Self::header`] of a format that reads only `version`.
    pub(crate) fn versioned(&mut self, magic: &[u8; 8], what: &str, version: u32) -> Result<(), IntegratorError> {
        match self.header(magic, what)? {
            v if v == version => Ok(()),
            v => Err(bad(format!("{what} checkpoint format version {v}, this build reads {version}"))),
        }
    }
    /// Checks that every byte was read.
    pub(crate) fn finish(&self) -> Result<(), IntegratorError> {
        match self.bytes.len() - self.pos {
            0 => Ok(()),
            n => Err(bad(format!("{n} trailing bytes"))),
        }
    }
    /// Bytes written by [`Writer::bytes`].
    pub(crate) fn bytes(&mut self, field: &str) -> Result<&[u8], IntegratorError> {
        let n = self.usize(field)?;
        self.take(n, field)
    }
    pub(crate) fn u64(&mut self, field: &str) -> Result<u64, IntegratorError> {
        let b = self.take(8, field)?;
        Ok(u64::from_le_bytes(b.try_into().expect("8 bytes")))
    }
    pub(crate) fn usize(&mut self, field: &str) -> Result<usize, IntegratorError> {
        let x = self.u64(field)?;
        usize::try_from(x).map_err(|_| bad(format!("`{field}` = {x} does not fit usize")))
    }
    pub(crate) fn f64(&mut self, field: &str) -> Result<f64, IntegratorError> {
        Ok(f64::from_bits(self.u64(field)?))
    }
    pub(crate) fn flag(&mut self, field: &str) -> Result<bool, IntegratorError> {
        match self.take(1, field)?[0] {
            0 => Ok(false),
            1 => Ok(true),
            x => Err(bad(format!("`{field}` flag is {x}, expected 0 or 1"))),
        }
    }
    pub(crate) fn vec(&mut self, field: &str) -> Result<Vec<f64>, IntegratorError> {
        let len = self.usize(field)?;
        if len > (self.bytes.len() - self.pos) / 8 {
            return Err(bad(format!("`{field}` claims {len} values, more than the remaining bytes")));
        }
        (0..len).map(|_| self.f64(field)).collect()
    }
    pub(crate) fn dur(&mut self, field: &str) -> Result<Duration, IntegratorError> {
        Ok(Duration::from_nanos(self.u64(field)?))
    }
    /// [`Writer::stats`] read back.
    pub(crate) fn stats(&mut self) -> Result<Stats, IntegratorError> {
        Ok(Stats {
            steps: self.usize("stats.steps")?,
            rejected_steps: self.usize("stats.rejected_steps")?,
            newton_iterations: self.usize("stats.newton_iterations")?,
            factorizations: self.usize("stats.factorizations")?,
            jacobian_evaluations: self.usize("stats.jacobian_evaluations")?,
            residual_evaluations: self.usize("stats.residual_evaluations")?,
            linear_solves: self.usize("stats.linear_solves")?,
            time_assembly: self.dur("stats.time_assembly")?,
            time_factorization: self.dur("stats.time_factorization")?,
            time_solve: self.dur("stats.time_solve")?,
            time_total: self.dur("stats.time_total")?,
        })
    }
}

impl Checkpoint {
    /// Serializes to bytes (format in the module docs). `f64` values are exact.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer(Vec::with_capacity(64 + 8 * (4 * self.q.len() + 4 * self.dq.len())));
        w.header(MAGIC, VERSION);
        w.f64(self.t);
        for x in [&self.q, &self.v, &self.a, &self.lambda] {
            w.vec(x);
        }
        w.vec(&self.a_prev);
        w.vec(&self.lambda_prev);
        w.f64(self.h_prev);
        w.f64(self.h_current);
        w.u64(self.easy_count as u64);
        w.0.push(u8::from(self.jac_valid));
        w.0.push(u8::from(self.factor_h.is_some()));
        w.f64(self.factor_h.unwrap_or(0.0));
        for x in [&self.mass_jac, &self.dq, &self.dv, &self.cq] {
            w.vec(x);
        }
        w.stats(&self.stats);
        w.0
    }

    /// Decodes [`to_bytes`](Self::to_bytes) output; any corruption (bad magic or
    /// version, truncation, trailing bytes, inconsistent lengths) is an
    /// [`IntegratorError::Checkpoint`] naming the field.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, IntegratorError> {
        let mut r = Reader { bytes, pos: 0 };
        let version = r.header(MAGIC, "HHT")?;
        if version != VERSION && version != 1 {
            return Err(bad(format!("format version {version}, this build reads 1 and {VERSION}")));
        }
        let t = r.f64("t")?;
        let q = r.vec("q")?;
        let v = r.vec("v")?;
        let a = r.vec("a")?;
        let lambda = r.vec("lambda")?;
        // version 1 had no predictor history: the resumed run holds at its first step
        let (a_prev, lambda_prev, h_prev) = if version >= 2 {
            (r.vec("a_prev")?, r.vec("lambda_prev")?, r.f64("h_prev")?)
        } else {
            (vec![0.0; a.len()], vec![0.0; lambda.len()], 0.0)
        };
        let h_current = r.f64("h_current")?;
        let easy_count = r.usize("easy_count")?;
        let jac_valid = r.flag("jac_valid")?;
        let has_factor = r.flag("factor_h")?;
        let fh = r.f64("factor_h")?;
        let mass_jac = r.vec("mass_jac")?;
        let dq = r.vec("dq")?;
        let dv = r.vec("dv")?;
        let cq = r.vec("cq")?;
        let stats = r.stats()?;
        r.finish()?;
        let n = q.len();
        if v.len() != n || a.len() != n || a_prev.len() != n {
            return Err(bad(format!("q, v, a, a_prev have lengths {n}, {}, {}, {}", v.len(), a.len(), a_prev.len())));
        }
        if lambda_prev.len() != lambda.len() {
            return Err(bad("lambda and lambda_prev have different lengths"));
        }
        if mass_jac.len() != dq.len() || dv.len() != dq.len() {
            return Err(bad("mass_jac, dq, dv have different lengths"));
        }
        Ok(Self {
            t,
            q,
            v,
            a,
            lambda,
            a_prev,
            lambda_prev,
            h_prev,
            h_current,
            easy_count,
            jac_valid,
            factor_h: has_factor.then_some(fh),
            mass_jac,
            dq,
            dv,
            cq,
            stats,
        })
    }
}

impl<S: MechanicalSystem> Hht<S> {
    /// Snapshot of everything that determines the following steps. Taking it does not
    /// change the run.
    pub fn checkpoint(&self) -> Checkpoint {
        Checkpoint {
            t: self.t,
            q: self.q.clone(),
            v: self.v.clone(),
            a: self.a.clone(),
            lambda: self.lambda.clone(),
            a_prev: self.a_prev.clone(),
            lambda_prev: self.lam_prev.clone(),
            h_prev: self.h_prev,
            h_current: self.h_current,
            easy_count: self.easy_count,
            jac_valid: self.jac_valid,
            factor_h: self.factor_h,
            mass_jac: self.mass_jac.clone(),
            dq: self.dq_vals.clone(),
            dv: self.dv_vals.clone(),
            cq: self.cq_jac.clone(),
            stats: self.stats,
        }
    }

    /// Rebuilds an integrator from a checkpoint of the same system (rebuilt by the
    /// caller) and parameters. Stepping on gives results bitwise identical to the run
    /// the checkpoint was taken from (with the same parameters; with other parameters
    /// it is a valid restart, not an identical one). The KKT matrix in use at the
    /// checkpoint is re-assembled and refactorized (not counted in the statistics).
    pub fn restore(system: S, checkpoint: &Checkpoint, params: HhtParams) -> Result<Self, IntegratorError> {
        let start = Instant::now();
        let c = checkpoint;
        let mut hht = Self::build(system, c.t, c.q.clone(), c.v.clone(), params)?;
        let (nd, nc) = (hht.pattern.dynamics.len(), hht.pattern.constraints.len());
        let sizes = [
            ("a", c.a.len(), hht.n),
            ("lambda", c.lambda.len(), hht.m),
            ("a_prev", c.a_prev.len(), hht.n),
            ("lambda_prev", c.lambda_prev.len(), hht.m),
            ("mass_jac", c.mass_jac.len(), nd),
            ("dq", c.dq.len(), nd),
            ("dv", c.dv.len(), nd),
            ("cq", c.cq.len(), nc),
        ];
        if let Some((field, got, want)) = sizes.iter().find(|(_, got, want)| got != want) {
            return Err(bad(format!("`{field}` has length {got}, the system needs {want}")));
        }
        let finite = |x: &[f64]| x.iter().all(|v| v.is_finite());
        if !(finite(&c.a)
            && finite(&c.lambda)
            && finite(&c.a_prev)
            && finite(&c.lambda_prev)
            && finite(&c.mass_jac)
            && finite(&c.dq)
            && finite(&c.dv)
            && finite(&c.cq))
        {
            return Err(bad("non-finite accelerations, multipliers or Jacobian values"));
        }
        if !(c.h_prev.is_finite() && c.h_prev >= 0.0) {
            return Err(bad(format!("previous step h_prev = {}", c.h_prev)));
        }
        if c.h_current.is_nan() || c.h_current <= 0.0 || c.factor_h.is_some_and(|h| !(h.is_finite() && h > 0.0)) {
            return Err(bad(format!("step sizes h_current = {}, factor_h = {:?}", c.h_current, c.factor_h)));
        }
        hht.a.copy_from_slice(&c.a);
        hht.lambda.copy_from_slice(&c.lambda);
        hht.a_prev.copy_from_slice(&c.a_prev);
        hht.lam_prev.copy_from_slice(&c.lambda_prev);
        hht.h_prev = c.h_prev;
        hht.h_current = c.h_current;
        hht.easy_count = c.easy_count;
        hht.mass_jac.copy_from_slice(&c.mass_jac);
        hht.dq_vals.copy_from_slice(&c.dq);
        hht.dv_vals.copy_from_slice(&c.dv);
        hht.cq_jac.copy_from_slice(&c.cq);
        if hht.mass_constant {
            hht.mass_vals.copy_from_slice(&c.mass_jac);
        }
        hht.jac_valid = c.jac_valid;
        hht.factor_h = None;
        if let Some(h) = c.factor_h {
            let coeffs = hht.kkt_coeffs(h);
            hht.kkt.assemble(&hht.mass_jac, &hht.dq_vals, &hht.dv_vals, &hht.cq_jac, coeffs);
            hht.kkt.factorize().map_err(|e| linear_error(e, c.t, h))?;
            hht.factor_h = Some(h);
        }
        hht.stats = c.stats;
        hht.stats.time_total += start.elapsed();
        Ok(hht)
    }
}
