//! The step bar: the operator's job in order (plan → data in → stripes
//! checked → calibrated → validated → reported, then measured: scans
//! through the calibrated cell), where the open session
//! stands, and the next action as one button, with an action in every
//! state: a stale step is done again, a FAIL leads to the outliers and
//! then to the planner, a session without validate measurements skips
//! the validation and goes on to the report. Whether a step is stale
//! comes from the one [`ledger`](crate::app::ledger) of the
//! state, never from a flag of its own.

use egui::RichText;

use crate::app::AppState;
use crate::app::command::ExportKind;
use crate::app::command::{Command, PlanCommand, RunCommand, ViewCommand};
use crate::app::job::Slot;
use crate::app::ledger::Artefact;
use crate::app::widgets::{AFTER, BAD, GOOD, MUTED, WARN};
use crate::app::{Forms, command::Tab};
use crate::engine::tools::result_view::Verdict;

/// Where one step stands.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum StepState {
    /// Done, and made from the inputs as they are.
    Done,
    /// Done, with something to look at (stripe warnings, a FAIL).
    Attention,
    /// Done, but an input it was made from has changed since: what
    /// changed, in words.
    Stale(String),
    /// Not needed for this session (no validate measurements).
    Skipped,
    /// Under way (a run, a file being opened).
    Running,
    /// Not done yet.
    Todo,
}

impl StepState {
    /// The mark on the bar: ● done, ! attention or stale, – skipped,
    /// … under way, ○ to do.
    #[must_use]
    pub fn mark(&self) -> &'static str {
        match self {
            Self::Done => "●",
            Self::Attention | Self::Stale(_) => "!",
            Self::Skipped => "–",
            Self::Running => "…",
            Self::Todo => "○",
        }
    }
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
    pub action: (String, Command),
    /// An optional step (compensating targets, a re-check): Next offers
    /// it once every required step is done, and "every step is done"
    /// names it while it is not.
    pub optional: bool,
}

fn show(tab: Tab) -> Command {
    Command::View(ViewCommand::ShowTab(tab))
}

/// The verdict of the result on show against the form's tolerance.
#[must_use]
pub fn verdict(state: &AppState, forms: &Forms) -> Option<Verdict> {
    state
        .result
        .as_ref()
        .map(|r| Verdict::of(r.shown.headline.as_ref(), &forms.tolerance))
}

/// The label of the one click that refines a result the loop made no
/// update to (the engine's warning names it).
const RUN_AT_ZERO: &str = "Run again with threshold 0";

/// The warning when the result on show was made without any update
/// (ε started within the threshold).
fn no_update(state: &AppState) -> Option<String> {
    state.result.as_ref()?.file.no_update_warning()
}

/// Measurements `ml` listed as outliers in the result on show.
fn outliers(state: &AppState) -> usize {
    state
        .result
        .as_ref()
        .and_then(|r| r.file.solver.ml())
        .map_or(0, |m| m.outliers.len())
}

/// Where the step of `artefact` stands, from the ledger and the job
/// table alone: under way (its phase), stale (what changed), done (what
/// it is), or not made.
#[must_use]
pub fn standing(state: &AppState, artefact: Artefact) -> (StepState, String) {
    let ledger = &state.ledger;
    if let Some(job) = Slot::of(artefact).and_then(|s| state.jobs.get(&s)) {
        return (StepState::Running, job.phase.clone());
    }
    match (ledger.made(artefact), ledger.stale(artefact)) {
        (Some(_), Some(s)) => (StepState::Stale(s.what_changed()), s.to_string()),
        (Some(m), None) => (StepState::Done, m.what.clone()),
        (None, _) => (StepState::Todo, String::new()),
    }
}

/// A required step `name`, where it stands and why, and its action.
fn plain(
    name: &'static str,
    (state, detail): (StepState, String),
    action: (&str, Command),
) -> Step {
    Step {
        name,
        state,
        detail,
        action: (action.0.into(), action.1),
        optional: false,
    }
}

/// A step of `artefact` ([`standing`]) with its words for each state:
/// `todo` before it is made, `again` added to what makes it stale.
fn step(
    state: &AppState,
    artefact: Artefact,
    name: &'static str,
    (todo, again): (&str, &str),
    action: (&str, Command),
) -> Step {
    let (state, words) = standing(state, artefact);
    let detail = match &state {
        StepState::Todo => todo.to_string(),
        StepState::Stale(_) => format!("{words}: {again}"),
        _ => words,
    };
    plain(name, (state, detail), action)
}

