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
