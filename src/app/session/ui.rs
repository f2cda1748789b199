//! The Session view: the table of measurements (id, station, use, side,
//! points, fit RMS, cut angle, warnings), filters and grouping, include or
//! leave out, and "Save as" of the session without the left-out ones; and
//! the left panel's loading part (the session open, the path field, the
//! demo, recent files, the error notice).

use egui::{Color32, RichText};
use egui_extras::{Column, TableBuilder};

use super::{Fit, Grouping, LoadedSession};
use crate::app::command::{Command, FilesCommand, ViewCommand};
use crate::app::dialog::{NO_DIALOG, Purpose};
use crate::app::job::Slot;
use crate::app::widgets::{
    BAD, DEFAULT_RANGE, MUTED, WARN, boxed, choice, coloured, command_button, labelled_field,
    range_fields, range_of, range_values, scrolled_text, weak,
};
use crate::app::{AppState, Forms};
use crate::engine::base::numeric::plural;
use crate::engine::base::session::{Measurement, Use};

/// A row of the table: a group header or a measurement.
enum Row {
    /// Group title; `Some(station)` for a station group (with a checkbox).
    Header(String, Option<String>),
    /// Index into the session's measurements.
    Item(usize),
}

/// The Session view.
pub fn session_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    let Some(loaded) = &state.loaded else {
        crate::app::widgets::no_session_ui(ui, state);
        return;
    };
    scene_panel_ui(ui, state, loaded, forms, commands);
    filters_ui(ui, loaded, forms, commands);
    let n = loaded.session.measurements.len();
    let excluded = state.excluded_count();
    ui.horizontal_wrapped(|ui| {
        let stations = plural(loaded.station_ids().len(), "station", "stations");
        ui.label(format!("{n} measurements in {stations}."));
        if excluded > 0 {
            coloured(ui, WARN, format!("{excluded} left out: the solver skips them; the opened file is unchanged until you save a copy."));
        } else {
            weak(ui, "Untick a measurement to leave it out of the solver.");
        }
    });
    range_ui(ui, loaded, forms, commands);
    save_ui(ui, state, forms, commands);
    crate::app::widgets::dialog_note_ui(ui, state, &[Purpose::SaveSession]);
    ui.separator();
    table_ui(ui, state, loaded, forms, commands);
}

/// Width the 3-D scene starts at beside the table, points.
const SCENE_WIDTH: f32 = 380.0;

/// The 3-D scene beside the table: every pose, and the robot, frames,
/// laser fan and stripe of the selected one; a pose picked there is
/// selected in the table.
fn scene_panel_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    loaded: &LoadedSession,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    egui::Panel::right("session_scene")
        .resizable(true)
        .default_size(SCENE_WIDTH)
        .size_range(260.0..=900.0)
        .show(ui, |ui| {
            let scene = super::scene::session_scene(loaded, state.selected, &state.excluded);
            let caption =
                super::scene::session_caption(loaded, state.selected.unwrap_or(0), &state.excluded);
            if let Some(i) = crate::app::scene::ui::scene_ui(
                ui,
                "session",
                &mut forms.scene.session,
                &scene,
                &caption,
                0.0,
            ) {
                commands.push(Command::View(ViewCommand::Select(i)));
            }
        });
}

