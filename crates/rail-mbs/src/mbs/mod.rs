//! Multibody core: rigid bodies with Euler parameters, joints with analytic constraint
//! Jacobians, force elements and wheel/rail contacts, assembled into one
//! [`MechanicalSystem`](crate::integrator::MechanicalSystem) ([`Multibody`]).
//!
//! Frames and signs: global `X, Y` horizontal, `Z` up (see `docs/frames.md`); body
//! origins are centres of mass; forces and moments are global.

pub mod body;
pub mod force;
pub mod joint;
pub mod rotation;
pub mod system;
pub mod wheelset;

pub use body::{Attachment, BodyId, BodyState, RigidBody};
pub use force::{BrakeTorque, Bushing, ForceElement, SpringDamper, SpringLaw, Table, Wrench};
pub use joint::{Joint, JointKind, SpeedProfile, TrajectoryDriver};
pub use system::Multibody;
pub use wheelset::{WheelsetContact, WheelsetReport};
