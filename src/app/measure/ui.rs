//! The Measure view: a scan measured with the calibrated cell. The
//! inputs (the result on show, the scan: the open session, a session
//! file or a raw scan's pose log and profiles; `use`, a workpiece frame,
//! the sensor's noise, σ or not), Measure and Cancel with the job's
//! progress; the cloud in three projections (XY, XZ, YZ) coloured by σ
//! with a colour bar in mm or µm, drawn from the job's decimated copy
//! (never more than [`DRAWN_MAX`] points whatever the cloud's size); the
//! counts; the self-validation on the sphere stations before and after
//! calibration; and the export to PLY, E57 or CSV, refused while the
//! cloud is stale. Also the Measure step of the step bar.

use egui::{Color32, RichText};
use egui_plot::{Plot, PlotPoint};

use crate::app::AppState;
use crate::app::Forms;
use crate::app::command::{Command, MeasureCommand};
use crate::app::dialog::Purpose;
use crate::app::import::form::CONVENTIONS;
use crate::app::job::Slot;
use crate::app::ledger::Artefact;
use crate::app::measure::job::MeasuredCloud;
use crate::app::measure::job::{DRAWN_MAX, group, has_covariance};
use crate::app::measure::{MeasureForm, RawLog, ScanChoice};
use crate::app::widgets::{
    AFTER, BAD, GOOD, MUTED, WARN, boxed, choice, coloured, command_button, labelled_field,
    number_field, path_row, stale_banner_ui, table,
};
use crate::engine::base::session::Use;
use crate::engine::files::import::{AngleUnit, LengthUnit};
use crate::engine::tools::simulate::config::MAX_SENSOR_NOISE_MM;
use crate::engine::uses::measure::{self, selfcheck::ModelCheck, selfcheck::Spacing};

/// Side of a drawn point, screen points: one or two pixels, so that
/// 50,000 points show the part's shape rather than a blot.
const POINT_SIZE: f32 = 2.0;

/// Width of the colour bar beside the projections, points.
const BAR_WIDTH: f32 = 86.0;

/// Tallest projection, points: three of them and the inputs above fit a
/// 1366×768 screen with the self-validation one scroll below.
const MAX_PLOT_HEIGHT: f32 = 270.0;

/// Below this largest σ (mm) the colour bar and figures are in µm: a
/// well calibrated cell's points are tens of micrometres.
const MICROMETRE_BELOW_MM: f64 = 0.1;

/// The colour scale (viridis at five stops): low σ dark blue, high σ
/// yellow; tells values apart in grey print and for the colour-blind.
const SCALE: [[u8; 3]; 5] = [
    [68, 1, 84],
    [59, 82, 139],
    [33, 145, 140],
    [94, 201, 98],
    [253, 231, 37],
];

/// The colour of `t` ∈ [0, 1] on [`SCALE`].
#[must_use]
pub fn scale_colour(t: f64) -> Color32 {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (SCALE.len() - 1) as f64;
    let k = (x.floor() as usize).min(SCALE.len() - 2);
    let f = x - k as f64;
    let mix = |i: usize| {
        let (a, b) = (f64::from(SCALE[k][i]), f64::from(SCALE[k + 1][i]));
        (a + (b - a) * f).round() as u8
    };
    Color32::from_rgb(mix(0), mix(1), mix(2))
}

/// The colour of a point of σ `s` (mm) on the cloud's scale; no σ:
/// the "after" colour.
#[must_use]
pub fn sigma_colour(c: &MeasuredCloud, s: f64) -> Color32 {
    match c.sigma_range {
        Some((lo, hi)) if s.is_finite() => {
            scale_colour(if hi > lo { (s - lo) / (hi - lo) } else { 0.5 })
        }
        _ => AFTER,
    }
}

/// The unit σ is shown in, and millimetres to it: µm when the largest σ
/// is below [`MICROMETRE_BELOW_MM`], else mm.
#[must_use]
pub fn sigma_unit(max_mm: f64) -> (&'static str, f64) {
    if max_mm < MICROMETRE_BELOW_MM {
        ("µm", 1000.0)
    } else {
        ("mm", 1.0)
    }
}