/// The steps of the job for the current state (the Measure step, the
/// cell's use once calibrated, last). Whether an artefact's step is done,
/// under way or stale comes from the ledger and the job table only.
///
/// `stripes_seen`: the Stripe view was opened on this session, so its
/// warnings have been looked at (the step is done, no longer "!").
#[must_use]
pub fn steps(state: &AppState, forms: &Forms, stripes_seen: bool) -> Vec<Step> {
    let loaded = state.loaded.as_ref();
    let failed = loaded.map_or(0, |l| l.analysis.failures().count());
    let warned = loaded.map_or(0, |l| l.analysis.warnings.len());
    let again = |label: &str, state: &StepState, first: &str| match state {
        StepState::Stale(_) => label.to_string(),
        _ => first.to_string(),
    };
    let mut plan = step(
        state,
        Artefact::Plan,
        "Plan",
        (
            "plan the poses for the robot and the sphere",
            "make it again before writing its program",
        ),
        ("", show(Tab::Plan)),
    );
    plan.action.0 = again("Make the plan again", &plan.state, "Plan the poses");
    if plan.state == StepState::Todo && loaded.is_some() {
        plan.state = StepState::Skipped;
        plan.detail = "not planned here: the open session's poses were planned elsewhere".into();
    }
    let mut calibrate = step(
        state,
        Artefact::Result,
        "Calibrated",
        ("run the calibration", "run again"),
        ("", Command::Run(RunCommand::Start)),
    );
    if calibrate.state == StepState::Running {
        calibrate.detail = format!("calibrating: {}", calibrate.detail);
    }
    calibrate.action.0 = again("▶ Run again", &calibrate.state, "▶ Run the calibration");
    // A result the loop made no update to is the start, not a
    // calibration: said, with the one click that refines it anyway.
    if let (StepState::Done, Some(w)) = (&calibrate.state, no_update(state)) {
        calibrate.state = StepState::Attention;
        calibrate.detail = w;
        let options = crate::engine::calibrate::solve::Options {
            threshold: 0.0,
            ..forms.solver
        };
        calibrate.action = (RUN_AT_ZERO.into(), Command::RunWith(Box::new(options)));
    }
    let mut report = step(
        state,
        Artefact::Report,
        "Reported",
        (
            "write the HTML report",
            "it no longer says what is on show; write it again",
        ),
        ("", Command::Export(ExportKind::ReportHtml)),
    );
    report.action.0 = again("Write the report again", &report.state, "Write the report");
    let validated = validated(state, forms, calibrate.state.clone());
    let data_in = match (state.jobs.get(&Slot::Load), loaded) {
        (Some(job), _) => (StepState::Running, job.phase.clone()),
        (None, Some(l)) => (
            StepState::Done,
            format!(
                "{} measurements in \"{}\"",
                l.session.measurements.len(),
                l.session.name
            ),
        ),
        (None, None) => (
            StepState::Todo,
            "import the robot's log and the sensor's profiles, or open a session".into(),
        ),
    };
    let stripes = match loaded {
        None => (StepState::Todo, "no session yet".into()),
        Some(_) if failed + warned > 0 && !stripes_seen => (
            StepState::Attention,
            format!(
                "{failed} stripe(s) cannot be fitted, {warned} with warnings: look at them in Stripe (Session: only warnings and failures), leave out what is wrong"
            ),
        ),
        Some(_) if failed + warned > 0 => (
            StepState::Done,
            format!(
                "looked at: {failed} stripe(s) cannot be fitted (the run leaves them out), {warned} with warnings"
            ),
        ),
        Some(_) => (
            StepState::Done,
            "every stripe fits a circle, no warnings".into(),
        ),
    };
    vec![
        plan,
        plain("Data in", data_in, ("Import data", show(Tab::Import))),
        plain(
            "Stripes checked",
            stripes,
            ("Check the stripes", show(Tab::Stripe)),
        ),
        calibrate,
        validated,
        report,
        measure_step(state),
        optional(
            state,
            Artefact::Compensation,
            "Compensated",
            (
                "compensate the robot's targets through the calibration (optional)",
                "compensate them again before writing the program",
            ),
            ("Compensate targets", Tab::Compensate),
        ),
        optional(
            state,
            Artefact::Check,
            "Re-checked",
            (
                "re-check the cell with a short scan (optional)",
                "check again",
            ),
            ("Re-check the cell", Tab::Check),
        ),
    ]
}

