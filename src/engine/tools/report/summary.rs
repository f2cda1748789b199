//! The command line's text summary of a finished [`Calibration`].

use std::fmt::Write as _;

use crate::engine::tools::result_view::{HAND_EYE_ONLY, HandEyeStrength, flange_poses};

use crate::engine::base::session::{Mount, Session};
use crate::engine::calibrate::solve::Calibration;
use crate::engine::calibrate::solve::plausible::identify_scatter;
use crate::engine::calibrate::validate::Stats;
use crate::engine::files::format::ResultFile;
use crate::engine::files::format::stations::prediction_errors;

/// A few lines for people: why the loop stopped (and a warning when the
/// paper's loop made ε worse), what the SVD kept, how the hand-eye moved,
/// the held-out figure beside the fit's own scatter, and the before/after
/// validation figures.
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
    if let Some(w) = cal
        .report
        .epsilon_warning(cal.epsilon_before(), cal.epsilon_after())
    {
        let _ = writeln!(s, "warning: {w}");
    }
    if let Some((p, kept)) = cal
        .report
        .paper()
        .and_then(|p| p.kept_directions.map(|k| (p, k)))
    {
        let _ = writeln!(
            s,
            "SVD: kept {} of {} directions (tolerance {:.1e} of σ_max), {} equations",
            kept,
            p.unknowns.as_ref().map_or(0, Vec::len),
            cal.options.paper.svd_tolerance,
            p.equations.unwrap_or(0)
        );
        for d in p.dropped_directions.iter().flatten() {
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
    let what = match session.mount {
        Mount::Flange => "hand-eye",
        Mount::Fixed => "base from sensor",
    };
    let _ = writeln!(
        s,
        "{what}: translation ({:.3}, {:.3}, {:.3}) mm; moved {dt:.3} mm and {dr:.4}° from the initial estimate",
        t.x, t.y, t.z
    );
    let within = &cal.identify_within;
    let _ = writeln!(
        s,
        "identify stations, centre distances: std {:.4} → {:.4} mm, max {:.4} → {:.4} mm",
        within.before.std, within.after.std, within.before.max, within.after.max
    );
    let (before, after) = identify_scatter(session, cal);
    let _ = writeln!(
        s,
        "identify stations, centre scatter about each station's mean (3-D rms): {before:.4} → {after:.4} mm"
    );
    if let Some(h) = &cal.held_out {
        let _ = writeln!(s, "{h}");
    }
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
    if session.mount == Mount::Fixed {
        fixed_lines(&mut s, session, cal);
    }
    if let Some(r) = cal.report.ml() {
        s.push_str(&r.summary());
    }
    if session.pose_only() {
        let _ = writeln!(s, "{HAND_EYE_ONLY}");
        let poses = flange_poses(session);
        if let Some(strength) = cal
            .report
            .ml()
            .and_then(|r| HandEyeStrength::of(r, poses.as_deref()))
        {
            for line in strength.lines() {
                let _ = writeln!(s, "{line}");
            }
        }
    }
    s
}

/// A fixed sensor's lines (FORMAT.md 2026-11-27): each target's point on
/// the flange, and the held-out check, each validate pose's predicted
/// point against the measured one.
fn fixed_lines(s: &mut String, session: &Session, cal: &Calibration) {
    let result = ResultFile::from_calibration(session, cal);
    for st in &result.stations {
        let _ = writeln!(
            s,
            "target {} on the flange: ({:.3}, {:.3}, {:.3}) mm",
            st.id, st.point[0], st.point[1], st.point[2]
        );
    }
    let after: Vec<f64> = prediction_errors(&result.centres, &result.stations)
        .iter()
        .map(|p| p.error)
        .collect();
    if after.is_empty() {
        return;
    }
    let before_records: Vec<_> = result
        .centres
        .iter()
        .map(|c| crate::engine::files::format::result::CentreRecord {
            after: c.before,
            ..c.clone()
        })
        .collect();
    let before_stations =
        crate::engine::files::format::stations::stations_of(&before_records, session.mount);
    let before: Vec<f64> = prediction_errors(&before_records, &before_stations)
        .iter()
        .map(|p| p.error)
        .collect();
    let (b, a) = (Stats::of(&before), Stats::of(&after));
    let _ = writeln!(
        s,
        "validation, {} validate poses, predicted point against the measured one (sensor frame): rms {:.4} → {:.4} mm, max {:.4} → {:.4} mm",
        after.len(),
        b.rms,
        a.rms,
        b.max,
        a.max
    );
}
