//! Export files of a result: the FORMAT.md result JSON, CSV of the centres
//! and of the distance errors, a PNG of the plots (cropped from a window
//! screenshot), the self-contained HTML report, and the calibrated model (JSON robot block, MDH CSV, URDF
//! fragment, as `spherecal export-model`). Every file is written atomically by the engine's
//! [`write_atomic`]. Runs on a job thread.

use std::fmt::Write as _;
use std::path::Path;
use std::time::SystemTime;

use crate::engine::format::{result_to_json, write_atomic};
use crate::engine::report::html::{self, ReportInput, ReportMeta};
use crate::engine::report::model::{self, ModelFormat};
use crate::engine::result_view;

use super::state::{ExportKind, LoadedSession};
use super::view::{ResultOrigin, ResultView};

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
/// The file cannot be written (the message names it), or `kind` is not a
/// text export.
pub fn write_text(kind: ExportKind, view: &ResultView, path: &Path) -> Result<(), String> {
    let text = match kind {
        ExportKind::ResultJson => result_to_json(&view.file),
        ExportKind::CentresCsv => centres_csv(view),
        ExportKind::DistancesCsv => distances_csv(view),
        ExportKind::PlotsPng => return Err("a PNG is written from a screenshot".to_string()),
        ExportKind::ReportHtml => return Err("a report needs its session".to_string()),
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
            model::export(&view.file, format, &source)
                .map_err(|e| format!("the model cannot be exported: {e}"))?
        }
    };
    write_atomic(path, text.as_bytes()).map_err(|e| e.to_string())
}

/// Writes the HTML report of `view` against its session atomically (the
/// engine's [`html::render`], as `spherecal report --result`), with the
/// stripe fits made when the session was loaded.
///
/// # Errors
/// The result is not of this session, or the file cannot be written.
pub fn write_report(view: &ResultView, loaded: &LoadedSession, path: &Path) -> Result<(), String> {
    let session = &loaded.session;
    result_view::check_result(session, &view.file, None)
        .map_err(|e| format!("the report was not written: {e}"))?;
    let prepared = loaded.analysis.clone().prepared(session).ok();
    let meta = ReportMeta::new(loaded.source.label(), SystemTime::now());
    let html = html::render(&ReportInput {
        session,
        session_bytes: &loaded.bytes,
        result: &view.file,
        prepared: prepared.as_ref(),
        meta: &meta,
    });
    write_atomic(path, html.as_bytes()).map_err(|e| e.to_string())
}

/// Crops `image` to `rect` (physical pixels: min x, min y, width, height)
/// and writes it as a PNG to `path` atomically.
///
/// # Errors
/// An empty crop, a PNG encoding error, or a write error.
pub fn write_png(image: &egui::ColorImage, rect: [usize; 4], path: &Path) -> Result<(), String> {
    let [w_img, h_img] = image.size;
    let x0 = rect[0].min(w_img);
    let y0 = rect[1].min(h_img);
    let w = rect[2].min(w_img - x0);
    let h = rect[3].min(h_img - y0);
    if w == 0 || h == 0 {
        return Err("the plots were not on screen: nothing to save".to_string());
    }
    let mut rgba = Vec::with_capacity(w * h * 4);
    for y in y0..y0 + h {
        for px in &image.pixels[y * w_img + x0..y * w_img + x0 + w] {
            rgba.extend_from_slice(&px.to_array());
        }
    }
    let (Ok(wu), Ok(hu)) = (u32::try_from(w), u32::try_from(h)) else {
        return Err("the screenshot is too large".to_string());
    };
    let mut bytes = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut bytes),
        &rgba,
        wu,
        hu,
        image::ExtendedColorType::Rgba8,
    )
    .map_err(|e| format!("could not encode the PNG: {e}"))?;
    write_atomic(path, &bytes).map_err(|e| e.to_string())
}
