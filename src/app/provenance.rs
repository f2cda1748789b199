//! Where everything derived came from, so that nothing out of date is
//! shown or written as if it were current: the one staleness mechanism
//! of the workbench.
//!
//! **Inputs.** [`Input`] lists what the operator can change that derived
//! things depend on: the session, the measurements left out, the solver
//! settings, the Plan form, the acceptance tolerance. Each frame the
//! workbench reads every input into a [`Reading`] (a fingerprint and the
//! fields people read, e.g. `robot: irb2400`) and hands them to
//! [`Provenance::observe`].
//!
//! **Outputs.** Everything derived ([`Output`]: the plan, the result, the
//! report) is [`recorded`](Provenance::record) with a [`Stamp`]: the
//! readings of the inputs it was made from, taken when its job started
//! (an input changed while the job ran makes it stale on arrival). It is
//! stale as soon as one of those inputs reads otherwise, and
//! [`Provenance::stale`] says which and how (`robot irb2400 → ur5e`);
//! changing the input back makes it current again. The step bar marks a
//! stale step `!` with that text, each view shows it over the stale
//! output, and every export of a stale output is refused with it
//! ([`Provenance::check`]). A file written from an output keeps the
//! output's stamp ([`Written`]), so it too is known stale later.
//!
//! **Adding an output** (a Measure step's point clouds, a Compensate
//! view's programs): add its inputs to [`Input`] if they are new (a
//! variant, its [`Input::name`], and its reading in
//! `AppState::readings`), add a variant to [`Output`] with its
//! [`Output::inputs`] and [`Output::name`]; take
//! [`Provenance::stamp`]`(Output::X)` when its job starts, call
//! [`Provenance::record`] with that stamp when it arrives and
//! [`Provenance::forget`] when it is cleared; before writing any of its
//! files call [`Provenance::check`] and refuse with the error's text;
//! show [`Provenance::stale`] where the output is on show. Nothing else
//! is needed: no flag per view.

use std::collections::BTreeMap;
use std::fmt;
use std::hash::{DefaultHasher, Hash, Hasher};
use std::path::PathBuf;

/// What derived outputs depend on and the operator can change.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Input {
    /// The open session: which one, and its edits (the measuring range).
    Session,
    /// The measurements left out of the run.
    LeftOut,
    /// The solver settings of the next run.
    Solver,
    /// The Plan form (robot, sphere, counts, cut angle, seed, range,
    /// hand-eye guess).
    PlanForm,
    /// The acceptance tolerance of the verdict.
    Tolerance,
    /// The calibration result on show (a new run, a result opened, or
    /// none).
    Calibration,
    /// The Compensate view's targets file (its path, size and time) and
    /// options (pose convention, TCP).
    Targets,
    /// The Measure form: the scan, `use`, frame, sensor noise, σ or not.
    MeasureForm,
}

impl Input {
    /// Every input, in the order of the job.
    pub const ALL: [Self; 8] = [
        Self::PlanForm,
        Self::Session,
        Self::LeftOut,
        Self::Solver,
        Self::Tolerance,
        Self::Calibration,
        Self::Targets,
        Self::MeasureForm,
    ];

    /// Its name in a sentence: "the Plan form changed".
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Session => "the session",
            Self::LeftOut => "the left-out measurements",
            Self::Solver => "the solver settings",
            Self::PlanForm => "the Plan form",
            Self::Tolerance => "the tolerance",
            Self::Calibration => "the calibration result",
            Self::Targets => "the targets",
            Self::MeasureForm => "the Measure form",
        }
    }
}

/// What one input reads now: the fields people read and a fingerprint of
/// everything it holds (fields and what they do not show).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Reading {
    /// `(field, value)` in words, e.g. `("robot", "irb2400")`.
    pub fields: Vec<(String, String)>,
    /// Equal fingerprints: the same input.
    pub fingerprint: u64,
}

impl Reading {
    /// A reading of these fields, fingerprinted with `hidden` (what the
    /// input holds besides them, e.g. a whole request's `Debug` text or
    /// which load of a session this is).
    #[must_use]
    pub fn new(fields: Vec<(String, String)>, hidden: impl Hash) -> Self {
        let mut h = DefaultHasher::new();
        fields.hash(&mut h);
        hidden.hash(&mut h);
        Self {
            fingerprint: h.finish(),
            fields,
        }
    }

    /// What changed from `was` to `self`, in words: each field that
    /// differs as `field old → new`, or "changed" when only what the
    /// fields do not show did.
    #[must_use]
    pub fn changes_from(&self, was: &Self) -> String {
        let mut parts = Vec::new();
        for (name, now) in &self.fields {
            let before = was.fields.iter().find(|(n, _)| n == name).map(|(_, v)| v);
            match before {
                Some(b) if b == now => {}
                Some(b) => parts.push(format!("{name} {b} → {now}")),
                None => parts.push(format!("{name} now {now}")),
            }
        }
        if parts.is_empty() {
            "changed".to_string()
        } else {
            parts.join(", ")
        }
    }
}

