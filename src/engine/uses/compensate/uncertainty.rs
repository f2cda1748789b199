//! The predicted 1σ residual of a compensated target, from `ml`'s
//! covariance of the estimated parameters (the result's
//! `solver.covariance`, file units): the TCP origin's base-frame error to
//! first order is `A·δθ` with `A` the sensitivity of a point fixed to the
//! TCP at the calibrated solution
//! ([`PoseSensitivity`](crate::engine::calibrate::solve::estimate::PoseSensitivity),
//! paper eq. 12-16: hand-eye twist in the sensor frame, then the MDH
//! parameters), so `σ² = tr(A·C·Aᵀ)` over the estimated parameters. The
//! hand-eye columns count only when the TCP is the sensor.
//!
//! **Aligned.** Sphere data see distances only, and a cell places its
//! work in a frame taught or measured where it works; part of the
//! parameter uncertainty moves every target alike (a rigid motion of the
//! whole region) and is taken out by that frame. As `ml`'s range
//! prediction does ([`crate::engine::calibrate::solve::ml::range`]), the rigid
//! motion that best fits the errors of the TCP over the poses the
//! calibration saw, `M = (RᵀR)⁻¹RᵀG`, is removed from each target's:
//! `H = A − R(p)·M`, `σ² = tr(H·C·Hᵀ)`. Without those poses (a result
//! that records no joints) σ is not aligned and says so. The robot's
//! repeatability is not in σ.

use nalgebra::{DMatrix, Isometry3, Vector3};

use crate::engine::base::geometry::skew;
use crate::engine::base::robot::Robot;
use crate::engine::base::robot::ik::DOF;
use crate::engine::calibrate::handeye::Sighting;
use crate::engine::calibrate::solve::SolverReport;
use crate::engine::calibrate::solve::estimate::{
    Estimate, PoseSensitivity, unknown_is_angle, unknown_label,
};

/// The covariance of the estimated parameters in the engine's units
/// (rad, mm), with each row's index in the update vector `ΔY`.
#[derive(Debug, Clone)]
pub struct Covariance {
    /// Index in `ΔY` (`he_x`… then `alpha1`…) of each row.
    index: Vec<usize>,
    /// Entries, rad and mm.
    matrix: DMatrix<f64>,
}

impl Covariance {
    /// The covariance of an `ml` report for a robot of `n_joints`, or
    /// `None` (the paper's method reports none; a malformed block).
    #[must_use]
    pub fn of(report: &SolverReport, n_joints: usize) -> Option<Self> {
        let SolverReport::Ml(ml) = report else {
            return None;
        };
        let c = &ml.covariance;
        let k = c.labels.len();
        if k == 0 || c.matrix.len() != k || c.matrix.iter().any(|r| r.len() != k) {
            return None;
        }
        let n = 6 + 5 * n_joints;
        let index: Vec<usize> = c
            .labels
            .iter()
            .map(|l| (0..n).find(|&u| unknown_label(u) == *l))
            .collect::<Option<_>>()?;
        // File units are deg for angles: back to rad.
        let scale = |u: usize| {
            if unknown_is_angle(u) {
                1f64.to_radians()
            } else {
                1.0
            }
        };
        let matrix = DMatrix::from_fn(k, k, |i, j| {
            c.matrix[i][j] * scale(index[i]) * scale(index[j])
        });
        matrix
            .iter()
            .all(|v| v.is_finite())
            .then_some(Self { index, matrix })
    }

