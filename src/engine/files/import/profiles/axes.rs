//! The axis map: the sensor's axes onto FORMAT.md's frame (laser plane
//! `x = 0`), given or guessed from the data, never a mirror.

use std::fmt;

use nalgebra::Matrix3;

use super::{AXIS_NAMES, PLANE_TOLERANCE_MM, RawProfile};
use crate::engine::base::numeric::approx;

/// One axis of an [`AxisMap`]: a sensor axis (0 = x, 1 = y, 2 = z) and a
/// sign.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct SignedAxis {
    axis: usize,
    negative: bool,
}

/// Why an axis map cannot be read or guessed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AxisMapError {
    /// Not three axes.
    #[error("axis map `{0}`: give three sensor axes for spherecal x, y, z, e.g. `-y,x,z`")]
    NotThree(String),
    /// A part that is not an axis.
    #[error("axis map `{text}`: `{part}` is not x, y or z (with an optional sign)")]
    NotAnAxis {
        /// The map as given.
        text: String,
        /// The part at fault.
        part: String,
    },
    /// A sensor axis used twice.
    #[error("axis map `{text}`: sensor axis {axis} is used twice")]
    Twice {
        /// The map as given.
        text: String,
        /// The axis.
        axis: &'static str,
    },
    /// A left-handed map.
    #[error(
        "axis map `{text}` mirrors the frame (a left-handed map): the hand-eye would be a reflection; change one sign, e.g. `{fixed}`"
    )]
    Mirror {
        /// The map as given.
        text: String,
        /// The map with spherecal's `x` negated.
        fixed: AxisMap,
    },
    /// No point to guess from.
    #[error("no profile points to guess the laser plane from")]
    NoPoints,
    /// No coordinate is constant over the profiles.
    #[error(
        "cannot guess the laser plane: no coordinate is constant (spreads x {}, y {}, z {} mm); give the axis map, e.g. `--axes -y,x,z`",
        approx(spreads[0]),
        approx(spreads[1]),
        approx(spreads[2])
    )]
    NoConstant {
        /// Each sensor coordinate's spread, mm.
        spreads: [f64; 3],
    },
    /// The constant coordinate is not 0.
    #[error(
        "every point has {axis} = {} mm: the laser plane does not pass through the sensor's origin; FORMAT.md needs the plane at 0",
        crate::engine::base::numeric::show(*value)
    )]
    OffOrigin {
        /// The sensor axis.
        axis: &'static str,
        /// Its value, mm.
        value: f64,
    },
}

/// The message, for the edges that show errors as text (the command
/// line's and the workbench's forms).
impl From<AxisMapError> for String {
    fn from(e: AxisMapError) -> Self {
        e.to_string()
    }
}

/// Maps the sensor's axes onto FORMAT.md's frame: spherecal's `x`, `y`,
/// `z` each the sensor axis named, with its sign. Always a rotation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxisMap {
    axes: [SignedAxis; 3],
}

impl AxisMap {
    /// The identity: the sensor's axes are FORMAT's.
    pub const IDENTITY: Self = Self {
        axes: [
            SignedAxis {
                axis: 0,
                negative: false,
            },
            SignedAxis {
                axis: 1,
                negative: false,
            },
            SignedAxis {
                axis: 2,
                negative: false,
            },
        ],
    };

    /// Parses `a,b,c`, each a sensor axis `x`, `y` or `z` with an optional
    /// sign, giving spherecal's `x`, `y`, `z` in turn (`-y,x,z`).
    ///
    /// # Errors
    /// Not three axes, an axis used twice, or a map that mirrors the frame.
    pub fn parse(text: &str) -> Result<Self, AxisMapError> {
        let parts: Vec<&str> = text.split(',').map(str::trim).collect();
        if parts.len() != 3 {
            return Err(AxisMapError::NotThree(text.to_string()));
        }
        let mut axes = [SignedAxis {
            axis: 0,
            negative: false,
        }; 3];
        for (slot, part) in axes.iter_mut().zip(&parts) {
            let (negative, name) = match part.strip_prefix('-') {
                Some(rest) => (true, rest),
                None => (false, part.strip_prefix('+').unwrap_or(part)),
            };
            let axis = AXIS_NAMES
                .iter()
                .position(|n| n.eq_ignore_ascii_case(name))
                .ok_or_else(|| AxisMapError::NotAnAxis {
                    text: text.to_string(),
                    part: (*part).to_string(),
                })?;
            *slot = SignedAxis { axis, negative };
        }
        let map = Self { axes };
        let mut used = [false; 3];
        for a in &map.axes {
            if std::mem::replace(&mut used[a.axis], true) {
                return Err(AxisMapError::Twice {
                    text: text.to_string(),
                    axis: AXIS_NAMES[a.axis],
                });
            }
        }
        if map.rotation().determinant() < 0.0 {
            return Err(AxisMapError::Mirror {
                text: text.to_string(),
                fixed: map.flipped_x(),
            });
        }
        Ok(map)
    }

