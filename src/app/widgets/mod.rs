//! The widgets every view shares: colours and station markers, labelled
//! text and number fields, labelled drop-downs and the robot presets',
//! path rows with their Browse… button and the note when a dialog chose
//! nothing, the export folder, a job's phase and fraction, the STALE
//! banner, framed boxes (a failure, a notice), the Replace / Keep
//! question, the tabs, the status bar, measuring-range fields; plot
//! helpers in [`plots`].

pub mod plots;

use egui::{Color32, RichText};

use super::AppState;
use super::Forms;
use super::command::Tab;
use super::command::{Command, ViewCommand};
use super::dialog::{NO_DIALOG, Purpose};
use super::job::{Job, Slot};
use super::ledger::Artefact;
use super::state::Level;

/// Colour of "before calibration" series (nominal model, initial hand-eye).
pub const BEFORE: Color32 = Color32::from_rgb(230, 120, 40);
/// Colour of "after calibration" series.
pub const AFTER: Color32 = Color32::from_rgb(40, 150, 230);
/// Colour of rejected stripe points and errors.
pub const BAD: Color32 = Color32::from_rgb(225, 60, 60);
/// A passed check.
pub const GOOD: Color32 = Color32::from_rgb(60, 170, 90);
/// Colour of warnings.
pub const WARN: Color32 = Color32::from_rgb(230, 170, 40);
/// Colour of things marked not identifiable.
pub const MUTED: Color32 = Color32::from_rgb(150, 150, 150);

/// Ten colours that print and show apart (matplotlib's tab10).
const STATION_PALETTE: [Color32; 10] = [
    Color32::from_rgb(31, 119, 180),
    Color32::from_rgb(255, 127, 14),
    Color32::from_rgb(44, 160, 44),
    Color32::from_rgb(214, 39, 40),
    Color32::from_rgb(148, 103, 189),
    Color32::from_rgb(140, 86, 75),
    Color32::from_rgb(227, 119, 194),
    Color32::from_rgb(188, 189, 34),
    Color32::from_rgb(23, 190, 207),
    Color32::from_rgb(127, 127, 127),
];

/// The marker shapes of stations, one per ten stations, with the glyph
/// that stands for each in a key (fillable shapes: before is drawn
/// hollow, after filled).
pub const STATION_SHAPES: [(egui_plot::MarkerShape, &str); 4] = [
    (egui_plot::MarkerShape::Circle, "●"),
    (egui_plot::MarkerShape::Square, "■"),
    (egui_plot::MarkerShape::Diamond, "◆"),
    (egui_plot::MarkerShape::Right, "▶"),
];

/// How station number `k` is marked: one of ten colours and, by tens,
/// one of four shapes; from the 41st station on the colours are lighter.
/// Distinct for the first 80 stations.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StationStyle {
    /// Colour.
    pub colour: Color32,
    /// Shape in plots.
    pub shape: egui_plot::MarkerShape,
    /// The glyph of the shape, for a key.
    pub glyph: &'static str,
}

/// The marker of station number `k` ([`StationStyle`]).
#[must_use]
pub fn station_style(k: usize) -> StationStyle {
    let base = STATION_PALETTE[k % STATION_PALETTE.len()];
    let tens = k / STATION_PALETTE.len();
    let (shape, glyph) = STATION_SHAPES[tens % STATION_SHAPES.len()];
    let lighter = (tens / STATION_SHAPES.len()) % 2 == 1;
    let colour = if lighter {
        let up = |c: u8| c + (255 - c) / 2;
        Color32::from_rgb(up(base.r()), up(base.g()), up(base.b()))
    } else {
        base
    };
    StationStyle {
        colour,
        shape,
        glyph,
    }
}

/// A one-line text field with a visible label tied to it (screen readers
/// and the UI tests find it by that label).
pub fn labelled_field(
    ui: &mut egui::Ui,
    label: &str,
    text: &mut String,
    hint: &str,
    width: f32,
) -> egui::Response {
    let l = ui.label(label);
    ui.add(
        egui::TextEdit::singleline(text)
            .hint_text(hint)
            .desired_width(width),
    )
    .labelled_by(l.id)
}

