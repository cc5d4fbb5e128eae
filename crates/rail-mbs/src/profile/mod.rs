//! Wheel and rail profiles (work in progress).
