//! The robot: the modified-DH model of FORMAT.md with forward kinematics
//! and its parameter Jacobians (paper eq. 1-2, the `J_i` of eq. 16), the
//! presets spherecal ships, multi-branch inverse kinematics for the
//! simulator and the planner, robot import from a URDF ([`urdf`]) or a
//! standard or modified DH table in CSV ([`dh_table`]), and the pose
//! conventions of robot controllers ([`controller`]).

pub mod chain_origins;
pub mod controller;
pub mod dh_table;
pub mod ik;
mod import_error;
pub mod kinematics;
pub mod presets;
pub mod urdf;

pub use dh_table::{DhConvention, robot_from_dh_csv};
pub use import_error::RobotImportError;
pub use kinematics::{
    Joint, JointLimit, PARAM_IS_ANGLE, PARAM_NAMES, PARAMS_PER_JOINT, Robot, pose_error,
};
pub use presets::{
    Preset, RobotChoice, TABLE1, irb120, irb2400, preset, presets, table1_errors, ur5e,
};
pub use urdf::{UrdfOptions, UrdfRobot, robot_from_urdf, robot_from_urdf_with};
