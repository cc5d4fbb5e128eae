//! Production defaults, one home for each (issue 18): the integrator settings of slosh runs,
//! the penalty rules of the fluid, the crude oils of seed 000, and the brake design of the braking
//! runs. Runs, the co-simulation participant, the FMU, the Python binding and the validation
//! cases all take them from here; physical constants live in [`ancf_core::constants`].

use ancf_core::constitutive::{Fluid, Rheology};
use ancf_core::error::{Result, invalid};

pub use ancf_core::constants::GRAVITY;

use crate::integrator::{AdaptiveParams, HhtParams, StepControl};
use crate::mbs::Table;
use crate::vehicle::{BrakeScope, TankCarParams};

/// Easy steps in a row before a slosh run doubles its step again (issue 17). After 5 (the
/// integrator's default) the step just grown mostly failed again: on the rectangular tank's
/// 0.3 g pulse (4×8×3, 2 s) 579 failed attempts and 1 320 factorizations; after 20, 347 and 686,
/// 1.17× faster and 3× closer to the 1 ms-capped run (docs/benchmarks.md, "Growing the step less
/// often"); after 50 the extra steps cost more than the factorizations save.
pub const SLOSH_GROW_AFTER: usize = 20;

/// HHT settings of slosh runs: α = −0.3 (numerical damping of the penalty and contact
/// modes), tolerances scaled to accelerations of order g, adaptive steps (h is the
/// largest step; it is halved where Newton fails or an element would invert, and doubles
/// again after [`SLOSH_GROW_AFTER`] steps in a row that converged in fewer than 5 iterations),
/// and the Jacobian reused until the Newton contraction rate exceeds 0.5 (measured fastest on
/// the tank-car benchmark: 10.0 s vs 17.5 s wall for 1 s simulated, `cargo bench -p rail-mbs
/// --bench slosh`).
pub fn slosh_params() -> HhtParams {
    HhtParams {
        alpha: -0.3,
        abs_tol_acc: 1e-3,
        max_iterations: 10,
        refresh_rate: 0.5,
        step_control: StepControl::Adaptive(AdaptiveParams {
            h_min: 1e-6,
            easy_iterations: 5,
            grow_after: SLOSH_GROW_AFTER,
            ..Default::default()
        }),
        ..Default::default()
    }
}

/// Hydrostatic volume strain the default penalty bulk modulus allows: k_IC = ρ g H / strain.
pub const PENALTY_STRAIN: f64 = 1e-3;

/// Default penalty bulk modulus k_IC (Pa) of a liquid `depth` m deep: the hydrostatic pressure
/// at the bottom, ρ g H, compresses it by `strain` (default [`PENALTY_STRAIN`]: k_IC = 1000 ρ g H,
/// two to three orders below the physical bulk modulus of oil, which keeps the system far less
/// stiff; docs/benchmarks.md shows the softer choices lose accuracy).
pub fn default_bulk_penalty(density: f64, depth: f64, strain: f64) -> Result<f64> {
    for (field, value) in [("density", density), ("depth", depth), ("strain", strain)] {
        if !(value.is_finite() && value > 0.0) {
            return Err(invalid(field, value, "a number > 0"));
        }
    }
    Ok(density * GRAVITY * depth / strain)
}

/// Default penalty bulk viscosity c_TD = 0.2 √(k_IC ρ) h_el (Pa·s) for elements `h_el` m high.
pub fn default_bulk_damping(bulk_penalty: f64, density: f64, h_el: f64) -> f64 {
    0.2 * (bulk_penalty * density).sqrt() * h_el
}

/// Recommended shear stabilization modulus as a fraction of the hydrostatic pressure over one
/// element height: G_s = SHEAR_STABILIZATION · ρ g h_el ([`default_shear_stabilization`]).
pub const SHEAR_STABILIZATION: f64 = 0.006;

/// Floor of the recommended shear stabilization for the liquid in a tank with heads, as a
/// fraction of the hydrostatic pressure at the bottom: G_s ≥ HEADS_SHEAR_STABILIZATION · ρ g H
/// ([`default_shear_stabilization`]).
pub const HEADS_SHEAR_STABILIZATION: f64 = 0.005;

