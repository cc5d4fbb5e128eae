//! The load filter of vehicle records (issue 16 §3): how the load channels are sampled at the
//! recording times ([`LoadFilter`]), the hat-weighted mean the runs accumulate step by step
//! ([`HatMean`], kept in run checkpoints), and the same mean resampling a finished series
//! ([`hat_mean_resample`]).

use ancf_core::error::{AncfError, invalid};

/// How the load channels of a vehicle record (wheel loads `Q` and `Y`, coupler forces and,
/// in fluid runs, the fluid force on each tank) are sampled at the recording times.
///
/// The integrator steps several times per recording interval; loads carry content (wheel/rail
/// and wall-contact ringing, 20-30 Hz in the ECP study) above the Nyquist frequency of the
/// record, which point samples alias into spurious low-frequency noise (issue 16 §3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LoadFilter {
    /// The value at the recording time (aliases content above 1/(2 `record_every`)).
    Sample,
    /// Default. The mean over the accepted steps weighted by the hat function of the sample,
    /// w_k(t) = 1 − |t − t_k|/Δ on [t_{k−1}, t_{k+1}] (integrated exactly for loads linear
    /// over each step): a zero-phase triangular low-pass of frequency response
    /// sinc²(fΔ) for Δ = `record_every`: −3 dB at 0.32/Δ (16 Hz at Δ = 0.02 s), −7.8 dB at
    /// the Nyquist frequency 0.5/Δ, zeros at multiples of 1/Δ, side lobes below −26 dB.
    /// The hats form a partition of unity, so means and impulses (∫F dt) are preserved.
    /// Kinematic channels (positions, speeds, centre of mass) stay point samples.
    #[default]
    HatMean,
}

impl LoadFilter {
    /// Name used in results metadata (`"hat_mean"` or `"sample"`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Sample => "sample",
            Self::HatMean => "hat_mean",
        }
    }

    /// Parses [`LoadFilter::name`].
    pub fn parse(name: &str) -> Result<Self, AncfError> {
        match name {
            "sample" => Ok(Self::Sample),
            "hat_mean" => Ok(Self::HatMean),
            other => Err(invalid("load_filter", other, "\"hat_mean\" or \"sample\"")),
        }
    }
}

/// Accumulates the hat-weighted means of [`LoadFilter::HatMean`] over the accepted steps:
/// every step lies between two recording times t_{k−1} ≤ t_a < t_b ≤ t_k, where only the
/// hats of samples k − 1 (falling) and k (rising) are non-zero.
#[derive(Debug, Default)]
pub(crate) struct HatMean {
    /// (t, loads) at the end of the last accepted step.
    last: Option<(f64, Vec<f64>)>,
    /// ∫ f w dt and ∫ w dt of samples k − 1 and k.
    num: [Vec<f64>; 2],
    den: [f64; 2],
}

impl HatMean {
    /// Starts at the first recording time with the loads there.
    pub(crate) fn start(&mut self, t: f64, f: Vec<f64>) {
        self.num = [vec![0.0; f.len()], vec![0.0; f.len()]];
        self.den = [0.0; 2];
        self.last = Some((t, f));
    }

    /// Adds the step from the last state to `(t, f)`, inside [t0, t1] = [t_{k−1}, t_k].
    pub(crate) fn step(&mut self, t0: f64, t1: f64, t: f64, f: Vec<f64>) {
        let Some((ta, fa)) = self.last.take() else { return };
        let width = t1 - t0;
        if width > 0.0 && t > ta {
            // weights of sample k (rising) at both ends; sample k − 1 has 1 − w
            let (wa, wb) = (((ta - t0) / width).clamp(0.0, 1.0), ((t - t0) / width).clamp(0.0, 1.0));
            let h6 = (t - ta) / 6.0;
            for (j, (ua, ub)) in [(1.0 - wa, 1.0 - wb), (wa, wb)].into_iter().enumerate() {
                // exact ∫ f w for f, w linear over the step
                for ((n, &x), &y) in self.num[j].iter_mut().zip(&fa).zip(&f) {
                    *n += h6 * (2.0 * x * ua + x * ub + y * ua + 2.0 * y * ub);
                }
                self.den[j] += h6 * 3.0 * (ua + ub);
            }
        }
        self.last = Some((t, f));
    }

