//! Simulated scans of parts with a known geometry, for measuring: a plane,
//! a sphere artefact (three spheres, each seen from many poses) and a
//! stepped block on a table, scanned along a path by the cell of a
//! [`SimConfig`] (the same true robot and hand-eye as the session of the
//! same seed, robot and error model, so the session's calibration measures
//! the scan). The output is what a cell leaves: a joint log (recorded
//! joints with reading noise, the nominal flange pose) and one profile a
//! pose (`y,z`, mm; a ray that meets nothing is `nan,nan`), and the
//! [`ScanTruth`]: the part in the base frame, the true robot, hand-eye and
//! actual joints.
//!
//! # The sensor
//!
//! The laser plane is the sensor's `x = 0` plane and the sensor looks
//! along its −z axis (its z axis points back to the flange, as in the
//! calibration's geometry): profile point `k` is where the ray from `(0,
//! y_k, z_max)` along −z first meets the part within the depth range,
//! `y_k` every [`RAY_SPACING_MM`] over the line. Gaussian noise of
//! `stripe_noise` on `y` and `z`, rounded to `stripe_decimals`.
//!
//! # Paths
//!
//! Every part faces the workspace's eye point (its normal `n` points from
//! the workspace's centre to the eye), the mean approach direction of the
//! cell. A plane and the block are swept along a straight line with the
//! sensor's z along `n` (the block's scans tilted by [`STEP_TILT_DEG`] in
//! the laser plane, so the rays also meet the steps' risers); each sphere
//! is seen from poses whose approach directions spread over a cone, the
//! laser plane cutting it at offsets across the sphere.

use std::fmt::Write as _;

use nalgebra::{Isometry3, Point3, Rotation3, Translation3, Unit, UnitQuaternion, Vector3};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::config::{SimConfig, SimError, validate_config};
use super::truth::{OrderedMap, TruthRobot};
use super::{JOINT_DECIMALS, true_cell};
use crate::engine::base::cell::joint_log;
use crate::engine::base::cell::random::{normal, stream};
use crate::engine::base::cell::sensor::paper_hand_eye_rows;
use crate::engine::base::cell::workspace::{Workspace, planning_limits};
use crate::engine::base::geometry::{rigid_from_rows, rows_from_isometry, wrap_deg};
use crate::engine::base::numeric::round_to;
use crate::engine::base::robot::ik::{Chain, DOF};
use crate::engine::base::session::{SensorRange, Use};

/// `"format"` of a scan truth file.
pub const SCAN_TRUTH_FORMAT: &str = "spherecal-scan-truth";

/// Stream id of a scan's noise (the session's are 0-2).
const STREAM_SCAN: u64 = 3;

/// Spacing of the rays along the laser line, mm (a line sensor's pitch).
pub const RAY_SPACING_MM: f64 = 0.25;

/// Length of the straight path over a plane or the block, mm.
pub const PATH_LENGTH_MM: f64 = 60.0;

/// Tilt of the block's scans in the laser plane, deg: rays at an angle to
/// the steps' vertical risers meet them.
pub const STEP_TILT_DEG: f64 = 15.0;

/// Half-angle of the cone of approach directions to a sphere, deg.
pub const SPHERE_CONE_DEG: f64 = 30.0;

/// The artefact's spheres stand this far from the workspace centre, mm.
pub const SPHERE_SPACING_MM: f64 = 150.0;

/// What part is scanned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PartKind {
    /// A plane.
    Plane,
    /// Three spheres of the configuration's diameter.
    Spheres,
    /// A block of four steps on a table.
    Steps,
}

impl PartKind {
    /// Parses `plane`, `spheres` or `steps`.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "plane" => Some(Self::Plane),
            "spheres" | "sphere" => Some(Self::Spheres),
            "steps" | "block" => Some(Self::Steps),
            _ => None,
        }
    }
}

/// A scan to simulate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanConfig {
    /// The part.
    pub part: PartKind,
    /// Poses along the path (a plane or the block), or per sphere.
    pub poses: usize,
    /// The sensor's field in the laser plane, mm: `y` the line, `z` depth.
    pub range: SensorRange,
}