/// The measuring range (`sensor.range`): where the calibrated sensor will
/// be used, so that `ml` predicts the error over it (Results) and the
/// planner spreads the sphere over it.
fn range_ui(
    ui: &mut egui::Ui,
    loaded: &LoadedSession,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    let current = loaded.session.sensor_range;
    ui.horizontal_wrapped(|ui| {
        ui.label(RichText::new("Measuring range").strong())
            .on_hover_text("sensor.range: the part of the laser plane the sensor measures in (sensor frame); the next run predicts the error over it");
        let mut edit = forms
            .range_edit
            .unwrap_or_else(|| current.as_ref().map_or(DEFAULT_RANGE, range_values));
        if range_fields(ui, "session_range", &mut edit, false) {
            forms.range_edit = Some(edit);
        }
        let parsed = range_of(&edit);
        let differs = parsed.ok() != current;
        let set = |r| Command::View(ViewCommand::SetSensorRange(r));
        let hover = "keep this range with the session (saved with it); run again to predict the error over it";
        let enabled = parsed.is_ok() && differs;
        command_button(ui, enabled, "Set range", hover, set(parsed.ok()), commands);
        if current.is_some() {
            let hover = "forget the range: the error is then predicted where the sphere was seen";
            command_button(ui, true, "Clear", hover, set(None), commands);
        }
        let (colour, text) = match (&parsed, current) {
            (Err(why), _) => (BAD, (*why).to_string()),
            (_, Some(r)) => {
                let [y0, y1, z0, z1] = range_values(&r);
                (MUTED, format!("set: y {y0:.0}…{y1:.0}, z {z0:.0}…{z1:.0} mm"))
            }
            (_, None) => (WARN, "not set: the error is predicted only where the sphere was seen".into()),
        };
        coloured(ui, colour, text);
    });
}

fn filters_ui(
    ui: &mut egui::Ui,
    loaded: &LoadedSession,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    ui.horizontal_wrapped(|ui| {
        // Each filter offers "all" first.
        let all = "all".to_string();
        let stations = loaded
            .station_ids()
            .into_iter()
            .map(|s| (Some(s.clone()), s));
        let options = std::iter::once((None, all.clone())).chain(stations);
        let (value, id) = (&mut forms.filter_station, "filter_station");
        choice(ui, "Station", id, value, options).on_hover_text("show one station only");
        let uses = Use::ALL.map(|u| (Some(u), u.as_str().to_string()));
        let options = std::iter::once((None, all)).chain(uses);
        choice(ui, "Use", "filter_use", &mut forms.filter_use, options)
            .on_hover_text("show one use only");
        let groupings = Grouping::ALL.map(|g| (g, g.label().to_string()));
        choice(ui, "Group by", "group", &mut forms.group, groupings)
            .on_hover_text("group the rows");
        let problems = loaded.analysis.failures().count() + loaded.analysis.warnings.len();
        ui.checkbox(
            &mut forms.filter_problems,
            format!("only warnings and failures ({problems})"),
        )
        .on_hover_text("show only the measurements whose stripe fit warned or failed");
        let search = ui.label("Find");
        ui.add(
            egui::TextEdit::singleline(&mut forms.search)
                .hint_text("id or station")
                .desired_width(110.0),
        )
        .labelled_by(search.id)
        .on_hover_text("show only measurements whose id or station contains this text");
        let all = Command::View(ViewCommand::IncludeAll);
        command_button(
            ui,
            true,
            "Use all",
            "include every measurement again",
            all,
            commands,
        );
    });
}

fn save_ui(ui: &mut egui::Ui, state: &AppState, forms: &mut Forms, commands: &mut Vec<Command>) {
    ui.horizontal(|ui| {
        let width = (ui.available_width() - 230.0).max(160.0);
        let field = labelled_field(
            ui,
            "Save as",
            &mut forms.save_path,
            "/path/to/edited-session.json",
            width,
        );
        let hover = "choose the file with the desktop's dialog";
        let browse = Command::Browse(Purpose::SaveSession);
        command_button(ui, true, "Browse…", hover, browse, commands);
        let save = ui
            .add_enabled(!state.jobs.writing(), egui::Button::new("Save"))
            .on_hover_text("write the session without the left-out measurements (atomic write)");
        let entered = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
        if save.clicked() || entered {
            commands.push(Command::Files(FilesCommand::SaveSession));
        }
    });
}

