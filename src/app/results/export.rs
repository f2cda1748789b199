//! Export files of a result: the FORMAT.md result JSON, CSV of the centres
//! and of the distance errors, a PNG of the plots (the engine's plot sheet
//! drawn off-screen on white, whole whatever is on screen), the
//! self-contained HTML report, and the calibrated model
//! (JSON robot block, MDH CSV, URDF fragment, as `spherecal
//! export-model`), and the files for the controller and the planner
//! ([`UseExport`]: tool data for every controller, the robot's own URDF
//! back calibrated, UR's calibration YAML). Every file is written atomically by the engine's
//! [`write_atomic`], on a job thread.

use std::path::Path;
use std::sync::Arc;
use std::time::SystemTime;

use crate::engine::base::session::Session;
use crate::engine::calibrate::solve::Analysis;
use crate::engine::files::format::{Cap, ResultFile, read_text, result_text_checked, write_atomic};
use crate::engine::tools::report::html::{self, ReportInput, ReportMeta};
use crate::engine::tools::report::model::{self, ModelFormat};
use crate::engine::tools::report::sheet::{self, SheetInput};
use crate::engine::tools::report::tables;
use crate::engine::tools::report::tool_data::{self, ToolTarget};
use crate::engine::tools::report::{ur_calibration, urdf_back};
use crate::engine::tools::result_view::{self, Tolerance};

use crate::app::command::Command;
use crate::app::command::ExportKind;
use crate::app::command::UseExport;
use crate::app::error::JobError;
use crate::app::ledger::Artefact;
use crate::app::results::{ResultOrigin, ResultView};
use crate::app::state::Level;
use crate::app::{Core, Write};

/// Writes a text export of `view` to `path` atomically.
///
/// # Errors
/// The file cannot be written (the message names it), the model cannot be
/// exported, or `kind` is not a text export.
pub fn write_text(kind: ExportKind, view: &ResultView, path: &Path) -> Result<(), JobError> {
    let text = match kind {
        ExportKind::ResultJson => result_text_checked(&view.file, path)?,
        ExportKind::CentresCsv => tables::centres_csv(&view.file),
        ExportKind::DistancesCsv => tables::distances_csv(&view.shown),
        ExportKind::PlotsPng => return write_plots_png(view, path),
        ExportKind::ReportHtml => {
            return Err(JobError::Missing("a report needs its session".to_string()));
        }
        ExportKind::ModelJson | ExportKind::ModelCsv | ExportKind::ModelUrdf => {
            let format = match kind {
                ExportKind::ModelJson => ModelFormat::Json,
                ExportKind::ModelCsv => ModelFormat::Csv,
                _ => ModelFormat::Urdf,
            };
            let source = match &view.origin {
                ResultOrigin::Review(p) => p.display().to_string(),
                ResultOrigin::Run { .. } => format!("a workbench run of {}", view.file.session),
            };
            model::export(&view.file, format, &source)?
        }
    };
    Ok(write_atomic(path, text.as_bytes())?)
}

/// The session a report is written against: the session, its file's
/// bytes (for the SHA-256), the stripe fits made when it was loaded, and
/// where it came from, in words.
pub struct ReportSession<'a> {
    /// The session.
    pub session: &'a Session,
    /// Its file's bytes.
    pub bytes: &'a [u8],
    /// Its stripe fits.
    pub analysis: &'a Analysis,
    /// Where it came from.
    pub source: String,
}

/// Writes the HTML report of `view` against its session atomically (the
/// engine's [`html::render`], as `spherecal report --result`), with the
/// stripe fits made when the session was loaded.
///
/// # Errors
/// The result is not of this session, or the file cannot be written.
pub fn write_report(
    view: &ResultView,
    of: &ReportSession<'_>,
    tolerance: Tolerance,
    path: &Path,
) -> Result<(), JobError> {
    let session = of.session;
    result_view::check_result(session, &view.file, None)?;
    let prepared = of.analysis.clone().prepared(session).ok();
    let meta = ReportMeta::new(of.source.clone(), SystemTime::now());
    let html = html::render(&ReportInput {
        session,
        session_bytes: of.bytes,
        result: &view.file,
        prepared: prepared.as_ref(),
        meta: &meta,
        tolerance: Some(tolerance),
    });
    Ok(write_atomic(path, html.as_bytes())?)
}

