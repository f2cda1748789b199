//! The candidate poses of a plan: at every station, flange orientations in
//! a cone about the mean approach, each with every IK branch within limits
//! and away from the wrist singularity, kept when the reference forward
//! kinematics puts the planned centre on the station; the hand-eye groups
//! at P0; `ml`'s analysis of a set of poses.

use nalgebra::{DMatrix, Isometry3, Matrix3, Point3, UnitQuaternion, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::engine::base::cell::workspace::{self, Workspace};
use crate::engine::base::cell::{Unreachable, approach, random};
use crate::engine::base::geometry::wrap_deg;
use crate::engine::base::robot::Robot;
use crate::engine::base::robot::ik::{Chain, DOF};
use crate::engine::base::session::{
    Measurement, Observation, ReferenceDistance, SensorRange, Session, Use,
};
use crate::engine::calibrate::handeye::{MIN_TRANSLATION_SPREAD, Sighting};
use crate::engine::calibrate::solve::estimate::{
    Estimate, PoseSensitivity, sensitivity, unknown_label,
};
use crate::engine::calibrate::solve::ml::range::{AlignedGrid, RANGE_POSES};
use crate::engine::calibrate::solve::ml::{self, MlOptions, MlReport};
use crate::engine::calibrate::solve::{self, Control, HandEyeSource, Method, Options, Prepared};
use crate::engine::tools::simulate::SimConfig;

use super::select::{Info, StationInfo, rotation_criterion};
use super::{
    Plan, PlanConfig, PlanError, PlannedPose, StationLayout, StationRole, VOLUME_ARC_DEG,
    VOLUME_SAMPLES, VOLUME_TILT_DEG,
};
use crate::engine::calibrate::solve::estimate::unknown_scale;

/// Reference FK must put the planned centre on the station to this, mm
/// (IK converges to 1e-9 mm; this only guards the fast chain).
pub(super) const FK_CHECK_MM: f64 = 1e-6;

/// Orientation draws tried for the translation group before `P0` is
/// declared out of reach, as a multiple of `candidates`.
pub(super) const TRANSLATION_TRIES_PER_CANDIDATE: usize = 4;

/// A translation pose must stay within this (deg, every joint) of the
/// previous one: the same IK branch, a pure flange translation.
pub(super) const TRANSLATION_SAME_BRANCH_DEG: f64 = 20.0;

/// Two rotation poses differ in orientation by at least this (deg), as in
/// the simulator, so eq. 8-9 get distinct rows.
pub(super) const MIN_ROTATION_SEPARATION_DEG: f64 = 15.0;

/// Stream ids of the plan's seed: stations and candidates; the random
/// baseline selection.
pub(super) const STREAM_GEOMETRY: u64 = 10;

/// See [`STREAM_GEOMETRY`].
pub(super) const STREAM_BASELINE: u64 = 11;

/// See [`STREAM_GEOMETRY`]: the sampled poses of the working volume.
pub(super) const STREAM_VOLUME: u64 = 12;

/// Orientation draws tried per sampled place of the working volume before
/// the place is dropped (out of reach in the whole cone and spin).
const VOLUME_TRIES: usize = 8;

/// One candidate pose.
#[derive(Debug, Clone)]
pub(super) struct Candidate {
    pub(super) joints: [f64; DOF],
    pub(super) side: i8,
    pub(super) centre: Vector3<f64>,
    pub(super) rotation: UnitQuaternion<f64>,
}

/// A station while planning.
#[derive(Debug, Clone)]
pub(super) struct Site {
    pub(super) role: StationRole,
    pub(super) position: Vector3<f64>,
    pub(super) candidates: Vec<Candidate>,
    /// Indices of the chosen candidates, in selection order.
    pub(super) chosen: Vec<usize>,
}

/// One pose of a group to order: joints, with its candidate.
#[derive(Debug, Clone)]
pub(super) struct Group {
    pub(super) usage: Use,
    /// Index into the sites.
    pub(super) site: usize,
    pub(super) poses: Vec<Candidate>,
}

/// The id a station will probably get (for messages before ordering).
pub(super) fn provisional_id(sites: &[Site], k: usize) -> String {
    let role = sites[k].role;
    let n = sites[..=k].iter().filter(|s| s.role == role).count();
    match role {
        StationRole::HandEye => "P0".to_owned(),
        StationRole::Identify => format!("P{n}"),
        StationRole::Validate => format!("V{n}"),
    }
}

/// Poses on `side` of a station of `n`: `ceil(n/2)` on +1, the rest on −1.
pub(super) fn side_quota(n: usize, side: i8) -> usize {
    if side > 0 { n.div_ceil(2) } else { n / 2 }
}

/// Indices into ΔY (`he_x`…, then the kinematic parameters) of `labels`.
pub(super) fn unknown_indices(robot: &Robot, labels: &[String]) -> Vec<usize> {
    (0..6 + robot.n_params())
        .filter(|&k| labels.iter().any(|l| *l == unknown_label(k)))
        .collect()
}

pub(super) fn joint_gap(a: &[f64; DOF], b: &[f64; DOF]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| wrap_deg(x - y).abs())
        .fold(0.0, f64::max)
}

