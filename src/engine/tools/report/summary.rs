//! The command line's text summary of a finished [`Calibration`].

use std::fmt::Write as _;

use crate::engine::tools::result_view::{HAND_EYE_ONLY, HandEyeStrength, flange_poses};

use crate::engine::base::session::Session;
use crate::engine::calibrate::solve::Calibration;
use crate::engine::calibrate::solve::plausible::identify_scatter;

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
