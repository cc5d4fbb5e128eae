//! The 32 shape functions of the 8-node ANCF brick.
//!
//! The element is the incomplete-cubic brick of Olshevskiy, Dmitrochenko & Kim (2014),
//! seed 000 Appendix A, eqs. (A.2)–(A.5), written in the normalized coordinates
//! ξ, η, ζ ∈ [-1, 1] used by Project Chrono's `ChElementHexaANCF_3843`.
//! Seed 000 writes the same functions on [0, 1]; the two are identical after the
//! affine change ξ_seed = (ξ + 1)/2 (both are the unique functions of the 32-term
//! polynomial space (A.2) that interpolate nodal positions and gradients).
//!
//! **Node order.** Bottom face (ζ = −1) counter-clockwise A, B, C, D, then the top
//! face E, F, G, H (see [`NODE_SIGNS`]).
//!
//! **Compact layout.** Each node carries the vectors r, r_x, r_y, r_z. The compact
//! index of shape function `a = 4k + m` is node `k`, vector `m` (0 = position,
//! 1..=3 = gradient along x, y, z). The element coordinate vector has 96 entries,
//! ordered `e[3a + i]` (component `i` of compact column `a`).
//!
//! **Normalized functions.** [`normalized_shape`] returns n_a(ξ) with the slope
//! functions *not* multiplied by the element lengths. The physical shape functions
//! are N_a = s_a n_a with s = 1 for positions and s = L_x, L_y, L_z for the slope
//! functions ([`slope_scale`]). Working with scaled nodal coordinates ê_a = s_a e_a
//! lets every element share one table of n_a and ∂n_a/∂ξ.

/// Number of shape functions (per spatial component).
pub const N_SHAPE: usize = 32;
/// Number of nodal coordinates of one element (3 × 32).
pub const N_COORDS: usize = 96;
/// Nodal coordinates per node: r, r_x, r_y, r_z.
pub const COORDS_PER_NODE: usize = 12;

