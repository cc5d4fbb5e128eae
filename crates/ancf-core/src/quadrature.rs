//! Gauss–Legendre quadrature on [-1, 1] and tensor-product rules on the reference cube.

use crate::error::{Result, invalid};

/// Largest number of Gauss points per direction supported.
pub const MAX_GAUSS_POINTS: usize = 8;

/// (P_n(z), P_{n−1}(z)) by the three-term recurrence (n ≥ 1).
fn legendre(n: usize, z: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, z);
    for k in 2..=n {
        let kf = k as f64;
        let p2 = ((2.0 * kf - 1.0) * z * p1 - (kf - 1.0) * p0) / kf;
        p0 = p1;
        p1 = p2;
    }
    (p1, p0)
}

/// Nodes and weights of the `n`-point Gauss–Legendre rule on [-1, 1],
/// computed by Newton iteration on the Legendre polynomial (exact to round-off).
pub fn gauss_legendre(n: usize) -> Result<(Vec<f64>, Vec<f64>)> {
    if n == 0 || n > MAX_GAUSS_POINTS {
        return Err(invalid("quadrature points per direction", n, &format!("an integer in [1, {MAX_GAUSS_POINTS}]")));
    }
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    let nf = n as f64;
    for i in 0..n.div_ceil(2) {
        // Chebyshev-like initial guess, refined by Newton.
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (pn, pn1) = legendre(n, z);
            dp = nf * (z * pn - pn1) / (z * z - 1.0);
            let dz = pn / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        if n == 1 {
            z = 0.0;
            dp = 1.0;
        }
        x[i] = -z;
        x[n - 1 - i] = z;
        let wi = 2.0 / ((1.0 - z * z) * dp * dp);
        w[i] = wi;
        w[n - 1 - i] = wi;
    }
    if n == 1 {
        w[0] = 2.0;
    }
    Ok((x, w))
}

/// Nodes and weights of the `n`-point Gauss–Lobatto rule on [-1, 1] (n ≥ 2): the end
/// points ±1 and the roots of P'_{n−1}, weights 2/(n(n−1) P_{n−1}(x)²); exact for
/// polynomials of degree 2n − 3. Interior nodes by Newton iteration on P'_{n−1}.
pub fn gauss_lobatto(n: usize) -> Result<(Vec<f64>, Vec<f64>)> {
    if !(2..=MAX_GAUSS_POINTS).contains(&n) {
        return Err(invalid(
            "Gauss-Lobatto points per direction",
            n,
            &format!("an integer in [2, {MAX_GAUSS_POINTS}]"),
        ));
    }
    let m = n - 1; // degree of the Legendre polynomial
    let mf = m as f64;
    let legendre = |z: f64| legendre(m, z);
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        let mut z = -(std::f64::consts::PI * i as f64 / mf).cos();
        if i > 0 {
            for _ in 0..100 {
                let (pm, pm1) = legendre(z);
                let d1 = mf * (z * pm - pm1) / (z * z - 1.0); // P'_m
                let d2 = (2.0 * z * d1 - mf * (mf + 1.0) * pm) / (1.0 - z * z); // P''_m
                let dz = d1 / d2;
                z -= dz;
                if dz.abs() < 1e-16 {
                    break;
                }
            }
        }
        if 2 * i + 1 == n {
            z = 0.0;
        }
        let (pm, _) = legendre(z);
        let wi = 2.0 / (mf * (mf + 1.0) * pm * pm);
        x[i] = z;
        x[n - 1 - i] = -z;
        w[i] = wi;
        w[n - 1 - i] = wi;
    }
    Ok((x, w))
}

/// Tensor-product Gauss rule on the reference cube [-1, 1]^3.
#[derive(Debug, Clone, PartialEq)]
pub struct CubeRule {
    /// Points per direction.
    pub n: usize,
    /// Point coordinates (ξ, η, ζ).
    pub points: Vec<[f64; 3]>,
    /// Weights (sum to 8).
    pub weights: Vec<f64>,
}

impl CubeRule {
    /// The `n × n × n` Gauss–Legendre rule.
    pub fn gauss(n: usize) -> Result<Self> {
        let (x, w) = gauss_legendre(n)?;
        Ok(Self::tensor(n, &x, &w))
    }

    /// The `n × n × n` Gauss–Lobatto rule (its points include the cube's corners).
    pub fn lobatto(n: usize) -> Result<Self> {
        let (x, w) = gauss_lobatto(n)?;
        Ok(Self::tensor(n, &x, &w))
    }

    fn tensor(n: usize, x: &[f64], w: &[f64]) -> Self {
        let mut points = Vec::with_capacity(n * n * n);
        let mut weights = Vec::with_capacity(n * n * n);
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    points.push([x[i], x[j], x[k]]);
                    weights.push(w[i] * w[j] * w[k]);
                }
            }
        }
        Self { n, points, weights }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True when the rule has no points (never for a valid rule).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_rules_integrate_polynomials_exactly() {
        for n in 1..=MAX_GAUSS_POINTS {
            let (x, w) = gauss_legendre(n).unwrap();
            for deg in 0..(2 * n) {
                let exact = if deg % 2 == 1 { 0.0 } else { 2.0 / (deg as f64 + 1.0) };
                let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg as i32)).sum();
                assert!((q - exact).abs() < 1e-14, "n={n} deg={deg}: {q} vs {exact}");
            }
            // degree 2n is NOT exact (proves the rule is not over-reported)
            let deg = 2 * n;
            let exact = 2.0 / (deg as f64 + 1.0);
            let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg as i32)).sum();
            assert!((q - exact).abs() > 1e-6);
        }
    }

    #[test]
    fn lobatto_rules_hold_the_end_points_and_integrate_degree_2n_minus_3() {
        // textbook values (Abramowitz & Stegun 25.4.32): n = 4: ±1/√5 with weight 5/6
        let (x, w) = gauss_lobatto(4).unwrap();
        assert!((x[1] + 1.0 / 5f64.sqrt()).abs() < 1e-15 && (w[1] - 5.0 / 6.0).abs() < 1e-15, "{x:?} {w:?}");
        for n in 2..=MAX_GAUSS_POINTS {
            let (x, w) = gauss_lobatto(n).unwrap();
            assert_eq!((x[0], x[n - 1]), (-1.0, 1.0), "n={n}");
            assert!(x.windows(2).all(|p| p[0] < p[1]), "n={n}: {x:?}");
            for deg in 0..=(2 * n - 3) {
                let exact = if deg % 2 == 1 { 0.0 } else { 2.0 / (deg as f64 + 1.0) };
                let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg as i32)).sum();
                assert!((q - exact).abs() < 1e-14, "n={n} deg={deg}: {q} vs {exact}");
            }
            let deg = 2 * n - 2;
            let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg as i32)).sum();
            assert!((q - 2.0 / (deg as f64 + 1.0)).abs() > 1e-6, "n={n}: degree {deg} must not be exact");
        }
        assert!(gauss_lobatto(1).is_err() && gauss_lobatto(MAX_GAUSS_POINTS + 1).is_err());
    }

    #[test]
    fn invalid_point_count_is_rejected() {
        assert!(gauss_legendre(0).is_err());
        assert!(gauss_legendre(MAX_GAUSS_POINTS + 1).is_err());
    }

    #[test]
    fn cube_rule_weights_sum_to_volume() {
        let r = CubeRule::gauss(3).unwrap();
        assert_eq!(r.len(), 27);
        assert!((r.weights.iter().sum::<f64>() - 8.0).abs() < 1e-13);
    }
}
