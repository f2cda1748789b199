//! How far an import is, for a progress bar and a Cancel button: the
//! profiles read (thousands of files in a large session), the stripe side
//! decided by calibrating both, the session checked by the file rules.

use super::ImportError;
use crate::engine::base::control::Control;

/// A stage of an import.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImportStage {
    /// Profiles read, of all to read.
    Profiles {
        /// Read so far.
        done: usize,
        /// To read in all.
        total: usize,
    },
    /// The stripe side decided by calibrating the session both ways (a
    /// pose file that gives no side).
    Side,
    /// The session checked by the session file's rules.
    Checking,
}

impl ImportStage {
    /// The stage in words, e.g. `reading profiles: 120 of 9600`.
    #[must_use]
    pub fn describe(&self) -> String {
        match self {
            Self::Profiles { done, total } => format!("reading profiles: {done} of {total}"),
            Self::Side => "deciding the stripe side (calibrating both)".to_string(),
            Self::Checking => "checking the session".to_string(),
        }
    }
}

/// The callback of an import: told each stage; it may cancel.
pub type ImportProgress<'a> = dyn FnMut(ImportStage) -> Control + 'a;

/// Tells `progress` of `stage`.
///
/// # Errors
/// [`ImportError::Cancelled`] when the callback cancels.
pub fn report(progress: &mut ImportProgress<'_>, stage: ImportStage) -> Result<(), ImportError> {
    match progress(stage) {
        Control::Continue => Ok(()),
        Control::Cancel => Err(ImportError::Cancelled),
    }
}

/// A callback that never cancels, for the calls without progress.
#[must_use]
pub fn quiet(_: ImportStage) -> Control {
    Control::Continue
}
