//! Wheel/rail contact (work in progress).
