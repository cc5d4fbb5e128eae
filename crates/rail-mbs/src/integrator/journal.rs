//! Crash-safe output: an append-only stream of result rows ([`Journal`]) and periodic
//! checkpoint files ([`CheckpointFile`]).
//!
//! A run that is interrupted (killed, out of time, power loss) loses nothing it has
//! already written: the journal is flushed after every row (or every `flush_every` rows)
//! and [`read_journal`] returns every complete row, ignoring a torn last one; a
//! checkpoint file is replaced atomically (written to `path.tmp`, synced, renamed), so it
//! always holds a complete [`Checkpoint`] of the last period.
//!
//! Journal format (little-endian): magic `RSLJRNL1`, the number of columns `c` (u32),
//! `c` column names (u32 byte length + UTF-8), then rows of `c` `f64` values
//! ([`f64::to_le_bytes`], exact).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use super::{Checkpoint, Explicit, Hht, IntegratorError, MechanicalSystem};

const MAGIC: &[u8; 8] = b"RSLJRNL1";

fn io_err(path: &Path, what: &str, e: std::io::Error) -> IntegratorError {
    IntegratorError::Checkpoint { what: format!("{what} {}: {e}", path.display()) }
}

/// Append-only stream of rows of `f64` with named columns.
pub struct Journal {
    out: BufWriter<File>,
    path: PathBuf,
    columns: usize,
    flush_every: usize,
    pending: usize,
    rows: usize,
}

impl Journal {
    /// Creates (truncates) `path` and writes the header. `flush_every` ≥ 1 rows are
    /// buffered before a flush to the operating system (1: every row).
    pub fn create(path: impl AsRef<Path>, columns: &[&str], flush_every: usize) -> Result<Self, IntegratorError> {
        let path = path.as_ref().to_path_buf();
        if columns.is_empty() || flush_every == 0 {
            return Err(IntegratorError::InvalidParameter {
                field: if columns.is_empty() { "columns" } else { "flush_every" },
                value: 0.0,
                allowed: ">= 1",
            });
        }
        let file = File::create(&path).map_err(|e| io_err(&path, "cannot create journal", e))?;
        let mut out = BufWriter::new(file);
        let mut header = MAGIC.to_vec();
        header.extend_from_slice(&(columns.len() as u32).to_le_bytes());
        for c in columns {
            header.extend_from_slice(&(c.len() as u32).to_le_bytes());
            header.extend_from_slice(c.as_bytes());
        }
        out.write_all(&header).and_then(|_| out.flush()).map_err(|e| io_err(&path, "cannot write journal", e))?;
        Ok(Self { out, path, columns: columns.len(), flush_every, pending: 0, rows: 0 })
    }

    /// Appends one row (exactly as many values as columns).
    pub fn append(&mut self, row: &[f64]) -> Result<(), IntegratorError> {
        if row.len() != self.columns {
            return Err(IntegratorError::InvalidSystem {
                what: format!("journal row has {} values, {} columns", row.len(), self.columns),
            });
        }
        for x in row {
            self.out.write_all(&x.to_le_bytes()).map_err(|e| io_err(&self.path, "cannot write journal", e))?;
        }
        self.rows += 1;
        self.pending += 1;
        if self.pending >= self.flush_every {
            self.flush()?;
        }
        Ok(())
    }

    /// Flushes buffered rows to the operating system.
    pub fn flush(&mut self) -> Result<(), IntegratorError> {
        self.pending = 0;
        self.out.flush().map_err(|e| io_err(&self.path, "cannot write journal", e))
    }

    /// Rows appended so far.
    pub fn rows(&self) -> usize {
        self.rows
    }
}

impl Drop for Journal {
    fn drop(&mut self) {
        let _ = self.out.flush();
    }
}

