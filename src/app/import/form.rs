//! The import wizard's form: what the operator chose (a joint log or a
//! flange-pose log, profiles and their axes, robot, units, column mapping,
//! flange-pose check) and the engine's [`ImportSpec`] or
//! [`PoseImportSpec`] it stands for. The import itself is
//! [`crate::engine::files::import`], the same functions `spherecal import` calls.

use std::path::PathBuf;

use nalgebra::{Isometry3, Translation3};

use crate::engine::files::import::{
    AngleUnit, AxisMap, ColumnMap, DEFAULT_POSITION_TOLERANCE_MM, DEFAULT_ROTATION_TOLERANCE_DEG,
    DEFAULT_SPHERE_DIAMETER, FlangeCheck, FlangeConvention, ImportSpec, LengthUnit, Observations,
    PoseFormat, PoseImportSpec, ProfileFormat, ProfileSource, RobotSource, SideChoice,
};
use crate::engine::files::robot_import::DhConvention;

/// Rows the preview shows.
pub const PREVIEW_ROWS: usize = 8;

/// Number of joint columns of the mapping (the presets are all 6-axis; a
/// robot file with another count is reported by the engine).
pub const JOINTS: usize = 6;

/// Where the stripe profiles are, as the form chooses it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProfilesKind {
    /// A folder of `<id>.csv` files.
    Folder,
    /// One CSV with a pose column.
    File,
}

/// The four flange-pose conventions with their labels.
pub const CONVENTIONS: [(FlangeConvention, &str); 4] = [
    (
        FlangeConvention::AbbQuaternion,
        "ABB (x y z mm, quaternion)",
    ),
    (FlangeConvention::KukaAbc, "KUKA (x y z mm, A B C deg)"),
    (FlangeConvention::FanucWpr, "FANUC (x y z mm, W P R deg)"),
    (
        FlangeConvention::UrRotationVector,
        "UR (x y z m, rotation vector rad)",
    ),
];

/// What the sensor gave for each pose of a pose file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ObservationKind {
    /// Stripe profiles (a folder or one file).
    Profiles,
    /// Sphere centres the sensor reported itself (one table, `x y z` a
    /// pose, sensor frame, mm): `spherecal import --centres`.
    Centres,
}

/// Where the initial hand-eye of a pose file's session comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HandEyeChoice {
    /// Computed by the import: eq. 6-9, else the general solution.
    Computed,
    /// A guess typed in: x y z mm, roll pitch yaw deg.
    Numbers,
    /// A guess from a file, as `spherecal import --hand-eye FILE`: a 4×4
    /// JSON matrix (rows, mm) or a session/result file's `hand_eye`.
    File,
}

/// What kind of pose log the wizard imports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LogKind {
    /// A joint log CSV (id, station, use, joints).
    Joints,
    /// A pose file in any layout the engine reads (a table with or
    /// without a header, JSON/`.rob`, FANUC `.ls`, RAPID, KUKA, URScript):
    /// flange poses give a pose-only session.
    FlangePoses,
}

