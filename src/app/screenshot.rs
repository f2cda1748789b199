//! The screenshots of the guide and the README (`assets/*.png`), taken by
//! the real window of the workbench driving itself through a scenario:
//!
//! ```text
//! SPHERECAL_SCREENSHOT=<scenario>:<out.png> spherecal gui   # one picture, then the window closes
//! SPHERECAL_SCREENSHOT=list spherecal gui                   # every scenario and its asset file
//! ```
//!
//! `tools/screenshots.sh` builds the binary, makes the scenarios' input
//! files with the command line and runs every scenario under Xvfb at
//! 1366×768; read it first. A scenario ([`Scenario`]) is a list of
//! [`Act`]s that a small state machine ([`Director`]) steps through, one
//! a frame: commands applied as a panel would push them, form fields set
//! as the widgets would, waits until no job is in flight, the pointer
//! moved or the wheel turned (injected into the frame's input), checks of
//! the state, then the window's own picture (egui's screenshot command)
//! saved as PNG with the `image` crate, and the window closed. Nothing
//! here computes anything or adds behaviour: the workbench does what the
//! operator's clicks would make it do.
//!
//! Input files are found relative to the working folder: the repository's
//! `sessions/`, `data/` and `examples/`, and the files the script makes
//! (each scenario's doc names them). The window starts on the embedded
//! demo, with default preferences; nothing is read from or written to the
//! user's stored preferences.
//!
//! A scenario fails (exit status 1, the reason printed) when an input is
//! missing, a check does not hold, an error notice is on show at the
//! picture, the picture is not 1366×768 pixels, or it takes longer than
//! [`TIMEOUT`].

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use egui::{Pos2, pos2};

use super::AppState;
use super::Core;
use super::Forms;
use super::command::ExportKind;
use super::command::Tab;
use super::command::{
    Command, CompensateCommand, FilesCommand, HistoryCommand, ImportCommand, MeasureCommand,
    PlanCommand, RunCommand, ViewCommand,
};
use crate::engine::base::session::SensorRange;
use crate::engine::tools::result_view::Tolerance;

/// The environment variable that asks for a screenshot.
pub const ENV: &str = "SPHERECAL_SCREENSHOT";

/// The size of every picture, pixels: the window's inner size at a
/// display scale of 1 (the operator's screen the workbench is laid out
/// for).
pub const SIZE: [usize; 2] = [1366, 768];

/// Longest a scenario may take, from the first frame to the picture (the
/// 3,011-station calibration takes about 10 s in a debug build).
pub const TIMEOUT: Duration = Duration::from_mins(5);

/// Consecutive frames with no job in flight before a wait ends: a panel
/// may start a job in the frame after a command (the import's scan, the
/// History view's drift).
const IDLE_FRAMES: u32 = 5;

/// The pause before each picture: scroll animations and tooltips settle.
const SETTLE: Duration = Duration::from_millis(800);

/// Frame period while a scenario runs (frames are asked for; no input
/// comes under Xvfb).
const FRAME: Duration = Duration::from_millis(20);

/// Where the pointer rests over the central view to turn the wheel.
const CENTRE: Pos2 = pos2(830.0, 450.0);

/// How long the pointer stays over the central view after a turn of the
/// wheel (egui scrolls smoothly over a few frames).
const SCROLLING: Duration = Duration::from_millis(700);

/// The measuring range of the range scenarios, ±40 mm in y and z.
const RANGE: SensorRange = SensorRange {
    y: [-40.0, 40.0],
    z: [-40.0, 40.0],
};