/// The planner's geometry: candidates and groups on the nominal model.
pub(super) struct Planner<'a> {
    pub(super) config: &'a PlanConfig,
    pub(super) chain: Chain,
}

impl Planner<'_> {
    /// The identify and validate stations (not yet `P0`).
    pub(super) fn sites(&self, rng: &mut ChaCha8Rng) -> Vec<Site> {
        let c = self.config;
        let (identify, validate): (Vec<Vector3<f64>>, Vec<Vector3<f64>>) = match &c.stations {
            StationLayout::Box { size } => {
                let centre = Vector3::from(c.design.sphere);
                let half = Vector3::from(*size) / 2.0;
                let eye = self.config.eye_point();
                let w = Workspace {
                    min: (centre - half).into(),
                    max: (centre + half).into(),
                    eye: eye.into(),
                };
                (
                    workspace::identify_stations(rng, &w, c.design.n_identify),
                    workspace::validate_stations(rng, &w, c.design.n_validate),
                )
            }
            StationLayout::Explicit { identify, validate } => (
                identify.iter().map(|p| Vector3::from(*p)).collect(),
                validate.iter().map(|p| Vector3::from(*p)).collect(),
            ),
        };
        let site = |role, position| Site {
            role,
            position,
            candidates: Vec::new(),
            chosen: Vec::new(),
        };
        identify
            .into_iter()
            .map(|p| site(StationRole::Identify, p))
            .chain(validate.into_iter().map(|p| site(StationRole::Validate, p)))
            .collect()
    }

    /// The mean approach at `station` from the configuration's eye point
    /// ([`approach::mean_approach`]).
    pub(super) fn mean_approach(&self, station: &Vector3<f64>) -> Vector3<f64> {
        approach::mean_approach(station, &self.config.eye_point())
    }

    /// The flange pose that puts the sphere at `station` and at `centre`
    /// in the sensor frame, with flange rotation `rotation`.
    pub(super) fn target(
        &self,
        station: &Vector3<f64>,
        rotation: &UnitQuaternion<f64>,
        centre: &Vector3<f64>,
    ) -> Isometry3<f64> {
        approach::flange_target(station, rotation, &self.config.flange_from_sensor, centre)
    }

    /// Whether the reference FK at `q` sees the station at `centre`.
    pub(super) fn sees(
        &self,
        q: &[f64; DOF],
        station: &Vector3<f64>,
        centre: &Vector3<f64>,
    ) -> bool {
        let seen = self.config.robot.base_from_flange(q)
            * self.config.flange_from_sensor
            * Point3::from(*centre);
        (seen.coords - station).norm() < FK_CHECK_MM
    }

    /// Every IK branch of every drawn orientation and side at a station.
    pub(super) fn station_candidates(
        &self,
        rng: &mut ChaCha8Rng,
        station: &Vector3<f64>,
        id: &str,
    ) -> Result<Vec<Candidate>, PlanError> {
        let c = self.config;
        let mean = self.mean_approach(station);
        let cone = c.cone_angle.to_radians();
        let mut out = Vec::new();
        for k in 0..c.design.candidates {
            let rotation = approach::random_orientation(rng, &mean, cone);
            for side in [1_i8, -1] {
                let offset = self.station_offset(rng, k, c.design.candidates);
                out.extend(self.candidates_at(
                    station,
                    &rotation,
                    &(c.centre(side) + offset),
                    side,
                ));
            }
        }
        if out.is_empty() {
            return Err(self.unreachable(id, station, c.design.candidates));
        }
        Ok(out)
    }

    /// A sensor-frame `(0, y, z)` offset of the planned centre, uniform in
    /// `±centre_spread`.
    pub(super) fn offset(&self, rng: &mut ChaCha8Rng) -> Vector3<f64> {
        let [y, z] = self.config.centre_spread;
        Vector3::new(
            0.0,
            random::uniform(rng, -y, y),
            random::uniform(rng, -z, z),
        )
    }

    /// The offset of an identify or validate candidate: anywhere in the
    /// sensor's range when the plan spreads the sphere (the `k`-th of `n`
    /// orientations takes the `k`-th cell of a jittered grid over the
    /// range, so the candidates of a station cover it evenly), else
    /// [`Self::offset`].
    pub(super) fn station_offset(&self, rng: &mut ChaCha8Rng, k: usize, n: usize) -> Vector3<f64> {
        let c = self.config;
        let (true, Some(r)) = (c.spread, c.range) else {
            let [y, z] = c.station_spread;
            return Vector3::new(
                0.0,
                random::uniform(rng, -y, y),
                random::uniform(rng, -z, z),
            );
        };
        // A jittered `side × side` grid (the orientations are random, so
        // cell order does not matter).
        let side = (n as f64).sqrt().ceil().max(1.0) as usize;
        let cell = k % (side * side);
        let (iy, iz) = (cell / side, cell % side);
        let mut at = |lo: f64, hi: f64, i: usize| {
            let w = (hi - lo) / side as f64;
            lo + w * (i as f64 + random::uniform(rng, 0.0, 1.0))
        };
        let y = at(r.y[0], r.y[1], iy);
        let z = at(r.z[0], r.z[1], iz);
        Vector3::new(0.0, y, z)
    }

    /// Every IK branch that sees `station` at `centre` (sensor frame) with
    /// the flange rotation `rotation`.
    pub(super) fn candidates_at(
        &self,
        station: &Vector3<f64>,
        rotation: &UnitQuaternion<f64>,
        centre: &Vector3<f64>,
        side: i8,
    ) -> Vec<Candidate> {
        let c = self.config;
        let centre = *centre;
        let target = self.target(station, rotation, &centre);
        let guesses = self.chain.arm_guess_grid(&target, &c.limits);
        self.chain
            .solutions(&target, &guesses, &c.limits, c.min_wrist_angle)
            .into_iter()
            .filter(|q| self.sees(q, station, &centre))
            .map(|joints| Candidate {
                joints,
                side,
                centre,
                rotation: *rotation,
            })
            .collect()
    }

    pub(super) fn unreachable(
        &self,
        id: &str,
        station: &Vector3<f64>,
        orientations: usize,
    ) -> PlanError {
        let (cone, cut, min_wrist) = (
            self.config.cone_angle,
            self.config.design.cut_angle,
            self.config.min_wrist_angle,
        );
        PlanError::Unreachable(Unreachable {
            station: id.to_owned(),
            position: [station.x, station.y, station.z],
            orientations,
            why: format!(
                "none of {orientations} flange orientations (approach within {cone:.0}° of the look from the eye point) sees it with the laser plane at ±{cut:.0}° within the joint limits and {min_wrist:.0}° from the wrist singularity; move the sphere (or the station box) toward the robot, or widen the cone"
            ),
        })
    }

    /// The translation group at `P0` (side +1, one orientation, one IK
    /// branch) and its flange rotation. Empty (with a reference
    /// orientation) when no translations are asked for.
    pub(super) fn translation_group(
        &self,
        rng: &mut ChaCha8Rng,
        p0: &Vector3<f64>,
    ) -> Result<(Vec<Candidate>, UnitQuaternion<f64>), PlanError> {
        let c = self.config;
        let mean = self.mean_approach(p0);
        // Near the middle of the cone, so the rotations about it stay reachable.
        let cone = c.cone_angle.to_radians() / 2.0;
        let n = c.design.n_translation;
        let tries = c.design.candidates * TRANSLATION_TRIES_PER_CANDIDATE;
        for _ in 0..tries {
            let rotation = approach::random_orientation(rng, &mean, cone);
            let phase = std::f64::consts::TAU * rng.random::<f64>();
            if n == 0 {
                // Only a reference orientation for the rotation group: one
                // that reaches P0.
                if !self
                    .candidates_at(p0, &rotation, &c.centre(1), 1)
                    .is_empty()
                {
                    return Ok((Vec::new(), rotation));
                }
                continue;
            }
            // Directions 120° apart for 4 translations (the simulator's),
            // evenly round the turn for more; the two displacements of 3
            // translations 90° apart (half a turn would be collinear).
            let step = if n == 3 {
                std::f64::consts::FRAC_PI_2
            } else {
                std::f64::consts::TAU / (n - 1) as f64
            };
            let first = c.centre(1);
            let centres: Vec<Vector3<f64>> = (0..n)
                .map(|k| {
                    if k == 0 {
                        first
                    } else {
                        let angle = phase + step * (k - 1) as f64;
                        first
                            + Vector3::new(
                                0.0,
                                c.translation_step * angle.cos(),
                                c.translation_step * angle.sin(),
                            )
                    }
                })
                .collect();
            for start in self.candidates_at(p0, &rotation, &first, 1) {
                let mut poses = vec![start.clone()];
                let mut previous = start.joints;
                for centre in &centres[1..] {
                    let target = self.target(p0, &rotation, centre);
                    let Some(q) =
                        self.chain
                            .solve_from(&target, &previous, &c.limits, c.min_wrist_angle)
                    else {
                        break;
                    };
                    if joint_gap(&q, &previous) > TRANSLATION_SAME_BRANCH_DEG
                        || !self.sees(&q, p0, centre)
                    {
                        break;
                    }
                    previous = q;
                    poses.push(Candidate {
                        joints: q,
                        side: 1,
                        centre: *centre,
                        rotation,
                    });
                }
                if poses.len() == n {
                    check_translations(&self.config.robot, &poses)?;
                    return Ok((poses, rotation));
                }
            }
        }
        Err(self.unreachable("P0", p0, tries))
    }

    /// The rotation group at `P0`: candidates turned `rotation_min..max`
    /// about random axes from `reference`, sides alternating; greedy on
    /// `ln det` of eq. 8's normal matrix, pairs at least 15° apart.
    pub(super) fn rotation_group(
        &self,
        rng: &mut ChaCha8Rng,
        p0: &Vector3<f64>,
        reference: &UnitQuaternion<f64>,
    ) -> Result<Vec<Candidate>, PlanError> {
        let c = self.config;
        let n = c.design.n_rotation;
        if n == 0 {
            return Ok(Vec::new());
        }
        let draws = c.design.candidates.max(n) * 2;
        let mut pool: Vec<Candidate> = Vec::new();
        for k in 0..draws {
            let rotation =
                approach::turned_orientation(rng, reference, c.rotation_min, c.rotation_max);
            let side = if k % 2 == 0 { 1 } else { -1 };
            // One branch per orientation: the eq. 8 rows depend on the
            // orientation only.
            let centre = c.centre(side) + self.offset(rng);
            if let Some(first) = self
                .candidates_at(p0, &rotation, &centre, side)
                .into_iter()
                .next()
            {
                pool.push(first);
            }
        }
        let mut chosen: Vec<usize> = Vec::new();
        while chosen.len() < n {
            let mut best: Option<(f64, usize)> = None;
            for (i, cand) in pool.iter().enumerate() {
                let distinct = chosen.iter().all(|&j| {
                    pool[j].rotation.angle_to(&cand.rotation)
                        >= MIN_ROTATION_SEPARATION_DEG.to_radians()
                });
                let used = chosen
                    .iter()
                    .filter(|&&j| pool[j].side == cand.side)
                    .count();
                if chosen.contains(&i) || !distinct || used >= side_quota(n, cand.side) {
                    continue;
                }
                let mut set: Vec<&Candidate> = chosen.iter().map(|&j| &pool[j]).collect();
                set.push(cand);
                let value = rotation_criterion(&self.config.robot, &set);
                if best.is_none_or(|(b, _)| value > b) {
                    best = Some((value, i));
                }
            }
            if let Some((_, i)) = best {
                chosen.push(i);
            } else {
                // The side still short of its quota.
                let plus = chosen.iter().filter(|&&j| pool[j].side == 1).count();
                let side: i8 = if plus < side_quota(n, 1) { 1 } else { -1 };
                let found = chosen.iter().filter(|&&j| pool[j].side == side).count();
                return Err(PlanError::TooFewPoses {
                    station: "P0".to_owned(),
                    position: [p0.x, p0.y, p0.z],
                    side,
                    found,
                    needed: side_quota(n, side),
                });
            }
        }
        Ok(chosen.into_iter().map(|i| pool[i].clone()).collect())
    }

    /// An identify or validate station's first pose: the candidate on side
    /// +1 whose approach is closest to the mean approach.
    pub(super) fn first_pose(&self, site: &Site) -> Option<usize> {
        let mean = self.mean_approach(&site.position);
        site.candidates
            .iter()
            .enumerate()
            .filter(|(_, c)| c.side == 1)
            .map(|(i, c)| (i, (c.rotation * Vector3::z()).dot(&mean)))
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    }

    /// The estimate the criterion linearises about: nominal model, guess.
    pub(super) fn estimate(&self) -> Estimate {
        Estimate {
            robot: self.config.robot.clone(),
            flange_from_sensor: self.config.flange_from_sensor,
            mount: crate::engine::base::session::Mount::Flange,
        }
    }

    pub(super) fn sighting(id: &str, c: &Candidate) -> Sighting {
        Sighting {
            id: id.to_owned(),
            joints: c.joints.to_vec(),
            flange: None,
            centre_in_sensor: c.centre,
        }
    }

    /// The sensor-frame covariance of a planned centre on `side`.
    pub(super) fn sensor_covariance(&self, side: i8) -> Matrix3<f64> {
        stripe_centre_covariance(
            self.config.radius(),
            self.config.design.cut_angle,
            side,
            self.config.stripe_sigma,
        )
    }

    pub(super) fn info(&self, c: &Candidate, estimated: &[usize]) -> Info {
        let est = self.estimate();
        let s = Self::sighting("candidate", c);
        let (_, full) = sensitivity(&est, &s);
        let a = DMatrix::from_fn(3, estimated.len(), |i, j| {
            full[(i, estimated[j])] / unknown_scale(estimated[j])
        });
        let cov = ml::noise::base_covariance(
            &est,
            &s,
            &self.sensor_covariance(c.side),
            self.config.joint_sigma_deg,
            0.0,
        );
        let w = cov.try_inverse().unwrap_or_else(Matrix3::zeros);
        Info { a, w }
    }

    /// A session and its prepared centres for `ml`'s analysis: the given
    /// poses at their stations, reference distances between consecutive
    /// validate stations, the planned centres with the stripe covariance.
    pub(super) fn analysis_input(
        &self,
        poses: &[(String, Use, Candidate)],
        validate: &[(String, Vector3<f64>)],
    ) -> (Session, Prepared) {
        let c = self.config;
        let mut measurements = Vec::with_capacity(poses.len());
        let mut prepared = Vec::with_capacity(poses.len());
        for (index, (station, usage, cand)) in poses.iter().enumerate() {
            measurements.push(Measurement {
                id: format!("m{}", index + 1),
                station: station.clone(),
                usage: *usage,
                side_given: Some(cand.side),
                side: cand.side,
                joints: cand.joints.to_vec(),
                flange: None,
                observation: Observation::Centre(cand.centre),
            });
            prepared.push(solve::PreparedMeasurement {
                index,
                centre_in_sensor: cand.centre,
                covariance: Some(self.sensor_covariance(cand.side)),
                stripe: None,
            });
        }
        let reference_distances = validate
            .windows(2)
            .map(|w| ReferenceDistance {
                from: w[0].0.clone(),
                to: w[1].0.clone(),
                distance: (w[1].1 - w[0].1).norm(),
            })
            .collect();
        let session = Session {
            base_given: false,
            flange_given: false,
            sensor_range: c.range,
            hand_eye: Some(c.flange_from_sensor),
            reference_distances,
            ..Session::made(
                "plan".to_owned(),
                c.robot.clone(),
                c.design.diameter,
                measurements,
            )
        };
        let prepared = Prepared {
            measurements: prepared,
            hand_eye_initial: c.flange_from_sensor,
            hand_eye_source: HandEyeSource::File,
            warnings: Vec::new(),
        };
        (session, prepared)
    }

    /// `ml`'s analysis (no update: the nominal model fits the planned
    /// centres exactly) of a session.
    pub(super) fn analyse(
        &self,
        session: &Session,
        prepared: &Prepared,
    ) -> Result<MlReport, PlanError> {
        ml::analyse(session, prepared, &self.analysis_options()).map_err(PlanError::Analysis)
    }

    /// `ml`'s settings for the planner's analyses: no update, the plan's
    /// joint noise, no cross-validation.
    fn analysis_options(&self) -> Options {
        Options {
            method: Method::Ml,
            threshold: 0.0,
            max_iterations: 0,
            paper: crate::engine::calibrate::solve::paper::PaperOptions::default(),
            ml: MlOptions {
                joint_sigma_deg: self.config.joint_sigma_deg,
                cross_validation: false,
                ..MlOptions::default()
            },
            held_out: false,
        }
    }

    /// The parameters `ml` estimates from every identify candidate (its
    /// identifiable set; [`ml::identifiable`]). `step` is told each of
    /// the analysis's looks at the cancel (see [`analysis_steps`]) and
    /// may cancel.
    pub(super) fn pool_estimated(
        &self,
        sites: &[Site],
        step: &mut dyn FnMut() -> Control,
    ) -> Result<Vec<String>, PlanError> {
        let poses: Vec<(String, Use, Candidate)> = sites
            .iter()
            .enumerate()
            .filter(|(_, s)| s.role == StationRole::Identify)
            .flat_map(|(k, s)| {
                s.candidates
                    .iter()
                    .map(move |c| (format!("S{k}"), Use::Identify, c.clone()))
            })
            .collect();
        let (session, prepared) = self.analysis_input(&poses, &[]);
        ml::identifiable(&session, &prepared, &self.analysis_options(), &mut |_| {
            step()
        })
        .map_err(PlanError::Analysis)?
        .ok_or(PlanError::Cancelled)
    }

    /// `ml`'s analysis of the plan's identify and validate poses.
    pub(super) fn plan_report(&self, plan: &Plan) -> Result<MlReport, PlanError> {
        let poses: Vec<(String, Use, Candidate)> = plan
            .poses
            .iter()
            .filter(|p| matches!(p.usage, Use::Identify | Use::Validate))
            .map(|p| (p.station.clone(), p.usage, pose_candidate(p)))
            .collect();
        let validate: Vec<(String, Vector3<f64>)> = plan
            .stations
            .iter()
            .filter(|s| s.role == StationRole::Validate)
            .map(|s| (s.id.clone(), s.position))
            .collect();
        let (session, prepared) = self.analysis_input(&poses, &validate);
        self.analyse(&session, &prepared)
    }

    /// `Q` of the range criterion ([`AlignedGrid::weight`]) over `range`
    /// at the working poses: the chosen validate poses (at most
    /// [`RANGE_POSES`], evenly), else each identify station's first pose.
    pub(super) fn range_weight(
        &self,
        sites: &[Site],
        estimated: &[usize],
        range: &SensorRange,
    ) -> DMatrix<f64> {
        let mut working: Vec<&Candidate> = sites
            .iter()
            .filter(|s| s.role == StationRole::Validate)
            .flat_map(|s| s.chosen.iter().map(|&i| &s.candidates[i]))
            .collect();
        if working.is_empty() {
            working = sites
                .iter()
                .filter(|s| s.role == StationRole::Identify)
                .filter_map(|s| self.first_pose(s).map(|i| &s.candidates[i]))
                .collect();
        }
        let stride = working.len().div_ceil(RANGE_POSES).max(1);
        let est = self.estimate();
        let poses: Vec<PoseSensitivity> = working
            .iter()
            .step_by(stride)
            .map(|c| PoseSensitivity::new(&est, &Self::sighting("working", c)))
            .collect();
        let scale: Vec<f64> = estimated.iter().map(|&k| unknown_scale(k)).collect();
        AlignedGrid::new(&est, &poses, estimated, &scale, range).weight()
    }

    /// The box of the working volume (base frame, mm): the station box
    /// about the sphere, or the box the explicit stations span.
    pub(super) fn volume_box(&self) -> (Vector3<f64>, Vector3<f64>) {
        let c = self.config;
        match &c.stations {
            StationLayout::Box { size } => {
                let centre = Vector3::from(c.design.sphere);
                let half = Vector3::from(*size) / 2.0;
                (centre - half, centre + half)
            }
            StationLayout::Explicit { identify, validate } => identify.iter().chain(validate).fold(
                (
                    Vector3::from(c.design.sphere),
                    Vector3::from(c.design.sphere),
                ),
                |(lo, hi), p| {
                    let p = Vector3::from(*p);
                    (lo.inf(&p), hi.sup(&p))
                },
            ),
        }
    }

    /// Poses sampled over the working volume: [`VOLUME_SAMPLES`] places
    /// uniform in [`Self::volume_box`], at each a viewing axis (the flange
    /// approach) tilted [`VOLUME_TILT_DEG`] from straight down toward an
    /// azimuth within [`VOLUME_ARC_DEG`] about the horizontal direction
    /// from the robot base to the place, and a spin within `±spin_deg`
    /// about it from the reference roll (the flange x axis toward the
    /// station, horizontally away from the robot), the sphere at the
    /// planned centre on alternating sides; the first reachable IK branch
    /// (up to [`VOLUME_TRIES`] draws per place; a place out of reach is
    /// dropped).
    pub(super) fn volume_samples(&self, rng: &mut ChaCha8Rng) -> Vec<Candidate> {
        let c = self.config;
        let (lo, hi) = self.volume_box();
        let spin = c.spin_deg.to_radians();
        let base = self.config.robot.base.translation.vector;
        let mut out = Vec::with_capacity(VOLUME_SAMPLES);
        for k in 0..VOLUME_SAMPLES {
            let place = Vector3::from_fn(|i, _| random::uniform(rng, lo[i], hi[i]));
            let side: i8 = if k % 2 == 0 { 1 } else { -1 };
            let outward = {
                let d = place - base;
                let h = Vector3::new(d.x, d.y, 0.0);
                if h.norm() > 1e-9 {
                    h.normalize()
                } else {
                    Vector3::x()
                }
            };
            for _ in 0..VOLUME_TRIES {
                let tilt =
                    random::uniform(rng, VOLUME_TILT_DEG[0], VOLUME_TILT_DEG[1]).to_radians();
                let azimuth = outward.y.atan2(outward.x)
                    + random::uniform(rng, -VOLUME_ARC_DEG / 2.0, VOLUME_ARC_DEG / 2.0)
                        .to_radians();
                let approach_dir = Vector3::new(
                    tilt.sin() * azimuth.cos(),
                    tilt.sin() * azimuth.sin(),
                    -tilt.cos(),
                );
                let turn = random::uniform(rng, -spin, spin);
                let reference = outward - approach_dir * outward.dot(&approach_dir);
                let x0 = if reference.norm() > 1e-9 {
                    reference.normalize()
                } else {
                    approach_dir.cross(&Vector3::y()).normalize()
                };
                let x = UnitQuaternion::from_axis_angle(
                    &nalgebra::Unit::new_normalize(approach_dir),
                    turn,
                ) * x0;
                let y = approach_dir.cross(&x);
                let rotation = UnitQuaternion::from_rotation_matrix(
                    &nalgebra::Rotation3::from_basis_unchecked(&[x, y, approach_dir]),
                );
                let offset = self.offset(rng);
                if let Some(found) = self
                    .candidates_at(&place, &rotation, &(c.centre(side) + offset), side)
                    .into_iter()
                    .next()
                {
                    out.push(found);
                    break;
                }
            }
        }
        out
    }

    /// The working volume's aligned grid over `estimated`: the sphere
    /// centre seen at each of `samples` (see [`AlignedGrid::at_points`]).
    pub(super) fn volume_grid(&self, samples: &[Candidate], estimated: &[usize]) -> AlignedGrid {
        let est = self.estimate();
        let points: Vec<(PoseSensitivity, Vector3<f64>)> = samples
            .iter()
            .map(|c| {
                (
                    PoseSensitivity::new(&est, &Self::sighting("volume", c)),
                    c.centre,
                )
            })
            .collect();
        let scale: Vec<f64> = estimated.iter().map(|&k| unknown_scale(k)).collect();
        AlignedGrid::at_points(&est, &points, estimated, &scale)
    }

    /// Condition number of the whitened, scaled Jacobian of `estimated`
    /// over the plan's identify poses (station centres eliminated).
    pub(super) fn condition(&self, plan: &Plan, estimated: &[usize]) -> f64 {
        let k = estimated.len();
        let mut m = DMatrix::zeros(k, k);
        for s in plan
            .stations
            .iter()
            .filter(|s| s.role == StationRole::Identify)
        {
            let infos: Vec<Info> = plan
                .poses
                .iter()
                .filter(|p| p.station == s.id && p.usage == Use::Identify)
                .map(|p| self.info(&pose_candidate(p), estimated))
                .collect();
            let all: Vec<usize> = (0..infos.len()).collect();
            m += StationInfo::of(&infos, &all, k).schur();
        }
        let Some(eig) = nalgebra::SymmetricEigen::try_new(
            m,
            f64::EPSILON,
            crate::engine::base::numeric::MAX_DECOMPOSITION_SWEEPS,
        )
        .map(|e| e.eigenvalues) else {
            return f64::INFINITY;
        };
        let max = eig.iter().copied().fold(0.0_f64, f64::max);
        let min = eig.iter().copied().fold(f64::INFINITY, f64::min);
        if min > 0.0 {
            (max / min).sqrt()
        } else {
            f64::INFINITY
        }
    }
}