/// The import wizard's fields.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportForm {
    /// Joint log or flange-pose log.
    pub log_kind: LogKind,
    /// The joint log CSV.
    pub joints: String,
    /// The pose file (any layout `spherecal import --poses` reads).
    pub poses: String,
    /// How a pose table or JSON list writes a pose (`--pose-convention`);
    /// `None`: as the program's language fixes it (a table or JSON list
    /// needs one).
    pub pose_convention: Option<FlangeConvention>,
    /// Side of the sphere centres for a flange-pose log without a side
    /// column.
    pub side: SideChoice,
    /// Axis map of the profiles: `auto` or e.g. `-y,x,z`.
    pub axes: String,
    /// The sensor's no-return value (empty: none).
    pub no_return: String,
    /// The convention of a DH-table robot file (`.csv`).
    pub dh: DhConvention,
    /// Folder or file of the stripe profiles.
    pub profiles: String,
    /// Whether `profiles` is a folder or one file.
    pub profiles_kind: ProfilesKind,
    /// Pose-id column of a single profile file.
    pub pose_column: String,
    /// Optional reference distances CSV (`from,to,distance`, mm).
    pub references: String,
    /// Robot preset key, used when `robot_file` is empty.
    pub robot_preset: String,
    /// A session or result file whose robot block is the nominal model.
    pub robot_file: String,
    /// Unit of the joint columns.
    pub joint_unit: AngleUnit,
    /// Unit of the profile coordinates.
    pub profile_unit: LengthUnit,
    /// Sphere diameter, mm.
    pub sphere_diameter: f64,
    /// Session name (empty: the joint log's file name).
    pub name: String,
    /// Column of the measurement id.
    pub id_column: String,
    /// Column of the station id.
    pub station_column: String,
    /// Column of the use.
    pub use_column: String,
    /// Column of the side (empty: none, every side +1).
    pub side_column: String,
    /// Columns of joints 1..6.
    pub joint_columns: Vec<String>,
    /// Check the flange poses in this convention.
    pub flange: Option<FlangeConvention>,
    /// The flange-pose columns, comma separated (empty: the convention's
    /// defaults).
    pub flange_columns: String,
    /// Position tolerance of the flange check, mm.
    pub tolerance_mm: f64,
    /// Rotation tolerance of the flange check, deg.
    pub tolerance_deg: f64,
    /// The sensor's measuring range to write as `sensor.range`, `[y0, y1,
    /// z0, z1]` mm; `None`: not known.
    pub range: Option<[f64; 4]>,
    /// The pose file's layout forced (`--pose-format`); `None`: detected
    /// from the content.
    pub pose_format: Option<PoseFormat>,
    /// Profiles or centres, for a pose file.
    pub observations: ObservationKind,
    /// The centres table (`--centres`), with [`ObservationKind::Centres`].
    pub centres: String,
    /// Where the initial hand-eye comes from.
    pub hand_eye: HandEyeChoice,
    /// The typed hand-eye guess `eT_s`: x, y, z (mm), roll, pitch, yaw
    /// (deg, `R = Rz(yaw)·Ry(pitch)·Rx(roll)`).
    pub hand_eye_numbers: [f64; 6],
    /// The hand-eye guess file, with [`HandEyeChoice::File`].
    pub hand_eye_file: String,
}

impl Default for ImportForm {
    fn default() -> Self {
        Self {
            log_kind: LogKind::Joints,
            joints: String::new(),
            poses: String::new(),
            pose_convention: None,
            side: SideChoice::Auto,
            axes: "auto".into(),
            no_return: String::new(),
            dh: DhConvention::Standard,
            profiles: String::new(),
            profiles_kind: ProfilesKind::Folder,
            pose_column: "pose".into(),
            references: String::new(),
            robot_preset: "irb2400".into(),
            robot_file: String::new(),
            joint_unit: AngleUnit::Deg,
            profile_unit: LengthUnit::Mm,
            sphere_diameter: DEFAULT_SPHERE_DIAMETER,
            name: String::new(),
            id_column: "id".into(),
            station_column: "station".into(),
            use_column: "use".into(),
            side_column: String::new(),
            joint_columns: (1..=JOINTS).map(|k| format!("j{k}")).collect(),
            flange: None,
            flange_columns: String::new(),
            tolerance_mm: DEFAULT_POSITION_TOLERANCE_MM,
            tolerance_deg: DEFAULT_ROTATION_TOLERANCE_DEG,
            range: None,
            pose_format: None,
            observations: ObservationKind::Profiles,
            centres: String::new(),
            hand_eye: HandEyeChoice::Computed,
            hand_eye_numbers: [0.0; 6],
            hand_eye_file: String::new(),
        }
    }
}

impl ImportForm {
    /// The profiles' source and format, shared by both kinds of log;
    /// unless `chosen`, an empty path when none is chosen (the preview).
    fn profile_choices(&self, chosen: bool) -> Result<(ProfileSource, ProfileFormat), String> {
        if chosen && self.profiles.trim().is_empty() {
            return Err("choose the stripe profiles (a folder or one file) first".into());
        }
        let profiles = self.profiles.trim();
        let source = match self.profiles_kind {
            ProfilesKind::Folder => ProfileSource::Folder(PathBuf::from(profiles)),
            ProfilesKind::File => ProfileSource::File {
                path: PathBuf::from(profiles),
                pose_column: self.pose_column.trim().to_string(),
            },
        };
        let axes = match self.axes.trim() {
            "" | "auto" => None,
            text => Some(AxisMap::parse(text)?),
        };
        let no_return = no_return(&self.no_return)?;
        Ok((
            source,
            ProfileFormat {
                unit: self.profile_unit,
                axes,
                no_return,
                key: None,
            },
        ))
    }