/// The Measure view.
pub fn measure_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    egui::ScrollArea::vertical()
        .id_salt("measure_scroll")
        .auto_shrink(false)
        .show(ui, |ui| {
            if state.measure.shown.is_none() {
                to_do_ui(ui, state, &forms.measure);
            }
            inputs_ui(ui, state, forms, commands);
            let Some(cloud) = &state.measure.shown else {
                return;
            };
            ui.separator();
            if let Some(s) = state.ledger.stale(Artefact::Cloud) {
                stale_banner_ui(
                    ui,
                    &s,
                    "Press ▶ Measure again; its export is refused until then.",
                );
            }
            summary_ui(ui, cloud);
            export_ui(ui, state, forms, commands);
            scene_ui(ui, cloud, forms);
            projections_ui(ui, cloud);
            ui.separator();
            self_check_ui(ui, cloud);
        });
}

/// With no cloud on show, what to do first, boxed at the top of the view
/// (issue 34: Next's "Measure a scan" opened the view and nothing said
/// where to start), and what comes with the cloud.
fn to_do_ui(ui: &mut egui::Ui, state: &AppState, form: &MeasureForm) {
    let press = "then press ▶ Measure";
    let todo = match (&state.result, form.choice, &state.loaded) {
        (None, ..) => {
            "run the calibration (step 4) or open a result file: the scan is measured through it"
                .to_string()
        }
        (Some(_), ScanChoice::OpenSession, Some(l)) => format!(
            "press ▶ Measure to measure the open session \"{}\" through the result on show, or choose a session file or a raw scan below",
            l.session.name
        ),
        (Some(_), ScanChoice::OpenSession, None) => {
            "open a session, or choose a session file or a raw scan below".to_string()
        }
        (Some(_), ScanChoice::SessionFile, _) if form.session_file.trim().is_empty() => {
            format!("type or browse the session file below, {press}")
        }
        (Some(_), ScanChoice::RawScan, _) => form
            .scan_files(0)
            .map_or_else(|why| format!("{why}, {press}"), |_| press.to_string()),
        (Some(_), ScanChoice::SessionFile, _) => press.to_string(),
    };
    boxed(ui, AFTER, &format!("To do: {todo}"), |ui| {
        let what = "The cloud is shown in the cell in 3-D and in three projections (XY, XZ, YZ), each point coloured by its σ; the counts, the export and the self-validation come with it.";
        ui.label(RichText::new(what).small().color(MUTED));
    });
}

/// Whether the view is drawn for the first time since it was last
/// hidden (opened by its tab or by Next).
fn newly_opened(ui: &egui::Ui) -> bool {
    let (id, frame) = (
        ui.make_persistent_id("measure_view_drawn"),
        ui.ctx().cumulative_frame_nr(),
    );
    let last: Option<u64> = ui.data_mut(|d| d.get_temp(id));
    ui.data_mut(|d| d.insert_temp(id, frame));
    last.is_none_or(|l| l + 1 < frame)
}

