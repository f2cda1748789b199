//! The library of a folder: every session and result file found (8 levels
//! deep), each result paired with its session, dated, and read into an
//! [`Entry`].

use std::collections::HashSet;
use std::fs;
use std::path::{Path, PathBuf};
use std::time::SystemTime;

use serde::Deserialize;
use serde::de::IgnoredAny;
use serde_json::Value;

use super::entry::build_entry;
use super::{
    CheckEntry, DateSource, HistoryError, Library, MAX_DEPTH, PairedBy, Problem, RESULT_SUFFIXES,
    SessionInfo, Timestamp, date_in_name,
};
use crate::engine::files::format::FileError;
use crate::engine::files::format::{
    self, CHECK_FORMAT, CheckRecord, RESULT_FORMAT, ResultFile, SESSION_FORMAT,
};

/// Scans `folder` for session and result files (see the module docs).
///
/// # Errors
/// [`HistoryError::Folder`] when the folder cannot be read,
/// [`HistoryError::NotAFolder`] when it is a file. Bad files are
/// [`Library::problems`], never an error.
pub fn read_library(folder: &Path) -> Result<Library, HistoryError> {
    let meta = fs::metadata(folder).map_err(|source| HistoryError::Folder {
        path: folder.to_path_buf(),
        source,
    })?;
    if !meta.is_dir() {
        return Err(HistoryError::NotAFolder {
            path: folder.to_path_buf(),
        });
    }
    let mut files = Vec::new();
    let mut problems = Vec::new();
    let top = fs::read_dir(folder).map_err(|source| HistoryError::Folder {
        path: folder.to_path_buf(),
        source,
    })?;
    let mut visited: HashSet<PathBuf> = fs::canonicalize(folder).into_iter().collect();
    walk(top, folder, 0, &mut visited, &mut files, &mut problems);
    files.sort();

    let mut results: Vec<(PathBuf, ResultFile, Option<SystemTime>)> = Vec::new();
    let mut sessions: Vec<(SessionInfo, Option<SystemTime>)> = Vec::new();
    let mut ignored = Vec::new();
    let mut checks = Vec::new();
    for path in files {
        match read_file(&path) {
            Ok(Found::Session {
                name,
                robot,
                measurements,
                modified,
            }) => {
                let (date, date_source) = session_date(&name, &path, modified);
                sessions.push((
                    SessionInfo {
                        path,
                        name,
                        robot,
                        measurements,
                        date,
                        date_source,
                        results: Vec::new(),
                    },
                    modified,
                ));
            }
            Ok(Found::Result { result, modified }) => results.push((path, *result, modified)),
            Ok(Found::Check { record, modified }) => {
                let date = date_in_name(&record.date)
                    .or_else(|| modified.and_then(Timestamp::from_system_time))
                    .unwrap_or_else(epoch);
                checks.push(CheckEntry {
                    path,
                    date,
                    record: *record,
                });
            }
            Ok(Found::Other(format)) => ignored.push((path, format)),
            Err(message) => problems.push(Problem { path, message }),
        }
    }

    let mut entries = Vec::new();
    for (path, result, modified) in results {
        let (session_index, paired_by, mut notes) = pair(&path, &result, &sessions);
        let session = session_index.map(|i| &sessions[i]);
        let (date, date_source) = entry_date(&result, &path, modified, session);
        if let Some((s, _)) = session {
            if s.robot != result.robot_name() {
                notes.push(format!(
                    "the session file's robot is {:?}, the result's {:?}",
                    s.robot,
                    result.robot_name()
                ));
            }
            if paired_by == Some(PairedBy::FileName) && s.name != result.session {
                notes.push(format!(
                    "the session file is named {:?}, the result says {:?}",
                    s.name, result.session
                ));
            }
        }
        match build_entry(
            path.clone(),
            &result,
            session.map(|(s, _)| s.path.clone()),
            paired_by,
            date,
            date_source,
            notes,
        ) {
            Ok(entry) => entries.push((entry, session_index)),
            Err(message) => problems.push(Problem { path, message }),
        }
    }
    entries.sort_by(|(a, _), (b, _)| a.date.cmp(&b.date).then_with(|| a.path.cmp(&b.path)));
    let mut sessions: Vec<SessionInfo> = sessions.into_iter().map(|(s, _)| s).collect();
    for (i, (_, s)) in entries.iter().enumerate() {
        if let Some(s) = s {
            sessions[*s].results.push(i);
        }
    }
    problems.sort_by(|a, b| a.path.cmp(&b.path));
    checks.sort_by(|a: &CheckEntry, b| a.date.cmp(&b.date).then_with(|| a.path.cmp(&b.path)));
    Ok(Library {
        checks,
        root: folder.to_path_buf(),
        entries: entries.into_iter().map(|(e, _)| e).collect(),
        sessions,
        problems,
        ignored,
    })
}