/// Everything the workbench derives from the inputs and may show or
/// write out of date.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Output {
    /// The pose plan of the Plan view (and its program and CSV).
    Plan,
    /// The result on show (and the verdict, the views and its exports).
    Result,
    /// The HTML report written of the result on show.
    Report,
    /// The Compensate view's compensated targets (and the program
    /// written of them).
    Compensation,
    /// The Measure view's point cloud (and its PLY, E57, CSV files).
    Cloud,
}

impl Output {
    /// The inputs it is made from.
    #[must_use]
    pub fn inputs(self) -> &'static [Input] {
        match self {
            Self::Plan => &[Input::PlanForm],
            Self::Result => &[Input::Session, Input::LeftOut, Input::Solver],
            Self::Report => &[
                Input::Session,
                Input::LeftOut,
                Input::Solver,
                Input::Tolerance,
            ],
            Self::Compensation => &[
                Input::Session,
                Input::LeftOut,
                Input::Solver,
                Input::Calibration,
                Input::Targets,
            ],
            Self::Cloud => &[Input::Session, Input::Calibration, Input::MeasureForm],
        }
    }

    /// Its name in a sentence: "the plan is stale".
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Plan => "the plan",
            Self::Result => "the result",
            Self::Report => "the report",
            Self::Compensation => "the compensation",
            Self::Cloud => "the cloud",
        }
    }
}

/// The readings of the inputs an output was made from.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Stamp {
    /// Input by input.
    pub made_from: BTreeMap<Input, Reading>,
}

impl Stamp {
    /// The same stamp with `input` read as `reading` too (a report: the
    /// result's stamp and the tolerance it was written with).
    #[must_use]
    pub fn with(mut self, input: Input, reading: Reading) -> Self {
        self.made_from.insert(input, reading);
        self
    }

    /// The same stamp without `input` (a reviewed result was not made
    /// with this window's solver settings).
    #[must_use]
    pub fn without(mut self, input: Input) -> Self {
        self.made_from.remove(&input);
        self
    }
}

/// Why an output is out of date: each input that reads otherwise now.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Stale {
    /// The output.
    pub output: Output,
    /// Each changed input and what changed, in words.
    pub changes: Vec<(Input, String)>,
}

impl Stale {
    /// The changes alone: "the Plan form changed (robot irb2400 → ur5e)".
    #[must_use]
    pub fn what_changed(&self) -> String {
        self.changes
            .iter()
            .map(|(input, how)| format!("{} changed ({how})", input.name()))
            .collect::<Vec<_>>()
            .join("; ")
    }
}

impl fmt::Display for Stale {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} is stale: {} since it was made",
            self.output.name(),
            self.what_changed()
        )
    }
}

/// A file written from an output, with the output's stamp.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Written {
    /// What it is, e.g. "Report HTML", "URScript program".
    pub what: String,
    /// Where.
    pub path: PathBuf,
    /// The output it was written from.
    pub from: Output,
    /// The inputs of that output when it was written.
    pub stamp: Stamp,
}

/// The inputs as they read now, and every output's stamp.
#[derive(Debug, Clone, Default)]
pub struct Provenance {
    now: BTreeMap<Input, Reading>,
    made: BTreeMap<Output, Stamp>,
    /// Files written, newest last.
    pub written: Vec<Written>,
}

/// Most files remembered in [`Provenance::written`].
pub const WRITTEN_MAX: usize = 50;

impl Provenance {
    /// Takes the inputs as they read now.
    pub fn observe(&mut self, readings: impl IntoIterator<Item = (Input, Reading)>) {
        for (input, reading) in readings {
            self.now.insert(input, reading);
        }
    }

    /// What `input` reads now (empty before the first observation).
    #[must_use]
    pub fn reading(&self, input: Input) -> Reading {
        self.now.get(&input).cloned().unwrap_or_default()
    }

    /// The readings now of the inputs `output` is made from: what a job
    /// making it takes when it starts.
    #[must_use]
    pub fn stamp(&self, output: Output) -> Stamp {
        Stamp {
            made_from: output
                .inputs()
                .iter()
                .map(|&i| (i, self.reading(i)))
                .collect(),
        }
    }

    /// `output` was made from the inputs of `stamp`.
    pub fn record(&mut self, output: Output, stamp: Stamp) {
        self.made.insert(output, stamp);
    }

    /// `output` is gone (cleared, or a new session opened).
    pub fn forget(&mut self, output: Output) {
        self.made.remove(&output);
    }

