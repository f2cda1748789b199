//! Export files of a result: the FORMAT.md result JSON, CSV of the centres
//! and of the distance errors, a PNG of the plots (the engine's plot sheet
//! drawn off-screen on white, whole whatever is on screen), the
//! self-contained HTML report, and the calibrated model
//! (JSON robot block, MDH CSV, URDF fragment, as `spherecal
//! export-model`), and the files for the controller and the planner
//! ([`UseExport`]: tool data for every controller, the robot's own URDF
//! back calibrated, UR's calibration YAML). Every file is written atomically by the engine's
//! [`write_atomic`], on a job thread.

use std::path::{Path, PathBuf};
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
use crate::app::ledger::{Artefact, Stamp};
use crate::app::results::ResultView;
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
        ExportKind::PlotsPng => return Ok(write_atomic(path, &plots_png(view)?)?),
        ExportKind::ReportHtml => {
            return Err(JobError::Missing("a report needs its session".to_string()));
        }
        ExportKind::ModelJson | ExportKind::ModelCsv | ExportKind::ModelUrdf => {
            let format = match kind {
                ExportKind::ModelJson => ModelFormat::Json,
                ExportKind::ModelCsv => ModelFormat::Csv,
                _ => ModelFormat::Urdf,
            };
            model::export(&view.file, format, &view.source())?
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
    let title = format!("{} · method {}", view.file.session, view.method());
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
    let paper = view.file.solver.paper();
    sheet::plots_sheet(&SheetInput {
        title: &title,
        lines: &lines,
        within: &view.shown.within,
        within_of: view.shown.within_of.as_str(),
        distances: &view.shown.distances,
        epsilons: &view.epsilons(),
        threshold: view.file.solver.threshold(),
        singular_values: paper
            .and_then(|p| p.singular_values.as_deref())
            .unwrap_or_default(),
        kept: paper.and_then(|p| p.kept_directions),
        svd_tolerance: paper.and_then(|p| p.svd_tolerance),
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

impl Core {
    /// The result on show, what it was made from and the path of
    /// `file_name(stem)` in the export folder, to write `label` of it; `None`
    /// (saying why) without a result, when `unavailable` says why not,
    /// while the result is stale (it is never written as if it were
    /// current), or without the folder.
    fn export_target(
        &mut self,
        label: &str,
        unavailable: impl FnOnce(&ResultView) -> Option<String>,
        file_name: impl FnOnce(&str) -> String,
    ) -> Option<(ResultView, Stamp, PathBuf)> {
        let Some(view) = &self.state.result else {
            let text = "nothing to export: run the solver or open a result first";
            self.state.say(Level::Warning, text);
            return None;
        };
        let title = format!("{label} not written");
        let why = unavailable(view).map_or_else(
            || {
                self.state
                    .ledger
                    .check(Artefact::Result)
                    .map_err(|why| format!("{why}: run the calibration again, then export"))
            },
            Err,
        );
        let view = view.clone();
        let stamp = why.map_err(|why| self.refuse(&title, &title, why)).ok()?;
        let dir = self.export_folder()?;
        let loaded = self.state.loaded.as_ref();
        let stem = loaded.map_or_else(|| "result".to_string(), |l| l.source.stem());
        Some((view, stamp, dir.join(file_name(&stem))))
    }

    /// Writes one export of the result on show into the export folder.
    pub(in crate::app) fn export(&mut self, ctx: &egui::Context, kind: ExportKind) {
        let report = kind == ExportKind::ReportHtml;
        if report && self.state.result.is_some() && self.state.loaded.is_none() {
            let text = "a report needs the session: open it first";
            return self.state.say(Level::Warning, text);
        }
        let target = self.export_target(kind.label(), |_| None, |stem| kind.file_name(stem));
        let Some((view, stamp, path)) = target else {
            return;
        };
        // The report judges by the tolerance: made from the result and it.
        let (from, stamp) = if report {
            (Artefact::Report, self.state.ledger.stamp(Artefact::Report))
        } else {
            (Artefact::Result, stamp)
        };
        let loaded = self.state.loaded.clone().filter(|_| report);
        let tolerance = self.forms.tolerance;
        let what = kind.label().to_string();
        let again = Command::Export(kind);
        let write = Write {
            what,
            from,
            stamp,
            again,
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
        let urdf = self.forms.urdf_source.clone();
        let unavailable = |view: &ResultView| unavailable(kind, view, &urdf);
        let target = self.export_target(&kind.label(), unavailable, |stem| kind.file_name(stem));
        let Some((view, stamp, path)) = target else {
            return;
        };
        let source = view.source();
        let urdf = PathBuf::from(urdf.trim());
        let what = kind.label();
        let again = Command::UseExport(kind);
        let write = Write {
            what,
            from: Artefact::Result,
            stamp,
            again,
        };
        self.write(ctx, path, write, move |path| {
            crate::engine::files::format::refuse_inputs(path, &[urdf.as_path()])?;
            let text = use_export_text(kind, &view.file, &source, &urdf)?;
            write_atomic(path, text.as_bytes())?;
            Ok(None)
        });
    }
}
