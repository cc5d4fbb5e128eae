//! Checkpoint of a whole slosh run (issue 18): the stepper's own checkpoint (implicit
//! [`crate::integrator::Checkpoint`] or explicit [`crate::integrator::ExplicitCheckpoint`], told
//! apart by their magics) and the run-time invariants' account ([`InvariantMonitor::save_account`]:
//! energy reference, input work, worst margins), so that a resumed run goes on with the same
//! energy balance, not a fresh one.
//!
//! Byte format: the magic `RSLSLOCK`, a version (u32 LE), the stepper checkpoint's bytes
//! (u64 length, then the bytes), the account (u64 length, then f64 LE values).
//!
//! [`InvariantMonitor::save_account`]: crate::invariants::InvariantMonitor::save_account

use crate::integrator::{BytesReader, BytesWriter, IntegratorError};

const MAGIC: &[u8; 8] = b"RSLSLOCK";
const VERSION: u32 = 1;

/// A slosh run's checkpoint (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct SloshCheckpoint {
    /// The stepper's checkpoint, as its own `to_bytes` wrote it.
    pub stepper: Vec<u8>,
    /// The invariant monitor's account.
    pub account: Vec<f64>,
}

impl SloshCheckpoint {
    /// Whether `bytes` start with this format's magic.
    pub fn is_one(bytes: &[u8]) -> bool {
        bytes.starts_with(MAGIC)
    }

    /// Serializes to bytes (format in the module docs); `f64` values are exact.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = BytesWriter(Vec::new());
        w.header(MAGIC, VERSION);
        w.bytes(&self.stepper);
        w.vec(&self.account);
        w.0
    }

    /// Reads bytes written by [`Self::to_bytes`].
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, IntegratorError> {
        let mut r = BytesReader { bytes, pos: 0 };
        r.versioned(MAGIC, "slosh-run", VERSION)?;
        let stepper = r.bytes("stepper")?.to_vec();
        let account = r.vec("account")?;
        r.finish()?;
        Ok(Self { stepper, account })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_round_trip_and_damage_is_a_typed_error() {
        let ck = SloshCheckpoint { stepper: b"RSLEXPCK-some-bytes".to_vec(), account: vec![1.5, -0.0, f64::MAX] };
        let bytes = ck.to_bytes();
        assert!(SloshCheckpoint::is_one(&bytes));
        assert_eq!(SloshCheckpoint::from_bytes(&bytes).unwrap(), ck);
        for cut in [4, 12, 20, bytes.len() - 1] {
            assert!(matches!(SloshCheckpoint::from_bytes(&bytes[..cut]), Err(IntegratorError::Checkpoint { .. })));
        }
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(matches!(SloshCheckpoint::from_bytes(&longer), Err(IntegratorError::Checkpoint { .. })));
    }
}
