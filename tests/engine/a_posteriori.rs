//! Every σ a user sees is a posteriori: the covariance as written times
//! the result's variance factor (issue 32). A result whose variance
//! factor is 4 × another's, all else equal, gives σ 2 × as large in
//! measuring's covariance, compensation's predicted σ and the result
//! view's (report's, workbench's) parameter and hand-eye σ, which also
//! keep the a priori σ.

// Test helpers may panic: a panic is a test failure with its message.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use spherecal::engine::calibrate::solve::SolverReport;
use spherecal::engine::calibrate::solve::ml::covariance::{ParameterCovariance, variance_factor};
use spherecal::engine::files::format::{ResultFile, load_result};
use spherecal::engine::tools::result_view::ResultFigures;
use spherecal::engine::uses::compensate::{Model, Tcp};

const RESULT: &str = "sessions/history/cell3-2026-05-11.result.json";

fn with_factor(result: &ResultFile, factor: f64) -> ResultFile {
    let mut r = result.clone();
    let SolverReport::Ml(ml) = &mut r.solver else {
        panic!("{RESULT} is not an ml result");
    };
    ml.variance_factor = factor;
    r
}

#[test]
fn every_sigma_downstream_scales_with_the_variance_factor() {
    let base = load_result(Path::new(RESULT)).unwrap();
    let one = with_factor(&base, 1.0);
    let four = with_factor(&base, 4.0);
    assert_eq!(variance_factor(&four.solver), 4.0);

    // The covariance every user reads (measure, compensate).
    let c1 = ParameterCovariance::read_a_posteriori(&one.solver, 6)
        .unwrap()
        .unwrap();
    let c4 = ParameterCovariance::read_a_posteriori(&four.solver, 6)
        .unwrap()
        .unwrap();
    let as_written = ParameterCovariance::read(&four.solver, 6).unwrap().unwrap();
    assert!((&c4.matrix - &c1.matrix * 4.0).amax() <= 1e-12 * c4.matrix.amax());
    assert!((&as_written.matrix - &c1.matrix).amax() <= 1e-15 * c1.matrix.amax());

    // Compensation's predicted σ at a few joint vectors.
    let m1 = Model::new(&one, None, Tcp::Sensor).unwrap();
    let m4 = Model::new(&four, None, Tcp::Sensor).unwrap();
    for q in [
        [0.0, 10.0, 20.0, 0.0, 40.0, 0.0],
        [30.0, -10.0, 35.0, 20.0, -60.0, 90.0],
    ] {
        let (s1, s4) = (
            m1.predicted_sigma(&q).unwrap(),
            m4.predicted_sigma(&q).unwrap(),
        );
        assert!(s1 > 0.0, "σ {s1}");
        assert!((s4 / s1 - 2.0).abs() < 1e-9, "{s4} / {s1}");
    }

    // The result view: σ a posteriori, the a priori kept.
    let v1 = ResultFigures::new(&one);
    let v4 = ResultFigures::new(&four);
    assert_eq!(v4.variance_factor, 4.0);
    let (h1, h4) = (v1.hand_eye_sigma.unwrap(), v4.hand_eye_sigma.unwrap());
    let prior = v4.hand_eye_sigma_a_priori.unwrap();
    for k in 0..6 {
        assert!((h4[k] / h1[k] - 2.0).abs() < 1e-9);
        assert!((prior[k] - h1[k]).abs() <= 1e-12 * h1[k]);
    }
    assert!(!v4.sigma.is_empty());
    for (label, s) in &v4.sigma {
        let s1 = &v1.sigma[label];
        assert!(
            (s.std - 2.0 * s1.std).abs() <= 1e-12 * s.std.max(1e-300),
            "{label}"
        );
        assert!(
            (s.a_priori - s1.std).abs() <= 1e-15 * s1.std.max(1e-300),
            "{label}"
        );
    }
}