/// Column names and every complete row of a journal; a torn last row (interrupted
/// write) is dropped. A bad header is an [`IntegratorError::Checkpoint`].
pub fn read_journal(path: impl AsRef<Path>) -> Result<(Vec<String>, Vec<Vec<f64>>), IntegratorError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| io_err(path, "cannot read journal", e))?;
    let bad = |what: &str| IntegratorError::Checkpoint { what: format!("journal {}: {what}", path.display()) };
    if bytes.len() < 12 || &bytes[..8] != MAGIC {
        return Err(bad("not a railslosh journal (bad magic)"));
    }
    let u32_at = |p: usize| -> Option<usize> {
        bytes.get(p..p + 4).map(|b| u32::from_le_bytes(b.try_into().expect("4 bytes")) as usize)
    };
    let columns = u32_at(8).ok_or_else(|| bad("truncated header"))?;
    if columns == 0 {
        return Err(bad("zero columns"));
    }
    let mut pos = 12;
    let mut names = Vec::new();
    for _ in 0..columns {
        let len = u32_at(pos).ok_or_else(|| bad("truncated header"))?;
        let name = bytes.get(pos + 4..pos + 4 + len).ok_or_else(|| bad("truncated header"))?;
        names.push(String::from_utf8(name.to_vec()).map_err(|_| bad("column name is not UTF-8"))?);
        pos += 4 + len;
    }
    let rows = bytes[pos..]
        .chunks_exact(8 * columns)
        .map(|row| row.chunks_exact(8).map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes"))).collect())
        .collect();
    Ok((names, rows))
}

/// A checkpoint file replaced atomically every `every` accepted steps.
pub struct CheckpointFile {
    path: PathBuf,
    every: usize,
    last_step: usize,
    written: usize,
}

impl CheckpointFile {
    /// Writes to `path` every `every` ≥ 1 steps (counted by `Stats::steps`).
    pub fn new(path: impl AsRef<Path>, every: usize) -> Result<Self, IntegratorError> {
        if every == 0 {
            return Err(IntegratorError::InvalidParameter { field: "every", value: 0.0, allowed: ">= 1" });
        }
        Ok(Self { path: path.as_ref().to_path_buf(), every, last_step: 0, written: 0 })
    }

    /// Writes a checkpoint if `every` steps have passed since the last one; returns
    /// whether it wrote.
    pub fn maybe_write<S: MechanicalSystem>(&mut self, hht: &Hht<S>) -> Result<bool, IntegratorError> {
        self.maybe_write_bytes(hht.stats().steps, || hht.checkpoint().to_bytes())
    }

    /// Writes an explicit run's checkpoint if `every` steps have passed since the last one;
    /// returns whether it wrote.
    pub fn maybe_write_explicit<S: MechanicalSystem>(&mut self, e: &Explicit<S>) -> Result<bool, IntegratorError> {
        self.maybe_write_bytes(e.stats().steps, || e.checkpoint().to_bytes())
    }

    /// Writes the bytes `make` gives if `every` steps have passed since the last checkpoint,
    /// `steps` being the run's count now (a run checkpoint of another format, such as a slosh
    /// run's); returns whether it wrote.
    pub fn maybe_write_bytes(&mut self, steps: usize, make: impl FnOnce() -> Vec<u8>) -> Result<bool, IntegratorError> {
        if steps < self.last_step + self.every {
            return Ok(false);
        }
        self.write_bytes(&make())?;
        self.last_step = steps;
        Ok(true)
    }

    /// Writes `checkpoint` now (atomically: temporary file, sync, rename).
    pub fn write(&mut self, checkpoint: &Checkpoint) -> Result<(), IntegratorError> {
        self.write_bytes(&checkpoint.to_bytes())
    }

    /// Writes `bytes` now, atomically (a run checkpoint of another format than [`Checkpoint`]).
    pub fn write_bytes(&mut self, bytes: &[u8]) -> Result<(), IntegratorError> {
        let tmp = self.path.with_extension("tmp");
        let result = (|| {
            let mut f = File::create(&tmp)?;
            f.write_all(bytes)?;
            f.sync_all()?;
            std::fs::rename(&tmp, &self.path)
        })();
        result.map_err(|e| io_err(&self.path, "cannot write checkpoint", e))?;
        self.written += 1;
        Ok(())
    }

    /// Checkpoints written so far.
    pub fn written(&self) -> usize {
        self.written
    }

    /// Reads the (implicit) checkpoint at `path`.
    pub fn read(path: impl AsRef<Path>) -> Result<Checkpoint, IntegratorError> {
        Checkpoint::from_bytes(&Self::read_bytes(path)?)
    }

    /// The raw bytes of the checkpoint at `path` (an implicit or an explicit one: their magics
    /// differ, see [`crate::slosh::SloshRun::resume_from_bytes`]).
    pub fn read_bytes(path: impl AsRef<Path>) -> Result<Vec<u8>, IntegratorError> {
        let path = path.as_ref();
        std::fs::read(path).map_err(|e| io_err(path, "cannot read checkpoint", e))
    }
}
