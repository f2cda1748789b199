//! UI tests of the Measure view (issue 20, item 6): after a calibration
//! of a small simulated session, the session measured on a job thread;
//! the projections, the σ colour bar and the counts; the self-validation
//! table; a PLY written and read back by an independent reader; a new
//! calibration making the cloud stale and its export refused; Cancel
//! keeping the cloud on show; a dense scan drawn decimated; a result
//! without covariance measured only without σ. egui_kittest, no display.

#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable as _;
use spherecal::app::WorkbenchApp;
use spherecal::app::command::Tab;
use spherecal::app::command::{Command, MeasureCommand, ViewCommand};
use spherecal::app::job::Slot;
use spherecal::app::measure::ScanChoice;
use spherecal::app::measure::job::{DRAWN_MAX, MeasureFailure, group, measure_cloud};
use spherecal::engine::base::session::Observation;
use spherecal::engine::calibrate::solve::Method;
use spherecal::engine::tools::simulate::SimConfig;
use spherecal::engine::uses::measure::{MeasureOptions, MeasureRequest, ModelChoice, ScanSource};

use crate::support::ui as ui_support;
use ui_support::{harness, settle, simulated, status, step_label};

/// The small simulated cell of these tests (seeded, the paper's).
fn small() -> SimConfig {
    SimConfig {
        seed: 20,
        n_validate: 4,
        ..SimConfig::default()
    }
}

/// A small simulated session (seeded, the paper's cell), opened and
/// calibrated with `method`.
fn calibrated(dir: &Path, method: Method) -> Harness<'static, WorkbenchApp> {
    let path = simulated(dir, "small.json", &small());
    let mut h = harness(WorkbenchApp::new(
        spherecal::app::state::Prefs::default(),
        Some(path),
        None,
    ));
    settle(&mut h);
    h.state_mut().forms_mut().solver.method = method;
    h.get_by_label("▶ Run").click();
    settle(&mut h);
    assert!(h.state().state().result.is_some(), "calibrated");
    h
}

/// Opens the Measure view through its step and measures the form's scan.
fn measure(h: &mut Harness<'static, WorkbenchApp>) {
    if h.state().forms().tab != Tab::Measure {
        h.get_by_label(&step_label(h, "7. Measured")).click();
        h.run();
        assert_eq!(h.state().forms().tab, Tab::Measure);
    }
    h.get_by_label("▶ Measure").click();
    settle(h);
}

/// Stripe points of a session: what the cloud of it holds.
fn stripe_points(h: &Harness<'static, WorkbenchApp>) -> usize {
    let loaded = h.state().state().loaded.as_ref().unwrap();
    loaded
        .session
        .measurements
        .iter()
        .map(|m| match &m.observation {
            Observation::Stripe(p) => p.len(),
            Observation::Centre(_) => 0,
        })
        .sum()
}

/// The whole path: Measure shows the cloud with its counts, projections,
/// σ colour bar and self-validation table, and writes a PLY that an
/// independent reader reads back point for point.
#[test]
fn the_session_is_measured_shown_and_written_as_ply() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = calibrated(dir.path(), Method::Ml);
    assert!(step_label(&h, "7. Measured").starts_with('○'));
    measure(&mut h);
    assert!(step_label(&h, "7. Measured").starts_with('●'), "measured");
    let n = stripe_points(&h);
    let shown = h.state().state().measure.shown.clone().expect("a cloud");
    assert_eq!(shown.cloud().len(), n, "every stripe point is in the cloud");
    assert_eq!(shown.drawn.len(), n, "a small cloud is drawn whole");
    assert_eq!(
        shown.cloud().dropped().non_finite + shown.cloud().dropped().no_return,
        0
    );
    let counts = format!("{} points kept of", group(n));
    assert!(h.query_by_label_contains(&counts).is_some(), "{counts}");
    assert!(
        h.query_by_label_contains(&format!("showing all {} points", group(n)))
            .is_some()
    );
    for projection in [
        "XY (from above)",
        "XZ (from the front)",
        "YZ (from the side)",
    ] {
        assert!(h.query_by_label(projection).is_some(), "{projection}");
    }
    // σ exists for every point; the bar in µm or mm as its size says.
    let sigma = shown.sigma.expect("σ of an ml result");
    assert!(sigma.median > 0.0 && sigma.max >= sigma.median && sigma.max < 1.0);
    let unit = if sigma.max < 0.1 {
        "σ (µm)"
    } else {
        "σ (mm)"
    };
    assert!(h.query_by_label(unit).is_some(), "the colour bar: {unit}");
    // The self-validation: the calibrated model fits the validate
    // spheres better than the nominal one (Table 1 errors are mm).
    let check = shown.outcome.check.as_ref().expect("validate stations");
    assert_eq!(check.after.stations.len(), 4);
    assert!(check.after.spread().0 * 3.0 < check.before.spread().0);
    assert!(check.after.size().0 * 10.0 < check.before.size().0);
    let (b, a) = (
        check.before.spacing_error().unwrap(),
        check.after.spacing_error().unwrap(),
    );
    assert!(a.0 * 10.0 < b.0, "spacing error {a:?} vs {b:?}");
    assert!(
        h.query_by_label("position spread (each pose's centre)")
            .is_some()
    );
    assert!(h.query_by_label("after (calibrated)").is_some());

    // Export a PLY; the independent reader finds every point, equal to
    // the cloud's to the last bit, and its σ.
    let ply = dir.path().join("cloud.ply");
    h.state_mut().forms_mut().measure.out = ply.display().to_string();
    h.get_by_label("Write cloud").click();
    settle(&mut h);
    assert!(status(&h).contains("wrote PLY cloud"), "{}", status(&h));
    let parser = ply_rs_bw::parser::Parser::<ply_rs_bw::ply::DefaultElement>::new();
    let read = parser
        .read_ply(&mut std::fs::File::open(&ply).unwrap())
        .unwrap();
    let vertices = &read.payload["vertex"];
    assert_eq!(vertices.len(), n);
    for (v, p) in vertices.iter().zip(shown.cloud().points()) {
        use ply_rs_bw::ply::Property;
        let d = |k: &str| match v[k] {
            Property::Double(x) => x,
            ref other => panic!("{k}: {other:?}"),
        };
        assert_eq!([d("x"), d("y"), d("z")], p.position);
        let Property::Float(s) = v["sigma_mm"] else {
            panic!("sigma_mm")
        };
        assert!((f64::from(s) - p.sigma_mm).abs() <= 1e-6 * p.sigma_mm);
    }
}