/// Collects `*.json` files below `dir` (already opened), depth-first.
/// Symbolic links are followed, to files and to folders; `visited` holds
/// the real path of every folder entered, so a link back to a folder
/// already scanned (a loop, or a second way to the same folder) is
/// reported once as a problem instead of being scanned again.
pub(super) fn walk(
    read: fs::ReadDir,
    dir: &Path,
    depth: usize,
    visited: &mut HashSet<PathBuf>,
    files: &mut Vec<PathBuf>,
    problems: &mut Vec<Problem>,
) {
    for item in read {
        let item = match item {
            Ok(i) => i,
            Err(e) => {
                problems.push(Problem {
                    path: dir.to_path_buf(),
                    message: format!("cannot list the folder: {e}"),
                });
                continue;
            }
        };
        let path = item.path();
        let name = item.file_name();
        let name = name.to_string_lossy();
        if name.starts_with('.') {
            continue;
        }
        // `metadata` follows a symbolic link to what it points to.
        let meta = match fs::metadata(&path) {
            Ok(m) => m,
            Err(e) => {
                let linked = item.file_type().is_ok_and(|t| t.is_symlink());
                problems.push(Problem {
                    path,
                    message: if linked {
                        format!("a link to nothing readable: {e}")
                    } else {
                        format!("cannot read the file type: {e}")
                    },
                });
                continue;
            }
        };
        if meta.is_dir() {
            if depth + 1 > MAX_DEPTH {
                problems.push(Problem {
                    path,
                    message: format!("not scanned: deeper than {MAX_DEPTH} folder levels"),
                });
                continue;
            }
            let real = fs::canonicalize(&path).unwrap_or_else(|_| path.clone());
            if !visited.insert(real.clone()) {
                problems.push(Problem {
                    path,
                    message: format!(
                        "not scanned again: a link to {}, which is already scanned",
                        real.display()
                    ),
                });
                continue;
            }
            match fs::read_dir(&path) {
                Ok(sub) => walk(sub, &path, depth + 1, visited, files, problems),
                Err(e) => problems.push(Problem {
                    path,
                    message: format!("cannot read the folder: {e}"),
                }),
            }
        } else if meta.is_file() && name.to_ascii_lowercase().ends_with(".json") {
            files.push(path);
        }
    }
}

/// What one file is.
pub(super) enum Found {
    Session {
        name: String,
        robot: String,
        measurements: usize,
        modified: Option<SystemTime>,
    },
    Result {
        result: Box<ResultFile>,
        modified: Option<SystemTime>,
    },
    Check {
        record: Box<CheckRecord>,
        modified: Option<SystemTime>,
    },
    Other(Option<String>),
}

/// Only the `format` key; everything else is skipped unparsed.
#[derive(Deserialize)]
pub(super) struct Header {
    #[serde(default)]
    format: Option<Value>,
}

pub(super) fn read_file(path: &Path) -> Result<Found, String> {
    let meta = fs::metadata(path).map_err(|e| format!("cannot read the file: {e}"))?;
    if meta.is_dir() {
        return Ok(Found::Other(None));
    }
    let modified = meta.modified().ok();
    let text = format::read_text(path, format::Cap::LIBRARY_FILE)
        .map_err(|e| format!("cannot read the file: {e}"))?;
    // A UTF-8 byte-order mark (Windows editors) is not part of the JSON;
    // the session and result readers skip it too.
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let format = if text.trim_start().starts_with('{') {
        serde_json::from_str::<Header>(text)
            .map_err(|e| format!("not valid JSON: {e}"))?
            .format
    } else {
        // Valid JSON that is not an object (an array, a number) is not ours.
        serde_json::from_str::<IgnoredAny>(text).map_err(|e| format!("not valid JSON: {e}"))?;
        None
    };
    match format.as_ref().and_then(Value::as_str) {
        Some(SESSION_FORMAT) => {
            let s = format::parse_session(text, path).map_err(|e| file_error_message(&e))?;
            Ok(Found::Session {
                name: s.name,
                robot: if s.robot_given {
                    s.robot.name
                } else {
                    crate::engine::files::format::result::NO_ROBOT.to_string()
                },
                measurements: s.measurements.len(),
                modified,
            })
        }
        Some(RESULT_FORMAT) => {
            let result = format::parse_result(text, path).map_err(|e| file_error_message(&e))?;
            Ok(Found::Result {
                result: Box::new(result),
                modified,
            })
        }
        Some(CHECK_FORMAT) => {
            let record =
                format::parse_check_record(text, path).map_err(|e| file_error_message(&e))?;
            Ok(Found::Check {
                record: Box::new(record),
                modified,
            })
        }
        Some(other) => Ok(Found::Other(Some(other.to_string()))),
        None => Ok(Found::Other(None)),
    }
}

