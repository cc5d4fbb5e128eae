//! Railway multibody dynamics for railslosh.
//!
//! Modules are grouped by physics:
//! - [`cosim`]: the slosh model as a co-simulation participant (seed 003);
//! - [`maneuvers`]: seed 003's tank manoeuvres (lane changes, bumps), the one definition used
//!   by the prescribed-motion scenes and the co-simulation;
//! - [`invariants`]: run-time checks of every fluid run (containment, energy, element validity);
//! - [`integrator`]: the sparse implicit HHT-α integrator (faer sparse LU) that advances
//!   rigid and ANCF bodies together;
//! - [`track`]: track geometry from segment tables;
//! - [`profile`]: wheel and rail profiles (analytic, splines, file import);
//! - [`wheel_rail`]: wheel/rail contact search, Hertz normal contact and creep forces.
#![warn(missing_docs)]

pub mod cosim;
pub mod defaults;
pub mod fluid_blocks;
pub mod integrator;
pub mod invariants;
pub mod maneuvers;
pub mod mbs;
pub mod observe;
pub mod profile;
pub mod slosh;
pub mod track;
pub mod vehicle;
pub mod wheel_rail;
