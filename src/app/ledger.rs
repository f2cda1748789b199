//! The artefact ledger: what every artefact of the workbench was made
//! from, so that nothing out of date is shown or written as if it were
//! current. One mechanism for every artefact; no view keeps a flag.
//!
//! **Inputs.** [`Input`] lists what the operator can change: the session,
//! the measurements left out, the solver settings, the forms, the
//! tolerance, the result on show. Each frame the workbench reads every
//! input into a [`Reading`] (the fields people read and a fingerprint of
//! all of it) and hands them to [`Ledger::observe`].
//!
//! **Artefacts.** Everything made ([`Artefact`]) is
//! [`recorded`](Ledger::record) with a [`Stamp`]: the readings of the
//! inputs it was made from, taken by [`Ledger::stamp`] when its job
//! started. An artefact made from another (a cloud, a compensation or a
//! report from the result) starts from that one's stamp, so that by
//! construction whatever makes the result stale makes them stale too. It
//! is stale as soon as one of its readings differs, and
//! [`Ledger::stale`] says which and how (`robot irb2400 → ur5e`);
//! changing the input back makes it current again.
//!
//! **Files.** Every file written of an artefact is refused while it is
//! stale ([`Ledger::check`]) and remembered with its stamp
//! ([`Written`]); a file that exists and was not written by this window
//! from the same artefact and inputs is replaced only when the operator
//! says so ([`Ledger::may_write`], [`Ledger::allow`]).

use std::collections::BTreeMap;
use std::fmt;
use std::hash::{DefaultHasher, Hash, Hasher};
use std::path::{Path, PathBuf};

use crate::engine::files::format::same_file;

/// What artefacts depend on and the operator can change.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Input {
    /// The Plan form (robot, sphere, counts, cut angle, seed, range,
    /// hand-eye guess).
    PlanForm,
    /// The open session: which one, and its edits (the measuring range).
    Session,
    /// The measurements left out of the run.
    LeftOut,
    /// The solver settings of the next run.
    Solver,
    /// The acceptance tolerance of the verdict.
    Tolerance,
    /// The calibration result on show (a new run, a result opened, or
    /// none).
    Calibration,
    /// The Compensate view's targets file (its path, size and time) and
    /// options (pose convention, TCP, limits).
    Targets,
    /// The Measure form: the scan, `use`, frame, sensor noise, σ or not.
    MeasureForm,
    /// The import wizard's form.
    ImportForm,
    /// What the pose file's preview reads of the import form.
    PoseFile,
    /// The History view's library (which scan of which folder).
    Library,
    /// The History view's choice: the robot, the ticked results, `k`.
    HistoryChoice,
    /// The Re-check view's sphere position (its plan of check poses).
    CheckForm,
    /// The Re-check view's check session (its path, size and time) and α.
    CheckSession,
}

impl Input {
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
            Self::ImportForm => "the import form",
            Self::PoseFile => "the pose file",
            Self::Library => "the library",
            Self::HistoryChoice => "the robot or the ticked results",
            Self::CheckForm => "the check's sphere position",
            Self::CheckSession => "the check session",
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
    /// input holds besides them, e.g. a whole request's `Debug` text).
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
    /// differs as `field old → new`, or when only what the fields do not
    /// show did (an edited file under the same name), the first field and
    /// "contents changed".
    #[must_use]
    pub fn changes_from(&self, was: &Self) -> String {
        let mut parts = Vec::new();
        for (name, now) in &self.fields {
            match was.fields.iter().find(|(n, _)| n == name).map(|(_, v)| v) {
                Some(b) if b == now => {}
                Some(b) => parts.push(format!("{name} {b} → {now}")),
                None => parts.push(format!("{name} now {now}")),
            }
        }
        if parts.is_empty() {
            match self.fields.first() {
                Some((name, now)) => format!("{name} {now}: contents changed"),
                None => "contents changed".to_string(),
            }
        } else {
            parts.join(", ")
        }
    }
}

/// What happens to an artefact when it goes stale.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WhenStale {
    /// It stays on show, marked STALE; its files are refused.
    Mark,
    /// It is cleared (a preview of a form that was edited).
    Clear,
    /// It is made again at once (a cheap preview, the drift).
    Redo,
}

/// Everything the workbench makes from the inputs and may show or write
/// out of date.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Artefact {
    /// The pose plan (and its program and CSV).
    Plan,
    /// The result on show (its verdict, views, exports: JSON, CSV,
    /// plots, model).
    Result,
    /// The HTML report of the result on show.
    Report,
    /// The compensated targets (and the program written of them).
    Compensation,
    /// The Measure view's point cloud (and its PLY, E57, CSV files).
    Cloud,
    /// The open session without the left-out measurements (Save as).
    EditedSession,
    /// The import wizard's preview, outcome and flange checks.
    ImportView,
    /// The pose file read and paired before the import.
    PoseScan,
    /// The drift of the chosen robot over the ticked results.
    Drift,
    /// The check poses planned for the result on show (and their program).
    CheckPlan,
    /// The re-check's verdict on the result on show (and its record).
    Check,
}

