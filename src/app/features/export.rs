//! Export files of a result: the FORMAT.md result JSON, CSV of the centres
//! and of the distance errors, a PNG of the plots (cropped from a window
//! screenshot), the self-contained HTML report, and the calibrated model
//! (JSON robot block, MDH CSV, URDF fragment, as `spherecal
//! export-model`). Every file is written atomically by the engine's
//! [`write_atomic`], on a job thread.

use std::fmt::Write as _;
use std::path::Path;
use std::sync::Arc;
use std::time::{Instant, SystemTime};

use crate::engine::format::{result_text_checked, write_atomic};
use crate::engine::report::html::{self, ReportInput, ReportMeta};
use crate::engine::report::model::{self, ModelFormat};
use crate::engine::result_view::{self, Tolerance};

use super::Core;
use crate::app::error::JobError;
use crate::app::forms::Tab;
use crate::app::jobs::{ExportMessage, JobMessage};
use crate::app::state::{ExportKind, Level, LoadedSession};
use crate::app::view::{ResultOrigin, ResultView};

/// CSV of every sphere centre: sensor frame and base frame before and
/// after, mm.
#[must_use]
pub fn centres_csv(view: &ResultView) -> String {
    let mut s = String::from(
        "measurement,station,use,sensor_x_mm,sensor_y_mm,sensor_z_mm,before_x_mm,before_y_mm,before_z_mm,after_x_mm,after_y_mm,after_z_mm\n",
    );
    for c in &view.file.centres {
        let _ = write!(
            s,
            "{},{},{}",
            csv_field(&c.measurement),
            csv_field(&c.station),
            c.usage.as_str()
        );
        for v in c.sensor.iter().chain(&c.before).chain(&c.after) {
            let _ = write!(s, ",{v}");
        }
        s.push('\n');
    }
    s
}

/// CSV of the distance errors: the reference distances (paper Fig. 6,
/// `kind` = `reference`, error = measured − reference) and the
/// within-station centre distances (Fig. 5, `kind` = `within_station`,
/// reference 0), mm.
#[must_use]
pub fn distances_csv(view: &ResultView) -> String {
    let mut s = String::from(
        "kind,from,to,pose,reference_mm,before_mm,after_mm,error_before_mm,error_after_mm\n",
    );
    for d in &view.shown.distances {
        let _ = writeln!(
            s,
            "reference,{},{},{},{},{},{},{},{}",
            csv_field(&d.from),
            csv_field(&d.to),
            d.pose,
            d.reference,
            d.before,
            d.after,
            d.error_before(),
            d.error_after()
        );
    }
    for p in &view.shown.within {
        let _ = writeln!(
            s,
            "within_station,{},{},{}/{},0,{},{},{},{}",
            csv_field(&p.station),
            csv_field(&p.station),
            csv_field(&p.ids.0),
            csv_field(&p.ids.1),
            p.before,
            p.after,
            p.before,
            p.after
        );
    }
    s
}

/// Quotes a CSV field when it holds a comma, quote or line break.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Writes a text export of `view` to `path` atomically.
///
/// # Errors
/// The file cannot be written (the message names it), the model cannot be
/// exported, or `kind` is not a text export.
pub fn write_text(kind: ExportKind, view: &ResultView, path: &Path) -> Result<(), JobError> {
    let text = match kind {
        ExportKind::ResultJson => result_text_checked(&view.file, path)?,
        ExportKind::CentresCsv => centres_csv(view),
        ExportKind::DistancesCsv => distances_csv(view),
        ExportKind::PlotsPng => {
            return Err(JobError::Missing(
                "a PNG is written from a screenshot".to_string(),
            ));
        }
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

/// Writes the HTML report of `view` against its session atomically (the
/// engine's [`html::render`], as `spherecal report --result`), with the
/// stripe fits made when the session was loaded.
///
/// # Errors
/// The result is not of this session, or the file cannot be written.
pub fn write_report(
    view: &ResultView,
    loaded: &LoadedSession,
    tolerance: Tolerance,
    path: &Path,
) -> Result<(), JobError> {
    let session = &loaded.session;
    result_view::check_result(session, &view.file, None)?;
    let prepared = loaded.analysis.clone().prepared(session).ok();
    let meta = ReportMeta::new(loaded.source.label(), SystemTime::now());
    let html = html::render(&ReportInput {
        session,
        session_bytes: &loaded.bytes,
        result: &view.file,
        prepared: prepared.as_ref(),
        meta: &meta,
        tolerance: Some(tolerance),
    });
    Ok(write_atomic(path, html.as_bytes())?)
}

/// Crops `image` to `rect` (physical pixels: min x, min y, width, height)
/// and writes it as a PNG to `path` atomically.
///
/// # Errors
/// An empty crop, a PNG encoding error, or a write error.
pub fn write_png(image: &egui::ColorImage, rect: [usize; 4], path: &Path) -> Result<(), JobError> {
    let [w_img, h_img] = image.size;
    let x0 = rect[0].min(w_img);
    let y0 = rect[1].min(h_img);
    let w = rect[2].min(w_img - x0);
    let h = rect[3].min(h_img - y0);
    if w == 0 || h == 0 {
        return Err(JobError::Png(
            "the plots were not on screen: nothing to save".to_string(),
        ));
    }
    let mut rgba = Vec::with_capacity(w * h * 4);
    for y in y0..y0 + h {
        for px in &image.pixels[y * w_img + x0..y * w_img + x0 + w] {
            rgba.extend_from_slice(&px.to_array());
        }
    }
    let (Ok(wu), Ok(hu)) = (u32::try_from(w), u32::try_from(h)) else {
        return Err(JobError::Png("the screenshot is too large".to_string()));
    };
    let mut bytes = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut bytes),
        &rgba,
        wu,
        hu,
        image::ExtendedColorType::Rgba8,
    )
    .map_err(|e| JobError::Png(format!("could not encode the PNG: {e}")))?;
    Ok(write_atomic(path, &bytes)?)
}