/// One thing a scenario does; the [`Director`] does one a frame.
#[derive(Debug, Clone)]
pub enum Act {
    /// Apply a command, as a panel would push it.
    Do(Command),
    /// A command made from the state (a measurement found by its id), or
    /// why there is none.
    Find(fn(&AppState) -> Result<Command, String>),
    /// Set form fields, as the widgets would.
    Edit(fn(&mut Forms)),
    /// Wait until no job has been in flight for a few frames.
    Settle,
    /// Move the pointer here and leave it there (a hover, a tooltip);
    /// without one the pointer is outside the window.
    Hover(Pos2),
    /// Move the pointer here and keep it moving within a pixel: what a
    /// hover shows at once (a centre's name plate), never a tooltip.
    Glance(Pos2),
    /// Turn the wheel over the central view by this many points (negative:
    /// down the page), then take the pointer away.
    Scroll(f32),
    /// Let this much time pass, frames drawn.
    Pause(Duration),
    /// A check of what the workbench shows; the message when it fails.
    Expect(fn(&AppState, &Forms) -> Result<(), String>),
    /// Save the window's picture to the output file and close.
    Shot,
    /// Copy a file the workbench wrote into its export folder (the
    /// working folder) to the output file and close.
    CopyExport(&'static str),
}

/// The scenarios, one an asset file (see [`Scenario::file_name`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scenario {
    /// First start on the demo: the "what to do" box, the step bar
    /// offering the run, the Session table.
    Steps,
    /// The demo calibrated with `ml`: the Results view's headline, the
    /// calibration and validation sets, Fig. 5 and 6.
    Results,
    /// The demo calibrated: the Results view scrolled to the hand-eye and
    /// joint tables and `ml`'s diagnostics.
    ResultsTables,
    /// The demo calibrated with the paper's method: ε per update and the
    /// singular values with the truncation line.
    ResultsPaper,
    /// The demo calibrated: the calibration set against the validation
    /// set with the histogram.
    Sets,
    /// The demo's Stripe view (its first measurement).
    Stripe,
    /// The demo calibrated: the Centres view, before hollow, after filled.
    Centres,
    /// The Import view on a simulated joint log (`sim/joints.csv`,
    /// `sim/profiles/`, `sim/references.csv`: `spherecal simulate
    /// --csv-out sim`), its columns guessed and previewed, the measuring
    /// range set.
    Import,
    /// The demo's Session view with the measuring range set to ±40 mm.
    SessionRange,
    /// The Plan view with the default IRB 2400 plan and its prediction.
    Plan,
    /// The Plan view planning for the ±40 mm measuring range, the sphere
    /// spread over it.
    PlanRange,
    /// A plan made for the IRB 2400, the robot then set to the UR5e
    /// without Make plan: STALE, its program refused (the reason on
    /// hover).
    StalePlan,
    /// The History view on `sessions/history`: the drift of cell 3.
    History,
    /// The Results view of 60 validate stations (`fig5-60.json`:
    /// `spherecal simulate --validate-stations 60`).
    Fig5Of60,
    /// The Results view of 12 reference distances (`fig6-12.json`:
    /// `--validate-stations 3 --seed 3`).
    Fig6Of12,
    /// The Centres view of 71 stations after calibration
    /// (`centres-70.json`: `--identify-stations 60 --validate-stations
    /// 10`).
    Centres70,
    /// The Centres view of 3,011 stations after calibration, a centre
    /// named on hover (`centres-3000.json`: `--identify-stations 3000
    /// --centres --poses 3`).
    Centres3000,
    /// After a FAIL: a sphere knocked by 1.5 mm at one pose (`fail.json`:
    /// `--centres`, one identify centre moved), the tolerance std ≤
    /// 0.08 mm; the Results view with the way forward.
    Fail,
    /// The demo with the ±40 mm measuring range, calibrated: the Results
    /// view's predicted error over the range.
    Range,
    /// The real set (`data/robcalibrator-sphere`) imported in the wizard:
    /// the Stripe view of pose p5.
    RealdataStripe,
    /// The seed-7 cell (`seed7.json`: `spherecal simulate --seed 7`)
    /// calibrated, `examples/path.mod` compensated through it.
    Compensate,
    /// The seed-7 cell calibrated, the three-sphere raw scan
    /// `examples/artefact` measured, its cloud written to `artefact.ply`.
    Measure,
    /// The demo calibrated: the Results view's Plots PNG export itself
    /// (not a window picture).
    PlotsExport,
}

impl Scenario {
    /// Every scenario, in the order the script takes them.
    pub const ALL: [Self; 23] = [
        Self::Steps,
        Self::Results,
        Self::ResultsTables,
        Self::ResultsPaper,
        Self::Sets,
        Self::Stripe,
        Self::Centres,
        Self::Import,
        Self::SessionRange,
        Self::Plan,
        Self::PlanRange,
        Self::StalePlan,
        Self::History,
        Self::Fig5Of60,
        Self::Fig6Of12,
        Self::Centres70,
        Self::Centres3000,
        Self::Fail,
        Self::Range,
        Self::RealdataStripe,
        Self::Compensate,
        Self::Measure,
        Self::PlotsExport,
    ];