/// An optional step of `artefact` (compensating targets, a re-check):
/// its standing in the ledger, its view as its action.
fn optional(
    state: &AppState,
    artefact: Artefact,
    name: &'static str,
    words: (&str, &str),
    (label, tab): (&str, Tab),
) -> Step {
    let mut c = step(state, artefact, name, words, (label, show(tab)));
    c.optional = true;
    c
}

/// The Validated step: the verdict of the result on show against the
/// tolerance, stale with the result.
fn validated(state: &AppState, forms: &Forms, calibrated: StepState) -> Step {
    let verdict = verdict(state, forms);
    let (state, detail) = match (calibrated, &verdict) {
        (StepState::Running | StepState::Todo, _) | (_, None) => {
            (StepState::Todo, "calibrate first".to_string())
        }
        (StepState::Attention, Some(v)) => (
            StepState::Todo,
            format!(
                "calibrate first: no update was made, so the verdict ({}) is of the uncalibrated start",
                v.describe(&forms.tolerance)
            ),
        ),
        (StepState::Stale(s), Some(_)) => (
            StepState::Stale(s.clone()),
            format!("the result is stale: {s}; its verdict no longer holds"),
        ),
        (_, Some(Verdict::Pass)) => (StepState::Done, Verdict::Pass.describe(&forms.tolerance)),
        (_, Some(v @ Verdict::Fail(_))) => (StepState::Attention, v.describe(&forms.tolerance)),
        (_, Some(Verdict::NotChecked)) => (
            StepState::Skipped,
            "skipped: no validate data (the session has no validate measurements)".to_string(),
        ),
    };
    plain(
        "Validated",
        (state, detail),
        ("See the verdict", show(Tab::Results)),
    )
}

/// What the Next button offers: its text, its command (`None`: shown
/// disabled, e.g. while a run is under way), why, and other ways on.
#[derive(Debug, Clone, PartialEq)]
pub struct NextAction {
    /// The button text after "Next: ".
    pub label: String,
    /// Its command; `None` while something is under way.
    pub command: Option<Command>,
    /// Why this is next (hover text).
    pub why: String,
    /// Other ways on, as smaller buttons ("or: write the report").
    pub others: Vec<(String, Command)>,
}

/// The next action in the current state; `None` when every step is done
/// (and nothing failed).
#[must_use]
pub fn next_action(state: &AppState, forms: &Forms, all: &[Step]) -> Option<NextAction> {
    let simple = |k: usize| {
        let step: &Step = &all[k];
        Some(NextAction {
            label: step.action.0.clone(),
            command: Some(step.action.1.clone()),
            why: step.detail.clone(),
            others: Vec::new(),
        })
    };
    if let Some(run) = state.jobs.get(&Slot::Run) {
        return Some(NextAction {
            label: format!(
                "calibrating… {:.0} %",
                run.fraction.unwrap_or_default() * 100.0
            ),
            command: None,
            why: format!(
                "{}: wait for the run, or press Cancel in the solver panel (the result on show stays)",
                run.phase
            ),
            others: Vec::new(),
        });
    }
    if state.jobs.runs(&Slot::Load) {
        return Some(NextAction {
            label: "opening…".into(),
            command: None,
            why: all[1].detail.clone(),
            others: Vec::new(),
        });
    }
    if state.loaded.is_none() {
        // Plan (again) or bring the data in.
        let k = usize::from(!matches!(
            all[0].state,
            StepState::Todo | StepState::Stale(_)
        ));
        return simple(k);
    }
    // A missing or stale result: run (again).
    if matches!(all[3].state, StepState::Todo | StepState::Stale(_)) {
        return simple(3);
    }
    let report = &all[5];
    let report_todo = !matches!(report.state, StepState::Done);
    // The verdict is seen before anything is written of it.
    if state.result_unseen && report_todo {
        return simple(4);
    }
    // No update made: refine first (or write the report anyway).
    if all[3].state == StepState::Attention {
        let mut next = simple(3);
        if let Some(n) = &mut next
            && report_todo
        {
            let write = ("write the report anyway".into(), report.action.1.clone());
            n.others.push(write);
        }
        return next;
    }
    if let Some(Verdict::Fail(reasons)) = verdict(state, forms) {
        let n = outliers(state);
        let mut others = Vec::new();
        if report_todo {
            others.push((
                "write the report (FAIL)".to_string(),
                report.action.1.clone(),
            ));
        }
        let why = format!("FAIL: {}", reasons.join(", "));
        if n > 0 && !state.outliers_seen {
            others.insert(
                0,
                (
                    "plan more stations".to_string(),
                    Command::Plan(PlanCommand::MoreStations),
                ),
            );
            return Some(NextAction {
                label: format!("Look at the {n} outlier(s)"),
                command: Some(Command::View(ViewCommand::ShowOutliers)),
                why: format!(
                    "{why}: see which measurements the solver flagged, leave out what is wrong, run again"
                ),
                others,
            });
        }
        return Some(NextAction {
            label: "Plan more stations".into(),
            command: Some(Command::Plan(PlanCommand::MoreStations)),
            why: format!(
                "{why}: more identify stations determine the parameters better; the planner opens with more of them"
            ),
            others,
        });
    }
    if report_todo {
        return simple(5);
    }
    if let Some(s) = all.iter().find(|s| s.state == StepState::Running) {
        return Some(NextAction {
            label: format!("{}…", s.name.to_lowercase()),
            command: None,
            why: s.detail.clone(),
            others: Vec::new(),
        });
    }
    // Then the required steps still to do, or showing "!": their action
    // (measure a scan, make the plan again, look at the stripes).
    let pending = |s: &Step| {
        matches!(
            s.state,
            StepState::Todo | StepState::Stale(_) | StepState::Attention
        )
    };
    if let Some(k) = all.iter().position(|s| !s.optional && pending(s)) {
        return simple(k);
    }
    None
}

