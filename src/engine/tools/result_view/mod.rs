//! What every reader shows of a result, computed once from the typed
//! [`ResultFile`]: the headline figures, the within-station centre
//! distances (paper Fig. 5) with their pairs, the hand-eye as translation
//! and roll/pitch/yaw, each parameter's σ, which parameters the data
//! could not identify, the held-out figure beside the fit's own scatter,
//! and the warnings about the run (the paper's loop making ε worse). The workbench, the HTML report, history and the
//! planner read these; none of them looks into the solver block itself.
//! Also here: whether a result belongs to a session, and how well a
//! hand-eye-only result determined the hand-eye ([`strength`]), and the
//! PASS/FAIL verdict against an acceptance tolerance ([`verdict`]); the
//! centres by station and the sets of errors before and after ([`sets`]).

pub mod sets;
pub mod strength;
pub mod verdict;

use std::collections::{BTreeMap, HashMap, HashSet};

use nalgebra::{Isometry3, Vector3};

use crate::engine::base::geometry::roll_pitch_yaw_deg;
use crate::engine::base::session::{Session, Use};
use crate::engine::calibrate::solve::{HeldOut, Prepared, SolverReport};
use crate::engine::calibrate::validate::{
    BeforeAfter, DistanceRecord, Stats, scatter_rms, within_station_distances,
};
use crate::engine::files::format::result::{CentreRecord, ResultFile};
pub use sets::{CALIBRATION_SET, CentrePoint, CentreSet, ErrorSet, Summary, VALIDATION_SET};
pub use strength::{HAND_EYE_ONLY, HandEyeStrength, flange_poses, hand_eye_only_lines};
pub use verdict::{Tolerance, Verdict};

/// A dropped SVD direction marks a parameter as not identifiable when its
/// coefficient in the (unit) direction is at least this large: about a
/// tenth of the direction's energy (0.3² ≈ 0.09). The workbench uses the
/// same value.
pub const MARK_COEFFICIENT: f64 = 0.3;

/// A sensor-frame centre in the result may differ from the one recomputed
/// from the session by this much (mm) and still count as the same data:
/// the result file holds the shortest round-tripping decimal, so the
/// recomputed fit agrees to far below this.
pub const CENTRE_MATCH_MM: f64 = 1e-6;

/// Why a result cannot be reported against a session.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReportError {
    /// The result names another session.
    #[error("the result is of session \"{result}\", not of session \"{session}\"")]
    OtherSession {
        /// `session` of the result.
        result: String,
        /// `name` of the session.
        session: String,
    },
    /// A result centre has no measurement of that id in the session.
    #[error("measurement {id} of the result is not in the session")]
    UnknownMeasurement {
        /// Measurement id.
        id: String,
    },
    /// A measurement's station or use differs between result and session.
    #[error("measurement {id}: {what} differs between the result and the session")]
    Differs {
        /// Measurement id.
        id: String,
        /// `station` or `use`.
        what: &'static str,
    },
    /// A measurement's sensor-frame centre differs (other stripe data).
    #[error(
        "measurement {id}: the result's sensor-frame centre is {mm:.6} mm from the one the session gives (other measurement data)"
    )]
    OtherData {
        /// Measurement id.
        id: String,
        /// Distance between the two centres, mm.
        mm: f64,
    },
}

/// Checks that `result` was computed from `session`: the same name, every
/// result measurement in the session with the same station and use, and
/// (when `prepared` is given) the same sensor-frame centre to
/// [`CENTRE_MATCH_MM`]. Measurements of the session missing from the
/// result are allowed: they were left out of the run
/// ([`excluded_measurements`]).
///
/// # Errors
/// The first mismatch found.
pub fn check_result(
    session: &Session,
    result: &ResultFile,
    prepared: Option<&Prepared>,
) -> Result<(), ReportError> {
    if result.session != session.name {
        return Err(ReportError::OtherSession {
            result: result.session.clone(),
            session: session.name.clone(),
        });
    }
    let index = measurement_index(session);
    for c in &result.centres {
        let Some(&i) = index.get(c.measurement.as_str()) else {
            return Err(ReportError::UnknownMeasurement {
                id: c.measurement.clone(),
            });
        };
        let m = &session.measurements[i];
        if m.station != c.station {
            return Err(ReportError::Differs {
                id: m.id.clone(),
                what: "station",
            });
        }
        if m.usage != c.usage {
            return Err(ReportError::Differs {
                id: m.id.clone(),
                what: "use",
            });
        }
        if let Some(p) = prepared.and_then(|p| p.measurements.get(i)) {
            let mm = (p.centre_in_sensor - nalgebra::Vector3::from(c.sensor)).norm();
            if mm.is_nan() || mm > CENTRE_MATCH_MM {
                return Err(ReportError::OtherData {
                    id: m.id.clone(),
                    mm,
                });
            }
        }
    }
    Ok(())
}

