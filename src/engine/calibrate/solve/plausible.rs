//! Whether a finished calibration is one at all: the scatter of the
//! identify centres about their station means after calibration against
//! what any sensor and robot can give. A pose log read in the wrong
//! convention (a FANUC log read as KUKA), joint readings in the wrong unit
//! or the wrong side of the laser plane still "converge" — the loop stops,
//! the variance factor is near 1 — but the centres of one sphere position
//! then lie tens of millimetres apart: a failed calibration, not a result.

use nalgebra::Vector3;

use super::Calibration;
use crate::engine::base::numeric::approx;
use crate::engine::base::session::{Session, Use};
use crate::engine::calibrate::validate::scatter_rms;

/// Largest plausible 3-D rms scatter of the identify centres about their
/// station means after calibration, mm. A laser-stripe sensor measures a
/// sphere centre to hundredths of a millimetre and an industrial robot's
/// uncalibrated accuracy is a few millimetres, so a calibrated cell (or a
/// pose-only one, judged by the controller's own poses) scatters well
/// below 5 mm; 10 mm is beyond any real cell and far below the scatter of
/// a wrong unit or pose convention (20 to 100 mm in practice).
pub const MAX_PLAUSIBLE_SCATTER_MM: f64 = 10.0;

/// A calibration whose centres scatter beyond
/// [`MAX_PLAUSIBLE_SCATTER_MM`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "the calibration failed: after it the identify centres still scatter by {} mm (3-D rms about each station's mean), beyond what any sensor and robot give (at most {} mm); likely causes: {causes}",
    approx(*scatter_mm),
    MAX_PLAUSIBLE_SCATTER_MM
)]
pub struct ImplausibleScatter {
    /// The scatter found, mm.
    pub scatter_mm: f64,
    /// What most likely went wrong, for the message.
    pub causes: &'static str,
}

/// The 3-D rms scatter of the identify centres about their station means,
/// before and after calibration, mm ([`scatter_rms`]).
#[must_use]
pub fn identify_scatter(session: &Session, cal: &Calibration) -> (f64, f64) {
    let stations = session.stations(Use::Identify);
    // Measurement index → its centre: linear in the measurements.
    let by_index: std::collections::HashMap<usize, &_> =
        cal.centres.iter().map(|c| (c.index, c)).collect();
    let group = |after: bool| -> Vec<Vec<Vector3<f64>>> {
        stations
            .iter()
            .map(|(_, idx)| {
                idx.iter()
                    .filter_map(|&i| by_index.get(&i).copied())
                    .map(|c| if after { c.after } else { c.before })
                    .collect()
            })
            .collect()
    };
    (scatter_rms(&group(false)), scatter_rms(&group(true)))
}

/// The verdict on a scatter of `scatter_mm` (3-D rms of sphere centres
/// about their station means, mm) of a session that is `pose_only` or not;
/// also for a scatter found before calibrating (an import's check of its
/// pose convention).
///
/// # Errors
/// [`ImplausibleScatter`] beyond [`MAX_PLAUSIBLE_SCATTER_MM`] (or not
/// finite), naming the likely causes.
pub fn check_scatter(scatter_mm: f64, pose_only: bool) -> Result<(), ImplausibleScatter> {
    if scatter_mm.is_finite() && scatter_mm <= MAX_PLAUSIBLE_SCATTER_MM {
        return Ok(());
    }
    Err(ImplausibleScatter {
        scatter_mm,
        causes: if pose_only {
            "flange poses read in the wrong convention (import with another --pose-convention, e.g. fanuc, kuka or abb), in the wrong unit, or the sphere on the other side of the laser plane (--side)"
        } else {
            "joint readings in the wrong unit (--joint-unit) or order, the wrong robot model, or the sphere on the other side of the laser plane (the session's side)"
        },
    })
}

/// [`check_scatter`] of a finished calibration of `session`.
///
/// # Errors
/// As [`check_scatter`].
pub fn check_calibration(session: &Session, cal: &Calibration) -> Result<(), ImplausibleScatter> {
    check_scatter(identify_scatter(session, cal).1, session.pose_only())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scatter_beyond_any_sensor_is_a_failure() {
        assert!(check_scatter(0.2, false).is_ok());
        assert!(check_scatter(MAX_PLAUSIBLE_SCATTER_MM, true).is_ok());
        let e = check_scatter(75.0, true).unwrap_err().to_string();
        assert!(
            e.contains("scatter by 75 mm") && e.contains("--pose-convention"),
            "{e}"
        );
        let e = check_scatter(f64::NAN, false).unwrap_err().to_string();
        assert!(e.contains("--joint-unit"), "{e}");
    }
}
