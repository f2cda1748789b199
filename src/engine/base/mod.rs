//! Layer 1, the ground every later layer stands on: numbers and frames,
//! the CSV reader, plausibility limits, the robot's modified-DH model and
//! the in-memory session. Nothing here knows how a calibration is made.
//!
//! | unit | holds |
//! |---|---|
//! | [`numeric`] | rounding, medians, shared numeric helpers |
//! | [`control`] | what a long job's progress callback answers (go on, cancel) |
//! | [`geometry`] | rigid transforms, twists, roll/pitch/yaw |
//! | [`table`] | CSV tables as the engine reads them (line numbers for messages) |
//! | [`limits`] | physical plausibility limits of a session's numbers |
//! | [`robot`] | the MDH model, forward kinematics and Jacobians (eq. 1-2, 16), presets, inverse kinematics, URDF and DH tables |
//! | [`session`] | the in-memory session every function takes, its rules, leaving measurements out |
//! | [`cell`] | what the simulator, the planner and compensation share about a cell: sensor, workspace, approach cones, joint logs, configuration branches, seeded streams |

pub mod numeric;
pub mod control;
pub mod geometry;
pub mod limits;
pub mod robot;
pub mod session;
pub mod records;
pub mod cell;
