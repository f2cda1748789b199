//! FORMAT.md's session rules on typed values, stated once. The file
//! loader (`format::session`) applies each where it reads the value and
//! adds the position in the file; an import, which builds its session
//! from other files, applies them all through [`Session::validate`] and
//! blames the file a broken rule came from by its measurement and key
//! ([`RuleError::measurement`], [`RuleError::key`]). Messages carry no
//! position; the caller adds it.

use nalgebra::{Isometry3, Vector3};

use super::{
    MIN_STRIPE_POINTS, Measurement, Observation, ReferenceDistance, RuleError, SensorRange,
    Session, SolverSettings, Use, limits,
};
use crate::engine::base::numeric::show;
use crate::engine::base::robot::Joint;

/// Largest `max_iterations` accepted: 2^53, the largest integer an `f64`
/// (JSON number) holds exactly. Any real value is far below.
pub const MAX_ITERATIONS_LIMIT: f64 = 9_007_199_254_740_992.0;

/// A session rule broken by one value: the key (as the file names it)
/// and what is wrong. The messages carry no position; the caller adds it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RuleViolation {
    /// Beyond a plausibility limit ([`limits`]).
    #[error(
        "{key} = {}{} is not plausible for a sphere calibration (at most {}{})",
        show(*value),
        spaced(unit),
        show(*limit),
        spaced(unit)
    )]
    Implausible {
        /// The key.
        key: String,
        /// The value.
        value: f64,
        /// The limit.
        limit: f64,
        /// Its unit (`mm`, `deg`, or empty).
        unit: String,
    },
    /// NaN or infinite.
    #[error("{key} is not a finite number")]
    NotFinite {
        /// The key.
        key: String,
    },
    /// A transform with a NaN or infinite entry.
    #[error("{key}: not a finite transform")]
    NotFiniteTransform {
        /// The key.
        key: String,
    },
    /// A transform's translation beyond the length limit.
    #[error(
        "{key}: a translation of {} mm is not plausible for a sphere calibration (at most {} mm)",
        show(*value),
        show(limits::LENGTH_MM)
    )]
    ImplausibleTranslation {
        /// The key.
        key: String,
        /// The translation coordinate at fault, mm.
        value: f64,
    },
    /// Zero, negative or not finite where a length must be positive.
    #[error("{key} must be positive (mm), found {}", show(*value))]
    NotPositive {
        /// The key.
        key: String,
        /// The value.
        value: f64,
    },
    /// Negative or not finite where zero or a positive length is wanted.
    #[error("{key} must be zero or positive (mm), found {}", show(*value))]
    Negative {
        /// The key.
        key: String,
        /// The value.
        value: f64,
    },
    /// Not an interval `[min, max]` with `min < max`.
    #[error(
        "{key} must be [min, max] with min < max (mm), found [{}, {}]",
        show(interval[0]),
        show(interval[1])
    )]
    NotAnInterval {
        /// The key.
        key: String,
        /// The interval as given.
        interval: [f64; 2],
    },
    /// Not a non-negative integer.
    #[error("{key} must be a non-negative integer, found {}", show(*value))]
    NotACount {
        /// The key.
        key: String,
        /// The value.
        value: f64,
    },
    /// An empty text.
    #[error("{key} must not be empty")]
    Empty {
        /// The key.
        key: String,
    },
    /// A side other than +1 or −1.
    #[error("{key} must be 1 or -1, found {side}")]
    NotASide {
        /// The key.
        key: String,
        /// The side given.
        side: i8,
    },
    /// Another count of joint readings than the robot has joints.
    #[error("{key} has {readings} readings, the robot has {joints} joints")]
    JointCount {
        /// The key.
        key: String,
        /// Readings given.
        readings: usize,
        /// The robot's joints.
        joints: usize,
    },
    /// A stripe with too few points (the words of the stripe fit's own
    /// refusal, `stripe::StripeError::TooFewPoints`, which comes later in
    /// the pipeline than the session's rules).
    #[error("{prefix}stripe has {points} points, at least {MIN_STRIPE_POINTS} are needed")]
    TooFewPoints {
        /// What starts the message (`measurements[3].` when the
        /// measurement has no id).
        prefix: String,
        /// Points given.
        points: usize,
    },
    /// Two distances for one pair of stations.
    #[error(
        "{key}: the pair {from} – {to} is {} mm here and {} mm in reference_distances[{first}]: two distances for one pair contradict each other; keep the right one",
        show(*distance),
        show(*other)
    )]
    ContradictingPair {
        /// The key (`reference_distances[i]`).
        key: String,
        /// One station.
        from: String,
        /// The other.
        to: String,
        /// This distance, mm.
        distance: f64,
        /// The index of the first distance of the pair.
        first: usize,
        /// The first distance, mm.
        other: f64,
    },
}