pub(super) fn pose_candidate(p: &PlannedPose) -> Candidate {
    let mut joints = [0.0; DOF];
    for (j, v) in joints.iter_mut().zip(&p.joints) {
        *j = *v;
    }
    Candidate {
        joints,
        side: p.side,
        centre: p.centre_in_sensor,
        rotation: p.base_from_flange.rotation,
    }
}

/// The collinearity check of eq. 6-7 on the planned translations.
pub(super) fn check_translations(robot: &Robot, poses: &[Candidate]) -> Result<(), PlanError> {
    let p: Vec<Vector3<f64>> = poses
        .iter()
        .map(|c| robot.base_from_flange(&c.joints).translation.vector)
        .collect();
    let d = DMatrix::from_fn(3, p.len() - 1, |i, k| p[k + 1][i] - p[0][i]);
    let sv = d.singular_values();
    let (s1, s2) = (sv[0], if sv.len() > 1 { sv[1] } else { 0.0 });
    if s1 <= 0.0 || s2 / s1 < MIN_TRANSLATION_SPREAD {
        return Err(PlanError::CollinearTranslations {
            detail: format!(
                "the flange displacements have σ₂/σ₁ = {:.3} (at least {MIN_TRANSLATION_SPREAD} needed)",
                if s1 > 0.0 { s2 / s1 } else { 0.0 }
            ),
        });
    }
    Ok(())
}