    /// The name given in [`ENV`].
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Steps => "steps",
            Self::Results => "results",
            Self::ResultsTables => "results-tables",
            Self::ResultsPaper => "results-paper",
            Self::Sets => "sets",
            Self::Stripe => "stripe",
            Self::Centres => "centres",
            Self::Import => "import",
            Self::SessionRange => "session-range",
            Self::Plan => "plan",
            Self::PlanRange => "plan-range",
            Self::StalePlan => "stale-plan",
            Self::History => "history",
            Self::Fig5Of60 => "fig5-60",
            Self::Fig6Of12 => "fig6-12",
            Self::Centres70 => "centres-70",
            Self::Centres3000 => "centres-3000",
            Self::Fail => "fail",
            Self::Range => "range",
            Self::RealdataStripe => "realdata-stripe",
            Self::Compensate => "compensate",
            Self::Measure => "measure",
            Self::PlotsExport => "plots-export",
        }
    }

    /// The file in `assets/` it makes.
    #[must_use]
    pub fn file_name(self) -> String {
        match self {
            Self::PlotsExport => "plots-export.png".to_string(),
            s => format!("screenshot-{}.png", s.name()),
        }
    }

    /// The scenario named so.
    ///
    /// # Errors
    /// An unknown name: the message lists the known ones.
    pub fn from_name(name: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|s| s.name() == name)
            .ok_or_else(|| {
                let known: Vec<&str> = Self::ALL.iter().map(|s| s.name()).collect();
                format!(
                    "unknown screenshot scenario `{name}` in {ENV}; known: {}",
                    known.join(", ")
                )
            })
    }

    /// What it does, in order.
    #[must_use]
    pub fn acts(self) -> Vec<Act> {
        let mut acts = match self {
            Self::Steps => vec![Act::Settle, Act::Expect(demo_open)],
            Self::Results => [demo_run(), vec![show(Tab::Results)]].concat(),
            Self::ResultsTables => {
                [demo_run(), vec![show(Tab::Results), Act::Scroll(-1000.0)]].concat()
            }
            Self::ResultsPaper => [
                vec![
                    Act::Settle,
                    dismiss(),
                    Act::Edit(|f| f.solver.method = crate::engine::calibrate::solve::Method::Paper),
                ],
                run(),
                vec![show(Tab::Results), Act::Scroll(-745.0)],
            ]
            .concat(),
            Self::Sets => [demo_run(), vec![show(Tab::Results), Act::Scroll(-200.0)]].concat(),
            Self::Stripe => vec![Act::Settle, dismiss(), show(Tab::Stripe)],
            Self::Centres => [demo_run(), vec![show(Tab::Centres)]].concat(),
            Self::Import => import(),
            Self::SessionRange => vec![
                Act::Settle,
                dismiss(),
                Act::Do(Command::View(ViewCommand::SetSensorRange(Some(RANGE)))),
                show(Tab::Session),
            ],
            Self::Plan => vec![
                Act::Settle,
                dismiss(),
                show(Tab::Plan),
                Act::Do(Command::Plan(PlanCommand::Make)),
                Act::Settle,
                Act::Expect(planned),
            ],
            Self::PlanRange => vec![
                Act::Settle,
                dismiss(),
                show(Tab::Plan),
                Act::Edit(|f| {
                    f.plan.request.range = Some(RANGE);
                    f.plan.request.spread = true;
                }),
                Act::Do(Command::Plan(PlanCommand::Make)),
                Act::Settle,
                Act::Expect(planned),
            ],
            Self::StalePlan => stale_plan(),
            Self::History => history(),
            Self::Fig5Of60 => [
                open_run("fig5-60.json"),
                vec![show(Tab::Results), Act::Scroll(-420.0)],
            ]
            .concat(),
            Self::Fig6Of12 => [
                open_run("fig6-12.json"),
                vec![show(Tab::Results), Act::Scroll(-420.0)],
            ]
            .concat(),
            Self::Centres70 => [open_run("centres-70.json"), vec![show(Tab::Centres)]].concat(),
            Self::Centres3000 => [open_run("centres-3000.json"), vec![show(Tab::Centres)]].concat(),
            Self::Fail => fail(),
            Self::Range => [
                vec![
                    Act::Settle,
                    dismiss(),
                    Act::Do(Command::View(ViewCommand::SetSensorRange(Some(RANGE)))),
                ],
                run(),
                vec![show(Tab::Results), Act::Scroll(-2400.0)],
            ]
            .concat(),
            Self::RealdataStripe => realdata_stripe(),
            Self::Compensate => compensate(),
            Self::Measure => measure(),
            Self::PlotsExport => {
                let mut acts = demo_run();
                acts.extend([
                    Act::Do(Command::Export(ExportKind::PlotsPng)),
                    Act::Settle,
                    Act::CopyExport("demo-irb2400-plots.png"),
                ]);
                return acts;
            }
        };
        acts.push(Act::Pause(SETTLE));
        if self == Self::Centres3000 {
            // A centre named on hover; the 3-D view's own tooltip would
            // cover the status line.
            acts.extend([
                Act::Glance(pos2(590.0, 430.0)),
                Act::Pause(Duration::from_millis(300)),
            ]);
        }
        acts.push(Act::Shot);
        acts
    }

    /// The input files it opens (relative to the working folder), to say
    /// which is missing before the window opens.
    #[must_use]
    pub fn inputs(self) -> &'static [&'static str] {
        match self {
            Self::Import => &["sim/joints.csv", "sim/profiles", "sim/references.csv"],
            Self::History => &["sessions/history"],
            Self::Fig5Of60 => &["fig5-60.json"],
            Self::Fig6Of12 => &["fig6-12.json"],
            Self::Centres70 => &["centres-70.json"],
            Self::Centres3000 => &["centres-3000.json"],
            Self::Fail => &["fail.json"],
            Self::RealdataStripe => &["data/robcalibrator-sphere/RobPoses.rob"],
            Self::Compensate => &["seed7.json", "examples/path.mod"],
            Self::Measure => &["seed7.json", "examples/artefact/joints.csv"],
            _ => &[],
        }
    }
}