    /// A sphere diameter that is a positive number of mm, or why not.
    fn check_diameter(&self) -> Result<(), String> {
        let d = self.sphere_diameter;
        if d.is_finite() && d > 0.0 {
            Ok(())
        } else {
            Err(format!("the sphere diameter {d} mm is not positive"))
        }
    }

    /// The nominal robot: the file (session/result, URDF, DH table) when
    /// one is given, else the preset.
    fn robot_source(&self) -> Result<RobotSource, String> {
        let file = self.robot_file.trim();
        if file.is_empty() {
            Ok(RobotSource::Preset(self.robot_preset.clone()))
        } else {
            RobotSource::from_text(file, None, Some(self.dh)).map_err(String::from)
        }
    }

    /// The engine's spec of a pose file, or what is missing. A guess from
    /// a file is not read here (the job reads it: [`Self::hand_eye_guess`]).
    ///
    /// # Errors
    /// No pose file, profiles or centres chosen, a bad axis map, sphere
    /// diameter or typed guess: a sentence for the operator.
    pub fn pose_spec(&self) -> Result<PoseImportSpec, String> {
        let mut spec = self.pose_preview_spec()?;
        spec.observations = match self.observations {
            ObservationKind::Profiles => Observations::Profiles(self.profile_choices(true)?.0),
            ObservationKind::Centres => {
                let centres = self.centres.trim();
                if centres.is_empty() {
                    return Err("choose the centres file first".into());
                }
                Observations::Centres(PathBuf::from(centres))
            }
        };
        self.check_diameter()?;
        match self.hand_eye {
            HandEyeChoice::Computed => {}
            HandEyeChoice::Numbers => spec.hand_eye = Some(self.typed_hand_eye()?),
            HandEyeChoice::File => {
                if self.hand_eye_file.trim().is_empty() {
                    return Err("choose the hand-eye guess file first".into());
                }
            }
        }
        Ok(spec)
    }

    /// The engine's spec of a pose file for its preview (the layout and
    /// the pairing): observations not chosen yet are left empty (the
    /// preview says so), no guess.
    ///
    /// # Errors
    /// No pose file chosen, a bad axis map or robot: a sentence.
    pub fn pose_preview_spec(&self) -> Result<PoseImportSpec, String> {
        let poses = self.poses.trim();
        if poses.is_empty() {
            return Err("choose the pose file first".into());
        }
        let (source, profile_format) = self.profile_choices(false)?;
        let name = self.name.trim();
        let references = self.references.trim();
        Ok(PoseImportSpec {
            poses: PathBuf::from(poses),
            format: self.pose_format,
            convention: self.pose_convention,
            pose_columns: None,
            observations: match self.observations {
                ObservationKind::Profiles => Observations::Profiles(source),
                ObservationKind::Centres => {
                    Observations::Centres(PathBuf::from(self.centres.trim()))
                }
            },
            profile_format,
            robot: (!self.robot_file.trim().is_empty())
                .then(|| self.robot_source())
                .transpose()?,
            sphere_diameter: self.sphere_diameter,
            side: self.side,
            hand_eye: None,
            name: (!name.is_empty()).then(|| name.to_string()),
            references: (!references.is_empty()).then(|| PathBuf::from(references)),
        })
    }

    /// What the pose file's preview depends on (the preview spec without
    /// the fields it does not read); `None` when there is nothing to
    /// preview (a joint log, no pose file, a bad field).
    #[must_use]
    pub fn pose_scan_key(&self) -> Option<PoseImportSpec> {
        if self.log_kind != LogKind::FlangePoses {
            return None;
        }
        let mut spec = self.pose_preview_spec().ok()?;
        spec.sphere_diameter = 0.0;
        spec.side = SideChoice::Auto;
        spec.name = None;
        spec.references = None;
        Some(spec)
    }