impl Core {
    /// Writes one export of the result on show into the export folder.
    pub(super) fn export(&mut self, ctx: &egui::Context, kind: ExportKind) {
        let Some(view) = &self.state.result else {
            self.state.say(
                Level::Warning,
                "nothing to export: run the solver or open a result first",
            );
            return;
        };
        let view = view.clone();
        let Some(dir) = self.export_folder() else {
            return;
        };
        let stem = match &self.state.loaded {
            Some(l) => l.source.stem(),
            None => "result".to_string(),
        };
        let path = dir.join(kind.file_name(&stem));
        if kind == ExportKind::PlotsPng {
            if self.state.busy.screenshot {
                return;
            }
            self.forms.tab = Tab::Results;
            self.png_target = Some((path, Instant::now()));
            self.state.busy.screenshot = true;
            let rep = self.jobs.reporter(ctx);
            ctx.request_screenshot(move |image| {
                rep.send(JobMessage::Export(ExportMessage::Screenshot(image)));
            });
            self.state
                .say(Level::Info, "taking a screenshot of the plots…");
            return;
        }
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
        let tolerance = self.forms.tolerance;
        let started = self.spawn(ctx, "export", move |rep| {
            let outcome = match &loaded {
                Some(loaded) => write_report(&view, loaded, tolerance, &path),
                None => write_text(kind, &view, &path),
            };
            rep.send(JobMessage::Export(ExportMessage::Written {
                kind,
                path,
                outcome,
            }));
        });
        if started {
            self.state.busy.exporting += 1;
        }
    }

    /// Gives up on a window screenshot that never came (a backend that
    /// cannot take one), so that the export stays usable.
    pub fn screenshot_timeout(&mut self, ctx: &egui::Context) {
        let Some((_, since)) = &self.png_target else {
            return;
        };
        if since.elapsed() >= super::SCREENSHOT_TIMEOUT {
            self.png_target = None;
            self.state.busy.screenshot = false;
            self.state.say(
                Level::Warning,
                "no screenshot came from the window system: no PNG written",
            );
        } else {
            ctx.request_repaint_after(super::SCREENSHOT_TIMEOUT);
        }
    }

    /// Handles an [`ExportMessage`].
    pub(super) fn on_export(&mut self, ctx: &egui::Context, message: ExportMessage) {
        match message {
            ExportMessage::Screenshot(image) => self.on_screenshot(ctx, &image),
            ExportMessage::Written {
                kind,
                path,
                outcome,
            } => {
                self.state.busy.exporting = self.state.busy.exporting.saturating_sub(1);
                if kind == ExportKind::ReportHtml && outcome.is_ok() {
                    self.state.reported = Some(path.clone());
                }
                self.say_written(kind.label(), &path, outcome);
            }
        }
    }

    fn on_screenshot(&mut self, ctx: &egui::Context, image: &Arc<egui::ColorImage>) {
        self.state.busy.screenshot = false;
        let (Some((path, _)), Some(rect)) = (self.png_target.take(), self.plots_rect) else {
            self.state.say(
                Level::Warning,
                "the plots were not on screen: no PNG written",
            );
            return;
        };
        let ppp = ctx.pixels_per_point();
        let px = |v: f32| (v * ppp).round().max(0.0) as usize;
        let crop = [
            px(rect.min.x),
            px(rect.min.y),
            px(rect.width()),
            px(rect.height()),
        ];
        let image = Arc::clone(image);
        let started = self.spawn(ctx, "export", move |rep| {
            let outcome = write_png(&image, crop, &path);
            rep.send(JobMessage::Export(ExportMessage::Written {
                kind: ExportKind::PlotsPng,
                path,
                outcome,
            }));
        });
        if started {
            self.state.busy.exporting += 1;
        }
    }
}