/// A new calibration makes the cloud stale: the step and the view say
/// so, and its export is refused with the reason, writing nothing.
#[test]
fn a_new_calibration_makes_the_cloud_stale_and_its_export_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = calibrated(dir.path(), Method::Ml);
    measure(&mut h);
    assert!(step_label(&h, "7. Measured").starts_with('●'));
    h.get_by_label("▶ Run").click();
    settle(&mut h);
    assert!(
        step_label(&h, "7. Measured").starts_with('!'),
        "stale after a new result"
    );
    assert!(h.query_by_label("STALE").is_some());
    let ply = dir.path().join("stale.ply");
    h.state_mut().forms_mut().measure.out = ply.display().to_string();
    h.get_by_label("Write cloud").click();
    settle(&mut h);
    let notice = h.state().state().notice.clone().expect("refused");
    assert_eq!(notice.title, "Cloud not written");
    assert!(
        notice.body.contains("the cloud is stale")
            && notice.body.contains("the calibration result"),
        "{}",
        notice.body
    );
    assert!(!ply.exists(), "nothing written");
    // Measured again, it is current and written.
    h.get_by_label("▶ Measure").click();
    settle(&mut h);
    assert!(step_label(&h, "7. Measured").starts_with('●'));
    h.get_by_label("Write cloud").click();
    settle(&mut h);
    assert!(ply.exists());
}

/// Cancel stops the job and keeps the cloud on show; the engine path
/// itself stops at a set cancel flag.
#[test]
fn cancel_stops_the_job_and_keeps_the_previous_cloud() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = calibrated(dir.path(), Method::Ml);
    measure(&mut h);
    let first = h.state().state().measure.shown.clone().unwrap();
    // Another scan (validate only), cancelled at once.
    h.state_mut().forms_mut().measure.usage = Some(spherecal::engine::base::session::Use::Validate);
    let ctx = h.ctx.clone();
    h.state_mut()
        .command(&ctx, Command::Measure(MeasureCommand::Start));
    assert!(
        h.state().state().jobs.get(&Slot::Measure).is_some(),
        "started"
    );
    h.state_mut()
        .command(&ctx, Command::Measure(MeasureCommand::Cancel));
    settle(&mut h);
    let m = &h.state().state().measure;
    assert!(h.state().state().jobs.get(&Slot::Measure).is_none());
    let kept = m.shown.as_ref().expect("the previous cloud");
    assert!(
        Arc::ptr_eq(&kept.outcome.measured.cloud, &first.outcome.measured.cloud),
        "the same cloud"
    );
    assert!(status(&h).contains("cancelled"), "{}", status(&h));

    // The job's work stops at the flag and gives nothing.
    let view = h.state().state().result.clone().unwrap();
    let session = h.state().state().loaded.as_ref().unwrap().session.clone();
    let request = MeasureRequest {
        scan: ScanSource::Session(Box::new(session), Vec::new(), "s".into()),
        result: view.file,
        joint_range: None,
        frame: None,
        options: MeasureOptions {
            model: ModelChoice::Calibrated,
            sigma: true,
            ..MeasureOptions::default()
        },
    };
    let cancelled = AtomicBool::new(true);
    let outcome = measure_cloud(request, "r".into(), &cancelled, &mut |_, _| true);
    assert!(matches!(outcome, Err(MeasureFailure::Cancelled)));
}