    /// The map with spherecal's `x` negated (mirror fixed).
    fn flipped_x(self) -> Self {
        let mut m = self;
        m.axes[0].negative = !m.axes[0].negative;
        m
    }

    /// `FORMAT_from_sensor`: the rotation taking sensor coordinates to
    /// spherecal's (`p_spherecal = R · p_sensor`).
    #[must_use]
    pub fn rotation(&self) -> Matrix3<f64> {
        let mut r = Matrix3::zeros();
        for (row, a) in self.axes.iter().enumerate() {
            r[(row, a.axis)] = if a.negative { -1.0 } else { 1.0 };
        }
        r
    }

    /// The sensor axis that becomes spherecal's `x`, the laser plane's
    /// normal.
    #[must_use]
    pub fn normal_axis(&self) -> usize {
        self.axes[0].axis
    }

    /// A sensor point in spherecal's axes.
    #[must_use]
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        self.axes
            .map(|a| if a.negative { -p[a.axis] } else { p[a.axis] })
    }

    /// In words: "spherecal x = −y, y = x, z = z".
    #[must_use]
    pub fn describe(&self) -> String {
        let part = |i: usize| {
            let a = self.axes[i];
            format!(
                "{} = {}{}",
                AXIS_NAMES[i],
                if a.negative { "−" } else { "" },
                AXIS_NAMES[a.axis]
            )
        };
        format!("spherecal {}, {}, {}", part(0), part(1), part(2))
    }

    /// The map guessed from the profiles: the sensor axis on which every
    /// point is 0 is the plane's normal (spherecal `x`), the other two keep
    /// their order as `y`, `z`, and `x`'s sign makes it a rotation.
    ///
    /// # Errors
    /// No coordinate is constant, or the constant one is not 0 (the plane
    /// does not pass through the sensor's origin).
    pub fn guess(profiles: &[RawProfile]) -> Result<Self, AxisMapError> {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in profiles.iter().flat_map(|p| &p.points) {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        if lo.iter().any(|v| !v.is_finite()) {
            return Err(AxisMapError::NoPoints);
        }
        let spread: [f64; 3] = std::array::from_fn(|k| hi[k] - lo[k]);
        let Some(normal) = (0..3).find(|&k| spread[k] <= PLANE_TOLERANCE_MM) else {
            return Err(AxisMapError::NoConstant { spreads: spread });
        };
        if lo[normal].abs() > PLANE_TOLERANCE_MM {
            return Err(AxisMapError::OffOrigin {
                axis: AXIS_NAMES[normal],
                value: lo[normal],
            });
        }
        let rest: Vec<usize> = (0..3).filter(|&k| k != normal).collect();
        let map = Self {
            axes: [
                SignedAxis {
                    axis: normal,
                    negative: false,
                },
                SignedAxis {
                    axis: rest[0],
                    negative: false,
                },
                SignedAxis {
                    axis: rest[1],
                    negative: false,
                },
            ],
        };
        Ok(if map.rotation().determinant() < 0.0 {
            map.flipped_x()
        } else {
            map
        })
    }
}

impl AxisMap {
    /// The profile that keeps [`Self::guess`] from finding the plane, when
    /// the others agree on it: the sensor axis that is 0 in the most
    /// profiles is taken for the normal, and the first profile that is not
    /// on it is the culprit (its index). `None` when no profile lies in a
    /// plane through the origin.
    #[must_use]
    pub fn odd_profile(profiles: &[RawProfile]) -> Option<usize> {
        let on = |p: &RawProfile, k: usize| {
            !p.points.is_empty() && p.points.iter().all(|q| q[k].abs() <= PLANE_TOLERANCE_MM)
        };
        let counts: [usize; 3] =
            std::array::from_fn(|k| profiles.iter().filter(|p| on(p, k)).count());
        let normal = (0..3)
            .max_by_key(|&k| counts[k])
            .filter(|&k| counts[k] > 0)?;
        profiles
            .iter()
            .position(|p| !p.points.is_empty() && !on(p, normal))
    }
}

impl fmt::Display for AxisMap {
    /// The form [`AxisMap::parse`] reads: `-y,x,z`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let parts: Vec<String> = self
            .axes
            .iter()
            .map(|a| {
                format!(
                    "{}{}",
                    if a.negative { "-" } else { "" },
                    AXIS_NAMES[a.axis]
                )
            })
            .collect();
        write!(f, "{}", parts.join(","))
    }
}
