//! The TCP compensation works with: a tool file's `flange_from_tcp`
//! ([`read_tool`]). Its tool data in each controller's own syntax, so that
//! the nominal controller computes the flange pose of a compensated
//! target exactly as the compensation assumed, is the controller's
//! ([`Controller::tool_data`](crate::engine::base::robot::controller::Controller::tool_data)).

use std::path::{Path, PathBuf};

use nalgebra::Isometry3;

use crate::engine::files::format::{TransformError, read_transform};

/// A tool file that gives no tool: the file and why.
#[derive(Debug, thiserror::Error)]
#[error("tool {}: {source}", path.display())]
pub struct ToolError {
    /// The file.
    pub path: PathBuf,
    /// Why.
    pub source: TransformError,
}

/// The message, for the edges that show errors as text (the command
/// line, the workbench's job).
impl From<ToolError> for String {
    fn from(e: ToolError) -> Self {
        e.to_string()
    }
}

/// Reads a tool `flange_from_tcp` from a JSON file: a 4×4 matrix (rows,
/// mm), alone or under the key `flange_from_tcp`
/// ([`read_transform`], with its plausibility caps).
///
/// # Errors
/// [`ToolError`], naming the file and what is wrong.
pub fn read_tool(path: &Path) -> Result<Isometry3<f64>, ToolError> {
    read_transform(path, "flange_from_tcp").map_err(|source| ToolError {
        path: path.to_path_buf(),
        source,
    })
}
