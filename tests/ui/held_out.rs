//! The Results view shows the held-out figure beside the fit's own
//! scatter, with the engine's numbers, and the paper's method's warning
//! when its loop made ε worse (egui_kittest, no display).

#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::path::Path;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable as _;
use spherecal::app::WorkbenchApp;
use spherecal::app::command::Tab;
use spherecal::engine::calibrate::solve::{Method, Options, calibrate};
use spherecal::engine::files::format::{parse_session, save_session};

use crate::support::ui as ui_support;
use ui_support::{demo_app, labels_with, open_path, settle};

use crate::support::one_station;
use one_station::{best_scatter_start, one_station};

/// Runs the open session and opens the Results view.
fn run_to_results(h: &mut Harness<'_, WorkbenchApp>) {
    h.get_by_label("▶ Run").click();
    settle(h);
    h.state_mut().forms_mut().tab = Tab::Results;
    h.run();
}

#[test]
fn the_results_view_shows_the_held_out_figure_beside_the_fit() {
    let mut h = demo_app();
    run_to_results(&mut h);
    let session = parse_session(
        spherecal::DEMO_SESSION_JSON,
        Path::new(spherecal::DEMO_SESSION_NAME),
    )
    .unwrap();
    let (_, cal) = calibrate(&session, &Options::from_session(&session)).unwrap();
    let ho = cal.held_out.expect("the engine computes it");
    assert!(
        !labels_with(&h, "held out (leave-one-pose-out)").is_empty(),
        "the scheme is named"
    );
    let figure = format!("rms {:.3} mm, max {:.3} mm", ho.rms, ho.max);
    assert_eq!(labels_with(&h, &figure).len(), 1, "{figure}");
    let fit = format!("fit's own scatter rms {:.3} mm", ho.fit_rms);
    assert_eq!(labels_with(&h, &fit).len(), 1, "{fit}");
    assert!(ho.rms > ho.fit_rms);
    assert!(labels_with(&h, "warning: ε rose").is_empty());
}

#[test]
fn the_paper_methods_rise_of_epsilon_is_a_warning_in_the_results_view() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("one-station.json");
    save_session(&best_scatter_start(one_station(5, 15, 0.15)), &path).unwrap();
    let mut h = demo_app();
    open_path(&mut h, path);
    h.state_mut().forms_mut().solver.method = Method::Paper;
    run_to_results(&mut h);
    let warning = labels_with(&h, "warning: ε rose from");
    assert_eq!(warning.len(), 1, "{warning:?}");
    assert!(
        warning[0].contains("Method ml or Pairs all"),
        "{}",
        warning[0]
    );
    // The paper's held-out figure: its own method rerun without each pose.
    assert!(!labels_with(&h, "held out (leave-one-pose-out)").is_empty());
}