    /// The sensitivity `A` (3 × k, the estimated parameters' columns) of
    /// the origin of the TCP `flange_from_tcp` at joints `q` (deg) of the
    /// `calibrated` model, and the origin (base frame, mm); `sensor` says
    /// whether the TCP is the calibrated sensor (its hand-eye columns then
    /// count).
    fn rows(
        &self,
        calibrated: &Robot,
        flange_from_tcp: &Isometry3<f64>,
        sensor: bool,
        q: &[f64; DOF],
    ) -> (Vector3<f64>, DMatrix<f64>) {
        let est = Estimate {
            robot: calibrated.clone(),
            flange_from_sensor: *flange_from_tcp,
        };
        let sighting = Sighting {
            id: String::new(),
            joints: q.to_vec(),
            flange: None,
            centre_in_sensor: Vector3::zeros(),
        };
        let (p, a) = PoseSensitivity::new(&est, &sighting).at(&est, &Vector3::zeros());
        let k = self.index.len();
        let cols = DMatrix::from_fn(3, k, |r, c| {
            let u = self.index[c];
            if u < 6 && !sensor { 0.0 } else { a[(r, u)] }
        });
        (p, cols)
    }
}

/// `R(p) = [I | −[p − c]×]`: a point's motion under a small rigid motion
/// `(t, ω)` about `c`.
fn rigid_rows(p: &Vector3<f64>, c: &Vector3<f64>) -> DMatrix<f64> {
    let d = p - c;
    let mut r = DMatrix::zeros(3, 6);
    r.view_mut((0, 0), (3, 3)).fill_with_identity();
    r.view_mut((0, 3), (3, 3)).copy_from(&(-skew(&d)));
    r
}

/// The predicted σ of targets of one calibration and TCP (module doc).
#[derive(Debug, Clone)]
pub struct Predictor {
    covariance: Covariance,
    calibrated: Robot,
    tool: Isometry3<f64>,
    sensor: bool,
    /// The rigid-motion fit `M` (6 × k) and the centroid, when aligned.
    alignment: Option<(DMatrix<f64>, Vector3<f64>)>,
}

impl Predictor {
    /// The predictor of `covariance` for the TCP `flange_from_tcp` of the
    /// `calibrated` model, aligned over `poses` (deg; none: not aligned).
    #[must_use]
    pub fn new(
        covariance: Covariance,
        calibrated: Robot,
        tool: Isometry3<f64>,
        sensor: bool,
        poses: &[[f64; DOF]],
    ) -> Self {
        let mut out = Self {
            covariance,
            calibrated,
            tool,
            sensor,
            alignment: None,
        };
        if poses.len() >= 3 {
            let rows: Vec<(Vector3<f64>, DMatrix<f64>)> = poses
                .iter()
                .map(|q| out.covariance.rows(&out.calibrated, &out.tool, sensor, q))
                .collect();
            let centroid = rows.iter().map(|(p, _)| p).sum::<Vector3<f64>>() / rows.len() as f64;
            let k = out.covariance.index.len();
            let mut rtr = DMatrix::zeros(6, 6);
            let mut rtg = DMatrix::zeros(6, k);
            for (p, g) in &rows {
                let r = rigid_rows(p, &centroid);
                rtr += r.transpose() * &r;
                rtg += r.transpose() * g;
            }
            // Poses on one line leave a rotation free: the pseudo-inverse
            // takes out what can be taken out.
            let tolerance = 1e-12 * rtr.norm().max(1e-300);
            if let Ok(pinv) = rtr.pseudo_inverse(tolerance) {
                out.alignment = Some((pinv * rtg, centroid));
            }
        }
        out
    }

    /// Whether σ is aligned (module doc).
    #[must_use]
    pub fn aligned(&self) -> bool {
        self.alignment.is_some()
    }

    /// σ (mm) of the TCP origin at the calibrated model's joints `q` (deg).
    #[must_use]
    pub fn sigma(&self, q: &[f64; DOF]) -> f64 {
        let (p, g) = self
            .covariance
            .rows(&self.calibrated, &self.tool, self.sensor, q);
        let h = match &self.alignment {
            Some((m, c)) => g - rigid_rows(&p, c) * m,
            None => g,
        };
        (&h * &self.covariance.matrix * h.transpose())
            .trace()
            .max(0.0)
            .sqrt()
    }
}
