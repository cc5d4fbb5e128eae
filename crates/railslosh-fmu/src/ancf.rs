//! The ANCF brick-fluid slosh model behind the FMU (`model` = 1), through
//! [`rail_mbs::cosim::SloshParticipant`].
//!
//! The liquid is the structured mesh of a flat-ended elliptical cylinder
//! ([`ancf_core::mesh::elliptic_cylinder`], `n_length × n_width × n_height` bricks), a
//! Newtonian fluid with the default penalties of the slosh validation cases
//! ([`rail_mbs::defaults::liquid`]: k_IC = 1000 ρ g H, c_TD = 0.2 √(k_IC ρ) h_el), the
//! default wall contact law for that depth, and the participant's HHT defaults (α = −0.3,
//! adaptive steps ≤ `h_max`). Loads are those of the wall contact; they have no direct
//! feedthrough from the inputs (the tank motion acts through the fluid's dynamics).

use ancf_core::constitutive::Rheology;
use ancf_core::mesh::{EllipticCylinderSpec, elliptic_cylinder};
use ancf_core::tank::{TankGeometry, TankShape};
use rail_mbs::cosim::{ParticipantState, SloshParticipant, SloshParticipantConfig, TankMotionInput};

use crate::model::{FmuModel, ModelConfig, Outputs, TankInput};
use crate::pendulum::Pendulum;
use crate::variables::GRAVITY;

/// The participant and the pendulum estimate of the slosh frequencies.
pub struct Ancf {
    participant: SloshParticipant,
    frequencies: [f64; 2],
}

fn sample(u: &TankInput) -> TankMotionInput {
    TankMotionInput::TankFrame(*u)
}

/// Build the ANCF participant of `config` at time `t0`, the fluid at rest in the tank.
pub fn build(config: &ModelConfig, t0: f64) -> Result<Box<dyn FmuModel>, String> {
    config.validate()?;
    let spec = EllipticCylinderSpec {
        length: config.length,
        semi_axis_y: config.semi_axis_y,
        semi_axis_z: config.semi_axis_z,
        fill: config.fill,
        n_length: config.counts[0],
        n_width: config.counts[1],
        n_height: config.counts[2],
    };
    let mesh = elliptic_cylinder(&spec).map_err(|e| e.to_string())?;
    let depth = mesh.liquid_depth();
    let h_el = (config.length / spec.n_length as f64)
        .min(2.0 * config.semi_axis_y / spec.n_width as f64)
        .min(depth / spec.n_height as f64);
    let fluid =
        rail_mbs::defaults::liquid(config.density, Rheology::Newtonian { viscosity: config.viscosity }, depth, h_el)
            .map_err(|e| e.to_string())?;
    let tank = TankGeometry::new(
        TankShape::EllipticCylinder {
            length: config.length,
            semi_axis_y: config.semi_axis_y,
            semi_axis_z: config.semi_axis_z,
        },
        vec![],
    )
    .map_err(|e| e.to_string())?;
    let mut c = SloshParticipantConfig::new(mesh, fluid, tank);
    c.h_max = config.h_max;
    c.reference_point = config.reference;
    c.gravity = GRAVITY;
    c.t0 = t0;
    let participant = SloshParticipant::new(c).map_err(|e| e.to_string())?;
    let frequencies = Pendulum::new(config, t0)?.slosh_frequencies();
    Ok(Box::new(Ancf { participant, frequencies }))
}

impl FmuModel for Ancf {
    fn time(&self) -> f64 {
        self.participant.time()
    }

    fn start(&mut self, u: &TankInput) -> Result<(), String> {
        self.participant.set_initial_input(&sample(u)).map(|_| ()).map_err(|e| e.to_string())
    }

    fn advance(&mut self, t_end: f64, u0: &TankInput, u1: &TankInput) -> Result<(), String> {
        self.participant.advance(t_end, &sample(u0), &sample(u1)).map(|_| ()).map_err(|e| e.to_string())
    }

    fn outputs(&self, _u: &TankInput) -> Outputs {
        let l = self.participant.loads();
        Outputs { force: l.force, moment: l.moment, com: self.participant.com_tank() }
    }

    fn mass(&self) -> f64 {
        self.participant.fluid_mass()
    }

    fn slosh_frequencies(&self) -> [f64; 2] {
        self.frequencies
    }

    fn save_state(&self) -> Vec<u8> {
        self.participant.save_state().to_bytes()
    }

    fn restore_state(&mut self, state: &[u8]) -> Result<(), String> {
        let s = ParticipantState::from_bytes(state).map_err(|e| e.to_string())?;
        self.participant.restore_state(&s).map_err(|e| e.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{ModelKind, build as build_model};

    fn config() -> ModelConfig {
        ModelConfig {
            kind: ModelKind::Ancf,
            fill: 0.5,
            density: 1000.0,
            viscosity: 0.05,
            length: 0.324,
            semi_axis_y: 0.208585,
            semi_axis_z: 0.132131,
            reference: [0.0; 3],
            h_max: 0.005,
            damping_ratio: 0.0,
            counts: [1, 2, 1],
        }
    }

    /// A tank at rest: the fluid mass is ρ A L, the load settles to the weight, and a
    /// rollback reproduces the loads bit for bit.
    #[test]
    fn ancf_model_at_rest_and_rollback() {
        let c = config();
        let mut m = build_model(&c, 0.0).unwrap();
        let area = 0.5 * std::f64::consts::PI * c.semi_axis_y * c.semi_axis_z;
        let mass = m.mass();
        // 2 bricks across the curved section: the mesh volume is within 1 % of the section's
        assert!((mass / (1000.0 * area * c.length) - 1.0).abs() < 0.01, "mass {mass}");
        let u = TankInput::at_rest(crate::variables::GRAVITY);
        m.start(&u).unwrap();
        m.advance(0.1, &u, &u).unwrap();
        let saved = m.save_state();
        m.advance(0.2, &u, &u).unwrap();
        let first = m.outputs(&u);
        m.restore_state(&saved).unwrap();
        assert_eq!(m.time(), 0.1);
        m.advance(0.2, &u, &u).unwrap();
        assert_eq!(m.outputs(&u), first);
        let w = mass * GRAVITY;
        assert!((first.force[2] / -w - 1.0).abs() < 0.1, "F_z {} vs {}", first.force[2], -w);
        assert!(m.restore_state(b"garbage").is_err());
    }
}
