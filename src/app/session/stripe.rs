//! The Stripe view: the selected measurement's stripe points and fitted
//! circle in the laser plane (equal axes, mm), the rejected points marked,
//! and the residuals. The arrow keys step through the table's order.

use std::f64::consts::TAU;

use egui::RichText;
use egui_plot::{HLine, Line, LineStyle, MarkerShape, Plot, PlotPoints, Points};

use crate::app::AppState;
use crate::app::Forms;
use crate::app::command::{Command, ViewCommand};
use crate::app::session::{Fit, LoadedSession};
use crate::app::widgets::{AFTER, BAD, BEFORE, MUTED, WARN, command_button};
use crate::engine::base::geometry::roll_pitch_yaw_deg;
use crate::engine::base::session::Observation;
use crate::engine::calibrate::stripe::StripeResult;

/// Points on the drawn circle.
const CIRCLE_SEGMENTS: usize = 256;

/// Stripes listed by name at most, in the row of flagged stripes.
const FLAGGED_SHOWN: usize = 8;

/// The stripes with warnings or failures, each a button that shows it:
/// "Check the stripes" (step 3) opens this view, which showed the first
/// measurement whatever it was, so a warned stripe could go unseen.
fn flagged_ui(
    ui: &mut egui::Ui,
    loaded: &LoadedSession,
    shown: usize,
    commands: &mut Vec<Command>,
) {
    let flagged: Vec<(usize, String)> = (0..loaded.session.measurements.len())
        .filter_map(|k| loaded.fit(k).problem().map(|why| (k, why)))
        .collect();
    if flagged.is_empty() {
        return;
    }
    ui.horizontal_wrapped(|ui| {
        let text = format!("{} with warnings or failures:", flagged.len());
        ui.label(RichText::new(text).color(WARN));
        for (k, why) in flagged.iter().take(FLAGGED_SHOWN) {
            let id = &loaded.session.measurements[*k].id;
            if ui
                .selectable_label(*k == shown, id)
                .on_hover_text(why)
                .clicked()
            {
                commands.push(Command::View(ViewCommand::Select(*k)));
            }
        }
        if flagged.len() > FLAGGED_SHOWN {
            let more = flagged.len() - FLAGGED_SHOWN;
            let text = format!("and {more} more (Session: only warnings and failures)");
            ui.label(RichText::new(text).small());
        }
    });
}

