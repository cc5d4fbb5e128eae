//! # ancf-core
//!
//! Pure-Rust kernels of the total-Lagrangian ANCF fluid model of seed 000
//! (Grossi & Shabana 2018): the 8-node ANCF brick element, the Newtonian and
//! non-Newtonian constitutive laws, penalty incompressibility, structured fluid
//! meshes, and fluid-body assembly.
//!
//! Data flow: [`mesh::FluidMesh`] (geometry) + [`constitutive::Fluid`] (material) →
//! [`body::FluidBody`] (precomputed reference data, mass matrix) → batched force and
//! Jacobian evaluation used by the implicit integrator of `rail-mbs`.
//!
//! Units are SI throughout. Frames and sign conventions are defined once in
//! `docs/frames.md`.
#![warn(missing_docs)]
// Index loops mirror the tensor index notation of the formulas they implement.
#![allow(clippy::needless_range_loop)]
// Element kernels take their data explicitly rather than through ad-hoc bundles.
#![allow(clippy::too_many_arguments)]
// `!(x > 0.0)` is deliberate: it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod body;
pub mod constants;
pub mod constitutive;
pub mod contact;
pub mod element;
pub mod error;
pub mod mesh;
pub mod quadrature;
pub mod rng;
pub mod roots;
pub mod shape;
pub mod simd;
pub mod tank;
pub mod testing;

pub use body::FluidBody;
pub use constitutive::{Fluid, Rheology};
pub use element::QuadratureOptions;
pub use error::{AncfError, Result};
pub use mesh::FluidMesh;

pub use simd::clear_upper_simd;