    /// The typed guess as `eT_s`.
    ///
    /// # Errors
    /// A number that is not finite.
    pub fn typed_hand_eye(&self) -> Result<Isometry3<f64>, String> {
        let [x, y, z, roll, pitch, yaw] = self.hand_eye_numbers;
        if self.hand_eye_numbers.iter().any(|v| !v.is_finite()) {
            return Err("the hand-eye guess has a number that is not finite".into());
        }
        Ok(Isometry3::from_parts(
            Translation3::new(x, y, z),
            crate::engine::base::geometry::rotation_from_rpy_deg([roll, pitch, yaw]),
        ))
    }

    /// The hand-eye guess the import starts from: typed, or read from the
    /// file (as `spherecal import --hand-eye FILE`); `None`: computed.
    /// Reads a file: call it on a job.
    ///
    /// # Errors
    /// The file cannot be read or holds no 4×4 `hand_eye`.
    pub fn hand_eye_guess(&self) -> Result<Option<Isometry3<f64>>, String> {
        match self.hand_eye {
            HandEyeChoice::Computed => Ok(None),
            HandEyeChoice::Numbers => self.typed_hand_eye().map(Some),
            HandEyeChoice::File => {
                let path = PathBuf::from(self.hand_eye_file.trim());
                crate::engine::files::format::read_transform(&path, "hand_eye")
                    .map(Some)
                    .map_err(|m| format!("hand-eye guess: {m} ({})", path.display()))
            }
        }
    }

    /// The engine's spec, or what is missing.
    ///
    /// # Errors
    /// No joint log or profiles chosen, a non-positive sphere diameter or
    /// tolerance: a sentence for the operator.
    pub fn spec(&self) -> Result<ImportSpec, String> {
        let joints = self.joints.trim();
        if joints.is_empty() {
            return Err("choose the joint log CSV first".into());
        }
        if !(self.tolerance_mm > 0.0 && self.tolerance_deg > 0.0) {
            return Err("the flange-check tolerances must be positive".into());
        }
        let (profiles, profile_format) = self.profile_choices(true)?;
        self.check_diameter()?;
        let robot = self.robot_source()?;
        let side = self.side_column.trim();
        let flange = self.flange.map(|convention| {
            let mut check = FlangeCheck::new(convention);
            let columns: Vec<String> = self
                .flange_columns
                .split(',')
                .map(|c| c.trim().to_string())
                .filter(|c| !c.is_empty())
                .collect();
            if !columns.is_empty() {
                check.columns = columns;
            }
            check.tolerance_mm = self.tolerance_mm;
            check.tolerance_deg = self.tolerance_deg;
            check
        });
        let name = self.name.trim();
        let references = self.references.trim();
        Ok(ImportSpec {
            joint_log: PathBuf::from(joints),
            columns: ColumnMap {
                id: self.id_column.trim().to_string(),
                station: self.station_column.trim().to_string(),
                usage: self.use_column.trim().to_string(),
                side: (!side.is_empty()).then(|| side.to_string()),
                joints: self
                    .joint_columns
                    .iter()
                    .map(|c| c.trim().to_string())
                    .collect(),
            },
            joint_unit: self.joint_unit,
            profiles,
            profile_format,
            robot,
            sphere_diameter: self.sphere_diameter,
            name: (!name.is_empty()).then(|| name.to_string()),
            flange,
            references: (!references.is_empty()).then(|| PathBuf::from(references)),
        })
    }

    /// Fills the mapping from a joint log's header where a column's name
    /// is an obvious match (case-insensitive: `id`/`pose`, `station`/
    /// `sphere`, `use`, `side`, `j1`/`a1`/`joint1`/`q1`…), leaving the
    /// other fields as they are. Returns how many fields it set.
    pub fn guess_mapping(&mut self, header: &[String]) -> usize {
        let find = |names: &[String]| -> Option<String> {
            header
                .iter()
                .find(|h| names.iter().any(|n| h.eq_ignore_ascii_case(n)))
                .cloned()
        };
        let mut set = 0;
        let mut assign = |field: &mut String, names: &[String]| {
            if let Some(f) = find(names) {
                *field = f;
                set += 1;
            }
        };
        let words = |list: &[&str]| -> Vec<String> { list.iter().map(|s| (*s).into()).collect() };
        let ids = words(&["id", "pose", "pose_id", "measurement"]);
        assign(&mut self.id_column, &ids);
        let stations = words(&["station", "sphere", "station_id"]);
        assign(&mut self.station_column, &stations);
        assign(&mut self.use_column, &words(&["use", "usage", "group"]));
        assign(&mut self.side_column, &words(&["side"]));
        for (k, slot) in (1..=JOINTS).zip(self.joint_columns.iter_mut()) {
            let names = ["j", "a", "joint", "joint_", "axis"].map(|p| format!("{p}{k}"));
            assign(slot, &names);
        }
        set
    }
}

