//! Atomic writes that never lose data: every file spherecal writes goes to
//! a temporary file in the target's folder, is flushed, and is renamed
//! over the target, so a crash or a full disk never leaves a partial file.
//! A command with several outputs writes them as one transaction
//! ([`write_all_atomic`]): all of them or none.
//!
//! - A target that is a **symbolic link** is not replaced: the file it
//!   points to is written (atomically, in that file's folder).
//! - A target that exists and is **not a regular file** (a folder, a FIFO,
//!   a device such as `/dev/null`, a socket) is refused, and so is a
//!   **read-only** one (no write permission bit, whoever runs spherecal,
//!   root included; or not writable by the user who does).
//! - [`refuse_inputs`] refuses an output that **is one of the command's
//!   inputs** (the same file by device and inode, whatever the path says);
//!   [`check_outputs`] lets a command refuse its outputs before any work.
//! - The temporary files, and the folders a write created, are removed on
//!   every error path, and on SIGINT, SIGTERM or SIGHUP by
//!   [`remove_pending`] (called by the program's signal handler, which
//!   then exits with 130; a write that has not yet renamed its files then
//!   renames none, and reports [`io::ErrorKind::Interrupted`]). Each is
//!   created and recorded under one lock, so no signal falls between the
//!   two. SIGPIPE is ignored by the Rust runtime: a closed reader is an
//!   error of the write to it, not a kill.
//!   Leftovers of a process that was killed outright (a dead process id in
//!   their name) are removed by the next write into the same folder.

use std::collections::HashMap;
use std::fs;
use std::io::{self, Write as _};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

use super::FileError;

/// Symbolic links followed at most before a target is called a loop.
const MAX_LINKS: usize = 40;

/// What a write under way has made and not yet committed: its temporary
/// files and the folders it created for its outputs.
struct Pending {
    /// Temporary files being written now.
    files: Vec<PathBuf>,
    /// Folders created for outputs not yet renamed into them, outermost
    /// first.
    folders: Vec<PathBuf>,
}

/// What [`remove_pending`] removes. Its lock is held while a temporary
/// file or a folder is created and recorded (so a signal never falls
/// between the two), and while a write renames its files (so a signal's
/// clean-up and a rename never interleave).
static PENDING: Mutex<Pending> = Mutex::new(Pending {
    files: Vec::new(),
    folders: Vec::new(),
});

/// Every file this process has written whole, in order (what a command
/// that fails after writing says it leaves behind).
static WRITTEN: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// The files this process has written whole so far, in order.
#[must_use]
pub fn written() -> Vec<PathBuf> {
    WRITTEN
        .lock()
        .map_or_else(|e| e.into_inner().clone(), |w| w.clone())
}

/// Set by [`remove_pending`]: the process is being interrupted, no write
/// may rename its files any more.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Whether the process has been interrupted (SIGINT or SIGTERM): the
/// signal handler called [`remove_pending`]. A command that fails after
/// that exits with 130, whatever its error says.
#[must_use]
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

/// Whether to create the missing folders of the outputs
/// ([`write_all_atomic`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Folders {
    /// Every output's folder must exist.
    Existing,
    /// Missing folders are created, and removed again if the write fails.
    Create,
}

/// Replaces `path` with `bytes` atomically: the bytes go to a new temporary
/// file in the same directory, which is flushed to disk and then renamed
/// over `path` (the directory is synced afterwards where the platform
/// allows). On any error the temporary file is removed and `path` is left
/// as it was. An existing target's permissions are kept. A symbolic link
/// is followed to the file it names; a target that is not a regular file,
/// or is read-only, is refused.
///
/// # Errors
/// [`FileError::Io`] with action "writing" and the target path.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    write_all_atomic(&[(path, bytes)], Folders::Existing)
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
    let plans = plan_targets(&[path])?;
    let plan = &plans[0];
    remove_stale(&plan.dir);
    let temp = stage_with(plan, write).map_err(|e| io_error(path, e))?;
    let temps = [temp];
    let guard = lock_pending();
    if let Err((_, e)) = commit(&plans, &temps, &INTERRUPTED, &guard) {
        drop(guard);
        let _ = fs::remove_file(&temps[0]);
        forget(&temps[0]);
        return Err(io_error(path, e));
    }
    drop(guard);
    forget(&temps[0]);
    sync_dir(&plan.dir);
    Ok(())
}

