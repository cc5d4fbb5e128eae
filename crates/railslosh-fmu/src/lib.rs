//! FMI 3.0 co-simulation FMU of the railslosh slosh model.
//!
//! The shared library `railslosh_slosh` exports the fmi3 C API ([`fmi3`]); `scripts/build-fmu`
//! packs it with `modelDescription.xml` ([`variables`]) into `dist/railslosh_slosh.fmu`.
//! Each instance ([`instance`]) drives a slosh model ([`model::FmuModel`]): the equivalent
//! pendulum model ([`pendulum`], `model` = 0, fast) or the ANCF brick fluid ([`ancf`],
//! `model` = 1). Inputs are the tank motion in the tank frame (seed 003's interface),
//! outputs the fluid loads on the tank and the fluid centre of mass. See `docs/fmu.md`.

pub mod ancf;
pub mod fmi3;
pub mod instance;
pub mod model;
pub mod pendulum;
pub mod variables;

#[cfg(test)]
mod tests;