/// Pixels per sheet px of the plots PNG: 2 prints a 968 px wide sheet
/// sharp at about 16 cm (300 dpi) and reads well on screen.
pub const PNG_SCALE: f32 = 2.0;

/// The plot sheet of `view` ([`sheet::plots_sheet`]): its title is the
/// session and method, the lines under it the headline figures and ε.
#[must_use]
pub fn plots_sheet(view: &ResultView) -> sheet::Sheet {
    let title = format!("{} · method {}", view.file.session, view.method);
    // Words rather than arrows: the built-in proportional font has no →.
    let mut lines = Vec::new();
    if let Some(h) = &view.shown.headline {
        let (b, a) = (h.stats.before, h.stats.after);
        lines.push(h.what.clone());
        lines.push(format!(
            "std {:.3} mm before, {:.3} mm after · max {:.3} mm before, {:.3} mm after",
            b.std, a.std, b.max, a.max
        ));
    }
    lines.push(format!(
        "ε {:.4} mm before, {:.4} mm after",
        view.file.epsilon_before, view.file.epsilon_after
    ));
    sheet::plots_sheet(&SheetInput {
        title: &title,
        lines: &lines,
        within: &view.shown.within,
        within_of: view.shown.within_of.as_str(),
        distances: &view.shown.distances,
        epsilons: &view.epsilons,
        threshold: view.threshold,
        singular_values: &view.singular_values,
        kept: view.kept,
        svd_tolerance: view.svd_tolerance,
    })
}

/// The fonts the sheet's text is drawn in: egui's own (built into the
/// program), so that the PNG looks the same on every machine; the
/// proportional one is the SVG's `sans-serif`.
fn sheet_fonts() -> resvg::usvg::fontdb::Database {
    let mut db = resvg::usvg::fontdb::Database::new();
    let defs = egui::FontDefinitions::default();
    let proportional = defs
        .families
        .get(&egui::FontFamily::Proportional)
        .and_then(|f| f.first())
        .cloned();
    let mut sans = None;
    for (name, data) in &defs.font_data {
        let before = db.len();
        db.load_font_data(data.font.as_ref().as_ref().to_vec());
        if Some(name) == proportional.as_ref() {
            sans = db
                .faces()
                .skip(before)
                .find_map(|f| f.families.first().map(|(family, _)| family.clone()));
        }
    }
    if let Some(family) = sans {
        db.set_sans_serif_family(family);
    }
    db
}

/// The plot sheet of `view` as PNG bytes, [`PNG_SCALE`] pixels per px,
/// on white.
///
/// # Errors
/// The sheet does not parse or is too large to draw (a bug), or the PNG
/// cannot be encoded.
pub fn plots_png(view: &ResultView) -> Result<Vec<u8>, JobError> {
    use resvg::{tiny_skia, usvg};
    let sheet = plots_sheet(view);
    let fontdb = sheet_fonts();
    let options = usvg::Options {
        font_family: "sans-serif".to_string(),
        fontdb: Arc::new(fontdb),
        ..usvg::Options::default()
    };
    let tree = usvg::Tree::from_str(&sheet.svg, &options)
        .map_err(|e| JobError::Png(format!("the plot sheet does not parse: {e}")))?;
    let size = tree.size();
    let (w, h) = (
        (size.width() * PNG_SCALE).ceil() as u32,
        (size.height() * PNG_SCALE).ceil() as u32,
    );
    let mut pixmap = tiny_skia::Pixmap::new(w, h)
        .ok_or_else(|| JobError::Png(format!("cannot draw a {w} × {h} image")))?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(
        &tree,
        tiny_skia::Transform::from_scale(PNG_SCALE, PNG_SCALE),
        &mut pixmap.as_mut(),
    );
    pixmap
        .encode_png()
        .map_err(|e| JobError::Png(format!("could not encode the PNG: {e}")))
}

