//! The error of the robot importers ([`urdf`](super::urdf) and
//! [`dh_table`](super::dh_table)): every variant names the file and, where
//! there is one, the joint, link or 1-based line that is wrong.

use std::path::PathBuf;

/// A robot description (URDF or DH table) could not be turned into a
/// [`Robot`](super::Robot).
#[derive(Debug, thiserror::Error)]
pub enum RobotImportError {
    /// The file could not be read at all.
    #[error("cannot read {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The URDF is not well-formed XML or breaks the URDF schema.
    #[error("{}: not a valid URDF: {message}", path.display())]
    UrdfSyntax {
        /// The file.
        path: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// The link tree does not give one serial chain (a branch without a
    /// chosen tip, an unknown tip link, a link with two parent joints, a
    /// joint naming an undeclared link, a loop, no moving joint at all).
    #[error("{}: {message}", path.display())]
    UrdfTree {
        /// The file.
        path: PathBuf,
        /// What is wrong, naming the links.
        message: String,
    },
    /// A joint of the chain cannot be part of the model (prismatic or
    /// other unsupported type, zero axis, mimic, empty limits).
    #[error("{}: joint `{joint}`: {message}", path.display())]
    UrdfJoint {
        /// The file.
        path: PathBuf,
        /// The joint's `name`.
        joint: String,
        /// What is wrong.
        message: String,
    },
    /// The chain has no moving joint, or a different number than the
    /// caller asked for.
    #[error(
        "{}: the chain from `{root}` to `{tip}` has {found} moving joints ({}), expected {}",
        path.display(),
        if joints.is_empty() { "none".to_owned() } else { joints.join(", ") },
        expected.map_or_else(|| "at least 1".to_owned(), |n| n.to_string())
    )]
    JointCount {
        /// The file.
        path: PathBuf,
        /// The root link.
        root: String,
        /// The tip link.
        tip: String,
        /// The moving joints found, root to tip.
        joints: Vec<String>,
        /// Number of moving joints found.
        found: usize,
        /// Number asked for; `None`: any number from 1 up.
        expected: Option<usize>,
    },
    /// A line of a DH table is wrong (header or row).
    #[error("{}, line {line}: {message}", path.display())]
    DhLine {
        /// The file.
        path: PathBuf,
        /// 1-based line number in the file.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The DH table as a whole is wrong (empty file, no rows).
    #[error("{}: {message}", path.display())]
    DhTable {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}
