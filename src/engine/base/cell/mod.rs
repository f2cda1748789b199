//! The cell: what the simulator and the pose planner share about a real
//! robot cell — the workspace box and station layouts per preset, approach
//! cones and flange orientations, the branch a cell teaches, the paper's
//! sensor mount, the seeded random streams, and the joint-log CSV that
//! goes to and from a controller.

pub mod approach;
pub mod branch;
pub mod joint_log;
pub mod random;
pub mod sensor;
pub mod workspace;

/// A station that no candidate pose reaches: the simulator's and the
/// planner's one refusal of a sphere out of reach.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "station {station} at [{:.1}, {:.1}, {:.1}] mm (base) is out of reach: {why}",
    position[0], position[1], position[2]
)]
pub struct Unreachable {
    /// Station id (and the pose, when one pose of a path failed).
    pub station: String,
    /// Its position, base frame, mm.
    pub position: [f64; 3],
    /// Flange orientations tried.
    pub orientations: usize,
    /// What was tried and what to change, in words.
    pub why: String,
}