fn rows(state: &AppState, loaded: &LoadedSession, forms: &Forms) -> Vec<Row> {
    let ms = &loaded.session.measurements;
    // The group a measurement is in.
    fn of(group: Grouping, m: &Measurement) -> Option<&str> {
        match group {
            Grouping::None => None,
            Grouping::Station => Some(m.station.as_str()),
            Grouping::Use => Some(m.usage.as_str()),
        }
    }
    let key = |m| of(forms.group, m);
    let mut out = Vec::new();
    let mut current = None;
    for i in state.visible_rows(forms) {
        let k = key(&ms[i]);
        if let Some(k) = k.filter(|_| k != current) {
            let members: Vec<_> = ms.iter().filter(|m| key(m) == Some(k)).collect();
            let used = members.iter().filter(|m| !state.excluded.contains(&m.id));
            let (n, used) = (members.len(), used.count());
            // A station group has its checkbox.
            let station = (forms.group == Grouping::Station).then(|| k.to_string());
            let what = if station.is_some() { "station " } else { "" };
            let title = format!("{what}{k}: {n} measurements, {used} used");
            out.push(Row::Header(title, station));
        }
        current = k;
        out.push(Row::Item(i));
    }
    out
}

fn table_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    loaded: &LoadedSession,
    forms: &Forms,
    commands: &mut Vec<Command>,
) {
    let rows = rows(state, loaded, forms);
    let selected_row = state.selected.and_then(|s| {
        rows.iter()
            .position(|r| matches!(r, Row::Item(i) if *i == s))
    });
    let ms = &loaded.session.measurements;
    // Scroll to the selection once each time it changes (arrow keys).
    let moved_id = egui::Id::unique("session_table_scrolled_to");
    let last: Option<Option<usize>> = ui.data(|d| d.get_temp(moved_id));
    let scroll = selected_row.filter(|_| last != Some(state.selected));
    ui.data_mut(|d| d.insert_temp(moved_id, state.selected));
    let mut table = TableBuilder::new(ui)
        .striped(true)
        .sense(egui::Sense::click())
        .cell_layout(egui::Layout::left_to_right(egui::Align::Center))
        .column(Column::initial(90.0).at_least(70.0))
        .column(Column::initial(60.0))
        .column(Column::initial(80.0))
        .column(Column::initial(40.0))
        .column(Column::initial(55.0))
        .column(Column::initial(95.0))
        .column(Column::initial(95.0))
        .column(Column::remainder().at_least(60.0).clip(true))
        .min_scrolled_height(0.0);
    if let Some(row) = scroll {
        table = table.scroll_to_row(row, None);
    }
    table
        .header(22.0, |mut h| {
            for title in [
                "use · id",
                "station",
                "use",
                "side",
                "points",
                "fit RMS (mm)",
                "cut angle (°)",
                "warnings",
            ] {
                h.col(|ui| {
                    ui.strong(title);
                });
            }
        })
        .body(|body| {
            body.rows(22.0, rows.len(), |mut row| match &rows[row.index()] {
                Row::Header(title, station) => {
                    row.col(|ui| {
                        if let Some(s) = station {
                            let all = ms
                                .iter()
                                .filter(|m| m.station == *s)
                                .all(|m| !state.excluded.contains(&m.id));
                            let mut v = all;
                            if ui
                                .checkbox(&mut v, "all")
                                .on_hover_text(format!("use every measurement of station {s}"))
                                .changed()
                            {
                                commands.push(Command::View(ViewCommand::SetStationIncluded {
                                    station: s.clone(),
                                    included: v,
                                }));
                            }
                        }
                    });
                    row.col(|ui| {
                        ui.add(egui::Label::new(RichText::new(title).strong()).extend());
                    });
                    for _ in 0..6 {
                        row.col(|_| {});
                    }
                }
                Row::Item(i) => {
                    let i = *i;
                    row.set_selected(state.selected == Some(i));
                    item_row(&mut row, state, loaded, i, commands);
                    let r = row.response();
                    if r.double_clicked() {
                        commands.push(Command::View(ViewCommand::Inspect(i)));
                    } else if r.clicked() {
                        commands.push(Command::View(ViewCommand::Select(i)));
                    }
                }
            });
        });
}