impl Default for ScanConfig {
    fn default() -> Self {
        Self {
            part: PartKind::Plane,
            poses: 40,
            range: SensorRange {
                y: [-40.0, 40.0],
                z: [-40.0, 40.0],
            },
        }
    }
}

/// One step of the block: its top face over `x` (block frame, mm).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Step {
    /// `[from, to]` along the block's x, mm.
    pub x: [f64; 2],
    /// Height of its top face above the table, mm.
    pub height: f64,
}

/// The scanned part in the base frame (mm): the truth the cloud is
/// compared with.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum Part {
    /// The plane through `point` with unit normal `normal`.
    Plane {
        /// A point of the plane.
        point: [f64; 3],
        /// Its unit normal (toward the sensor).
        normal: [f64; 3],
    },
    /// Spheres of one diameter at the stations.
    Spheres {
        /// Diameter, mm.
        diameter: f64,
        /// Centre of each sphere, by station id.
        centres: OrderedMap<[f64; 3]>,
    },
    /// Steps on a table: in the block frame the table is `z = 0`, step `k`
    /// the rectangle `x ∈ steps[k].x`, `|y| ≤ width / 2` at `z =
    /// height`, with vertical risers between neighbours.
    Steps {
        /// `base_from_block`, 4×4 rows.
        base_from_block: [[f64; 4]; 4],
        /// Width along the block's y, mm.
        width: f64,
        /// The steps in order of x.
        steps: Vec<Step>,
    },
}

/// A flat face: the parallelogram `origin + s·u + t·v`, `s, t ∈ [0, 1]`.
#[derive(Debug, Clone, Copy)]
struct Face {
    origin: Vector3<f64>,
    u: Vector3<f64>,
    v: Vector3<f64>,
}

impl Face {
    /// The ray parameter of `o + λ·d` on the face, if it meets it.
    fn hit(&self, o: &Vector3<f64>, d: &Vector3<f64>) -> Option<f64> {
        let n = self.u.cross(&self.v);
        let denom = n.dot(d);
        if denom.abs() < 1e-12 {
            return None;
        }
        let lambda = n.dot(&(self.origin - o)) / denom;
        let (s, t) = self.coordinates(&(o + d * lambda));
        ((0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t)).then_some(lambda)
    }

    /// `(s, t)` of the projection of `p` on the face's plane.
    fn coordinates(&self, p: &Vector3<f64>) -> (f64, f64) {
        let r = p - self.origin;
        let (uu, uv, vv) = (
            self.u.dot(&self.u),
            self.u.dot(&self.v),
            self.v.dot(&self.v),
        );
        let (ru, rv) = (r.dot(&self.u), r.dot(&self.v));
        let det = uu * vv - uv * uv;
        ((ru * vv - rv * uv) / det, (rv * uu - ru * uv) / det)
    }

    /// Distance from `p` to the face (axis-aligned rectangles: the
    /// clamped projection).
    fn distance(&self, p: &Vector3<f64>) -> f64 {
        let (s, t) = self.coordinates(p);
        let q = self.origin + self.u * s.clamp(0.0, 1.0) + self.v * t.clamp(0.0, 1.0);
        (p - q).norm()
    }
}

/// The block's faces in the block frame: the table around the block
/// (a square of [`TABLE_HALF_MM`]), the tops and the risers.
fn block_faces(width: f64, steps: &[Step]) -> Vec<Face> {
    let w = width / 2.0;
    let mut faces = Vec::new();
    let (Some(first), Some(last)) = (steps.first(), steps.last()) else {
        return faces;
    };
    let (x0, x1) = (first.x[0], last.x[1]);
    let table = |xa: f64, xb: f64, ya: f64, yb: f64| Face {
        origin: Vector3::new(xa, ya, 0.0),
        u: Vector3::new(xb - xa, 0.0, 0.0),
        v: Vector3::new(0.0, yb - ya, 0.0),
    };
    let h = TABLE_HALF_MM;
    faces.push(table(-h, x0, -h, h));
    faces.push(table(x1, h, -h, h));
    faces.push(table(x0, x1, -h, -w));
    faces.push(table(x0, x1, w, h));
    let mut previous = 0.0;
    for s in steps {
        faces.push(Face {
            origin: Vector3::new(s.x[0], -w, s.height),
            u: Vector3::new(s.x[1] - s.x[0], 0.0, 0.0),
            v: Vector3::new(0.0, width, 0.0),
        });
        faces.push(Face {
            origin: Vector3::new(s.x[0], -w, previous),
            u: Vector3::new(0.0, 0.0, s.height - previous),
            v: Vector3::new(0.0, width, 0.0),
        });
        previous = s.height;
    }
    faces.push(Face {
        origin: Vector3::new(x1, -w, 0.0),
        u: Vector3::new(0.0, 0.0, previous),
        v: Vector3::new(0.0, width, 0.0),
    });
    faces
}

