//! The record of the loop of FORMAT.md "The iteration" (threshold, most
//! updates, why it stopped), as every method's report carries it: its own
//! file, so that the solver block ([`report`](super::report)) and `ml`'s
//! report ([`ml`](super::ml)) both use it without using each other.

use serde::{Deserialize, Serialize};

/// The loop of FORMAT.md "The iteration" as a result records it.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct LoopRecord {
    /// Threshold on ε, mm.
    pub threshold: f64,
    /// Most updates.
    pub max_iterations: usize,
    /// Stop code (`threshold`, `converged`, `max_iterations`, `cancelled`).
    pub stop: String,
    /// Why the loop stopped, in words, with ε beside the threshold.
    pub stop_reason: String,
}
