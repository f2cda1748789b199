//! The way forward after a FAIL, under the verdict: the measurements the
//! solver flagged as outliers (largest first), each to inspect or leave
//! out, all of them left out and the run started again in one click, and
//! the planner with more identify stations. Next's "Look at the
//! outliers" scrolls here.

use egui::RichText;

use crate::app::AppState;
use crate::app::Forms;
use crate::app::command::{Command, PlanCommand, RunCommand, ViewCommand};
use crate::app::widgets::{BAD, MUTED};
use crate::engine::base::session::Use;
use crate::engine::tools::result_view::Verdict;

/// Outliers listed here; the rest are in the Outliers table below.
const OUTLIERS_SHOWN: usize = 8;

/// The accessible title of the box (Next scrolls to it).
pub const AFTER_FAIL_TITLE: &str = "After a FAIL: what to do next";

/// The box, when the verdict is FAIL.
pub(super) fn after_fail_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    let Some(view) = &state.result else {
        return;
    };
    let Verdict::Fail(reasons) = Verdict::of(view.shown.headline.as_ref(), &forms.tolerance) else {
        return;
    };
    let outliers = view
        .file
        .solver
        .ml()
        .map(|m| m.outliers.as_slice())
        .unwrap_or_default();
    let running = state.jobs.runs(&crate::app::job::Slot::Run);
    let leave_out = |id: &String| {
        let (id, included) = (id.clone(), false);
        Command::View(ViewCommand::SetIncluded { id, included })
    };
    let response = crate::app::widgets::boxed(ui, BAD, AFTER_FAIL_TITLE, |ui| {
        let reasons = reasons.join(", ");
        ui.label(format!("The validation is beyond the tolerance ({reasons})."));
        if outliers.is_empty() {
            ui.label(
                "1. No measurement stands out: the solver flags none as an outlier, so the data agree with each other and the error is in what the stations determine.",
            );
        } else {
            ui.label(format!(
                "1. Look at the {} measurement(s) the solver flagged as outliers (largest first): inspect the stripe, leave out what is wrong, run again.",
                outliers.len()
            ));
            let header = ["measurement", "station", "residual (mm)", "σ", ""];
            crate::app::widgets::table(ui, "after_fail_outliers", &header, |ui| {
                for o in outliers.iter().take(OUTLIERS_SHOWN) {
                    ui.label(&o.measurement);
                    ui.label(&o.station);
                    ui.label(format!("{:.3}", o.residual_mm));
                    ui.label(format!("{:.1}", o.sigma));
                    let mut points = view.centres.points.iter();
                    let index = points.find(|p| p.id == o.measurement).and_then(|p| p.index);
                    ui.horizontal(|ui| {
                        let inspect = ui.add_enabled(index.is_some(), egui::Button::new("Inspect"));
                        if inspect.on_hover_text("its stripe in the Stripe view").clicked()
                            && let Some(i) = index
                        {
                            commands.push(Command::View(ViewCommand::Inspect(i)));
                        }
                        let out = state.excluded.contains(&o.measurement);
                        let button = ui.add_enabled(!out, egui::Button::new("Leave out"));
                        if button.on_disabled_hover_text("left out of the next run").clicked() {
                            commands.push(leave_out(&o.measurement));
                        }
                    });
                    ui.end_row();
                }
            });
            if outliers.len() > OUTLIERS_SHOWN {
                let more = outliers.len() - OUTLIERS_SHOWN;
                let text = format!("and {more} more in the Outliers table below");
                ui.label(RichText::new(text).color(MUTED));
            }
            let text = format!("Leave out all {} and run again", outliers.len());
            if ui.add_enabled(!running, egui::Button::new(text)).clicked() {
                commands.extend(outliers.iter().map(|o| leave_out(&o.measurement)));
                commands.push(Command::Run(RunCommand::Start));
            }
        }
        let stations = state.loaded.as_ref().map(|l| l.session.stations(Use::Identify));
        let have = stations.as_ref().map_or(0, Vec::len);
        ui.horizontal_wrapped(|ui| {
            ui.label("2. Measure more stations: more identify stations determine the parameters better.");
            let text = format!("Plan more stations ({have} → {} identify)", more_stations(have));
            if ui
                .button(text)
                .on_hover_text("the Plan view, set for this robot with more identify stations; Make plan there, measure the new poses, import and run")
                .clicked()
            {
                commands.push(Command::Plan(PlanCommand::MoreStations));
            }
        });
        ui.label(
            RichText::new(
                "3. If the tolerance is tighter than the job needs, set it above; the report can also be written with the FAIL.",
            )
            .color(MUTED),
        );
    })
    .response;
    if std::mem::take(&mut forms.focus_after_fail) {
        ui.scroll_to_rect(response.rect, Some(egui::Align::TOP));
    }
}

/// Most identify stations the Plan form offers.
pub const MAX_IDENTIFY_STATIONS: usize = 30;

/// How many identify stations to plan after a FAIL with `have`: half as
/// many again, at least three more (more stations determine the
/// parameters better: README, Evidence), at most
/// [`MAX_IDENTIFY_STATIONS`] unless the session already had more.
#[must_use]
pub fn more_stations(have: usize) -> usize {
    let want = (have + have.div_ceil(2)).max(have + 3);
    want.min(MAX_IDENTIFY_STATIONS.max(have))
}