/// The Import view previewing a simulated joint log.
fn import() -> Vec<Act> {
    vec![
        Act::Settle,
        dismiss(),
        show(Tab::Import),
        Act::Edit(|f| {
            f.import.joints = "sim/joints.csv".into();
            f.import.profiles = "sim/profiles".into();
            f.import.references = "sim/references.csv".into();
            f.import.range = Some([RANGE.y[0], RANGE.y[1], RANGE.z[0], RANGE.z[1]]);
        }),
        Act::Do(Command::Import(ImportCommand::Preview { guess: true })),
        Act::Settle,
        Act::Expect(|s, _| match &s.import.preview {
            Some(Ok(_)) => Ok(()),
            Some(Err(e)) => Err(format!("the import preview failed: {e}")),
            None => Err("no import preview".into()),
        }),
    ]
}

/// A plan made, then the robot changed without Make plan.
fn stale_plan() -> Vec<Act> {
    vec![
        Act::Settle,
        dismiss(),
        show(Tab::Plan),
        Act::Do(Command::Plan(PlanCommand::Make)),
        Act::Settle,
        Act::Expect(planned),
        // The robot picked in the form, as its combo box does it
        // (the sphere follows the robot), and no Make plan.
        Act::Edit(|f| {
            f.plan.robot = "ur5e".into();
            f.plan.request.design.sphere = super::plan::form::default_sphere("ur5e");
        }),
        Act::Pause(Duration::from_millis(300)),
        Act::Expect(|s, _| {
            s.ledger
                .stale(super::ledger::Artefact::Plan)
                .map(|_| ())
                .ok_or_else(|| "the plan is not marked stale".to_string())
        }),
        Act::Hover(pos2(1170.0, 452.0)),
    ]
}

/// The History view on the example library.
fn history() -> Vec<Act> {
    vec![
        Act::Settle,
        dismiss(),
        show(Tab::History),
        Act::Edit(|f| f.history.folder = "sessions/history".into()),
        Act::Do(Command::History(HistoryCommand::Scan)),
        Act::Settle,
        Act::Expect(|s, _| match &s.history.drift {
            Some(Ok(_)) => Ok(()),
            Some(Err(e)) => Err(format!("no drift: {e}")),
            None => Err("no drift".into()),
        }),
    ]
}

/// The knocked sphere calibrated and judged at std ≤ 0.08 mm.
fn fail() -> Vec<Act> {
    [
        open_run("fail.json"),
        vec![
            Act::Do(Command::View(ViewCommand::SetTolerance(Tolerance {
                std_mm: 0.08,
                max_mm: 0.5,
            }))),
            show(Tab::Results),
            Act::Expect(|s, f| {
                use crate::engine::tools::result_view::Verdict;
                let fail = s.result.as_ref().is_some_and(|r| {
                    matches!(
                        Verdict::of(r.shown.headline.as_ref(), &f.tolerance),
                        Verdict::Fail(_)
                    )
                });
                if fail {
                    Ok(())
                } else {
                    Err("the knocked sphere does not FAIL at std ≤ 0.08 mm".into())
                }
            }),
        ],
    ]
    .concat()
}

/// The real set imported in the wizard, pose p5's stripe.
fn realdata_stripe() -> Vec<Act> {
    vec![
        Act::Settle,
        dismiss(),
        show(Tab::Import),
        Act::Edit(|f| {
            let dir = "data/robcalibrator-sphere";
            f.import.log_kind = super::import::form::LogKind::FlangePoses;
            f.import.poses = format!("{dir}/RobPoses.rob");
            f.import.profiles = dir.into();
            f.import.pose_convention =
                Some(crate::engine::files::import::FlangeConvention::FanucWpr);
            f.import.sphere_diameter = 80.0;
        }),
        Act::Settle,
        Act::Do(Command::Import(ImportCommand::Run)),
        Act::Settle,
        Act::Expect(|s, _| match &s.import.outcome {
            Some(Ok(_)) => Ok(()),
            Some(Err(e)) => Err(format!("the real set did not import: {e}")),
            None => Err("the real set did not import".into()),
        }),
        Act::Find(|s| measurement(s, "p5").map(|i| Command::View(ViewCommand::Inspect(i)))),
    ]
}

/// The seed-7 cell calibrated, the example RAPID module compensated.
fn compensate() -> Vec<Act> {
    [
        open_run("seed7.json"),
        vec![
            show(Tab::Compensate),
            Act::Edit(|f| f.compensate.targets = "examples/path.mod".into()),
            Act::Do(Command::Compensate(CompensateCommand::Run)),
            Act::Settle,
            Act::Expect(|s, _| match &s.compensate.outcome {
                Some(Ok(_)) => Ok(()),
                Some(Err(e)) => Err(format!("nothing compensated: {e}")),
                None => Err("nothing compensated".into()),
            }),
        ],
    ]
    .concat()
}

