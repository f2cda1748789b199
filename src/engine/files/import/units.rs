//! Units of the imported files: joint readings (deg or rad) and profile
//! coordinates (mm, µm or m); the session holds deg and mm.

use crate::engine::base::numeric::approx;

/// Unit of the joint readings in the log.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AngleUnit {
    /// Degrees (the session's unit).
    Deg,
    /// Radians.
    Rad,
}

impl AngleUnit {
    /// The value in degrees.
    #[must_use]
    pub fn to_deg(self, v: f64) -> f64 {
        match self {
            Self::Deg => v,
            Self::Rad => v.to_degrees(),
        }
    }

    /// Short name, `deg` or `rad`.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Deg => "deg",
            Self::Rad => "rad",
        }
    }

    /// Parses `deg` or `rad`.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "deg" => Some(Self::Deg),
            "rad" => Some(Self::Rad),
            _ => None,
        }
    }
}

/// Unit of the stripe profile coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LengthUnit {
    /// Millimetres (the session's unit).
    Mm,
    /// Micrometres.
    Um,
    /// Metres.
    M,
}

impl LengthUnit {
    /// The value in millimetres.
    #[must_use]
    pub fn to_mm(self, v: f64) -> f64 {
        match self {
            Self::Mm => v,
            Self::Um => v / 1000.0,
            Self::M => v * 1000.0,
        }
    }

    /// Short name, `mm`, `um` or `m` (what [`Self::parse`] reads).
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Mm => "mm",
            Self::Um => "um",
            Self::M => "m",
        }
    }

    /// The unit's symbol for people: `mm`, `µm` or `m`.
    #[must_use]
    pub fn symbol(self) -> &'static str {
        match self {
            Self::Mm => "mm",
            Self::Um => "µm",
            Self::M => "m",
        }
    }

    /// Parses `mm`, `um` (or `µm`) or `m`.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "mm" => Some(Self::Mm),
            "um" | "µm" => Some(Self::Um),
            "m" => Some(Self::M),
            _ => None,
        }
    }
}

/// Largest joint reading taken as plausible, deg: two turns. A joint log
/// in degrees read as radians multiplies every reading by 57.3, so any
/// joint beyond 12.6° shows up far beyond this.
pub const MAX_PLAUSIBLE_JOINT_DEG: f64 = 720.0;

/// Catches joint readings in the wrong unit: read as radians, a log in
/// degrees gives readings of thousands of degrees; the message says which
/// flag to change. `rows` are `(line, pose id, raw readings)` in file
/// units.
///
/// # Errors
/// The first implausible reading, its pose and what reading it as the
/// other unit gives.
pub fn check_joint_unit<'a>(
    unit: AngleUnit,
    rows: impl IntoIterator<Item = (usize, &'a str, &'a [f64])>,
) -> Result<(), (usize, String)> {
    let rows: Vec<(usize, &str, &[f64])> = rows.into_iter().collect();
    let worst = rows
        .iter()
        .flat_map(|&(line, id, raw)| raw.iter().enumerate().map(move |(j, &v)| (line, id, j, v)))
        .max_by(|a, b| a.3.abs().total_cmp(&b.3.abs()));
    let Some((line, id, j, v)) = worst else {
        return Ok(());
    };
    let deg = unit.to_deg(v);
    if deg.abs() <= MAX_PLAUSIBLE_JOINT_DEG {
        return Ok(());
    }
    let hint = match unit {
        AngleUnit::Rad if v.abs() <= MAX_PLAUSIBLE_JOINT_DEG => format!(
            "; the log looks like degrees: read with --joint-unit deg, joint {} would be {}°",
            j + 1,
            crate::engine::base::numeric::approx(v)
        ),
        _ => String::new(),
    };
    Err((
        line,
        format!(
            "pose {id}: joint {} reads {} {} = {}°, beyond any robot joint's range (±{MAX_PLAUSIBLE_JOINT_DEG}°){hint}",
            j + 1,
            crate::engine::base::numeric::show(v),
            unit.as_str(),
            crate::engine::base::numeric::approx(deg)
        ),
    ))
}

/// Share of a log's readings within ±2π at or above which a log read in
/// degrees is taken for radians. A log in radians has all its readings
/// there but for the odd wrist joint beyond a turn (5 of 744 in a real
/// case); a calibration in degrees moves its joints by tens of degrees, so
/// nearly all of its readings lie beyond ±6.3°.
const RADIAN_LIKE_SHARE: f64 = 0.95;

