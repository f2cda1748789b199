//! Atomic writes that never lose data: every file spherecal writes goes to
//! a temporary file in the target's folder, is flushed, and is renamed
//! over the target, so a crash or a full disk never leaves a partial file.
//!
//! - A target that is a **symbolic link** is not replaced: the file it
//!   points to is written (atomically, in that file's folder).
//! - A target that exists and is **not a regular file** (a folder, a FIFO,
//!   a device such as `/dev/null`, a socket) is refused.
//! - [`refuse_inputs`] refuses an output that **is one of the command's
//!   inputs** (the same file by device and inode, whatever the path says).
//! - The temporary file is removed on every error path, and on SIGINT or
//!   SIGTERM by [`remove_pending`] (called by the program's signal
//!   handler); leftovers of a process that was killed outright are removed
//!   by the next write of the same file.

use std::fs;
use std::io::{self, Write as _};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

use super::FileError;

/// Symbolic links followed at most before a target is called a loop.
const MAX_LINKS: usize = 40;

/// Temporary files being written now, for [`remove_pending`].
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Replaces `path` with `bytes` atomically: the bytes go to a new temporary
/// file in the same directory, which is flushed to disk and then renamed
/// over `path` (the directory is synced afterwards where the platform
/// allows). On any error the temporary file is removed and `path` is left
/// as it was. An existing target's permissions are kept. A symbolic link
/// is followed to the file it names; a target that is not a regular file
/// is refused.
///
/// # Errors
/// [`FileError::Io`] with action "writing" and the target path.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    write_atomic_with(path, |file| file.write_all(bytes))
}

/// As [`write_atomic`], with the content streamed by `write` into the
/// temporary file (opened for reading and writing, so that a writer may
/// seek back and read, as an E57 writer does): a large output (a point
/// cloud) is never held in memory whole. An error of `write` removes the
/// temporary file and leaves `path` as it was.
///
/// # Errors
/// [`FileError::Io`] with action "writing" and the target path, carrying
/// `write`'s error when it failed.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut fs::File) -> io::Result<()>,
) -> Result<(), FileError> {
    let io_error = |source: io::Error| FileError::Io {
        action: "writing",
        path: path.to_path_buf(),
        source,
    };
    let target = resolve_links(path).map_err(io_error)?;
    check_target(&target).map_err(io_error)?;
    let Some(file_name) = target.file_name() else {
        return Err(io_error(io::Error::new(
            io::ErrorKind::InvalidInput,
            "the path does not name a file",
        )));
    };
    let dir = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    remove_stale(&dir, file_name);
    let (temp_path, mut file) = create_temp(&dir, file_name).map_err(io_error)?;
    let written = (|| {
        write(&mut file)?;
        if let Ok(meta) = fs::metadata(&target) {
            // Best effort: a read-only target stays read-only after a save.
            let _ = file.set_permissions(meta.permissions());
        }
        file.sync_all()?;
        drop(file);
        fs::rename(&temp_path, &target)
    })();
    if let Err(source) = written {
        // The temporary file is ours; if even this fails there is nothing
        // better to report than the original error.
        let _ = fs::remove_file(&temp_path);
        forget(&temp_path);
        return Err(io_error(source));
    }
    forget(&temp_path);
    sync_dir(&dir);
    Ok(())
}

/// `path` with every symbolic link of its last component followed (a
/// dangling link names the file to create).
fn resolve_links(path: &Path) -> io::Result<PathBuf> {
    let mut current = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        match fs::symlink_metadata(&current) {
            Ok(meta) if meta.file_type().is_symlink() => {
                let link = fs::read_link(&current)?;
                current = if link.is_absolute() {
                    link
                } else {
                    current
                        .parent()
                        .map_or_else(|| link.clone(), |dir| dir.join(&link))
                };
            }
            _ => return Ok(current),
        }
    }
    Err(io::Error::new(
        io::ErrorKind::InvalidInput,
        format!("more than {MAX_LINKS} symbolic links: a loop?"),
    ))
}

/// Refuses a target that exists and is not a regular file.
fn check_target(target: &Path) -> io::Result<()> {
    let Ok(meta) = fs::metadata(target) else {
        return Ok(());
    };
    let kind = file_kind(&meta);
    if kind == "a regular file" {
        Ok(())
    } else {
        Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} is {kind}, not a file to write", target.display()),
        ))
    }
}

/// What kind of file `meta` describes, for messages.
fn file_kind(meta: &fs::Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_file() {
        return "a regular file";
    }
    if t.is_dir() {
        return "a folder";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt as _;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    "not a regular file"
}

/// Whether `a` and `b` are the same existing file (Unix: device and
/// inode, so hard links, `..` and symbolic links are seen through; else
/// the canonical paths).
#[must_use]
pub fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt as _;
        match (fs::metadata(a), fs::metadata(b)) {
            (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        match (fs::canonicalize(a), fs::canonicalize(b)) {
            (Ok(x), Ok(y)) => x == y,
            _ => false,
        }
    }
}

/// Refuses an output that is one of `inputs` (see [`same_file`]): writing
/// it would destroy the input.
///
/// # Errors
/// [`FileError::Io`] naming the output and the input it is.
pub fn refuse_inputs(output: &Path, inputs: &[&Path]) -> Result<(), FileError> {
    match inputs.iter().find(|i| same_file(output, i)) {
        Some(input) => Err(FileError::Io {
            action: "writing",
            path: output.to_path_buf(),
            source: io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "the output is the input {} (the same file): it would be destroyed; choose another output",
                    input.display()
                ),
            ),
        }),
        None => Ok(()),
    }
}

