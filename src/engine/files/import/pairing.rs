//! Profile folders as cells publish them, and the one pairing of profiles
//! with the poses of a log, the import's and a raw scan's (`measure`): by
//! id when the log's ids name the profiles ([`ids_naming_profiles`],
//! [`read_by_id`]), else pose `k` with the `k`-th profile
//! ([`read_in_order`]).
//!
//! A folder holds the profiles and often more: the pose file itself, the
//! sensor vendor's or another tool's calibration output, notes. The
//! profiles are the files named alike (`p1.yml` … `p15.yml`,
//! `1_3C_line.yml` … `10_3C_line.yml`, `scan_001.csv` …): names are
//! grouped by their shape (digit runs as `#`), and the group of profile
//! files (the one with as many files as there are poses, else the
//! largest) is kept; every other file is skipped and listed with why.
//!
//! The pose number is the digit run that tells the files apart, wherever
//! it is in the name (`p7`, `7_3C_line`, `scan_007`); the profiles are in
//! that number's order, and pose `k` of the log (in its order) is paired
//! with profile `k`.

use std::collections::{BTreeMap, HashSet};
use std::fs;
use std::path::{Path, PathBuf};

use super::ImportError;
use super::profiles::{self, PROFILE_EXTENSIONS, ProfileFormat, ProfileSource, RawProfile};
use super::progress::{self, ImportProgress, ImportStage};
use crate::engine::base::numeric::plural;
use crate::engine::files::format::same_file;

/// The profile files of a folder and what was left out.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FolderListing {
    /// The profiles, in the order of their number.
    pub profiles: Vec<PathBuf>,
    /// Each profile's number (`None` for a name with no digits).
    pub numbers: Vec<Option<u64>>,
    /// Files of the folder that are not profiles, with the reason.
    pub skipped: Vec<(PathBuf, String)>,
}

impl FolderListing {
    /// One line: how many profiles, their first and last name, the skipped files.
    #[must_use]
    pub fn summary(&self) -> String {
        let name = |p: &PathBuf| {
            p.file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
        };
        let range = match (self.profiles.first(), self.profiles.last()) {
            (Some(a), Some(b)) if self.profiles.len() > 1 => format!("{} … {}", name(a), name(b)),
            (Some(a), _) => name(a),
            _ => String::new(),
        };
        let mut out = format!(
            "profile files: {} ({range}) in the order of the number in their names",
            self.profiles.len()
        );
        if !self.skipped.is_empty() {
            let skipped: Vec<String> = self
                .skipped
                .iter()
                .map(|(p, why)| format!("{} ({why})", name(p)))
                .collect();
            out.push_str(&format!("; skipped: {}", skipped.join(", ")));
        }
        out
    }
}

/// The poses' ids when the profiles are paired by them: every pose has
/// an id and, for a folder, each names a profile file (`<id>.<ext>`; a
/// single profile table has a pose column). `None`: pose `k` goes with the
/// `k`-th profile ([`read_in_order`]).
#[must_use]
pub fn ids_naming_profiles<'a>(
    source: &ProfileSource,
    ids: impl IntoIterator<Item = Option<&'a str>>,
) -> Option<Vec<String>> {
    let ids: Vec<String> = ids
        .into_iter()
        .map(|id| id.map(str::to_string))
        .collect::<Option<_>>()?;
    let named = match source {
        ProfileSource::Folder(dir) => ids.iter().all(|id| profiles::file_of(dir, id).is_some()),
        ProfileSource::File { .. } => true,
    };
    named.then_some(ids)
}

/// Most skipped files a summary names (the rest are counted).
const MAX_SKIPPED_NAMED: usize = 5;

/// The entries of a profile folder paired by pose id that are not the
/// profile of one of `ids` (`<id>.<ext>` of a profile extension): a
/// README, an old profile, a folder or a link named like a profile.
/// Nothing for a profile table.
#[must_use]
pub fn naming_no_pose(source: &ProfileSource, ids: &[String]) -> Vec<PathBuf> {
    let ProfileSource::Folder(dir) = source else {
        return Vec::new();
    };
    let read: HashSet<PathBuf> = ids
        .iter()
        .filter_map(|id| profiles::file_of(dir, id))
        .collect();
    let Ok(entries) = fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut others: Vec<PathBuf> = entries
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| !read.contains(p))
        .collect();
    others.sort();
    others
}

