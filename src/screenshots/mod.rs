//! The screenshots of the guide and the README (`assets/*.png`), taken by
//! the real window of the workbench driving itself through a scenario:
//!
//! ```text
//! SPHERECAL_SCREENSHOT=<scenario>:<out.png> spherecal gui   # one picture, then the window closes
//! SPHERECAL_SCREENSHOT=list spherecal gui                   # every scenario and its asset file
//! ```
//!
//! A developer's tool beside the workbench (not part of it): it drives
//! [`crate::app`] from outside, as a [`Driver`].
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

mod scenarios;

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use egui::{Pos2, pos2};

use crate::app::workbench::Driver;
use crate::app::{Core, WorkbenchApp, state::Prefs};
pub use scenarios::{Act, Scenario};

/// The environment variable that asks for a screenshot.
pub const ENV: &str = "SPHERECAL_SCREENSHOT";

/// The size of every picture, pixels: the window's inner size at a
/// display scale of 1 (the operator's screen the workbench is laid out
/// for).
pub const SIZE: [usize; 2] = [1366, 768];

/// Longest a scenario may take, from the first frame to the picture (the
/// 3,011-station calibration takes about 10 s in a debug build).
pub const TIMEOUT: Duration = Duration::from_mins(5);

/// Frame period while a scenario runs (frames are asked for; no input
/// comes under Xvfb).
const FRAME: Duration = Duration::from_millis(20);

/// Where the pointer rests over the central view to turn the wheel.
const CENTRE: Pos2 = pos2(830.0, 450.0);

/// How long the pointer stays over the central view after a turn of the
/// wheel (egui scrolls smoothly over a few frames).
const SCROLLING: Duration = Duration::from_millis(700);

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
    /// Jobs started when the job table was last seen idle: a wait ends
    /// when a whole frame passes idle with none started.
    idle_at: Option<u64>,
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
            idle_at: None,
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
    fn raw_input_of(&mut self, raw: &mut egui::RawInput) {
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
    fn frame_of(&mut self, ctx: &egui::Context, core: &mut Core) {
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
                let jobs = &core.state.jobs;
                let started = (!jobs.is_busy()).then(|| jobs.started());
                if started.is_some() && started == self.idle_at {
                    self.advance();
                } else {
                    self.idle_at = started;
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
            Act::Scroll(dy) | Act::ScrollAt(_, dy) => {
                if first {
                    self.pointer = Some(match act {
                        Act::ScrollAt(at, _) => at,
                        _ => CENTRE,
                    });
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
        self.idle_at = None;
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
impl Driver for Director {
    fn raw_input(&mut self, raw: &mut egui::RawInput) {
        self.raw_input_of(raw);
    }

    fn frame(&mut self, ctx: &egui::Context, core: &mut Core) {
        self.frame_of(ctx, core);
    }
}

/// Does what [`ENV`] asks: prints the scenarios, or opens the workbench on
/// `session` (and `result`) with default preferences, none stored, drives
/// it through the scenario, saves its picture and says where.
///
/// # Errors
/// An input missing, the window not opened, or the scenario failed
/// (why, in words).
pub fn run(
    request: Request,
    session: Option<PathBuf>,
    result: Option<PathBuf>,
) -> Result<(), String> {
    let spec = match request {
        Request::List => {
            print!("{}", listing());
            return Ok(());
        }
        Request::Take(spec) => spec,
    };
    let mut options = crate::app::native_options();
    let director = Director::new(spec, &mut options);
    director.check_inputs()?;
    let outcome = director.outcome();
    let opened = eframe::run_native(
        "spherecal",
        options,
        Box::new(move |_| {
            let app = WorkbenchApp::new(Prefs::default(), session, result);
            Ok(Box::new(app.with_driver(director)))
        }),
    )
    .map_err(|e| format!("could not open the workbench window ({e})"));
    remove_storage();
    opened?;
    println!("{}", outcome.result()?);
    Ok(())
}

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
