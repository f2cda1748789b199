//! Where the nominal robot model of an import comes from: a preset, the
//! `robot` block of a session or result file, a URDF, or a DH table.

use std::path::{Path, PathBuf};

use super::ImportError;
use crate::engine::base::robot::{self, Robot};
use crate::engine::files::format::{Cap, parse_result, parse_session, read_text};
use crate::engine::files::robot_import::{
    DhConvention, RobotImportError, UrdfOptions, UrdfRobot, robot_from_dh_csv, robot_from_urdf_with,
};

/// A command-line or form value that names no robot source.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RobotSourceError {
    /// A DH table without its convention.
    #[error(
        "{0} is a DH table: say whether it is the standard or the modified convention (--dh standard|modified)"
    )]
    DhConvention(String),
}

/// The message, for the edges that show errors as text (the command
/// line's and the workbench's forms).
impl From<RobotSourceError> for String {
    fn from(e: RobotSourceError) -> Self {
        e.to_string()
    }
}

/// Where the nominal robot model comes from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum RobotSource {
    /// A preset key of [`robot::preset`] (`irb2400`, `irb120`, `ur5e`).
    Preset(String),
    /// The `robot` block of a session or result file.
    File(PathBuf),
    /// A URDF: the serial chain of revolute joints from its root link to
    /// `tip` (default: the chain's only end link), converted to FORMAT.md's
    /// modified DH ([`robot_import::urdf`](crate::engine::files::robot_import::urdf)).
    Urdf {
        /// The file.
        path: PathBuf,
        /// The tip link, e.g. `tool0`.
        tip: Option<String>,
    },
    /// A DH table (CSV, columns a, alpha, d, theta), standard or modified
    /// ([`robot_import::dh_table`](crate::engine::files::robot_import::dh_table)).
    DhTable {
        /// The file.
        path: PathBuf,
        /// The table's convention.
        convention: DhConvention,
    },
}

impl RobotSource {
    /// The source a command-line or form value names: a `.json` session
    /// or result file, a `.urdf`, a `.csv` DH table (with `convention`,
    /// which a DH table needs), else a preset key.
    ///
    /// # Errors
    /// [`RobotSourceError::DhConvention`]: a `.csv` without a DH
    /// convention.
    pub fn from_text(
        text: &str,
        tip: Option<String>,
        convention: Option<DhConvention>,
    ) -> Result<Self, RobotSourceError> {
        let path = Path::new(text);
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        Ok(match ext.as_str() {
            "json" => Self::File(path.to_path_buf()),
            "urdf" | "xml" => Self::Urdf {
                path: path.to_path_buf(),
                tip,
            },
            "csv" | "txt" => Self::DhTable {
                path: path.to_path_buf(),
                convention: convention
                    .ok_or_else(|| RobotSourceError::DhConvention(text.to_string()))?,
            },
            _ => Self::Preset(text.to_string()),
        })
    }
}

/// The nominal robot model of the spec.
///
/// # Errors
/// [`ImportError::Spec`] for an unknown preset, the loader's error for a
/// file that is neither a valid session nor a valid result file.
pub fn load_robot(source: &RobotSource) -> Result<Robot, ImportError> {
    match source {
        RobotSource::Preset(key) => robot::preset(key).map(|p| p.robot).ok_or_else(|| {
            let keys: Vec<&str> = robot::presets().iter().map(|p| p.key).collect();
            ImportError::Spec(format!(
                "unknown robot `{key}`, expected one of: {} or a session/result file, a URDF or a DH table",
                keys.join(", ")
            ))
        }),
        RobotSource::File(path) => {
            let text = read_text(path, Cap::SESSION).map_err(|source| ImportError::Io {
                path: path.clone(),
                source,
            })?;
            let no_robot = || ImportError::File {
                path: path.clone(),
                message: "the file has no robot model (a pose-only session or result)".into(),
            };
            match parse_session(&text, path) {
                Ok(s) if s.robot_given => Ok(s.robot),
                Ok(_) => Err(no_robot()),
                Err(session_error) => match parse_result(&text, path) {
                    Ok(r) => r.robot.ok_or_else(no_robot),
                    Err(_) => Err(ImportError::Session(session_error)),
                },
            }
        }
        RobotSource::Urdf { path, tip } => {
            let options = UrdfOptions {
                tip: tip.clone(),
                ..UrdfOptions::default()
            };
            load_urdf(path, &options)
                .map(|u| u.robot)
                .map_err(|e| ImportError::Robot(Box::new(e)))
        }
        RobotSource::DhTable { path, convention } => load_dh_csv(path, *convention)
            .map_err(|e| ImportError::Robot(Box::new(e))),
    }
}

/// Reads the URDF file at `path` (at most [`Cap::URDF`]) and takes its
/// chain ([`robot_from_urdf_with`]).
///
/// # Errors
/// [`RobotImportError::Io`] for a file that cannot be read or is beyond
/// the cap, or any error of [`robot_from_urdf_with`].
pub fn load_urdf(path: &Path, options: &UrdfOptions) -> Result<UrdfRobot, RobotImportError> {
    let text = read_text(path, Cap::URDF).map_err(|source| RobotImportError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    robot_from_urdf_with(&text, path, options)
}

/// Reads the DH table at `path` (at most [`Cap::DH_TABLE`]) as a robot
/// ([`robot_from_dh_csv`]).
///
/// # Errors
/// [`RobotImportError::Io`] for a file that cannot be read or is beyond
/// the cap, or any error of [`robot_from_dh_csv`].
pub fn load_dh_csv(path: &Path, convention: DhConvention) -> Result<Robot, RobotImportError> {
    let text = read_text(path, Cap::DH_TABLE).map_err(|source| RobotImportError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    robot_from_dh_csv(&text, path, convention)
}