/// `unit` with a space before it, or nothing.
fn spaced(unit: &str) -> String {
    if unit.is_empty() {
        String::new()
    } else {
        format!(" {unit}")
    }
}

/// `|value| ≤ limit` (a [`limits`] constant), else "`key` = v unit is
/// not plausible for a sphere calibration (at most limit unit)".
///
/// # Errors
/// The message, without position.
pub fn plausible(value: f64, limit: f64, key: &str, unit: &str) -> Result<(), RuleViolation> {
    if value.abs() <= limit {
        return Ok(());
    }
    Err(RuleViolation::Implausible {
        key: key.to_string(),
        value,
        limit,
        unit: unit.to_string(),
    })
}

/// One MDH joint `robot.joints[i]`: each parameter plausible.
///
/// # Errors
/// The first implausible parameter.
pub fn joint(i: usize, joint: &Joint) -> Result<(), RuleViolation> {
    for (name, v, limit, unit) in [
        ("alpha", joint.alpha, limits::ANGLE_DEG, "deg"),
        ("a", joint.a, limits::LENGTH_MM, "mm"),
        ("beta", joint.beta, limits::ANGLE_DEG, "deg"),
        ("theta", joint.theta, limits::ANGLE_DEG, "deg"),
        ("d", joint.d, limits::LENGTH_MM, "mm"),
    ] {
        let key = format!("robot.joints[{i}].{name}");
        plausible(v, limit, &key, unit)?;
        if !v.is_finite() {
            return Err(RuleViolation::NotFinite { key });
        }
    }
    Ok(())
}

/// A 4×4 transform `key`: finite, its translation plausible.
///
/// # Errors
/// The message.
pub fn transform(key: &str, iso: &Isometry3<f64>) -> Result<(), RuleViolation> {
    let t = iso.translation.vector;
    if !(t.iter().all(|v| v.is_finite()) && iso.rotation.coords.iter().all(|v| v.is_finite())) {
        return Err(RuleViolation::NotFiniteTransform {
            key: key.to_string(),
        });
    }
    if let Some(value) = t.iter().copied().find(|v| v.abs() > limits::LENGTH_MM) {
        return Err(RuleViolation::ImplausibleTranslation {
            key: key.to_string(),
            value,
        });
    }
    Ok(())
}

/// `sphere.diameter`: positive and plausible.
///
/// # Errors
/// The message.
pub fn sphere_diameter(diameter: f64) -> Result<(), RuleViolation> {
    if !(diameter > 0.0 && diameter.is_finite()) {
        return Err(RuleViolation::NotPositive {
            key: "sphere.diameter".to_string(),
            value: diameter,
        });
    }
    plausible(
        diameter,
        limits::SPHERE_DIAMETER_MM,
        "sphere.diameter",
        "mm",
    )
}

/// `sensor.range`: each interval plausible with `min < max`.
///
/// # Errors
/// The message.
pub fn range(range: &SensorRange) -> Result<(), RuleViolation> {
    for (name, v) in [("y", range.y), ("z", range.z)] {
        let key = format!("sensor.range.{name}");
        for x in v {
            plausible(x, limits::SENSOR_COORDINATE_MM, &key, "mm")?;
        }
        if v[0] >= v[1] || !v.iter().all(|x| x.is_finite()) {
            return Err(RuleViolation::NotAnInterval { key, interval: v });
        }
    }
    Ok(())
}