fn item_row(
    row: &mut egui_extras::TableRow<'_, '_>,
    state: &AppState,
    loaded: &LoadedSession,
    i: usize,
    commands: &mut Vec<Command>,
) {
    let m = &loaded.session.measurements[i];
    let used = !state.excluded.contains(&m.id);
    let dim = |t: String| {
        if used {
            RichText::new(t)
        } else {
            RichText::new(t).color(MUTED).strikethrough()
        }
    };
    row.col(|ui| {
        let mut v = used;
        if ui
            .checkbox(&mut v, dim(m.id.clone()))
            .on_hover_text(format!("use measurement {} in the solver", m.id))
            .changed()
        {
            commands.push(Command::View(ViewCommand::SetIncluded {
                id: m.id.clone(),
                included: v,
            }));
        }
    });
    // A cell of text, and its hover.
    let mut cell = |text: RichText, hover: Option<String>| {
        row.col(|ui| {
            let r = ui.add(egui::Label::new(text).extend());
            if let Some(h) = hover {
                r.on_hover_text(h);
            }
        });
    };
    cell(dim(m.station.clone()), None);
    cell(dim(m.usage.as_str().to_string()), None);
    cell(dim(format!("{:+}", m.side)), None);
    let points = loaded.points(i);
    cell(
        dim(points.map_or_else(|| "—".into(), |n| n.to_string())),
        None,
    );
    match loaded.fit(i) {
        Fit::GivenCentre => {
            cell(dim("given centre".into()), None);
            cell(dim("—".into()), None);
            cell(RichText::new(""), None);
        }
        Fit::Failed(e) => {
            cell(RichText::new("fit failed").color(BAD), Some(e.to_string()));
            cell(RichText::new("—"), None);
            cell(RichText::new(e.to_string()).color(BAD), Some(e.to_string()));
        }
        Fit::Stripe(s) => {
            cell(dim(format!("{:.4}", s.fit.rms)), None);
            cell(dim(format!("{:+.1}", s.sphere.cut_angle_deg)), None);
            if s.warnings.is_empty() {
                cell(RichText::new("ok").color(OK_GREEN), None);
            } else {
                // Every warning named, in a few words each (the whole
                // text on hover and in the Stripe view).
                let text = RichText::new(warnings_cell(&s.warnings)).color(WARN);
                cell(text, Some(s.warnings.join("\n")));
            }
        }
    }
}

/// The colour of a stripe fit without warnings.
const OK_GREEN: Color32 = Color32::from_rgb(90, 170, 90);

/// Longest tag of a warning without a recognised opening, characters.
const TAG_CHARS: usize = 32;

/// A stripe warning in a few words, for the table: what it is about
/// ("raw profile", "3 points rejected", "short arc", "high fit RMS",
/// "centre on the laser plane", "cut angle 72.3° is above 60°").
#[must_use]
pub fn warning_tag(warning: &str) -> String {
    let before_colon = warning.split(':').next().unwrap_or(warning).trim();
    if warning.starts_with("raw profile") {
        "raw profile".to_string()
    } else if let Some(n) = warning
        .find(" stripe points rejected")
        .and_then(|at| warning[..at].split(" of ").next())
    {
        format!("{n} points rejected")
    } else if warning.starts_with("short arc") {
        "short arc".to_string()
    } else if warning.starts_with("high circle-fit RMS") {
        "high fit RMS".to_string()
    } else if warning.starts_with("stripe radius") {
        "centre on the laser plane".to_string()
    } else if warning.starts_with("cut angle") {
        before_colon.to_string()
    } else {
        let mut tag: String = before_colon.chars().take(TAG_CHARS).collect();
        if before_colon.chars().count() > TAG_CHARS {
            tag.push('…');
        }
        tag
    }
}

/// Every warning of a measurement, tagged, in one line.
#[must_use]
pub fn warnings_cell(warnings: &[String]) -> String {
    warnings
        .iter()
        .map(|w| warning_tag(w))
        .collect::<Vec<_>>()
        .join(" · ")
}