/// A button that asks for `command` when clicked, greyed out unless
/// `enabled`, saying on hover what it does.
pub fn command_button(
    ui: &mut egui::Ui,
    enabled: bool,
    text: impl Into<egui::WidgetText>,
    hover: &str,
    command: Command,
    commands: &mut Vec<Command>,
) -> egui::Response {
    let response = ui.add_enabled(enabled, egui::Button::new(text));
    let response = response.on_hover_text(hover);
    if response.clicked() {
        commands.push(command);
    }
    response
}

/// A line of text in `colour`.
pub fn coloured(ui: &mut egui::Ui, colour: Color32, text: impl Into<String>) -> egui::Response {
    ui.label(RichText::new(text).color(colour))
}

/// A line of weak text (a hint, what to do first).
pub fn weak(ui: &mut egui::Ui, text: impl Into<String>) -> egui::Response {
    ui.label(RichText::new(text).weak())
}

/// A number dragged or typed, after the label `label` tied to it.
pub fn labelled_drag(ui: &mut egui::Ui, label: &str, drag: egui::DragValue) -> egui::Response {
    let l = ui.label(label);
    ui.add(drag).labelled_by(l.id)
}

/// A form's grid: `columns` columns (label, field, button), spaced alike
/// in every view.
pub fn form_grid<R>(
    ui: &mut egui::Ui,
    id: &str,
    columns: usize,
    add: impl FnOnce(&mut egui::Ui) -> R,
) -> egui::InnerResponse<R> {
    egui::Grid::new(id)
        .num_columns(columns)
        .spacing([8.0, 6.0])
        .show(ui, add)
}

/// A striped table of one row of strong `headers` above the rows `add`
/// draws (each ended with `ui.end_row()`).
pub fn table<R>(
    ui: &mut egui::Ui,
    id: &str,
    headers: &[&str],
    add: impl FnOnce(&mut egui::Ui) -> R,
) -> egui::InnerResponse<R> {
    egui::Grid::new(id)
        .striped(true)
        .num_columns(headers.len())
        .show(ui, |ui| {
            for h in headers {
                ui.label(RichText::new(*h).strong());
            }
            ui.end_row();
            add(ui)
        })
}

/// A drop-down that sets `value` to one of `options` (each with its
/// text, the chosen one's shown), after the label `label` tied to it
/// (screen readers and the UI tests find it by that label; none when
/// empty).
pub fn choice<T: PartialEq>(
    ui: &mut egui::Ui,
    label: &str,
    id_salt: &str,
    value: &mut T,
    options: impl IntoIterator<Item = (T, String)>,
) -> egui::Response {
    let l = (!label.is_empty()).then(|| ui.label(label));
    let options: Vec<(T, String)> = options.into_iter().collect();
    let shown = options
        .iter()
        .find(|(v, _)| v == value)
        .map_or_else(String::new, |(_, t)| t.clone());
    let response = egui::ComboBox::from_id_salt(id_salt)
        .selected_text(shown)
        .show_ui(ui, |ui| {
            for (v, t) in options {
                ui.selectable_value(value, v, t);
            }
        })
        .response;
    match l {
        Some(l) => response.labelled_by(l.id),
        None => response,
    }
}

/// The robot presets to choose from, each as `key (name)`, the key
/// shown: returns the drop-down's response (to tie a label to it).
pub fn preset_ui(ui: &mut egui::Ui, id_salt: &str, key: &mut String) -> egui::Response {
    egui::ComboBox::from_id_salt(id_salt)
        .selected_text(key.as_str())
        .show_ui(ui, |ui| {
            for p in crate::engine::base::robot::presets() {
                let text = format!("{} ({})", p.key, p.robot.name);
                ui.selectable_value(key, p.key.to_string(), text);
            }
        })
        .response
}

