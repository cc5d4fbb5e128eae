//! Analysis of recorded slosh signals: the dominant frequency of a load or centre-of-mass
//! history. Used by the validation cases and the work–precision sweeps (crate
//! `railslosh-cases`), the explicit-stepper tests and the `explicit_bench` example; it moved
//! here from the slosh validation module when the cases left the library (issue 18).

/// Dominant frequency of `x(t)` for t ≥ t0 in [f_lo, f_hi] Hz: the signal is resampled
/// uniformly, detrended, Hann-windowed, and the peak of its Fourier amplitude is located on
/// a fine frequency grid (parabolic refinement). Robust to high-frequency contact chatter.
pub fn dominant_frequency(t: &[f64], x: &[f64], t0: f64, f_lo: f64, f_hi: f64) -> f64 {
    let i0 = t.iter().position(|&ti| ti >= t0).unwrap_or(t.len());
    if t.len() < i0 + 8 {
        return f64::NAN;
    }
    let (ta, tb) = (t[i0], t[t.len() - 1]);
    let n = 2048;
    let dt = (tb - ta) / (n - 1) as f64;
    let mut y = Vec::with_capacity(n);
    let mut j = i0;
    for k in 0..n {
        let tk = ta + k as f64 * dt;
        while j + 1 < t.len() - 1 && t[j + 1] < tk {
            j += 1;
        }
        let s = ((tk - t[j]) / (t[j + 1] - t[j])).clamp(0.0, 1.0);
        y.push(x[j] + s * (x[j + 1] - x[j]));
    }
    let mean = y.iter().sum::<f64>() / n as f64;
    for (k, v) in y.iter_mut().enumerate() {
        let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * k as f64 / (n - 1) as f64).cos();
        *v = (*v - mean) * w;
    }
    let amp = |f: f64| {
        let (mut re, mut im) = (0.0, 0.0);
        for (k, v) in y.iter().enumerate() {
            let ph = 2.0 * std::f64::consts::PI * f * k as f64 * dt;
            re += v * ph.cos();
            im += v * ph.sin();
        }
        (re * re + im * im).sqrt()
    };
    let m = 600;
    let grid: Vec<f64> = (0..=m).map(|i| f_lo + (f_hi - f_lo) * i as f64 / m as f64).collect();
    let a: Vec<f64> = grid.iter().map(|&f| amp(f)).collect();
    let ib = (1..m).max_by(|&p, &q| a[p].total_cmp(&a[q])).unwrap_or(1);
    let (y0, y1, y2) = (a[ib - 1], a[ib], a[ib + 1]);
    let den = y0 - 2.0 * y1 + y2;
    let off = if den != 0.0 { 0.5 * (y0 - y2) / den } else { 0.0 };
    grid[ib] + off * (f_hi - f_lo) / m as f64
}
