//! The Plan view's objective (issue 32): the working volume (I-optimal,
//! the default, as `spherecal plan`) or D-optimal (`--d-optimal`), set in
//! the engine's plan request. egui_kittest, no display.

#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use egui_kittest::kittest::Queryable as _;
use spherecal::engine::tools::plan::{Plan, Selection};

use crate::support::ui::{demo_app, settle, small_plan};

fn made(h: &egui_kittest::Harness<'_, spherecal::app::WorkbenchApp>) -> Plan {
    h.state()
        .state()
        .plan
        .outcome
        .as_ref()
        .and_then(|o| o.as_ref().ok())
        .map(|o| o.plan.as_ref().clone())
        .expect("a plan")
}

#[test]
fn the_plan_view_chooses_the_objective() {
    let mut h = demo_app();
    h.get_by_label("Plan").click();
    h.run();
    assert_eq!(
        h.state().forms().plan.request.design.selection,
        Selection::Volume
    );
    small_plan(&mut h, 4, 3);
    h.get_by_label("Make plan").click();
    settle(&mut h);
    let volume = made(&h);
    h.get_by_label("D-optimal").click();
    h.run();
    assert_eq!(
        h.state().forms().plan.request.design.selection,
        Selection::DOptimal
    );
    h.get_by_label("Make plan").click();
    settle(&mut h);
    let d = made(&h);
    // The same stations and candidates, chosen for another objective:
    // each plan is the better one by its own criterion.
    assert_ne!(volume.poses, d.poses);
    let (v, dv) = (
        volume.stats.volume_error.expect("predicted").rms_mm,
        d.stats.volume_error.expect("predicted").rms_mm,
    );
    assert!(v < dv, "volume {v:.4} mm vs D-optimal {dv:.4} mm");
    assert!(
        d.stats.log_det >= volume.stats.log_det - 1e-9,
        "ln det {} vs {}",
        d.stats.log_det,
        volume.stats.log_det
    );
    // And back.
    h.get_by_label("working volume").click();
    h.run();
    assert_eq!(
        h.state().forms().plan.request.design.selection,
        Selection::Volume
    );
}
