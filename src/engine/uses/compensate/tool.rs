//! The TCP compensation works with: a tool file's `flange_from_tcp`
//! ([`read_tool`]). Its tool data in each controller's own syntax, so that
//! the nominal controller computes the flange pose of a compensated
//! target exactly as the compensation assumed, is the controller's
//! ([`Controller::tool_data`](crate::engine::base::robot::controller::Controller::tool_data)).

use std::path::Path;

use nalgebra::Isometry3;

use crate::engine::files::format::read_transform;

/// Reads a tool `flange_from_tcp` from a JSON file: a 4×4 matrix (rows,
/// mm), alone or under the key `flange_from_tcp`
/// ([`read_transform`], with its plausibility caps).
///
/// # Errors
/// A message naming the file and what is wrong.
pub fn read_tool(path: &Path) -> Result<Isometry3<f64>, String> {
    read_transform(path, "flange_from_tcp").map_err(|e| format!("tool {}: {e}", path.display()))
}