/// Half the side of the table square around the block, mm.
const TABLE_HALF_MM: f64 = 150.0;

impl Part {
    /// The first hit of the ray `o + λ·d` (base frame, `d` unit) with the
    /// part, as `λ` (mm), if any.
    #[must_use]
    pub fn hit(&self, o: &Vector3<f64>, d: &Vector3<f64>) -> Option<f64> {
        match self {
            Self::Plane { point, normal } => {
                let n = Vector3::from(*normal);
                let denom = n.dot(d);
                (denom.abs() > 1e-12).then(|| n.dot(&(Vector3::from(*point) - o)) / denom)
            }
            Self::Spheres { diameter, centres } => centres
                .iter()
                .filter_map(|(_, c)| {
                    let r = diameter / 2.0;
                    let oc = o - Vector3::from(*c);
                    let b = oc.dot(d);
                    let disc = b * b - (oc.norm_squared() - r * r);
                    (disc >= 0.0).then(|| -b - disc.sqrt())
                })
                .min_by(f64::total_cmp),
            Self::Steps {
                base_from_block,
                width,
                steps,
            } => {
                let inv = rigid_from_rows(base_from_block).inverse();
                let (ob, db) = ((inv * Point3::from(*o)).coords, inv.rotation * d);
                block_faces(*width, steps)
                    .iter()
                    .filter_map(|f| f.hit(&ob, &db))
                    .filter(|l| *l > 0.0)
                    .min_by(f64::total_cmp)
            }
        }
    }

    /// The distance (mm) of the base-frame point `p` from the part's
    /// surface.
    #[must_use]
    pub fn distance(&self, p: &Vector3<f64>) -> f64 {
        match self {
            Self::Plane { point, normal } => Vector3::from(*normal)
                .dot(&(p - Vector3::from(*point)))
                .abs(),
            Self::Spheres { diameter, centres } => centres
                .iter()
                .map(|(_, c)| ((p - Vector3::from(*c)).norm() - diameter / 2.0).abs())
                .fold(f64::INFINITY, f64::min),
            Self::Steps {
                base_from_block,
                width,
                steps,
            } => {
                let pb = (rigid_from_rows(base_from_block).inverse() * Point3::from(*p)).coords;
                block_faces(*width, steps)
                    .iter()
                    .map(|f| f.distance(&pb))
                    .fold(f64::INFINITY, f64::min)
            }
        }
    }
}

/// The truth of a simulated scan (format `spherecal-scan-truth`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScanTruth {
    /// [`SCAN_TRUTH_FORMAT`].
    pub format: String,
    /// 1.
    pub version: u32,
    /// The seed of the cell (the session of the same seed has the same
    /// true robot).
    pub seed: u64,
    /// The true robot.
    pub robot: TruthRobot,
    /// The nominal robot.
    pub nominal: TruthRobot,
    /// The true hand-eye `flange_from_sensor`, 4×4 rows, mm.
    pub hand_eye: [[f64; 4]; 4],
    /// The part, base frame.
    pub part: Part,
    /// Each pose's actual joints (deg), by pose id.
    pub poses: OrderedMap<Vec<f64>>,
}

/// A simulated scan: the files a cell leaves and the truth.
#[derive(Debug, Clone, PartialEq)]
pub struct SimulatedScan {
    /// The joint log: `id,station,use,side,j1..jn,x,y,z,q1..q4` (use
    /// `validate`; the station is the sphere, or `part`).
    pub joints_csv: String,
    /// One profile per pose: `(id, "y,z" CSV text)`, mm.
    pub profiles: Vec<(String, String)>,
    /// For the artefact: `from,to,distance` (mm) between its spheres, the
    /// true distances (a calibrated artefact's certificate).
    pub references_csv: Option<String>,
    /// The truth.
    pub truth: ScanTruth,
}