    /// The stamp `output` was recorded with, if it is there.
    #[must_use]
    pub fn made(&self, output: Output) -> Option<&Stamp> {
        self.made.get(&output)
    }

    /// Whether the inputs of `stamp` read otherwise now, and how.
    #[must_use]
    pub fn compare(&self, output: Output, stamp: &Stamp) -> Option<Stale> {
        let changes: Vec<(Input, String)> = stamp
            .made_from
            .iter()
            .filter_map(|(&input, was)| {
                let now = self.reading(input);
                (now.fingerprint != was.fingerprint).then(|| (input, now.changes_from(was)))
            })
            .collect();
        (!changes.is_empty()).then_some(Stale { output, changes })
    }

    /// Why `output` is stale, or `None` when it is current or not made.
    #[must_use]
    pub fn stale(&self, output: Output) -> Option<Stale> {
        self.made
            .get(&output)
            .and_then(|stamp| self.compare(output, stamp))
    }

    /// `Ok` when `output` may be written or used: made and current.
    ///
    /// # Errors
    /// The output is stale (why, in words), or was never made.
    pub fn check(&self, output: Output) -> Result<(), String> {
        if !self.made.contains_key(&output) {
            return Err(format!("{} has not been made", output.name()));
        }
        match self.stale(output) {
            Some(s) => Err(s.to_string()),
            None => Ok(()),
        }
    }

    /// Remembers a file written from `from`, whose inputs were `stamp`
    /// when its job started.
    pub fn wrote(&mut self, what: impl Into<String>, path: PathBuf, from: Output, stamp: Stamp) {
        self.written.push(Written {
            what: what.into(),
            path,
            from,
            stamp,
        });
        if self.written.len() > WRITTEN_MAX {
            self.written.remove(0);
        }
    }

    /// Whether the inputs of a written file read otherwise now.
    #[must_use]
    pub fn written_stale(&self, w: &Written) -> Option<Stale> {
        self.compare(w.from, &w.stamp)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn robot(key: &str) -> Reading {
        Reading::new(vec![("robot".into(), key.into())], 0)
    }

    /// The defect: a plan made for the IRB 2400 stayed on show
    /// unmarked after the robot changed. Stale at once, with how; current
    /// again when the robot is changed back.
    #[test]
    fn a_plan_is_stale_when_its_form_changes_and_current_when_it_changes_back() {
        let mut p = Provenance::default();
        p.observe([(Input::PlanForm, robot("irb2400"))]);
        assert!(p.check(Output::Plan).is_err(), "not made yet");
        let stamp = p.stamp(Output::Plan);
        p.record(Output::Plan, stamp);
        assert!(p.stale(Output::Plan).is_none());
        assert!(p.check(Output::Plan).is_ok());
        p.observe([(Input::PlanForm, robot("ur5e"))]);
        let stale = p.stale(Output::Plan).expect("stale");
        assert_eq!(
            stale.to_string(),
            "the plan is stale: the Plan form changed (robot irb2400 → ur5e) since it was made"
        );
        assert!(
            p.check(Output::Plan)
                .unwrap_err()
                .contains("irb2400 → ur5e")
        );
        // Inputs it does not depend on change nothing.
        p.observe([(Input::Tolerance, robot("x"))]);
        p.observe([(Input::PlanForm, robot("irb2400"))]);
        assert!(p.stale(Output::Plan).is_none());
    }

    /// A job stamps its inputs when it starts: a change during the job
    /// makes its output stale on arrival.
    #[test]
    fn a_change_during_the_job_makes_its_output_stale_on_arrival() {
        let mut p = Provenance::default();
        let left = |n: usize| Reading::new(vec![("left out".into(), n.to_string())], n);
        p.observe([(Input::LeftOut, left(0)), (Input::Session, robot("s"))]);
        let stamp = p.stamp(Output::Result);
        p.observe([(Input::LeftOut, left(1))]);
        p.record(Output::Result, stamp);
        let stale = p.stale(Output::Result).expect("stale");
        assert_eq!(stale.changes.len(), 1);
        assert_eq!(stale.changes[0].0, Input::LeftOut);
        assert_eq!(stale.changes[0].1, "left out 0 → 1");
        let made = p.made(Output::Result).cloned().expect("recorded");
        p.wrote("Result JSON", PathBuf::from("r.json"), Output::Result, made);
        assert!(p.written_stale(&p.written[0]).is_some());
        p.forget(Output::Result);
        assert!(p.stale(Output::Result).is_none());
    }

    /// A change the fields do not show is still a change.
    #[test]
    fn a_hidden_change_is_named_by_its_input() {
        let was = Reading::new(vec![("session".into(), "demo".into())], 1);
        let now = Reading::new(vec![("session".into(), "demo".into())], 2);
        assert_ne!(was.fingerprint, now.fingerprint);
        assert_eq!(now.changes_from(&was), "changed");
    }
}
