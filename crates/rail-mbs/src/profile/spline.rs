//! C² interpolating cubic spline `z(y)` with natural end conditions.

use super::ProfileError;

/// Interpolating cubic spline through `(y_i, z_i)` with natural end conditions
/// (`z'' = 0` at both ends), so it is C² everywhere inside the knot range. Outside the
/// knots it continues as the straight line tangent at the end knot (C¹).
#[derive(Debug, Clone, PartialEq)]
pub struct CubicSpline {
    y: Vec<f64>,
    z: Vec<f64>,
    /// Second derivatives at the knots.
    m: Vec<f64>,
    /// `1/h` when the knots are uniformly spaced (to 1e-9 relative): the interval of a
    /// point is then found in O(1) instead of by bisection.
    inv_uniform_step: Option<f64>,
}

impl CubicSpline {
    /// Builds the spline. `y` must be strictly increasing, finite and at least 3 points
    /// long (2 points give a straight line).
    pub fn new(y: &[f64], z: &[f64]) -> Result<Self, ProfileError> {
        let n = y.len();
        if n != z.len() {
            return Err(ProfileError::Invalid(format!("spline: {} abscissae but {} ordinates", n, z.len())));
        }
        if n < 2 {
            return Err(ProfileError::TooFewPoints(n));
        }
        for i in 0..n {
            if !y[i].is_finite() || !z[i].is_finite() {
                return Err(ProfileError::Invalid(format!("spline: non-finite point {i}")));
            }
            if i > 0 && y[i] <= y[i - 1] {
                return Err(ProfileError::NotIncreasing { index: i, y: y[i] });
            }
        }
        // Tridiagonal system for the interior second derivatives (Thomas algorithm).
        let mut m = vec![0.0; n];
        if n > 2 {
            let k = n - 2;
            let mut diag = vec![0.0; k];
            let mut rhs = vec![0.0; k];
            let mut upper = vec![0.0; k];
            for j in 0..k {
                let i = j + 1;
                let h0 = y[i] - y[i - 1];
                let h1 = y[i + 1] - y[i];
                diag[j] = 2.0 * (h0 + h1);
                upper[j] = h1;
                rhs[j] = 6.0 * ((z[i + 1] - z[i]) / h1 - (z[i] - z[i - 1]) / h0);
            }
            // lower[j] = h0 of row j = y[j+1]-y[j]
            for j in 1..k {
                let lower = y[j + 1] - y[j];
                let w = lower / diag[j - 1];
                diag[j] -= w * upper[j - 1];
                rhs[j] -= w * rhs[j - 1];
            }
            let mut sol = vec![0.0; k];
            sol[k - 1] = rhs[k - 1] / diag[k - 1];
            for j in (0..k - 1).rev() {
                sol[j] = (rhs[j] - upper[j] * sol[j + 1]) / diag[j];
            }
            m[1..(k + 1)].copy_from_slice(&sol);
        }
        let h = (y[n - 1] - y[0]) / (n - 1) as f64;
        let uniform = y.iter().enumerate().all(|(i, v)| (v - (y[0] + h * i as f64)).abs() <= 1e-9 * h);
        Ok(Self { y: y.to_vec(), z: z.to_vec(), m, inv_uniform_step: uniform.then_some(1.0 / h) })
    }

    /// Knot abscissae.
    pub fn knots(&self) -> &[f64] {
        &self.y
    }
    /// Knot ordinates.
    pub fn values(&self) -> &[f64] {
        &self.z
    }
    /// First and last knot.
    pub fn range(&self) -> (f64, f64) {
        (self.y[0], self.y[self.y.len() - 1])
    }

    /// Value, first and second derivative at `y`.
    pub fn eval(&self, y: f64) -> (f64, f64, f64) {
        let n = self.y.len();
        let (y0, yn) = (self.y[0], self.y[n - 1]);
        if y < y0 {
            let (z, d, _) = self.eval_in(0, y0);
            return (z + d * (y - y0), d, 0.0);
        }
        if y > yn {
            let (z, d, _) = self.eval_in(n - 2, yn);
            return (z + d * (y - yn), d, 0.0);
        }
        let i = match self.inv_uniform_step {
            Some(inv) => {
                // Guess from the uniform spacing, then correct for rounding at a knot.
                let mut i = (((y - y0) * inv) as usize).min(n - 2);
                if y < self.y[i] && i > 0 {
                    i -= 1;
                } else if y >= self.y[i + 1] && i + 2 < n {
                    i += 1;
                }
                i
            }
            None => (self.y.partition_point(|&v| v <= y).max(1) - 1).min(n - 2),
        };
        self.eval_in(i, y)
    }

    fn eval_in(&self, i: usize, y: f64) -> (f64, f64, f64) {
        let h = self.y[i + 1] - self.y[i];
        let a = (self.y[i + 1] - y) / h;
        let b = (y - self.y[i]) / h;
        let (m0, m1) = (self.m[i], self.m[i + 1]);
        let (z0, z1) = (self.z[i], self.z[i + 1]);
        let z = a * z0 + b * z1 + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0;
        let d = (z1 - z0) / h - (3.0 * a * a - 1.0) / 6.0 * h * m0 + (3.0 * b * b - 1.0) / 6.0 * h * m1;
        let dd = a * m0 + b * m1;
        (z, d, dd)
    }

    /// Value at `y`.
    pub fn value(&self, y: f64) -> f64 {
        self.eval(y).0
    }
    /// First derivative at `y`.
    pub fn derivative(&self, y: f64) -> f64 {
        self.eval(y).1
    }
    /// Second derivative at `y`.
    pub fn second_derivative(&self, y: f64) -> f64 {
        self.eval(y).2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_knot_lookup_equals_bisection() {
        let y: Vec<f64> = (0..200).map(|i| -0.07 + 6.5e-4 * i as f64).collect();
        let z: Vec<f64> = y.iter().map(|v| (40.0 * v).sin() * 1e-2 + v * v).collect();
        let uni = CubicSpline::new(&y, &z).unwrap();
        assert!(uni.inv_uniform_step.is_some());
        let mut slow = uni.clone();
        slow.inv_uniform_step = None;
        for k in 0..5000 {
            let v = -0.075 + 0.14 * k as f64 / 4999.0;
            assert_eq!(uni.eval(v), slow.eval(v), "at {v}");
        }
        for &v in &y {
            assert_eq!(uni.eval(v), slow.eval(v), "at knot {v}");
        }
        let mut ny = y.clone();
        ny[5] += 1e-5;
        assert!(CubicSpline::new(&ny, &z).unwrap().inv_uniform_step.is_none());
    }
}
