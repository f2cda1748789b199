//! How well the data determined the hand-eye: for a result that
//! calibrated the hand-eye only (a pose-only session), the 1σ of each
//! hand-eye direction from `ml`'s covariance, the least determined
//! translation direction, and the spread of the flange orientations that
//! explains it. Rotations between poses are the lever on the translation:
//! with small ones (RobCalibrator's data: up to about 15°) some
//! translation directions stay weak, and the output says so.

use nalgebra::{Isometry3, Matrix3, SymmetricEigen, Vector3};

use crate::engine::base::session::Session;
use crate::engine::calibrate::solve::estimate::HAND_EYE_LABELS;
use crate::engine::calibrate::solve::ml::MlReport;
use crate::engine::files::format::ResultFile;

/// What a hand-eye-only result calibrated, in one sentence.
pub const HAND_EYE_ONLY: &str = "pose-only session (flange poses, no joint readings): the hand-eye and the station centres were calibrated; no kinematic parameter was identified";

/// The flange poses of a pose-only session, in measurement order.
#[must_use]
pub fn flange_poses(session: &Session) -> Option<Vec<Isometry3<f64>>> {
    session.pose_only().then(|| {
        let robot = session.solver_robot();
        (0..session.measurements.len())
            .map(|i| session.base_from_flange(&robot, i))
            .collect()
    })
}

/// For a result that calibrated the hand-eye only: [`HAND_EYE_ONLY`] and
/// the [`HandEyeStrength`] lines (with the poses' spread when `session`
/// is given). `None` for a result with a kinematic model.
#[must_use]
pub fn hand_eye_only_lines(result: &ResultFile, session: Option<&Session>) -> Option<Vec<String>> {
    if !result.hand_eye_only() {
        return None;
    }
    let mut lines = vec![HAND_EYE_ONLY.to_string()];
    let poses = session.and_then(flange_poses);
    if let Some(strength) = result
        .solver
        .ml()
        .and_then(|m| HandEyeStrength::of(m, poses.as_deref()))
    {
        lines.extend(strength.lines());
    }
    Some(lines)
}

/// A translation direction determined worse than this (1σ, mm) is called
/// weak: more than a typical sensor's accuracy and a robot's repeatability.
pub const WEAK_TRANSLATION_MM: f64 = 0.1;

/// Flange orientations spread over less than this (largest angle between
/// two poses, deg) are called small in the explanation.
pub const WIDE_ORIENTATION_DEG: f64 = 30.0;

/// How well the data determined the hand-eye.
#[derive(Debug, Clone, PartialEq)]
pub struct HandEyeStrength {
    /// 1σ of the hand-eye directions, sensor frame, in the order of
    /// [`HAND_EYE_LABELS`]: x, y, z (mm), rx, ry, rz (deg).
    pub sigma: [f64; 6],
    /// The least determined translation direction (unit vector, sensor
    /// frame) and its 1σ, mm.
    pub weakest_translation: ([f64; 3], f64),
    /// The best determined translation direction's 1σ, mm.
    pub best_translation: f64,
    /// The largest angle between two flange orientations of the
    /// measurements, deg, when the poses are known.
    pub orientation_span_deg: Option<f64>,
}

impl HandEyeStrength {
    /// The strength in `report` (`ml`'s covariance of the hand-eye
    /// unknowns), with the spread of `flange_poses` when given. `None`
    /// when the report has no hand-eye covariance.
    #[must_use]
    pub fn of(report: &MlReport, flange_poses: Option<&[Isometry3<f64>]>) -> Option<Self> {
        let cov = &report.covariance;
        let index: Vec<usize> = HAND_EYE_LABELS
            .iter()
            .map(|l| cov.labels.iter().position(|x| x == l))
            .collect::<Option<_>>()?;
        let entry = |i: usize, j: usize| -> Option<f64> {
            cov.matrix.get(index[i])?.get(index[j]).copied()
        };
        let mut sigma = [0.0; 6];
        for (k, s) in sigma.iter_mut().enumerate() {
            *s = crate::engine::base::numeric::sigma_of_variance(entry(k, k)?);
        }
        let mut t = Matrix3::zeros();
        for i in 0..3 {
            for j in 0..3 {
                t[(i, j)] = entry(i, j)?;
            }
        }
        let eig = SymmetricEigen::try_new(
            (t + t.transpose()) * 0.5,
            f64::EPSILON,
            crate::engine::base::numeric::MAX_DECOMPOSITION_SWEEPS,
        )?;
        let (mut hi, mut lo) = (0, 0);
        for k in 0..3 {
            if eig.eigenvalues[k] > eig.eigenvalues[hi] {
                hi = k;
            }
            if eig.eigenvalues[k] < eig.eigenvalues[lo] {
                lo = k;
            }
        }
        let mut dir: Vector3<f64> = eig.eigenvectors.column(hi).into();
        // Report the direction with its largest component positive.
        let largest = dir.iamax();
        if dir[largest] < 0.0 {
            dir = -dir;
        }
        let span = flange_poses.map(|poses| {
            let mut widest: f64 = 0.0;
            for (i, a) in poses.iter().enumerate() {
                for b in &poses[i + 1..] {
                    widest = widest.max(a.rotation.angle_to(&b.rotation).to_degrees());
                }
            }
            widest
        });
        Some(Self {
            sigma,
            weakest_translation: (
                dir.into(),
                crate::engine::base::numeric::sigma_of_variance(eig.eigenvalues[hi]),
            ),
            best_translation: crate::engine::base::numeric::sigma_of_variance(eig.eigenvalues[lo]),
            orientation_span_deg: span,
        })
    }

    /// True when some translation direction is weak
    /// ([`WEAK_TRANSLATION_MM`]).
    #[must_use]
    pub fn weak(&self) -> bool {
        self.weakest_translation.1 > WEAK_TRANSLATION_MM
    }

    /// Lines for people: the σ of each direction, the weakest, and why.
    #[must_use]
    pub fn lines(&self) -> Vec<String> {
        let s = &self.sigma;
        let mut out = vec![format!(
            "hand-eye 1σ (sensor frame): x ±{:.3}, y ±{:.3}, z ±{:.3} mm; rx ±{:.3}°, ry ±{:.3}°, rz ±{:.3}°",
            s[0], s[1], s[2], s[3], s[4], s[5]
        )];
        let (d, sd) = self.weakest_translation;
        let span = self
            .orientation_span_deg
            .map(|a| format!("; the flange orientations differ by at most {a:.1}°"))
            .unwrap_or_default();
        if self.weak() {
            let advice = match self.orientation_span_deg {
                Some(a) if a < WIDE_ORIENTATION_DEG => format!(
                    ": small rotations between poses leave the translation weak; orientations spread over {WIDE_ORIENTATION_DEG:.0}° or more about two axes would determine it"
                ),
                _ => String::new(),
            };
            out.push(format!(
                "weakly determined: the hand-eye translation along ({:.2}, {:.2}, {:.2}) (sensor frame), ±{sd:.3} mm (best direction ±{:.3} mm){span}{advice}",
                d[0], d[1], d[2], self.best_translation
            ));
        } else {
            out.push(format!(
                "every hand-eye translation direction is determined to ±{sd:.3} mm or better{span}"
            ));
        }
        out
    }
}