/// The result, the scan and the options, Measure and Cancel; ▶ Measure
/// takes the keyboard focus when the view opens with no cloud and a scan
/// to measure (Enter measures).
fn inputs_ui(ui: &mut egui::Ui, state: &AppState, forms: &mut Forms, commands: &mut Vec<Command>) {
    let opened = newly_opened(ui);
    let form = &mut forms.measure;
    ui.horizontal_wrapped(|ui| {
        ui.label(RichText::new("Result:").strong());
        match &state.result {
            Some(v) => {
                let origin = match &v.origin {
                    crate::app::results::ResultOrigin::Review(p) => p.display().to_string(),
                    crate::app::results::ResultOrigin::Run { .. } => "this window's run".to_string(),
                };
                ui.label(format!(
                    "the result on show: {origin} (method {}, session \"{}\")",
                    v.method(), v.file.session
                ));
                if !has_covariance(&v.file) {
                    let method = v.file.solver.method();
                    coloured(ui, WARN, format!(
                        "σ is unavailable: method {method} gives no parameter covariance; tick \"no σ\" to measure without it"
                    ));
                }
                if let Some(s) = state.ledger.stale(Artefact::Result) {
                    coloured(ui, WARN, s.to_string());
                }
            }
            None => drop(coloured(ui, WARN, "none: run the calibration (or open a result file) first")),
        }
    });
    let summary = match form.choice {
        ScanChoice::OpenSession => "the open session".to_string(),
        ScanChoice::SessionFile => form.session_file.trim().to_string(),
        ScanChoice::RawScan => form.log.trim().to_string(),
    };
    egui::CollapsingHeader::new(RichText::new(format!("Scan and options: {summary}")).strong())
        .id_salt("measure_inputs")
        .default_open(true)
        .show(ui, |ui| scan_ui(ui, state, form, commands));
    ui.horizontal_wrapped(|ui| {
        if let Some(v) = number_field(
            ui,
            "measure_noise",
            "Sensor noise (1σ in-plane)",
            form.options.sensor_noise_mm,
            0.0..=MAX_SENSOR_NOISE_MM,
            "mm",
        ) {
            form.options.sensor_noise_mm = v;
        }
        let mut no_sigma = !form.options.sigma;
        ui.checkbox(&mut no_sigma, "no σ (as --no-sigma)")
            .on_hover_text("measure without σ: for a result without covariance (method paper)");
        form.options.sigma = !no_sigma;
        ui.add_space(12.0);
        let running = state.jobs.runs(&Slot::Measure);
        let (start, cancel) = (MeasureCommand::Start, MeasureCommand::Cancel);
        let text = RichText::new("▶ Measure").size(16.0);
        let hover = "measure the scan with the result on show, on a background thread";
        let idle = !running && state.result.is_some();
        let measure = command_button(ui, idle, text, hover, Command::Measure(start), commands)
            .on_disabled_hover_text("a result is needed (and no measuring under way)");
        if opened && idle && state.measure.shown.is_none() {
            measure.request_focus();
        }
        let hover = "stop the measuring job; the cloud on show stays";
        let cancel = Command::Measure(cancel);
        command_button(ui, running, "Cancel measuring", hover, cancel, commands);
        if let Some(job) = state.jobs.get(&Slot::Measure) {
            crate::app::widgets::job_ui(ui, job);
        }
    });
    if let Some(why) = &state.measure.failure {
        coloured(ui, BAD, why);
    }
}

/// What is measured and how: the scan (the open session, a session
/// file, a raw scan's files and their options), the workpiece frame.
fn scan_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    form: &mut MeasureForm,
    commands: &mut Vec<Command>,
) {
    ui.horizontal_wrapped(|ui| {
        ui.label(RichText::new("Scan:").strong());
        for choice in ScanChoice::ALL {
            ui.radio_value(&mut form.choice, choice, choice.label());
        }
        if form.choice != ScanChoice::RawScan {
            let uses = Use::ALL.map(|u| (Some(u), u.as_str().to_string()));
            let options = std::iter::once((None, "all".to_string())).chain(uses);
            choice(ui, "  use", "measure_use", &mut form.usage, options)
                .on_hover_text("which measurements of the session are measured (as --use)");
        }
    });
    // A path field with its Browse… button (the note when a dialog chose
    // nothing is under the scan's fields).
    let busy = state.jobs.runs(&Slot::Dialog);
    let mut row = |ui: &mut egui::Ui, label, hint, text: &mut String, purpose| {
        ui.horizontal(|ui| path_row(ui, label, text, hint, busy, purpose, commands));
    };
    match form.choice {
        ScanChoice::OpenSession => {
            let what = state.loaded.as_ref().map_or_else(
                || "no session open".to_string(),
                |l| {
                    format!(
                        "\"{}\": every stripe point of its measurements, as they are",
                        l.session.name
                    )
                },
            );
            ui.label(RichText::new(what).small().color(MUTED));
        }
        ScanChoice::SessionFile => {
            let (text, purpose) = (&mut form.session_file, Purpose::MeasureSession);
            row(ui, "Session file", "a session .json", text, purpose);
        }
        ScanChoice::RawScan => {
            ui.horizontal_wrapped(|ui| {
                ui.radio_value(&mut form.raw_log, RawLog::Joints, "joint log CSV")
                    .on_hover_text("columns id, j1..jn (optional station, use)");
                ui.radio_value(&mut form.raw_log, RawLog::Poses, "pose file")
                    .on_hover_text("a table, a JSON list or a robot program (layout detected); only the hand-eye applies to flange poses");
            });
            let hint = "joint log CSV or pose file";
            row(ui, "Pose log", hint, &mut form.log, Purpose::MeasureLog);
            let hint = "a folder of <id>.csv…, or one CSV with a pose column";
            row(
                ui,
                "Profiles",
                hint,
                &mut form.profiles,
                Purpose::MeasureProfiles,
            );
            raw_units_ui(ui, form);
            let hint = "optional: the artefact's distances CSV (from,to,distance mm)";
            let (text, purpose) = (&mut form.references, Purpose::MeasureReferences);
            row(ui, "References", hint, text, purpose);
        }
    }
    let hint = "optional: a JSON 4×4 base_from_workpiece (mm); empty: robot base frame";
    row(
        ui,
        "Workpiece frame",
        hint,
        &mut form.frame,
        Purpose::MeasureFrame,
    );
    let purposes = [
        Purpose::MeasureSession,
        Purpose::MeasureLog,
        Purpose::MeasureProfiles,
        Purpose::MeasureReferences,
        Purpose::MeasureFrame,
    ];
    crate::app::widgets::dialog_note_ui(ui, state, &purposes);
}

