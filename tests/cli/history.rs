//! The history library on simulated truth: a folder of dated calibrations
//! of one IRB 2400 (repeats of one truth, then a sensor knocked 0.4 mm
//! along its y axis, then a joint-3 zero moved by 0.15°), a UR5e beside
//! it, a `paper` result among them and bad files. The jumps are flagged at
//! the right date and parameter, the repeats are not, and the σ the
//! library carries explains the scatter of the repeats; dates come from
//! names, then file names, then file times; bad files are reported and do
//! not stop the scan; the command line prints and writes the same.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use nalgebra::Vector3;
use spherecal::engine::base::robot::RobotChoice;
use spherecal::engine::base::session::{Observation, Session};
use spherecal::engine::calibrate::solve::SolverReport;
use spherecal::engine::calibrate::solve::ml::identifiability::Partner;
use spherecal::engine::calibrate::solve::ml::{Inseparable, MlReport};
use spherecal::engine::calibrate::solve::{self, Method, Options};
use spherecal::engine::files::format::{self, ResultFile};
use spherecal::engine::tools::history::{
    self, DEFAULT_K, DateSource, Drift, DriftOptions, HAND_EYE_NAMES, Library, SeriesKind, Status,
    Timestamp, Verdict,
};
use spherecal::engine::tools::simulate::{self, SimConfig};

const IRB: &str = "ABB IRB 2400/16";
/// The sensor moves this far along its own y axis (mm) on 2026-06-01.
const SENSOR_SHIFT_MM: f64 = 0.4;
/// Joint 3's zero moves by this much (deg) on 2026-07-06.
const JOINT3_SHIFT_DEG: f64 = 0.15;
const SENSOR_DATE: &str = "2026-06-01";
const JOINT_DATE: &str = "2026-07-06";

/// One calibration of the test library, in memory.
struct Cal {
    stem: String,
    session: Session,
    result: ResultFile,
}

/// Centre sessions with few poses keep each calibration fast (the debug
/// build calibrates each in well under a second).
fn config(seed: u64, name: &str, robot: RobotChoice) -> SimConfig {
    SimConfig {
        seed,
        name: Some(name.to_string()),
        robot,
        centres: true,
        n_identify: 9,
        n_validate: 3,
        poses_per_station: 4,
        ..SimConfig::default()
    }
}

/// A sensor moved by `shift` (its own frame) sees every centre at `c − shift`:
/// the true hand-eye is then `eT_s · Trans(shift)`.
fn shift_sensor(s: &mut Session, shift: Vector3<f64>) {
    for m in &mut s.measurements {
        match &mut m.observation {
            Observation::Centre(c) => *c -= shift,
            Observation::Stripe(_) => panic!("the test library has centre sessions only"),
        }
    }
}

/// A joint whose zero moved by `delta` reads `delta` less at the same
/// physical angle: the calibrated `theta` grows by `delta`.
fn move_joint_zero(s: &mut Session, joint: usize, delta: f64) {
    for m in &mut s.measurements {
        m.joints[joint] -= delta;
    }
}

fn calibrate(stem: &str, session: Session, method: Method) -> Cal {
    let mut options = Options::from_session(&session);
    options.method = method;
    options.ml.cross_validation = false;
    let (_, cal) = solve::calibrate(&session, &options).expect("calibration");
    let result = ResultFile::from_calibration(&session, &cal);
    Cal {
        stem: stem.to_string(),
        session,
        result,
    }
}

/// The calibrations, computed once for all tests.
fn calibrations() -> &'static [Cal] {
    static CALS: OnceLock<Vec<Cal>> = OnceLock::new();
    CALS.get_or_init(|| {
        let mut out = Vec::new();
        let months = [
            ("2026-01-05", 11),
            ("2026-02-02", 12),
            ("2026-03-02", 13),
            ("2026-04-06", 14),
            ("2026-05-04", 15),
            (SENSOR_DATE, 16),
            (JOINT_DATE, 17),
        ];
        for (date, seed) in months {
            let name = format!("IRB2400 cell 3, {date}");
            let (mut s, _) =
                simulate::simulate(&config(seed, &name, RobotChoice::Irb2400)).unwrap();
            if date >= SENSOR_DATE {
                shift_sensor(&mut s, Vector3::new(0.0, SENSOR_SHIFT_MM, 0.0));
            }
            if date >= JOINT_DATE {
                move_joint_zero(&mut s, 2, JOINT3_SHIFT_DEG);
            }
            out.push(calibrate(&format!("cell3-{date}"), s, Method::Ml));
        }
        // The paper's method between two repeats: no σ to judge by.
        let name = "IRB2400 cell 3, 2026-03-16 (paper method)";
        let (s, _) = simulate::simulate(&config(18, name, RobotChoice::Irb2400)).unwrap();
        out.push(calibrate("cell3-paper", s, Method::Paper));
        // A second robot on dates among the first one's.
        for (date, seed) in [("2026-02-16", 21), ("2026-06-15", 22)] {
            let name = format!("UR5e cell 7, {date}");
            let (s, _) = simulate::simulate(&config(seed, &name, RobotChoice::Ur5e)).unwrap();
            out.push(calibrate(&format!("ur5e-{date}"), s, Method::Ml));
        }
        out
    })
}

