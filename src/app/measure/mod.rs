//! Measuring with the calibrated cell: the Measure form (what is
//! measured: the open session, a session file, or a raw scan's pose log
//! and profiles as `spherecal measure --joints/--poses --profiles` reads
//! them; how: `--use`, a workpiece frame, the sensor's noise, no σ; and
//! where the cloud is written), the measuring job with progress and
//! Cancel ([`job`]), the cloud on show, and its export (PLY, E57 or CSV
//! by the extension), refused while the cloud is stale. The view is
//! [`ui`].

pub mod job;
pub mod scene;
pub mod ui;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::engine::base::robot::kinematics::Robot;
use crate::engine::base::session::Use;
use crate::engine::files::format::refuse_inputs;
use crate::engine::files::import::{
    AngleUnit, AxisMap, FlangeConvention, LengthUnit, ProfileFormat, ProfileSource,
};
use crate::engine::uses::measure::{
    self, CloudFormat, JointRange, MeasureOptions, MeasureRequest, ScanColumns, ScanFiles, ScanLog,
    ScanSource,
};

use super::command::{Command, MeasureCommand};
use super::import::form::no_return;
use super::job::{Job, Slot};
use super::ledger::{Artefact, Reading, Stamp};
use super::results::ResultOrigin;
use super::state::Level;
use super::{Core, Write};
use job::{MeasureFailure, MeasuredCloud, group, has_covariance, measure_cloud};

/// The Measure view's state.
#[derive(Debug, Default)]
pub struct MeasureView {
    /// The cloud on show.
    pub shown: Option<MeasuredCloud>,
    /// The last job's error, until the next job.
    pub failure: Option<String>,
}

/// What is measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScanChoice {
    /// The session open in the workbench: its stripes as they are.
    OpenSession,
    /// A session file: its stripes as they are.
    SessionFile,
    /// A raw scan: a pose log (joint log CSV or pose file) and profiles.
    RawScan,
}

impl ScanChoice {
    /// Every choice, in the order of the radio buttons.
    pub const ALL: [Self; 3] = [Self::OpenSession, Self::SessionFile, Self::RawScan];

    /// The radio button's text.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::OpenSession => "the open session",
            Self::SessionFile => "a session file",
            Self::RawScan => "a raw scan (pose log + profiles)",
        }
    }
}

/// The pose log of a raw scan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RawLog {
    /// A joint log CSV (columns `id`, `j1..jn`, optional `station`, `use`).
    Joints,
    /// A pose file: a table, a JSON list or a robot program (layout
    /// detected); only the hand-eye applies to flange poses.
    Poses,
}

/// The Measure view's fields.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasureForm {
    /// What is measured.
    pub choice: ScanChoice,
    /// Which measurements of a session (`--use`): `None` for all.
    pub usage: Option<Use>,
    /// The session file (for [`ScanChoice::SessionFile`]).
    pub session_file: String,
    /// A raw scan's pose log kind.
    pub raw_log: RawLog,
    /// A raw scan's pose log file.
    pub log: String,
    /// A raw scan's profiles: a folder, or one CSV with a `pose` column.
    pub profiles: String,
    /// Unit of a joint log's joint columns.
    pub joint_unit: AngleUnit,
    /// Unit of the profile coordinates.
    pub profile_unit: LengthUnit,
    /// How a pose table writes a pose; `None`: as the file says (a
    /// robot program fixes its own).
    pub pose_convention: Option<FlangeConvention>,
    /// Axis map of the profiles: `auto` or e.g. `-y,x,z`.
    pub axes: String,
    /// The sensor's no-return value (file units); empty for none.
    pub no_return: String,
    /// A raw scan of a sphere artefact: the spheres' diameter, mm, for
    /// the self-validation of its stations; empty for none.
    pub sphere_diameter: String,
    /// A raw scan of a sphere artefact: reference distances between its
    /// stations (CSV `from,to,distance`, mm); empty for none.
    pub references: String,
    /// A workpiece frame file (a JSON 4×4 `base_from_workpiece`, mm);
    /// empty for the robot base frame.
    pub frame: String,
    /// How it is measured, the engine's options as the request carries
    /// them: σ or not (`--no-sigma`), the sensor's own noise (1σ of each
    /// in-plane coordinate, mm); the calibrated model, the frame from
    /// [`MeasureForm::frame`].
    pub options: MeasureOptions,
    /// Where Export writes the cloud; the extension chooses the format
    /// (`.ply`, `.e57`, `.csv`).
    pub out: String,
}