/// Ids of the session's measurements that the result does not hold (left
/// out of the run, e.g. `calibrate --exclude`), in session order.
#[must_use]
pub fn excluded_measurements(session: &Session, result: &ResultFile) -> Vec<String> {
    let held: HashSet<&str> = result
        .centres
        .iter()
        .map(|c| c.measurement.as_str())
        .collect();
    session
        .measurements
        .iter()
        .filter(|m| !held.contains(m.id.as_str()))
        .map(|m| m.id.clone())
        .collect()
}

/// Each measurement id of `session` with its index (the first, should
/// ids repeat): a lookup that stays fast at 20,000 measurements, where a
/// scan per id takes seconds.
#[must_use]
pub fn measurement_index(session: &Session) -> HashMap<&str, usize> {
    let mut index = HashMap::with_capacity(session.measurements.len());
    for (i, m) in session.measurements.iter().enumerate() {
        index.entry(m.id.as_str()).or_insert(i);
    }
    index
}

/// `items` grouped by `key`, groups in order of first appearance, items
/// in their order: one pass, however many groups.
pub fn group_in_order<'a, T>(
    items: impl IntoIterator<Item = &'a T>,
    key: impl Fn(&T) -> &str,
) -> Vec<(String, Vec<&'a T>)>
where
    T: 'a,
{
    let mut at: HashMap<String, usize> = HashMap::new();
    let mut groups: Vec<(String, Vec<&'a T>)> = Vec::new();
    for item in items {
        let k = key(item);
        if let Some(&g) = at.get(k) {
            groups[g].1.push(item);
        } else {
            at.insert(k.to_string(), groups.len());
            groups.push((k.to_string(), vec![item]));
        }
    }
    groups
}

/// Parameter labels (`theta1`, `he_z`, …) this result marks as not
/// identifiable, each with why: a coefficient of at least
/// [`MARK_COEFFICIENT`] (as written, two decimals) in a dropped SVD
/// direction (the paper's method), or held fixed (`ml`).
#[must_use]
pub fn identifiability_marks(solver: &SolverReport) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    if let Some(dropped) = solver.paper().and_then(|p| p.dropped_directions.as_ref()) {
        for direction in dropped {
            for (c, label) in &direction.terms {
                if c.abs() >= MARK_COEFFICIENT {
                    out.entry(label.clone())
                        .or_insert_with(|| format!("in the dropped SVD direction {direction}"));
                }
            }
        }
    }
    for label in solver.fixed() {
        out.insert(
            label.clone(),
            "held fixed at its start: not identifiable from centre distances".to_string(),
        );
    }
    out
}

/// The hand-eye `eT_s` in numbers people read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HandEyeView {
    /// Translation, mm, flange frame.
    pub translation: [f64; 3],
    /// Roll, pitch, yaw, deg ([`roll_pitch_yaw_deg`]).
    pub rpy_deg: [f64; 3],
}

impl HandEyeView {
    /// The view of `flange_from_sensor`.
    #[must_use]
    pub fn new(flange_from_sensor: &Isometry3<f64>) -> Self {
        Self {
            translation: flange_from_sensor.translation.vector.into(),
            rpy_deg: roll_pitch_yaw_deg(&flange_from_sensor.rotation),
        }
    }
}

/// One within-station centre distance (true value 0; paper Fig. 5).
#[derive(Debug, Clone, PartialEq)]
pub struct PairDistance {
    /// Station id.
    pub station: String,
    /// Measurement ids of the pair.
    pub ids: (String, String),
    /// Distance with the nominal model and initial hand-eye, mm.
    pub before: f64,
    /// Distance with the calibrated model and hand-eye, mm.
    pub after: f64,
}