fn write_pair(dir: &Path, cal: &Cal) -> (PathBuf, PathBuf) {
    fs::create_dir_all(dir).unwrap();
    let s = dir.join(format!("{}.json", cal.stem));
    let r = dir.join(format!("{}.result.json", cal.stem));
    format::save_session(&cal.session, &s).unwrap();
    format::save_result(&cal.result, &r).unwrap();
    (s, r)
}

/// The library folder: every calibration as `X.json` + `X.result.json`,
/// one pair in a subfolder, one result apart from its session, and bad
/// or foreign files around them.
fn write_library(dir: &Path) {
    for cal in calibrations() {
        match cal.stem.as_str() {
            // Recursion: a subfolder two levels down.
            "cell3-2026-02-02" => {
                write_pair(&dir.join("archive/2026"), cal);
            }
            // A result in another folder than its session, found by the
            // session name.
            "cell3-2026-04-06" => {
                let (_, r) = write_pair(&dir.join("sessions"), cal);
                fs::create_dir_all(dir.join("results")).unwrap();
                fs::rename(r, dir.join("results/april.result.json")).unwrap();
            }
            _ => {
                write_pair(dir, cal);
            }
        }
    }
    // A result cut short, a session with a typo, JSON of other kinds, a
    // text file, a hidden folder and a folder nested too deep.
    let good = format::result_to_json(&calibrations()[0].result);
    fs::write(dir.join("broken.result.json"), &good[..good.len() / 2]).unwrap();
    let bad_session =
        format::session_to_json(&calibrations()[0].session).replacen("\"sphere\"", "\"spehre\"", 1);
    fs::write(dir.join("typo.json"), bad_session).unwrap();
    fs::write(
        dir.join("notes.json"),
        r#"{"format": "someone-else", "x": 1}"#,
    )
    .unwrap();
    fs::write(dir.join("list.json"), "[1, 2, 3]").unwrap();
    fs::write(dir.join("readme.txt"), "not json").unwrap();
    fs::create_dir_all(dir.join(".cache")).unwrap();
    fs::write(dir.join(".cache/x.result.json"), "garbage").unwrap();
    let mut deep = dir.to_path_buf();
    for level in 0..=history::MAX_DEPTH {
        deep.push(format!("d{level}"));
    }
    fs::create_dir_all(&deep).unwrap();
    fs::write(deep.join("lost.result.json"), &good).unwrap();
}

fn library() -> (tempfile::TempDir, Library) {
    let dir = tempfile::tempdir().unwrap();
    write_library(dir.path());
    let library = history::read_library(dir.path()).unwrap();
    (dir, library)
}

fn irb_drift(library: &Library) -> Drift {
    history::drift(library, IRB, &DriftOptions::default()).unwrap()
}

fn date(library: &Library, entry: usize) -> String {
    library.entries[entry].date.to_string()
}

