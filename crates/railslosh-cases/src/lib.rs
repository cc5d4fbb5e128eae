//! # railslosh-cases
//!
//! The validation cases, the studies of the papers and the work–precision sweeps of
//! railslosh, run by `railslosh validate`, `railslosh bench`, the test suites and the examples
//! of this crate. They live outside the solver crates (issue 18): `ancf-core` and `rail-mbs`
//! hold the model, this crate the checks and studies run on it, and neither library depends on
//! it. The Python binding (`railslosh._core`) calls the cases through here.
//!
//! Modules mirror where the cases came from:
//!
//! | module | cases | was |
//! |---|---|---|
//! | [`element`] | the ANCF brick: mass, Jacobians, rigid-motion invariance | `ancf_core::validate` |
//! | [`slosh`] | prescribed-motion sloshing (seed 003 tank, cylinder, viscous decay, bulkheads, linear theory, load convergence) | `rail_mbs::slosh::validate` |
//! | [`contact`] | wheel/rail contact: Manchester against CONTACT, Klingel | `rail_mbs::wheel_rail::validate` |
//! | [`vehicle`] | the tank car: static wheel loads, balance-speed curving, lateral stability | `rail_mbs::vehicle::validate` |
//! | [`vehicle::studies`] | the crude-oil paper's braking and curving studies (seed 000 §8.2–8.5) and their cases | `rail_mbs::vehicle::studies` |
//! | [`work_precision`] | run time against error (`railslosh bench`) | `rail_mbs::work_precision` |
//!
//! Every case returns [`Record`]s: one measured quantity against its reference with a
//! tolerance. What stayed in the libraries because production code, library tests or
//! benchmarks use it: `ancf_core::rng::Rng`, `ancf_core::testing` (sample fluids, the
//! element's finite-difference check), `rail_mbs::slosh::analysis::dominant_frequency`,
//! `rail_mbs::slosh::linear_theory::rect_tank_frequency`, `rail_mbs::track::presets::table1`
//! and `rail_mbs::wheel_rail::manchester` (the shared-data search and CONTACT's readers).
#![warn(missing_docs)]

pub mod contact;
pub mod element;
mod record;
pub mod slosh;
pub mod vehicle;
pub mod work_precision;

pub use record::Record;

/// Wall damping ratio of the shipped scenes (critical: the crude-oil car scenes and the lane
/// changes, docs/validation.md "Wall damping"), used by the cases that measure what the scenes
/// run: `slosh-load-convergence`, `bulkhead-longitudinal`, `tank-frame-equivalence` and
/// `coupler-force-convergence` (the other car studies keep the library's walls: with these, the
/// quick form of `ecp-braking-oils` loses its oil orderings, docs/validation.md "Crude-oil
/// studies").
pub const SCENE_WALL_DAMPING: f64 = 1.0;
/// Wall adhesion (suction, × ρ g H) of the shipped crude-oil scenes (docs/validation.md "Wall
/// peeling"), used by the same cases as [`SCENE_WALL_DAMPING`].
pub const SCENE_WALL_ADHESION: f64 = 4.0;
