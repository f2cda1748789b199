//! The one capped reader: every file spherecal reads comes in through
//! [`read_bytes`] or [`read_text`], bounded by the bytes actually read
//! (`Read::take`), not by the size the file system reports. A FIFO or a
//! device (`/dev/zero`) reports 0 bytes and never ends, a file may grow
//! while it is read: each stops at the cap of its kind ([`Cap`]) instead
//! of filling memory. A regular file whose reported size is already
//! beyond the cap is refused unread.
//!
//! A refusal is an [`io::Error`] of kind [`io::ErrorKind::InvalidData`]
//! whose message names the cap; each reader's own error adds the file
//! (`reading failed: the file has more than the 256 MiB a session or
//! result file may have (/dev/zero)`).

use std::fs::File;
use std::io::{self, Read as _};
use std::path::Path;

use crate::engine::files::robot_import::dh_table::MAX_DH_BYTES;
use crate::engine::files::robot_import::urdf::MAX_URDF_BYTES;

/// The most bytes a kind of file may have, and the kind in words.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Cap {
    /// Bytes.
    pub bytes: u64,
    /// The kind, with its article: "a table".
    pub what: &'static str,
}

impl Cap {
    /// Session and result files, and the truth files of simulations
    /// (256 MiB): a stripe session of 124 measurements is 240 KB, so this
    /// leaves room for sessions a thousand times larger. A 4×4 transform
    /// file is read as one too (it may be a session or result whose
    /// `hand_eye` is taken).
    pub const SESSION: Self = Self {
        bytes: 256 << 20,
        what: "a session or result file",
    };

    /// Text tables (joint logs, profiles, profile tables, centres tables,
    /// reference distances, station lists; 512 MiB): a calibration's joint
    /// log is a few kB, a table of every profile of a thousand poses a
    /// hundred MB.
    pub const TABLE: Self = Self {
        bytes: 512 << 20,
        what: "a table",
    };

    /// Pose files and robot programs (256 MiB): a program of a hundred
    /// thousand targets is a few MB.
    pub const POSE_FILE: Self = Self {
        bytes: 256 << 20,
        what: "a pose file or robot program",
    };

    /// URDF robot descriptions ([`MAX_URDF_BYTES`]): meshes live in
    /// their own files.
    pub const URDF: Self = Self {
        bytes: MAX_URDF_BYTES,
        what: "a robot description",
    };

    /// DH tables ([`MAX_DH_BYTES`]): a row per joint.
    pub const DH_TABLE: Self = Self {
        bytes: MAX_DH_BYTES,
        what: "a DH table",
    };

    /// A file of a `history` library walk (64 MiB): the walk reads every
    /// JSON file of a folder tree, so a stray data dump is skipped early.
    pub const LIBRARY_FILE: Self = Self {
        bytes: 64 << 20,
        what: "a session or result file of a library",
    };

    /// The cap in words: "the 512 MiB a table may have".
    #[must_use]
    pub fn describe(self) -> String {
        format!("the {} MiB {} may have", self.bytes >> 20, self.what)
    }
}

/// The refusal of a file beyond `cap`; `size` when the file system told
/// it.
fn too_large(cap: Cap, size: Option<u64>) -> io::Error {
    let message = match size {
        Some(size) => format!("the file has {size} bytes, more than {}", cap.describe()),
        None => format!(
            "the file has more than {} (read up to the cap)",
            cap.describe()
        ),
    };
    io::Error::new(io::ErrorKind::InvalidData, message)
}

/// The bytes of `path`, at most `cap.bytes` of them.
///
/// # Errors
/// The file cannot be opened or read, or holds more than the cap
/// ([`io::ErrorKind::InvalidData`], naming the cap).
pub fn read_bytes(path: &Path, cap: Cap) -> io::Result<Vec<u8>> {
    let file = File::open(path)?;
    let meta = file.metadata()?;
    if meta.is_file() && meta.len() > cap.bytes {
        return Err(too_large(cap, Some(meta.len())));
    }
    let expected = if meta.is_file() { meta.len() } else { 0 };
    let mut bytes = Vec::with_capacity(usize::try_from(expected).unwrap_or(0));
    // One byte beyond the cap tells a file of exactly the cap from a
    // longer one.
    file.take(cap.bytes.saturating_add(1))
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > cap.bytes {
        return Err(too_large(cap, None));
    }
    Ok(bytes)
}

/// The UTF-8 text of `path`, at most `cap.bytes` bytes of it.
///
/// # Errors
/// As [`read_bytes`]; text that is not UTF-8
/// ([`io::ErrorKind::InvalidData`], as `std::fs::read_to_string` says it).
pub fn read_text(path: &Path, cap: Cap) -> io::Result<String> {
    String::from_utf8(read_bytes(path, cap)?).map_err(|_| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            "stream did not contain valid UTF-8",
        )
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    const SMALL: Cap = Cap {
        bytes: 10,
        what: "a test file",
    };

    #[test]
    fn a_file_within_the_cap_is_read_whole() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("ten.txt");
        std::fs::write(&path, "0123456789").unwrap();
        assert_eq!(read_text(&path, SMALL).unwrap(), "0123456789");
    }

    #[test]
    fn a_longer_file_is_refused_naming_its_size_and_the_cap() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("eleven.txt");
        std::fs::write(&path, "0123456789A").unwrap();
        let e = read_text(&path, SMALL).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::InvalidData);
        assert_eq!(
            e.to_string(),
            "the file has 11 bytes, more than the 0 MiB a test file may have"
        );
    }

    /// A device that never ends stops at the cap, whatever size the file
    /// system reports (0).
    #[cfg(unix)]
    #[test]
    fn an_endless_device_stops_at_the_cap() {
        let e = read_bytes(Path::new("/dev/zero"), SMALL).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("the file has more than the 0 MiB a test file may have"),
            "{e}"
        );
    }

    #[test]
    fn text_that_is_not_utf8_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("latin1.txt");
        std::fs::write(&path, b"caf\xe9").unwrap();
        assert_eq!(
            read_text(&path, SMALL).unwrap_err().kind(),
            io::ErrorKind::InvalidData
        );
    }
}