    /// The mean of slot `j` (0: sample k − 1, 1: sample k), `None` before any step.
    pub(crate) fn mean(&self, j: usize) -> Option<Vec<f64>> {
        (self.den[j] > 0.0).then(|| self.num[j].iter().map(|n| n / self.den[j]).collect())
    }

    /// Moves on to the next interval: sample k becomes k − 1.
    pub(crate) fn shift(&mut self) {
        self.num.swap(0, 1);
        self.num[1].iter_mut().for_each(|x| *x = 0.0);
        self.den = [self.den[1], 0.0];
    }

    /// The partial integrals as a flat vector (a run checkpoint, [`Self::restore`]).
    pub(crate) fn save(&self) -> Vec<f64> {
        let (has_last, t, f) = self.last.as_ref().map_or((0.0, 0.0, &[][..]), |(t, f)| (1.0, *t, &f[..]));
        let mut out = vec![has_last, t, f.len() as f64];
        out.extend_from_slice(f);
        out.push(self.num[0].len() as f64);
        out.extend(self.num[0].iter().chain(&self.num[1]));
        out.extend(self.den);
        out
    }

    /// The filter [`Self::save`] wrote; `None` when `data` is malformed.
    pub(crate) fn restore(data: &[f64]) -> Option<Self> {
        let count = |x: f64| (x >= 0.0 && x.fract() == 0.0).then_some(x as usize);
        let (&has_last, &t, n) = (data.first()?, data.get(1)?, count(*data.get(2)?)?);
        let f = data.get(3..3 + n)?.to_vec();
        let m = count(*data.get(3 + n)?)?;
        let rest = data.get(4 + n..)?;
        if rest.len() != 2 * m + 2 {
            return None;
        }
        Some(Self {
            last: (has_last == 1.0).then_some((t, f)),
            num: [rest[..m].to_vec(), rest[m..2 * m].to_vec()],
            den: [rest[2 * m], rest[2 * m + 1]],
        })
    }
}

/// Resamples a series recorded at arbitrary increasing times `t` (channels `f[i]` at `t[i]`,
/// linear in between) onto the grid 0, Δ, 2Δ, … (up to the last time) by the hat-weighted mean
/// of [`LoadFilter::HatMean`], the filter vehicle runs record their loads with: the sweep puts
/// the adaptive steps of slosh runs on a common grid this way. Grid times are inserted into the
/// series by linear interpolation, so the integral is exact for the piecewise-linear series.
pub fn hat_mean_resample(t: &[f64], f: &[Vec<f64>], dt: f64) -> Result<Vec<Vec<f64>>, AncfError> {
    if t.len() != f.len() || t.is_empty() {
        return Err(invalid("t", t.len(), &format!("as many times as samples ({}), at least one", f.len())));
    }
    if !(dt.is_finite() && dt > 0.0) {
        return Err(invalid("dt", dt, "a finite interval > 0"));
    }
    if let Some(i) = t.windows(2).position(|w| w[1] <= w[0] || w[1].is_nan()) {
        return Err(invalid(&format!("t[{}]", i + 1), t[i + 1], "increasing times"));
    }
    let n_rec = ((t[t.len() - 1] - t[0]) / dt + 1e-9).floor() as usize;
    let at = |x: f64, i: usize| -> Vec<f64> {
        // linear interpolation on [t[i], t[i + 1]]
        let w = (x - t[i]) / (t[i + 1] - t[i]);
        f[i].iter().zip(&f[i + 1]).map(|(a, b)| a + w * (b - a)).collect()
    };
    let mut hat = HatMean::default();
    hat.start(t[0], f[0].clone());
    let mut out: Vec<Vec<f64>> = Vec::with_capacity(n_rec + 1);
    let mut i = 0;
    for k in 1..=n_rec + 1 {
        let (t0, t1) = (t[0] + (k - 1) as f64 * dt, t[0] + k as f64 * dt);
        // the samples inside (t0, t1], then the grid time t1 itself (interpolated)
        while i + 1 < t.len() && t[i + 1] < t1 {
            i += 1;
            hat.step(t0, t1, t[i], f[i].clone());
        }
        if i + 1 < t.len() {
            hat.step(t0, t1, t1, at(t1, i));
        }
        // sample k − 1 is final: its window [t_{k−2}, t_k] is integrated
        out.push(hat.mean(0).unwrap_or_else(|| f[0].clone()));
        hat.shift();
    }
    Ok(out)
}
