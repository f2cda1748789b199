//! `spherecal measure` against the truth of seeded simulated sessions:
//! the cloud is the result's model applied (checked by a forward
//! kinematics written here from FORMAT.md, on the files' JSON), each
//! point's σ agrees with the realised error of the calibrated model, the
//! validate spheres fitted in the measured cloud sit much closer to the
//! truth than with the nominal model, the PLY and E57 files read back
//! with readers we did not write, and bad inputs are refused with exit
//! status 2 and nothing written.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use nalgebra::{Isometry3, Matrix4, Point3, Vector3, Vector4};
use serde_json::Value;
use spherecal::engine::base::geometry::kabsch;
use spherecal::engine::base::session::{Session, Use};
use spherecal::engine::calibrate::solve::{self, Control, Method, Options, SolverReport};
use spherecal::engine::files::format::{self, ResultFile};
use spherecal::engine::tools::simulate::{self, SimConfig, Truth};
use spherecal::engine::uses::measure::{
    self, CellModel, MeasureOptions, ModelChoice, Scan, model::covariance_of,
};

use crate::support::measure as measure_support;
use measure_support::{calibrated, csv_cloud, files, rms, run, seed, temp_dir};

// ---------------------------------------------------------------------
// The model applied, from FORMAT.md, on the files' JSON (no engine code).

fn matrix(v: &Value) -> Matrix4<f64> {
    Matrix4::from_fn(|i, j| v[i][j].as_f64().unwrap())
}

fn rx(a: f64) -> Matrix4<f64> {
    let (s, c) = a.to_radians().sin_cos();
    Matrix4::new(
        1.0, 0.0, 0.0, 0.0, 0.0, c, -s, 0.0, 0.0, s, c, 0.0, 0.0, 0.0, 0.0, 1.0,
    )
}

fn ry(a: f64) -> Matrix4<f64> {
    let (s, c) = a.to_radians().sin_cos();
    Matrix4::new(
        c, 0.0, s, 0.0, 0.0, 1.0, 0.0, 0.0, -s, 0.0, c, 0.0, 0.0, 0.0, 0.0, 1.0,
    )
}

fn rz(a: f64) -> Matrix4<f64> {
    let (s, c) = a.to_radians().sin_cos();
    Matrix4::new(
        c, -s, 0.0, 0.0, s, c, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    )
}

fn tr(x: f64, y: f64, z: f64) -> Matrix4<f64> {
    Matrix4::new(
        1.0, 0.0, 0.0, x, 0.0, 1.0, 0.0, y, 0.0, 0.0, 1.0, z, 0.0, 0.0, 0.0, 1.0,
    )
}

/// `B · T_1 · … · T_n · F · eT_s` of the result file at joints `q` (deg),
/// `T_i = Rx(alpha) Tx(a) Ry(beta) Rz(q + theta) Tz(d)`.
fn base_from_sensor(result: &Value, q: &[f64]) -> Matrix4<f64> {
    let robot = &result["robot"];
    let mut t = matrix(&robot["base"]);
    for (j, qi) in robot["joints"].as_array().unwrap().iter().zip(q) {
        let p = |k: &str| j[k].as_f64().unwrap();
        t = t
            * rx(p("alpha"))
            * tr(p("a"), 0.0, 0.0)
            * ry(p("beta"))
            * rz(qi + p("theta"))
            * tr(0.0, 0.0, p("d"));
    }
    t * matrix(&robot["flange"]) * matrix(&result["hand_eye"])
}