/// Writes the plots PNG of `view` ([`plots_png`]) to `path` atomically.
///
/// # Errors
/// As [`plots_png`], or the file cannot be written.
pub fn write_plots_png(view: &ResultView, path: &Path) -> Result<(), JobError> {
    let bytes = plots_png(view)?;
    Ok(write_atomic(path, &bytes)?)
}

impl Core {
    /// Writes one export of the result on show into the export folder.
    pub(in crate::app) fn export(&mut self, ctx: &egui::Context, kind: ExportKind) {
        let Some(view) = &self.state.result else {
            self.state.say(
                Level::Warning,
                "nothing to export: run the solver or open a result first",
            );
            return;
        };
        // A stale result is never written as if it were current.
        let stamp = match self.state.ledger.check(Artefact::Result) {
            Ok(stamp) => stamp,
            Err(why) => {
                let title = format!("{} not written", kind.label());
                let why = format!("{why}: run the calibration again, then export");
                self.refuse(&title, &title, why);
                return;
            }
        };
        let view = view.clone();
        // The report judges by the tolerance: made from the result and it.
        let (from, stamp) = if kind == ExportKind::ReportHtml {
            (Artefact::Report, self.state.ledger.stamp(Artefact::Report))
        } else {
            (Artefact::Result, stamp)
        };
        let loaded = if kind == ExportKind::ReportHtml {
            let Some(loaded) = &self.state.loaded else {
                self.state
                    .say(Level::Warning, "a report needs the session: open it first");
                return;
            };
            Some(loaded.clone())
        } else {
            None
        };
        let Some(dir) = self.export_folder() else {
            return;
        };
        let stem = self
            .state
            .loaded
            .as_ref()
            .map_or_else(|| "result".to_string(), |l| l.source.stem());
        let path = dir.join(kind.file_name(&stem));
        let tolerance = self.forms.tolerance;
        let write = Write {
            what: kind.label().to_string(),
            from,
            stamp,
            again: Command::Export(kind),
        };
        self.write(ctx, path, write, move |path| {
            match &loaded {
                Some(l) => {
                    let of = ReportSession {
                        session: &l.session,
                        bytes: &l.bytes,
                        analysis: &l.analysis,
                        source: l.source.label(),
                    };
                    write_report(&view, &of, tolerance, path)
                }
                None => write_text(kind, &view, path),
            }
            .map(|()| None)
        });
    }
}

/// Why `kind` cannot be written of `view` (`urdf`: the source URDF's
/// path field), or `None`.
#[must_use]
pub fn unavailable(kind: UseExport, view: &ResultView, urdf: &str) -> Option<String> {
    let robot = view.file.robot.as_ref();
    match kind {
        UseExport::Tool(_) => None,
        UseExport::UrdfBack if robot.is_none() => {
            Some("the result has no robot to write back".to_string())
        }
        UseExport::UrdfBack if urdf.trim().is_empty() => Some(
            "type the path of the URDF the session's robot came from (its joint origins are calibrated, every other byte kept)"
                .to_string(),
        ),
        UseExport::UrCalibration => match robot {
            Some(r) if ur_calibration::is_ur(r) => None,
            Some(r) => Some(format!("{} is not a Universal Robots arm", r.name)),
            None => Some("the result has no robot".to_string()),
        },
        UseExport::UrdfBack => None,
    }
}

/// The text of `kind` of `result` (from `source`, in words) by the
/// engine's exporters, with what to know about it.
///
/// # Errors
/// What the engine refuses (naming the URDF), or a URDF that cannot be read.
pub fn use_export_text(
    kind: UseExport,
    result: &ResultFile,
    source: &str,
    urdf: &Path,
) -> Result<String, JobError> {
    let fail = |e: &dyn std::fmt::Display| JobError::Missing(format!("{e} ({source})"));
    match kind {
        UseExport::Tool(target) => Ok(tool_data::tool_export(result, target, source)),
        UseExport::UrCalibration => {
            ur_calibration::ur_calibration(result, source, false).map_err(|e| fail(&e))
        }
        UseExport::UrdfBack => {
            let text = read_text(urdf, Cap::URDF).map_err(|e| JobError::Path {
                what: format!("the robot's URDF cannot be read: {e}"),
                path: urdf.to_path_buf(),
            })?;
            let done =
                urdf_back::calibrated_urdf(result, &text, urdf, None).map_err(|e| fail(&e))?;
            Ok(done.text)
        }
    }
}