/// Covariance (mm², sensor frame) of the sphere centre of a stripe whose
/// laser plane cuts a sphere of `radius` at `cut_deg`, with `sigma` (mm)
/// noise on the points: the circle fit's `(y_c, z_c, r)` covariance
/// `σ²·(JᵀJ)⁻¹` for the points the simulator draws (the arc facing the
/// camera, 0.5 mm apart over ±55°), carried to `x = side·sqrt(R² − r²)`
/// (eq. 21: `∂x/∂r = −side·r/t`).
#[must_use]
pub fn stripe_centre_covariance(radius: f64, cut_deg: f64, side: i8, sigma: f64) -> Matrix3<f64> {
    let sim = SimConfig::default();
    let r = radius * cut_deg.to_radians().cos();
    let t = radius * cut_deg.to_radians().sin();
    let half = sim.arc_half_angle.to_radians();
    let arc = 2.0 * half * r;
    let n = ((arc / sim.point_spacing).floor().max(0.0) as usize + 1).max(3);
    let mut jtj = Matrix3::zeros();
    for k in 0..n {
        let phi = -half + 2.0 * half * k as f64 / (n - 1) as f64;
        // Residual of a point along the circle normal: ∂/∂(y_c, z_c, r).
        let row = Vector3::new(-phi.sin(), -phi.cos(), -1.0);
        jtj += row * row.transpose();
    }
    let fit = jtj.try_inverse().unwrap_or_else(Matrix3::zeros) * sigma * sigma;
    // (x, y, z) from (y_c, z_c, r).
    let dx_dr = -f64::from(side) * r / t;
    let jac = Matrix3::new(0.0, 0.0, dx_dr, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0);
    jac * fit * jac.transpose()
}