/// The headline figures: validation statistics before and after.
#[derive(Debug, Clone, PartialEq)]
pub struct Headline {
    /// What the statistics are of, e.g. "validation: 54 reference distances (measured − reference)".
    pub what: String,
    /// Before and after.
    pub stats: BeforeAfter,
}

/// A parameter's standard deviation as the method reports it.
#[derive(Debug, Clone, PartialEq)]
pub struct Sigma {
    /// 1σ a posteriori (the covariance as written times the variance
    /// factor, [`ResultFigures::variance_factor`]), file units.
    pub std: f64,
    /// 1σ a priori (the covariance as written, from the noise model).
    pub a_priori: f64,
    /// `mm` or `deg`.
    pub unit: String,
}

/// What every reader shows of a result.
#[derive(Debug, Clone, PartialEq)]
pub struct ResultFigures {
    /// The headline figures, when the result has validation.
    pub headline: Option<Headline>,
    /// Within-station distances of the validate stations (or, without any,
    /// of the identify stations), station order then pair order.
    pub within: Vec<PairDistance>,
    /// Which stations `within` is of: validate or identify.
    pub within_of: Use,
    /// Statistics of `within`.
    pub within_stats: BeforeAfter,
    /// Statistics of the identify stations' within-station distances.
    pub identify_within: BeforeAfter,
    /// Reference-distance comparisons (paper Fig. 6).
    pub distances: Vec<DistanceRecord>,
    /// Initial hand-eye.
    pub hand_eye_before: HandEyeView,
    /// Calibrated hand-eye.
    pub hand_eye_after: HandEyeView,
    /// Rotation between the two hand-eyes, deg.
    pub hand_eye_rotation_change_deg: f64,
    /// Parameter labels not identifiable from this data, each with why.
    pub marked: BTreeMap<String, String>,
    /// σ of each estimated parameter (`ml`), by label.
    pub sigma: BTreeMap<String, Sigma>,
    /// The 3-D rms scatter of the identify centres about their station
    /// means, before and after, mm ([`scatter_rms`]): what a hand-eye-only
    /// result is judged by.
    pub identify_scatter: (f64, f64),
    /// 1σ of the calibrated hand-eye as the tables show it: x, y, z (mm,
    /// flange frame) and roll, pitch, yaw (deg), propagated from `ml`'s
    /// covariance of the sensor-frame perturbation (`None` without one,
    /// or when a hand-eye direction was held fixed). A posteriori: the
    /// covariance times [`Self::variance_factor`].
    pub hand_eye_sigma: Option<[f64; 6]>,
    /// The same from the covariance as written (a priori).
    pub hand_eye_sigma_a_priori: Option<[f64; 6]>,
    /// `ml`'s predicted measuring error over the session's volume (a
    /// posteriori), when the result has it.
    pub volume_error: Option<crate::engine::calibrate::solve::ml::range::VolumeError>,
    /// The a posteriori variance factor every σ shown is scaled by
    /// ([`variance_factor`](crate::engine::calibrate::solve::ml::covariance::variance_factor):
    /// 1 without one); σ a posteriori = σ a priori × √factor.
    pub variance_factor: f64,
    /// Each identify measurement predicted by a calibration made without
    /// it, beside the fit's own scatter (`None` for a result written
    /// without it).
    pub held_out: Option<HeldOut>,
    /// Warnings about the run itself: the paper's loop ending with ε above
    /// its start ([`SolverReport::epsilon_warning`]), or no update made
    /// ([`ResultFile::no_update_warning`]).
    pub warnings: Vec<String>,
}