/// The raw scan's units and readings: joint unit or pose convention,
/// profile unit, axes, no-return value, the artefact's diameter.
fn raw_units_ui(ui: &mut egui::Ui, form: &mut MeasureForm) {
    ui.horizontal_wrapped(|ui| {
        match form.raw_log {
            RawLog::Joints => {
                let units = [AngleUnit::Deg, AngleUnit::Rad].map(|u| (u, u.as_str().to_string()));
                choice(ui, "joints in", "measure_joint_unit", &mut form.joint_unit, units);
            }
            RawLog::Poses => {
                let conventions = CONVENTIONS.map(|(c, t)| (Some(c), t.to_string()));
                let options = std::iter::once((None, "as the file says".to_string()));
                let (value, id) = (&mut form.pose_convention, "measure_convention");
                choice(ui, "pose convention", id, value, options.chain(conventions));
            }
        }
        let units = [LengthUnit::Mm, LengthUnit::Um, LengthUnit::M].map(|u| (u, u.as_str().to_string()));
        choice(ui, "profiles in", "measure_profile_unit", &mut form.profile_unit, units);
        labelled_field(ui, "axes", &mut form.axes, "auto or -y,x,z", 70.0);
        labelled_field(ui, "no-return value", &mut form.no_return, "none", 60.0);
        labelled_field(
            ui,
            "sphere artefact Ø (mm)",
            &mut form.sphere_diameter,
            "none",
            60.0,
        )
        .on_hover_text("a scan of a sphere artefact: its spheres' diameter, for the self-validation of the log's stations");
    });
}

/// The counts, the σ figures, the warnings.
fn summary_ui(ui: &mut egui::Ui, c: &MeasuredCloud) {
    let (cloud, o) = (c.cloud(), &c.outcome);
    let (points, dropped) = (cloud.len(), cloud.dropped());
    ui.label(
        RichText::new(format!(
            "{} points kept of {} poses ({} model, {}); dropped {} NaN and {} no-return points",
            group(points),
            group(cloud.poses.len()),
            cloud.model,
            cloud.frame,
            group(dropped.non_finite),
            group(dropped.no_return)
        ))
        .strong(),
    );
    let origin = format!("scan {} · result {} · {:.2} s", o.scan, c.result, c.seconds);
    ui.label(RichText::new(origin).small().color(MUTED));
    let decimation = if c.drawn.len() < points {
        format!(
            "showing {} of {} points (spread evenly; at most {} are drawn)",
            group(c.drawn.len()),
            group(points),
            group(DRAWN_MAX)
        )
    } else {
        format!("showing all {} points", group(points))
    };
    ui.horizontal_wrapped(|ui| {
        ui.label(decimation);
        match (&c.sigma, &c.no_sigma) {
            (Some(s), _) => {
                let (unit, k) = sigma_unit(s.max);
                ui.label(format!(
                    "· σ of a point: median {:.3} {unit}, rms {:.3} {unit}, max {:.3} {unit} (3-D, after the cloud's best rigid alignment; {})",
                    s.median * k,
                    s.rms * k,
                    s.max * k,
                    c.sigma_basis
                ));
            }
            (None, Some(why)) => drop(coloured(ui, WARN, format!("· {why}"))),
            (None, None) => {}
        }
    });
    if !o.skipped.is_empty() {
        let n = o.skipped.len();
        let text = format!("{n} measurement(s) give a sphere centre, no profile: not in the cloud");
        ui.label(RichText::new(text).small());
    }
    for note in &o.notes {
        ui.label(RichText::new(note).small());
    }
    for w in &o.measured.warnings {
        coloured(ui, WARN, format!("warning: {w}"));
    }
    let outside = &o.measured.out_of_range;
    if !outside.is_empty() {
        let title = format!(
            "warning: {} pose(s) outside the joint range the calibration saw (the model was not checked there)",
            outside.len()
        );
        ui.collapsing(RichText::new(title).color(WARN), |ui| {
            for o in measure::listed(outside) {
                ui.label(RichText::new(o).small());
            }
        });
    }
}