/// A sensor pose: origin and the sensor's z (toward the flange) and x
/// axes, base frame.
fn sensor_pose(origin: Vector3<f64>, z: Vector3<f64>, x: Vector3<f64>) -> Isometry3<f64> {
    let z = z.normalize();
    let x = (x - z * x.dot(&z)).normalize();
    let y = z.cross(&x);
    let r = Rotation3::from_basis_unchecked(&[x, y, z]);
    Isometry3::from_parts(
        Translation3::from(origin),
        UnitQuaternion::from_rotation_matrix(&r),
    )
}

/// A unit vector perpendicular to `n`.
fn perpendicular(n: &Vector3<f64>) -> Vector3<f64> {
    let a = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    n.cross(&a).normalize()
}

/// The part and the sensor poses (base frame) with their stations.
fn layout(
    scan: &ScanConfig,
    workspace: &Workspace,
    diameter: f64,
) -> (Part, Vec<(String, Isometry3<f64>)>) {
    let centre = workspace.centre();
    let n = (Vector3::from(workspace.eye) - centre).normalize();
    let e1 = perpendicular(&n);
    let e2 = n.cross(&e1);
    let along = |k: usize| {
        if scan.poses < 2 {
            0.0
        } else {
            -PATH_LENGTH_MM / 2.0 + PATH_LENGTH_MM * k as f64 / (scan.poses - 1) as f64
        }
    };
    let station = |s: &str| s.to_string();
    match scan.part {
        PartKind::Plane => {
            let part = Part::Plane {
                point: centre.into(),
                normal: n.into(),
            };
            let poses = (0..scan.poses)
                .map(|k| (station("part"), sensor_pose(centre + e1 * along(k), n, e1)))
                .collect();
            (part, poses)
        }
        PartKind::Steps => {
            let steps: Vec<Step> = (0..4)
                .map(|k| Step {
                    x: [-40.0 + 20.0 * f64::from(k), -20.0 + 20.0 * f64::from(k)],
                    height: 8.0 * f64::from(k + 1),
                })
                .collect();
            // Block frame: z along n, x along the laser line e2.
            let base_from_block = sensor_pose(centre, n, e2);
            let tilt = UnitQuaternion::from_axis_angle(
                &Unit::new_normalize(e1),
                -STEP_TILT_DEG.to_radians(),
            );
            let mid = centre + n * 16.0;
            let poses = (0..scan.poses)
                .map(|k| {
                    let p = sensor_pose(mid + e1 * along(k), tilt * n, e1);
                    (station("part"), p)
                })
                .collect();
            let part = Part::Steps {
                base_from_block: rows_from_isometry(&base_from_block),
                width: 60.0,
                steps,
            };
            (part, poses)
        }
        PartKind::Spheres => {
            let r = diameter / 2.0;
            let places = [
                ("A", centre - e1 * SPHERE_SPACING_MM),
                ("B", centre + e1 * SPHERE_SPACING_MM),
                ("C", centre + e2 * SPHERE_SPACING_MM),
            ];
            let mut poses = Vec::new();
            for (id, c) in &places {
                for k in 0..scan.poses {
                    // Approach directions on a cone about n (and n itself),
                    // cuts across the sphere at -0.6R … 0.6R.
                    let azimuth = 2.399_963 * k as f64;
                    let tilt = if k == 0 {
                        0.0
                    } else {
                        SPHERE_CONE_DEG.to_radians()
                    };
                    let axis = e1 * azimuth.cos() + e2 * azimuth.sin();
                    let a = UnitQuaternion::from_axis_angle(&Unit::new_normalize(axis), tilt) * n;
                    let x = perpendicular(&a);
                    let cut = if scan.poses < 2 {
                        0.0
                    } else {
                        r * (-0.6 + 1.2 * k as f64 / (scan.poses - 1) as f64)
                    };
                    poses.push((station(id), sensor_pose(c + a * r + x * cut, a, x)));
                }
            }
            let part = Part::Spheres {
                diameter,
                centres: OrderedMap(
                    places
                        .iter()
                        .map(|(id, c)| ((*id).to_string(), (*c).into()))
                        .collect(),
                ),
            };
            (part, poses)
        }
    }
}