/// `solver.threshold`: zero or positive, plausible.
///
/// # Errors
/// The message.
pub fn threshold(threshold: f64) -> Result<(), RuleViolation> {
    if !(threshold >= 0.0 && threshold.is_finite()) {
        return Err(RuleViolation::Negative {
            key: "solver.threshold".to_string(),
            value: threshold,
        });
    }
    plausible(threshold, limits::THRESHOLD_MM, "solver.threshold", "mm")
}

/// `solver.max_iterations` as written (a JSON number): a non-negative
/// integer, plausible.
///
/// # Errors
/// The message.
pub fn max_iterations(n: f64) -> Result<(), RuleViolation> {
    if !(n >= 0.0 && n.fract() == 0.0 && n <= MAX_ITERATIONS_LIMIT) {
        return Err(RuleViolation::NotACount {
            key: "solver.max_iterations".to_string(),
            value: n,
        });
    }
    plausible(n, limits::MAX_ITERATIONS, "solver.max_iterations", "")
}

/// A measurement's `key` (`id`, `station`) is not empty.
///
/// # Errors
/// The message.
pub fn non_empty(key: &str, value: &str) -> Result<(), RuleViolation> {
    if value.is_empty() {
        Err(RuleViolation::Empty {
            key: key.to_string(),
        })
    } else {
        Ok(())
    }
}

/// A side: +1 or −1.
///
/// # Errors
/// The message.
pub fn side(key: &str, side: i8) -> Result<(), RuleViolation> {
    if side == 1 || side == -1 {
        Ok(())
    } else {
        Err(RuleViolation::NotASide {
            key: key.to_string(),
            side,
        })
    }
}

/// Joint readings `key`: each plausible, one per robot joint.
///
/// # Errors
/// The message.
pub fn joints(key: &str, joints: &[f64], robot_joints: usize) -> Result<(), RuleViolation> {
    for (k, q) in joints.iter().enumerate() {
        let reading = format!("{key}[{k}]");
        plausible(*q, limits::ANGLE_DEG, &reading, "deg")?;
        if !q.is_finite() {
            return Err(RuleViolation::NotFinite { key: reading });
        }
    }
    if joints.len() != robot_joints {
        return Err(RuleViolation::JointCount {
            key: key.to_string(),
            readings: joints.len(),
            joints: robot_joints,
        });
    }
    Ok(())
}

/// Stripe points `key`: each plausible and finite, at least
/// [`MIN_STRIPE_POINTS`]. `prefix` starts the count message
/// (`measurements[3].` when the measurement has no id).
///
/// # Errors
/// The message.
pub fn stripe_points(key: &str, prefix: &str, points: &[[f64; 2]]) -> Result<(), RuleViolation> {
    if let Some((i, p)) = points.iter().enumerate().find(|(_, p)| {
        p.iter()
            .any(|v| v.abs() > limits::SENSOR_COORDINATE_MM || !v.is_finite())
    }) {
        let v = if p[0].abs() > limits::SENSOR_COORDINATE_MM || !p[0].is_finite() {
            p[0]
        } else {
            p[1]
        };
        let point = format!("{key}[{i}]");
        plausible(v, limits::SENSOR_COORDINATE_MM, &point, "mm")?;
        return Err(RuleViolation::NotFinite { key: point });
    }
    if points.len() < MIN_STRIPE_POINTS {
        return Err(RuleViolation::TooFewPoints {
            prefix: prefix.to_string(),
            points: points.len(),
        });
    }
    Ok(())
}

/// A given centre `key`: plausible and finite.
///
/// # Errors
/// The message.
pub fn centre(key: &str, c: &Vector3<f64>) -> Result<(), RuleViolation> {
    for v in c.iter() {
        plausible(*v, limits::SENSOR_COORDINATE_MM, key, "mm")?;
        if !v.is_finite() {
            return Err(RuleViolation::NotFinite {
                key: key.to_string(),
            });
        }
    }
    Ok(())
}