/// The Stripe view.
pub fn stripe_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    let Some(loaded) = &state.loaded else {
        crate::app::widgets::no_session_ui(ui, state);
        return;
    };
    let rows = state.visible_rows(forms);
    let Some(i) = state
        .selected
        .filter(|&i| i < loaded.session.measurements.len())
    else {
        ui.label("Select a measurement in the Session view.");
        return;
    };
    let m = &loaded.session.measurements[i];
    ui.horizontal(|ui| {
        let pos = rows.iter().position(|&r| r == i);
        let step = |delta| Command::View(ViewCommand::Step(delta));
        let (first, last) = (
            pos.is_none_or(|p| p == 0),
            pos.is_none_or(|p| p + 1 == rows.len()),
        );
        let hover = "the previous row in the Session table's order";
        command_button(ui, !first, "◀ Previous", hover, step(-1), commands);
        // The same search as the Session table's: narrows the picker and
        // Previous/Next (a session has a hundred measurements and more).
        let find = ui.label("Find");
        ui.add(
            egui::TextEdit::singleline(&mut forms.search)
                .hint_text("id or station")
                .desired_width(90.0),
        )
        .labelled_by(find.id)
        .on_hover_text("list only measurements whose id or station contains this text");
        egui::ComboBox::from_id_salt("stripe_measurement")
            .selected_text(RichText::new(&m.id).strong())
            .height(400.0)
            .show_ui(ui, |ui| {
                for &r in &rows {
                    let other = &loaded.session.measurements[r];
                    if ui
                        .selectable_label(
                            r == i,
                            format!("{} ({}, {})", other.id, other.station, other.usage.as_str()),
                        )
                        .clicked()
                    {
                        commands.push(Command::View(ViewCommand::Select(r)));
                    }
                }
            })
            .response
            .on_hover_text("measurement");
        let hover = "the next row in the Session table's order";
        command_button(ui, !last, "Next ▶", hover, step(1), commands);
        let used = !state.excluded.contains(&m.id);
        let mut v = used;
        if ui.checkbox(&mut v, "use in solver").changed() {
            commands.push(Command::View(ViewCommand::SetIncluded {
                id: m.id.clone(),
                included: v,
            }));
        }
        ui.label(RichText::new("arrow keys: previous / next").small().weak());
    });
    flagged_ui(ui, loaded, i, commands);
    let pose = match &m.flange {
        Some(f) => {
            let t = f.translation.vector;
            let [roll, pitch, yaw] = roll_pitch_yaw_deg(&f.rotation);
            format!(
                "flange at ({:.2}, {:.2}, {:.2}) mm, roll/pitch/yaw ({roll:.3}, {pitch:.3}, {yaw:.3})°",
                t.x, t.y, t.z
            )
        }
        None => format!(
            "joints [{}] deg",
            m.joints
                .iter()
                .map(|q| format!("{q:.2}"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    ui.label(format!(
        "station {}, use {}, side {:+}, {pose}",
        m.station,
        m.usage.as_str(),
        m.side,
    ));
    match (loaded.fit(i), &m.observation) {
        (Fit::GivenCentre, Observation::Centre(c)) => {
            ui.add_space(10.0);
            ui.label(format!(
                "This measurement gives its sphere centre directly: ({:.3}, {:.3}, {:.3}) mm in the sensor frame. There is no stripe to show.",
                c.x, c.y, c.z
            ));
        }
        (Fit::Failed(e), Observation::Stripe(points)) => {
            ui.label(RichText::new(format!("The circle fit failed: {e}")).color(BAD));
            plots_ui(ui, points, None);
        }
        (Fit::Stripe(s), Observation::Stripe(points)) => {
            facts_ui(ui, s, loaded.session.sphere_radius());
            plots_ui(ui, points, Some(s));
        }
        _ => {}
    }
}

fn facts_ui(ui: &mut egui::Ui, s: &StripeResult, sphere_radius: f64) {
    let f = &s.fit;
    let c = &s.sphere.centre_in_sensor;
    let off_arc = s
        .segment
        .as_ref()
        .map_or(0, |seg| seg.on_arc.iter().filter(|k| !**k).count());
    ui.horizontal_wrapped(|ui| {
        ui.label(format!(
            "points {} used, {} rejected{} · circle centre ({:.3}, {:.3}) mm · r = {:.3} ± {:.3} mm (R = {:.3} mm, r/R = {:.3}) · RMS {:.4} mm · arc {:.0}° · cut angle {:+.1}°",
            f.used(),
            f.rejected() - off_arc,
            if off_arc > 0 {
                format!(", {off_arc} off the sphere's arc")
            } else {
                String::new()
            },
            f.centre[0],
            f.centre[1],
            f.radius,
            f.radius_std(),
            sphere_radius,
            s.sphere.r_over_r,
            f.rms,
            f.arc_span_deg,
            s.sphere.cut_angle_deg
        ));
    });
    ui.label(format!(
        "sphere centre in the sensor frame: ({:.3}, {:.3}, {:.3}) mm{}",
        c.x,
        c.y,
        c.z,
        if s.sphere.on_plane {
            " (taken on the laser plane)"
        } else {
            ""
        }
    ));
    for w in &s.warnings {
        ui.label(RichText::new(format!("warning: {w}")).color(WARN));
    }
}

/// The residual plot's scale above the used points, as a fraction.
const RESIDUAL_MARGIN: f64 = 1.15;

/// How far the residual plot reaches (µm, each side of 0): the largest
/// used residual or twice the RMS, with a margin; never the rejected
/// points'.
#[must_use]
pub fn residual_limit(used: &[[f64; 2]], rms_um: f64) -> f64 {
    let largest = used.iter().fold(0.0_f64, |m, p| m.max(p[1].abs()));
    (largest.max(2.0 * rms_um) * RESIDUAL_MARGIN).max(1e-3)
}

/// Height of a plot's title and key lines above it, points.
const KEY_HEIGHT: f32 = 44.0;

/// How the fit took a stripe point.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Taken {
    /// Used by the fit.
    Kept,
    /// Rejected by the fit as an outlier.
    Rejected,
    /// Left out by a raw profile's arc search (background, the stand).
    OffArc,
}

/// The stripe plot beside the residual plot, the points sorted into
/// kept, rejected by the fit and off the arc.
fn plots_ui(ui: &mut egui::Ui, points: &[[f64; 2]], fit: Option<&StripeResult>) {
    let flag = |flags: Option<&Vec<bool>>, k: usize| flags.is_none_or(|f| f.get(k) != Some(&false));
    let taken: Vec<Taken> = (0..points.len())
        .map(|k| {
            if flag(fit.map(|s| &s.fit.inlier), k) {
                Taken::Kept
            } else if flag(fit.and_then(|s| s.segment.as_ref()).map(|s| &s.on_arc), k) {
                Taken::Rejected
            } else {
                Taken::OffArc
            }
        })
        .collect();
    let height = ui.available_height().max(200.0);
    let width = ui.available_width();
    ui.horizontal(|ui| {
        ui.vertical(|ui| {
            ui.set_width(width * 0.58);
            stripe_plot_ui(ui, height, fit, points, &taken);
        });
        ui.vertical(|ui| {
            let Some(s) = fit else {
                ui.label(RichText::new("Residuals |p − c| − r").strong());
                ui.label(RichText::new("no fit").color(MUTED));
                return;
            };
            residual_plot_ui(ui, height, s, &taken);
        });
    });
}

/// The points (or, by `value`, another of their figures) taken as `how`,
/// `[index or y, value]`.
fn of(taken: &[Taken], how: Taken, value: impl Fn(usize) -> [f64; 2]) -> Vec<[f64; 2]> {
    (0..taken.len())
        .filter(|&k| taken[k] == how)
        .map(value)
        .collect()
}

/// The stripe in the laser plane with its key: the points kept by the
/// fit, the fitted circle and its centre, the points the fit rejected
/// and those off the arc (`[y, z]` mm).
fn stripe_plot_ui(
    ui: &mut egui::Ui,
    height: f32,
    fit: Option<&StripeResult>,
    points: &[[f64; 2]],
    taken: &[Taken],
) {
    let [kept, rejected, dropped] =
        [Taken::Kept, Taken::Rejected, Taken::OffArc].map(|how| of(taken, how, |k| points[k]));
    ui.label(RichText::new("Stripe in the laser plane (sensor x = 0)").strong());
    // The key above the plot, off the data.
    let mut key = vec![("● stripe points", AFTER)];
    if fit.is_some() {
        key.push(("- - fitted circle", BEFORE));
        key.push(("+ circle centre", BEFORE));
    }
    if !rejected.is_empty() {
        key.push(("× rejected", BAD));
    }
    if !dropped.is_empty() {
        key.push(("• off the arc (dropped)", MUTED));
    }
    crate::app::widgets::plot_key(ui, &key);
    crate::app::widgets::plots::readable(Plot::new("stripe_plot"), false)
        .data_aspect(1.0)
        .height(height - KEY_HEIGHT)
        .x_axis_label("y (mm)")
        .y_axis_label("z (mm)")
        .show(ui, |p| {
            if let Some(s) = fit {
                let [yc, zc] = s.fit.centre;
                let r = s.fit.radius;
                let circle: Vec<[f64; 2]> = (0..=CIRCLE_SEGMENTS)
                    .map(|k| {
                        let a = TAU * k as f64 / CIRCLE_SEGMENTS as f64;
                        [yc + r * a.cos(), zc + r * a.sin()]
                    })
                    .collect();
                p.line(
                    Line::new("fitted circle", PlotPoints::from(circle))
                        .color(BEFORE)
                        .style(LineStyle::dashed_loose())
                        .width(1.5),
                );
                p.points(
                    Points::new("circle centre", PlotPoints::from(vec![[yc, zc]]))
                        .shape(MarkerShape::Plus)
                        .radius(6.0)
                        .color(BEFORE),
                );
            }
            if !dropped.is_empty() {
                p.points(
                    Points::new("off the arc (dropped)", PlotPoints::from(dropped))
                        .color(MUTED)
                        .radius(1.5),
                );
            }
            p.points(
                Points::new("stripe points", PlotPoints::from(kept))
                    .color(AFTER)
                    .radius(2.5),
            );
            if !rejected.is_empty() {
                p.points(
                    Points::new("rejected", PlotPoints::from(rejected))
                        .shape(MarkerShape::Cross)
                        .color(BAD)
                        .radius(6.0),
                );
            }
        });
}

/// The fit's residuals of each point (µm) with ± RMS and its key; the
/// scale is the used points' and the rejected beyond it are drawn at its
/// edge (points off the arc are not drawn).
fn residual_plot_ui(ui: &mut egui::Ui, height: f32, s: &StripeResult, taken: &[Taken]) {
    ui.label(RichText::new("Residuals |p − c| − r").strong());
    let um = |k: usize| {
        [
            k as f64,
            s.fit.residuals.get(k).copied().unwrap_or(0.0) * 1000.0,
        ]
    };
    let used = of(taken, Taken::Kept, um);
    let rms = s.fit.rms * 1000.0;
    // The scale is the used points' (and ±RMS): a rejected point
    // of 783 µm must not flatten residuals of ±10 µm. Rejected
    // points beyond it are drawn at its edge.
    let limit = residual_limit(&used, rms);
    // Points off the arc are far from the circle: not plotted here.
    let rejected_um = of(taken, Taken::Rejected, um);
    let beyond = rejected_um.iter().filter(|p| p[1].abs() > limit).count();
    let largest = rejected_um.iter().fold(0.0_f64, |m, p| m.max(p[1].abs()));
    let out: Vec<[f64; 2]> = rejected_um
        .iter()
        .map(|p| [p[0], p[1].clamp(-limit, limit)])
        .collect();
    let rms_key = format!("- - ± RMS ({rms:.1} µm)");
    let rejected_key = if beyond > 0 {
        format!(
            "× rejected ({beyond} beyond ±{limit:.0} µm drawn at the edge; largest {largest:.0} µm)"
        )
    } else {
        "× rejected".to_string()
    };
    let mut key = vec![("● used", AFTER), (rms_key.as_str(), MUTED)];
    if !out.is_empty() {
        key.push((rejected_key.as_str(), BAD));
    }
    crate::app::widgets::plot_key(ui, &key);
    crate::app::widgets::plots::readable(Plot::new("residual_plot"), true)
        .height(height - KEY_HEIGHT)
        .x_axis_label("point")
        .y_axis_label("residual (µm)")
        .include_y(-limit)
        .include_y(limit)
        .show(ui, |p| {
            p.points(
                Points::new("used", PlotPoints::from(used))
                    .color(AFTER)
                    .radius(2.5)
                    .stems(0.0),
            );
            if !out.is_empty() {
                p.points(
                    Points::new("rejected", PlotPoints::from(out))
                        .shape(MarkerShape::Cross)
                        .color(BAD)
                        .radius(5.0)
                        .stems(0.0),
                );
            }
            for y in [rms, -rms] {
                let line = HLine::new("± RMS", y).color(MUTED);
                p.hline(line.style(LineStyle::dashed_dense()));
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The issue: one rejected point of 783 µm set the residual scale and
    /// flattened residuals of ±10 µm. The scale is the used points'.
    #[test]
    fn the_residual_scale_is_the_used_points() {
        let used = [[0.0, 9.0], [1.0, -10.0], [2.0, 4.0]];
        let limit = residual_limit(&used, 3.0);
        assert!((limit - 10.0 * RESIDUAL_MARGIN).abs() < 1e-9, "{limit}");
        // At least twice the RMS when the points are all small.
        assert!((residual_limit(&[[0.0, 1.0]], 6.0) - 12.0 * RESIDUAL_MARGIN).abs() < 1e-9);
    }
}