#[test]
fn jumps_are_flagged_at_the_right_date_and_parameter_and_repeats_are_not() {
    let (_dir, library) = library();
    let drift = irb_drift(&library);
    assert_eq!(drift.entries.len(), 8, "7 ml results and one paper result");
    let flagged: Vec<(String, String, f64)> = drift
        .jumps()
        .map(|c| (date(&library, c.to), c.parameter.clone(), c.ratio.unwrap()))
        .collect();
    // The sensor moved along its y axis: in the flange frame that is a
    // move along (R_es · y) = (0.49, −0.87, 0.01), so x and y jump, z not.
    let at = |d: &str| -> Vec<&str> {
        flagged
            .iter()
            .filter(|f| f.0 == d)
            .map(|f| f.1.as_str())
            .collect()
    };
    assert_eq!(at(SENSOR_DATE), ["hand_eye.x", "hand_eye.y"], "{flagged:?}");
    assert_eq!(at(JOINT_DATE), ["theta3"], "{flagged:?}");
    assert_eq!(flagged.len(), 3, "no flag among the repeats: {flagged:?}");

    // The sizes of the flagged changes are the injected ones.
    let check = |d: &str, p: &str| {
        drift
            .checks
            .iter()
            .find(|c| date(&library, c.to) == d && c.parameter == p)
            .unwrap()
    };
    let dx = check(SENSOR_DATE, "hand_eye.x").change;
    let dy = check(SENSOR_DATE, "hand_eye.y").change;
    let moved = dx.hypot(dy);
    assert!(
        (moved - SENSOR_SHIFT_MM).abs() < 0.06,
        "the hand-eye moved {moved} mm in x-y, the sensor {SENSOR_SHIFT_MM} mm"
    );
    let theta3 = check(JOINT_DATE, "theta3");
    assert!(
        (theta3.change - JOINT3_SHIFT_DEG).abs() < 3.0 * theta3.combined.unwrap(),
        "{theta3:?}"
    );
    // theta3 carries the fixed beta4 (ml: beta4 ~ theta3, d4): said.
    assert!(
        theta3.notes.iter().any(|n| n.contains("beta4")),
        "{:?}",
        theta3.notes
    );
    // The jumped theta3 is among the series shown.
    assert!(drift.series("theta3").is_some());
}

#[test]
fn sigma_explains_the_scatter_of_repeats() {
    // Between repeats of one truth the change over its combined σ is a
    // standard normal if the σ the library carries is right (ml's
    // covariance, carried to x, y, z, roll, pitch, yaw for the hand-eye).
    // Pool every steady check between the five repeats: ~110 values, so
    // the mean square has a standard error of ~0.14.
    let (_dir, library) = library();
    let drift = irb_drift(&library);
    let repeats_end = "2026-05-04".to_string();
    let ratios: Vec<(String, f64)> = drift
        .checks
        .iter()
        .filter(|c| date(&library, c.to) <= repeats_end)
        .filter_map(|c| c.ratio.map(|r| (c.parameter.clone(), r)))
        .collect();
    assert!(ratios.len() >= 90, "{}", ratios.len());
    let mean_square = ratios.iter().map(|(_, r)| r * r).sum::<f64>() / ratios.len() as f64;
    assert!(
        (0.5..2.0).contains(&mean_square),
        "mean square of change/σ over repeats: {mean_square}"
    );
    // The hand-eye alone (24 values): its σ goes through the Jacobian.
    let he: Vec<f64> = ratios
        .iter()
        .filter(|(p, _)| p.starts_with("hand_eye."))
        .map(|(_, r)| r * r)
        .collect();
    assert_eq!(he.len(), 24);
    let he_ms = he.iter().sum::<f64>() / he.len() as f64;
    assert!((0.3..3.0).contains(&he_ms), "hand-eye mean square {he_ms}");
}

#[test]
fn paper_results_are_not_checked_and_do_not_break_the_chain() {
    let (_dir, library) = library();
    let drift = irb_drift(&library);
    let paper = drift
        .entries
        .iter()
        .copied()
        .find(|&e| library.entries[e].method == "paper")
        .unwrap();
    assert_eq!(date(&library, paper), "2026-03-16");
    let into: Vec<_> = drift.checks.iter().filter(|c| c.to == paper).collect();
    assert!(!into.is_empty());
    for c in &into {
        match &c.verdict {
            Verdict::NotChecked(reason) => assert!(reason.contains("paper"), "{reason}"),
            v => panic!("{}: {v:?}", c.parameter),
        }
        assert!(c.sigma_after.is_none());
    }
    // The next ml result is compared with the ml result before the paper one.
    let april = drift
        .checks
        .iter()
        .find(|c| date(&library, c.to) == "2026-04-06" && c.parameter == "hand_eye.x")
        .unwrap();
    assert_eq!(date(&library, april.from), "2026-03-02");
    assert_eq!(april.verdict, Verdict::Steady);
    assert!(
        april.notes.iter().any(|n| n.contains("no σ")),
        "{:?}",
        april.notes
    );
    // A paper result has values but no σ and no identifiability.
    let p = library.entries[paper].param("theta3").unwrap();
    assert!(p.sigma.is_none());
    assert_eq!(p.status, Status::Unknown);
    assert!(library.entries[paper].kept_directions.is_some());
}