/// A number that is typed, never dragged (a sideways drag over it
/// changes nothing): a text field labelled `label`, showing `value` with
/// `unit` beside it, that takes what is typed on Enter or when it loses
/// focus, if it is a number in `range` (shown in red while it is not).
/// Returns the new value once taken, when it differs.
pub fn number_field(
    ui: &mut egui::Ui,
    id_salt: &str,
    label: &str,
    value: f64,
    range: std::ops::RangeInclusive<f64>,
    unit: &str,
) -> Option<f64> {
    let id = ui.make_persistent_id(("number_field", id_salt));
    let shown = plots::tick_label(egui_plot::GridMark {
        value,
        step_size: NUMBER_FIELD_RESOLUTION,
    });
    let typed: Option<String> = ui.data(|d| d.get_temp(id));
    let mut text = typed.clone().unwrap_or_else(|| shown.clone());
    let parse = |t: &str| {
        t.trim()
            .trim_end_matches(unit)
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && range.contains(v))
    };
    let l = ui.label(label);
    let valid = parse(&text).is_some();
    let mut edit = egui::TextEdit::singleline(&mut text)
        .id_salt(id)
        .desired_width(NUMBER_FIELD_WIDTH);
    if !valid {
        edit = edit.text_color(BAD);
    }
    let response = ui.add(edit).labelled_by(l.id).on_hover_text(format!(
        "type a number of {unit} ({} to {}), then Enter",
        range.start(),
        range.end()
    ));
    ui.label(unit);
    let mut taken = None;
    if response.has_focus() {
        ui.data_mut(|d| d.insert_temp(id, text));
    } else {
        if response.lost_focus() || typed.is_some() {
            taken = parse(&text).filter(|v| (*v - value).abs() > 0.0);
        }
        ui.data_mut(|d| d.remove::<String>(id));
    }
    taken
}

/// Decimals a [`number_field`] shows: steps of a micrometre.
const NUMBER_FIELD_RESOLUTION: f64 = 0.001;

/// Width of a [`number_field`], points.
const NUMBER_FIELD_WIDTH: f32 = 56.0;

/// What a view says with no session: that one is being opened (with a
/// spinner), else how to open one.
pub fn no_session_ui(ui: &mut egui::Ui, state: &AppState) {
    match state.jobs.get(&Slot::Load) {
        Some(job) => {
            ui.horizontal(|ui| {
                ui.spinner();
                ui.label(&job.phase);
            });
        }
        None => {
            ui.label("No session open: type a path on the left, press Open…, or drop a file here.");
        }
    }
}

/// The note that the last file dialog for one of `purposes` chose
/// nothing (or none is available), beside that dialog's Browse button.
pub fn dialog_note_ui(ui: &mut egui::Ui, state: &AppState, purposes: &[Purpose]) {
    if state.dialog_empty.is_some_and(|p| purposes.contains(&p)) {
        ui.label(RichText::new(NO_DIALOG).small().color(WARN));
    }
}

/// A job under way: a spinner, or the bar of its fraction, and its phase
/// by name (the bar never sits still without saying what it does).
pub fn job_ui(ui: &mut egui::Ui, job: &Job) {
    match job.fraction {
        Some(f) => {
            ui.add(
                egui::ProgressBar::new(f as f32)
                    .desired_width(160.0)
                    .show_percentage(),
            );
        }
        None => {
            ui.spinner();
        }
    }
    ui.add(egui::Label::new(RichText::new(&job.phase).small()).wrap());
}

/// The job in `slot`, when one runs, as [`job_ui`] on one line.
pub fn slot_ui(ui: &mut egui::Ui, state: &AppState, slot: &Slot) {
    if let Some(job) = state.jobs.get(slot) {
        ui.horizontal_wrapped(|ui| job_ui(ui, job));
    }
}

/// The mark over a stale output: what changed since it was made, and
/// what to do; its exports are refused (the buttons say why).
pub fn stale_banner_ui(ui: &mut egui::Ui, stale: &crate::app::ledger::Stale, todo: &str) {
    egui::Frame::group(ui.style())
        .stroke(egui::Stroke::new(2.0, WARN))
        .show(ui, |ui| {
            ui.set_width(ui.available_width());
            ui.horizontal_wrapped(|ui| {
                ui.label(RichText::new("STALE").strong().size(18.0).color(WARN));
                ui.label(
                    RichText::new(format!("{stale}. {todo}"))
                        .color(WARN)
                        .strong(),
                );
            });
        });
}

