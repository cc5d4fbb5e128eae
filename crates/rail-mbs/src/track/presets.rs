//! Named tracks of the papers: Table 1 of seed 000 (two opposite 3° curves with spirals and
//! 3 in super-elevation, 2800 ft), the track of the crude-oil studies' curving runs and of the
//! train benchmark. Python's scene preset `table1` (`railslosh.scene.track`) holds the same
//! rows. Moved here from the studies when they left the library (issue 18).

use std::sync::Arc;

use ancf_core::error::{Result, invalid};

use super::{FOOT, Track, TrackPoint};

/// Seed 000 Table 1 track: (distance ft, curvature degrees, super-elevation in).
pub const TABLE1_ROWS: [(f64, f64, f64); 10] = [
    (0.0, 0.0, 0.0),
    (100.0, 0.0, 0.0),
    (300.0, 3.0, 3.0),
    (600.0, 3.0, 3.0),
    (800.0, 0.0, 0.0),
    (1000.0, 0.0, 0.0),
    (1200.0, -3.0, -3.0),
    (1500.0, -3.0, -3.0),
    (1700.0, 0.0, 0.0),
    (2800.0, 0.0, 0.0),
];

/// Seed 000 Table 1 track (US units).
pub fn table1() -> Result<Arc<Track>> {
    let pts = TABLE1_ROWS.iter().map(|&(d, c, e)| TrackPoint::from_us(d, c, e, 0.0, 0.025, -0.025)).collect();
    Track::new(pts).map(Arc::new).map_err(|e| invalid("track", e, "valid"))
}

/// End of the body (constant curvature) of the first Table 1 curve, m.
pub const TABLE1_BODY_END: f64 = TABLE1_ROWS[3].0 * FOOT;