/// The seed-7 cell calibrated, the example artefact scan measured and written.
fn measure() -> Vec<Act> {
    [
        open_run("seed7.json"),
        vec![
            show(Tab::Measure),
            Act::Edit(|f| {
                use super::measure::{RawLog, ScanChoice};
                let m = &mut f.measure;
                m.choice = ScanChoice::RawScan;
                m.raw_log = RawLog::Joints;
                m.log = "examples/artefact/joints.csv".into();
                m.profiles = "examples/artefact/profiles".into();
                m.references = "examples/artefact/references.csv".into();
                m.out = "artefact.ply".into();
            }),
            Act::Do(Command::Measure(MeasureCommand::Start)),
            Act::Settle,
            Act::Expect(|s, _| {
                s.measure
                    .shown
                    .as_ref()
                    .map(|_| ())
                    .ok_or_else(|| "no cloud measured".to_string())
            }),
            Act::Do(Command::Measure(MeasureCommand::Export)),
            Act::Settle,
        ],
    ]
    .concat()
}

/// Show a view.
fn show(tab: Tab) -> Act {
    Act::Do(Command::View(ViewCommand::ShowTab(tab)))
}

/// Close the first-start "what to do" (not kept: nothing is stored).
fn dismiss() -> Act {
    Act::Do(Command::View(ViewCommand::DismissIntro))
}

/// Press ▶ Run, wait for the result and look at it (the Results tab is
/// then no longer marked as unseen).
fn run() -> Vec<Act> {
    vec![
        Act::Do(Command::Run(RunCommand::Start)),
        Act::Settle,
        Act::Expect(|s, _| {
            s.result
                .as_ref()
                .map(|_| ())
                .ok_or_else(|| "the run gave no result".to_string())
        }),
        show(Tab::Results),
    ]
}

/// The demo, calibrated with the default settings (`ml`).
fn demo_run() -> Vec<Act> {
    [vec![Act::Settle, Act::Expect(demo_open), dismiss()], run()].concat()
}

/// A session file opened, then calibrated.
fn open_run(path: &'static str) -> Vec<Act> {
    [
        vec![
            Act::Settle,
            dismiss(),
            Act::Do(Command::Files(FilesCommand::OpenPath(PathBuf::from(path)))),
            Act::Settle,
            Act::Expect(|s, _| {
                s.loaded
                    .as_ref()
                    .filter(|l| l.source.path().is_some())
                    .map(|_| ())
                    .ok_or_else(|| "the session file did not open".to_string())
            }),
        ],
        run(),
    ]
    .concat()
}

fn demo_open(state: &AppState, _: &Forms) -> Result<(), String> {
    state
        .loaded
        .as_ref()
        .map(|_| ())
        .ok_or_else(|| "the demo session did not open".to_string())
}

fn planned(state: &AppState, _: &Forms) -> Result<(), String> {
    match &state.plan.outcome {
        Some(Ok(_)) => Ok(()),
        Some(Err(e)) => Err(format!("no plan: {e}")),
        None => Err("no plan".into()),
    }
}

/// The index of measurement `id` in the open session.
fn measurement(state: &AppState, id: &str) -> Result<usize, String> {
    state
        .loaded
        .as_ref()
        .and_then(|l| l.session.measurements.iter().position(|m| m.id == id))
        .ok_or_else(|| format!("no measurement {id} in the open session"))
}

/// What [`ENV`] asks for.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Request {
    /// Print every scenario and its asset file, one a line.
    List,
    /// Take one scenario's picture into this file.
    Take(Spec),
}

/// One picture to take.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Spec {
    /// What to show.
    pub scenario: Scenario,
    /// The PNG file to write.
    pub out: PathBuf,
}

impl Request {
    /// Reads `text` as [`ENV`] holds it: `list`, or `<scenario>:<out.png>`.
    ///
    /// # Errors
    /// Another form, an unknown scenario (the known ones listed), or an
    /// output that is not a `.png` file.
    pub fn parse(text: &str) -> Result<Self, String> {
        let text = text.trim();
        if text == "list" {
            return Ok(Self::List);
        }
        let Some((name, out)) = text.split_once(':') else {
            return Err(format!(
                "{ENV}=`{text}`: expected `<scenario>:<out.png>` or `list`"
            ));
        };
        let scenario = Scenario::from_name(name.trim())?;
        let out = out.trim();
        let is_png = Path::new(out)
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"));
        if !is_png || Path::new(out).file_stem().is_none() {
            return Err(format!(
                "{ENV}=`{text}`: the picture `{out}` must be a .png file"
            ));
        }
        Ok(Self::Take(Spec {
            scenario,
            out: PathBuf::from(out),
        }))
    }