impl Artefact {
    /// Every artefact.
    pub const ALL: [Self; 11] = [
        Self::Plan,
        Self::Result,
        Self::Report,
        Self::Compensation,
        Self::Cloud,
        Self::EditedSession,
        Self::ImportView,
        Self::PoseScan,
        Self::Drift,
        Self::CheckPlan,
        Self::Check,
    ];

    /// The artefact it is made from, whose stamp it starts from.
    #[must_use]
    pub fn upstream(self) -> Option<Self> {
        match self {
            Self::Report | Self::Compensation | Self::Cloud | Self::CheckPlan | Self::Check => {
                Some(Self::Result)
            }
            _ => None,
        }
    }

    /// The inputs it reads itself (besides its upstream's).
    #[must_use]
    pub fn inputs(self) -> &'static [Input] {
        match self {
            Self::Plan => &[Input::PlanForm],
            Self::Result => &[Input::Session, Input::LeftOut, Input::Solver],
            Self::Report => &[Input::Calibration, Input::Tolerance],
            Self::Compensation => &[Input::Calibration, Input::Targets],
            Self::Cloud => &[Input::Calibration, Input::MeasureForm],
            Self::EditedSession => &[Input::Session, Input::LeftOut],
            Self::ImportView => &[Input::ImportForm],
            Self::PoseScan => &[Input::PoseFile],
            Self::Drift => &[Input::Library, Input::HistoryChoice],
            Self::CheckPlan => &[Input::Calibration, Input::PlanForm, Input::CheckForm],
            Self::Check => &[Input::Calibration, Input::CheckSession],
        }
    }

    /// What happens to it when it goes stale.
    #[must_use]
    pub fn when_stale(self) -> WhenStale {
        match self {
            Self::ImportView => WhenStale::Clear,
            Self::PoseScan | Self::Drift => WhenStale::Redo,
            _ => WhenStale::Mark,
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
            Self::EditedSession => "the edited session",
            Self::ImportView => "the import preview",
            Self::PoseScan => "the pose file's preview",
            Self::Drift => "the drift",
            Self::CheckPlan => "the check's plan",
            Self::Check => "the check's verdict",
        }
    }
}

/// The readings of the inputs an artefact was made from.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Stamp {
    /// Input by input.
    pub made_from: BTreeMap<Input, Reading>,
}

impl Stamp {
    /// The same stamp without `input` (a reviewed result was not made
    /// with this window's solver settings).
    #[must_use]
    pub fn without(mut self, input: Input) -> Self {
        self.made_from.remove(&input);
        self
    }
}

/// Why an artefact is out of date: each input that reads otherwise now.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Stale {
    /// The artefact.
    pub artefact: Artefact,
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
            self.artefact.name(),
            self.what_changed()
        )
    }
}

/// A file written of an artefact, with the artefact's stamp.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Written {
    /// What it is, e.g. "Report HTML", "URScript program".
    pub what: String,
    /// Where.
    pub path: PathBuf,
    /// The artefact it was written of.
    pub from: Artefact,
    /// The inputs of that artefact when it was written.
    pub stamp: Stamp,
}

/// An artefact as made: its stamp and what it is, in words.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Made {
    /// The readings it was made from.
    pub stamp: Stamp,
    /// What it is, for the step bar ("method ml", "1,234 points of …").
    pub what: String,
}

/// The inputs as they read now, every artefact's stamp, the files written.
#[derive(Debug, Clone, Default)]
pub struct Ledger {
    now: BTreeMap<Input, Reading>,
    made: BTreeMap<Artefact, Made>,
    /// Files written, newest last.
    pub written: Vec<Written>,
    /// A file the operator agreed to replace (the next write to it
    /// goes ahead).
    allowed: Option<PathBuf>,
}

/// Most files remembered in [`Ledger::written`].
pub const WRITTEN_MAX: usize = 50;

impl Ledger {
    /// Takes the inputs as they read now.
    pub fn observe(&mut self, readings: impl IntoIterator<Item = (Input, Reading)>) {
        self.now.extend(readings);
    }

    /// What `input` reads now (empty before the first observation).
    #[must_use]
    pub fn reading(&self, input: Input) -> Reading {
        self.now.get(&input).cloned().unwrap_or_default()
    }