impl ResultFigures {
    /// The view of `result`.
    #[must_use]
    pub fn new(result: &ResultFile) -> Self {
        let validate = within_pairs(&result.centres, Use::Validate);
        let identify = within_pairs(&result.centres, Use::Identify);
        let identify_within = pair_stats(&identify);
        let (within, within_of) = if validate.is_empty() {
            (identify, Use::Identify)
        } else {
            (validate, Use::Validate)
        };
        let headline = match &result.validation {
            Some(v) if !v.distances.is_empty() => Some(Headline {
                what: format!(
                    "validation: {} reference distances (measured − reference)",
                    v.distances.len()
                ),
                stats: BeforeAfter {
                    before: v.before,
                    after: v.after,
                },
            }),
            Some(v) => Some(Headline {
                what: "validation: within-station centre distances".to_string(),
                stats: v.within_station,
            }),
            None => None,
        };
        let variance_factor =
            crate::engine::calibrate::solve::ml::covariance::variance_factor(&result.solver);
        let root = variance_factor.sqrt();
        let sigma = result
            .solver
            .ml()
            .iter()
            .flat_map(|r| &r.parameters)
            .map(|p| {
                (
                    p.parameter.clone(),
                    Sigma {
                        std: p.std * root,
                        a_priori: p.std,
                        unit: p.unit.clone(),
                    },
                )
            })
            .collect();
        let hand_eye_sigma_a_priori = result
            .solver
            .ml()
            .and_then(|ml| hand_eye_sigma(&result.hand_eye, &ml.covariance));
        Self {
            headline,
            within_stats: pair_stats(&within),
            within,
            within_of,
            identify_within,
            distances: result
                .validation
                .as_ref()
                .map(|v| v.distances.clone())
                .unwrap_or_default(),
            hand_eye_before: HandEyeView::new(&result.hand_eye_initial),
            hand_eye_after: HandEyeView::new(&result.hand_eye),
            hand_eye_rotation_change_deg: result
                .hand_eye_initial
                .rotation
                .angle_to(&result.hand_eye.rotation)
                .to_degrees(),
            marked: identifiability_marks(&result.solver),
            sigma,
            identify_scatter: identify_scatter(&result.centres),
            hand_eye_sigma: hand_eye_sigma_a_priori.map(|s| s.map(|v| v * root)),
            hand_eye_sigma_a_priori,
            variance_factor,
            volume_error: result.solver.ml().and_then(|m| m.volume_error.clone()),
            held_out: result.held_out.clone(),
            warnings: result
                .solver
                .epsilon_warning(result.epsilon_before, result.epsilon_after)
                .into_iter()
                .chain(result.no_update_warning())
                .collect(),
        }
    }
}

/// 1σ of the hand-eye's x, y, z (mm, flange frame) and roll, pitch, yaw
/// (deg) from the covariance of the perturbation `eT_s·exp(ΔX)` (sensor
/// frame, translation first; `he_x … he_rz`, mm and deg): to first order
/// the flange-frame translation moves by `R·Δt` and the angles by the
/// derivative of roll/pitch/yaw under `R·exp(Δω)` (central differences).
/// `None` when any of the six is not in the covariance (held fixed).
#[must_use]
pub fn hand_eye_sigma(
    hand_eye: &Isometry3<f64>,
    covariance: &crate::engine::base::records::ml::LabelledMatrix,
) -> Option<[f64; 6]> {
    use crate::engine::calibrate::solve::estimate::HAND_EYE_LABELS;
    use nalgebra::{Matrix6, UnitQuaternion};
    let index: Vec<usize> = HAND_EYE_LABELS
        .iter()
        .map(|l| covariance.labels.iter().position(|x| x == l))
        .collect::<Option<_>>()?;
    let mut c = Matrix6::<f64>::zeros();
    for (a, &i) in index.iter().enumerate() {
        for (b, &j) in index.iter().enumerate() {
            c[(a, b)] = *covariance.matrix.get(i)?.get(j)?;
        }
    }
    let r = hand_eye.rotation;
    let mut jac = Matrix6::<f64>::zeros();
    jac.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(r.to_rotation_matrix().matrix());
    // Angles per degree of Δω, unwrapped across ±180°.
    let h = 1e-6_f64;
    for k in 0..3 {
        let mut axis = nalgebra::Vector3::zeros();
        axis[k] = h.to_radians();
        let plus = roll_pitch_yaw_deg(&(r * UnitQuaternion::from_scaled_axis(axis)));
        let minus = roll_pitch_yaw_deg(&(r * UnitQuaternion::from_scaled_axis(-axis)));
        for m in 0..3 {
            jac[(3 + m, 3 + k)] =
                crate::engine::base::geometry::wrap_deg(plus[m] - minus[m]) / (2.0 * h);
        }
    }
    let f = jac * c * jac.transpose();
    let out: [f64; 6] =
        std::array::from_fn(|i| crate::engine::base::numeric::sigma_of_variance(f[(i, i)]));
    out.iter().all(|v| v.is_finite()).then_some(out)
}

