//! The robot: the modified-DH model of FORMAT.md with forward kinematics
//! and its parameter Jacobians (paper eq. 1-2, the `J_i` of eq. 16), the
//! presets spherecal ships, multi-branch inverse kinematics for the
//! simulator and the planner, and the pose conventions of robot
//! controllers ([`controller`]). A URDF or a DH table is read into this
//! model by [`crate::engine::files::robot_import`].

pub mod chain_origins;
pub mod controller;
pub mod ik;
pub mod kinematics;
pub mod presets;

pub use kinematics::{
    Joint, JointLimit, PARAM_IS_ANGLE, PARAM_NAMES, PARAMS_PER_JOINT, Robot, pose_error,
};
pub use presets::{
    Preset, RobotChoice, TABLE1, irb120, irb2400, preset, presets, table1_errors, ur5e,
};