/// Why an entry of a profile folder is not a file, in words.
fn not_a_file(path: &Path) -> &'static str {
    if path.is_dir() {
        "a folder"
    } else if fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink()) {
        "a link to nothing"
    } else {
        "not a file (a FIFO or a device)"
    }
}

/// `; skipped N files that name no pose: a, b, …` for a summary line, or
/// nothing.
#[must_use]
pub fn skipped_summary(skipped: &[PathBuf]) -> String {
    if skipped.is_empty() {
        return String::new();
    }
    let mut names: Vec<String> = skipped
        .iter()
        .take(MAX_SKIPPED_NAMED)
        .map(|p| {
            let name = p
                .file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
            if p.is_file() {
                name
            } else {
                format!("{name} ({})", not_a_file(p))
            }
        })
        .collect();
    if skipped.len() > MAX_SKIPPED_NAMED {
        names.push(format!("{} more", skipped.len() - MAX_SKIPPED_NAMED));
    }
    format!(
        "; skipped {} that name no pose: {}",
        plural(skipped.len(), "entry", "entries"),
        names.join(", ")
    )
}

/// Reads the profiles of the poses `ids` from `source` in that order (a
/// folder's `<id>.<ext>`, or the id's rows of one table, which may name
/// no pose the log does not have), handing each to `each` as it is read:
/// a caller that converts them keeps one raw profile in memory at a
/// time. `progress` is told of each profile read.
///
/// # Errors
/// A profile missing or unreadable, a table pose not in the log,
/// [`ImportError::Cancelled`], or the first error of `each`.
pub fn read_by_id(
    source: &ProfileSource,
    format: &ProfileFormat,
    ids: &[String],
    progress: &mut ImportProgress<'_>,
    mut each: impl FnMut(&str, RawProfile) -> Result<(), ImportError>,
) -> Result<(), ImportError> {
    let total = ids.len();
    match source {
        ProfileSource::Folder(dir) => {
            for (k, id) in ids.iter().enumerate() {
                let file =
                    profiles::file_of(dir, id).ok_or_else(|| ImportError::MissingProfile {
                        id: id.clone(),
                        path: dir.join(format!("{id}.csv")),
                    })?;
                each(id, profiles::read_profile(&file, format)?)?;
                progress::report(progress, ImportStage::Profiles { done: k + 1, total })?;
            }
        }
        ProfileSource::File { path, pose_column } => {
            let (order, mut by_id) = profiles::read_profile_table(path, pose_column, format)?;
            if let Some(stray) = order.iter().find(|id| !ids.contains(id)) {
                return Err(ImportError::File {
                    path: path.clone(),
                    message: format!("pose `{stray}` is not in the pose log"),
                });
            }
            for id in ids {
                let raw = by_id
                    .remove(id)
                    .ok_or_else(|| ImportError::MissingProfile {
                        id: id.clone(),
                        path: path.clone(),
                    })?;
                each(id, raw)?;
            }
            progress::report(progress, ImportStage::Profiles { done: total, total })?;
        }
    }
    Ok(())
}

/// Profiles paired with a log's poses in order.
#[derive(Debug)]
pub struct InOrder {
    /// Each pose's id, from its profile's file name.
    pub ids: Vec<String>,
    /// Each pose's profile.
    pub raws: Vec<RawProfile>,
    /// The folder as listed (a folder source).
    pub listing: Option<FolderListing>,
}