/// A box framed in `colour` with its `title` in that colour (a failure,
/// a notice, what to do next) above what `add` draws.
pub fn boxed<R>(
    ui: &mut egui::Ui,
    colour: Color32,
    title: &str,
    add: impl FnOnce(&mut egui::Ui) -> R,
) -> egui::InnerResponse<R> {
    egui::Frame::group(ui.style())
        .stroke(egui::Stroke::new(1.5, colour))
        .show(ui, |ui| {
            ui.set_width(ui.available_width());
            ui.label(RichText::new(title).strong().color(colour));
            add(ui)
        })
}

/// A long text (an error, a why) that scrolls past `max_height` points
/// rather than push what follows off the screen.
pub fn scrolled_text(
    ui: &mut egui::Ui,
    id: &str,
    max_height: f32,
    text: impl Into<egui::WidgetText>,
) {
    egui::ScrollArea::vertical()
        .id_salt(id)
        .max_height(max_height)
        .show(ui, |ui| {
            ui.label(text);
        });
}

/// The folder field the exports are written to, with its Browse… button.
pub fn export_folder_ui(
    ui: &mut egui::Ui,
    label: &str,
    folder: &mut String,
    width: f32,
    commands: &mut Vec<Command>,
) {
    labelled_field(ui, label, folder, "/path/to/folder", width);
    let hover = "choose the folder with the desktop's dialog";
    let browse = Command::Browse(Purpose::ExportFolder);
    command_button(ui, true, "Browse…", hover, browse, commands);
}

/// A plot's key on one line above it, each entry in its series' colour
/// (a legend inside the plot would cover data).
pub fn plot_key(ui: &mut egui::Ui, entries: &[(&str, egui::Color32)]) {
    ui.horizontal_wrapped(|ui| {
        for (text, colour) in entries {
            ui.label(RichText::new(*text).color(*colour).small());
        }
    });
}

/// The default measuring range offered before one is set: 80 × 80 mm
/// about the sensor origin, `[y0, y1, z0, z1]`.
pub const DEFAULT_RANGE: [f64; 4] = [-40.0, 40.0, -40.0, 40.0];

/// Four fields for a measuring range `[y0, y1, z0, z1]` (mm, laser plane,
/// sensor frame), each labelled, on one line or (`rows`) a line per axis;
/// true when one changed.
pub fn range_fields(ui: &mut egui::Ui, id: &str, v: &mut [f64; 4], rows: bool) -> bool {
    let mut changed = false;
    let mut pair = |ui: &mut egui::Ui, first: usize, axis: &str, what: &str| {
        for (k, label) in [
            (first, format!("{axis} from")),
            (first + 1, "to".to_owned()),
        ] {
            let l = ui.label(label);
            let hint = format!(
                "{what}, {} (mm, sensor frame)",
                if k == first { "smallest" } else { "largest" }
            );
            changed |= ui
                .push_id((id, k), |ui| {
                    ui.add(
                        egui::DragValue::new(&mut v[k])
                            .range(-2000.0..=2000.0)
                            .speed(0.5)
                            .suffix(" mm"),
                    )
                    .labelled_by(l.id)
                    .on_hover_text(hint)
                })
                .inner
                .changed();
        }
    };
    if rows {
        ui.horizontal(|ui| pair(ui, 0, "y", "along the laser line"));
        ui.horizontal(|ui| pair(ui, 2, "z", "in depth"));
    } else {
        pair(ui, 0, "y", "along the laser line");
        pair(ui, 2, "z", "in depth");
    }
    changed
}

/// The range of `[y0, y1, z0, z1]`, or why it is not one.
///
/// # Errors
/// Why the four numbers are not a range (a lower bound not below its
/// upper one).
pub fn range_of(v: &[f64; 4]) -> Result<crate::engine::base::session::SensorRange, &'static str> {
    if v[0] < v[1] && v[2] < v[3] {
        Ok(crate::engine::base::session::SensorRange {
            y: [v[0], v[1]],
            z: [v[2], v[3]],
        })
    } else {
        Err("each side needs from < to")
    }
}