/// The scatter of the identify centres about their station means, before
/// and after.
fn identify_scatter(centres: &[CentreRecord]) -> (f64, f64) {
    let stations = group_in_order(centres.iter().filter(|c| c.usage == Use::Identify), |c| {
        c.station.as_str()
    });
    let group = |after: bool| -> Vec<Vec<Vector3<f64>>> {
        stations
            .iter()
            .map(|(_, cs)| {
                cs.iter()
                    .map(|c| Vector3::from(if after { c.after } else { c.before }))
                    .collect()
            })
            .collect()
    };
    (scatter_rms(&group(false)), scatter_rms(&group(true)))
}

/// Statistics of the before and after distances of `pairs`.
fn pair_stats(pairs: &[PairDistance]) -> BeforeAfter {
    BeforeAfter {
        before: Stats::of(&pairs.iter().map(|p| p.before).collect::<Vec<_>>()),
        after: Stats::of(&pairs.iter().map(|p| p.after).collect::<Vec<_>>()),
    }
}

/// Pairwise distances within each station of `usage` (station order of
/// first appearance, then `i < j`), by [`within_station_distances`].
#[must_use]
pub fn within_pairs(centres: &[CentreRecord], usage: Use) -> Vec<PairDistance> {
    let stations = group_in_order(centres.iter().filter(|c| c.usage == usage), |c| {
        c.station.as_str()
    });
    let of = |f: fn(&CentreRecord) -> [f64; 3]| -> Vec<Vec<Vector3<f64>>> {
        stations
            .iter()
            .map(|(_, cs)| cs.iter().map(|c| f(c).into()).collect())
            .collect()
    };
    let before = within_station_distances(&of(|c| c.before));
    let after = within_station_distances(&of(|c| c.after));
    let mut labels = Vec::new();
    for (station, cs) in &stations {
        for i in 0..cs.len() {
            for j in i + 1..cs.len() {
                labels.push((
                    station.clone(),
                    (cs[i].measurement.clone(), cs[j].measurement.clone()),
                ));
            }
        }
    }
    labels
        .into_iter()
        .zip(before.into_iter().zip(after))
        .map(|((station, ids), (before, after))| PairDistance {
            station,
            ids,
            before,
            after,
        })
        .collect()
}

#[cfg(test)]
mod sigma_tests {
    use super::*;
    use crate::engine::base::records::ml::LabelledMatrix;
    use crate::engine::calibrate::solve::estimate::HAND_EYE_LABELS;
    use nalgebra::{Translation3, UnitQuaternion, Vector3};

    fn diagonal(values: [f64; 6]) -> LabelledMatrix {
        LabelledMatrix {
            labels: HAND_EYE_LABELS.iter().map(|s| (*s).to_string()).collect(),
            units: vec![],
            matrix: (0..6)
                .map(|i| {
                    (0..6)
                        .map(|j| if i == j { values[i] } else { 0.0 })
                        .collect()
                })
                .collect(),
        }
    }

    #[test]
    fn the_hand_eye_sigma_turns_into_the_flange_frame() {
        let c = diagonal([0.01, 0.04, 0.09, 1e-4, 4e-4, 9e-4]);
        // Identity rotation: the σ are the perturbation's own.
        let s = hand_eye_sigma(&Isometry3::identity(), &c).unwrap();
        let expect = [0.1, 0.2, 0.3, 0.01, 0.02, 0.03];
        for (a, b) in s.iter().zip(expect) {
            assert!((a - b).abs() < 1e-6, "{s:?}");
        }
        // Turned 90° about z: the sensor's x is the flange's y.
        let he = Isometry3::from_parts(
            Translation3::new(10.0, 0.0, 50.0),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_2),
        );
        let s = hand_eye_sigma(&he, &c).unwrap();
        assert!(
            (s[0] - 0.2).abs() < 1e-9 && (s[1] - 0.1).abs() < 1e-9,
            "{s:?}"
        );
        assert!((s[2] - 0.3).abs() < 1e-9);
        // A fixed direction (missing label): no σ.
        let mut partial = c.clone();
        partial.labels[5] = "beta6".into();
        assert!(hand_eye_sigma(&he, &partial).is_none());
    }
}
