//! Sparse implicit HHT-α integrator (work in progress).
