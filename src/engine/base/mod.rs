//! Layer 1, the ground every later layer stands on: numbers and frames,
//! plausibility limits, the robot's modified-DH model, the in-memory
//! session and what a calibration records. Nothing here reads a file or
//! knows how a calibration is made.
//!
//! | unit | holds |
//! |---|---|
//! | [`numeric`] | rounding, medians, shared numeric helpers |
//! | [`control`] | what a long job's progress callback answers (go on, cancel) |
//! | [`geometry`] | rigid transforms, twists, roll/pitch/yaw |
//! | [`limits`] | physical plausibility limits of a session's numbers |
//! | [`robot`] | the MDH model, forward kinematics and Jacobians (eq. 1-2, 16), presets, inverse kinematics, controllers' pose conventions |
//! | [`session`] | the in-memory session every function takes, its rules, leaving measurements out |
//! | [`records`] | what a calibration records, as the result file stores it: the solver's report, the validation, the held-out figure |
//! | [`cell`] | what the simulator, the planner and compensation share about a cell: sensor, workspace, approach cones, joint logs, configuration branches, seeded streams |

pub mod numeric;
pub mod control;
pub mod geometry;
pub mod limits;
pub mod robot;
pub mod session;
pub mod records;
pub mod cell;
