//! What a compensation reports: the summary line (targets, largest
//! correction, flagged), the table of targets, and the flagged ones with
//! why, as the command line prints them and the workbench will show them.

use std::fmt::Write as _;

use nalgebra::Isometry3;

use super::TargetReport;
use crate::engine::base::robot::controller::Controller;
use crate::engine::base::robot::controller::FlangeConvention;
use crate::engine::files::program::PoseFile;

/// Targets, largest correction, flagged.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Summary {
    /// Targets compensated (written).
    pub compensated: usize,
    /// Targets in all (joint targets kept included).
    pub targets: usize,
    /// Largest TCP position correction, mm, and its target.
    pub largest_mm: f64,
    /// The target with the largest correction.
    pub largest_at: String,
    /// Largest rotation correction, deg.
    pub largest_deg: f64,
    /// RMS of the position corrections, mm.
    pub rms_mm: f64,
    /// Largest predicted σ, mm (`ml` results).
    pub largest_sigma_mm: Option<f64>,
    /// Targets flagged outside what the calibration saw.
    pub flagged: usize,
    /// Targets whose configuration was updated.
    pub configurations_updated: usize,
}

impl Summary {
    /// The summary of `targets`.
    #[must_use]
    pub fn of(targets: &[TargetReport]) -> Self {
        let written: Vec<&TargetReport> = targets.iter().filter(|t| t.written).collect();
        let largest = written
            .iter()
            .max_by(|a, b| a.correction_mm.total_cmp(&b.correction_mm));
        let n = written.len().max(1) as f64;
        Self {
            compensated: written.len(),
            targets: targets.len(),
            largest_mm: largest.map_or(0.0, |t| t.correction_mm),
            largest_at: largest.map(|t| t.name.clone()).unwrap_or_default(),
            largest_deg: written.iter().map(|t| t.correction_deg).fold(0.0, f64::max),
            rms_mm: (written.iter().map(|t| t.correction_mm.powi(2)).sum::<f64>() / n).sqrt(),
            largest_sigma_mm: targets.iter().filter_map(|t| t.sigma_mm).reduce(f64::max),
            flagged: targets.iter().filter(|t| !t.flags.is_empty()).count(),
            configurations_updated: targets.iter().filter(|t| t.config_update.is_some()).count(),
        }
    }

    /// One line: "24 targets compensated: largest correction 6.832 mm
    /// (P[7]), 0.412°, rms 4.1 mm; 2 flagged; 1 configuration updated".
    #[must_use]
    pub fn line(&self) -> String {
        let kept = self.targets - self.compensated;
        let mut s = format!(
            "{} target{} compensated{}: largest correction {:.3} mm{}, {:.3}°, rms {:.3} mm",
            self.compensated,
            if self.compensated == 1 { "" } else { "s" },
            if kept > 0 {
                format!(
                    " ({kept} joint target{} kept)",
                    if kept == 1 { "" } else { "s" }
                )
            } else {
                String::new()
            },
            self.largest_mm,
            if self.largest_at.is_empty() {
                String::new()
            } else {
                format!(" ({})", self.largest_at)
            },
            self.largest_deg,
            self.rms_mm
        );
        if let Some(s_max) = self.largest_sigma_mm {
            let _ = write!(s, "; predicted σ up to {s_max:.3} mm");
        }
        let _ = write!(
            s,
            "; {} flagged outside what the calibration saw",
            self.flagged
        );
        if self.configurations_updated > 0 {
            let _ = write!(
                s,
                "; {} configuration{} updated",
                self.configurations_updated,
                if self.configurations_updated == 1 {
                    ""
                } else {
                    "s"
                }
            );
        }
        s
    }
}

