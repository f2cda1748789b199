//! The Measure view's form: what is measured (the open session, a
//! session file, or a raw scan's pose log and profiles as `spherecal
//! measure --joints/--poses --profiles` reads them), how (`--use`, a
//! workpiece frame, the sensor's noise, no σ), and where the cloud is
//! written. [`MeasureForm::scan_files`] builds the engine's
//! [`ScanFiles`] as the command does; nothing here reads a file.

use std::path::PathBuf;

use crate::engine::base::session::Use;
use crate::engine::files::import::{
    AngleUnit, AxisMap, FlangeConvention, LengthUnit, ProfileFormat, ProfileSource,
};
use crate::engine::uses::measure::{ScanColumns, ScanFiles, ScanLog};

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
    /// The sensor's own noise: 1σ of each in-plane coordinate, mm.
    pub sensor_noise_mm: f64,
    /// Write no σ (`--no-sigma`): for a result without covariance.
    pub no_sigma: bool,
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
            sensor_noise_mm: 0.0,
            no_sigma: false,
            out: String::new(),
        }
    }
}

/// Largest sensor noise the form takes, mm: a laser-stripe sensor's
/// in-plane noise is micrometres to a few tenths of a millimetre; more
/// is a typing error (a value in µm).
pub const MAX_SENSOR_NOISE_MM: f64 = 10.0;

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
        let log = PathBuf::from(self.log.trim());
        if log.as_os_str().is_empty() {
            return Err("choose the raw scan's pose log (joint log CSV or pose file) first".into());
        }
        let profiles = self.profiles.trim();
        if profiles.is_empty() {
            return Err("choose the raw scan's profiles (a folder or one CSV) first".into());
        }
        let profiles = PathBuf::from(profiles);
        let profiles = if profiles.is_dir() {
            ProfileSource::Folder(profiles)
        } else {
            ProfileSource::File {
                path: profiles,
                pose_column: "pose".into(),
            }
        };
        let axes = match self.axes.trim() {
            "" | "auto" => None,
            text => Some(AxisMap::parse(text).map_err(|e| format!("axes: {e}"))?),
        };
        let no_return = super::no_return(&self.no_return)?;
        let sphere_diameter = match self.sphere_diameter.trim() {
            "" => None,
            text => Some(
                text.parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite() && *v > 0.0)
                    .ok_or_else(|| {
                        format!("the sphere diameter `{text}` is not a positive number of mm")
                    })?,
            ),
        };
        let references = self.references.trim();
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
        Ok(ScanFiles {
            log,
            profiles,
            profile_format: ProfileFormat {
                unit: self.profile_unit,
                axes,
                no_return,
                key: None,
            },
            robot: None,
            sphere_diameter,
            references: (!references.is_empty()).then(|| PathBuf::from(references)),
        })
    }
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