/// Recommended shear stabilization (Pa) for elements `h_el` m high (`ancf_core::constitutive`,
/// "Shear stabilization"): G_s = [`SHEAR_STABILIZATION`] ρ g h_el, and in a tank with heads
/// (`heads_depth` = Some(H), the liquid depth) at least [`HEADS_SHEAR_STABILIZATION`] ρ g H.
///
/// On the rectangular and elliptic tanks the unstable rest modes it removes are discretization
/// errors that shrink as the mesh is refined, so G_s shrinks with the element; the factor is the
/// smallest that made the rest state of the rectangular tank's 4×8×3 mesh stable, with a margin.
/// In a tank with heads the growing modes do not shrink with refinement but grow with the
/// number of layers (λ_min with the element-height rule: 6×4×3 −0.036, 4×8×4 −1.62; they sit
/// where the free surface meets the shell and at the section map's 180° corners, and the
/// flat-ended meshes do not have them), and the floor 0.005 ρ g H, 25 % above the smallest
/// multiple of ρ g H that makes them all stable (0.004), makes every car mesh from 2×2×2 to
/// 8×6×4 stable (docs/validation.md, "A stable rest state").
///
/// It is not applied by default: it also stiffens the sloshing (first frequency +0.8 % on the
/// 2×6×2 rectangular tank, +1.0 to +2.1 % on the car meshes), so runs opt in (scene key
/// `mesh.shear_stabilization`, on by default in scenes).
pub fn default_shear_stabilization(density: f64, h_el: f64, heads_depth: Option<f64>) -> f64 {
    let by_element = SHEAR_STABILIZATION * density * GRAVITY * h_el;
    match heads_depth {
        Some(depth) => by_element.max(HEADS_SHEAR_STABILIZATION * density * GRAVITY * depth),
        None => by_element,
    }
}

/// A fluid with the default penalties for liquid depth `depth` and element height `h_el`:
/// [`default_bulk_penalty`] and [`default_bulk_damping`] (no shear stabilization).
pub fn liquid(density: f64, rheology: Rheology, depth: f64, h_el: f64) -> Result<Fluid> {
    let k = default_bulk_penalty(density, depth, PENALTY_STRAIN)?;
    let mut f = Fluid::new(density, rheology, k)?;
    f.bulk_damping = default_bulk_damping(k, density, h_el);
    Ok(f)
}

/// The liquids of seed 000 Table 2 (and water), by name in scenes and the Python API.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Oil {
    /// Light crude: 850 kg/m³, 0.005 Pa·s, no yield stress (seed 000 Table 2).
    Light,
    /// Medium crude: 900 kg/m³, 10 Pa·s, 30 Pa.
    Medium,
    /// Heavy crude: 1000 kg/m³, 100 Pa·s, 100 Pa.
    Heavy,
    /// Water at 20 °C: 998 kg/m³, 1e-3 Pa·s.
    Water,
}

impl Oil {
    /// Density, viscosity, yield stress.
    pub fn properties(self) -> (f64, f64, f64) {
        match self {
            Oil::Light => (850.0, 0.005, 0.0),
            Oil::Medium => (900.0, 10.0, 30.0),
            Oil::Heavy => (1000.0, 100.0, 100.0),
            Oil::Water => (998.0, 1e-3, 0.0),
        }
    }

    /// Name.
    pub fn name(self) -> &'static str {
        match self {
            Oil::Light => "light",
            Oil::Medium => "medium",
            Oil::Heavy => "heavy",
            Oil::Water => "water",
        }
    }

    /// The oil of a name: `light`, `medium`, `heavy` or `water`.
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "light" => Ok(Oil::Light),
            "medium" => Ok(Oil::Medium),
            "heavy" => Ok(Oil::Heavy),
            "water" => Ok(Oil::Water),
            other => Err(invalid("oil", other, "'light', 'medium', 'heavy' or 'water'")),
        }
    }

    /// The fluid with the default penalties ([`liquid`]) for a liquid depth and element height.
    pub fn fluid(self, depth: f64, h_el: f64) -> Result<Fluid> {
        let (rho, mu, tau) = self.properties();
        let rheology = match self {
            Oil::Water => Rheology::Newtonian { viscosity: mu },
            _ => Rheology::Oldroyd { viscosity: mu, yield_stress: tau, elastic_modulus: None },
        };
        liquid(rho, rheology, depth, h_el)
    }
}

/// Settling time before the brakes apply, s.
pub const SETTLE: f64 = 0.5;

/// Largest time step of the conventional-braking runs (the front car braked) and of the
/// shipped conventional-braking scenes, s: their coupler force, the brake difference between
/// the cars (tens of kN), changes by less than 0.01 % from 4 to 2 ms
/// (`coupler-force-convergence`, `railslosh_cases`).
pub const BRAKING_STEP: f64 = 4e-3;