/// Reference distance `key` (`reference_distances[i]`) between validate
/// stations of `session`: the key at fault (`from`, `to`, `distance` or
/// the whole item, empty) and the message.
///
/// # Errors
/// The key and the message.
pub fn reference(
    key: &str,
    r: &ReferenceDistance,
    session: &Session,
) -> Result<(), (&'static str, String)> {
    let validate = session.stations(Use::Validate);
    for (field, id) in [("from", &r.from), ("to", &r.to)] {
        if validate.iter().any(|(s, _)| s == id) {
            continue;
        }
        let other = session
            .measurements
            .iter()
            .find(|m| m.station == *id)
            .map(|m| m.usage.as_str());
        let detail = match other {
            Some(u) => format!(" (it has {u} measurements)"),
            None => " (no measurement has this station)".to_owned(),
        };
        return Err((
            field,
            format!(
                "{key}.{field}: station `{id}` has no validate measurements{detail}; reference distances may only name validate stations"
            ),
        ));
    }
    if r.from == r.to {
        return Err((
            "",
            format!("{key}: from and to are the same station `{}`", r.from),
        ));
    }
    if !(r.distance > 0.0 && r.distance.is_finite()) {
        return Err((
            "distance",
            format!(
                "{key}.distance must be positive (mm), found {}",
                show(r.distance)
            ),
        ));
    }
    plausible(
        r.distance,
        limits::DISTANCE_MM,
        &format!("{key}.distance"),
        "mm",
    )
    .map_err(|m| ("distance", m.to_string()))
}

/// The reference distances seen so far, by pair of stations (in name
/// order): two different distances for one pair contradict each other.
#[derive(Debug, Default)]
pub struct ReferencePairs {
    first: std::collections::HashMap<(String, String), (usize, f64)>,
}

impl ReferencePairs {
    /// Records `reference_distances[index]` (`key`).
    ///
    /// # Errors
    /// The pair was given before with another distance.
    pub fn check(
        &mut self,
        key: &str,
        index: usize,
        r: &ReferenceDistance,
    ) -> Result<(), RuleViolation> {
        let pair = if r.from < r.to {
            (r.from.clone(), r.to.clone())
        } else {
            (r.to.clone(), r.from.clone())
        };
        match self.first.get(&pair) {
            Some(&(first, other)) if other != r.distance => Err(RuleViolation::ContradictingPair {
                key: key.to_string(),
                from: r.from.clone(),
                to: r.to.clone(),
                distance: r.distance,
                first,
                other,
            }),
            Some(_) => Ok(()),
            None => {
                self.first.insert(pair, (index, r.distance));
                Ok(())
            }
        }
    }
}

/// "gives `joints` but the session has no `robot`…".
pub const JOINTS_WITHOUT_ROBOT: &str = "gives `joints` but the session has no `robot`: joint readings need the robot model (only a pose-only session, `flange` in every measurement, may leave `robot` out)";

/// Two measurements share an id.
#[must_use]
pub fn duplicate_id(id: &str, first: usize, index: usize) -> String {
    format!(
        "id `{id}` is used by measurements[{first}] and measurements[{index}]; ids must be unique"
    )
}

/// `m` gives the other pose kind than `first` (joints or flange).
#[must_use]
pub fn mixed_pose_kind(first: &Measurement, m: &Measurement) -> Option<String> {
    let kind = |m: &Measurement| {
        if m.flange.is_some() {
            "flange"
        } else {
            "joints"
        }
    };
    (kind(first) != kind(m)).then(|| {
        format!(
            "gives `{}` but measurement {} gives `{}`: a session uses `joints` in every measurement or `flange` in every measurement, not both",
            kind(m),
            first.id,
            kind(first)
        )
    })
}

