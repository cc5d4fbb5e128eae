//! Track geometry (work in progress).