impl Default for MeasureForm {
    fn default() -> Self {
        Self {
            choice: ScanChoice::OpenSession,
            usage: None,
            session_file: String::new(),
            raw_log: RawLog::Joints,
            log: String::new(),
            profiles: String::new(),
            joint_unit: AngleUnit::Deg,
            profile_unit: LengthUnit::Mm,
            pose_convention: None,
            axes: "auto".into(),
            no_return: String::new(),
            sphere_diameter: String::new(),
            references: String::new(),
            frame: String::new(),
            options: MeasureOptions {
                sigma: true,
                ..MeasureOptions::default()
            },
            out: String::new(),
        }
    }
}

impl MeasureForm {
    /// The uses `--use` names: empty for all.
    #[must_use]
    pub fn uses(&self) -> Vec<Use> {
        self.usage.into_iter().collect()
    }

    /// The workpiece frame file, if one is typed.
    #[must_use]
    pub fn frame_path(&self) -> Option<PathBuf> {
        let f = self.frame.trim();
        (!f.is_empty()).then(|| PathBuf::from(f))
    }

    /// A raw scan's files as `spherecal measure --joints/--poses
    /// --profiles` reads them (default columns `id`, `j1..jn`, `station`,
    /// `use`; layout of a pose file detected), for a robot of `dof`
    /// joints.
    ///
    /// # Errors
    /// A field is missing or not valid, in words.
    pub fn scan_files(&self, dof: usize) -> Result<ScanFiles, String> {
        let path = |text: &str| (!text.trim().is_empty()).then(|| PathBuf::from(text.trim()));
        let log = path(&self.log)
            .ok_or("choose the raw scan's pose log (joint log CSV or pose file) first")?;
        let profiles = path(&self.profiles)
            .ok_or("choose the raw scan's profiles (a folder or one CSV) first")?;
        let profiles = if profiles.is_dir() {
            ProfileSource::Folder(profiles)
        } else {
            let pose_column = "pose".into();
            ProfileSource::File {
                path: profiles,
                pose_column,
            }
        };
        let axes = match self.axes.trim() {
            "" | "auto" => None,
            text => Some(AxisMap::parse(text).map_err(|e| format!("axes: {e}"))?),
        };
        let no_return = no_return(&self.no_return)?;
        let sphere_diameter = match self.sphere_diameter.trim() {
            "" => None,
            text => Some(
                text.parse()
                    .ok()
                    .filter(|v: &f64| v.is_finite() && *v > 0.0)
                    .ok_or_else(|| {
                        format!("the sphere diameter `{text}` is not a positive number of mm")
                    })?,
            ),
        };
        let log = match self.raw_log {
            RawLog::Joints => ScanLog::Joints {
                path: log,
                columns: ScanColumns::new(dof),
                unit: self.joint_unit,
            },
            RawLog::Poses => ScanLog::Poses {
                path: log,
                format: None,
                convention: self.pose_convention,
                columns: None,
            },
        };
        let (unit, key) = (self.profile_unit, None);
        Ok(ScanFiles {
            log,
            profiles,
            profile_format: ProfileFormat {
                unit,
                axes,
                no_return,
                key,
            },
            robot: None,
            sphere_diameter,
            references: path(&self.references),
            uses: self.uses(),
        })
    }
}

impl Core {
    /// Handles a [`MeasureCommand`].
    pub(super) fn measure(&mut self, ctx: &egui::Context, command: MeasureCommand) {
        match command {
            MeasureCommand::Start => self.start_measure(ctx),
            MeasureCommand::Cancel => {
                if let Some(job) = self.state.jobs.cancel(&Slot::Measure) {
                    let (phase, s) = (&job.phase, job.started.elapsed().as_secs_f64());
                    let text = format!(
                        "measuring cancelled in \"{phase}\" ({s:.2} s); the cloud on show is unchanged"
                    );
                    self.state.say(Level::Warning, text);
                }
            }
            MeasureCommand::Export => self.export_cloud(ctx),
        }
    }

    /// The job's request from the form and the result on show, or why
    /// there is none.
    fn measure_request(&self) -> Result<(MeasureRequest, String), String> {
        let Some(view) = &self.state.result else {
            return Err("no result on show: run the calibration or open a result first".into());
        };
        self.state
            .ledger
            .check(Artefact::Result)
            .map_err(|why| format!("{why}: run the calibration again, then measure"))?;
        let form = &self.forms.measure;
        if form.options.sigma && !has_covariance(&view.file) {
            return Err(format!(
                "σ is unavailable: the result (method {}) has no parameter covariance; tick \"no σ\" to measure without it (as --no-sigma), or calibrate with method ml",
                view.file.solver.method()
            ));
        }
        let loaded = self.state.loaded.as_ref();
        let scan = match form.choice {
            ScanChoice::OpenSession => {
                let Some(l) = loaded else {
                    return Err("no session open to measure".into());
                };
                ScanSource::Session(
                    Box::new(l.session.clone()),
                    form.uses(),
                    format!("\"{}\" ({})", l.session.name, l.source.label()),
                )
            }
            ScanChoice::SessionFile => match form.session_file.trim() {
                "" => return Err("type or choose the session file to measure".into()),
                path => ScanSource::SessionFile(PathBuf::from(path), form.uses()),
            },
            ScanChoice::RawScan => {
                let dof = view.file.robot.as_ref().map_or(0, Robot::dof);
                ScanSource::Files(Box::new(form.scan_files(dof)?))
            }
        };
        let result_label = match &view.origin {
            ResultOrigin::Review(p) => p.display().to_string(),
            ResultOrigin::Run { .. } => format!(
                "a workbench run (method {}) of \"{}\"",
                view.method(),
                view.file.session
            ),
        };
        let request = MeasureRequest {
            scan,
            result: view.file.clone(),
            joint_range: loaded.and_then(|l| JointRange::of_session(&l.session)),
            frame: form.frame_path(),
            options: form.options.clone(),
        };
        Ok((request, result_label))
    }