/// Height of the 3-D scene of the cloud, points.
const SCENE_HEIGHT: f32 = 330.0;

/// The cloud in the cell, in 3-D: its drawn points coloured by σ, the
/// frame's axes and the sensor's path, with the budget said.
fn scene_ui(ui: &mut egui::Ui, c: &MeasuredCloud, forms: &mut Forms) {
    let scene = crate::app::measure::scene::cloud_scene(c);
    let caption = format!(
        "3-D: {} of {} points drawn (budget {}, spread evenly), coloured by σ as the bar below; axes of the {} (x red, y green, z blue); the sensor's path in red",
        group(c.drawn.len()),
        group(c.cloud().len()),
        group(DRAWN_MAX),
        c.cloud().frame
    );
    crate::app::scene::ui::scene_ui(
        ui,
        "measure",
        &mut forms.scene.measure,
        &scene,
        &caption,
        SCENE_HEIGHT,
    );
}

/// The three projections and the colour bar.
fn projections_ui(ui: &mut egui::Ui, c: &MeasuredCloud) {
    let Some((lo, hi)) = c.bounds else {
        ui.label("the cloud has no points");
        return;
    };
    let spacing = ui.spacing().item_spacing.x;
    let width = ((ui.available_width() - BAR_WIDTH - 4.0 * spacing) / 3.0).max(160.0);
    let height = (width * 0.9).min(MAX_PLOT_HEIGHT);
    let axes = ["x", "y", "z"];
    ui.horizontal_top(|ui| {
        for (name, a, b) in [
            ("XY (from above)", 0, 1),
            ("XZ (from the front)", 0, 2),
            ("YZ (from the side)", 1, 2),
        ] {
            ui.vertical(|ui| {
                ui.label(RichText::new(name).strong());
                // The workbench's readable axes: a tick every few tens of
                // points on both axes, not one.
                let response = crate::app::widgets::plots::readable(
                    Plot::new(("measure_projection", a, b)),
                    false,
                )
                .width(width)
                .height(height)
                .data_aspect(1.0)
                .include_x(lo[a])
                .include_x(hi[a])
                .include_y(lo[b])
                .include_y(hi[b])
                .x_axis_label(format!("{} (mm)", axes[a]))
                .y_axis_label(format!("{} (mm)", axes[b]))
                .allow_scroll(false)
                .show(ui, |_| {});
                paint_points(ui, c, a, b, &response.transform);
            });
        }
        colour_bar_ui(ui, c, height);
    });
}

