//! The Centres view: sphere centres in the base frame by station, before
//! and after calibration, in the 3-D scene ([`scene`]) and in the three
//! plane projections. Clicking a centre selects its measurement; hovering
//! one names it.
//!
//! Readable from one station to 3,000 and more: up to [`KEY_FULL_MAX`]
//! stations each is named in the key above the plots; beyond, the key
//! collapses to one line (the names are on hover, and in a scrolled list
//! when opened), the projections' deviations switch from µm to mm when they
//! exceed a millimetre, and the view scrolls when the window is short.
//! Markers are drawn as one series per station style (80 styles), not
//! per station, so 20,000 centres draw in a frame.

pub mod scene;

use egui::{RichText, Vec2};
use egui_plot::{MarkerShape, Plot, PlotPoints, Points};

use crate::app::AppState;
use crate::app::command::{Command, ViewCommand};
use crate::app::ledger::Artefact;
use crate::app::results::CentreSet;
use crate::app::scene::ui::scene_ui_within;
use crate::app::widgets::plots::readable;
use crate::app::widgets::station_style;
use crate::app::{Forms, results::CentresForm};
use crate::engine::base::session::Mount;
pub use scene::{ORBIT_LABEL, orbit_positions};

/// A click selects the nearest centre within this many points of the pointer.
const PICK_RADIUS: f32 = 10.0;

/// The key of the before markers (hollow, in the station's colour).
pub const BEFORE_KEY: &str = "○ before (nominal): hollow";
/// The key of the after markers (filled, in the station's colour).
pub const AFTER_KEY: &str = "● after (calibrated): filled";

/// Stations named one by one in the key; beyond, it collapses to a line
/// (40 keys fill about two lines at 1366 px).
pub const KEY_FULL_MAX: usize = 40;

/// Distinct station markers: ten colours, four shapes, two shades
/// ([`station_style`] repeats after this many).
const STYLES: usize = 80;

/// Least height of each plane projection, points: the three fit under
/// the options and the key at 1366×768; a shorter window scrolls.
pub const PROJECTION_MIN_HEIGHT: f32 = 150.0;

/// Height of a projection's caption, points.
const CAPTION_HEIGHT: f32 = 22.0;

/// Room around the data of a projection, points: the selection ring
/// (radius 8) stays whole at the edge.
const RING_ROOM: f32 = 14.0;

/// Accessible names of the three projections, in order.
pub const PROJECTION_LABELS: [&str; 3] = ["top view: x–y", "side view: x–z", "front view: y–z"];

/// The key of station number `k` named `name`: its shape and name, e.g.
/// "◆ V5" (shown in its colour).
#[must_use]
pub fn station_key(k: usize, name: &str) -> String {
    // A no-break space: a wrapped row never parts a shape from its name.
    format!("{}\u{a0}{name}", station_style(k).glyph)
}

/// One drawn marker: where, which centre (index into the set's points)
/// and measurement, its station, before or after.
struct Marker {
    pos: [f64; 3],
    point: usize,
    index: Option<usize>,
    station: usize,
    after: bool,
}

/// The Centres view.
pub fn centres_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    let set = match (&state.result, &state.loaded) {
        (Some(r), _) => &r.centres,
        (None, Some(l)) => match &l.before {
            Ok(set) => set,
            Err(e) => {
                ui.label(RichText::new(format!("No centres: {e}")).color(crate::app::widgets::BAD));
                return;
            }
        },
        (None, None) => {
            crate::app::widgets::no_session_ui(ui, state);
            return;
        }
    };
    // The height the plots may fill without scrolling.
    let view_height = ui.available_height();
    egui::ScrollArea::vertical()
        .id_salt("centres_scroll")
        .auto_shrink([false, false])
        .show(ui, |ui| {
            let top = ui.cursor().min.y;
            if state.result.is_some()
                && let Some(s) = state.ledger.stale(Artefact::Result)
            {
                crate::app::widgets::stale_banner_ui(
                    ui,
                    &s,
                    "The centres after calibration are of the stale result: run again.",
                );
            }
            let has_after = set.points.iter().any(|p| p.after.is_some());
            options_ui(ui, &mut forms.centres, has_after);
            key_ui(ui, set);
            let used = ui.cursor().min.y - top;
            let plots =
                (view_height - used - 8.0).max(3.0 * (PROJECTION_MIN_HEIGHT + CAPTION_HEIGHT));
            plots_ui(ui, state, forms, set, plots, commands);
        });
}