    /// The request in the environment, if any.
    ///
    /// # Errors
    /// As [`Request::parse`]; a value that is not UTF-8.
    pub fn from_env() -> Result<Option<Self>, String> {
        match std::env::var(ENV) {
            Ok(text) => Self::parse(&text).map(Some),
            Err(std::env::VarError::NotPresent) => Ok(None),
            Err(std::env::VarError::NotUnicode(_)) => Err(format!("{ENV} is not UTF-8 text")),
        }
    }
}

/// Every scenario and its asset file, one a line (`<scenario> <file>`).
#[must_use]
pub fn listing() -> String {
    Scenario::ALL
        .iter()
        .map(|s| format!("{} {}\n", s.name(), s.file_name()))
        .collect()
}

/// How the scenario ended: the file written, or why not; `None` while it
/// runs (and when the window closed before it ended).
#[derive(Debug, Clone, Default)]
pub struct Outcome(Arc<Mutex<Option<Result<String, String>>>>);

impl Outcome {
    fn set(&self, outcome: Result<String, String>) {
        if let Ok(mut slot) = self.0.lock()
            && slot.is_none()
        {
            *slot = Some(outcome);
        }
    }

    /// What to tell once the window has closed: a line on the file
    /// written.
    ///
    /// # Errors
    /// Why the scenario failed, or that the window closed before it ended.
    pub fn result(&self) -> Result<String, String> {
        self.0
            .lock()
            .map_err(|_| "the screenshot's outcome was lost (a thread panicked)".to_string())?
            .clone()
            .unwrap_or_else(|| Err("the window closed before the screenshot was taken".into()))
    }
}

/// The picture egui hands back after a screenshot command.
type Picture = Arc<Mutex<Option<Arc<egui::ColorImage>>>>;

/// Steps a scenario through the workbench, one act a frame.
#[derive(Debug)]
pub struct Director {
    spec: Spec,
    acts: Vec<Act>,
    /// The act being done.
    next: usize,
    /// When the act being done started.
    since: Instant,
    /// When the first frame came.
    started: Option<Instant>,
    /// Frames in a row with no job in flight.
    idle: u32,
    /// Frames the act being done has been under way.
    frames: u32,
    /// Input to put into the next frame (the wheel).
    events: Vec<egui::Event>,
    /// Where the pointer rests; `None`: outside the window.
    pointer: Option<Pos2>,
    /// Where the frames were last told the pointer is.
    told: Option<Pos2>,
    /// The pointer keeps moving within a pixel ([`Act::Glance`]).
    glancing: bool,
    /// The picture asked for, once it has come.
    picture: Option<Picture>,
    outcome: Outcome,
    done: bool,
}

impl Director {
    /// A director for `spec`. Makes the window's `options` leave the
    /// user's stored preferences and window geometry alone.
    #[must_use]
    pub fn new(spec: Spec, options: &mut eframe::NativeOptions) -> Self {
        options.persist_window = false;
        options.persistence_path = Some(storage_path());
        Self {
            acts: spec.scenario.acts(),
            spec,
            next: 0,
            since: Instant::now(),
            started: None,
            idle: 0,
            frames: 0,
            events: Vec::new(),
            pointer: None,
            told: None,
            glancing: false,
            picture: None,
            outcome: Outcome::default(),
            done: false,
        }
    }

    /// The handle to read how the scenario ended.
    #[must_use]
    pub fn outcome(&self) -> Outcome {
        self.outcome.clone()
    }

    /// Says which input file is missing, before the window opens.
    ///
    /// # Errors
    /// The first input of the scenario that is not in the working folder.
    pub fn check_inputs(&self) -> Result<(), String> {
        match self
            .spec
            .scenario
            .inputs()
            .iter()
            .find(|p| !Path::new(p).exists())
        {
            Some(p) => Err(format!(
                "screenshot scenario {}: its input {p} is not in the working folder {} (tools/screenshots.sh makes it)",
                self.spec.scenario.name(),
                std::env::current_dir().map_or_else(|_| "?".into(), |d| d.display().to_string())
            )),
            None => Ok(()),
        }
    }

    /// Puts the scenario's pointer and wheel into the frame's input. The
    /// display's own pointer (the middle of Xvfb's screen, where the
    /// window opens) is put out of the window every frame unless the
    /// scenario hovers; a hover is told once, so that egui sees the
    /// pointer still (a tooltip needs that).
    pub fn raw_input(&mut self, raw: &mut egui::RawInput) {
        match self.pointer {
            None => {
                raw.events.push(egui::Event::PointerGone);
                self.told = None;
            }
            Some(p) if self.glancing => {
                let p = if self.told == Some(p) {
                    p + egui::vec2(0.5, 0.0)
                } else {
                    p
                };
                raw.events.push(egui::Event::PointerMoved(p));
                self.told = Some(p);
            }
            Some(p) if self.told != Some(p) => {
                raw.events.push(egui::Event::PointerMoved(p));
                self.told = Some(p);
            }
            Some(_) => {}
        }
        raw.events.append(&mut self.events);
    }