/// Loading: the current session (three lines whatever it is, so that
/// nothing below moves), the path field with Open… and the demo.
pub fn load_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    ui.heading("Session");
    let line = |ui: &mut egui::Ui, text: RichText| ui.add(egui::Label::new(text).truncate());
    // Each line in a fixed number of rows whatever its length (cut with
    // …, whole on hover), so that Run below never moves: it sat at 368,
    // 382 or 410 px as the name, source or counts wrapped.
    if let Some(l) = &state.loaded {
        name_ui(ui, &l.session.name);
        let weak = ui.visuals().weak_text_color();
        rows_ui(ui, &l.source.label(), egui::TextStyle::Small, weak, 2);
        let n = l.session.measurements.len();
        let stations = plural(l.station_ids().len(), "station", "stations");
        let pose_only = if l.session.pose_only() {
            " · pose-only (flange poses)"
        } else {
            ""
        };
        let d = l.session.sphere_diameter;
        let text = format!("{n} measurements, {stations}, sphere Ø {d} mm{pose_only}");
        let text_colour = ui.visuals().text_color();
        rows_ui(ui, &text, egui::TextStyle::Small, text_colour, 2);
    } else {
        match state.jobs.get(&Slot::Load) {
            Some(job) => name_ui(ui, &job.phase),
            None => name_ui(ui, "no session open"),
        }
        let colour = ui.visuals().text_color();
        rows_ui(ui, "", egui::TextStyle::Small, colour, 2);
        rows_ui(ui, "", egui::TextStyle::Small, colour, 2);
    }
    ui.add_space(4.0);
    let width = ui.available_width();
    let field = ui
        .vertical(|ui| {
            labelled_field(
                ui,
                "Session or result file",
                &mut forms.open_path,
                "/path/to/session.json",
                width,
            )
        })
        .inner;
    let entered = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
    ui.horizontal(|ui| {
        let open = Command::Files(FilesCommand::OpenPath(forms.open_path.trim().into()));
        if ui
            .button("Open path")
            .on_hover_text("open the file typed above")
            .clicked()
            || entered
        {
            commands.push(open);
        }
        let hover = "choose a file with the desktop's file dialog";
        let idle = !state.jobs.runs(&Slot::Dialog);
        command_button(
            ui,
            idle,
            "Open…",
            hover,
            Command::Browse(Purpose::Open),
            commands,
        );
        let hover = "the demo session built into the program";
        let demo = Command::Files(FilesCommand::OpenDemo);
        command_button(ui, true, "Demo", hover, demo, commands);
    });
    // One line either way: the dialog's note replaces the drop hint.
    let hint = if state.dialog_empty == Some(Purpose::Open) {
        NO_DIALOG
    } else {
        "or drop a file onto the window"
    };
    line(ui, RichText::new(hint).small().weak()).on_hover_text(hint);
}

/// The session's name in two lines of room whatever its length (wrapped,
/// cut with … beyond two lines, whole on hover).
fn name_ui(ui: &mut egui::Ui, name: &str) {
    let colour = ui.visuals().strong_text_color();
    rows_ui(ui, name, egui::TextStyle::Body, colour, 2);
}

/// `text` in exactly `rows` lines of room of `style` whatever its length:
/// wrapped (anywhere in a path), cut with … beyond `rows` lines, whole
/// on hover; the room is kept when the text is shorter or empty.
pub fn rows_ui(
    ui: &mut egui::Ui,
    text: &str,
    style: egui::TextStyle,
    colour: egui::Color32,
    rows: usize,
) {
    let width = ui.available_width();
    let height = rows as f32 * ui.text_style_height(&style);
    let mut job = egui::text::LayoutJob::single_section(
        text.to_string(),
        egui::TextFormat {
            font_id: style.resolve(ui.style()),
            color: colour,
            ..Default::default()
        },
    );
    job.wrap = egui::text::TextWrapping {
        max_width: width,
        max_rows: rows,
        break_anywhere: false,
        overflow_character: Some('…'),
    };
    let rect = egui::Rect::from_min_size(ui.cursor().min, egui::vec2(width, height));
    ui.scope_builder(egui::UiBuilder::new().max_rect(rect), |ui| {
        if !text.is_empty() {
            ui.add(egui::Label::new(job)).on_hover_text(text);
        }
    });
    // The whole room, whatever the label took.
    ui.advance_cursor_after_rect(rect);
}

