//! The solver's input: every measurement's sphere centre in the sensor
//! frame (a given centre, or the circle fit of its stripe and paper
//! eq. 21) and the initial hand-eye (the session's, else paper eq. 6-9 on
//! the nominal model).
//!
//! [`analyse`] fits every stripe once and keeps each measurement's outcome
//! (its centre, or why its stripe gave none), so the workbench lists the
//! bad ones from the same data it later calibrates with; [`Analysis::prepared`]
//! turns an analysis whose every measurement succeeded into the
//! [`Prepared`] session the loop takes, without fitting anything again.

use nalgebra::{Isometry3, Matrix3, Vector3};

use super::SolveError;
use super::estimate::Station;
use crate::engine::base::session::Mount;
use crate::engine::base::session::{Observation, Session, Use};
use crate::engine::calibrate::handeye::general::{
    GeneralHandEye, GeneralSighting, general_hand_eye,
};
use crate::engine::calibrate::handeye::{InitialHandEye, Sighting, initial_hand_eye};
use crate::engine::calibrate::stripe::{StripeError, StripeResult, centre_from_stripe};

/// A measurement's sphere centre in the sensor frame, ready for the solver.
#[derive(Debug, Clone, PartialEq)]
pub struct PreparedMeasurement {
    /// Index into `session.measurements`.
    pub index: usize,
    /// Sphere centre in the sensor frame, mm.
    pub centre_in_sensor: Vector3<f64>,
    /// Its covariance, mm² (from the circle fit; `None` for given centres).
    pub covariance: Option<Matrix3<f64>>,
    /// Circle fit and quality, for stripe measurements.
    pub stripe: Option<StripeResult>,
}

/// Where the initial hand-eye came from.
#[derive(Debug, Clone, PartialEq)]
pub enum HandEyeSource {
    /// The session's `hand_eye`.
    File,
    /// Computed by eq. 6-9, with its diagnostics.
    Computed(InitialHandEye),
    /// A fixed sensor's `bT_s`, with the targets on the flange, linear in
    /// the unknowns from all identify measurements at once (FORMAT.md
    /// 2026-11-27; [`general_hand_eye`] on the inverted flange poses).
    Linear(GeneralHandEye),
}

/// What [`analyse`] made of a session: every measurement's outcome, in
/// session order, and the initial hand-eye when it could be had.
#[derive(Debug, Clone, PartialEq)]
pub struct Analysis {
    /// One per session measurement: its centre, or why its stripe gave none.
    pub measurements: Vec<Result<PreparedMeasurement, StripeError>>,
    /// `eT_s` before identification and where it came from, or why it
    /// could not be had (a translation or rotation stripe failed, or the
    /// poses do not determine it).
    pub hand_eye: Result<(Isometry3<f64>, HandEyeSource), SolveError>,
    /// Warnings `(measurement id, text)` of the stripe fits.
    pub warnings: Vec<(String, String)>,
}

/// A session with every centre computed and the initial hand-eye known.
#[derive(Debug, Clone, PartialEq)]
pub struct Prepared {
    /// One per session measurement, same order.
    pub measurements: Vec<PreparedMeasurement>,
    /// `eT_s` before identification.
    pub hand_eye_initial: Isometry3<f64>,
    /// Where it came from.
    pub hand_eye_source: HandEyeSource,
    /// Warnings `(measurement id, text)` from the stripe fits.
    pub warnings: Vec<(String, String)>,
}

impl Prepared {
    /// Sightings of the measurements with this use, grouped by station in
    /// order of first appearance.
    #[must_use]
    pub fn stations(&self, session: &Session, usage: Use) -> Vec<Station> {
        session
            .stations(usage)
            .into_iter()
            .map(|(id, idx)| Station {
                id,
                sightings: idx.iter().map(|&i| self.sighting(session, i)).collect(),
            })
            .collect()
    }

    /// The sighting of measurement `i`.
    #[must_use]
    pub fn sighting(&self, session: &Session, i: usize) -> Sighting {
        sighting(session, i, self.measurements[i].centre_in_sensor)
    }
}

/// The sighting of measurement `i` with its sensor-frame centre.
fn sighting(session: &Session, i: usize, centre_in_sensor: Vector3<f64>) -> Sighting {
    let m = &session.measurements[i];
    Sighting {
        id: m.id.clone(),
        joints: m.joints.clone(),
        flange: m.flange,
        centre_in_sensor,
    }
}

/// The sphere centre of measurement `index` of `session` (eq. 21 for a
/// stripe), with the fit's warnings.
fn measure(
    session: &Session,
    index: usize,
) -> (Result<PreparedMeasurement, StripeError>, Vec<String>) {
    let m = &session.measurements[index];
    match &m.observation {
        Observation::Centre(c) => (
            Ok(PreparedMeasurement {
                index,
                centre_in_sensor: *c,
                covariance: None,
                stripe: None,
            }),
            Vec::new(),
        ),
        Observation::Stripe(points) => {
            match centre_from_stripe(points, session.sphere_radius(), m.side) {
                Ok(fit) => {
                    let warnings = fit.warnings.clone();
                    (
                        Ok(PreparedMeasurement {
                            index,
                            centre_in_sensor: fit.sphere.centre_in_sensor,
                            covariance: Some(fit.sphere.covariance),
                            stripe: Some(fit),
                        }),
                        warnings,
                    )
                }
                Err(e) => (Err(e), Vec::new()),
            }
        }
    }
}

