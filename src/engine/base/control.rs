//! What a progress callback answers, for every long job of the engine
//! (the solver, an import, a plan, a measurement): one type, so that the
//! lower layers (the file readers) and the solver share it without the
//! readers depending on the solver.

/// What the progress callback asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Control {
    /// Go on.
    Continue,
    /// Stop now: the job ends as cancelled (the solver's
    /// `StopReason::Cancelled`, an import's `ImportError::Cancelled`).
    Cancel,
}