/// The 3-D view beside the three projections, `height` points tall.
fn plots_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    set: &CentreSet,
    height: f32,
    commands: &mut Vec<Command>,
) {
    let markers = markers(set, &forms.centres);
    let unit = ProjectionUnit::of(set, &forms.centres);
    let flat = projection_markers(set, &forms.centres, unit);
    let magnify = forms
        .centres
        .relative
        .then_some(f64::from(forms.centres.magnify));
    let selected = state.selected;
    let width = ui.available_width();
    ui.horizontal_top(|ui| {
        let w3d = (width * 0.55).max(200.0);
        ui.vertical(|ui| {
            ui.set_width(w3d);
            let frame = centres_frame(state);
            let scene = scene::centres_scene(set, &markers, selected);
            let caption = match magnify {
                Some(k) => format!(
                    "3D, {frame}: deviations ×{k:.0} about each station's mean; before faint, after solid"
                ),
                None => format!("3D, {frame}: before faint, after solid"),
            };
            let camera = &mut forms.centres.camera;
            if let Some(i) = scene_ui_within(ui, scene::ORBIT_ID, camera, &scene, &caption, height)
                .and_then(|k| set.points.get(k)?.index)
            {
                commands.push(Command::View(ViewCommand::Select(i)));
            }
        });
        ui.vertical(|ui| {
            let h = (height / 3.0 - CAPTION_HEIGHT).max(PROJECTION_MIN_HEIGHT);
            for (k, (a, b)) in [(0, 1), (0, 2), (1, 2)].into_iter().enumerate() {
                let name = PROJECTION_LABELS[k];
                let caption = match unit {
                    ProjectionUnit::Position => name.to_string(),
                    _ => format!("{name}, deviations from each station's mean"),
                };
                ui.label(RichText::new(caption).small().weak());
                if let Some(i) = projection_ui(ui, k, (a, b), h, unit, &flat, set, selected) {
                    commands.push(Command::View(ViewCommand::Select(i)));
                }
            }
        });
    });
}

/// What the centres are and their frame, by the mount of the result on
/// show (else the open session's): sphere centres in the base frame, or a
/// fixed sensor's targets in the flange frame.
#[must_use]
pub fn centres_frame(state: &AppState) -> &'static str {
    let mount = match (&state.result, &state.loaded) {
        (Some(r), _) => r.file.mount(),
        (None, Some(l)) => l.session.mount,
        (None, None) => Mount::default(),
    };
    match mount {
        Mount::Flange => "sphere centres in the robot base frame",
        Mount::Fixed => "targets in the flange frame (a fixed sensor)",
    }
}

fn options_ui(ui: &mut egui::Ui, f: &mut CentresForm, has_after: bool) {
    ui.horizontal_wrapped(|ui| {
        // Both are drawn in their station's colour: the cue is the fill.
        ui.checkbox(&mut f.show_before, BEFORE_KEY)
            .on_hover_text("nominal model, initial hand-eye: hollow markers");
        ui.add_enabled_ui(has_after, |ui| {
            ui.checkbox(&mut f.show_after, AFTER_KEY)
                .on_hover_text("calibrated: filled markers")
                .on_disabled_hover_text("run the solver first");
        });
        ui.checkbox(
            &mut f.relative,
            "deviations from the station mean, magnified",
        )
        .on_hover_text(
            "each centre is drawn at its station's mean plus its deviation times the factor",
        );
        ui.add_enabled_ui(f.relative, |ui| {
            let l = ui.label("×");
            ui.add(
                egui::DragValue::new(&mut f.magnify)
                    .range(1.0..=2000.0)
                    .speed(1.0),
            )
            .labelled_by(l.id);
        });
    });
}

/// The line saying how stations are marked when there are too many to
/// name one by one.
#[must_use]
pub fn collapsed_key_text(stations: usize) -> String {
    format!(
        "{stations} stations: 10 colours × 4 shapes, lighter from the 41st, repeating every 80; hover a centre for its name"
    )
}

