//! Atomic writes: every file spherecal writes goes to a temporary file in
//! the target's folder, is flushed, and is renamed over the target, so a
//! crash or a full disk never leaves a partial file.

use std::fs;
use std::io::{self, Write as _};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use super::FileError;

/// Replaces `path` with `bytes` atomically: the bytes go to a new temporary
/// file in the same directory, which is flushed to disk and then renamed
/// over `path` (the directory is synced afterwards where the platform
/// allows). On any error the temporary file is removed and `path` is left
/// as it was. An existing target's permissions are kept.
///
/// # Errors
/// [`FileError::Io`] with action "writing" and the target path.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    let io_error = |source: io::Error| FileError::Io {
        action: "writing",
        path: path.to_path_buf(),
        source,
    };
    let Some(file_name) = path.file_name() else {
        return Err(io_error(io::Error::new(
            io::ErrorKind::InvalidInput,
            "the path does not name a file",
        )));
    };
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let (temp_path, mut file) = create_temp(dir, file_name).map_err(io_error)?;
    let written = (|| {
        file.write_all(bytes)?;
        if let Ok(meta) = fs::metadata(path) {
            // Best effort: a read-only target stays read-only after a save.
            let _ = file.set_permissions(meta.permissions());
        }
        file.sync_all()?;
        drop(file);
        fs::rename(&temp_path, path)
    })();
    if let Err(source) = written {
        // The temporary file is ours; if even this fails there is nothing
        // better to report than the original error.
        let _ = fs::remove_file(&temp_path);
        return Err(io_error(source));
    }
    sync_dir(dir);
    Ok(())
}

/// Distinguishes temporary files of concurrent saves in one process.
static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// Creates a new, empty temporary file next to the target (same directory,
/// hence same file system, so the rename is atomic).
fn create_temp(dir: &Path, file_name: &std::ffi::OsStr) -> io::Result<(PathBuf, fs::File)> {
    let mut last_error = None;
    for _ in 0..100 {
        let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
        let mut name = std::ffi::OsString::from(".");
        name.push(file_name);
        name.push(format!(".{}.{n}.tmp", std::process::id()));
        let temp = dir.join(name);
        match fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&temp)
        {
            Ok(file) => return Ok((temp, file)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last_error = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last_error.unwrap_or_else(|| io::Error::other("no free temporary file name")))
}

/// Makes the rename durable (Unix); best effort, the file is already in place.
fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    if let Ok(d) = fs::File::open(dir) {
        let _ = d.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}