    /// Does the next act, or waits on the one under way; called at the end
    /// of every frame.
    pub fn frame(&mut self, ctx: &egui::Context, core: &mut Core) {
        if self.done {
            return;
        }
        ctx.request_repaint_after(FRAME);
        let started = *self.started.get_or_insert_with(Instant::now);
        if started.elapsed() > TIMEOUT {
            let at = self.acts.get(self.next);
            self.fail(
                ctx,
                format!("timed out after {} s at {at:?}", TIMEOUT.as_secs()),
            );
            return;
        }
        let Some(act) = self.acts.get(self.next).cloned() else {
            self.fail(ctx, "the scenario ended without a picture".into());
            return;
        };
        let first = self.frames == 0;
        self.frames += 1;
        match act {
            Act::Do(command) => {
                core.apply(ctx, command);
                self.advance();
            }
            Act::Find(f) => match f(&core.state) {
                Ok(command) => {
                    core.apply(ctx, command);
                    self.advance();
                }
                Err(e) => self.fail(ctx, e),
            },
            Act::Edit(f) => {
                f(&mut core.forms);
                self.advance();
            }
            Act::Settle => {
                if core.state.is_busy() {
                    self.idle = 0;
                } else {
                    self.idle += 1;
                    if self.idle >= IDLE_FRAMES {
                        self.advance();
                    }
                }
            }
            Act::Hover(p) => {
                self.pointer = Some(p);
                self.glancing = false;
                self.advance();
            }
            Act::Glance(p) => {
                self.pointer = Some(p);
                self.glancing = true;
                self.advance();
            }
            Act::Scroll(dy) => {
                if first {
                    self.pointer = Some(CENTRE);
                    self.glancing = false;
                    self.events.push(egui::Event::MouseWheel {
                        unit: egui::MouseWheelUnit::Point,
                        delta: egui::vec2(0.0, dy),
                        phase: egui::TouchPhase::Move,
                        source: egui::MouseWheelSource::Unknown,
                        modifiers: egui::Modifiers::NONE,
                    });
                } else if self.since.elapsed() >= SCROLLING {
                    self.pointer = None;
                    self.advance();
                }
            }
            Act::Pause(d) => {
                if self.since.elapsed() >= d {
                    self.advance();
                }
            }
            Act::Expect(f) => match f(&core.state, &core.forms) {
                Ok(()) => self.advance(),
                Err(e) => {
                    let why = match &core.state.notice {
                        Some(n) => format!("{e} (the notice on show: {}: {})", n.title, n.body),
                        None => e,
                    };
                    self.fail(ctx, why);
                }
            },
            Act::Shot => self.shot(ctx, core),
            Act::CopyExport(name) => {
                let from = PathBuf::from(core.forms.export_dir.trim()).join(name);
                let outcome = std::fs::copy(&from, &self.spec.out)
                    .map(|_| self.written())
                    .map_err(|e| {
                        format!(
                            "could not copy {} to {}: {e}",
                            from.display(),
                            self.spec.out.display()
                        )
                    });
                self.end(ctx, outcome);
            }
        }
    }

    /// Asks for the window's picture, then saves it when it has come.
    fn shot(&mut self, ctx: &egui::Context, core: &Core) {
        if let Some(notice) = &core.state.notice {
            let text = format!(
                "an error notice is on show: {}: {}",
                notice.title, notice.body
            );
            self.fail(ctx, text);
            return;
        }
        let Some(picture) = &self.picture else {
            let slot: Picture = Arc::default();
            let (to, repaint) = (Arc::clone(&slot), ctx.clone());
            ctx.request_screenshot(move |image| {
                if let Ok(mut s) = to.lock() {
                    *s = Some(image);
                }
                repaint.request_repaint();
            });
            self.picture = Some(slot);
            return;
        };
        let image = picture.lock().ok().and_then(|mut s| s.take());
        if let Some(image) = image {
            let outcome = save_png(&image, &self.spec.out).map(|()| self.written());
            self.end(ctx, outcome);
        }
    }

    fn written(&self) -> String {
        let seconds = self.started.map_or(0.0, |s| s.elapsed().as_secs_f64());
        format!(
            "wrote {} (scenario {}, {seconds:.1} s)",
            self.spec.out.display(),
            self.spec.scenario.name()
        )
    }

    fn advance(&mut self) {
        self.next += 1;
        self.since = Instant::now();
        self.idle = 0;
        self.frames = 0;
    }

    fn fail(&mut self, ctx: &egui::Context, why: String) {
        let text = format!("screenshot scenario {}: {why}", self.spec.scenario.name());
        self.end(ctx, Err(text));
    }

    fn end(&mut self, ctx: &egui::Context, outcome: Result<String, String>) {
        self.outcome.set(outcome);
        self.done = true;
        ctx.send_viewport_cmd(egui::ViewportCommand::Close);
    }
}