/// The station key: each station's marker and name up to
/// [`KEY_FULL_MAX`] stations; beyond, one line and the names in a
/// closed, scrolled list.
fn key_ui(ui: &mut egui::Ui, set: &CentreSet) {
    let entries = |ui: &mut egui::Ui| {
        ui.horizontal_wrapped(|ui| {
            for (k, s) in set.stations.iter().enumerate() {
                let style = station_style(k);
                ui.label(RichText::new(station_key(k, s)).color(style.colour).small());
            }
        });
    };
    if set.stations.len() <= KEY_FULL_MAX {
        entries(ui);
        return;
    }
    ui.label(RichText::new(collapsed_key_text(set.stations.len())).small());
    egui::CollapsingHeader::new(format!("station key ({})", set.stations.len()))
        .id_salt("centres_station_key")
        .default_open(false)
        .show(ui, |ui| {
            egui::ScrollArea::vertical()
                .id_salt("centres_key_scroll")
                .max_height(120.0)
                .show(ui, entries);
        });
}

/// Every marker to draw, before and after as the form shows them, each
/// placed by `place(centre, its station's mean, the station's mean
/// before)`.
fn placed_markers(
    set: &CentreSet,
    f: &CentresForm,
    place: impl Fn([f64; 3], [f64; 3], [f64; 3]) -> [f64; 3],
) -> Vec<Marker> {
    let mut out = Vec::new();
    for (i, p) in set.points.iter().enumerate() {
        let s = set.station_of.get(i).copied().unwrap_or(0);
        let (mean_before, mean_after) = set.means.get(s).copied().unwrap_or(([0.0; 3], [0.0; 3]));
        if f.show_before {
            out.push(Marker {
                pos: place(p.before, mean_before, mean_before),
                point: i,
                index: p.index,
                station: s,
                after: false,
            });
        }
        if f.show_after
            && let Some(a) = p.after
        {
            out.push(Marker {
                pos: place(a, mean_after, mean_before),
                point: i,
                index: p.index,
                station: s,
                after: true,
            });
        }
    }
    out
}

/// The markers of the 3-D view: the centres, or in relative mode each
/// centre's deviation from its station's mean magnified about the
/// station's mean before.
fn markers(set: &CentreSet, f: &CentresForm) -> Vec<Marker> {
    let k = f64::from(f.magnify);
    placed_markers(set, f, |p, own_mean, anchor| {
        if f.relative {
            std::array::from_fn(|c| anchor[c] + k * (p[c] - own_mean[c]))
        } else {
            p
        }
    })
}

/// Micrometres in a millimetre.
const UM_PER_MM: f64 = 1000.0;

/// What the plane projections' axes carry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProjectionUnit {
    /// Positions in the base frame, mm.
    Position,
    /// Deviations from each station's mean, µm (all up to a millimetre).
    DeviationUm,
    /// Deviations from each station's mean, mm (some beyond a
    /// millimetre: ±60,000 µm reads worse than ±60 mm).
    DeviationMm,
}

impl ProjectionUnit {
    /// The unit for `set` drawn with `form`.
    #[must_use]
    pub fn of(set: &CentreSet, form: &CentresForm) -> Self {
        if !form.relative {
            Self::Position
        } else if set.largest_deviation > 1.0 {
            Self::DeviationMm
        } else {
            Self::DeviationUm
        }
    }

    /// Units drawn per mm.
    fn per_mm(self) -> f64 {
        match self {
            Self::DeviationUm => UM_PER_MM,
            Self::Position | Self::DeviationMm => 1.0,
        }
    }
}

/// What the plane projections draw: in relative mode each centre's
/// deviation from its station's mean (before from the mean before, after
/// from the mean after; every station about one origin, so the axes
/// carry true deviations, not magnified millimetres) in µm or mm, else
/// the centres in mm.
fn projection_markers(set: &CentreSet, f: &CentresForm, unit: ProjectionUnit) -> Vec<Marker> {
    if unit == ProjectionUnit::Position {
        return markers(set, f);
    }
    let scale = unit.per_mm();
    placed_markers(set, f, |p, own_mean, _| {
        std::array::from_fn(|c| (p[c] - own_mean[c]) * scale)
    })
}