/// Removes every temporary file being written now (a signal handler's
/// clean-up before the process exits). Safe to call at any time.
pub fn remove_pending() {
    let pending = match PENDING.lock() {
        Ok(p) => p.clone(),
        Err(poisoned) => poisoned.into_inner().clone(),
    };
    for p in pending {
        let _ = fs::remove_file(p);
    }
}

fn remember(temp: &Path) {
    if let Ok(mut p) = PENDING.lock() {
        p.push(temp.to_path_buf());
    }
}

fn forget(temp: &Path) {
    if let Ok(mut p) = PENDING.lock() {
        p.retain(|x| x != temp);
    }
}

/// Distinguishes temporary files of concurrent saves in one process.
static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// The temporary-file name of `file_name` for process `pid`, number `n`.
fn temp_name(file_name: &std::ffi::OsStr, pid: u32, n: u64) -> std::ffi::OsString {
    let mut name = std::ffi::OsString::from(".");
    name.push(file_name);
    name.push(format!(".{pid}.{n}.tmp"));
    name
}

/// Creates a new, empty temporary file next to the target (same directory,
/// hence same file system, so the rename is atomic), and remembers it for
/// [`remove_pending`].
fn create_temp(dir: &Path, file_name: &std::ffi::OsStr) -> io::Result<(PathBuf, fs::File)> {
    let mut last_error = None;
    for _ in 0..100 {
        let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
        let temp = dir.join(temp_name(file_name, std::process::id(), n));
        match fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create_new(true)
            .open(&temp)
        {
            Ok(file) => {
                remember(&temp);
                return Ok((temp, file));
            }
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last_error = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last_error.unwrap_or_else(|| io::Error::other("no free temporary file name")))
}

/// Removes temporary files of `file_name` left by processes that no longer
/// run (killed outright mid-write). Linux only (`/proc`); best effort.
fn remove_stale(dir: &Path, file_name: &std::ffi::OsStr) {
    if !Path::new("/proc/self").exists() {
        return;
    }
    let prefix = format!(".{}.", file_name.to_string_lossy());
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for entry in entries.filter_map(Result::ok) {
        let name = entry.file_name().to_string_lossy().into_owned();
        let Some(rest) = name
            .strip_prefix(&prefix)
            .and_then(|r| r.strip_suffix(".tmp"))
        else {
            continue;
        };
        let Some((pid, n)) = rest.split_once('.') else {
            continue;
        };
        let alive = Path::new("/proc").join(pid).exists();
        if !alive && pid.parse::<u32>().is_ok() && n.parse::<u64>().is_ok() {
            let _ = fs::remove_file(entry.path());
        }
    }
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

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn links_are_followed_and_special_files_refused() {
        let dir = tempfile_dir();
        let real = dir.join("real.json");
        fs::write(&real, "old").unwrap();
        #[cfg(unix)]
        {
            let link = dir.join("link.json");
            std::os::unix::fs::symlink("real.json", &link).unwrap();
            write_atomic(&link, b"new").unwrap();
            assert!(
                fs::symlink_metadata(&link)
                    .unwrap()
                    .file_type()
                    .is_symlink()
            );
            assert_eq!(fs::read_to_string(&real).unwrap(), "new");
            let e = write_atomic(Path::new("/dev/null"), b"x")
                .unwrap_err()
                .to_string();
            assert!(e.contains("a device"), "{e}");
        }
        let e = write_atomic(&dir, b"x").unwrap_err().to_string();
        assert!(e.contains("a folder"), "{e}");
        assert!(same_file(&real, &dir.join(".").join("real.json")));
        assert!(refuse_inputs(&real, &[&dir.join("real.json")]).is_err());
        assert!(refuse_inputs(&dir.join("other.json"), &[&real]).is_ok());
        // A stale temporary file of a dead process goes with the next write.
        let stale = dir.join(".real.json.999999999.0.tmp");
        fs::write(&stale, "partial").unwrap();
        write_atomic(&real, b"newer").unwrap();
        assert!(!stale.exists());
        let _ = fs::remove_dir_all(&dir);
    }

    fn tempfile_dir() -> PathBuf {
        let dir = std::env::temp_dir().join(format!(
            "spherecal-atomic-{}-{}",
            std::process::id(),
            TEMP_COUNTER.fetch_add(1, Ordering::Relaxed)
        ));
        fs::create_dir_all(&dir).unwrap();
        dir
    }
}