    /// What a job making `artefact` starts from: its upstream's stamp as
    /// recorded, and its own inputs as they read now.
    #[must_use]
    pub fn stamp(&self, artefact: Artefact) -> Stamp {
        let mut stamp = artefact
            .upstream()
            .and_then(|u| self.made.get(&u))
            .map(|m| m.stamp.clone())
            .unwrap_or_default();
        for &i in artefact.inputs() {
            stamp.made_from.insert(i, self.reading(i));
        }
        stamp
    }

    /// `artefact` was made from the inputs of `stamp`; `what` says what
    /// it is.
    pub fn record(&mut self, artefact: Artefact, stamp: Stamp, what: impl Into<String>) {
        let what = what.into();
        self.made.insert(artefact, Made { stamp, what });
    }

    /// `artefact` is gone (cleared, or a new session opened).
    pub fn forget(&mut self, artefact: Artefact) {
        self.made.remove(&artefact);
    }

    /// `artefact` as recorded, if it is there.
    #[must_use]
    pub fn made(&self, artefact: Artefact) -> Option<&Made> {
        self.made.get(&artefact)
    }

    /// Whether the inputs of `stamp` read otherwise now, and how.
    #[must_use]
    pub fn compare(&self, artefact: Artefact, stamp: &Stamp) -> Option<Stale> {
        let changes: Vec<(Input, String)> = stamp
            .made_from
            .iter()
            .filter_map(|(&input, was)| {
                let now = self.reading(input);
                (now.fingerprint != was.fingerprint).then(|| (input, now.changes_from(was)))
            })
            .collect();
        (!changes.is_empty()).then_some(Stale { artefact, changes })
    }

    /// Why `artefact` is stale, or `None` when it is current or not made.
    #[must_use]
    pub fn stale(&self, artefact: Artefact) -> Option<Stale> {
        self.made
            .get(&artefact)
            .and_then(|m| self.compare(artefact, &m.stamp))
    }

    /// The stamp of `artefact` when it may be written or used: made and
    /// current.
    ///
    /// # Errors
    /// It is stale (why, in words), or was never made.
    pub fn check(&self, artefact: Artefact) -> Result<Stamp, String> {
        let Some(m) = self.made.get(&artefact) else {
            return Err(format!("{} has not been made", artefact.name()));
        };
        match self.compare(artefact, &m.stamp) {
            Some(s) => Err(s.to_string()),
            None => Ok(m.stamp.clone()),
        }
    }

    /// Whether `path` may be written of `from` made from `stamp` without
    /// asking: it does not exist, the operator agreed, or this window
    /// wrote it last of the same artefact from the same inputs.
    ///
    /// # Errors
    /// Why to ask first, in words.
    pub fn may_write(&mut self, path: &Path, from: Artefact, stamp: &Stamp) -> Result<(), String> {
        if !path.exists() || self.allowed.take_if(|p| p.as_path() == path).is_some() {
            return Ok(());
        }
        match self.written.iter().rev().find(|w| same_file(&w.path, path)) {
            None => Err(format!(
                "{} exists and was not written by this window",
                path.display()
            )),
            Some(w) if w.from == from && &w.stamp == stamp => Ok(()),
            Some(w) => Err(format!(
                "{} exists: this window wrote it of {}{}",
                path.display(),
                w.from.name(),
                self.compare(w.from, &w.stamp).map_or_else(
                    || " made from other inputs".to_string(),
                    |s| format!(" before {}", s.what_changed())
                )
            )),
        }
    }

    /// The operator agreed to replace `path`: its next write goes ahead.
    pub fn allow(&mut self, path: PathBuf) {
        self.allowed = Some(path);
    }