    fn start_measure(&mut self, ctx: &egui::Context) {
        if self.state.jobs.runs(&Slot::Measure) {
            return;
        }
        let (request, result_label) = match self.measure_request() {
            Ok(r) => r,
            Err(why) => {
                self.state.say(Level::Warning, "nothing measured");
                self.state.measure.failure = Some(why);
                return;
            }
        };
        let stamp = self.state.ledger.stamp(Artefact::Cloud);
        if self.start(ctx, Slot::Measure, stamp, move |w| {
            measure_cloud(request, result_label, w.flag(), &mut |phase, fraction| {
                w.progress(phase, Some(fraction))
            })
            .map(Box::new)
        }) {
            self.state.measure.failure = None;
            self.state.say(Level::Info, "measuring the scan…");
        }
    }

    /// Shows the cloud of a measuring job (after the frame's commands: a
    /// job cancelled in the frame it arrived in is not shown).
    pub(super) fn on_measured(
        &mut self,
        job: &Job,
        outcome: Result<Box<MeasuredCloud>, MeasureFailure>,
    ) {
        let m = &mut self.state.measure;
        match outcome {
            Ok(shown) => {
                let (cloud, scan) = (shown.cloud(), &shown.outcome.scan);
                let (points, poses) = (group(cloud.len()), group(cloud.poses.len()));
                let text = format!(
                    "measured {points} points of {poses} poses in {:.2} s (Measure view)",
                    shown.seconds
                );
                let what = format!("{points} points measured of {scan}");
                m.shown = Some(*shown);
                self.state
                    .ledger
                    .record(Artefact::Cloud, job.stamp.clone(), what);
                self.state.say(Level::Info, text);
            }
            Err(MeasureFailure::Cancelled) => self.state.say(
                Level::Warning,
                "measuring cancelled; the cloud on show is unchanged",
            ),
            Err(MeasureFailure::Failed(e)) => {
                m.failure = Some(e.to_string());
                self.refuse("The scan could not be measured", "", e.to_string());
                self.state
                    .say(Level::Error, "the scan could not be measured");
            }
        }
    }

    /// Every input file of the cloud on show and of the form, to refuse
    /// an export over one of them.
    fn measure_inputs(&self) -> Vec<PathBuf> {
        let f = &self.forms.measure;
        let typed = [
            &f.session_file,
            &f.log,
            &f.profiles,
            &f.frame,
            &f.references,
        ];
        let typed = typed
            .into_iter()
            .map(|t| t.trim())
            .filter(|t| !t.is_empty());
        let mut out: Vec<PathBuf> = typed.map(PathBuf::from).collect();
        out.extend(
            self.state
                .loaded
                .as_ref()
                .and_then(|l| l.source.path())
                .map(Path::to_path_buf),
        );
        if let Some(ResultOrigin::Review(p)) = self.state.result.as_ref().map(|v| &v.origin) {
            out.push(p.clone());
        }
        out
    }

    /// Where and in which format the cloud on show is written, or why it
    /// is not; `None` when the export folder is missing (that says so).
    fn cloud_target(&mut self) -> Result<Option<(PathBuf, CloudFormat, Stamp)>, String> {
        if self.state.measure.shown.is_none() {
            return Err("no cloud to write: measure a scan first".into());
        }
        // A stale cloud is never written as if it were current.
        let stamp = (self.state.ledger.check(Artefact::Cloud))
            .map_err(|why| format!("{why}: measure again, then export"))?;
        // An empty field writes the default it shows: the export folder's
        // `<session stem>-cloud.ply`.
        if self.forms.measure.out.trim().is_empty() {
            let Some(dir) = self.export_folder() else {
                return Ok(None);
            };
            self.forms.measure.out = dir.join(self.cloud_file_name()).display().to_string();
        }
        let path = PathBuf::from(self.forms.measure.out.trim());
        let format = CloudFormat::of_path(&path).ok_or_else(|| {
            let path = path.display();
            format!("{path}: the extension chooses the format: .ply, .e57 or .csv")
        })?;
        let inputs = self.measure_inputs();
        let refs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
        refuse_inputs(&path, &refs).map_err(|e| e.to_string())?;
        Ok(Some((path, format, stamp)))
    }