/// Every stripe point of the session file through the result file: `(id,
/// x, y, z)` in file order.
fn expected_cloud(session: &Path, result: &Path) -> Vec<(String, [f64; 3])> {
    let s: Value = serde_json::from_str(&std::fs::read_to_string(session).unwrap()).unwrap();
    let r: Value = serde_json::from_str(&std::fs::read_to_string(result).unwrap()).unwrap();
    let mut out = Vec::new();
    for m in s["measurements"].as_array().unwrap() {
        let q: Vec<f64> = m["joints"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let t = base_from_sensor(&r, &q);
        for p in m["stripe"]["points"].as_array().unwrap() {
            let (y, z) = (p[0].as_f64().unwrap(), p[1].as_f64().unwrap());
            let x = t * Vector4::new(0.0, y, z, 1.0);
            out.push((m["id"].as_str().unwrap().to_string(), [x.x, x.y, x.z]));
        }
    }
    out
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    (Vector3::from(a) - Vector3::from(b)).norm()
}

#[test]
fn the_cloud_is_the_model_applied_and_reads_back_in_every_format() {
    let dir = temp_dir("exact");
    let (session, _, result) = calibrated(&seed(11), Method::Ml);
    let (s, r) = files(&dir, &session, &result);
    let csv = dir.join("cloud.csv");
    let out = run(&[
        "measure",
        s.to_str().unwrap(),
        "--result",
        r.to_str().unwrap(),
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("self-validation") && text.contains("size error"),
        "{text}"
    );
    let expected = expected_cloud(&s, &r);
    let cloud = csv_cloud(&csv);
    assert_eq!(cloud.len(), expected.len());
    let mut worst = 0.0_f64;
    for ((id, x, sigma), (eid, ex)) in cloud.iter().zip(&expected) {
        assert_eq!(id, eid);
        worst = worst.max(distance(*x, *ex));
        assert!(sigma.is_finite() && *sigma > 0.0 && *sigma < 1.0, "{sigma}");
    }
    assert!(worst <= 1e-9, "largest difference {worst:e} mm");

    // PLY, read by ply-rs-bw: the same points, σ as float, pose indices.
    let ply = dir.join("cloud.ply");
    assert!(
        run(&[
            "measure",
            s.to_str().unwrap(),
            "--result",
            r.to_str().unwrap(),
            "--out",
            ply.to_str().unwrap(),
            "-q"
        ])
        .status
        .success()
    );
    let parser = ply_rs_bw::parser::Parser::<ply_rs_bw::ply::DefaultElement>::new();
    let mut file = std::fs::File::open(&ply).unwrap();
    let read = parser.read_ply(&mut file).unwrap();
    assert!(
        read.header.comments.iter().any(|c| c.contains("r.json")),
        "{:?}",
        read.header.comments
    );
    assert!(
        read.header
            .comments
            .iter()
            .any(|c| c.contains("robot base frame"))
    );
    let vertices = &read.payload["vertex"];
    assert_eq!(vertices.len(), cloud.len());
    let ids: Vec<&str> = session.measurements.iter().map(|m| m.id.as_str()).collect();
    for (v, (id, x, sigma)) in vertices.iter().zip(&cloud) {
        use ply_rs_bw::ply::Property;
        let d = |k: &str| match v[k] {
            Property::Double(x) => x,
            ref other => panic!("{k}: {other:?}"),
        };
        assert_eq!([d("x"), d("y"), d("z")], *x, "PLY doubles equal the CSV's");
        let Property::Float(s) = v["sigma_mm"] else {
            panic!()
        };
        assert!((f64::from(s) - sigma).abs() <= 1e-6 * sigma);
        let Property::UInt(k) = v["pose"] else {
            panic!()
        };
        assert_eq!(ids[k as usize], id);
    }

    // E57, read by the e57 crate with each scan's pose applied (metres).
    let e57_path = dir.join("cloud.e57");
    assert!(
        run(&[
            "measure",
            s.to_str().unwrap(),
            "--result",
            r.to_str().unwrap(),
            "--out",
            e57_path.to_str().unwrap(),
            "-q"
        ])
        .status
        .success()
    );
    let mut reader = e57::E57Reader::from_file(&e57_path).unwrap();
    let scans = reader.pointclouds();
    assert_eq!(scans.len(), session.measurements.len(), "one scan a pose");
    let mut k = 0;
    let mut worst = 0.0_f64;
    for pc in &scans {
        assert!(pc.transform.is_some(), "each scan carries its sensor pose");
        let name = pc.name.clone().unwrap();
        for p in reader.pointcloud_simple(pc).unwrap() {
            let p = p.unwrap();
            let e57::CartesianCoordinate::Valid { x, y, z } = p.cartesian else {
                panic!()
            };
            let (id, expected, _) = &cloud[k];
            assert_eq!(&name, id);
            worst = worst.max(distance([x * 1e3, y * 1e3, z * 1e3], *expected));
            k += 1;
        }
    }
    assert_eq!(k, cloud.len());
    assert!(worst < 1e-9, "E57 vs CSV {worst:e} mm");
    // σ rides as the extension attribute spherecal:sigma_mm.
    let raw: Vec<_> = reader
        .pointcloud_raw(&scans[0])
        .unwrap()
        .map(Result::unwrap)
        .collect();
    let e57::RecordValue::Single(s0) = raw[0][3] else {
        panic!("{:?}", raw[0])
    };
    assert!((f64::from(s0) - cloud[0].2).abs() <= 1e-6 * cloud[0].2);
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------
// σ against the realised error of the calibrated model.

/// Per point of the session's cloud: σ (mm) and the realised error of the
/// calibrated model (calibrated minus true model, the same sensor point
/// and the true joints, after the best rigid alignment of all points).
fn sigma_and_error(session: &Session, truth: &Truth, result: &ResultFile) -> (Vec<f64>, Vec<f64>) {
    let true_robot = truth.true_robot();
    let true_he = truth.true_hand_eye();
    let calibrated = result.robot.clone().unwrap();
    let mut cal = Vec::new();
    let mut exact = Vec::new();
    for m in &session.measurements {
        let q = &truth.measurement(&m.id).unwrap().joints_actual;
        let bc: Isometry3<f64> = calibrated.base_from_flange(q) * result.hand_eye;
        let bt: Isometry3<f64> = true_robot.base_from_flange(q) * true_he;
        let spherecal::engine::base::session::Observation::Stripe(points) = &m.observation else {
            panic!()
        };
        for &[y, z] in points {
            let g = Point3::new(0.0, y, z);
            cal.push((bc * g).coords);
            exact.push((bt * g).coords);
        }
    }
    let fit = kabsch(&cal, &exact).unwrap();
    let errors = cal
        .iter()
        .zip(&exact)
        .map(|(c, t)| ((fit * Point3::from(*c)).coords - t).norm())
        .collect();
    let measured = measure::measure(
        Scan::from_session(session.clone(), &[]),
        result,
        &MeasureOptions {
            sigma: true,
            ..MeasureOptions::default()
        },
        None,
        &mut |_| Control::Continue,
    )
    .unwrap();
    let sigma = measured.cloud.points().map(|p| p.sigma_mm).collect();
    (sigma, errors)
}

#[test]
fn sigma_agrees_with_the_realised_model_error() {
    let (mut sigma_sq, mut error_sq, mut n) = (0.0, 0.0, 0.0);
    let mut per_seed = Vec::new();
    let mut wrong_sq = [0.0; 3];
    for s in [1_u64, 2, 3, 4, 5] {
        let (session, truth, result) = calibrated(&seed(s), Method::Ml);
        let (sigma, errors) = sigma_and_error(&session, &truth, &result);
        assert_eq!(sigma.len(), errors.len());
        per_seed.push((rms(&sigma), rms(&errors)));
        sigma_sq += sigma.iter().map(|x| x * x).sum::<f64>();
        error_sq += errors.iter().map(|x| x * x).sum::<f64>();
        n += sigma.len() as f64;
        // Wrong covariances must fail the same check: 9 times too large
        // or too small (σ off by 3), and without its correlations.
        for (slot, wrong) in [
            scaled(&result, 9.0),
            scaled(&result, 1.0 / 9.0),
            diagonal(&result),
        ]
        .iter()
        .enumerate()
        {
            let (wrong_sigma, _) = sigma_and_error(&session, &truth, wrong);
            wrong_sq[slot] += wrong_sigma.iter().map(|x| x * x).sum::<f64>();
        }
    }
    let ratio = (error_sq / sigma_sq).sqrt();
    let wrong: Vec<f64> = wrong_sq.iter().map(|w| (error_sq / w).sqrt()).collect();
    eprintln!(
        "rms σ and realised error per seed: {per_seed:?}; realised / σ = {ratio:.3}; with covariance ×9, ÷9, diagonal: {wrong:.3?}; {n} points"
    );
    assert!(
        (0.5..=2.0).contains(&ratio),
        "realised / predicted = {ratio}"
    );
    assert!(
        !(0.5..=2.0).contains(&wrong[0]),
        "a covariance 9× too large passes: {}",
        wrong[0]
    );
    assert!(
        !(0.5..=2.0).contains(&wrong[1]),
        "a covariance 9× too small passes: {}",
        wrong[1]
    );
    assert!(
        !(0.5..=2.0).contains(&wrong[2]),
        "a covariance without correlations passes: {}",
        wrong[2]
    );
}

#[test]
fn sigma_follows_a_noisier_cell_through_the_variance_factor() {
    // Joints 3× noisier than ml's noise model assumes (0.01° against
    // 0.003°): the covariance as written is too small by about that much,
    // the variance factor (≈ 10) restores it.
    let (mut sigma_sq, mut written_sq, mut error_sq) = (0.0, 0.0, 0.0);
    for s in [1_u64, 2, 3] {
        let config = SimConfig {
            joint_noise: 0.01,
            ..seed(s)
        };
        let (session, truth, result) = calibrated(&config, Method::Ml);
        let vf = measure::variance_factor(&result);
        assert!(vf > 4.0, "variance factor {vf}");
        let (sigma, errors) = sigma_and_error(&session, &truth, &result);
        sigma_sq += sigma.iter().map(|x| x * x).sum::<f64>();
        written_sq += sigma.iter().map(|x| x * x / vf).sum::<f64>();
        error_sq += errors.iter().map(|x| x * x).sum::<f64>();
    }
    let ratio = (error_sq / sigma_sq).sqrt();
    let as_written = (error_sq / written_sq).sqrt();
    eprintln!(
        "noisier joints: realised / σ = {ratio:.3}, with the covariance as written {as_written:.3}"
    );
    assert!((0.5..=2.0).contains(&ratio), "{ratio}");
    assert!(as_written > ratio, "{as_written} vs {ratio}");
}

/// The result with its covariance times `factor`.
fn scaled(result: &ResultFile, factor: f64) -> ResultFile {
    let mut out = result.clone();
    if let SolverReport::Ml(ml) = &mut out.solver {
        for row in &mut ml.covariance.matrix {
            for v in row.iter_mut() {
                *v *= factor;
            }
        }
    }
    out
}

/// The result with its covariance's correlations dropped.
fn diagonal(result: &ResultFile) -> ResultFile {
    let mut out = result.clone();
    if let SolverReport::Ml(ml) = &mut out.solver {
        for (i, row) in ml.covariance.matrix.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                if i != j {
                    *v = 0.0;
                }
            }
        }
    }
    out
}

// ---------------------------------------------------------------------
// The self-validation against the true stations.

/// RMS distance (mm) of fitted station centres from the true ones after
/// the best rigid alignment.
fn aligned_rms(centres: &[Vector3<f64>], truth: &[Vector3<f64>]) -> f64 {
    let fit = kabsch(centres, truth).unwrap();
    let e: Vec<f64> = centres
        .iter()
        .zip(truth)
        .map(|(c, t)| ((fit * Point3::from(*c)).coords - t).norm())
        .collect();
    rms(&e)
}

#[test]
fn validate_spheres_sit_at_least_three_times_closer_to_the_truth() {
    for s in [1_u64, 2, 3] {
        let (session, truth, result) = calibrated(&seed(s), Method::Ml);
        let measured = measure::measure(
            Scan::from_session(session.clone(), &[Use::Validate]),
            &result,
            &MeasureOptions::default(),
            None,
            &mut |_| Control::Continue,
        )
        .unwrap();
        let check = measure::self_validate(
            &measured.cloud.poses,
            &CellModel::of_result(&result, ModelChoice::Nominal),
            &CellModel::of_result(&result, ModelChoice::Calibrated),
            session.sphere_diameter,
            &session.reference_distances,
        )
        .unwrap();
        assert_eq!(check.after.stations.len(), 10);
        let true_centres: Vec<Vector3<f64>> = check
            .after
            .stations
            .iter()
            .map(|st| truth.station(&st.station).unwrap())
            .collect();
        let centres = |m: &measure::selfcheck::ModelCheck| -> Vec<Vector3<f64>> {
            m.stations.iter().map(|st| st.fit.centre).collect()
        };
        let before = aligned_rms(&centres(&check.before), &true_centres);
        let after = aligned_rms(&centres(&check.after), &true_centres);
        eprintln!("seed {s}: station centres vs truth {before:.4} → {after:.4} mm");
        assert!(before >= 3.0 * after, "seed {s}: {before} vs {after}");
        assert!(after < 0.3, "seed {s}: {after}");
        // ISO-style figures: the calibrated cell measures the sphere's size
        // and spacing far better than the nominal one.
        assert!(check.after.size().0 < check.before.size().0 / 3.0);
        let (b, a) = (
            check.before.spacing_error().unwrap(),
            check.after.spacing_error().unwrap(),
        );
        assert!(a.0 < b.0 / 3.0, "{a:?} {b:?}");
    }
}

// ---------------------------------------------------------------------
// Options, a decimated view, and bad input.

#[test]
fn frames_models_and_decimation() {
    let dir = temp_dir("frames");
    let (session, _, result) = calibrated(&seed(4), Method::Ml);
    let (s, r) = files(&dir, &session, &result);
    let (s, r) = (s.to_str().unwrap(), r.to_str().unwrap());
    // A workpiece frame: the cloud is W⁻¹ · X_b, σ unchanged.
    let w = Isometry3::new(
        Vector3::new(900.0, -50.0, 400.0),
        Vector3::new(0.1, -0.2, 0.7),
    );
    let frame = dir.join("frame.json");
    let rows = spherecal::engine::base::geometry::rows_from_isometry(&w);
    std::fs::write(&frame, serde_json::to_string(&rows).unwrap()).unwrap();
    let (base_csv, part_csv) = (dir.join("base.csv"), dir.join("part.csv"));
    assert!(
        run(&[
            "measure",
            s,
            "--result",
            r,
            "--out",
            base_csv.to_str().unwrap(),
            "-q"
        ])
        .status
        .success()
    );
    let out = run(&[
        "measure",
        s,
        "--result",
        r,
        "--out",
        part_csv.to_str().unwrap(),
        "--frame",
        frame.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("workpiece frame"));
    for ((_, b, sb), (_, p, sp)) in csv_cloud(&base_csv).iter().zip(&csv_cloud(&part_csv)) {
        let expect = (w.inverse() * Point3::from(*b)).coords;
        assert!((Vector3::from(*p) - expect).norm() < 1e-9);
        assert!((sb - sp).abs() < 1e-12 * sb);
    }
    // Validate only, the nominal model: no σ, NaN in the file.
    let nominal = dir.join("nominal.csv");
    assert!(
        run(&[
            "measure",
            s,
            "--result",
            r,
            "--out",
            nominal.to_str().unwrap(),
            "--use",
            "validate",
            "--model",
            "nominal",
            "-q"
        ])
        .status
        .success()
    );
    let cloud = csv_cloud(&nominal);
    assert!(
        cloud
            .iter()
            .all(|(id, _, sigma)| id.starts_with('v') && sigma.is_nan())
    );
    // The decimated view: evenly spread, the same points.
    let measured = measure::measure(
        Scan::from_session(session.clone(), &[]),
        &result,
        &MeasureOptions {
            sigma: true,
            ..MeasureOptions::default()
        },
        None,
        &mut |_| Control::Continue,
    )
    .unwrap();
    let all: Vec<_> = measured.cloud.points().collect();
    let view = measured.cloud.decimated(1000);
    assert_eq!(view.len(), 1000);
    for (k, p) in view.iter().enumerate() {
        assert_eq!(*p, all[k * all.len() / 1000]);
    }
    assert_eq!(measured.cloud.decimated(all.len() + 5).len(), all.len());
    // Progress reaches the end of both stages; Cancel stops.
    let mut steps = 0;
    let cancelled = measure::measure(
        Scan::from_session(session.clone(), &[]),
        &result,
        &MeasureOptions {
            sigma: true,
            ..MeasureOptions::default()
        },
        None,
        &mut |p| {
            steps += 1;
            if p.stage == measure::Stage::Sigma {
                Control::Cancel
            } else {
                Control::Continue
            }
        },
    );
    assert!(matches!(cancelled, Err(measure::MeasureError::Cancelled)));
    assert_eq!(steps, session.measurements.len() + 1);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs `measure` expecting exit 2 with `needle` in the message and no
/// output file.
fn refused(args: &[&str], out: &Path, needle: &str) {
    let o = run(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert!(
        err.starts_with("error:") && err.contains(needle),
        "{args:?}: {err}"
    );
    assert!(!out.exists(), "{} was written", out.display());
}

#[test]
fn bad_input_is_refused_and_nothing_is_written() {
    let dir = temp_dir("bad");
    let (session, _, result) = calibrated(&seed(6), Method::Ml);
    let (s, r) = files(&dir, &session, &result);
    let (s, r) = (s.to_str().unwrap(), r.to_str().unwrap());
    let out = dir.join("cloud.ply");
    let o = out.to_str().unwrap();
    // A result of another robot.
    let ur = SimConfig {
        robot: spherecal::engine::base::robot::RobotChoice::Ur5e,
        ..seed(6)
    };
    let (ur_session, _, ur_result) = calibrated(&ur, Method::Paper);
    let ur_r = dir.join("ur.result.json");
    format::save_result(&ur_result, &ur_r).unwrap();
    refused(
        &[
            "measure",
            s,
            "--result",
            ur_r.to_str().unwrap(),
            "--out",
            o,
            "--no-sigma",
        ],
        &out,
        "not the result's",
    );
    // A frame that is not rigid (a scaled rotation), and one that is not 4x4.
    let frame = dir.join("frame.json");
    std::fs::write(&frame, "[[2,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]").unwrap();
    refused(
        &[
            "measure",
            s,
            "--result",
            r,
            "--out",
            o,
            "--frame",
            frame.to_str().unwrap(),
        ],
        &out,
        "not a rigid transform",
    );
    std::fs::write(&frame, "[[1,0,0],[0,1,0],[0,0,1]]").unwrap();
    refused(
        &[
            "measure",
            s,
            "--result",
            r,
            "--out",
            o,
            "--frame",
            frame.to_str().unwrap(),
        ],
        &out,
        "4x4",
    );
    // A result without covariance: σ refused unless --no-sigma.
    let (_, _, paper) = calibrated(&seed(6), Method::Paper);
    let pr = dir.join("paper.result.json");
    format::save_result(&paper, &pr).unwrap();
    assert!(covariance_of(&paper).unwrap().is_none());
    refused(
        &["measure", s, "--result", pr.to_str().unwrap(), "--out", o],
        &out,
        "--no-sigma",
    );
    let csv = dir.join("paper.csv");
    assert!(
        run(&[
            "measure",
            s,
            "--result",
            pr.to_str().unwrap(),
            "--out",
            csv.to_str().unwrap(),
            "--no-sigma",
            "-q"
        ])
        .status
        .success()
    );
    assert!(csv_cloud(&csv).iter().all(|(_, _, sigma)| sigma.is_nan()));
    // A session of given centres has no profile to measure.
    let centres = concat!(env!("CARGO_MANIFEST_DIR"), "/sessions/centres-irb2400.json");
    refused(
        &["measure", centres, "--result", r, "--out", o],
        &out,
        "nothing to measure",
    );
    // Output = input; an unknown extension.
    refused(
        &["measure", s, "--result", r, "--out", r],
        Path::new("/nonexistent"),
        "the input",
    );
    let txt = dir.join("cloud.txt");
    refused(
        &["measure", s, "--result", r, "--out", txt.to_str().unwrap()],
        &txt,
        ".ply, .e57 or .csv",
    );
    // Poses beyond the joint range the calibration saw: warned and listed,
    // the cloud written. The UR session's joints against its own result
    // calibrated from identify poses only.
    let ur_s = dir.join("ur.json");
    format::save_session(&ur_session, &ur_s).unwrap();
    let o2 = run(&[
        "measure",
        ur_s.to_str().unwrap(),
        "--result",
        ur_r.to_str().unwrap(),
        "--out",
        o,
        "--no-sigma",
    ]);
    assert!(o2.status.success());
    let err = String::from_utf8_lossy(&o2.stderr);
    assert!(
        err.contains("outside the joint range the calibration saw") && err.contains("pose "),
        "{err}"
    );
    assert!(out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn pose_only_results_measure_with_the_given_flange_poses() {
    // A session turned pose-only: each flange pose the true robot's.
    let (mut session, truth) = simulate::simulate(&seed(9)).unwrap();
    let joints_session = session.clone();
    let robot = truth.true_robot();
    for m in &mut session.measurements {
        m.flange = Some(robot.base_from_flange(&m.joints));
        m.joints.clear();
    }
    session.robot_given = false;
    session.robot = spherecal::engine::base::robot::Robot::new(String::new(), Vec::new());
    let mut options = Options::from_session(&session);
    options.ml.cross_validation = false;
    let (_, cal) = solve::calibrate(&session, &options).unwrap();
    let result = ResultFile::from_calibration(&session, &cal);
    assert!(result.hand_eye_only());
    let measured = measure::measure(
        Scan::from_session(session.clone(), &[]),
        &result,
        &MeasureOptions {
            sigma: true,
            ..MeasureOptions::default()
        },
        None,
        &mut |_| Control::Continue,
    )
    .unwrap();
    let mut points = measured.cloud.points();
    for m in &session.measurements {
        let t = m.flange.unwrap() * result.hand_eye;
        let spherecal::engine::base::session::Observation::Stripe(stripe) = &m.observation else {
            panic!()
        };
        for &[y, z] in stripe {
            let p = points.next().unwrap();
            assert!(
                (Vector3::from(p.position) - (t * Point3::new(0.0, y, z)).coords).norm() < 1e-9
            );
            assert!(p.sigma_mm > 0.0 && p.sigma_mm < 0.5, "{}", p.sigma_mm);
        }
    }
    // With the robot kept in the pose-only session, the result keeps it
    // unchanged: the scan's robot is the result's.
    let mut with_robot = session.clone();
    with_robot.robot = joints_session.robot.clone();
    with_robot.robot_given = true;
    let (_, cal) = solve::calibrate(&with_robot, &options).unwrap();
    let kept = ResultFile::from_calibration(&with_robot, &cal);
    assert!(kept.hand_eye_only() && kept.robot.is_some());
    measure::measure(
        Scan::from_session(with_robot, &[]),
        &kept,
        &MeasureOptions {
            sigma: true,
            ..MeasureOptions::default()
        },
        None,
        &mut |_| Control::Continue,
    )
    .unwrap();
    // Joint readings cannot be measured with a hand-eye-only result.
    let e = measure::measure(
        Scan::from_session(joints_session, &[]),
        &result,
        &MeasureOptions::default(),
        None,
        &mut |_| Control::Continue,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("pose-only") && e.contains("--poses"), "{e}");
}