    /// Remembers a file written of `from`, whose stamp was `stamp`.
    pub fn wrote(&mut self, what: impl Into<String>, path: PathBuf, from: Artefact, stamp: Stamp) {
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

    /// Forgets the files written of artefacts made from `input` (a new
    /// session: what was written of the last one is not of this one).
    pub fn forget_written_of(&mut self, input: Input) {
        self.written
            .retain(|w| !w.stamp.made_from.contains_key(&input));
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

    /// A plan made for the IRB 2400 stayed on show unmarked after the
    /// robot changed. Stale at once, with how; current again when the
    /// robot is changed back.
    #[test]
    fn a_plan_is_stale_when_its_form_changes_and_current_when_it_changes_back() {
        let mut p = Ledger::default();
        p.observe([(Input::PlanForm, robot("irb2400"))]);
        assert!(p.check(Artefact::Plan).is_err(), "not made yet");
        let stamp = p.stamp(Artefact::Plan);
        p.record(Artefact::Plan, stamp, "a plan");
        assert!(p.stale(Artefact::Plan).is_none());
        assert!(p.check(Artefact::Plan).is_ok());
        p.observe([(Input::PlanForm, robot("ur5e"))]);
        let stale = p.stale(Artefact::Plan).expect("stale");
        assert_eq!(
            stale.to_string(),
            "the plan is stale: the Plan form changed (robot irb2400 → ur5e) since it was made"
        );
        assert!(
            p.check(Artefact::Plan)
                .unwrap_err()
                .contains("irb2400 → ur5e")
        );
        p.observe([(Input::Tolerance, robot("x"))]);
        p.observe([(Input::PlanForm, robot("irb2400"))]);
        assert!(p.stale(Artefact::Plan).is_none());
    }

    /// A job stamps its inputs when it starts: a change during the job
    /// makes its artefact stale on arrival.
    #[test]
    fn a_change_during_the_job_makes_its_artefact_stale_on_arrival() {
        let mut p = Ledger::default();
        let left = |n: usize| Reading::new(vec![("left out".into(), n.to_string())], n);
        p.observe([(Input::LeftOut, left(0)), (Input::Session, robot("s"))]);
        let stamp = p.stamp(Artefact::Result);
        p.observe([(Input::LeftOut, left(1))]);
        p.record(Artefact::Result, stamp, "method ml");
        let stale = p.stale(Artefact::Result).expect("stale");
        assert_eq!(stale.changes, [(Input::LeftOut, "left out 0 → 1".into())]);
        let made = p.made(Artefact::Result).cloned().expect("recorded").stamp;
        p.wrote(
            "Result JSON",
            PathBuf::from("r.json"),
            Artefact::Result,
            made,
        );
        assert!(p.written_stale(&p.written[0]).is_some());
        p.forget(Artefact::Result);
        assert!(p.stale(Artefact::Result).is_none());
    }

    /// The operator's defect: a cloud stayed current (and was written)
    /// after a measurement was left out of its result. An artefact made
    /// from the result starts from the result's stamp: whatever makes the
    /// result stale makes it stale too, with the same words.
    #[test]
    fn what_makes_the_result_stale_makes_what_was_made_from_it_stale() {
        let mut p = Ledger::default();
        let left = |n: usize| Reading::new(vec![("left out".into(), n.to_string())], n);
        p.observe([(Input::LeftOut, left(0)), (Input::MeasureForm, robot("m"))]);
        let stamp = p.stamp(Artefact::Result);
        p.record(Artefact::Result, stamp, "method ml");
        let cloud = p.stamp(Artefact::Cloud);
        assert!(cloud.made_from.contains_key(&Input::LeftOut));
        p.record(Artefact::Cloud, cloud, "a cloud");
        assert!(p.check(Artefact::Cloud).is_ok());
        p.observe([(Input::LeftOut, left(1))]);
        let why = p.check(Artefact::Cloud).unwrap_err();
        assert_eq!(
            why,
            "the cloud is stale: the left-out measurements changed (left out 0 → 1) since it was made"
        );
        p.observe([(Input::LeftOut, left(0))]);
        assert!(p.check(Artefact::Cloud).is_ok(), "current again");
    }

    /// A file that exists is replaced without asking only when this
    /// window wrote it last of the same artefact from the same inputs.
    #[test]
    fn a_file_not_written_for_these_inputs_is_replaced_only_when_allowed() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("P-compensated.csv");
        let mut p = Ledger::default();
        p.observe([(Input::Targets, robot("T1"))]);
        let first = p.stamp(Artefact::Compensation);
        assert!(p.may_write(&path, Artefact::Compensation, &first).is_ok());
        std::fs::write(&path, "one").unwrap();
        p.wrote(
            "compensated program",
            path.clone(),
            Artefact::Compensation,
            first.clone(),
        );
        assert!(p.may_write(&path, Artefact::Compensation, &first).is_ok());
        p.observe([(Input::Targets, robot("T2"))]);
        let second = p.stamp(Artefact::Compensation);
        let why = p
            .may_write(&path, Artefact::Compensation, &second)
            .unwrap_err();
        assert!(why.contains("robot T1 → T2"), "{why}");
        p.allow(path.clone());
        assert!(p.may_write(&path, Artefact::Compensation, &second).is_ok());
        assert!(
            p.may_write(&path, Artefact::Compensation, &second).is_err(),
            "once"
        );
        let other = dir.path().join("mine.csv");
        std::fs::write(&other, "theirs").unwrap();
        let why = p
            .may_write(&other, Artefact::Compensation, &second)
            .unwrap_err();
        assert!(why.contains("not written by this window"), "{why}");
    }

    /// A change the fields do not show is still a change.
    #[test]
    fn a_hidden_change_is_named_by_its_input() {
        let was = Reading::new(vec![("session".into(), "demo".into())], 1);
        let now = Reading::new(vec![("session".into(), "demo".into())], 2);
        assert_ne!(was.fingerprint, now.fingerprint);
        assert_eq!(now.changes_from(&was), "session demo: contents changed");
    }
}
