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
//! prediction does, the rigid motion that best fits the errors of the
//! TCP over the poses the calibration saw, `M = (RᵀR)⁺RᵀG`, is removed
//! from each target's: `H = A − R(p)·M`, `σ² = tr(H·C·Hᵀ)` (the algebra
//! and the covariance's reading are
//! [`covariance`](crate::engine::calibrate::solve::ml::covariance)'s). Without those poses (a result
//! that records no joints) σ is not aligned and says so. The robot's
//! repeatability is not in σ.

use nalgebra::{DMatrix, Isometry3, Vector3};

use crate::engine::base::robot::Robot;
use crate::engine::base::robot::ik::DOF;
use crate::engine::base::session::Mount;
use crate::engine::calibrate::solve::estimate::{Estimate, PoseSensitivity};
use crate::engine::calibrate::solve::ml::covariance::{
    ParameterCovariance, RigidFit, aligned_sigma,
};

/// The predicted σ of targets of one calibration and TCP (module doc).
#[derive(Debug, Clone)]
pub struct Predictor {
    /// Index in `ΔY` of each row of the covariance.
    unknowns: Vec<usize>,
    /// The covariance in engine units (rad, mm).
    matrix: DMatrix<f64>,
    calibrated: Robot,
    tool: Isometry3<f64>,
    sensor: bool,
    /// The rigid-motion fit over the calibration's poses, when aligned.
    alignment: Option<RigidFit>,
}

impl Predictor {
    /// The predictor of `covariance` for the TCP `flange_from_tcp` of the
    /// `calibrated` model, aligned over `poses` (deg; fewer than 3: not
    /// aligned); `sensor` says whether the TCP is the calibrated sensor
    /// (its hand-eye columns then count).
    #[must_use]
    pub fn new(
        covariance: &ParameterCovariance,
        calibrated: Robot,
        tool: Isometry3<f64>,
        sensor: bool,
        poses: &[[f64; DOF]],
    ) -> Self {
        let mut out = Self {
            unknowns: covariance.unknowns.clone(),
            matrix: covariance.in_engine_units(),
            calibrated,
            tool,
            sensor,
            alignment: None,
        };
        if poses.len() >= 3 {
            let rows: Vec<(Vector3<f64>, DMatrix<f64>)> =
                poses.iter().map(|q| out.rows(q)).collect();
            out.alignment = Some(RigidFit::new(
                rows.iter().map(|(p, g)| (p, g)),
                out.unknowns.len(),
            ));
        }
        out
    }

    /// The sensitivity `A` (3 × k, the covariance's columns) of the TCP
    /// origin at joints `q` (deg) of the calibrated model, and the origin
    /// (base frame, mm).
    fn rows(&self, q: &[f64; DOF]) -> (Vector3<f64>, DMatrix<f64>) {
        let est = Estimate {
            robot: self.calibrated.clone(),
            flange_from_sensor: self.tool,
            mount: Mount::Flange,
        };
        let (p, a) = PoseSensitivity::at_pose(&est, q, None).at(&est, &Vector3::zeros());
        let cols = DMatrix::from_fn(3, self.unknowns.len(), |r, c| {
            let u = self.unknowns[c];
            if u < 6 && !self.sensor {
                0.0
            } else {
                a[(r, u)]
            }
        });
        (p, cols)
    }

    /// Whether σ is aligned (module doc).
    #[must_use]
    pub fn aligned(&self) -> bool {
        self.alignment.is_some()
    }

    /// σ (mm) of the TCP origin at the calibrated model's joints `q` (deg).
    #[must_use]
    pub fn sigma(&self, q: &[f64; DOF]) -> f64 {
        let (p, g) = self.rows(q);
        let h = match &self.alignment {
            Some(fit) => fit.aligned(&g, &p),
            None => g,
        };
        aligned_sigma(&h, &self.matrix)
    }
}