/// The throw-away preferences file of a screenshot run (removed by
/// [`remove_storage`]).
fn storage_path() -> PathBuf {
    std::env::temp_dir().join(format!("spherecal-screenshot-{}.ron", std::process::id()))
}

/// Removes the preferences file of a screenshot run.
pub fn remove_storage() {
    let _ = std::fs::remove_file(storage_path());
}

/// Writes the window's picture as an RGB PNG, refusing any size but
/// [`SIZE`].
fn save_png(image: &egui::ColorImage, out: &Path) -> Result<(), String> {
    let [w, h] = image.size;
    if image.size != SIZE {
        return Err(format!(
            "the window's picture is {w}×{h} pixels, not {}×{} (a display scale other than 1, or a screen smaller than the window?)",
            SIZE[0], SIZE[1]
        ));
    }
    let bytes: Vec<u8> = image
        .pixels
        .iter()
        .flat_map(|c| [c.r(), c.g(), c.b()])
        .collect();
    let buffer = image::RgbImage::from_raw(w as u32, h as u32, bytes)
        .ok_or_else(|| format!("the window's picture has not {w}×{h} pixels"))?;
    buffer
        .save_with_format(out, image::ImageFormat::Png)
        .map_err(|e| format!("could not write {}: {e}", out.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scenario_and_a_png_are_read() {
        assert_eq!(
            Request::parse("results:assets/screenshot-results.png"),
            Ok(Request::Take(Spec {
                scenario: Scenario::Results,
                out: PathBuf::from("assets/screenshot-results.png"),
            }))
        );
        assert_eq!(
            Request::parse(" centres-3000 : /tmp/a b.PNG "),
            Ok(Request::Take(Spec {
                scenario: Scenario::Centres3000,
                out: PathBuf::from("/tmp/a b.PNG"),
            }))
        );
        assert_eq!(Request::parse("list"), Ok(Request::List));
    }

    #[test]
    fn an_unknown_scenario_lists_every_known_one() {
        let e = Request::parse("resluts:x.png").unwrap_err();
        assert!(e.contains("unknown screenshot scenario `resluts`"), "{e}");
        for s in Scenario::ALL {
            assert!(e.contains(s.name()), "{} not listed: {e}", s.name());
        }
    }

    #[test]
    fn other_forms_are_refused_saying_the_expected_one() {
        for text in [
            "",
            "results",
            "results:",
            "results:shot.jpg",
            "results:.png",
        ] {
            let e = Request::parse(text).unwrap_err();
            assert!(
                e.contains("<scenario>:<out.png>") || e.contains("must be a .png file"),
                "{text}: {e}"
            );
        }
    }

    /// Each scenario has its own name and asset file, the files the guide
    /// and the README show (so a regenerated set keeps their links), and
    /// ends in one picture.
    #[test]
    fn scenarios_are_named_once_and_make_the_existing_assets() {
        let names: std::collections::BTreeSet<&str> =
            Scenario::ALL.iter().map(|s| s.name()).collect();
        assert_eq!(names.len(), Scenario::ALL.len());
        let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
        for s in Scenario::ALL {
            assert_eq!(Scenario::from_name(s.name()), Ok(s));
            assert!(
                assets.join(s.file_name()).is_file(),
                "assets/{} is missing",
                s.file_name()
            );
            let acts = s.acts();
            let last = acts.last().expect("acts");
            assert!(
                matches!(last, Act::Shot | Act::CopyExport(_)),
                "{}: {last:?}",
                s.name()
            );
            let ends = acts
                .iter()
                .filter(|a| matches!(a, Act::Shot | Act::CopyExport(_)))
                .count();
            assert_eq!(ends, 1, "{}", s.name());
        }
        assert_eq!(listing().lines().count(), Scenario::ALL.len());
        assert!(listing().contains("results screenshot-results.png\n"));
        assert!(listing().contains("plots-export plots-export.png\n"));
    }

    #[test]
    fn only_a_1366_by_768_picture_is_saved() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("shot.png");
        let small = egui::ColorImage::new([4, 3], vec![egui::Color32::RED; 12]);
        let e = save_png(&small, &out).unwrap_err();
        assert!(e.contains("4×3 pixels, not 1366×768"), "{e}");
        assert!(!out.exists());
        let mut pixels = vec![egui::Color32::from_rgb(10, 20, 30); SIZE[0] * SIZE[1]];
        pixels[SIZE[0] + 2] = egui::Color32::from_rgb(200, 100, 50);
        save_png(&egui::ColorImage::new(SIZE, pixels), &out).unwrap();
        let back = image::open(&out).unwrap().to_rgb8();
        assert_eq!(back.dimensions(), (1366, 768));
        assert_eq!(back.get_pixel(0, 0).0, [10, 20, 30]);
        assert_eq!(back.get_pixel(2, 1).0, [200, 100, 50]);
    }
}
