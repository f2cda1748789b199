//! Issue 32's real-set check: the real set `data/robcalibrator-sphere`
//! imported with the default start (eq. 6-9) and with RobCalibrator's own
//! hand-eye as the guess (`import --hand-eye`) reaches the same hand-eye,
//! and reports the same pose σ, variance factor and hand-eye 1σ (within
//! 5 %): the uncertainty is a property of the data, not of the start.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion};
use spherecal::engine::calibrate::solve::{self, Options, SolverReport};
use spherecal::engine::files::import::{
    AxisMap, FlangeConvention, Observations, PoseImportSpec, ProfileFormat, ProfileSource,
    SideChoice,
};

fn spec(dir: &Path, hand_eye: Option<Isometry3<f64>>) -> PoseImportSpec {
    PoseImportSpec {
        poses: dir.join("RobPoses.rob"),
        format: None,
        convention: Some(FlangeConvention::FanucWpr),
        pose_columns: None,
        observations: Observations::Profiles(ProfileSource::Folder(dir.to_path_buf())),
        profile_format: ProfileFormat::default(),
        robot: None,
        sphere_diameter: 80.0,
        side: SideChoice::Auto,
        hand_eye,
        name: None,
        references: None,
    }
}

/// RobCalibrator's hand-eye (`calibration.sec`, `Solution.HTM`) in
/// spherecal's sensor axes (the import's guessed map `-y,x,z`).
fn robcalibrator_hand_eye(dir: &Path) -> Isometry3<f64> {
    let text = std::fs::read_to_string(dir.join("calibration.sec")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let m = &v["Solution"]["HTM"];
    let at = |i: usize, j: usize| m[i][j].as_f64().unwrap();
    let theirs = Isometry3::from_parts(
        Translation3::new(at(0, 3), at(1, 3), at(2, 3)),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix(&Matrix3::from_fn(at))),
    );
    let map = AxisMap::parse("-y,x,z").unwrap().rotation();
    theirs
        * Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix(&map.transpose())),
        )
}

/// (pose σ, variance factor, hand-eye 1σ per axis: x y z mm, rx ry rz deg,
/// the hand-eye).
fn calibrated(spec: &PoseImportSpec) -> (f64, f64, Vec<f64>, Isometry3<f64>) {
    let imported = spherecal::engine::assemble::import_poses(spec).unwrap();
    let session = &imported.session;
    let (_, cal) = solve::calibrate(session, &Options::from_session(session)).unwrap();
    let SolverReport::Ml(ml) = &cal.report else {
        panic!("not an ml report")
    };
    let c = &ml.covariance;
    let sigmas = ["he_x", "he_y", "he_z", "he_rx", "he_ry", "he_rz"]
        .iter()
        .map(|l| {
            let k = c.labels.iter().position(|x| x == l).expect(l);
            c.matrix[k][k].sqrt()
        })
        .collect();
    (
        ml.noise_model.pose_sigma_mm.expect("estimated"),
        ml.variance_factor,
        sigmas,
        cal.hand_eye,
    )
}

#[test]
fn the_real_set_reports_the_same_uncertainty_from_both_starts() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/robcalibrator-sphere");
    assert!(
        dir.join("RobPoses.rob").is_file(),
        "the real set is missing"
    );
    let (s0, f0, h0, he0) = calibrated(&spec(&dir, None));
    let (s1, f1, h1, he1) = calibrated(&spec(&dir, Some(robcalibrator_hand_eye(&dir))));
    let apart = (he0.translation.vector - he1.translation.vector).norm();
    eprintln!(
        "default start: pose σ {s0:.4} mm, variance factor {f0:.3}, hand-eye 1σ {h0:.3?}\n\
         RobCalibrator's hand-eye: pose σ {s1:.4} mm, variance factor {f1:.3}, hand-eye 1σ {h1:.3?}\n\
         hand-eyes {apart:.4} mm apart"
    );
    assert!(
        apart < 0.1,
        "the two starts reach hand-eyes {apart} mm apart"
    );
    let within = |a: f64, b: f64| (a / b - 1.0).abs() <= 0.05;
    assert!(within(s1, s0), "pose σ {s1} vs {s0} mm");
    assert!(within(f1, f0), "variance factor {f1} vs {f0}");
    for (k, (a, b)) in h1.iter().zip(&h0).enumerate() {
        assert!(within(*a, *b), "hand-eye 1σ {k}: {a} vs {b}");
    }
}