/// The row of the files for the controller and the planner: tool data
/// for every controller, the URDF back (with its source's path), UR's
/// calibration; each disabled with why.
pub fn use_exports_ui(
    ui: &mut egui::Ui,
    view: &ResultView,
    forms: &mut crate::app::Forms,
    stale: bool,
    commands: &mut Vec<Command>,
) {
    use crate::app::widgets::{command_button, labelled_field};
    ui.horizontal_wrapped(|ui| {
        ui.label("For the controller:");
        let kinds = ToolTarget::ALL.map(UseExport::Tool);
        for kind in kinds.into_iter().chain([UseExport::UrCalibration]) {
            let why = unavailable(kind, view, &forms.urdf_source);
            let hover = match (&why, stale) {
                (_, true) => "refused: the result is stale; run again, then export",
                (Some(w), _) => w.as_str(),
                (None, _) => "the calibrated hand-eye (and model) in the controller's own syntax, with its 1σ",
            };
            let enabled = why.is_none() && !stale;
            command_button(ui, enabled, kind.label(), hover, Command::UseExport(kind), commands);
        }
    });
    if view.file.robot.is_some() {
        ui.horizontal_wrapped(|ui| {
            let hint = "the robot's URDF (.urdf), for URDF back";
            labelled_field(ui, "Robot's URDF", &mut forms.urdf_source, hint, 300.0);
            let browse = Command::Browse(crate::app::dialog::Purpose::UrdfSource);
            command_button(ui, true, "Browse…", "choose the URDF", browse, commands);
            let kind = UseExport::UrdfBack;
            let why = unavailable(kind, view, &forms.urdf_source);
            let hover = why.as_deref().unwrap_or(
                "that file with only the calibrated joint origins changed and a sensor link added",
            );
            let enabled = why.is_none() && !stale;
            command_button(
                ui,
                enabled,
                kind.label(),
                hover,
                Command::UseExport(kind),
                commands,
            );
        });
    }
}

impl Core {
    /// Writes a file of the result on show for the controller or the
    /// planner into the export folder: refused while the result is stale.
    pub(in crate::app) fn use_export(&mut self, ctx: &egui::Context, kind: UseExport) {
        let Some(view) = &self.state.result else {
            self.state.say(
                Level::Warning,
                "nothing to export: run the solver or open a result first",
            );
            return;
        };
        let title = format!("{} not written", kind.label());
        if let Some(why) = unavailable(kind, view, &self.forms.urdf_source) {
            self.refuse(&title, &title, why);
            return;
        }
        let stamp = match self.state.ledger.check(Artefact::Result) {
            Ok(stamp) => stamp,
            Err(why) => {
                self.refuse(
                    &title,
                    &title,
                    format!("{why}: run the calibration again, then export"),
                );
                return;
            }
        };
        let result = view.file.clone();
        let source = match &view.origin {
            ResultOrigin::Review(p) => p.display().to_string(),
            ResultOrigin::Run { .. } => format!("a workbench run of {}", view.file.session),
        };
        let Some(dir) = self.export_folder() else {
            return;
        };
        let stem = self
            .state
            .loaded
            .as_ref()
            .map_or_else(|| "result".to_string(), |l| l.source.stem());
        let path = dir.join(kind.file_name(&stem));
        let urdf = std::path::PathBuf::from(self.forms.urdf_source.trim());
        let write = Write {
            what: kind.label(),
            from: Artefact::Result,
            stamp,
            again: Command::UseExport(kind),
        };
        self.write(ctx, path, write, move |path| {
            crate::engine::files::format::refuse_inputs(path, &[urdf.as_path()])?;
            let text = use_export_text(kind, &result, &source, &urdf)?;
            write_atomic(path, text.as_bytes())?;
            Ok(None)
        });
    }
}