/// Pose `k` of a log of `poses` poses with the `k`-th profile: a folder's
/// profile files in the order of the number in their names (the log file
/// `log` and other files skipped, [`list_profiles`]), or a table's poses
/// in its order; the counts must match. `progress` is told of each
/// profile read.
///
/// # Errors
/// The folder or a profile cannot be read, the counts differ (naming
/// both), [`ImportError::Cancelled`].
pub fn read_in_order(
    source: &ProfileSource,
    format: &ProfileFormat,
    log: &Path,
    poses: usize,
    progress: &mut ImportProgress<'_>,
) -> Result<InOrder, ImportError> {
    let (raws, listing) = match source {
        ProfileSource::Folder(dir) => {
            let listing = list_profiles(dir, &[log], Some(poses))?;
            if listing.profiles.len() != poses {
                return Err(ImportError::File {
                    path: dir.clone(),
                    message: format!(
                        "{} profiles for {poses} poses of {}: pose k is paired with the k-th profile in the order of the number in their names, so the counts must match ({})",
                        listing.profiles.len(),
                        log.display(),
                        listing.summary()
                    ),
                });
            }
            let total = listing.profiles.len();
            let mut raws = Vec::with_capacity(total);
            for (k, p) in listing.profiles.iter().enumerate() {
                raws.push(profiles::read_profile(p, format)?);
                progress::report(progress, ImportStage::Profiles { done: k + 1, total })?;
            }
            (raws, Some(listing))
        }
        ProfileSource::File { path, pose_column } => {
            let (order, mut by_id) = profiles::read_profile_table(path, pose_column, format)?;
            if order.len() != poses {
                return Err(ImportError::File {
                    path: path.clone(),
                    message: format!(
                        "{} profiles for {poses} poses of {}: without pose ids that name the table's profiles, pose k pairs with the k-th profile, so the counts must match",
                        order.len(),
                        log.display()
                    ),
                });
            }
            let total = order.len();
            progress::report(progress, ImportStage::Profiles { done: total, total })?;
            (
                order.iter().filter_map(|id| by_id.remove(id)).collect(),
                None,
            )
        }
    };
    let ids = raws
        .iter()
        .map(|r: &RawProfile| {
            r.source
                .file_stem()
                .map_or_else(|| "pose".into(), |s| s.to_string_lossy().into_owned())
        })
        .collect();
    Ok(InOrder { ids, raws, listing })
}

/// A file name's shape: lower case, each digit run as `#`.
fn shape(name: &str) -> String {
    let mut out = String::new();
    let mut in_digits = false;
    for c in name.chars() {
        if c.is_ascii_digit() {
            if !in_digits {
                out.push('#');
            }
            in_digits = true;
        } else {
            out.extend(c.to_lowercase());
            in_digits = false;
        }
    }
    out
}

/// The digit runs of a name, as numbers (saturating).
fn digit_runs(name: &str) -> Vec<u64> {
    let mut out = Vec::new();
    let mut current: Option<u64> = None;
    for c in name.chars() {
        if let Some(d) = c.to_digit(10) {
            current = Some(
                current
                    .unwrap_or(0)
                    .saturating_mul(10)
                    .saturating_add(u64::from(d)),
            );
        } else if let Some(v) = current.take() {
            out.push(v);
        }
    }
    out.extend(current);
    out
}

