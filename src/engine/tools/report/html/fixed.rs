//! The report's section for a fixed sensor (FORMAT.md `sensor.mount:
//! "fixed"`): the sensor's pose in the base frame, the targets on the
//! flange, and each validate pose's predicted point against the measured
//! one, before and after.

use std::fmt::Write as _;

use super::{Ctx, end_section, escape, head_row, num, section};
use crate::engine::base::geometry::roll_pitch_yaw_deg;
use crate::engine::base::session::Mount;
use crate::engine::files::format::result::CentreRecord;
use crate::engine::files::format::stations::{prediction_errors, stations_of};

/// The section, written only for a fixed sensor.
pub(super) fn fixed_sensor(h: &mut String, ctx: &Ctx<'_>) {
    let result = ctx.result();
    if result.mount() != Mount::Fixed {
        return;
    }
    section(
        h,
        "fixed-sensor",
        "Fixed sensor: base from sensor, targets, prediction",
    );
    h.push_str("<p>The sensor stands in the cell and measures targets on the tool: the result's <code>hand_eye</code> is the sensor's pose in the base frame (<code>base_from_sensor</code>) and every station is a point on the flange. A shifted base and a shifted sensor cannot be told apart, so the first joint's parameters are held at nominal and <code>base_from_sensor</code> takes them up; the last joint's <code>theta</code> and <code>d</code> are taken up by the targets.</p>\n");
    let t = result.hand_eye.translation.vector;
    let rpy = roll_pitch_yaw_deg(&result.hand_eye.rotation);
    let _ = writeln!(
        h,
        "<p>base from sensor: translation ({}, {}, {}) mm; roll, pitch, yaw ({}, {}, {})°.</p>",
        num(t.x, 3),
        num(t.y, 3),
        num(t.z, 3),
        num(rpy[0], 4),
        num(rpy[1], 4),
        num(rpy[2], 4)
    );
    h.push_str("<table class=\"keep\">\n");
    head_row(h, &["target", "#x (mm)", "#y (mm)", "#z (mm)", "frame"]);
    for st in &result.stations {
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td>{}</td></tr>",
            escape(&st.id),
            num(st.point[0], 3),
            num(st.point[1], 3),
            num(st.point[2], 3),
            escape(&st.frame)
        );
    }
    h.push_str("</table>\n");
    let after = prediction_errors(&result.centres, &result.stations);
    if after.is_empty() {
        h.push_str("<p>No validate measurements: the prediction is not checked.</p>\n");
        end_section(h);
        return;
    }
    let before_rows: Vec<CentreRecord> = result
        .centres
        .iter()
        .map(|c| CentreRecord {
            after: c.before,
            ..c.clone()
        })
        .collect();
    let before = prediction_errors(&before_rows, &stations_of(&before_rows, Mount::Fixed));
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt();
    let a: Vec<f64> = after.iter().map(|p| p.error).collect();
    let b: Vec<f64> = before.iter().map(|p| p.error).collect();
    let _ = writeln!(
        h,
        "<p>Each validate pose's predicted point against the measured one (sensor frame, mm): rms {} → {} mm over {} measurements.</p>",
        num(rms(&b), 4),
        num(rms(&a), 4),
        a.len()
    );
    h.push_str("<table class=\"small\">\n");
    head_row(h, &["measurement", "target", "#before (mm)", "#after (mm)"]);
    for (p, q) in after.iter().zip(&before) {
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td></tr>",
            escape(&p.measurement),
            escape(&p.station),
            num(q.error, 4),
            num(p.error, 4)
        );
    }
    h.push_str("</table>\n");
    end_section(h);
}
