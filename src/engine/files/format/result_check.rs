//! The checks of a result's numbers before it is written and after it is
//! read: plausibility against the session limits, and a `null` that stands
//! for a number that is not finite.

use nalgebra::Isometry3;
use serde_json::Value;

use super::result::ResultFile;
use crate::engine::base::numeric::show;
use crate::engine::base::records::SolverReport;
use crate::engine::base::robot::Joint;
use crate::engine::base::session::limits;

/// The first finite number of `r` beyond the session file's plausibility
/// limits ([`limits`]), as its key path, value and limit: a hand-eye of
/// 1e308 mm or a length of 1e300 mm is not a calibration, and would flow
/// into every report, export and history table. Checked on reading and
/// before writing, so that every result spherecal writes loads.
/// (Numbers that are not finite are [`result_text_checked`]'s.)
#[must_use]
pub fn implausible_number(r: &ResultFile) -> Option<String> {
    let mut f = Finder(None);
    for (key, t) in [
        ("hand_eye_initial", &r.hand_eye_initial),
        ("hand_eye", &r.hand_eye),
    ] {
        f.transform(key, t);
    }
    if let Some(robot) = &r.robot {
        f.joints("robot.joints", &robot.joints);
        f.transform("robot.base", &robot.base);
        f.transform("robot.flange", &robot.flange);
    }
    f.joints("joint_errors", &r.joint_errors);
    for (i, it) in r.iterations.iter().enumerate() {
        f.check(
            || format!("iterations[{i}].epsilon"),
            it.epsilon,
            limits::DISTANCE_MM,
            "mm",
        );
    }
    for (i, c) in r.centres.iter().enumerate() {
        for k in 0..3 {
            let limit = limits::SENSOR_COORDINATE_MM;
            f.check(
                || format!("centres[{i}].sensor[{k}]"),
                c.sensor[k],
                limit,
                "mm",
            );
            let limit = limits::LENGTH_MM;
            f.check(
                || format!("centres[{i}].before[{k}]"),
                c.before[k],
                limit,
                "mm",
            );
            f.check(
                || format!("centres[{i}].after[{k}]"),
                c.after[k],
                limit,
                "mm",
            );
        }
    }
    if let Some(v) = &r.validation {
        let limit = limits::DISTANCE_MM;
        for (i, d) in v.distances.iter().enumerate() {
            for (name, x) in [
                ("reference", d.reference),
                ("before", d.before),
                ("after", d.after),
            ] {
                f.check(
                    || format!("validation.distances[{i}].{name}"),
                    x,
                    limit,
                    "mm",
                );
            }
        }
        for (key, st) in [
            ("validation.before", &v.before),
            ("validation.after", &v.after),
            ("validation.within_station.before", &v.within_station.before),
            ("validation.within_station.after", &v.within_station.after),
        ] {
            for (name, x) in [("max", st.max), ("std", st.std), ("rms", st.rms)] {
                f.check(|| format!("{key}.{name}"), x, limit, "mm");
            }
        }
    }
    for (i, st) in r.stations.iter().enumerate() {
        for k in 0..3 {
            f.check(
                || format!("stations[{i}].point[{k}]"),
                st.point[k],
                limits::LENGTH_MM,
                "mm",
            );
        }
    }
    if let (None, SolverReport::Ml(ml)) = (&f.0, &r.solver) {
        f.0 = ml.implausible();
    }
    f.0
}

/// The first implausible number found ([`implausible_number`]).
struct Finder(Option<String>);

impl Finder {
    /// Notes `v` under `key` when it is finite and beyond `limit`.
    fn check(&mut self, key: impl FnOnce() -> String, v: f64, limit: f64, unit: &str) {
        if self.0.is_none() && v.is_finite() && v.abs() > limit {
            self.0 = Some(format!(
                "`{}` = {} {unit} is not plausible (at most {limit} {unit})",
                key(),
                show(v)
            ));
        }
    }

    /// The translation of a 4×4 matrix written under `key`.
    fn transform(&mut self, key: &str, t: &Isometry3<f64>) {
        for (k, v) in t.translation.vector.iter().enumerate() {
            self.check(|| format!("{key}[{k}][3]"), *v, limits::LENGTH_MM, "mm");
        }
    }

    /// MDH joints (or their errors) under `key`.
    fn joints(&mut self, key: &str, joints: &[Joint]) {
        for (i, j) in joints.iter().enumerate() {
            for (name, v, limit, unit) in [
                ("alpha", j.alpha, limits::ANGLE_DEG, "deg"),
                ("a", j.a, limits::LENGTH_MM, "mm"),
                ("beta", j.beta, limits::ANGLE_DEG, "deg"),
                ("theta", j.theta, limits::ANGLE_DEG, "deg"),
                ("d", j.d, limits::LENGTH_MM, "mm"),
            ] {
                self.check(|| format!("{key}[{i}].{name}"), v, limit, unit);
            }
        }
    }
}

/// Whether JSON `text` has a `null` outside its strings.
pub(super) fn has_bare_null(text: &str) -> bool {
    let b = text.as_bytes();
    let (mut in_string, mut escaped) = (false, false);
    for (i, &c) in b.iter().enumerate() {
        if in_string {
            match c {
                _ if escaped => escaped = false,
                b'\\' => escaped = true,
                b'"' => in_string = false,
                _ => {}
            }
        } else if c == b'"' {
            in_string = true;
        } else if c == b'n' && b[i..].starts_with(b"null") {
            return true;
        }
    }
    false
}

/// Keys whose `null` is a legal value: a pose-only result's robot, and
/// the optional parts of ml's report (no validate pairs, no
/// cross-validation).
fn null_allowed(key: &str) -> bool {
    let last = key.rsplit('.').next().unwrap_or(key);
    key == "robot"
        || (key.starts_with("solver.")
            && matches!(last, "predicted_distance_std_validate" | "cross_validation"))
}

/// The key path of the first `null` that stands for a number (serde_json
/// writes NaN and ±infinity as `null`).
pub(super) fn first_non_finite(v: &Value, key: &str) -> Option<String> {
    match v {
        Value::Null if !null_allowed(key) => Some(key.to_string()),
        Value::Array(items) => items
            .iter()
            .enumerate()
            .find_map(|(i, x)| first_non_finite(x, &format!("{key}[{i}]"))),
        Value::Object(map) => map.iter().find_map(|(k, x)| {
            let sub = if key.is_empty() {
                k.clone()
            } else {
                format!("{key}.{k}")
            };
            first_non_finite(x, &sub)
        }),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bare_null_is_told_from_one_in_a_string() {
        assert!(has_bare_null(r#"{"a": null}"#));
        assert!(has_bare_null("[1,\n  null]"));
        assert!(!has_bare_null(
            r#"{"session": "null \"null\" null", "b": 1}"#
        ));
        assert!(!has_bare_null(r#"{"a\\": "nullable"}"#));
        assert!(has_bare_null(r#"{"a\\": 1, "b": null}"#));
    }
}
