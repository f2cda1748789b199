//! The screenshot scenarios ([`Scenario`]): for each asset, the acts
//! ([`Act`]) the [`Director`](super::Director) steps through, one a
//! frame, and the input files it opens.

use std::path::PathBuf;
use std::time::Duration;

use egui::{Pos2, pos2};

use crate::app::command::{
    Command, CompensateCommand, ExportKind, FilesCommand, HistoryCommand, ImportCommand,
    MeasureCommand, PlanCommand, RunCommand, Tab, ViewCommand,
};
use crate::app::{AppState, Forms};
use crate::engine::base::session::SensorRange;
use crate::engine::tools::result_view::Tolerance;

use super::ENV;

/// The pause before each picture: scroll animations and tooltips settle.
const SETTLE: Duration = Duration::from_millis(800);

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
    /// The same with the pointer here (off a 3-D scene, which takes the
    /// wheel to zoom).
    ScrollAt(Pos2, f32),
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
    /// The demo's Session view with the 3-D scene: the robot at a
    /// selected pose, its frames, the laser fan, the spheres.
    SceneSession,
    /// A pose-only real set (RobCalibrator's, imported) in the Session
    /// view's 3-D scene: the flange poses as frames.
    ScenePoses,
    /// The example artefact measured: the cloud in the 3-D scene.
    SceneMeasure,
    /// The Plan view's 3-D scene of the default IRB 2400 plan, a pose
    /// picked: the robot there, every pose's flange by station, the
    /// sphere at every station.
    ScenePlan,
    /// The Compensate view's 3-D scene: `examples/path.mod` through the
    /// seed-7 cell, every target as written and as compensated.
    SceneCompensate,
    /// A fixed-sensor cell (`fixed.json`: `spherecal simulate --mount
    /// fixed --seed 4`) calibrated: the Session view's scene with the
    /// tracker in the base frame, the targets on the flange, the line of
    /// sight.
    SceneFixed,
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
    /// The demo calibrated, a check planned for it and the demo's own
    /// session checked against it: the Re-check view.
    Check,
}

impl Scenario {
    /// Every scenario, in the order the script takes them.
    pub const ALL: [Self; 30] = [
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
        Self::SceneSession,
        Self::ScenePoses,
        Self::SceneMeasure,
        Self::ScenePlan,
        Self::SceneCompensate,
        Self::SceneFixed,
        Self::Check,
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
            Self::SceneSession => "scene-session",
            Self::ScenePoses => "scene-poses",
            Self::SceneMeasure => "scene-measure",
            Self::ScenePlan => "scene-plan",
            Self::SceneCompensate => "scene-compensate",
            Self::SceneFixed => "scene-fixed",
            Self::PlotsExport => "plots-export",
            Self::Check => "check",
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
            Self::Check => check(),
            Self::SceneSession => vec![
                Act::Settle,
                dismiss(),
                show(Tab::Session),
                Act::Find(|s| measurement(s, "c13").map(|i| Command::View(ViewCommand::Select(i)))),
            ],
            Self::ScenePoses => [realdata_stripe(), vec![show(Tab::Session)]].concat(),
            Self::SceneMeasure => [measure(), vec![Act::Scroll(-330.0)]].concat(),
            Self::ScenePlan => vec![
                Act::Settle,
                dismiss(),
                show(Tab::Plan),
                Act::Do(Command::Plan(PlanCommand::Make)),
                Act::Settle,
                Act::Expect(planned),
                Act::Edit(|f| f.scene.plan_pose = Some(40)),
                Act::ScrollAt(pos2(1000.0, 78.0), -330.0),
            ],
            Self::SceneCompensate => compensate(),
            Self::SceneFixed => [
                open_run("fixed.json"),
                vec![
                    show(Tab::Session),
                    Act::Find(|s| {
                        measurement(s, "p12-SMR1").map(|i| Command::View(ViewCommand::Select(i)))
                    }),
                ],
            ]
            .concat(),
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
            Self::Compensate | Self::SceneCompensate => &["seed7.json", "examples/path.mod"],
            Self::SceneFixed => &["fixed.json"],
            Self::Measure | Self::SceneMeasure => &["seed7.json", "examples/artefact/joints.csv"],
            Self::ScenePoses => &["data/robcalibrator-sphere/RobPoses.rob"],
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
            f.plan.request.design.sphere = crate::app::plan::form::default_sphere("ur5e");
        }),
        Act::Pause(Duration::from_millis(300)),
        Act::Expect(|s, _| {
            s.ledger
                .stale(crate::app::ledger::Artefact::Plan)
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
            f.import.log_kind = crate::app::import::form::LogKind::FlangePoses;
            f.import.poses = format!("{dir}/RobPoses.rob").into();
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

/// The demo calibrated, its check planned, the demo's session checked.
fn check() -> Vec<Act> {
    use crate::app::command::CheckCommand;
    [
        demo_run(),
        vec![
            show(Tab::Check),
            Act::Do(Command::Check(CheckCommand::Plan)),
            Act::Settle,
            Act::Edit(|f| f.check.session = "sessions/demo-irb2400.json".into()),
            Act::Do(Command::Check(CheckCommand::Run)),
            Act::Settle,
            Act::Expect(|s, _| match &s.check.outcome {
                Some(Ok(_)) => Ok(()),
                Some(Err(e)) => Err(format!("not checked: {e}")),
                None => Err("not checked".into()),
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
                use crate::app::measure::{RawLog, ScanChoice};
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