/// Refuses, before any work is done, outputs that [`write_all_atomic`]
/// would refuse: a target that is not a regular file or is read-only, two
/// outputs that are the same file, an output whose folder does not exist
/// (unless `folders` is [`Folders::Create`]).
///
/// # Errors
/// [`FileError::Io`] naming the output and why.
pub fn check_outputs(paths: &[&Path], folders: Folders) -> Result<(), FileError> {
    let plans = plan_targets(paths)?;
    if folders == Folders::Existing {
        for (plan, path) in plans.iter().zip(paths) {
            if !plan.dir.is_dir() {
                return Err(io_error(
                    path,
                    io::Error::new(
                        io::ErrorKind::NotFound,
                        format!("the folder {} does not exist", plan.dir.display()),
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Writes every `(path, bytes)` atomically as one transaction: all files
/// are checked ([`check_outputs`]) and written to temporary files first;
/// only when every one is complete are they renamed over their targets.
/// Should a rename fail, the targets already renamed get their old
/// content back (or are removed, if they did not exist), so the command
/// has written all of its files or none. With [`Folders::Create`] missing
/// folders are created first and removed again on failure.
///
/// # Errors
/// [`FileError::Io`] with action "writing", naming the file that failed;
/// [`io::ErrorKind::Interrupted`] when the process is being interrupted.
pub fn write_all_atomic(files: &[(&Path, &[u8])], folders: Folders) -> Result<(), FileError> {
    let paths: Vec<&Path> = files.iter().map(|(p, _)| *p).collect();
    let plans = plan_targets(&paths)?;
    let mut created: Vec<PathBuf> = Vec::new();
    if folders == Folders::Create {
        for (plan, path) in plans.iter().zip(&paths) {
            create_folders(&plan.dir, &mut created).map_err(|e| {
                remove_folders(&created);
                io_error(path, e)
            })?;
        }
    }
    let mut swept: Vec<&Path> = Vec::new();
    for plan in &plans {
        if !swept.contains(&plan.dir.as_path()) {
            remove_stale(&plan.dir);
            swept.push(&plan.dir);
        }
    }
    let fail = |temps: &[PathBuf], created: &[PathBuf], path: &Path, e: io::Error| {
        for t in temps {
            let _ = fs::remove_file(t);
            forget(t);
        }
        remove_folders(created);
        io_error(path, e)
    };
    // Stage: every file complete on disk beside its target.
    let mut temps: Vec<PathBuf> = Vec::with_capacity(files.len());
    for (plan, (path, bytes)) in plans.iter().zip(files) {
        match stage(plan, bytes) {
            Ok(temp) => temps.push(temp),
            Err(e) => return Err(fail(&temps, &created, path, e)),
        }
    }
    // Commit: rename them all, or put back what was renamed.
    let mut guard = lock_pending();
    if let Err((k, e)) = commit(&plans, &temps, &INTERRUPTED, &guard) {
        drop(guard);
        return Err(fail(&temps, &created, paths[k], e));
    }
    // The folders now hold the outputs: no longer the write's to remove.
    guard.folders.retain(|d| !created.contains(d));
    drop(guard);
    for t in &temps {
        forget(t);
    }
    for dir in swept {
        sync_dir(dir);
    }
    Ok(())
}

/// Where one output goes.
struct TargetPlan {
    /// The file to replace (symbolic links followed).
    target: PathBuf,
    /// Its folder.
    dir: PathBuf,
    /// Its file name.
    name: std::ffi::OsString,
}

/// An I/O error of writing `path`.
fn io_error(path: &Path, source: io::Error) -> FileError {
    FileError::Io {
        action: "writing",
        path: path.to_path_buf(),
        source,
    }
}

/// Each output's target, checked; two outputs that are one file refused
/// (by path, the folder canonical, and by device and inode; linear in the
/// outputs).
fn plan_targets(paths: &[&Path]) -> Result<Vec<TargetPlan>, FileError> {
    let mut plans: Vec<TargetPlan> = Vec::with_capacity(paths.len());
    let mut seen: HashMap<Identity, usize> = HashMap::with_capacity(paths.len());
    for (k, path) in paths.iter().enumerate() {
        let target = resolve_links(path).map_err(|e| io_error(path, e))?;
        check_target(&target).map_err(|e| io_error(path, e))?;
        let Some(name) = target.file_name().map(std::ffi::OsStr::to_os_string) else {
            return Err(io_error(
                path,
                io::Error::new(io::ErrorKind::InvalidInput, "the path does not name a file"),
            ));
        };
        let dir = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let canonical = fs::canonicalize(&dir).unwrap_or_else(|_| dir.clone());
        let mut identities = vec![Identity::Path(canonical.join(&name))];
        identities.extend(inode(&target));
        for id in identities {
            if let Some(&other) = seen.get(&id) {
                return Err(io_error(
                    path,
                    io::Error::new(
                        io::ErrorKind::InvalidInput,
                        format!(
                            "{} is also written as {} (the same file): give each output its own path",
                            path.display(),
                            paths[other].display()
                        ),
                    ),
                ));
            }
            seen.insert(id, k);
        }
        plans.push(TargetPlan { target, dir, name });
    }
    Ok(plans)
}

/// What makes two outputs one file.
#[derive(Debug, PartialEq, Eq, Hash)]
enum Identity {
    /// The canonical folder joined with the file name.
    Path(PathBuf),
    /// Device and inode of an existing file.
    Inode(u64, u64),
}

/// The device and inode of an existing file (Unix).
fn inode(path: &Path) -> Option<Identity> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt as _;
        fs::metadata(path)
            .ok()
            .map(|m| Identity::Inode(m.dev(), m.ino()))
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        None
    }
}

/// Creates the missing folders of `dir`, recording each one created
/// (outermost first) in `created`.
fn create_folders(dir: &Path, created: &mut Vec<PathBuf>) -> io::Result<()> {
    let mut missing = Vec::new();
    let mut at = Some(dir);
    while let Some(d) = at {
        if d.as_os_str().is_empty() || d.exists() {
            break;
        }
        missing.push(d.to_path_buf());
        at = d.parent();
    }
    for d in missing.into_iter().rev() {
        // Created and recorded under the lock: a signal's clean-up sees
        // the folder, or stops the write before it is made.
        let mut pending = lock_pending();
        if interrupted() {
            return Err(interrupted_error());
        }
        match fs::create_dir(&d) {
            Ok(()) => {
                pending.folders.push(d.clone());
                created.push(d);
            }
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists && d.is_dir() => {}
            Err(e) => {
                return Err(io::Error::new(
                    e.kind(),
                    format!("creating the folder {} failed: {e}", d.display()),
                ));
            }
        }
    }
    Ok(())
}

/// Removes the folders a failed write created (innermost first; only
/// while empty).
fn remove_folders(created: &[PathBuf]) {
    let mut pending = lock_pending();
    for d in created.iter().rev() {
        let _ = fs::remove_dir(d);
    }
    pending.folders.retain(|d| !created.contains(d));
}

/// The error of a write stopped by a signal before it renamed anything.
fn interrupted_error() -> io::Error {
    io::Error::new(
        io::ErrorKind::Interrupted,
        "interrupted: nothing was written",
    )
}

/// Writes `bytes` to a new temporary file beside the plan's target,
/// flushed to disk, with the target's permissions; returns its path.
fn stage(plan: &TargetPlan, bytes: &[u8]) -> io::Result<PathBuf> {
    stage_with(plan, |file| file.write_all(bytes))
}

/// As [`stage`], the content streamed into the temporary file by `write`.
fn stage_with(
    plan: &TargetPlan,
    write: impl FnOnce(&mut fs::File) -> io::Result<()>,
) -> io::Result<PathBuf> {
    let (temp, mut file) = create_temp(&plan.dir, &plan.name)?;
    let written = (|| {
        write(&mut file)?;
        if let Ok(meta) = fs::metadata(&plan.target) {
            let _ = file.set_permissions(meta.permissions());
        }
        file.sync_all()
    })();
    match written {
        Ok(()) => Ok(temp),
        Err(e) => {
            let _ = fs::remove_file(&temp);
            forget(&temp);
            Err(e)
        }
    }
}

/// Renames every staged temporary file over its target, unless
/// `interrupted` is set. On a failure the targets already renamed get
/// their old content back (a hard link made before each rename) or are
/// removed; returns the index of the failing output and its error. The
/// caller holds the [`PENDING`] lock (`_pending`), so a signal's clean-up
/// waits for the renames to finish.
fn commit(
    plans: &[TargetPlan],
    temps: &[PathBuf],
    interrupted: &AtomicBool,
    _pending: &MutexGuard<'_, Pending>,
) -> Result<(), (usize, io::Error)> {
    if interrupted.load(Ordering::SeqCst) {
        return Err((0, interrupted_error()));
    }
    // (target, backup of its old content if it had one) of each rename done.
    let mut done: Vec<(&Path, Option<PathBuf>)> = Vec::with_capacity(plans.len());
    let mut outcome = Ok(());
    for (k, (plan, temp)) in plans.iter().zip(temps).enumerate() {
        // The last rename needs no backup: if it fails, nothing after it
        // is undone; its own target is untouched.
        let backup = if k + 1 < plans.len() && plan.target.exists() {
            backup_of(plan)
        } else {
            None
        };
        match fs::rename(temp, &plan.target) {
            Ok(()) => done.push((&plan.target, backup)),
            Err(e) => {
                if let Some(b) = backup {
                    let _ = fs::remove_file(b);
                }
                outcome = Err((k, e));
                break;
            }
        }
    }
    if outcome.is_ok() {
        let mut written = WRITTEN
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        written.extend(done.iter().map(|(target, _)| target.to_path_buf()));
    }
    for (target, backup) in done.into_iter().rev() {
        match (&outcome, backup) {
            (Ok(()), Some(b)) => {
                let _ = fs::remove_file(b);
            }
            (Ok(()), None) => {}
            (Err(_), Some(b)) => {
                let _ = fs::rename(b, target);
            }
            (Err(_), None) => {
                let _ = fs::remove_file(target);
            }
        }
    }
    outcome
}

/// A hard link to the target's current content, named like a temporary
/// file (so that a killed process's leftover is cleaned up like one);
/// `None` where the file system has no hard links.
fn backup_of(plan: &TargetPlan) -> Option<PathBuf> {
    for _ in 0..100 {
        let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
        let backup = plan.dir.join(temp_name(&plan.name, std::process::id(), n));
        match fs::hard_link(&plan.target, &backup) {
            Ok(()) => return Some(backup),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {}
            Err(_) => return None,
        }
    }
    None
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

/// Refuses a target that exists and is not a regular file, or is
/// read-only.
fn check_target(target: &Path) -> io::Result<()> {
    let Ok(meta) = fs::metadata(target) else {
        return Ok(());
    };
    let kind = file_kind(&meta);
    if kind != "a regular file" {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} is {kind}, not a file to write", target.display()),
        ));
    }
    check_writable(target, &meta)
}

/// Whether a file can be written into the folder `dir`: it has a write
/// permission bit (checked on the mode, as [`check_writable`] does, so
/// that root is told the same as anyone) and an empty temporary file,
/// named as a write's are, can be created in it (and is removed at once).
/// Lets a caller propose an output where it can be written.
#[must_use]
pub fn can_write_in(dir: &Path) -> bool {
    let mode = fs::metadata(dir).is_ok_and(|m| m.is_dir() && !m.permissions().readonly());
    mode && create_temp(dir, std::ffi::OsStr::new("probe")).is_ok_and(|(temp, file)| {
        drop(file);
        let _ = fs::remove_file(&temp);
        forget(&temp);
        true
    })
}

/// Refuses a regular file that is read-only: no write permission bit at
/// all (checked on the mode, so that root, whom the kernel lets write
/// anything, is refused too), or not writable by the user running
/// spherecal (asked of the kernel by opening it for writing, which
/// changes nothing). Replacing it by a rename would need neither.
fn check_writable(target: &Path, meta: &fs::Metadata) -> io::Result<()> {
    let refuse = |why: String| {
        Err(io::Error::new(
            io::ErrorKind::PermissionDenied,
            format!(
                "{} is {why}: it is not replaced; make it writable or choose another output",
                target.display()
            ),
        ))
    };
    if meta.permissions().readonly() {
        return refuse(read_only_mode(meta));
    }
    match fs::OpenOptions::new().write(true).open(target) {
        Err(e) if e.kind() == io::ErrorKind::PermissionDenied => {
            refuse("not writable by you".to_owned())
        }
        _ => Ok(()),
    }
}

/// "read-only (mode 0444)" where the platform has modes.
fn read_only_mode(meta: &fs::Metadata) -> String {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt as _;
        format!(
            "read-only (mode {:04o})",
            meta.permissions().mode() & 0o7777
        )
    }
    #[cfg(not(unix))]
    {
        let _ = meta;
        "read-only".to_owned()
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

/// Whether `a` and `b` name the same file, the one test of the crate
/// (outputs against inputs, a profile folder's pose file): on Unix the
/// device and inode, so hard links, `..` and symbolic links are seen
/// through; elsewhere the canonical paths. When either cannot be looked
/// up (not there yet, no permission) the paths as written are compared.
#[must_use]
pub fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt as _;
        match (fs::metadata(a), fs::metadata(b)) {
            (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
            _ => a == b,
        }
    }
    #[cfg(not(unix))]
    {
        match (fs::canonicalize(a), fs::canonicalize(b)) {
            (Ok(x), Ok(y)) => x == y,
            _ => a == b,
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
        Some(input) => Err(io_error(
            output,
            io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "the output is the input {} (the same file): it would be destroyed; choose another output",
                    input.display()
                ),
            ),
        )),
        None => Ok(()),
    }
}

/// The [`PENDING`] lock, poisoned or not.
fn lock_pending() -> MutexGuard<'static, Pending> {
    PENDING
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Removes every temporary file being written now and stops every write
/// that has not renamed its files yet (a signal handler's clean-up before
/// the process exits; [`interrupted`] is true from then on). Waits for a
/// write that is renaming its files to finish, so a target is either
/// entirely old or entirely new.
pub fn remove_pending() {
    INTERRUPTED.store(true, Ordering::SeqCst);
    let mut pending = lock_pending();
    for p in pending.files.drain(..) {
        let _ = fs::remove_file(p);
    }
    // Innermost first; a folder that holds anything else stays.
    for d in pending.folders.drain(..).rev() {
        let _ = fs::remove_dir(d);
    }
}

fn forget(temp: &Path) {
    lock_pending().files.retain(|x| x != temp);
}

/// Distinguishes temporary files of concurrent saves in one process.
static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// The temporary-file name of `file_name` for process `pid`, number `n`:
/// `.<file_name>.<pid>.<n>.tmp`.
fn temp_name(file_name: &std::ffi::OsStr, pid: u32, n: u64) -> std::ffi::OsString {
    let mut name = std::ffi::OsString::from(".");
    name.push(file_name);
    name.push(format!(".{pid}.{n}.tmp"));
    name
}

/// The process id of a temporary-file name of [`temp_name`]'s form.
fn temp_owner(name: &str) -> Option<u32> {
    let rest = name.strip_prefix('.')?.strip_suffix(".tmp")?;
    let (rest, n) = rest.rsplit_once('.')?;
    let (file, pid) = rest.rsplit_once('.')?;
    if file.is_empty() || n.is_empty() || !n.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    n.parse::<u64>().ok()?;
    pid.parse().ok()
}

/// Creates a new, empty temporary file next to the target (same directory,
/// hence same file system, so the rename is atomic), and remembers it for
/// [`remove_pending`].
fn create_temp(dir: &Path, file_name: &std::ffi::OsStr) -> io::Result<(PathBuf, fs::File)> {
    // Created and recorded under the lock: a signal's clean-up sees the
    // file, or stops the write before it is made.
    let mut pending = lock_pending();
    if interrupted() {
        return Err(interrupted_error());
    }
    let mut last_error = None;
    for _ in 0..100 {
        let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
        let temp = dir.join(temp_name(file_name, std::process::id(), n));
        // Read as well: a streaming writer may seek back and read (E57).
        match fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create_new(true)
            .open(&temp)
        {
            Ok(file) => {
                pending.files.push(temp.clone());
                return Ok((temp, file));
            }
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last_error = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last_error.unwrap_or_else(|| io::Error::other("no free temporary file name")))
}

/// Removes the temporary files in `dir` left by spherecal processes that
/// no longer run (killed outright mid-write), whatever file they were
/// for. Linux only (`/proc`); best effort.
fn remove_stale(dir: &Path) {
    if !Path::new("/proc/self").exists() {
        return;
    }
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for entry in entries.filter_map(Result::ok) {
        let name = entry.file_name();
        let Some(pid) = name.to_str().and_then(temp_owner) else {
            continue;
        };
        let alive = Path::new("/proc").join(pid.to_string()).exists();
        let regular = entry.file_type().is_ok_and(|t| t.is_file());
        if !alive && regular {
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

    /// Issue 23: a killed process's temporary file of *another* file in
    /// the folder went unnoticed by later writes.
    #[test]
    fn stale_temporary_files_of_any_name_go_with_the_next_write() {
        let dir = tempfile_dir();
        let stale = dir.join(".big session.json.999999999.3.tmp");
        let foreign = dir.join(".notes.txt.tmp");
        let mine = dir.join(format!(".live.json.{}.0.tmp", std::process::id()));
        for f in [&stale, &foreign, &mine] {
            fs::write(f, "partial").unwrap();
        }
        write_atomic(&dir.join("result.json"), b"{}").unwrap();
        assert!(!stale.exists(), "a dead process's temporary file stays");
        assert!(foreign.exists(), "a file not of spherecal's form is kept");
        assert!(mine.exists(), "a live process's temporary file is kept");
        assert_eq!(temp_owner(".a.b.12.3.tmp"), Some(12));
        assert_eq!(temp_owner(".12.3.tmp"), None);
        assert_eq!(temp_owner(".a.x.3.tmp"), None);
        let _ = fs::remove_dir_all(&dir);
    }

    /// Issue 23: a read-only target was replaced (the rename needs only
    /// the folder's permission). The mode bits are checked, so this holds
    /// when the tests run as root too.
    #[cfg(unix)]
    #[test]
    fn a_read_only_target_is_refused() {
        use std::os::unix::fs::PermissionsExt as _;
        let dir = tempfile_dir();
        let target = dir.join("locked.json");
        fs::write(&target, "keep").unwrap();
        fs::set_permissions(&target, fs::Permissions::from_mode(0o444)).unwrap();
        let e = write_atomic(&target, b"new").unwrap_err().to_string();
        assert!(e.contains("read-only (mode 0444)"), "{e}");
        assert_eq!(fs::read_to_string(&target).unwrap(), "keep");
        assert!(check_outputs(&[&target], Folders::Existing).is_err());
        assert_eq!(fs::read_dir(&dir).unwrap().count(), 1, "no temporary file");
        let _ = fs::remove_dir_all(&dir);
    }

    /// Issue 34: a folder a file can be written into, and not: read-only
    /// by its mode (root too), a file, none; the probe leaves nothing.
    #[cfg(unix)]
    #[test]
    fn a_folder_is_writable_or_not() {
        use std::os::unix::fs::PermissionsExt as _;
        let dir = tempfile_dir();
        assert!(can_write_in(&dir));
        assert_eq!(fs::read_dir(&dir).unwrap().count(), 0, "no probe left");
        let file = dir.join("a.json");
        fs::write(&file, "{}").unwrap();
        assert!(!can_write_in(&file));
        assert!(!can_write_in(&dir.join("none")));
        fs::set_permissions(&dir, fs::Permissions::from_mode(0o555)).unwrap();
        assert!(!can_write_in(&dir));
        fs::set_permissions(&dir, fs::Permissions::from_mode(0o755)).unwrap();
        let _ = fs::remove_dir_all(&dir);
    }

    /// Issue 23: a command with several outputs left some written when a
    /// later one failed.
    #[test]
    fn several_outputs_are_all_written_or_none() {
        let dir = tempfile_dir();
        let a = dir.join("a.json");
        let b = dir.join("b.json");
        fs::write(&a, "old a").unwrap();
        // The second output is a folder: refused before anything is written.
        fs::create_dir(&b).unwrap();
        let e = write_all_atomic(&[(&a, b"new a"), (&b, b"new b")], Folders::Existing);
        assert!(e.unwrap_err().to_string().contains("a folder"));
        assert_eq!(fs::read_to_string(&a).unwrap(), "old a");
        // A missing folder: with Create it is made, and removed on failure.
        let deep = dir.join("new/sub/c.csv");
        let e = write_all_atomic(&[(&deep, b"c"), (&b, b"b")], Folders::Create);
        assert!(e.is_err());
        assert!(!dir.join("new").exists(), "the created folders are removed");
        write_all_atomic(&[(&deep, b"c"), (&a, b"new a")], Folders::Create).unwrap();
        assert_eq!(fs::read_to_string(&deep).unwrap(), "c");
        assert_eq!(fs::read_to_string(&a).unwrap(), "new a");
        // Two outputs that are one file.
        let e = write_all_atomic(
            &[(&a, b"1"), (&dir.join("./a.json"), b"2")],
            Folders::Existing,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("the same file"), "{e}");
        assert_eq!(fs::read_to_string(&a).unwrap(), "new a");
        let _ = fs::remove_dir_all(&dir);
    }

    /// A failing rename puts back what was renamed before it.
    #[test]
    fn a_failed_commit_restores_the_old_files() {
        let dir = tempfile_dir();
        let a = dir.join("a.txt");
        let b = dir.join("b.txt");
        let c = dir.join("c.txt");
        fs::write(&a, "old a").unwrap();
        let paths: [&Path; 3] = [&a, &b, &c];
        let plans = plan_targets(&paths).unwrap();
        let temps: Vec<PathBuf> = plans.iter().map(|p| stage(p, b"new").unwrap()).collect();
        // The third temporary file vanishes: its rename fails.
        fs::remove_file(&temps[2]).unwrap();
        let guard = lock_pending();
        let (k, _) = commit(&plans, &temps, &AtomicBool::new(false), &guard).unwrap_err();
        drop(guard);
        assert_eq!(k, 2);
        assert_eq!(fs::read_to_string(&a).unwrap(), "old a");
        assert!(!b.exists() && !c.exists());
        assert_eq!(fs::read_dir(&dir).unwrap().count(), 1, "no backup left");
        for t in &temps {
            forget(t);
        }
        let _ = fs::remove_dir_all(&dir);
    }

    /// Issue 23: a late Ctrl-C removed the temporary file under a write
    /// about to rename it, which then failed with "No such file or
    /// directory" (exit 1). Once interrupted, a write renames nothing and
    /// says so (the command line exits 130 on it).
    #[test]
    fn an_interrupted_write_renames_nothing() {
        let dir = tempfile_dir();
        let a = dir.join("a.txt");
        fs::write(&a, "old").unwrap();
        let paths: [&Path; 1] = [&a];
        let plans = plan_targets(&paths).unwrap();
        let temps = vec![stage(&plans[0], b"new").unwrap()];
        let guard = lock_pending();
        let (_, e) = commit(&plans, &temps, &AtomicBool::new(true), &guard).unwrap_err();
        drop(guard);
        assert_eq!(e.kind(), io::ErrorKind::Interrupted);
        assert_eq!(fs::read_to_string(&a).unwrap(), "old");
        let _ = fs::remove_file(&temps[0]);
        forget(&temps[0]);
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
