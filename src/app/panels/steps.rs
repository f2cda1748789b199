//! The step bar: the operator's job in order (plan → data in → stripes
//! checked → calibrated → validated → reported), where the open session
//! stands, and the next action as one button.

use egui::RichText;

use super::{AFTER, BAD, GOOD, MUTED, WARN};
use crate::app::commands::{Command, RunCommand, ViewCommand};
use crate::app::forms::{Forms, Tab};
use crate::app::state::{AppState, ExportKind};
use crate::engine::result_view::Verdict;

/// Where one step stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepState {
    /// Done.
    Done,
    /// Done, but with something to look at (failed stripes, a FAIL).
    Attention,
    /// Not done yet.
    Todo,
}

/// One step of the job.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// Its name on the bar.
    pub name: &'static str,
    /// Where it stands.
    pub state: StepState,
    /// A few words on its state (hover text).
    pub detail: String,
    /// The button that does or shows it, and its command.
    pub action: (&'static str, Command),
}

/// The six steps of the job for the current state.
#[must_use]
pub fn steps(state: &AppState, forms: &Forms) -> Vec<Step> {
    let planned = state.plan.outcome.as_ref().is_some_and(Result::is_ok);
    let loaded = state.loaded.as_ref();
    let failed = loaded.map_or(0, |l| l.analysis.failures().count());
    let verdict = state
        .result
        .as_ref()
        .map(|r| Verdict::of(r.shown.headline.as_ref(), &forms.tolerance));
    let show = |tab| Command::View(ViewCommand::ShowTab(tab));
    vec![
        Step {
            name: "Plan",
            state: if planned || loaded.is_some() {
                StepState::Done
            } else {
                StepState::Todo
            },
            detail: if planned {
                "a pose plan is made".into()
            } else if loaded.is_some() {
                "a session is open (its poses were planned elsewhere)".into()
            } else {
                "plan the poses for the robot and the sphere".into()
            },
            action: ("Plan the poses", show(Tab::Plan)),
        },
        Step {
            name: "Data in",
            state: if loaded.is_some() {
                StepState::Done
            } else {
                StepState::Todo
            },
            detail: loaded.map_or_else(
                || "import the robot's log and the sensor's profiles, or open a session".into(),
                |l| {
                    format!(
                        "{} measurements in \"{}\"",
                        l.session.measurements.len(),
                        l.session.name
                    )
                },
            ),
            action: ("Import data", show(Tab::Import)),
        },
        Step {
            name: "Stripes checked",
            state: match loaded {
                None => StepState::Todo,
                Some(_) if failed > 0 => StepState::Attention,
                Some(_) => StepState::Done,
            },
            detail: match loaded {
                None => "no session yet".into(),
                Some(_) if failed > 0 => format!(
                    "{failed} stripe(s) cannot be fitted: look at them in Stripe, leave them out in Session"
                ),
                Some(_) => "every stripe fits a circle".into(),
            },
            action: ("Check the stripes", show(Tab::Stripe)),
        },
        Step {
            name: "Calibrated",
            state: if state.result.is_some() {
                StepState::Done
            } else {
                StepState::Todo
            },
            detail: state.result.as_ref().map_or_else(
                || "run the calibration".into(),
                |r| format!("method {}", r.method),
            ),
            action: ("▶ Run the calibration", Command::Run(RunCommand::Start)),
        },
        Step {
            name: "Validated",
            state: match &verdict {
                None | Some(Verdict::NotChecked) => StepState::Todo,
                Some(Verdict::Pass) => StepState::Done,
                Some(Verdict::Fail(_)) => StepState::Attention,
            },
            detail: verdict.as_ref().map_or_else(
                || "calibrate first".into(),
                |v| v.describe(&forms.tolerance),
            ),
            action: ("See the verdict", show(Tab::Results)),
        },
        Step {
            name: "Reported",
            state: if state.reported.is_some() {
                StepState::Done
            } else {
                StepState::Todo
            },
            detail: state.reported.as_ref().map_or_else(
                || "write the HTML report".into(),
                |p| format!("report written: {}", p.display()),
            ),
            action: ("Write the report", Command::Export(ExportKind::ReportHtml)),
        },
    ]
}

/// The first-start "what to do", on the demo until dismissed.
fn intro_ui(ui: &mut egui::Ui, state: &AppState, commands: &mut Vec<Command>) {
    let on_demo = state
        .loaded
        .as_ref()
        .is_some_and(|l| l.source == crate::app::state::Source::Demo);
    if !on_demo || state.prefs.intro_dismissed {
        return;
    }
    egui::Frame::group(ui.style()).show(ui, |ui| {
        ui.horizontal_wrapped(|ui| {
            ui.label(RichText::new("What to do").strong());
            ui.label(
                "This is the demo: a simulated paper-like cell. The bar below is the job in order. \
                 Press Next to run the calibration, then see the verdict in Results and write the report. \
                 For your own cell: Plan the poses, Import the robot's log and the sensor's profiles \
                 (or open a session file on the left), check the stripes, then run.",
            );
            if ui.button("Got it").clicked() {
                commands.push(Command::View(ViewCommand::DismissIntro));
            }
        });
    });
}

/// The bar: each step with its mark, then the next action's button.
pub fn steps_ui(ui: &mut egui::Ui, state: &AppState, forms: &Forms, commands: &mut Vec<Command>) {
    intro_ui(ui, state, commands);
    let all = steps(state, forms);
    // The next step: the first not done, else a step that needs attention.
    let next = all
        .iter()
        .position(|s| s.state == StepState::Todo)
        .or_else(|| all.iter().position(|s| s.state == StepState::Attention));
    ui.horizontal_wrapped(|ui| {
        for (k, step) in all.iter().enumerate() {
            if k > 0 {
                ui.label(RichText::new("›").color(MUTED));
            }
            let (mark, colour) = match step.state {
                StepState::Done => ("●", GOOD),
                StepState::Attention => ("!", if step.name == "Validated" { BAD } else { WARN }),
                StepState::Todo => ("○", MUTED),
            };
            let mut text = RichText::new(format!("{mark} {}. {}", k + 1, step.name))
                .size(14.0)
                .color(colour);
            if Some(k) == next {
                text = text.strong();
            }
            // A step is a link to its view (or does its action).
            let busy = state.run.is_some() && matches!(step.action.1, Command::Run(_));
            if ui
                .add_enabled(!busy, egui::Button::new(text).frame(false))
                .on_hover_text(format!("{} ({})", step.detail, step.action.0))
                .clicked()
            {
                commands.push(step.action.1.clone());
            }
        }
        if let Some(k) = next {
            ui.add_space(12.0);
            let (label, command) = &all[k].action;
            let busy = state.run.is_some() && matches!(command, Command::Run(_));
            let button = egui::Button::new(RichText::new(format!("Next: {label}")).color(AFTER));
            if ui
                .add_enabled(!busy, button)
                .on_hover_text(&all[k].detail)
                .clicked()
            {
                commands.push(command.clone());
            }
        }
    });
}