/// `[y0, y1, z0, z1]` of a range.
#[must_use]
pub fn range_values(r: &crate::engine::base::session::SensorRange) -> [f64; 4] {
    [r.y[0], r.y[1], r.z[0], r.z[1]]
}

/// The row of view tabs.
pub fn tabs_ui(ui: &mut egui::Ui, state: &AppState, forms: &Forms, commands: &mut Vec<Command>) {
    ui.horizontal(|ui| {
        for tab in Tab::ALL {
            let unseen = tab == Tab::Results && state.result_unseen && state.result.is_some();
            let label = if unseen {
                format!("{} ●", tab.label())
            } else {
                tab.label().to_string()
            };
            let mut text = RichText::new(label).size(16.0);
            if forms.tab == tab {
                text = text.strong();
            }
            if unseen {
                text = text.color(AFTER);
            }
            if ui.selectable_label(forms.tab == tab, text).clicked() {
                commands.push(Command::View(ViewCommand::ShowTab(tab)));
            }
        }
        // The session's name at the right, cut with … where it would come
        // nearer the last tab than a gap (a long name touched "History").
        ui.add_space(TABS_GAP);
        let room = (ui.available_width() - ui.spacing().item_spacing.x).max(0.0);
        let size = egui::vec2(room, ui.spacing().interact_size.y);
        let layout = egui::Layout::right_to_left(egui::Align::Center);
        ui.allocate_ui_with_layout(size, layout, |ui| {
            if let Some(l) = &state.loaded {
                let name = RichText::new(&l.session.name).weak();
                ui.add(egui::Label::new(name).truncate())
                    .on_hover_text(&l.session.name);
            }
        });
    });
}

/// Least room between the last tab and the session's name, points.
const TABS_GAP: f32 = 24.0;

/// The question of a write that would replace a file this window did not
/// write of the same artefact from the same inputs: Replace, or Keep.
pub fn confirm_ui(ctx: &egui::Context, state: &AppState, commands: &mut Vec<Command>) {
    let Some(c) = &state.confirm else {
        return;
    };
    egui::Modal::new(egui::Id::unique("confirm_replace")).show(ctx, |ui| {
        ui.set_max_width(520.0);
        ui.label(RichText::new(format!("Replace {}?", c.path.display())).strong());
        ui.add(egui::Label::new(RichText::new(&c.why).color(WARN)).wrap());
        ui.horizontal(|ui| {
            for (text, hover, replace) in [
                ("Replace", "write the new file over it", true),
                (
                    "Keep the file",
                    "write nothing: the file stays as it is",
                    false,
                ),
            ] {
                command_button(ui, true, text, hover, Command::Confirm(replace), commands);
            }
        });
    });
}

/// The files written this session of the `of` artefacts, newest first
/// (the last [`WRITTEN_SHOWN`]), each marked stale when an input of it
/// has changed since (what changed on hover).
pub fn written_ui(ui: &mut egui::Ui, state: &AppState, of: &[Artefact]) {
    let ledger = &state.ledger;
    let written = ledger.written.iter().rev().filter(|w| of.contains(&w.from));
    let mine: Vec<_> = written.take(WRITTEN_SHOWN).collect();
    if mine.is_empty() {
        return;
    }
    ui.horizontal_wrapped(|ui| {
        ui.label(RichText::new("written:").small().weak());
        for w in mine {
            let name = w.path.file_name().map_or_else(
                || w.path.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            );
            let (text, colour, hover) = match ledger.written_stale(w) {
                Some(s) => (
                    format!("! {name} (stale)"),
                    WARN,
                    format!("{}: {s}", w.path.display()),
                ),
                None => (
                    format!("● {name}"),
                    GOOD,
                    format!("{} ({}), current", w.path.display(), w.what),
                ),
            };
            ui.label(RichText::new(text).small().color(colour))
                .on_hover_text(hover);
        }
    });
}

/// Files listed by [`written_ui`], newest first.
const WRITTEN_SHOWN: usize = 4;