/// Simulates a scan (module doc) with the cell of `config` (its seed,
/// robot, error model, joint and stripe noise, sphere diameter).
///
/// # Errors
/// [`SimError::InvalidConfig`] for settings out of range,
/// [`SimError::Unreachable`] when a pose of the path cannot be reached.
pub fn simulate_scan(config: &SimConfig, scan: &ScanConfig) -> Result<SimulatedScan, SimError> {
    validate_config(config)?;
    if scan.poses == 0 || scan.poses > 100_000 {
        return Err(SimError::InvalidConfig(format!(
            "scan poses must be within 1..100000, found {}",
            scan.poses
        )));
    }
    let (preset, true_robot, _) = true_cell(config)?;
    let nominal = preset.robot.clone();
    let chain = Chain::new(&true_robot).ok_or_else(|| {
        SimError::InvalidConfig(format!(
            "the simulator plans for 6-axis arms, {} has {}",
            nominal.name,
            nominal.dof()
        ))
    })?;
    let limits = planning_limits(config.robot, &preset.limits);
    let hand_eye_rows = paper_hand_eye_rows();
    let flange_from_sensor = rigid_from_rows(&hand_eye_rows);
    let workspace = config
        .workspace
        .unwrap_or_else(|| Workspace::for_robot(config.robot));
    let (part, poses) = layout(scan, &workspace, config.diameter);
    let mut rng = stream(config.seed, STREAM_SCAN);
    let mut previous: Option<[f64; DOF]> = None;
    let mut rows_data = Vec::with_capacity(poses.len());
    let mut profiles = Vec::with_capacity(poses.len());
    let mut truths = Vec::with_capacity(poses.len());
    for (k, (station, base_from_sensor)) in poses.iter().enumerate() {
        let id = format!("s{}", k + 1);
        let target = base_from_sensor * flange_from_sensor.inverse();
        let guesses = chain.arm_guess_grid(&target, &limits);
        let solutions = chain.solutions(&target, &guesses, &limits, config.min_wrist_angle);
        let nearest = |q: &[f64; DOF]| {
            previous.map_or(0.0, |p| {
                p.iter().zip(q).map(|(a, b)| wrap_deg(a - b).abs()).sum()
            })
        };
        let actual = solutions
            .into_iter()
            .min_by(|a, b| nearest(a).total_cmp(&nearest(b)))
            .ok_or_else(|| {
                SimError::Unreachable(super::poses::unreachable_after(
                    format!("{station} (scan pose {id})"),
                    base_from_sensor.translation.vector.into(),
                    1,
                ))
            })?;
        previous = Some(actual);
        let recorded: Vec<f64> = actual
            .iter()
            .map(|q| round_to(q + config.joint_noise * normal(&mut rng), JOINT_DECIMALS))
            .collect();
        // The true sensor pose: the true robot at the actual joints.
        let truly = true_robot.base_from_flange(&actual) * flange_from_sensor;
        profiles.push((id.clone(), profile(config, scan, &part, &truly, &mut rng)));
        truths.push((id.clone(), actual.to_vec()));
        rows_data.push((id, station.clone(), recorded));
    }
    let rows: Vec<joint_log::Row> = rows_data
        .iter()
        .map(|(id, station, q)| joint_log::Row {
            id,
            station,
            usage: Use::Validate,
            side: 1,
            joints: q,
            flange: nominal.base_from_flange(q),
            extra: Vec::new(),
        })
        .collect();
    let joints_csv = joint_log::write(
        &[format!(
            "simulated scan of a {:?} part, {} poses, seed {}",
            scan.part,
            rows.len(),
            config.seed
        )],
        nominal.dof(),
        &[],
        &rows,
    );
    let references_csv = match &part {
        Part::Spheres { centres, .. } => {
            let mut text = String::from("from,to,distance\n");
            for pair in centres.0.windows(2) {
                let d = (Vector3::from(pair[1].1) - Vector3::from(pair[0].1)).norm();
                let _ = writeln!(text, "{},{},{d}", pair[0].0, pair[1].0);
            }
            Some(text)
        }
        _ => None,
    };
    Ok(SimulatedScan {
        joints_csv,
        profiles,
        references_csv,
        truth: ScanTruth {
            format: SCAN_TRUTH_FORMAT.into(),
            version: 1,
            seed: config.seed,
            robot: TruthRobot::from_robot(&true_robot),
            nominal: TruthRobot::from_robot(&nominal),
            hand_eye: hand_eye_rows,
            part,
            poses: OrderedMap(truths),
        },
    })
}