#[test]
fn identifiability_and_uncertainty_come_from_the_ml_block() {
    let (_dir, library) = library();
    let e = library
        .entries
        .iter()
        .find(|e| e.session == "IRB2400 cell 3, 2026-01-05")
        .unwrap();
    assert_eq!(e.method, "ml");
    // ml fixes the rigid motions of the base, d6 (with he_z) and theta6
    // (with he_rz) among others; they are never checked for jumps.
    for fixed in ["theta1", "d1", "d6", "theta6"] {
        let p = e.param(fixed).unwrap();
        assert_eq!(p.status, Status::Fixed, "{fixed}");
        assert!(p.sigma.is_none());
    }
    let drift = irb_drift(&library);
    assert!(
        !drift
            .checks
            .iter()
            .any(|c| ["theta1", "d1", "d6", "theta6"].contains(&c.parameter.as_str())),
    );
    // Every hand-eye value and theta3 are estimated with a σ.
    for name in HAND_EYE_NAMES.iter().copied().chain(["theta3"]) {
        let p = e.param(name).unwrap();
        assert_eq!(p.status, Status::Estimated, "{name}");
        assert!(p.sigma.unwrap() > 0.0, "{name}");
    }
    // Values: the hand-eye is the result's matrix; joint errors as written.
    let t = e.hand_eye.translation;
    assert_eq!(e.param("hand_eye.z").unwrap().value, t[2]);
    assert_eq!(
        e.param("theta3").unwrap().value,
        calibrations()[0].result.joint_errors[2].theta
    );
    assert!(
        e.combinations
            .iter()
            .any(|c| c.fixed == ["d6"] && c.partners == ["he_z"])
    );
    // The main deviations include the paper's largest identifiable Table 1
    // errors (theta3 0.76°, beta3 0.71°).
    let main: Vec<&str> = drift
        .series
        .iter()
        .filter(|s| matches!(s.kind, SeriesKind::Main { .. }))
        .map(|s| s.name.as_str())
        .collect();
    assert_eq!(main.len(), history::DEFAULT_TOP);
    assert!(
        main.contains(&"theta3") && main.contains(&"beta3"),
        "{main:?}"
    );
    // Library table figures.
    let v = e.validation_after.unwrap();
    assert_eq!(
        v.std,
        calibrations()[0]
            .result
            .validation
            .as_ref()
            .unwrap()
            .after
            .std
    );
    assert!(e.within_station_after.is_some());
}

