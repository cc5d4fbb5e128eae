//! Checkpoint and resume of a whole vehicle run (issue 18): every kind of cargo, continued bit
//! for bit.
//!
//! A vehicle run's checkpoint is taken right after a recorded sample `k`, every
//! [`RunCheckpoints::every`] samples. It holds what the following samples depend on:
//! - the integrator's own [`Checkpoint`] (state, step controller, stored Jacobians);
//! - what the system carries from step to step beyond its coordinates
//!   ([`MechanicalSystem::save_internal_state`]: the wheel/rail searches' warm starts, the
//!   liquids' energy accounts and worst margins);
//! - the recorder's state before sample `k`: the wheel/rail warm starts of the recording and
//!   the wheel-lift watch, so that the resumed run records sample `k` again exactly;
//! - the load filter's partial hat integrals after sample `k`.
//!
//! A resumed run records from sample `k` on; its samples are those of the uninterrupted run,
//! bit for bit (test `run_vehicle::a_resumed_run_continues_bit_for_bit`). The model itself (car,
//! track, cargo) is not in the file: the caller runs the same scenario and cargo, and the sizes
//! are checked.
//!
//! Byte format: the magic `RSLVEHCK`, a version (u32 LE), then `k` (u64), the integrator
//! checkpoint's bytes (length-prefixed), and the vectors of f64 (u64 length, then values LE):
//! system state, recorder warm starts, wheel-lift watch, hat-filter state.

use std::path::PathBuf;

use crate::integrator::{BytesReader, BytesWriter, Checkpoint, IntegratorError};

const MAGIC: &[u8; 8] = b"RSLVEHCK";
const VERSION: u32 = 1;

/// Where a vehicle run writes its checkpoints: the file (replaced atomically) and how many
/// recorded samples apart.
#[derive(Debug, Clone, PartialEq)]
pub struct RunCheckpoints {
    /// The checkpoint file.
    pub path: PathBuf,
    /// Recorded samples between two checkpoints (≥ 1).
    pub every: usize,
}

/// A vehicle run's checkpoint (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct VehicleCheckpoint {
    /// The recorded sample it was taken after.
    pub sample: usize,
    /// The integrator's checkpoint.
    pub integrator: Checkpoint,
    /// [`crate::integrator::MechanicalSystem::save_internal_state`].
    pub system: Vec<f64>,
    /// The recorder's wheel/rail warm starts before sample `sample`.
    pub recorder: Vec<f64>,
    /// The wheel-lift watch before sample `sample`: per wheelset and side, 1 and the time
    /// since which the wheel has carried no load, or 0 and 0.
    pub wheel_lift: Vec<f64>,
    /// The load filter after sample `sample` (an unfiltered run's holds no integrals).
    pub filter: Vec<f64>,
}

impl VehicleCheckpoint {
    /// Serializes to bytes (format in the module docs); `f64` values are exact.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = BytesWriter(Vec::new());
        w.header(MAGIC, VERSION);
        w.u64(self.sample as u64);
        w.bytes(&self.integrator.to_bytes());
        for v in [&self.system, &self.recorder, &self.wheel_lift, &self.filter] {
            w.vec(v);
        }
        w.0
    }

    /// Reads bytes written by [`Self::to_bytes`].
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, IntegratorError> {
        let mut r = BytesReader { bytes, pos: 0 };
        r.versioned(MAGIC, "vehicle-run", VERSION)?;
        let sample = r.usize("sample")?;
        let integrator = Checkpoint::from_bytes(r.bytes("integrator")?)?;
        let (system, recorder, wheel_lift, filter) =
            (r.vec("system")?, r.vec("recorder")?, r.vec("wheel_lift")?, r.vec("filter")?);
        r.finish()?;
        Ok(Self { sample, integrator, system, recorder, wheel_lift, filter })
    }
}