/// The table of targets, largest correction first: name, line,
/// correction (mm, deg), largest joint change, σ, distance to the nearest
/// identify pose, flags. At most `limit` rows (all with `None`).
#[must_use]
pub fn table(targets: &[TargetReport], limit: Option<usize>) -> String {
    let rows = largest_first(targets);
    let shown = limit.unwrap_or(rows.len()).min(rows.len());
    let mut s = String::new();
    let _ = writeln!(
        s,
        "  {:<14} {:>6} {:>10} {:>9} {:>9} {:>9} {:>9}  flags",
        "target", "line", "corr. mm", "corr. °", "Δq max °", "σ mm", "near. °"
    );
    for t in &rows[..shown] {
        let _ = writeln!(
            s,
            "  {:<14} {:>6} {:>10.4} {:>9.4} {:>9.4} {:>9} {:>9}  {}",
            clip(&t.name, 14),
            t.line,
            t.correction_mm,
            t.correction_deg,
            t.joint_change_deg,
            t.sigma_mm
                .map_or_else(|| "-".to_string(), |v| format!("{v:.4}")),
            t.nearest_identify_deg
                .map_or_else(|| "-".to_string(), |v| format!("{v:.1}")),
            if t.flags.is_empty() {
                if t.written { "" } else { "kept" }
            } else {
                "FLAGGED"
            }
        );
    }
    if shown < rows.len() {
        let _ = writeln!(
            s,
            "  … {} more (--all lists every target)",
            rows.len() - shown
        );
    }
    s
}

/// The flagged targets, one line each with why; empty when none.
#[must_use]
pub fn flagged(targets: &[TargetReport]) -> String {
    let mut s = String::new();
    for t in targets.iter().filter(|t| !t.flags.is_empty()) {
        let why: Vec<String> = t.flags.iter().map(super::Flag::describe).collect();
        let _ = writeln!(
            s,
            "  {} (line {}): {}; compensated by {:.3} mm",
            t.name,
            t.line,
            why.join("; "),
            t.correction_mm
        );
    }
    s
}

/// What the targets file is and how it was read, one line: "pose table
/// T.csv: 8 poses in the order written (layout detected)".
#[must_use]
pub fn file_line(file: &PoseFile) -> String {
    format!(
        "{} {}: {} ({})",
        file.format.describe(),
        file.path.display(),
        file.order_note,
        if file.detected {
            "layout detected"
        } else {
            "layout given"
        }
    )
}

/// The controllers whose tool data to show for `file`: its language's,
/// else the one of the `convention` given for a table, else all four
/// (a matrix table).
#[must_use]
pub fn tool_controllers(file: &PoseFile, convention: Option<FlangeConvention>) -> Vec<Controller> {
    match file.format.convention().or(convention).map(Controller::of) {
        Some(Some(c)) => vec![c],
        _ => Controller::ALL.to_vec(),
    }
}

/// The targets, largest position correction first (the order of the
/// command line's table and the workbench's).
#[must_use]
pub fn largest_first(targets: &[TargetReport]) -> Vec<&TargetReport> {
    let mut rows: Vec<&TargetReport> = targets.iter().collect();
    rows.sort_by(|a, b| b.correction_mm.total_cmp(&a.correction_mm));
    rows
}

/// Name of the tool in the tool data (RAPID's `tooldata` name).
pub const TOOL_NAME: &str = "tSpherecal";

/// The tool data to set on the controller for the TCP `flange_from_tcp`
/// ([`TOOL_NAME`]), for each controller of [`tool_controllers`]: the kind
/// of data and its text.
#[must_use]
pub fn tool_data(
    file: &PoseFile,
    convention: Option<FlangeConvention>,
    flange_from_tcp: &Isometry3<f64>,
) -> Vec<(&'static str, String)> {
    tool_controllers(file, convention)
        .into_iter()
        .map(|c| (c.tool_data_kind(), c.tool_data(flange_from_tcp, TOOL_NAME)))
        .collect()
}

/// `name` cut to `n` characters with `…`.
fn clip(name: &str, n: usize) -> String {
    if name.chars().count() <= n {
        name.to_string()
    } else {
        let mut s: String = name.chars().take(n - 1).collect();
        s.push('…');
        s
    }
}