/// The sensor's no-return value as a form field holds it (profile file
/// units): `None` when the field is empty.
///
/// # Errors
/// The message to show when the text is not a finite number.
pub fn no_return(text: &str) -> Result<Option<f64>, String> {
    match text.trim() {
        "" => Ok(None),
        text => text
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .map(Some)
            .ok_or_else(|| format!("the no-return value `{text}` is not a number")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mapping_is_guessed_from_a_kuka_style_header() {
        let mut f = ImportForm::default();
        let header: Vec<String> = ["Pose", "Sphere", "Use", "A1", "A2", "A3", "A4", "A5", "A6"]
            .iter()
            .map(|s| (*s).to_string())
            .collect();
        assert_eq!(f.guess_mapping(&header), 9);
        assert_eq!(f.id_column, "Pose");
        assert_eq!(f.station_column, "Sphere");
        assert_eq!(f.joint_columns[5], "A6");
        assert!(f.side_column.is_empty(), "no side column in the header");
    }

    #[test]
    fn a_pose_file_spec_carries_the_layout_centres_and_the_typed_guess() {
        let mut f = ImportForm {
            log_kind: LogKind::FlangePoses,
            ..ImportForm::default()
        };
        assert!(f.pose_spec().unwrap_err().contains("pose file"));
        f.poses = "calib.ls".into();
        assert!(f.pose_spec().unwrap_err().contains("profiles"));
        // The preview needs only the pose file.
        let p = f.pose_preview_spec().unwrap();
        assert_eq!(p.convention, None, "a program's language fixes it");
        f.observations = ObservationKind::Centres;
        assert!(f.pose_spec().unwrap_err().contains("centres"));
        f.centres = "centres.txt".into();
        f.pose_format = Some(PoseFormat::FanucLs);
        f.hand_eye = HandEyeChoice::Numbers;
        f.hand_eye_numbers = [10.0, -20.0, 150.0, 0.0, 0.0, 90.0];
        let s = f.pose_spec().unwrap();
        assert_eq!(s.format, Some(PoseFormat::FanucLs));
        assert_eq!(s.observations, Observations::Centres("centres.txt".into()));
        let he = s.hand_eye.unwrap();
        assert_eq!(
            he.translation.vector,
            nalgebra::Vector3::new(10.0, -20.0, 150.0)
        );
        // yaw 90°: the sensor's x is the flange's y.
        let x = he.rotation * nalgebra::Vector3::x();
        assert!((x - nalgebra::Vector3::y()).norm() < 1e-12, "{x}");
        f.hand_eye = HandEyeChoice::File;
        assert!(f.pose_spec().unwrap_err().contains("hand-eye guess file"));
    }

    #[test]
    fn spec_needs_the_files_and_carries_the_choices() {
        let mut f = ImportForm::default();
        assert!(f.spec().unwrap_err().contains("joint log"));
        f.joints = "log.csv".into();
        assert!(f.spec().unwrap_err().contains("profiles"));
        f.profiles = "p.csv".into();
        f.profiles_kind = ProfilesKind::File;
        f.side_column = "side".into();
        f.flange = Some(FlangeConvention::KukaAbc);
        f.references = " refs.csv ".into();
        let s = f.spec().unwrap();
        assert_eq!(s.columns.side.as_deref(), Some("side"));
        assert_eq!(s.flange.unwrap().columns.len(), 6);
        assert_eq!(s.references, Some(PathBuf::from("refs.csv")));
        assert!(matches!(s.profiles, ProfileSource::File { .. }));
        f.sphere_diameter = 0.0;
        assert!(f.spec().unwrap_err().contains("diameter"));
    }
}
