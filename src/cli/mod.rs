//! The command line (in progress).
pub mod simulate;