/// The profile files of `dir`: files of a profile extension named alike,
/// in the order of their number; `exclude` (the pose file) and the rest
/// skipped. With `expected` (the count of poses), the group of that size
/// is chosen when there is one.
///
/// # Errors
/// The folder cannot be read, or holds no profile file.
pub fn list_profiles(
    dir: &Path,
    exclude: &[&Path],
    expected: Option<usize>,
) -> Result<FolderListing, ImportError> {
    let entries = fs::read_dir(dir).map_err(|source| ImportError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut skipped = Vec::new();
    let mut groups: BTreeMap<String, Vec<PathBuf>> = BTreeMap::new();
    let mut files: Vec<PathBuf> = entries.filter_map(Result::ok).map(|e| e.path()).collect();
    files.sort();
    for path in files {
        let name = path
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        // A folder, a FIFO or a link to nothing named like a profile is
        // listed as skipped, not passed over (a count that then differs
        // names it).
        if !path.is_file() {
            skipped.push((path.clone(), not_a_file(&path).to_string()));
            continue;
        }
        if exclude.iter().any(|e| same_file(e, &path)) {
            skipped.push((path, "the pose file".to_string()));
            continue;
        }
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        if !PROFILE_EXTENSIONS.contains(&ext.as_str()) {
            let why = if ext.is_empty() {
                "not a profile file: no extension".to_string()
            } else {
                format!("not a profile file: .{ext}")
            };
            skipped.push((path, why));
            continue;
        }
        groups.entry(shape(&name)).or_default().push(path);
    }
    if groups.is_empty() {
        return Err(ImportError::File {
            path: dir.to_path_buf(),
            message: format!(
                "no profile file in the folder (profiles are .{} files){}",
                PROFILE_EXTENSIONS.join(", ."),
                if skipped.is_empty() {
                    String::new()
                } else {
                    format!(
                        "; it holds {}",
                        skipped
                            .iter()
                            .filter_map(|(p, _)| p
                                .file_name()
                                .map(|n| n.to_string_lossy().into_owned()))
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                }
            ),
        });
    }
    // Two groups that could both be the profiles: refused, naming them.
    let sized: Vec<(&String, &Vec<PathBuf>)> = groups
        .iter()
        .filter(|(_, v)| expected.is_some_and(|n| v.len() == n))
        .collect();
    if sized.len() > 1 {
        let name = |p: &PathBuf| {
            p.file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
        };
        let named: Vec<String> = sized
            .iter()
            .map(|(shape, v)| {
                format!(
                    "{shape} ({} … {})",
                    v.first().map(name).unwrap_or_default(),
                    v.last().map(name).unwrap_or_default()
                )
            })
            .collect();
        return Err(ImportError::File {
            path: dir.to_path_buf(),
            message: format!(
                "{} sets of {} files named alike could be the profiles: {}; move the set that is not out of the folder, or give the profiles' folder alone",
                sized.len(),
                sized[0].1.len(),
                named.join(" and ")
            ),
        });
    }
    // The group of profiles: as many files as poses, else the largest
    // (ties: the first shape in order).
    let chosen = expected
        .and_then(|n| {
            let sized: Vec<&String> = groups
                .iter()
                .filter(|(_, v)| v.len() == n)
                .map(|(k, _)| k)
                .collect();
            (sized.len() == 1).then(|| sized[0].clone())
        })
        .or_else(|| {
            groups
                .iter()
                .max_by(|a, b| a.1.len().cmp(&b.1.len()).then_with(|| b.0.cmp(a.0)))
                .map(|(k, _)| k.clone())
        })
        .unwrap_or_default();
    let mut profiles = groups.remove(&chosen).unwrap_or_default();
    for (shape, paths) in groups {
        for p in paths {
            skipped.push((
                p,
                format!("not named like the profiles ({shape} vs {chosen})"),
            ));
        }
    }
    // The varying digit run is the pose number.
    let runs: Vec<Vec<u64>> = profiles
        .iter()
        .map(|p| {
            digit_runs(
                &p.file_stem()
                    .map_or_else(String::new, |n| n.to_string_lossy().into_owned()),
            )
        })
        .collect();
    let width = runs.iter().map(Vec::len).min().unwrap_or(0);
    let column = (0..width).find(|&k| {
        let values: HashSet<u64> = runs.iter().map(|r| r[k]).collect();
        values.len() == runs.len()
    });
    let numbers: Vec<Option<u64>> = runs.iter().map(|r| column.map(|k| r[k])).collect();
    let mut order: Vec<usize> = (0..profiles.len()).collect();
    order.sort_by(|&a, &b| {
        numbers[a]
            .cmp(&numbers[b])
            .then_with(|| profiles[a].cmp(&profiles[b]))
    });
    let numbers = order.iter().map(|&i| numbers[i]).collect();
    let sorted: Vec<PathBuf> = order
        .iter()
        .map(|&i| std::mem::take(&mut profiles[i]))
        .collect();
    skipped.sort();
    Ok(FolderListing {
        profiles: sorted,
        numbers,
        skipped,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_and_runs() {
        assert_eq!(shape("7_3C_line.yml"), "#_#c_line.yml");
        assert_eq!(shape("P12.YML"), "p#.yml");
        assert_eq!(digit_runs("7_3C_line"), vec![7, 3]);
        assert_eq!(digit_runs("scan_007"), vec![7]);
    }

    #[test]
    fn folders_as_published() {
        let dir = tempfile::tempdir().unwrap();
        let touch = |n: &str| fs::write(dir.path().join(n), "1 2\n").unwrap();
        for k in [1, 2, 10, 3] {
            touch(&format!("{k}_3C_line.yml"));
        }
        touch("robpose.txt");
        touch("calibration.sec");
        touch("notes.txt");
        let pose_file = dir.path().join("robpose.txt");
        let l = list_profiles(dir.path(), &[&pose_file], Some(4)).unwrap();
        let names: Vec<String> = l
            .profiles
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(
            names,
            [
                "1_3C_line.yml",
                "2_3C_line.yml",
                "3_3C_line.yml",
                "10_3C_line.yml"
            ]
        );
        assert_eq!(l.numbers, vec![Some(1), Some(2), Some(3), Some(10)]);
        assert_eq!(l.skipped.len(), 3, "{:?}", l.skipped);
        let s = l.summary();
        assert!(
            s.contains("robpose.txt (the pose file)") && s.contains("calibration.sec"),
            "{s}"
        );
        assert!(s.contains("notes.txt (not named like the profiles"), "{s}");
    }
}