/// The drawn points of `c` on axes `a`, `b` as small squares in one
/// mesh (a shape per point would cost the frame far more).
fn paint_points(
    ui: &egui::Ui,
    c: &MeasuredCloud,
    a: usize,
    b: usize,
    transform: &egui_plot::PlotTransform,
) {
    let frame = *transform.frame();
    let mut mesh = egui::Mesh::default();
    mesh.reserve_vertices(4 * c.drawn.len());
    mesh.reserve_triangles(2 * c.drawn.len());
    let size = egui::vec2(POINT_SIZE, POINT_SIZE);
    for p in &c.drawn {
        let at = transform.position_from_point(&PlotPoint::new(p.position[a], p.position[b]));
        if frame.contains(at) {
            mesh.add_colored_rect(
                egui::Rect::from_center_size(at, size),
                sigma_colour(c, p.sigma_mm),
            );
        }
    }
    ui.painter_at(frame).add(egui::Shape::mesh(mesh));
}

/// The colour bar: σ from the smallest (bottom) to the largest (top)
/// drawn, in mm or µm; or why there is no σ.
fn colour_bar_ui(ui: &mut egui::Ui, c: &MeasuredCloud, height: f32) {
    ui.vertical(|ui| {
        ui.set_width(BAR_WIDTH);
        let Some((lo, hi)) = c.sigma_range else {
            ui.label(RichText::new("σ").strong());
            ui.label(
                RichText::new(c.no_sigma.as_deref().unwrap_or("no σ"))
                    .small()
                    .color(WARN),
            );
            return;
        };
        let (unit, k) = sigma_unit(hi);
        ui.label(RichText::new(format!("σ ({unit})")).strong())
            .on_hover_text(
                "1σ of each point's 3-D position, after the cloud's best rigid alignment",
            );
        ui.label(format!("{:.3}", hi * k));
        let bar_height = (height - 70.0).max(60.0);
        let (rect, _) = ui.allocate_exact_size(egui::vec2(24.0, bar_height), egui::Sense::hover());
        let mut mesh = egui::Mesh::default();
        const STRIPS: usize = 32;
        for i in 0..STRIPS {
            let t0 = i as f32 / STRIPS as f32;
            let t1 = (i + 1) as f32 / STRIPS as f32;
            let strip = egui::Rect::from_x_y_ranges(
                rect.x_range(),
                egui::Rangef::new(
                    rect.bottom() - t1 * rect.height(),
                    rect.bottom() - t0 * rect.height(),
                ),
            );
            mesh.add_colored_rect(strip, scale_colour(f64::from(t0 + t1) / 2.0));
        }
        ui.painter().add(egui::Shape::mesh(mesh));
        ui.label(format!("{:.3}", lo * k));
        ui.label(
            RichText::new(format!("mid {:.3}", f64::midpoint(lo, hi) * k))
                .small()
                .color(MUTED),
        );
    });
}

/// `rms / max` of a figure, mm.
fn pair(v: (f64, f64)) -> String {
    format!("{:.4} / {:.4} mm", v.0, v.1)
}

/// The self-validation table: the ISO 10360-8-style figures before and
/// after calibration, with units.
fn self_check_ui(ui: &mut egui::Ui, c: &MeasuredCloud) {
    ui.label(RichText::new("Self-validation with the cell's own scanner").strong());
    let Some(v) = &c.outcome.check else {
        ui.label(
            RichText::new(
                "no sphere station in the scan (a session's validate stations, or a raw scan with a station column): nothing to check",
            )
            .small()
            .color(MUTED),
        );
        return;
    };
    ui.label(
        RichText::new(format!(
            "the {} mm sphere at {} station(s), fitted in the base frame (ISO 10360-8-style; rms / max over stations)",
            v.diameter,
            v.after.stations.len()
        ))
        .small(),
    );
    let (b, a) = (&v.before, &v.after);
    let mut rows = vec![
        (
            "size error (fitted − calibrated diameter)".to_string(),
            b.size(),
            a.size(),
        ),
        (
            "form error (range of radial residuals)".to_string(),
            b.form(),
            a.form(),
        ),
        (
            "position spread (each pose's centre)".to_string(),
            b.spread(),
            a.spread(),
        ),
    ];
    if let (Some(before), Some(after)) = (b.spacing_error(), a.spacing_error()) {
        let n = a.spacings.iter().filter(|s| s.reference.is_some()).count();
        rows.push((
            format!("spacing error ({n} reference distances)"),
            before,
            after,
        ));
    }
    let headers = ["figure", "before (nominal)", "after (calibrated)", ""];
    table(ui, "measure_selfcheck", &headers, |ui| {
        for (name, b, a) in &rows {
            ui.label(name);
            ui.label(pair(*b));
            coloured(ui, if a.0 <= b.0 { GOOD } else { WARN }, pair(*a));
            ui.label(RichText::new(crate::app::widgets::ratio_text(b.0, a.0)).small());
            ui.end_row();
        }
    });
    distances_ui(ui, &v.before, &v.after);
}