/// Largest time step of the ECP runs (every car braked) with light crude or water and of the
/// shipped light-crude ECP scenes, s. With identical brakes the coupler force is a few tens of
/// newtons riding on ±50 kN liquid loads, and at 4 ms it is not resolved in time: on the 4×4×2
/// mesh over 6 s its RMS is 39.2 / 34.9 / 34.5 N at 4 / 2 / 1 ms (12 % then 1.1 %), and tighter
/// Newton tolerances (1e-7 against 1e-4) move it by no more than the step does (docs/validation.md,
/// "coupler-force-convergence"). On the scenes' 6×4×2 mesh over the full 10.5 s (symmetric mesh,
/// 2026-11-28) the RMS is 46.7 / 44.4 / 43.5 N at 2 / 1 / 0.5 ms (5.2 % then 2.0 %), while going to
/// 8×4×2 moves it by 27 %: 2 ms is kept, since halving it costs 1.8× the run time for an error
/// the mesh error dwarfs ("The full form on the mirror-symmetric meshes").
pub const ECP_STEP: f64 = 2e-3;

/// Largest time step of the ECP runs with the medium and heavy crudes (and of their scenes), s:
/// their coupler force converges more slowly in the step. On 4×4×2 over 6 s its RMS at
/// 2 / 1 / 0.5 ms is 29.8 / 28.4 / 27.9 N (medium) and 40.6 / 37.5 / 36.7 N (heavy): 2 ms is
/// 6.8 % and 10.6 % from the 0.5 ms figure, 1 ms 1.8 % and 2.2 %.
pub const ECP_STEP_VISCOUS: f64 = 1e-3;

/// The largest time step of a braking run with brake `scope` and liquid `oil` ([`ECP_STEP`],
/// [`ECP_STEP_VISCOUS`] or [`BRAKING_STEP`]).
pub fn braking_step(scope: BrakeScope, oil: Oil) -> f64 {
    match (scope, oil) {
        (BrakeScope::FrontCar, _) => BRAKING_STEP,
        (BrakeScope::AllCars, Oil::Medium | Oil::Heavy) => ECP_STEP_VISCOUS,
        (BrakeScope::AllCars, _) => ECP_STEP,
    }
}

/// Brake torque per wheelset `T₀(1 − e^{−(t−t_s)/τ})` that slows a car of total mass
/// `mass` from `v0` to `v1` in `duration` (rigid estimate, spin inertia included).
pub fn brake_torque(p: &TankCarParams, mass: f64, v0: f64, v1: f64, duration: f64) -> Result<Table> {
    let tau: f64 = 0.5;
    let m_eq = mass + 4.0 * p.wheelset.inertia[1] / (p.wheel_radius * p.wheel_radius);
    let eff = duration - tau * (1.0 - (-duration / tau).exp());
    let t0 = (v0 - v1) * p.wheel_radius * m_eq / (4.0 * eff);
    let ts: Vec<f64> = (0..=60).map(|i| SETTLE + 0.1 * i as f64).collect();
    let mut x = vec![0.0];
    let mut y = vec![0.0];
    for t in ts {
        x.push(t);
        y.push(t0 * (1.0 - (-(t - SETTLE) / tau).exp()));
    }
    Table::new("brake torque", x, y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_penalty_rule_allows_the_stated_hydrostatic_strain() {
        // ρ g H / k_IC is the volume strain at the bottom of the liquid
        let (rho, depth) = (850.0, 1.5);
        let k = default_bulk_penalty(rho, depth, PENALTY_STRAIN).unwrap();
        assert!((rho * GRAVITY * depth / k - PENALTY_STRAIN).abs() < 1e-18);
        let f = liquid(rho, Rheology::Newtonian { viscosity: 0.005 }, depth, 0.75).unwrap();
        assert_eq!(f.bulk_penalty, k);
        assert_eq!(f.bulk_damping, 0.2 * (k * rho).sqrt() * 0.75);
        let e = default_bulk_penalty(rho, 0.0, PENALTY_STRAIN).unwrap_err().to_string();
        assert!(e.contains("depth"), "{e}");
    }

    #[test]
    fn an_oil_is_its_table_row_with_the_default_penalties() {
        for oil in [Oil::Light, Oil::Medium, Oil::Heavy, Oil::Water] {
            let (rho, mu, tau) = oil.properties();
            let f = oil.fluid(1.5, 0.75).unwrap();
            let rheology = if oil == Oil::Water {
                Rheology::Newtonian { viscosity: mu }
            } else {
                Rheology::Oldroyd { viscosity: mu, yield_stress: tau, elastic_modulus: None }
            };
            assert_eq!(f, liquid(rho, rheology, 1.5, 0.75).unwrap());
            assert_eq!(Oil::from_name(oil.name()).unwrap(), oil);
        }
        assert!(Oil::from_name("olive").unwrap_err().to_string().contains("oil"));
    }
}