/// The label of projection axis `k` (0 x, 1 y, 2 z) in `unit`: position
/// in mm, or the deviation from the station mean in µm or mm (the
/// caption above each projection says of what; the label must fit the
/// plot's height).
#[must_use]
pub fn projection_axis_label(k: usize, unit: ProjectionUnit) -> String {
    let name = ["x", "y", "z"].get(k).copied().unwrap_or("?");
    match unit {
        ProjectionUnit::Position => format!("{name} (mm)"),
        ProjectionUnit::DeviationUm => format!("Δ{name} (µm)"),
        ProjectionUnit::DeviationMm => format!("Δ{name} (mm)"),
    }
}

/// Where the plane projections draw each centre (x, y, z in the units of
/// [`projection_axis_label`] for [`ProjectionUnit::of`]) and its
/// measurement index.
#[must_use]
pub fn projection_points(set: &CentreSet, form: &CentresForm) -> Vec<([f64; 3], Option<usize>)> {
    projection_markers(set, form, ProjectionUnit::of(set, form))
        .into_iter()
        .map(|m| (m.pos, m.index))
        .collect()
}

/// What hovering a centre says: its measurement, station, before or
/// after.
fn tooltip(set: &CentreSet, m: &Marker) -> String {
    let id = set.points.get(m.point).map_or("?", |p| p.id.as_str());
    let station = set.stations.get(m.station).map_or("?", String::as_str);
    format!(
        "{id} ({station}, {})",
        if m.after { "after" } else { "before" }
    )
}