/// The distances between the spheres, before and after (with the
/// reference where there is one).
fn distances_ui(ui: &mut egui::Ui, before: &ModelCheck, after: &ModelCheck) {
    if after.spacings.is_empty() {
        return;
    }
    ui.collapsing(
        format!("distances between spheres ({})", after.spacings.len()),
        |ui| {
            let headers = ["spheres", "before", "after", "reference"];
            table(ui, "measure_spacings", &headers, |ui| {
                let mm =
                    |v: Option<f64>| v.map_or_else(|| "–".to_string(), |v| format!("{v:.4} mm"));
                for s in &after.spacings {
                    let same = |x: &&Spacing| x.from == s.from && x.to == s.to;
                    ui.label(format!("{}–{}", s.from, s.to));
                    ui.label(mm(before.spacings.iter().find(same).map(|x| x.measured)));
                    ui.label(mm(Some(s.measured)));
                    ui.label(mm(s.reference));
                    ui.end_row();
                }
            });
        },
    );
}

/// The export on one line: a path (format by its extension), Write
/// and Save as… (a dialog); refused with the reason while the cloud is
/// stale; the files written of it below.
fn export_ui(ui: &mut egui::Ui, state: &AppState, forms: &mut Forms, commands: &mut Vec<Command>) {
    let stale = state.ledger.stale(Artefact::Cloud);
    ui.horizontal_wrapped(|ui| {
        ui.label(RichText::new("Export:").strong());
        let default = std::path::Path::new(forms.export_dir.trim())
            .join(super::default_cloud_name(state))
            .display()
            .to_string();
        labelled_field(ui, "Export to", &mut forms.measure.out, &default, 260.0)
            .on_hover_text(
                "PLY (binary: x y z double mm, sigma_mm float, pose), E57 (a scan per pose with its sensor pose) or CSV (id,x,y,z,sigma_mm), by the extension; written whole or not at all",
            );
        let busy = state.jobs.writing() || state.jobs.runs(&Slot::Dialog);
        let why = stale.as_ref().map_or_else(
            || "write the cloud on show to the typed file".to_string(),
            |s| format!("refused: {s}; measure again first"),
        );
        let export = Command::Measure(MeasureCommand::Export);
        command_button(ui, !busy, "Write cloud", &why, export, commands);
        let hover = "choose the file (.ply, .e57, .csv) in a dialog, then write it";
        let save_as = Command::Browse(Purpose::MeasureExport);
        command_button(ui, !busy, "Save as…", hover, save_as, commands);
        ui.label(RichText::new(".ply · .e57 · .csv").small().color(MUTED));
        crate::app::widgets::dialog_note_ui(ui, state, &[Purpose::MeasureExport]);
    });
    if let Some(s) = &stale {
        ui.label(
            RichText::new(format!("export refused: {s}"))
                .small()
                .color(WARN),
        );
    }
    crate::app::widgets::written_ui(ui, state, &[Artefact::Cloud]);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scale_runs_from_dark_blue_to_yellow() {
        assert_eq!(scale_colour(0.0), Color32::from_rgb(68, 1, 84));
        assert_eq!(scale_colour(1.0), Color32::from_rgb(253, 231, 37));
        assert_eq!(scale_colour(0.5), Color32::from_rgb(33, 145, 140));
        assert_eq!(scale_colour(f64::NAN), scale_colour(0.0));
        assert_eq!(scale_colour(7.0), scale_colour(1.0));
    }

    #[test]
    fn small_sigmas_are_shown_in_micrometres() {
        assert_eq!(sigma_unit(0.05), ("µm", 1000.0));
        assert_eq!(sigma_unit(0.1), ("mm", 1.0));
        assert_eq!(sigma_unit(2.0), ("mm", 1.0));
    }
}
