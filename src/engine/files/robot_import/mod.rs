//! Robot models from outside formats: a URDF ([`urdf`]) or a standard or
//! modified DH table in CSV ([`dh_table`]) read into the modified-DH model
//! of [`crate::engine::base::robot`], with the typed error both give
//! ([`RobotImportError`]).

pub mod dh_table;
mod error;
pub mod urdf;

pub use dh_table::{DhConvention, robot_from_dh_csv};
pub use error::RobotImportError;
pub use urdf::{UrdfOptions, UrdfRobot, robot_from_urdf, robot_from_urdf_with};