    /// Writes the cloud on show to the form's path, refused when it is
    /// stale or the path is not a cloud file.
    pub(super) fn export_cloud(&mut self, ctx: &egui::Context) {
        let (path, format, stamp) = match self.cloud_target() {
            Ok(Some(target)) => target,
            Ok(None) => return,
            Err(why) => return self.refuse("Cloud not written", "cloud not written", why),
        };
        let Some(shown) = &self.state.measure.shown else {
            return;
        };
        let cloud = Arc::clone(&shown.outcome.measured.cloud);
        let provenance = measure::Provenance {
            result: shown.result.clone(),
            scan: shown.outcome.scan.clone(),
        };
        let what = format!("{} cloud", format!("{format:?}").to_uppercase());
        self.state.say(Level::Info, format!("writing the {what}…"));
        let (from, again) = (Artefact::Cloud, Command::Measure(MeasureCommand::Export));
        let write = Write {
            what,
            from,
            stamp,
            again,
        };
        self.write(ctx, path, write, move |path| {
            measure::write_cloud(&cloud, path, format, &provenance)?;
            Ok(None)
        });
    }

    /// The name the export's save dialog offers: the export field's, else
    /// [`default_cloud_name`].
    pub(super) fn cloud_file_name(&self) -> String {
        Path::new(self.forms.measure.out.trim())
            .file_name()
            .map_or_else(
                || default_cloud_name(&self.state),
                |n| n.to_string_lossy().into_owned(),
            )
    }
}

/// The cloud's default file name: `<session stem>-cloud.ply` (`scan`
/// without a session).
#[must_use]
pub fn default_cloud_name(state: &crate::app::AppState) -> String {
    let stem = state
        .loaded
        .as_ref()
        .map_or_else(|| "scan".to_string(), |l| l.source.stem());
    format!("{stem}-cloud.ply")
}

/// The Measure form: what is measured and how (not where it is
/// exported).
#[must_use]
pub fn reading(f: &MeasureForm) -> Reading {
    let scan = match f.choice {
        ScanChoice::OpenSession => "the open session".to_string(),
        ScanChoice::SessionFile => f.session_file.trim().to_string(),
        ScanChoice::RawScan => format!("{} + {}", f.log.trim(), f.profiles.trim()),
    };
    let frame = f.frame_path();
    let fields = [
        ("scan", scan),
        ("use", f.usage.map_or("all", |u| u.as_str()).to_string()),
        (
            "frame",
            frame.map_or_else(|| "base".to_string(), |p| p.display().to_string()),
        ),
        ("sensor noise", format!("{} mm", f.options.sensor_noise_mm)),
        ("σ", if f.options.sigma { "yes" } else { "no" }.to_string()),
    ];
    let mut unseen = f.clone();
    unseen.out.clear();
    let fields = fields.map(|(k, v)| (k.to_string(), v));
    Reading::new(fields.into(), format!("{unseen:?}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The form builds the command's spec: default columns for the
    /// robot's joints, a folder or a file of profiles, the axis map.
    #[test]
    fn a_raw_scan_form_builds_the_commands_spec() {
        let mut f = MeasureForm {
            choice: ScanChoice::RawScan,
            ..MeasureForm::default()
        };
        assert!(f.scan_files(6).unwrap_err().contains("pose log"));
        f.log = "scan.csv".into();
        assert!(f.scan_files(6).unwrap_err().contains("profiles"));
        f.profiles = "no-such-profiles.csv".into();
        f.axes = "-y,x,z".into();
        let spec = f.scan_files(6).unwrap();
        match &spec.log {
            ScanLog::Joints { columns, unit, .. } => {
                assert_eq!(columns.joints, ["j1", "j2", "j3", "j4", "j5", "j6"]);
                assert_eq!(*unit, AngleUnit::Deg);
            }
            other @ ScanLog::Poses { .. } => panic!("{other:?}"),
        }
        assert!(matches!(spec.profiles, ProfileSource::File { .. }));
        assert!(spec.profile_format.axes.is_some());
        f.sphere_diameter = "25.4".into();
        assert_eq!(f.scan_files(6).unwrap().sphere_diameter, Some(25.4));
        f.sphere_diameter = "-1".into();
        assert!(f.scan_files(6).unwrap_err().contains("diameter"));
        f.sphere_diameter.clear();
        f.no_return = "x".into();
        assert!(f.scan_files(6).unwrap_err().contains("no-return"));
    }
}
