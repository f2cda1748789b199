//! From a finished [`Calibration`] to what people and files read: the
//! FORMAT.md result file ([`result_file`]) and a short text summary
//! ([`summary`]) for the command line.

use std::fmt::Write as _;

use crate::engine::format::result::{CentreRecord, IterationRecord, ResultFile, RobotRecord};
use crate::engine::geometry::rows_from_isometry;
use crate::engine::session::Session;
use crate::engine::solve::{Calibration, Prepared};

/// The FORMAT.md result file of a run.
#[must_use]
pub fn result_file(session: &Session, prepared: &Prepared, cal: &Calibration) -> ResultFile {
    let _ = prepared;
    ResultFile {
        session: session.name.clone(),
        hand_eye_initial: rows_from_isometry(&cal.hand_eye_initial),
        hand_eye: rows_from_isometry(&cal.hand_eye),
        robot: RobotRecord {
            name: cal.calibrated.name.clone(),
            joints: cal.calibrated.joints.clone(),
            base: rows_from_isometry(&cal.calibrated.base),
            flange: rows_from_isometry(&cal.calibrated.flange),
        },
        joint_errors: cal.calibrated.joint_errors(&cal.nominal),
        solver: cal.solver.clone(),
        iterations: cal
            .iterations
            .iter()
            .map(|&epsilon| IterationRecord { epsilon })
            .collect(),
        epsilon_before: cal.epsilon_before(),
        epsilon_after: cal.epsilon_after(),
        centres: cal
            .centres
            .iter()
            .map(|c| {
                let m = &session.measurements[c.index];
                CentreRecord {
                    measurement: m.id.clone(),
                    station: m.station.clone(),
                    usage: m.usage.as_str().to_string(),
                    sensor: c.sensor.into(),
                    before: c.before.into(),
                    after: c.after.into(),
                }
            })
            .collect(),
        validation: cal.validation.clone(),
    }
}

/// A few lines for people: why the loop stopped, what the SVD kept, how
/// the hand-eye moved, and the before/after validation figures.
#[must_use]
pub fn summary(session: &Session, cal: &Calibration) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "{}", cal.stop.describe());
    let _ = writeln!(
        s,
        "ε: {:.4} mm before, {:.4} mm after",
        cal.epsilon_before(),
        cal.epsilon_after()
    );
    if let Some(u) = &cal.last_update {
        let _ = writeln!(
            s,
            "SVD: kept {} of {} directions (tolerance {:.1e} of σ_max), {} equations",
            u.kept,
            u.delta.len(),
            cal.options.paper.svd_tolerance,
            u.rows
        );
        for d in &u.dropped {
            let _ = writeln!(s, "  not identifiable from this data: {d}");
        }
    }
    let dr = cal
        .hand_eye_initial
        .rotation
        .angle_to(&cal.hand_eye.rotation)
        .to_degrees();
    let dt = (cal.hand_eye.translation.vector - cal.hand_eye_initial.translation.vector).norm();
    let t = cal.hand_eye.translation.vector;
    let _ = writeln!(
        s,
        "hand-eye: translation ({:.3}, {:.3}, {:.3}) mm; moved {dt:.3} mm and {dr:.4}° from the initial estimate",
        t.x, t.y, t.z
    );
    let within = &cal.identify_within;
    let _ = writeln!(
        s,
        "identify stations, centre distances: std {:.4} → {:.4} mm, max {:.4} → {:.4} mm",
        within.before.std, within.after.std, within.before.max, within.after.max
    );
    match &cal.validation {
        Some(v) if !v.distances.is_empty() => {
            let _ = writeln!(
                s,
                "validation, {} reference distances (measured − reference): std {:.4} → {:.4} mm, max {:.4} → {:.4} mm, rms {:.4} → {:.4} mm",
                v.distances.len(),
                v.before.std,
                v.after.std,
                v.before.max,
                v.after.max,
                v.before.rms,
                v.after.rms
            );
            let _ = writeln!(
                s,
                "validation, within-station centre distances: std {:.4} → {:.4} mm, max {:.4} → {:.4} mm",
                v.within_station.before.std,
                v.within_station.after.std,
                v.within_station.before.max,
                v.within_station.after.max
            );
        }
        Some(v) => {
            let _ = writeln!(
                s,
                "validation (no reference distances), within-station centre distances: std {:.4} → {:.4} mm, max {:.4} → {:.4} mm",
                v.within_station.before.std,
                v.within_station.after.std,
                v.within_station.before.max,
                v.within_station.after.max
            );
        }
        None => {
            let _ = writeln!(
                s,
                "no validate measurements in session {:?}: accuracy not checked",
                session.name
            );
        }
    }
    s
}