/// Height of the notice's body before it scrolls, points (about seven
/// lines: the box stays on screen at 768 px).
const NOTICE_BODY_HEIGHT: f32 = 110.0;

/// The error of the last thing that failed (a file that did not open, an
/// export not written), until dismissed.
pub fn notice_ui(ui: &mut egui::Ui, state: &AppState, commands: &mut Vec<Command>) {
    if let Some(notice) = &state.notice {
        ui.add_space(6.0);
        // The title wrapped (a long path in it was cut at the panel's
        // edge), a long body scrolled within the box.
        let shown = boxed(ui, BAD, &notice.title, |ui| {
            let body = notice.body.as_str();
            scrolled_text(ui, "notice_body", NOTICE_BODY_HEIGHT, body);
            if ui.button("Dismiss").clicked() {
                commands.push(Command::View(ViewCommand::DismissNotice));
            }
        });
        // The panel scrolls the whole box into sight once when it comes
        // (it sits below the ε plot, under the fold at 768 px).
        let key = egui::Id::unique("notice_in_sight");
        let this = (notice.title.clone(), notice.body.clone());
        if ui.data(|d| d.get_temp::<(String, String)>(key)).as_ref() != Some(&this) {
            ui.data_mut(|d| d.insert_temp(key, this));
            shown.response.scroll_to_me(Some(egui::Align::Max));
        }
    }
}

/// The recent files, newest first.
pub fn recent_ui(ui: &mut egui::Ui, state: &AppState, commands: &mut Vec<Command>) {
    if !state.prefs.recent.is_empty() {
        ui.add_space(4.0);
        egui::CollapsingHeader::new("Recent files")
            .default_open(true)
            .show(ui, |ui| {
                for p in &state.prefs.recent {
                    let name = p.file_name().map_or_else(
                        || p.display().to_string(),
                        |n| n.to_string_lossy().into_owned(),
                    );
                    if ui
                        .add(egui::Button::new(name).truncate())
                        .on_hover_text(p.display().to_string())
                        .clicked()
                    {
                        commands.push(Command::Files(FilesCommand::OpenPath(p.clone())));
                    }
                }
                if ui.small_button("Clear list").clicked() {
                    commands.push(Command::Files(FilesCommand::ClearRecent));
                }
            });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The issue: "(2) raw profile, …" hid the cut-angle warning behind
    /// the count and cut the rest with "…". Every warning is named.
    #[test]
    fn every_warning_is_named_in_a_few_words() {
        let ws = vec![
            "raw profile, the sphere's arc: 412 of 800 points, 38.1° to 141.9°".to_string(),
            "cut angle 66.2° is above 60°: the laser plane is near the sphere's pole and the stripe circle is small (r = 16.2 mm); about ±40° is best".to_string(),
        ];
        assert_eq!(
            warnings_cell(&ws),
            "raw profile · cut angle 66.2° is above 60°"
        );
        assert_eq!(
            warning_tag("3 of 120 stripe points rejected as outliers (largest residual 0.300 mm)"),
            "3 points rejected"
        );
        assert_eq!(
            warning_tag("short arc: the stripe spans 12.0° of its circle"),
            "short arc"
        );
        assert_eq!(
            warning_tag("high circle-fit RMS: 0.2 mm over 9 points"),
            "high fit RMS"
        );
        assert_eq!(
            warning_tag("stripe radius r = 19.1 mm exceeds the sphere radius"),
            "centre on the laser plane"
        );
        assert!(warning_tag(&"x".repeat(80)).ends_with('…'));
    }
}