#[test]
fn bad_files_are_reported_and_the_scan_goes_on() {
    let (dir, library) = library();
    let problems: Vec<String> = library
        .problems
        .iter()
        .map(|p| {
            p.path
                .strip_prefix(dir.path())
                .unwrap()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    assert_eq!(problems.len(), 3, "{:?}", library.problems);
    assert!(problems.contains(&"broken.result.json".to_string()));
    assert!(problems.contains(&"typo.json".to_string()));
    assert!(
        problems.iter().any(|p| p.ends_with("d7/d8")),
        "{problems:?}"
    );
    let typo = library
        .problems
        .iter()
        .find(|p| p.path.ends_with("typo.json"))
        .unwrap();
    assert!(typo.message.contains("spehre"), "{typo}");
    assert!(
        library
            .problems
            .iter()
            .find(|p| p.path.ends_with("broken.result.json"))
            .unwrap()
            .message
            .contains("not valid JSON")
    );
    // Foreign JSON is ignored, not a problem; text and hidden files unseen.
    assert_eq!(library.ignored.len(), 2, "{:?}", library.ignored);
    assert!(
        library
            .ignored
            .iter()
            .any(|(_, f)| f.as_deref() == Some("someone-else"))
    );
    // Every good calibration is there, the nested one too.
    assert_eq!(library.entries.len(), calibrations().len());
    assert!(library.entries.iter().any(|e| {
        e.path
            .ends_with("archive/2026/cell3-2026-02-02.result.json")
    }));
    // Pairing: by file name, and by session name across folders.
    let april = library
        .entries
        .iter()
        .find(|e| e.path.ends_with("results/april.result.json"))
        .unwrap();
    assert_eq!(april.paired_by, Some(history::PairedBy::SessionName));
    assert!(
        april
            .session_path
            .as_ref()
            .unwrap()
            .ends_with("sessions/cell3-2026-04-06.json")
    );
    assert!(library.entries.iter().all(|e| e.session_path.is_some()));
    assert_eq!(
        library
            .entries
            .iter()
            .filter(|e| e.paired_by == Some(history::PairedBy::FileName))
            .count(),
        calibrations().len() - 1
    );
    // Entries are in date order.
    assert!(library.entries.windows(2).all(|w| w[0].date <= w[1].date));
    // A folder that cannot be scanned is an error, not an empty library.
    assert!(matches!(
        history::read_library(&dir.path().join("missing")),
        Err(history::HistoryError::Folder { .. })
    ));
    assert!(matches!(
        history::read_library(&dir.path().join("readme.txt")),
        Err(history::HistoryError::NotAFolder { .. })
    ));
}

/// Issue 12: `history` skipped symlinked subfolders silently and rejected
/// a result with a UTF-8 BOM that `calibrate` and `report` accept. Linked
/// folders are followed; a link back (a loop) is reported once, not
/// followed forever; a BOM is skipped.
#[cfg(unix)]
#[test]
fn linked_folders_are_followed_without_loops_and_a_bom_is_accepted() {
    let top = tempfile::tempdir().unwrap();
    let lib = top.path().join("lib");
    let outside = top.path().join("elsewhere");
    fs::create_dir_all(&lib).unwrap();
    let (_, linked_result) = write_pair(&outside, &calibrations()[0]);
    std::os::unix::fs::symlink(&outside, lib.join("linked")).unwrap();
    std::os::unix::fs::symlink(&lib, outside.join("back")).unwrap();
    let bom = format!(
        "\u{feff}{}",
        format::result_to_json(&calibrations()[1].result)
    );
    fs::write(lib.join("bom.result.json"), bom).unwrap();

    let library = history::read_library(&lib).unwrap();
    let found: Vec<&Path> = library.entries.iter().map(|e| e.path.as_path()).collect();
    assert_eq!(found.len(), 2, "{found:?} {:?}", library.problems);
    assert!(
        found.contains(
            &lib.join("linked")
                .join(linked_result.file_name().unwrap())
                .as_path()
        )
    );
    assert!(found.contains(&lib.join("bom.result.json").as_path()));
    // The result in the linked folder is paired with its session there.
    assert_eq!(library.sessions.len(), 1);
    assert_eq!(library.problems.len(), 1, "{:?}", library.problems);
    assert!(library.problems[0].path.ends_with("linked/back"));
    assert!(
        library.problems[0].message.contains("already scanned"),
        "{}",
        library.problems[0].message
    );
}

#[test]
fn a_second_robot_is_kept_apart() {
    let (_dir, library) = library();
    let robots = library.robots();
    assert_eq!(robots.len(), 2, "{robots:?}");
    assert_eq!(robots[0], (IRB.to_string(), 8));
    assert_eq!(robots[1].1, 2);
    let ur = library.find_robot("ur5e").unwrap();
    assert_eq!(ur, robots[1].0);
    let d = history::drift(&library, &ur, &DriftOptions::default()).unwrap();
    assert_eq!(d.entries.len(), 2);
    assert!(
        d.entries
            .iter()
            .all(|&e| library.entries[e].session.starts_with("UR5e"))
    );
    // Its two repeats: no jump; the IRB's dates in between play no part.
    assert_eq!(d.jumps().count(), 0, "{:?}", d.jumps().collect::<Vec<_>>());
    assert!(d.checks.iter().all(|c| d.entries.contains(&c.from)));
    let irb = irb_drift(&library);
    assert!(irb.entries.iter().all(|&e| library.entries[e].robot == IRB));
    assert!(matches!(
        library.find_robot("kuka"),
        Err(history::HistoryError::UnknownRobot { .. })
    ));
    // "r" is in both names.
    assert!(matches!(
        library.find_robot("r"),
        Err(history::HistoryError::AmbiguousRobot { .. })
    ));
}

#[test]
fn chosen_parameters_and_options() {
    let (_dir, library) = library();
    let options = DriftOptions {
        k: DEFAULT_K,
        top: 2,
        extra: vec!["a2".into(), "theta3".into()],
    };
    let d = history::drift(&library, IRB, &options).unwrap();
    let kinds: Vec<(&str, String)> = d
        .series
        .iter()
        .map(|s| (s.name.as_str(), s.kind.label(d.mount)))
        .collect();
    assert_eq!(
        kinds.len(),
        6 + 2 + 1 + usize::from(!kinds.iter().any(|k| k.0 == "theta3"))
    );
    assert!(kinds.contains(&("a2", "chosen".to_string())), "{kinds:?}");
    // Every series has one point per result, in date order.
    for s in &d.series {
        assert_eq!(s.points.len(), d.entries.len(), "{}", s.name);
        assert!(s.points.windows(2).all(|w| w[0].date <= w[1].date));
    }
    // A huge k flags nothing; a bad k or parameter is an error.
    let lax = DriftOptions {
        k: 1000.0,
        ..DriftOptions::default()
    };
    assert_eq!(
        history::drift(&library, IRB, &lax).unwrap().jumps().count(),
        0
    );
    for k in [0.0, -1.0, f64::NAN] {
        let bad = DriftOptions {
            k,
            ..DriftOptions::default()
        };
        assert!(matches!(
            history::drift(&library, IRB, &bad),
            Err(history::HistoryError::InvalidK { .. })
        ));
    }
    let bad = DriftOptions {
        extra: vec!["theta9".into()],
        ..DriftOptions::default()
    };
    assert!(matches!(
        history::drift(&library, IRB, &bad),
        Err(history::HistoryError::UnknownParameter { .. })
    ));
}

fn set_mtime(path: &Path, t: SystemTime) {
    fs::File::options()
        .write(true)
        .open(path)
        .unwrap()
        .set_modified(t)
        .unwrap();
}

#[test]
fn dates_come_from_names_then_file_names_then_file_times() {
    let dir = tempfile::tempdir().unwrap();
    let base = &calibrations()[0];
    // 2026-08-01 12:00:00 UTC and 2026-09-02 08:30:00 UTC.
    let aug = UNIX_EPOCH + Duration::from_hours(495996);
    let sep = UNIX_EPOCH + Duration::from_mins(29805630);
    let undated = |stem: &str, session_name: &str| Cal {
        stem: stem.to_string(),
        session: Session {
            name: session_name.to_string(),
            ..base.session.clone()
        },
        result: ResultFile {
            session: session_name.to_string(),
            ..base.result.clone()
        },
    };
    // 1. A date and time in the session name.
    write_pair(dir.path(), &undated("a", "cell 3 2026-10-03T07:45"));
    // 2. None in the name, one in the file name.
    write_pair(dir.path(), &undated("run-2026-11-04", "cell 3 run"));
    // 3. None in either: the session file's time.
    let (s, r) = write_pair(dir.path(), &undated("b", "cell 3 again"));
    set_mtime(&s, aug);
    set_mtime(&r, sep);
    // 4. A result alone: its own file time.
    let (s, r) = write_pair(dir.path(), &undated("c", "cell 3 alone"));
    fs::remove_file(s).unwrap();
    set_mtime(&r, sep);

    let library = history::read_library(dir.path()).unwrap();
    let found = |session: &str| {
        let e = library
            .entries
            .iter()
            .find(|e| e.session == session)
            .unwrap();
        (e.date.to_string(), e.date_source)
    };
    assert_eq!(
        found("cell 3 2026-10-03T07:45"),
        ("2026-10-03 07:45:00".into(), DateSource::SessionName)
    );
    assert_eq!(
        found("cell 3 run"),
        ("2026-11-04".into(), DateSource::FileName)
    );
    assert_eq!(
        found("cell 3 again"),
        ("2026-08-01 12:00:00".into(), DateSource::SessionModified)
    );
    assert_eq!(
        found("cell 3 alone"),
        ("2026-09-02 08:30:00".into(), DateSource::ResultModified)
    );
    // Date order across sources, and the drift says that dates came from
    // file times.
    let order: Vec<&str> = library.entries.iter().map(|e| e.session.as_str()).collect();
    assert_eq!(
        order,
        [
            "cell 3 again",
            "cell 3 alone",
            "cell 3 2026-10-03T07:45",
            "cell 3 run"
        ]
    );
    let d = history::drift(&library, IRB, &DriftOptions::default()).unwrap();
    assert!(
        d.notes.iter().any(|n| n.contains("file times")),
        "{:?}",
        d.notes
    );
    // The same data four times: nothing moves.
    assert_eq!(d.jumps().count(), 0);
    assert!(
        d.checks
            .iter()
            .filter(|c| c.verdict == Verdict::Steady)
            .all(|c| c.change.abs() < 1e-12)
    );
    assert_eq!(
        Timestamp::date(2026, 10, 3).unwrap().at(7, 45, 0),
        history::date_in_name("cell 3 2026-10-03T07:45")
    );
}

#[test]
fn csv_has_every_parameter_of_every_result() {
    let (_dir, library) = library();
    let d = irb_drift(&library);
    let csv = history::drift_csv(&library, std::slice::from_ref(&d));
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "robot,date,date_source,result,session,method,parameter,unit,value,sigma,status,prior_held,series"
    );
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), d.entries.len() * 36);
    // Session names hold commas: quoted.
    assert!(
        rows[0].contains("\"IRB2400 cell 3, 2026-01-05\""),
        "{}",
        rows[0]
    );
    let theta3_june = rows
        .iter()
        .find(|r| r.contains(JOINT_DATE) && r.contains(",theta3,"))
        .unwrap();
    assert!(
        theta3_june.ends_with(",jumped") || theta3_june.contains(",main "),
        "{theta3_june}"
    );
}