/// A file error's message without its path (a [`Problem`] has the path).
pub(super) fn file_error_message(e: &FileError) -> String {
    match e {
        FileError::Io { action, source, .. } => format!("{action} failed: {source}"),
        FileError::Invalid {
            measurement,
            message,
            ..
        } => match measurement {
            Some(m) => format!("measurement {m}: {message}"),
            None => message.clone(),
        },
    }
}

/// `X` for a result file `X.result.json` (also `-result`, `_result`).
pub(super) fn result_stem(path: &Path) -> Option<String> {
    let name = path.file_name()?.to_string_lossy().into_owned();
    let stem = strip_json(&name)?;
    RESULT_SUFFIXES
        .iter()
        .find_map(|s| stem.strip_suffix(s))
        .map(str::to_string)
}

pub(super) fn strip_json(name: &str) -> Option<&str> {
    let n = name.len();
    (n >= 5 && name.is_char_boundary(n - 5) && name[n - 5..].eq_ignore_ascii_case(".json"))
        .then(|| &name[..n - 5])
}

/// The session of a result: by file name, else by session name.
pub(super) fn pair(
    path: &Path,
    result: &ResultFile,
    sessions: &[(SessionInfo, Option<SystemTime>)],
) -> (Option<usize>, Option<PairedBy>, Vec<String>) {
    let dir = path.parent();
    if let Some(stem) = result_stem(path) {
        let found = sessions.iter().position(|(s, _)| {
            s.path.parent() == dir
                && s.path
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .as_deref()
                    .and_then(strip_json)
                    == Some(stem.as_str())
        });
        if let Some(i) = found {
            return (Some(i), Some(PairedBy::FileName), Vec::new());
        }
    }
    let named: Vec<usize> = sessions
        .iter()
        .enumerate()
        .filter(|(_, (s, _))| s.name == result.session)
        .map(|(i, _)| i)
        .collect();
    let here: Vec<usize> = named
        .iter()
        .copied()
        .filter(|&i| sessions[i].0.path.parent() == dir)
        .collect();
    let chosen = match (here.as_slice(), named.as_slice()) {
        ([one], _) | ([], [one]) => Some(*one),
        _ => None,
    };
    match chosen {
        Some(i) => (Some(i), Some(PairedBy::SessionName), Vec::new()),
        None if named.len() > 1 => (
            None,
            None,
            vec![format!(
                "{} session files are named {:?}; none was chosen",
                named.len(),
                result.session
            )],
        ),
        None => (None, None, Vec::new()),
    }
}

pub(super) fn file_name_date(path: &Path) -> Option<Timestamp> {
    date_in_name(&path.file_name()?.to_string_lossy())
}

pub(super) fn session_date(
    name: &str,
    path: &Path,
    modified: Option<SystemTime>,
) -> (Timestamp, DateSource) {
    if let Some(d) = date_in_name(name) {
        return (d, DateSource::SessionName);
    }
    if let Some(d) = file_name_date(path) {
        return (d, DateSource::FileName);
    }
    match modified.and_then(Timestamp::from_system_time) {
        Some(d) => (d, DateSource::SessionModified),
        None => (epoch(), DateSource::Unknown),
    }
}

pub(super) fn epoch() -> Timestamp {
    Timestamp {
        year: 1970,
        month: 1,
        day: 1,
        hour: 0,
        minute: 0,
        second: 0,
        has_time: false,
    }
}

pub(super) fn entry_date(
    result: &ResultFile,
    path: &Path,
    modified: Option<SystemTime>,
    session: Option<&(SessionInfo, Option<SystemTime>)>,
) -> (Timestamp, DateSource) {
    if let Some(d) = date_in_name(&result.session) {
        return (d, DateSource::SessionName);
    }
    if let Some(d) =
        file_name_date(path).or_else(|| session.and_then(|(s, _)| file_name_date(&s.path)))
    {
        return (d, DateSource::FileName);
    }
    if let Some(d) = session
        .and_then(|(_, m)| *m)
        .and_then(Timestamp::from_system_time)
    {
        return (d, DateSource::SessionModified);
    }
    match modified.and_then(Timestamp::from_system_time) {
        Some(d) => (d, DateSource::ResultModified),
        None => (epoch(), DateSource::Unknown),
    }
}
