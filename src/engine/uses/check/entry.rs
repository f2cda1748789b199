//! The re-check in one entry, [`check_file`], that the command line
//! calls: the check session read (a session as it is, or a session
//! file) and checked against a result ([`check_session`]).

use std::path::PathBuf;

use super::{CheckError, Checked, check_session};
use crate::engine::base::session::Session;
use crate::engine::files::format::{self, ResultFile};

/// The check's scan.
#[derive(Debug, Clone)]
pub enum CheckSource {
    /// A session as it is.
    Session(Box<Session>),
    /// A session file.
    SessionFile(PathBuf),
}

/// Everything a check needs.
#[derive(Debug, Clone)]
pub struct CheckRequest {
    /// The check's scan.
    pub scan: CheckSource,
    /// The result it is checked against.
    pub result: ResultFile,
    /// The false-alarm rate.
    pub alpha: f64,
}

/// Reads the request's session and checks it (module doc); the session
/// with the verdict.
///
/// # Errors
/// A session that cannot be read (naming the file), or what
/// [`check_session`] refuses.
pub fn check_file(request: CheckRequest) -> Result<(Session, Checked), CheckError> {
    let session = match request.scan {
        CheckSource::Session(s) => *s,
        CheckSource::SessionFile(path) => format::load_session(&path)?,
    };
    let checked = check_session(&session, &request.result, request.alpha)?;
    Ok((session, checked))
}