/// The initial hand-eye of `session` from its measurements' outcomes: the
/// file's, else eq. 6-9 on the translation and rotation sightings (the
/// first of them whose stripe failed is the error).
fn hand_eye(
    session: &Session,
    measurements: &[Result<PreparedMeasurement, StripeError>],
) -> Result<(Isometry3<f64>, HandEyeSource), SolveError> {
    if let Some(he) = session.hand_eye {
        return Ok((he, HandEyeSource::File));
    }
    let sightings = |usage: Use| -> Result<Vec<Sighting>, SolveError> {
        session
            .measurements
            .iter()
            .enumerate()
            .filter(|(_, m)| m.usage == usage)
            .map(|(i, m)| match &measurements[i] {
                Ok(p) => Ok(sighting(session, i, p.centre_in_sensor)),
                Err(source) => Err(SolveError::Stripe {
                    id: m.id.clone(),
                    source: source.clone(),
                }),
            })
            .collect()
    };
    if session.mount == Mount::Fixed {
        return fixed_initial(session, measurements);
    }
    let translations = sightings(Use::Translation)?;
    let rotations = sightings(Use::Rotation)?;
    let initial = initial_hand_eye(&session.robot, &translations, &rotations)?;
    Ok((initial.flange_from_sensor, HandEyeSource::Computed(initial)))
}

/// A fixed sensor's initial `bT_s` (FORMAT.md 2026-11-27): the constraint
/// `bT_s·X_s = bT_e(q)·X_e` is `bT_e(q)⁻¹·(R_s·X_s + t_s) = X_e`, the
/// general hand-eye's `R_i·(R_s·x_i + t_s) + p_i = c_s` with the inverted
/// nominal flange pose in place of the flange pose: linear in `R_s`, `t_s`
/// and the station points, from every identify measurement at once.
fn fixed_initial(
    session: &Session,
    measurements: &[Result<PreparedMeasurement, StripeError>],
) -> Result<(Isometry3<f64>, HandEyeSource), SolveError> {
    let stations = session.stations(Use::Identify);
    let mut sightings = Vec::new();
    for (k, (_, indices)) in stations.iter().enumerate() {
        for &i in indices {
            let m = &session.measurements[i];
            let p = measurements[i]
                .as_ref()
                .map_err(|source| SolveError::Stripe {
                    id: m.id.clone(),
                    source: source.clone(),
                })?;
            sightings.push(GeneralSighting {
                id: m.id.clone(),
                station: k,
                base_from_flange: session.base_from_flange(&session.robot, i).inverse(),
                centre_in_sensor: p.centre_in_sensor,
            });
        }
    }
    let initial = general_hand_eye(&sightings, stations.len())?;
    Ok((initial.flange_from_sensor, HandEyeSource::Linear(initial)))
}

/// Fits every stripe of `session` once (eq. 21) and computes the initial
/// hand-eye: nothing fails here, each outcome is kept.
#[must_use]
pub fn analyse(session: &Session) -> Analysis {
    let mut measurements = Vec::with_capacity(session.measurements.len());
    let mut warnings = Vec::new();
    for (index, m) in session.measurements.iter().enumerate() {
        let (outcome, w) = measure(session, index);
        warnings.extend(w.into_iter().map(|w| (m.id.clone(), w)));
        measurements.push(outcome);
    }
    let hand_eye = hand_eye(session, &measurements);
    Analysis {
        measurements,
        hand_eye,
        warnings,
    }
}

impl Analysis {
    /// The measurements whose stripe gave no centre: `(index, error)`.
    pub fn failures(&self) -> impl Iterator<Item = (usize, &StripeError)> {
        self.measurements
            .iter()
            .enumerate()
            .filter_map(|(i, m)| m.as_ref().err().map(|e| (i, e)))
    }

    /// The analysis of `kept`, a session made of the measurements
    /// `indices` of the analysed one (in that order, e.g. with some left
    /// out): the outcomes are taken over, not fitted again, and only the
    /// initial hand-eye is recomputed.
    #[must_use]
    pub fn subset(&self, kept: &Session, indices: &[usize]) -> Self {
        let measurements: Vec<Result<PreparedMeasurement, StripeError>> = indices
            .iter()
            .enumerate()
            .map(|(new, &old)| {
                self.measurements[old].clone().map(|mut p| {
                    p.index = new;
                    p
                })
            })
            .collect();
        let ids: Vec<&str> = kept.measurements.iter().map(|m| m.id.as_str()).collect();
        let warnings = self
            .warnings
            .iter()
            .filter(|(id, _)| ids.contains(&id.as_str()))
            .cloned()
            .collect();
        let hand_eye = hand_eye(kept, &measurements);
        Self {
            measurements,
            hand_eye,
            warnings,
        }
    }

    /// The prepared session, when every measurement gave a centre and the
    /// initial hand-eye is known.
    ///
    /// # Errors
    /// The first measurement (session order) whose stripe failed, naming
    /// it; else why the initial hand-eye could not be had.
    pub fn prepared(self, session: &Session) -> Result<Prepared, SolveError> {
        let mut measurements = Vec::with_capacity(self.measurements.len());
        for (m, outcome) in session.measurements.iter().zip(self.measurements) {
            measurements.push(outcome.map_err(|source| SolveError::Stripe {
                id: m.id.clone(),
                source,
            })?);
        }
        let (hand_eye_initial, hand_eye_source) = self.hand_eye?;
        Ok(Prepared {
            measurements,
            hand_eye_initial,
            hand_eye_source,
            warnings: self.warnings,
        })
    }
}

/// Sphere centres of every measurement (eq. 21) and the initial hand-eye
/// (the file's, else eq. 6-9 on the nominal model): [`analyse`] then
/// [`Analysis::prepared`].
///
/// # Errors
/// A stripe that cannot be fitted (naming the measurement) or a pose set
/// that does not determine the hand-eye.
pub fn prepare(session: &Session) -> Result<Prepared, SolveError> {
    analyse(session).prepared(session)
}