fn spherecal(args: &[&str], folder: &Path) -> (i32, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_spherecal"))
        .arg("history")
        .arg(folder)
        .args(args)
        .output()
        .unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn command_line_prints_the_library_drift_and_jumps() {
    let (dir, _library) = library();
    let csv = dir.path().join("out/drift.csv");
    fs::create_dir_all(dir.path().join("out")).unwrap();
    let csv_arg = csv.to_string_lossy().into_owned();
    let (status, out, err) = spherecal(&["--robot", "irb 2400", "--csv", &csv_arg], dir.path());
    assert_eq!(status, 0, "{err}");
    assert!(out.contains("IRB2400 cell 3, 2026-01-05"), "{out}");
    assert!(out.contains("session name"), "{out}");
    assert!(!out.contains("UR5e cell 7"), "only the chosen robot: {out}");
    let jump_lines: Vec<&str> = out
        .lines()
        .filter(|l| l.contains(" → ") && l.contains("ratio"))
        .collect();
    assert_eq!(jump_lines.len(), 3, "{out}");
    assert!(jump_lines[0].starts_with(&format!("  2026-05-04 → {SENSOR_DATE}  hand_eye.x")));
    assert!(jump_lines[2].contains(&format!("→ {JOINT_DATE}  theta3")));
    assert!(
        out.contains("no uncertainty in the result (paper method)"),
        "{out}"
    );
    assert!(out.contains("problems (files not used):"), "{out}");
    let written = fs::read_to_string(&csv).unwrap();
    assert_eq!(written.lines().count(), 1 + 8 * 36);

    // All robots without --robot.
    let (status, out, _) = spherecal(&[], dir.path());
    assert_eq!(status, 0);
    assert!(
        out.contains("== ABB IRB 2400/16") && out.contains("== Universal Robots UR5e"),
        "{out}"
    );

    // Bad input: one error line, exit 2.
    for (args, folder, needle) in [
        (
            vec!["--robot", "kuka"],
            dir.path().to_path_buf(),
            "no result of a robot",
        ),
        (vec![], dir.path().join("missing"), "cannot read the folder"),
        (
            vec!["--param", "theta9"],
            dir.path().to_path_buf(),
            "unknown parameter",
        ),
    ] {
        let (status, out, err) = spherecal(&args, &folder);
        assert_eq!(status, 2, "{args:?}: {out}{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.starts_with("error: ") && err.contains(needle), "{err}");
    }
    let (status, _, err) = spherecal(&["--k", "0"], dir.path());
    assert_eq!(status, 2);
    assert!(err.contains("positive"), "{err}");
}

#[test]
fn the_example_library_shows_its_two_events() {
    // sessions/history (make.sh): three repeats, a sensor remount on
    // 2026-04-13, a joint-3 zero change on 2026-05-11.
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("sessions/history");
    let library = history::read_library(&folder).unwrap();
    assert!(library.problems.is_empty(), "{:?}", library.problems);
    assert_eq!(library.entries.len(), 5);
    assert!(library.entries.iter().all(|e| {
        e.date_source == DateSource::SessionName && e.paired_by == Some(history::PairedBy::FileName)
    }));
    let d = irb_drift(&library);
    let jumps: Vec<(String, &str)> = d
        .jumps()
        .map(|c| (date(&library, c.to), c.parameter.as_str()))
        .collect();
    assert_eq!(
        jumps,
        [
            ("2026-04-13".to_string(), "hand_eye.x"),
            ("2026-04-13".to_string(), "hand_eye.y"),
            ("2026-05-11".to_string(), "theta3"),
        ]
    );
}

/// A copy of the first calibration under another date, its `ml` report
/// edited by `edit`.
fn edited(date: &str, edit: impl Fn(&mut MlReport)) -> Cal {
    let base = &calibrations()[0];
    let name = format!("IRB2400 cell 3, {date}");
    let mut result = base.result.clone();
    result.session.clone_from(&name);
    if let SolverReport::Ml(report) = &mut result.solver {
        edit(report);
    }
    Cal {
        stem: format!("edited-{date}"),
        session: Session {
            name,
            ..base.session.clone()
        },
        result,
    }
}

#[test]
fn variance_factor_prior_and_fixed_sets_are_respected() {
    let dir = tempfile::tempdir().unwrap();
    let theta3_std = |report: &SolverReport| {
        report
            .ml()
            .unwrap()
            .parameters
            .iter()
            .find(|p| p.parameter == "theta3")
            .unwrap()
            .std
    };
    let reported = theta3_std(&calibrations()[0].result.solver);
    // 1. As calibrated.
    write_pair(dir.path(), &edited("2026-01-01", |_| {}));
    // 2. An optimistic noise model (variance factor 4): every σ doubles.
    //    theta3's σ also made 0.15° (≥ half the 0.2° prior): prior-held.
    write_pair(
        dir.path(),
        &edited("2026-02-01", |b| {
            b.variance_factor = 4.0;
            for p in &mut b.parameters {
                if p.parameter == "theta3" {
                    p.std = 0.15;
                }
            }
        }),
    );
    // 3. d4 fixed (d4 ~ a3): d4 is then not comparable, a3 carries
    //    something else, theta3 is unaffected.
    write_pair(
        dir.path(),
        &edited("2026-03-01", |b| {
            b.estimated.retain(|x| x != "d4");
            b.fixed.push("d4".into());
            b.inseparable.push(Inseparable::Combination {
                fixed: "d4".into(),
                partners: vec![Partner {
                    parameter: "a3".into(),
                    undo: -1.0,
                }],
                explained_pct: None,
            });
        }),
    );
    let library = history::read_library(dir.path()).unwrap();
    let e = &library.entries;
    assert_eq!(
        e[0].sigma_scale,
        1.0_f64.max(e[0].variance_factor.unwrap()).sqrt()
    );
    assert_eq!(e[1].sigma_scale, 2.0);
    let s0 = e[0].param("hand_eye.x").unwrap().sigma.unwrap();
    let s1 = e[1].param("hand_eye.x").unwrap().sigma.unwrap();
    assert!(
        (s1 / s0 - 2.0 / e[0].sigma_scale).abs() < 1e-12,
        "{s0} {s1}"
    );
    let t1 = e[1].param("theta3").unwrap();
    assert!(t1.prior_held);
    assert_eq!(t1.sigma, Some(0.3));
    assert!(!e[0].param("theta3").unwrap().prior_held);
    assert!(
        (e[0].param("theta3").unwrap().sigma.unwrap() - reported * e[0].sigma_scale).abs() < 1e-15
    );
    assert_eq!(e[2].param("d4").unwrap().status, Status::Fixed);

    let d = irb_drift(&library);
    let check = |to: usize, p: &str| {
        d.checks
            .iter()
            .find(|c| c.to == to && c.parameter == p)
            .unwrap_or_else(|| panic!("no check of {p} into entry {to}"))
    };
    // Same data: nothing moves, the prior-held one is said to be weak.
    let c = check(1, "theta3");
    assert_eq!(c.verdict, Verdict::Steady);
    assert!(c.notes.iter().any(|n| n.contains("prior")), "{:?}", c.notes);
    let reason = |c: &history::JumpCheck| match &c.verdict {
        Verdict::NotChecked(r) => r.clone(),
        v => panic!("{}: {v:?}", c.parameter),
    };
    assert!(reason(check(2, "d4")).contains("fixed in the other"));
    assert!(reason(check(2, "a3")).contains("fixed different parameters (d4)"));
    assert_eq!(check(2, "theta3").verdict, Verdict::Steady);
    assert_eq!(check(2, "hand_eye.x").verdict, Verdict::Steady);
}
