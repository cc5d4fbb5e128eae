//! Vehicle builders: the freight tank car of seed 000 §8.1 (Fig. 7) and trains of such
//! cars joined by couplers.
//!
//! # The tank car
//!
//! Fifteen rigid bodies: the tank (car body), two stub sills welded to it, and two
//! bogies (trucks), each with a bolster, a frame, two equalizers and two wheelsets.
//! Connections, as in seed 000 §8.1:
//!
//! | connection | model |
//! |---|---|
//! | stub sill – tank | fixed joint (6 equations each) |
//! | bolster – frame | pin: revolute joint about the vertical (5 equations each) |
//! | wheelset – frame (primary suspension) | one bushing per axle box, translational |
//! | wheelset – equalizer (journal bearing) | one bushing per bearing, spin free |
//! | bolster – stub sill (secondary suspension) | one bushing per side |
//! | wheelset – rails | ECF-A wheel/rail contact, Hertz + creep ([`crate::wheel_rail`]) |
//!
//! The car has 15 × 6 − 2 × 6 − 2 × 5 = **68 degrees of freedom**. The paper reports
//! 73 for its model without listing its joints; the five-DOF difference cannot be
//! traced from the text (it may model the journal bearings or pins differently).
//!
//! Every parameter is a field of [`TankCarParams`]; the defaults and their sources are
//! listed there. Suspension springs carry their static share of the car weight as a
//! preload at the assembled (reference) configuration, so a car placed on level track
//! starts in equilibrium except for the Hertzian contact deflection.
//!
//! # Placement
//!
//! A car is placed on a [`Track`](crate::track::Track) with its tank centre at arc length `s`: every body
//! sits at its own station, in the local track frame (tangent, left, up, banked by the
//! super-elevation), and moves initially with the speed `V` along the tangent, the yaw
//! rate `V κ`, and — wheelsets — the rolling spin `V / r₀`. The front of the car (bogie
//! 1, coupler end A) points towards increasing `s`.

pub mod checkpoint;
pub mod equivalent;
pub mod fluid;
mod load_filter;
mod record;
mod run;
mod tank_car;

pub use checkpoint::{RunCheckpoints, VehicleCheckpoint};
pub use equivalent::{
    EquivalentCargo, EquivalentModel, EquivalentTrainFailure, EquivalentTrainRecord, SloshAxis, build_equivalent_train,
    run_equivalent_train,
};
pub use fluid::{
    FluidCargo, FluidTrainFailure, FluidTrainRecord, FluidVehicle, TankFluid, build_fluid_train, run_fluid_train,
};
pub use run::{
    BrakeScope, Cargo, LoadFilter, Observer, Progress, RigidCargo, RunFailure, RunResult, SampleSink, TrainFailure,
    TrainRecord, TrainScenario, WHEEL_OFF_RAIL_LIMIT, build_train, hat_mean_resample, run_train, run_vehicle,
    stopped_by_observer,
};
pub use tank_car::{
    BodyMass, CarBodies, CarPlacement, ContactParams, SuspensionParams, TANK_HEAD_DEPTH, TankCarParams, TruckModel,
    WheelLoad, add_coupler, add_tank_car, wheel_loads,
};