/// A dimmed overlay while files are dragged over the window.
pub fn drop_overlay_ui(ctx: &egui::Context) {
    let hovering = ctx.input(|i| !i.raw.hovered_files.is_empty());
    if !hovering {
        return;
    }
    let painter = ctx.layer_painter(egui::LayerId::new(
        egui::Order::Foreground,
        egui::Id::unique("drop"),
    ));
    let rect = ctx.content_rect();
    painter.rect_filled(rect, 0.0, Color32::from_black_alpha(160));
    painter.text(
        rect.center(),
        egui::Align2::CENTER_CENTER,
        "Drop a session or result file to open it",
        egui::FontId::proportional(24.0),
        Color32::WHITE,
    );
}

/// `before → after` ratio as text, e.g. "3.3× lower".
#[must_use]
pub fn ratio_text(before: f64, after: f64) -> String {
    if after > 0.0 && before > 0.0 {
        let r = before / after;
        if r >= 1.0 {
            format!("{r:.1}× lower")
        } else {
            format!("{:.1}× higher", 1.0 / r)
        }
    } else {
        String::new()
    }
}

/// The label of a log-scale tick at `log10(v) = exponent`: `v` with the
/// fewest decimals that give it to 1e-6 of itself (ticks sit on round
/// values: 0.1, 0.365, 20), at most four significant digits; outside
/// 0.001 … 10,000 in scientific notation.
#[must_use]
pub fn log_tick(exponent: f64) -> String {
    let v = 10f64.powf(exponent);
    if !(1e-3..1e4).contains(&v) {
        return format!("{v:.1e}");
    }
    let most = (3.0 - v.log10().floor()).max(0.0) as usize;
    let decimals = (0..=most)
        .find(|&d| {
            // At most four decimals: the cast cannot wrap.
            let scale = 10f64.powi(i32::try_from(d).unwrap_or(i32::MAX));
            ((v * scale).round() / scale - v).abs() <= v * 1e-6
        })
        .unwrap_or(most);
    format!("{v:.decimals$}")
}

/// Width of the path fields, points.
pub const PATH_WIDTH: f32 = 420.0;

/// A path row of a form grid: its label, the path field and a Browse…
/// button that asks for the desktop's dialog for `purpose`.
pub fn path_row(
    ui: &mut egui::Ui,
    label: &str,
    text: &mut String,
    hint: &str,
    busy: bool,
    purpose: Purpose,
    commands: &mut Vec<Command>,
) {
    labelled_field(ui, label, text, hint, PATH_WIDTH);
    let hover = format!(
        "choose the {} with the desktop's dialog",
        label.to_lowercase()
    );
    command_button(
        ui,
        !busy,
        "Browse…",
        &hover,
        Command::Browse(purpose),
        commands,
    );
    ui.end_row();
}

/// The status bar.
pub fn status_ui(ui: &mut egui::Ui, state: &AppState) {
    ui.horizontal(|ui| {
        ui.set_min_height(22.0);
        if state.is_busy() {
            ui.spinner();
        }
        if let Some(s) = &state.status {
            let text = RichText::new(&s.text);
            let text = match s.level {
                Level::Info => text,
                Level::Warning => text.color(WARN),
                Level::Error => text.color(BAD),
            };
            // Whole, on as many lines as it takes: a cut status hides
            // what happened.
            ui.add(egui::Label::new(text).wrap());
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The issue: with ten colours for 20 stations P0 and V1 shared blue.
    /// Every one of 80 stations now has its own colour and shape.
    #[test]
    fn station_markers_are_distinct() {
        let styles: Vec<StationStyle> = (0..80).map(station_style).collect();
        for (a, sa) in styles.iter().enumerate() {
            for (b, sb) in styles.iter().enumerate().skip(a + 1) {
                assert!(
                    (sa.colour, sa.glyph) != (sb.colour, sb.glyph),
                    "stations {a} and {b} look alike"
                );
            }
        }
        // P0 (station 0) and V1 (station 10) of the demo: same hue, other shape.
        assert_eq!(station_style(0).colour, station_style(10).colour);
        assert_ne!(station_style(0).shape, station_style(10).shape);
    }
}
