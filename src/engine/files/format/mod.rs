//! The files of FORMAT.md: session and result files (strict loading that
//! names every broken rule and where, exact pretty writing), the capped
//! read every input of spherecal comes in by, and the atomic write every
//! output goes through.

use std::path::PathBuf;

pub mod atomic;
pub mod check_record;
mod json;
mod layout;
pub mod read;
pub mod result;
mod result_check;
pub mod session;
pub mod stations;
pub mod transform;

pub use atomic::{
    Folders, can_write_in, check_outputs, interrupted, refuse_inputs, remove_pending, same_file,
    write_all_atomic, write_atomic, write_atomic_with, written,
};
pub use check_record::{
    CHECK_FORMAT, CheckCentre, CheckRecord, check_record_path, load_check_record,
    parse_check_record, save_check_record,
};
pub use read::{Cap, read_bytes, read_text};
pub use result::{
    ResultFile, load_result, parse_result, result_text_checked, result_to_json, save_result,
    solver_block,
};
pub use session::{load_session, parse_session, save_session, session_to_json};
pub use transform::{TransformError, read_transform, read_typed_transform};

/// The `format` of a session file.
pub const SESSION_FORMAT: &str = "spherecal-session";
/// The `format` of a result file.
pub const RESULT_FORMAT: &str = "spherecal-result";
/// The file-format version this build reads and writes (session and result).
pub const FORMAT_VERSION: u32 = 1;

/// A session or result file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    /// The file could not be read or written at all.
    #[error("{action} failed: {source} ({path})")]
    Io {
        /// "reading" or "writing".
        action: &'static str,
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file's content breaks a rule of FORMAT.md.
    #[error("{}{message} ({path})", measurement.as_ref().map(|m| format!("measurement {m}: ")).unwrap_or_default())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// Id of the offending measurement, when the problem is in one.
        measurement: Option<String>,
        /// What is wrong.
        message: String,
    },
}

impl FileError {
    /// The measurement id the error names, if any.
    #[must_use]
    pub fn measurement(&self) -> Option<&str> {
        match self {
            Self::Invalid { measurement, .. } => measurement.as_deref(),
            Self::Io { .. } => None,
        }
    }
}