/// One profile: each ray of the line against the part (module doc), as
/// `y,z` CSV text; a miss is `nan,nan`.
fn profile(
    config: &SimConfig,
    scan: &ScanConfig,
    part: &Part,
    base_from_sensor: &Isometry3<f64>,
    rng: &mut ChaCha8Rng,
) -> String {
    let [y0, y1] = scan.range.y;
    let [z0, z1] = scan.range.z;
    // Truncation intended: whole rays over the line.
    let rays = ((y1 - y0) / RAY_SPACING_MM).floor() as usize + 1;
    let d = base_from_sensor.rotation * -Vector3::z();
    let mut text = String::from("y,z\n");
    for k in 0..rays {
        let y = y0 + RAY_SPACING_MM * k as f64;
        let o = (base_from_sensor * Point3::new(0.0, y, z1)).coords;
        match part.hit(&o, &d) {
            Some(lambda) if lambda >= 0.0 && z1 - lambda >= z0 => {
                let z = z1 - lambda;
                let noisy = |v: f64, rng: &mut ChaCha8Rng| {
                    round_to(
                        v + config.stripe_noise * normal(rng),
                        config.stripe_decimals,
                    )
                };
                let (yn, zn) = (noisy(y, rng), noisy(z, rng));
                let _ = writeln!(text, "{yn},{zn}");
            }
            _ => text.push_str("nan,nan\n"),
        }
    }
    text
}

/// A text that is not a scan truth.
#[derive(Debug, thiserror::Error)]
pub enum ScanTruthError {
    /// Not JSON, or not the truth's shape.
    #[error("not a scan truth file: {0}")]
    Json(#[from] serde_json::Error),
    /// Another format or version.
    #[error("\"format\" {format:?} version {version}, expected \"{SCAN_TRUTH_FORMAT}\" version 1")]
    Format {
        /// The `format` found.
        format: String,
        /// The `version` found.
        version: u32,
    },
}

/// Reads a scan truth file's text.
///
/// # Errors
/// [`ScanTruthError`]: not JSON, not the truth's shape, or another format
/// or version.
pub fn parse_scan_truth(text: &str) -> Result<ScanTruth, ScanTruthError> {
    let t: ScanTruth = serde_json::from_str(text)?;
    if t.format != SCAN_TRUTH_FORMAT || t.version != 1 {
        return Err(ScanTruthError::Format {
            format: t.format,
            version: t.version,
        });
    }
    Ok(t)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn rays_meet_the_parts_where_they_are() {
        let ws = Workspace::for_robot(crate::engine::base::robot::RobotChoice::Irb2400);
        for kind in [PartKind::Plane, PartKind::Spheres, PartKind::Steps] {
            let scan = ScanConfig {
                part: kind,
                poses: 5,
                ..ScanConfig::default()
            };
            let (part, poses) = layout(&scan, &ws, 38.1);
            let mut hits = 0;
            for (_, pose) in &poses {
                let d = pose.rotation * -Vector3::z();
                for y in [-30.0, -10.0, 0.0, 5.0, 25.0] {
                    let o = (pose * Point3::new(0.0, y, 40.0)).coords;
                    if let Some(l) = part.hit(&o, &d) {
                        let p = o + d * l;
                        assert!(part.distance(&p) < 1e-9, "{kind:?}: {}", part.distance(&p));
                        hits += 1;
                    }
                }
            }
            assert!(hits >= 10, "{kind:?}: {hits}");
        }
    }
}