/// A scan of more points than are drawn: the view draws DRAWN_MAX of
/// them, spread evenly, and says so.
#[test]
fn a_dense_scan_is_drawn_decimated_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = calibrated(dir.path(), Method::Ml);
    let dense = simulated(
        dir.path(),
        "dense.json",
        &SimConfig {
            seed: 21,
            n_identify: 3,
            n_validate: 2,
            point_spacing: 0.015,
            ..SimConfig::default()
        },
    );
    let form = &mut h.state_mut().forms_mut().measure;
    form.choice = ScanChoice::SessionFile;
    form.session_file = dense.display().to_string();
    measure(&mut h);
    let shown = h.state().state().measure.shown.clone().expect("a cloud");
    assert!(
        shown.cloud().len() > DRAWN_MAX,
        "{} points",
        shown.cloud().len()
    );
    assert_eq!(shown.drawn.len(), DRAWN_MAX);
    let text = format!(
        "showing {} of {} points",
        group(DRAWN_MAX),
        group(shown.cloud().len())
    );
    assert!(h.query_by_label_contains(&text).is_some(), "{text}");
    // Drawn in σ order (the largest on top) and spread over the cloud:
    // its bounds are (nearly) those of the whole cloud.
    assert!(
        shown
            .drawn
            .windows(2)
            .all(|w| w[0].sigma_mm <= w[1].sigma_mm)
    );
    let (lo, hi) = shown.bounds.unwrap();
    for k in 0..3 {
        let min = shown
            .drawn
            .iter()
            .map(|p| p.position[k])
            .fold(f64::INFINITY, f64::min);
        assert!((min - lo[k]) < 0.05 * (hi[k] - lo[k]) + 1.0, "axis {k}");
    }
}

/// A result without covariance (the paper's method): σ is refused with
/// the reason, and "no σ" measures the cloud without it.
#[test]
fn a_paper_result_is_measured_only_without_sigma() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = calibrated(dir.path(), Method::Paper);
    h.get_by_label(&step_label(&h, "7. Measured")).click();
    h.run();
    assert!(
        h.query_by_label_contains("σ is unavailable: method paper")
            .is_some()
    );
    h.get_by_label("▶ Measure").click();
    settle(&mut h);
    let m = &h.state().state().measure;
    assert!(m.shown.is_none());
    assert!(
        m.failure.as_deref().unwrap_or("").contains("no σ"),
        "{:?}",
        m.failure
    );
    h.get_by_label("no σ (as --no-sigma)").click();
    h.run();
    h.get_by_label("▶ Measure").click();
    settle(&mut h);
    let shown = h.state().state().measure.shown.clone().expect("a cloud");
    assert!(shown.sigma.is_none());
    assert_eq!(shown.cloud().len(), stripe_points(&h));
    assert!(
        h.query_all_by_label_contains("has no parameter covariance")
            .count()
            >= 1
    );
}

