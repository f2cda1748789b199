//! The real binary, run as a user runs it: one way for every test file.

use std::ffi::OsStr;
use std::process::{Command, Output};

/// A `Command` for the binary under test.
pub fn spherecal() -> Command {
    Command::new(env!("CARGO_BIN_EXE_spherecal"))
}

/// (exit status, stdout, stderr) of a finished run; the status is -1 when
/// a signal ended it.
pub fn outcome(o: &Output) -> (i32, String, String) {
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// Runs `spherecal args…`; returns (exit status, stdout, stderr).
pub fn run<S: AsRef<OsStr>>(args: &[S]) -> (i32, String, String) {
    outcome(&spherecal().args(args).output().unwrap())
}