/// Signs (ξ_k, η_k, ζ_k) of the 8 corner nodes, in element node order A..H.
pub const NODE_SIGNS: [[f64; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// Scale s_a of compact column `a` for an element with straight-configuration
/// edge lengths `l = [L_x, L_y, L_z]`.
#[inline]
pub fn slope_scale(a: usize, l: &[f64; 3]) -> f64 {
    match a % 4 {
        0 => 1.0,
        m => l[m - 1],
    }
}

/// Normalized shape functions n_a(ξ) and their derivatives ∂n_a/∂ξ_j at `xi`.
pub fn normalized_shape(xi: [f64; 3]) -> ([f64; N_SHAPE], [[f64; 3]; N_SHAPE]) {
    let [x, y, z] = xi;
    let mut n = [0.0; N_SHAPE];
    let mut dn = [[0.0; 3]; N_SHAPE];
    for (k, s) in NODE_SIGNS.iter().enumerate() {
        let [sa, sb, sc] = *s;
        let a = 1.0 + sa * x;
        let b = 1.0 + sb * y;
        let c = 1.0 + sc * z;
        let q = 2.0 + sa * x + sb * y + sc * z - x * x - y * y - z * z;
        let i = 4 * k;
        // position function
        n[i] = a * b * c * q / 16.0;
        dn[i] = [
            (sa * b * c * q + a * b * c * (sa - 2.0 * x)) / 16.0,
            (a * sb * c * q + a * b * c * (sb - 2.0 * y)) / 16.0,
            (a * b * sc * q + a * b * c * (sc - 2.0 * z)) / 16.0,
        ];
        // x-slope function
        let px = sa * (x * x - 1.0) / 32.0;
        n[i + 1] = px * a * b * c;
        dn[i + 1] = [sa * (2.0 * x * a + (x * x - 1.0) * sa) * b * c / 32.0, px * a * sb * c, px * a * b * sc];
        // y-slope function
        let py = sb * (y * y - 1.0) / 32.0;
        n[i + 2] = py * a * b * c;
        dn[i + 2] = [py * sa * b * c, sb * (2.0 * y * b + (y * y - 1.0) * sb) * a * c / 32.0, py * a * b * sc];
        // z-slope function
        let pz = sc * (z * z - 1.0) / 32.0;
        n[i + 3] = pz * a * b * c;
        dn[i + 3] = [pz * sa * b * c, pz * a * sb * c, sc * (2.0 * z * c + (z * z - 1.0) * sc) * a * b / 32.0];
    }
    (n, dn)
}

/// Physical shape functions N_a and their straight-configuration derivatives
/// ∂N_a/∂x_j for an element of edge lengths `l`.
pub fn physical_shape(xi: [f64; 3], l: &[f64; 3]) -> ([f64; N_SHAPE], [[f64; 3]; N_SHAPE]) {
    let (mut n, mut dn) = normalized_shape(xi);
    for a in 0..N_SHAPE {
        let s = slope_scale(a, l);
        n[a] *= s;
        for j in 0..3 {
            dn[a][j] *= s * 2.0 / l[j];
        }
    }
    (n, dn)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pseudo_random(seed: &mut u64) -> f64 {
        *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((*seed >> 11) as f64) / ((1u64 << 53) as f64) * 2.0 - 1.0
    }

    #[test]
    fn partition_of_unity_and_derivative_sums() {
        let mut s = 7;
        for _ in 0..50 {
            let xi = [pseudo_random(&mut s), pseudo_random(&mut s), pseudo_random(&mut s)];
            let (n, dn) = normalized_shape(xi);
            let sum: f64 = (0..8).map(|k| n[4 * k]).sum();
            assert!((sum - 1.0).abs() < 1e-14);
            for j in 0..3 {
                let d: f64 = (0..8).map(|k| dn[4 * k][j]).sum();
                assert!(d.abs() < 1e-14);
            }
        }
    }

    #[test]
    fn nodal_interpolation_of_values_and_gradients() {
        let l = [2.0, 0.5, 1.25];
        for (k, s) in NODE_SIGNS.iter().enumerate() {
            let (n, dn) = physical_shape(*s, &l);
            for a in 0..N_SHAPE {
                let node = a / 4;
                let m = a % 4;
                let want_val = if node == k && m == 0 { 1.0 } else { 0.0 };
                assert!((n[a] - want_val).abs() < 1e-14, "value a={a} at node {k}");
                for j in 0..3 {
                    let want = if node == k && m == j + 1 { 1.0 } else { 0.0 };
                    assert!((dn[a][j] - want).abs() < 1e-13, "d/dx{j} of a={a} at node {k}");
                }
            }
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let mut s = 11;
        for _ in 0..20 {
            let xi = [pseudo_random(&mut s), pseudo_random(&mut s), pseudo_random(&mut s)];
            let (_, dn) = normalized_shape(xi);
            let h = 1e-6;
            for j in 0..3 {
                let mut xp = xi;
                let mut xm = xi;
                xp[j] += h;
                xm[j] -= h;
                let (np, _) = normalized_shape(xp);
                let (nm, _) = normalized_shape(xm);
                for a in 0..N_SHAPE {
                    let fd = (np[a] - nm[a]) / (2.0 * h);
                    assert!((fd - dn[a][j]).abs() < 1e-8, "a={a} j={j}");
                }
            }
        }
    }

    /// The 32 monomials of seed 000 eq. (A.2) are reproduced exactly by interpolating
    /// their nodal values and gradients: the shape functions span exactly that space.
    #[test]
    fn reproduces_every_monomial_of_eq_a2() {
        let exps: [[i32; 3]; 32] = [
            [0, 0, 0],
            [1, 0, 0],
            [0, 1, 0],
            [0, 0, 1],
            [2, 0, 0],
            [0, 2, 0],
            [0, 0, 2],
            [1, 1, 0],
            [0, 1, 1],
            [1, 0, 1],
            [3, 0, 0],
            [0, 3, 0],
            [0, 0, 3],
            [2, 1, 0],
            [2, 0, 1],
            [0, 2, 1],
            [1, 2, 0],
            [1, 0, 2],
            [0, 1, 2],
            [1, 1, 1],
            [3, 1, 0],
            [3, 0, 1],
            [1, 3, 0],
            [0, 3, 1],
            [1, 0, 3],
            [0, 1, 3],
            [2, 1, 1],
            [1, 2, 1],
            [1, 1, 2],
            [3, 1, 1],
            [1, 3, 1],
            [1, 1, 3],
        ];
        let l = [1.3, 0.7, 0.9];
        let f = |p: [f64; 3], e: [i32; 3]| p[0].powi(e[0]) * p[1].powi(e[1]) * p[2].powi(e[2]);
        let df = |p: [f64; 3], e: [i32; 3], j: usize| {
            if e[j] == 0 {
                0.0
            } else {
                let mut ee = e;
                ee[j] -= 1;
                e[j] as f64 * f(p, ee)
            }
        };
        let mut s = 3;
        for e in exps {
            // nodal data in physical (straight) coordinates x = (ξ+1) L / 2
            let mut coef = [0.0; N_SHAPE];
            for (k, sg) in NODE_SIGNS.iter().enumerate() {
                let x = [(sg[0] + 1.0) * l[0] / 2.0, (sg[1] + 1.0) * l[1] / 2.0, (sg[2] + 1.0) * l[2] / 2.0];
                coef[4 * k] = f(x, e);
                for j in 0..3 {
                    coef[4 * k + 1 + j] = df(x, e, j);
                }
            }
            for _ in 0..10 {
                let xi = [pseudo_random(&mut s), pseudo_random(&mut s), pseudo_random(&mut s)];
                let x = [(xi[0] + 1.0) * l[0] / 2.0, (xi[1] + 1.0) * l[1] / 2.0, (xi[2] + 1.0) * l[2] / 2.0];
                let (n, _) = physical_shape(xi, &l);
                let interp: f64 = (0..N_SHAPE).map(|a| n[a] * coef[a]).sum();
                assert!((interp - f(x, e)).abs() < 1e-12, "monomial {e:?}");
            }
        }
        // ... and a monomial outside the space (x^2 y^2) is NOT reproduced.
        let e = [2, 2, 0];
        let mut coef = [0.0; N_SHAPE];
        for (k, sg) in NODE_SIGNS.iter().enumerate() {
            let x = [(sg[0] + 1.0) * l[0] / 2.0, (sg[1] + 1.0) * l[1] / 2.0, (sg[2] + 1.0) * l[2] / 2.0];
            coef[4 * k] = f(x, e);
            for j in 0..3 {
                coef[4 * k + 1 + j] = df(x, e, j);
            }
        }
        let xi = [0.1, -0.2, 0.3];
        let x = [(xi[0] + 1.0) * l[0] / 2.0, (xi[1] + 1.0) * l[1] / 2.0, (xi[2] + 1.0) * l[2] / 2.0];
        let (n, _) = physical_shape(xi, &l);
        let interp: f64 = (0..N_SHAPE).map(|a| n[a] * coef[a]).sum();
        assert!((interp - f(x, e)).abs() > 1e-6);
    }
}