/// The optional steps not done yet ("8. Compensated"), with their
/// actions: named when every required step is done.
#[must_use]
pub fn optional_left(all: &[Step]) -> Vec<(String, &Step)> {
    all.iter()
        .enumerate()
        .filter(|(_, s)| s.optional && s.state != StepState::Done)
        .map(|(k, s)| (format!("{}. {}", k + 1, s.name), s))
        .collect()
}

/// The first-start "what to do", on the demo until dismissed.
fn intro_ui(ui: &mut egui::Ui, state: &AppState, commands: &mut Vec<Command>) {
    let on_demo = state
        .loaded
        .as_ref()
        .is_some_and(|l| l.source == crate::app::session::Source::Demo);
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

/// The colour of a step's mark and name.
fn colour(step: &Step) -> egui::Color32 {
    match step.state {
        StepState::Done => GOOD,
        StepState::Attention if step.name == "Validated" => BAD,
        StepState::Attention | StepState::Stale(_) => WARN,
        StepState::Running => AFTER,
        StepState::Skipped | StepState::Todo => MUTED,
    }
}

/// Height of the bar's rows (the steps; Next, the other ways on and the
/// stale line), points: fixed, so that the tabs below never move when a
/// line comes or goes.
const ROW_HEIGHT: f32 = 22.0;

/// Whether the Stripe view has been opened on the open session (its
/// warnings looked at), kept in egui's memory by the session's name and
/// size.
fn stripes_seen(ui: &egui::Ui, state: &AppState, forms: &Forms) -> bool {
    let Some(l) = state.loaded.as_ref() else {
        return false;
    };
    let key = format!("{}|{}", l.session.name, l.session.measurements.len());
    let id = egui::Id::unique("steps_stripes_seen");
    if forms.tab == Tab::Stripe {
        ui.data_mut(|d| d.insert_temp(id, key.clone()));
    }
    ui.data(|d| d.get_temp::<String>(id))
        .is_some_and(|k| k == key)
}

/// The bar: each step with its mark, then the next action's button and
/// the other ways on and what is stale; two rows of fixed height.
pub fn steps_ui(ui: &mut egui::Ui, state: &AppState, forms: &Forms, commands: &mut Vec<Command>) {
    intro_ui(ui, state, commands);
    let all = steps(state, forms, stripes_seen(ui, state, forms));
    let next = next_action(state, forms, &all);
    let width = ui.available_width();
    let row = |ui: &mut egui::Ui, add: &mut dyn FnMut(&mut egui::Ui)| {
        ui.allocate_ui_with_layout(
            egui::vec2(width, ROW_HEIGHT),
            egui::Layout::left_to_right(egui::Align::Center),
            |ui| {
                ui.set_min_size(egui::vec2(width, ROW_HEIGHT));
                ui.set_clip_rect(ui.max_rect().intersect(ui.clip_rect()));
                add(ui);
            },
        );
    };
    row(ui, &mut |ui| {
        for (k, step) in all.iter().enumerate() {
            if k > 0 {
                ui.label(RichText::new("›").color(MUTED));
            }
            let name = if step.optional {
                format!("{} {}. {} (optional)", step.state.mark(), k + 1, step.name)
            } else {
                format!("{} {}. {}", step.state.mark(), k + 1, step.name)
            };
            let text = RichText::new(name).size(13.0).color(colour(step));
            // A step is a link to its view (or does its action).
            let busy = state.jobs.runs(&Slot::Run) && matches!(step.action.1, Command::Run(_));
            let hover = match &step.state {
                StepState::Stale(_) => format!("stale: {} ({})", step.detail, step.action.0),
                _ => format!("{} ({})", step.detail, step.action.0),
            };
            if ui
                .add_enabled(!busy, egui::Button::new(text).frame(false))
                .on_hover_text(hover)
                .clicked()
            {
                commands.push(step.action.1.clone());
            }
        }
    });
    // What changed, in words: the stale steps, by cause, on the Next
    // row (the whole of it on hover).
    let mut causes: Vec<(&str, Vec<String>)> = Vec::new();
    for (k, step) in all.iter().enumerate() {
        if let StepState::Stale(what) = &step.state {
            let name = format!("{}. {}", k + 1, step.name);
            match causes.iter_mut().find(|(w, _)| *w == what.as_str()) {
                Some((_, names)) => names.push(name),
                None => causes.push((what, vec![name])),
            }
        }
    }
    let stale: Vec<String> = causes
        .into_iter()
        .map(|(what, names)| format!("! stale: {} — {what}", names.join(", ")))
        .collect();
    row(ui, &mut |ui| {
        match &next {
            Some(n) => {
                let button =
                    egui::Button::new(RichText::new(format!("Next: {}", n.label)).color(AFTER));
                if ui
                    .add_enabled(n.command.is_some(), button)
                    .on_hover_text(&n.why)
                    .on_disabled_hover_text(&n.why)
                    .clicked()
                    && let Some(c) = &n.command
                {
                    commands.push(Command::Next(Box::new(c.clone())));
                }
                for (label, command) in &n.others {
                    if ui
                        .small_button(format!("or: {label}"))
                        .on_hover_text(&n.why)
                        .clicked()
                    {
                        commands.push(command.clone());
                    }
                }
            }
            None if state.loaded.is_some() => {
                let left = optional_left(&all);
                if left.is_empty() {
                    ui.label(RichText::new("● every step is done").color(GOOD));
                } else {
                    let names: Vec<&str> = left.iter().map(|(n, _)| n.as_str()).collect();
                    ui.label(
                        RichText::new(format!(
                            "● every required step is done; optional, not done: {}",
                            names.join(", ")
                        ))
                        .color(GOOD),
                    );
                    for (_, step) in left {
                        if ui
                            .small_button(format!("or: {}", step.action.0))
                            .on_hover_text(&step.detail)
                            .clicked()
                        {
                            commands.push(step.action.1.clone());
                        }
                    }
                }
            }
            None => {}
        }
        if !stale.is_empty() {
            ui.add_space(12.0);
            let text = stale.join("; ");
            ui.add(egui::Label::new(RichText::new(&text).small().color(WARN)).truncate())
                .on_hover_text(&text);
        }
    });
}

/// The Measure step of the step bar: to do, under way, done or stale
/// (the cloud's standing in the ledger).
#[must_use]
pub fn measure_step(state: &AppState) -> Step {
    let mut m = step(
        state,
        Artefact::Cloud,
        "Measured",
        (
            "measure a scan with the calibrated cell (optional)",
            "measure again before exporting",
        ),
        ("Measure a scan", show(Tab::Measure)),
    );
    if let (StepState::Running, Some(job)) = (&m.state, state.jobs.get(&Slot::Measure)) {
        let percent = job.fraction.unwrap_or_default() * 100.0;
        m.detail = format!("measuring: {} ({percent:.0} %)", job.phase);
    }
    m
}