/// The raw-scan door: a simulated scan of a three-sphere artefact (the
/// same seed's cell) read from its joint log and profiles folder as
/// `spherecal measure --joints --profiles` reads them: every finite point
/// kept, the no-hit (NaN) points dropped and counted, the artefact's
/// self-validation; a workpiece frame moves the cloud by its inverse
/// and, changed, makes the cloud stale.
#[test]
fn a_raw_scan_of_an_artefact_is_measured_through_the_form() {
    use spherecal::engine::tools::simulate::{PartKind, ScanConfig, simulate_scan};
    let dir = tempfile::tempdir().unwrap();
    let mut h = calibrated(dir.path(), Method::Ml);
    let sim = simulate_scan(
        &small(),
        &ScanConfig {
            part: PartKind::Spheres,
            poses: 8,
            ..ScanConfig::default()
        },
    )
    .unwrap();
    let scan = dir.path().join("scan");
    std::fs::create_dir_all(scan.join("profiles")).unwrap();
    std::fs::write(scan.join("joints.csv"), &sim.joints_csv).unwrap();
    std::fs::write(
        scan.join("references.csv"),
        sim.references_csv.as_ref().unwrap(),
    )
    .unwrap();
    let (mut finite, mut nan) = (0, 0);
    for (id, text) in &sim.profiles {
        std::fs::write(scan.join("profiles").join(format!("{id}.csv")), text).unwrap();
        for line in text
            .lines()
            .filter(|l| l.starts_with(|c: char| c == '-' || c == 'n' || c.is_ascii_digit()))
        {
            if line.contains("nan") {
                nan += 1;
            } else {
                finite += 1;
            }
        }
    }
    let form = &mut h.state_mut().forms_mut().measure;
    form.choice = ScanChoice::RawScan;
    form.log = scan.join("joints.csv").display().to_string();
    form.profiles = scan.join("profiles").display().to_string();
    form.sphere_diameter = "38.1".into();
    form.references = scan.join("references.csv").display().to_string();
    measure(&mut h);
    let first = h.state().state().measure.shown.clone().expect("a cloud");
    assert_eq!(first.cloud().len(), finite);
    assert_eq!(first.cloud().dropped().non_finite, nan);
    assert!(nan > 0, "the artefact scan has rays that meet nothing");
    assert!(
        h.query_by_label_contains(&format!("dropped {} NaN", group(nan)))
            .is_some()
    );
    let check = first
        .outcome
        .check
        .as_ref()
        .expect("the artefact's stations");
    assert_eq!(check.after.stations.len(), 3);
    let (b, a) = (
        check.before.spacing_error().unwrap(),
        check.after.spacing_error().unwrap(),
    );
    assert!(a.0 * 10.0 < b.0, "spacing error {a:?} vs {b:?}");

    // A workpiece frame 100 mm along x of the base: the cloud moves by
    // −100 mm in x; typing it makes the cloud on show stale at once.
    let frame = dir.path().join("wobj.json");
    std::fs::write(&frame, "[[1,0,0,100],[0,1,0,0],[0,0,1,0],[0,0,0,1]]").unwrap();
    h.state_mut().forms_mut().measure.frame = frame.display().to_string();
    h.run();
    assert!(
        step_label(&h, "7. Measured").starts_with('!'),
        "the frame changed"
    );
    h.get_by_label("▶ Measure").click();
    settle(&mut h);
    let moved = h.state().state().measure.shown.clone().unwrap();
    assert!(
        moved.cloud().frame.to_string().contains("workpiece frame"),
        "{}",
        moved.cloud().frame
    );
    for (p, q) in first.cloud().points().zip(moved.cloud().points()) {
        assert!((p.position[0] - 100.0 - q.position[0]).abs() < 1e-9);
        assert!((p.position[1] - q.position[1]).abs() < 1e-9);
        assert!((p.position[2] - q.position[2]).abs() < 1e-9);
    }
}

/// The operator's defect (issue 30): a measurement left out after the
/// cloud was measured made the result STALE while step 7 stayed ● and
/// the cloud was written all the same. A cloud starts from its result's
/// stamp: whatever makes the result stale makes it stale too, at once;
/// its export is refused and nothing is written; with the input as it
/// was, it is current again and written.
#[test]
fn a_cloud_is_stale_and_its_export_refused_once_its_result_is_stale() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = calibrated(dir.path(), Method::Ml);
    measure(&mut h);
    assert!(step_label(&h, "7. Measured").starts_with('●'));
    let id = h
        .state()
        .state()
        .loaded
        .as_ref()
        .unwrap()
        .session
        .measurements[3]
        .id
        .clone();
    let include = |h: &mut Harness<'static, WorkbenchApp>, included: bool| {
        let ctx = h.ctx.clone();
        let c = Command::View(ViewCommand::SetIncluded {
            id: id.clone(),
            included,
        });
        h.state_mut().command(&ctx, c);
        h.run();
    };
    include(&mut h, false);
    assert!(step_label(&h, "4. Calibrated").starts_with('!'));
    assert!(
        step_label(&h, "7. Measured").starts_with('!'),
        "the cloud is stale with its result"
    );
    assert!(h.query_by_label("STALE").is_some());
    let ply = dir.path().join("left-out.ply");
    h.state_mut().forms_mut().measure.out = ply.display().to_string();
    h.get_by_label("Write cloud").click();
    settle(&mut h);
    let notice = h.state().state().notice.clone().expect("refused");
    assert_eq!(notice.title, "Cloud not written");
    assert!(
        notice.body.contains("the cloud is stale")
            && notice.body.contains("the left-out measurements changed"),
        "{}",
        notice.body
    );
    assert!(!ply.exists(), "nothing written");
    // The solver settings the result was made with: the same.
    include(&mut h, true);
    assert!(step_label(&h, "7. Measured").starts_with('●'));
    let threshold = h.state().forms().solver.threshold;
    h.state_mut().forms_mut().solver.threshold = threshold * 2.0;
    h.run();
    assert!(step_label(&h, "7. Measured").starts_with('!'), "the solver");
    h.state_mut().forms_mut().solver.threshold = threshold;
    h.run();
    assert!(
        step_label(&h, "7. Measured").starts_with('●'),
        "current again"
    );
    h.get_by_label("Write cloud").click();
    settle(&mut h);
    assert!(ply.exists(), "written once current");
}
