//! A small deterministic pseudo-random generator, for reproducible random input: the
//! synthetic track irregularities (`rail_mbs::track::irregularity`), the random states of the
//! tests and benchmarks, and the validation cases (crate `railslosh-cases`). It moved here from
//! the element validation module when the cases left the library (issue 18).

/// Small deterministic pseudo-random generator (SplitMix64), uniform in [-1, 1).
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// Seeded generator.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }
    /// Next number in [-1, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E3779B97F4A7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58476D1CE4E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D049BB133111EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
    /// A random unit-ish vector scaled by `s`.
    pub fn vec3(&mut self, s: f64) -> [f64; 3] {
        [s * self.uniform(), s * self.uniform(), s * self.uniform()]
    }
}