/// The rules of one measurement that concern only itself: id and station
/// not empty, side, joints or flange (one, joints only with a robot),
/// stripe or centre. The key of the fault, relative to the measurement
/// (`joints`, `stripe.points`, …), and the message.
///
/// # Errors
/// The key and the message.
pub fn measurement(
    m: &Measurement,
    robot_joints: usize,
    robot_given: bool,
) -> Result<(), (&'static str, String)> {
    let at = |key: &'static str| move |e: RuleViolation| (key, e.to_string());
    non_empty("id", &m.id).map_err(at("id"))?;
    non_empty("station", &m.station).map_err(at("station"))?;
    side("side", m.side).map_err(at("side"))?;
    if let Some(pose) = &m.flange {
        transform("flange", pose).map_err(at("flange"))?;
    } else {
        if !robot_given {
            return Err(("joints", JOINTS_WITHOUT_ROBOT.to_string()));
        }
        joints("joints", &m.joints, robot_joints).map_err(at("joints"))?;
    }
    match &m.observation {
        Observation::Stripe(points) => {
            stripe_points("stripe.points", "", points).map_err(at("stripe.points"))
        }
        Observation::Centre(c) => centre("centre", c).map_err(at("centre")),
    }
}

impl Session {
    /// Every FORMAT.md rule of a session, on its typed values: what the
    /// file loader checks as it reads, for a session built in code (an
    /// import). A broken rule names its measurement (when one is to
    /// blame) and its key.
    ///
    /// # Errors
    /// The first broken rule.
    pub fn validate(&self) -> Result<(), RuleError> {
        let general = |key: &str, message: &dyn std::fmt::Display| RuleError {
            measurement: None,
            key: Some(key.to_string()),
            message: message.to_string(),
        };
        if self.robot_given || !self.robot.joints.is_empty() {
            if self.robot.joints.is_empty() {
                return Err(general(
                    "robot.joints",
                    &"robot.joints is empty: at least one joint is needed",
                ));
            }
            for (i, j) in self.robot.joints.iter().enumerate() {
                joint(i, j).map_err(|m| general(&format!("robot.joints[{i}]"), &m))?;
            }
            transform("robot.base", &self.robot.base).map_err(|m| general("robot.base", &m))?;
            transform("robot.flange", &self.robot.flange)
                .map_err(|m| general("robot.flange", &m))?;
        }
        sphere_diameter(self.sphere_diameter).map_err(|m| general("sphere.diameter", &m))?;
        side("sensor.side", self.default_side).map_err(|m| general("sensor.side", &m))?;
        if let Some(r) = &self.sensor_range {
            range(r).map_err(|m| general("sensor.range", &m))?;
        }
        if let Some(h) = &self.hand_eye {
            transform("hand_eye", h).map_err(|m| general("hand_eye", &m))?;
        }
        let SolverSettings {
            threshold: t,
            max_iterations: n,
        } = self.solver;
        threshold(t).map_err(|m| general("solver.threshold", &m))?;
        max_iterations(n as f64).map_err(|m| general("solver.max_iterations", &m))?;
        let robot_given = self.robot_given || !self.robot.joints.is_empty();
        let mut first: std::collections::HashMap<&str, usize> = std::collections::HashMap::new();
        for (index, m) in self.measurements.iter().enumerate() {
            measurement(m, self.robot.dof(), robot_given).map_err(|(key, message)| RuleError {
                measurement: (!m.id.is_empty()).then(|| m.id.clone()),
                key: Some(key.to_string()),
                message,
            })?;
            if let Some(f) = first.insert(m.id.as_str(), index) {
                return Err(RuleError {
                    measurement: Some(m.id.clone()),
                    key: Some("id".to_string()),
                    message: duplicate_id(&m.id, f, index),
                });
            }
            if let Some(message) = self
                .measurements
                .first()
                .and_then(|f| mixed_pose_kind(f, m))
            {
                return Err(RuleError {
                    measurement: Some(m.id.clone()),
                    key: Some(
                        if m.flange.is_some() {
                            "flange"
                        } else {
                            "joints"
                        }
                        .to_string(),
                    ),
                    message,
                });
            }
        }
        let mut pairs = ReferencePairs::default();
        for (i, r) in self.reference_distances.iter().enumerate() {
            let key = format!("reference_distances[{i}]");
            reference(&key, r, self).map_err(|(_, m)| general(&key, &m))?;
            pairs.check(&key, i, r).map_err(|m| general(&key, &m))?;
        }
        self.check_rules()
    }
}
