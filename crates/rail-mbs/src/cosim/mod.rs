//! Co-simulation (issue 6): the slosh model as a coupling participant (seed 003 §2.3).
//!
//! # API (stable; the Python binding and the FMI 3.0 FMU are built on it)
//!
//! ```text
//! SloshParticipantConfig::new(mesh: FluidMesh, fluid: Fluid, tank: TankGeometry) -> Self
//!     pub fields: mesh, fluid, tank, contact: Option<WallContactLaw>, quadrature,
//!                 hht: HhtParams, h_max: f64, reference_point: [f64; 3],
//!                 gravity: f64, t0: f64
//! SloshParticipant::new(config) -> Result<SloshParticipant, CosimError>
//! SloshParticipant::set_initial_input(&mut self, &TankMotionInput) -> Result<Loads, CosimError>
//! SloshParticipant::settle(&mut self, duration, &TankMotionInput) -> Result<Loads, CosimError>
//! SloshParticipant::advance(&mut self, t_end, &TankMotionInput, &TankMotionInput)
//!     -> Result<Loads, CosimError>
//! SloshParticipant::save_state(&self) -> ParticipantState
//! SloshParticipant::restore_state(&mut self, &ParticipantState) -> Result<(), CosimError>
//! SloshParticipant::added_mass(&self) -> [[f64; 6]; 6]
//! SloshParticipant::{time, fluid_mass, com_tank, volume, loads, stats, reference_point,
//!                    h_max, gravity, tank_frame_sample}
//! ParticipantState::{time, to_bytes, from_bytes}
//! TankMotionInput::TankFrame(TankFrameSample) | TankMotionInput::Pose(PoseInput)
//! PoseInput::rotation_from_quaternion([w, x, y, z]) -> Result<[[f64; 3]; 3], CosimError>
//! PoseInput::to_tank_frame(&self, gravity: f64) -> Result<TankFrameSample, CosimError>
//! Loads { force: [f64; 3], moment: [f64; 3] }
//! maneuvers (= crate::maneuvers)::{lane_change, lane_change_course, half_round_bump,
//!             trapezoidal_bump, bump, seed003_maneuvers, Maneuver, ManeuverSpec,
//!             LaneChangeCourse, BumpProfile, BumpVehicle}
//! ```
//!
//! # Conventions (docs/frames.md)
//!
//! - The fluid is modelled in the **tank frame** K (x along the tank axis, y left, z up)
//!   with the pseudo-forces of seed 003 appendix C eq. (7.40):
//!   −ρ[R̈ + ω̇ × r + ω × (ω × r) + 2 ω × ṙ], and gravity given in tank axes.
//! - Inputs, form 1 ([`TankFrameSample`], seed 003's interface): acceleration R̈ of the
//!   tank origin, angular velocity ω and angular acceleration ω̇, and the gravity vector
//!   (direction × g), **all in tank axes**.
//! - Inputs, form 2 ([`PoseInput`]): position R and rotation A of the tank (tank → global,
//!   x_global = R + A x_tank), velocity Ṙ, angular velocity ω, acceleration R̈ and angular
//!   acceleration ω̇, **all in global axes**; gravity is (0, 0, −g) global with g from the
//!   config. They are converted to form 1 (A^T R̈, A^T ω, A^T ω̇, A^T g); position and
//!   velocity do not enter the tank-frame equations (checked finite only).
//! - [`SloshParticipant::advance`] integrates the window [t, t_end] with the HHT
//!   integrator in equal steps ≤ `h_max` (halved where Newton fails, when
//!   `hht.step_control` is adaptive), the input interpolated **linearly** between
//!   `input_start` (at t) and `input_end` (at t_end).
//! - Output [`Loads`]: force and moment that the fluid exerts **on the tank** (wall
//!   contact), tank axes, moment about `reference_point` (tank frame), at t_end.
//!   A tank at rest with gravity −z carries (0, 0, −m g).
//! - Rollback: [`SloshParticipant::save_state`] / [`SloshParticipant::restore_state`]
//!   are exact: restoring and advancing with the same inputs reproduces the loads bit for
//!   bit (every window starts from freshly evaluated Jacobians, restored or not).
//!   A window that fails restores the state of its start before returning the error.
//!   A state holds the integrator's full [`Checkpoint`](crate::integrator::Checkpoint),
//!   stored Jacobian values included (about 1.2 MB for a 2×2×2-element box; it grows
//!   with the number of node-pair blocks).
//! - Cost: every window starts with fresh Jacobians and a refactorization (that is what
//!   makes a restored and an uninterrupted run identical), so windows of a few integrator
//!   steps or more are efficient.
//! - [`SloshParticipant::added_mass`]: the 6×6 rigid-body mass matrix of the fluid in
//!   its current configuration about `reference_point`, tank axes, for generalized
//!   velocities (v_P, ω): `[[m I, −m c̃], [m c̃, J_P]]`, c = centre of mass − P. It is the
//!   mass the tank carries when the fluid moves rigidly with it (an upper bound of the
//!   sloshing added mass; masters use it for added-mass splitting).

mod participant;

/// The manoeuvre library lives in [`crate::maneuvers`] (one definition for the co-simulation
/// examples and the prescribed-motion scenes); re-exported here under its old path.
pub use crate::maneuvers;

pub use participant::{
    CosimError, Loads, ParticipantState, PoseInput, SloshParticipant, SloshParticipantConfig, TankMotionInput,
};

pub use crate::slosh::{TankFrameInput, TankFrameSample};