/// A warning when the joint readings of a log read in degrees look like
/// radians: at least [`RADIAN_LIKE_SHARE`] of them within ±2π and none
/// beyond two turns in radians (±4π, [`MAX_PLAUSIBLE_JOINT_DEG`] read as
/// radians). A calibration moves its joints by tens of degrees, so the log
/// is probably in radians.
#[must_use]
pub fn joint_unit_warning(
    unit: AngleUnit,
    readings: impl IntoIterator<Item = f64>,
) -> Option<String> {
    if unit != AngleUnit::Deg {
        return None;
    }
    let tau = std::f64::consts::TAU;
    let (mut count, mut within, mut largest) = (0usize, 0usize, 0.0f64);
    for v in readings {
        count += 1;
        if v.abs() <= tau {
            within += 1;
        }
        largest = largest.max(v.abs());
    }
    let share = within as f64 / count.max(1) as f64;
    let radian_like =
        count >= 6 && share >= RADIAN_LIKE_SHARE && largest <= MAX_PLAUSIBLE_JOINT_DEG.to_radians();
    radian_like.then(|| {
        let which = if within == count {
            "every joint reading lies".to_owned()
        } else {
            format!("{within} of {count} joint readings lie")
        };
        format!(
            "warning: {which} within ±{}° (largest {}°); if the log is in radians, import again with --joint-unit rad",
            crate::engine::base::numeric::approx(tau),
            crate::engine::base::numeric::approx(largest)
        )
    })
}

/// Smallest plausible median profile extent, in sphere diameters.
const MIN_PROFILE_EXTENT: f64 = 1.0 / 20.0;
/// Largest plausible median profile extent, in sphere diameters (a
/// sensor's whole field, background included, around a small sphere).
const MAX_PROFILE_EXTENT: f64 = 200.0;

/// Profiles whose size does not fit the sphere: their median size, the
/// poses it is over, the sphere, the unit they were read in and the unit
/// that would fit, if one does.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "the profiles span {} mm (median over {poses} poses) against a sphere of {} mm diameter, read as {}: not plausible{}",
    approx(*median_mm),
    approx(*diameter_mm),
    unit.symbol(),
    hint(*suggestion)
)]
pub struct ProfileUnitError {
    /// The median profile size, mm as read.
    pub median_mm: f64,
    /// Profiles it is over.
    pub poses: usize,
    /// The sphere's diameter, mm.
    pub diameter_mm: f64,
    /// The unit the profiles were read in.
    pub unit: LengthUnit,
    /// A unit that makes the size plausible, and the size then (mm).
    pub suggestion: Option<(LengthUnit, f64)>,
}

/// The suggestion of a [`ProfileUnitError`] in words.
fn hint(suggestion: Option<(LengthUnit, f64)>) -> String {
    match suggestion {
        Some((u, e)) => format!(
            "; read as {} they would span {} mm: import with --profile-unit {}",
            u.symbol(),
            approx(e),
            u.as_str()
        ),
        None => "; check --profile-unit and --sphere-diameter".to_string(),
    }
}

/// Catches profile coordinates in the wrong unit: the profiles' typical
/// size (the median over poses of each profile's bounding-box diagonal,
/// mm) against the sphere's diameter. A stripe across a sphere spans
/// about a diameter, more with background; micrometres read as
/// millimetres make it a thousand times more, millimetres read as
/// micrometres a thousand times less. The message names the unit flag
/// that makes the size plausible, if one does.
///
/// # Errors
/// [`ProfileUnitError`]: the median size, the sphere and the suggestion.
pub fn check_profile_unit(
    unit: LengthUnit,
    diameter_mm: f64,
    extents_mm: &[f64],
) -> Result<(), ProfileUnitError> {
    let Some(median) = crate::engine::base::numeric::median(extents_mm) else {
        return Ok(());
    };
    let plausible =
        |e: f64| (MIN_PROFILE_EXTENT * diameter_mm..=MAX_PROFILE_EXTENT * diameter_mm).contains(&e);
    if plausible(median) {
        return Ok(());
    }
    let suggestion = [LengthUnit::Mm, LengthUnit::Um, LengthUnit::M]
        .into_iter()
        .filter(|&u| u != unit)
        .map(|u| (u, median / unit.to_mm(1.0) * u.to_mm(1.0)))
        .find(|&(_, e)| plausible(e));
    Err(ProfileUnitError {
        median_mm: median,
        poses: extents_mm.len(),
        diameter_mm,
        unit,
        suggestion,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 23: a log in radians with 5 of 744 readings beyond 2π (a
    /// wrist past a turn) was read as degrees without a word.
    #[test]
    fn a_radian_log_with_a_few_readings_past_a_turn_is_warned() {
        let mut readings: Vec<f64> = (0..744)
            .map(|k| 2.5 * (f64::from(k) * 0.37).sin())
            .collect();
        for v in readings.iter_mut().take(5) {
            *v = 6.9;
        }
        let w = joint_unit_warning(AngleUnit::Deg, readings.iter().copied()).unwrap();
        assert!(
            w.contains("739 of 744") && w.contains("--joint-unit rad"),
            "{w}"
        );
        // Read as radians: nothing to say.
        assert!(joint_unit_warning(AngleUnit::Rad, readings.iter().copied()).is_none());
        // A log in degrees moves its joints by tens of degrees.
        let degrees: Vec<f64> = readings.iter().map(|v| v.to_degrees()).collect();
        assert!(joint_unit_warning(AngleUnit::Deg, degrees).is_none());
        // Beyond two turns in radians it is not a radian log either.
        readings[6] = 20.0;
        assert!(joint_unit_warning(AngleUnit::Deg, readings).is_none());
    }
}
