//! Wheel/rail contact of a wheelset body: both wheels against their rails (ECF-A,
//! [`crate::wheel_rail`]), as a force element on the wheelset.

use nalgebra::Vector3;

use super::body::{BodyId, BodyState};
use super::force::Wrench;
use crate::wheel_rail::{ContactError, ContactPoint, WheelPose, WheelRailContact};

/// Contact of one wheelset with the two rails.
#[derive(Debug, Clone)]
pub struct WheelsetContact {
    /// Name (e.g. "car1/bogie1/wheelset1").
    pub name: String,
    /// The wheelset body.
    pub body: BodyId,
    /// Left wheel on the left rail, and right wheel on the right rail.
    pub wheels: [WheelRailContact; 2],
}

/// Contact points of one wheelset at one instant.
#[derive(Debug, Clone, Default)]
pub struct WheelsetReport {
    /// Loaded contact points of the left and right wheels.
    pub points: [Vec<ContactPoint>; 2],
}

impl WheelsetReport {
    /// Sum of the contact forces on a wheel (0 = left, 1 = right), global, N.
    pub fn wheel_force(&self, side: usize) -> Vector3<f64> {
        self.points[side].iter().map(|p| p.force_on_wheel()).sum()
    }
}

fn pose(s: &BodyState) -> WheelPose {
    WheelPose { position: s.position, rotation: s.rotation, velocity: s.velocity, angular_velocity: s.angular_velocity }
}

impl WheelsetContact {
    /// Contact points of both wheels at `state`, leaving the contact search's warm start
    /// unchanged ([`WheelRailContact::observe`]).
    pub fn evaluate(&mut self, state: &BodyState) -> Result<WheelsetReport, ContactError> {
        let p = pose(state);
        let [l, r] = &mut self.wheels;
        Ok(WheelsetReport { points: [l.observe(&p)?, r.observe(&p)?] })
    }

    /// Total contact wrench on the wheelset about its centre of mass (no allocation once
    /// the contacts' buffers have grown).
    pub fn wrench(&mut self, state: &BodyState) -> Result<Wrench, ContactError> {
        self.wrench_with(state, WheelRailContact::evaluate_cached)
    }

    /// [`Self::wrench`] at a state within a finite-difference perturbation of the last one
    /// evaluated, for a Jacobian column: the search warm-starts from the last solutions and
    /// leaves them as they were ([`WheelRailContact::evaluate_perturbed`]).
    pub fn wrench_perturbed(&mut self, state: &BodyState) -> Result<Wrench, ContactError> {
        self.wrench_with(state, WheelRailContact::evaluate_perturbed)
    }

    fn wrench_with(
        &mut self,
        state: &BodyState,
        evaluate: for<'a> fn(&'a mut WheelRailContact, &WheelPose) -> Result<&'a [ContactPoint], ContactError>,
    ) -> Result<Wrench, ContactError> {
        let p = pose(state);
        let mut w = Wrench::default();
        for wheel in &mut self.wheels {
            for c in evaluate(wheel, &p)? {
                w.force += c.force_on_wheel();
                w.moment += c.moment_on_wheel(&state.position);
            }
        }
        Ok(w)
    }
}