/// One plane projection, its markers as one series per station style
/// and fill. Returns the measurement clicked.
#[allow(clippy::too_many_arguments)]
fn projection_ui(
    ui: &mut egui::Ui,
    k: usize,
    (a, b): (usize, usize),
    height: f32,
    unit: ProjectionUnit,
    markers: &[Marker],
    set: &CentreSet,
    selected: Option<usize>,
) -> Option<usize> {
    // Series `style * 2 + after`, each with its markers (for hover names).
    let mut series: Vec<Vec<&Marker>> = vec![Vec::new(); 2 * STYLES];
    for m in markers {
        series[(m.station % STYLES) * 2 + usize::from(m.after)].push(m);
    }
    let names: Vec<String> = (0..2 * STYLES).map(|s| format!("series {s}")).collect();
    let width = ui.available_width();
    let lookup = &series;
    let response = readable(Plot::new(("projection", k)), false)
        .data_aspect(1.0)
        .height(height)
        .set_margin_fraction(Vec2::new(
            RING_ROOM / width.max(1.0),
            RING_ROOM / height.max(1.0),
        ))
        // The wheel scrolls the view (drag pans, ctrl+wheel zooms).
        .allow_scroll(false)
        .x_axis_label(projection_axis_label(a, unit))
        .y_axis_label(projection_axis_label(b, unit))
        .label_formatter(move |pos| match pos {
            egui_plot::HoverPosition::NearDataPoint {
                plot_name, index, ..
            } => plot_name
                .strip_prefix("series ")
                .and_then(|s| s.parse::<usize>().ok())
                .and_then(|s| lookup.get(s))
                .and_then(|ms| ms.get(*index))
                .map(|m| tooltip(set, m)),
            egui_plot::HoverPosition::Elsewhere { .. } => None,
        })
        .show(ui, |p| {
            for (s, ms) in series.iter().enumerate() {
                if ms.is_empty() {
                    continue;
                }
                let style = station_style(s / 2);
                let after = s % 2 == 1;
                let pts: Vec<[f64; 2]> = ms.iter().map(|m| [m.pos[a], m.pos[b]]).collect();
                p.points(
                    Points::new(names[s].clone(), PlotPoints::from(pts))
                        .color(style.colour)
                        .filled(after)
                        .shape(style.shape)
                        .radius(if after { 3.5 } else { 4.0 }),
                );
            }
            if let Some(sel) = selected {
                let pts: Vec<[f64; 2]> = markers
                    .iter()
                    .filter(|m| m.index == Some(sel))
                    .map(|m| [m.pos[a], m.pos[b]])
                    .collect();
                p.points(
                    Points::new("", PlotPoints::from(pts))
                        .shape(MarkerShape::Circle)
                        .filled(false)
                        .radius(8.0)
                        .allow_hover(false)
                        .color(p.ctx().global_style().visuals.strong_text_color()),
                );
            }
            let clicked = p.response().clicked();
            let pointer = p.response().interact_pointer_pos();
            match (clicked, pointer) {
                (true, Some(pointer)) => markers
                    .iter()
                    .map(|m| {
                        let s = p.screen_from_plot(egui_plot::PlotPoint::new(m.pos[a], m.pos[b]));
                        (s.distance(pointer), m.index)
                    })
                    .filter(|(d, _)| *d <= PICK_RADIUS)
                    .min_by(|x, y| x.0.total_cmp(&y.0))
                    .and_then(|(_, i)| i),
                _ => None,
            }
        });
    let label = PROJECTION_LABELS[k];
    response
        .response
        .widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, label));
    response.inner
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::results::CentrePoint;

    fn point(id: &str, station: &str, before: [f64; 3], after: [f64; 3]) -> CentrePoint {
        CentrePoint {
            id: id.into(),
            station: station.into(),
            usage: "identify".into(),
            index: None,
            before,
            after: Some(after),
        }
    }

    /// The issue: at ×250 the magnified projections showed ±2000 "mm".
    /// Now they show each centre's true deviation in µm.
    #[test]
    fn magnified_projections_are_in_micrometres() {
        let set = CentreSet::new(vec![
            point("a", "P0", [1000.0, 0.0, 500.0], [1000.0, 0.0, 500.0]),
            point("b", "P0", [1000.02, 0.0, 500.0], [1000.002, 0.0, 500.0]),
            point("c", "P1", [0.0, 800.0, 300.0], [0.0, 800.0, 300.0]),
            point("d", "P1", [0.0, 800.0, 300.04], [0.0, 800.0, 300.0]),
        ]);
        let form = CentresForm {
            magnify: 250.0,
            ..CentresForm::default()
        };
        assert!(form.relative);
        assert_eq!(ProjectionUnit::of(&set, &form), ProjectionUnit::DeviationUm);
        let pts = projection_points(&set, &form);
        let largest = pts
            .iter()
            .flat_map(|(p, _)| p.iter())
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        // b's deviation before: 0.01 mm from P0's mean = 10 µm; d's 20 µm.
        assert!((largest - 20.0).abs() < 1e-6, "{largest}");
        assert!((pts[2].0[0] - 10.0).abs() < 1e-6, "{:?}", pts[2]);
        assert!((pts[3].0[0] - 1.0).abs() < 1e-6, "after: {:?}", pts[3]);
        assert_eq!(
            projection_axis_label(0, ProjectionUnit::DeviationUm),
            "Δx (µm)"
        );
        assert_eq!(projection_axis_label(2, ProjectionUnit::Position), "z (mm)");
        // Not magnified: positions in mm.
        let plain = CentresForm {
            relative: false,
            ..form
        };
        assert_eq!(projection_points(&set, &plain)[0].0, [1000.0, 0.0, 500.0]);
    }

    /// The issue: deviations of tens of millimetres read ±60,000 µm. Past
    /// a millimetre the projections switch to mm.
    #[test]
    fn large_deviations_are_in_millimetres() {
        let set = CentreSet::new(vec![
            point("a", "P0", [1000.0, 0.0, 500.0], [1000.0, 0.0, 500.0]),
            point("b", "P0", [1120.0, 0.0, 500.0], [1000.002, 0.0, 500.0]),
        ]);
        let form = CentresForm::default();
        assert_eq!(ProjectionUnit::of(&set, &form), ProjectionUnit::DeviationMm);
        let pts = projection_points(&set, &form);
        assert!((pts[0].0[0] + 60.0).abs() < 1e-9, "{:?}", pts[0]);
        assert_eq!(
            projection_axis_label(1, ProjectionUnit::DeviationMm),
            "Δy (mm)"
        );
    }

    #[test]
    fn a_station_key_is_its_shape_and_name() {
        assert_eq!(station_key(12, "V3"), "■\u{a0}V3");
    }
}
