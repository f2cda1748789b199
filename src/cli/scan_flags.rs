//! The flags that say how to read a raw scan's pose file and profiles,
//! shared by `spherecal import` and `spherecal measure` (flattened into
//! both with `#[command(flatten)]`): the pose file's layout and
//! convention, the profiles' unit, axes, no-return value and key, the
//! joint unit, and how to read a URDF or DH table robot.

use clap::Args;

use crate::engine::base::robot::DhConvention;
use crate::engine::files::import::{
    AngleUnit, AxisMap, FlangeConvention, LengthUnit, PoseFormat, ProfileFormat, RobotSource,
};

use super::CliError;

/// How to read a raw scan's pose file and profiles (help text as
/// `spherecal import` shows it; `spherecal measure` words some of it for
/// its own use with `mut_arg`).
#[derive(Debug, Args)]
pub struct ScanFlags {
    /// Force the pose file's layout: table, json, fanuc-ls, rapid, krl or urscript (default: detected from the content).
    #[arg(long, value_parser = parse_pose_format)]
    pub pose_format: Option<PoseFormat>,
    /// How a pose table or JSON list writes a pose: ABB (x y z q1..q4), KUKA (x y z A B C), FANUC (x y z W P R), UR (x y z m, rotation vector) or matrix (16 numbers row-major). A robot program's language fixes its own.
    #[arg(long, value_parser = parse_convention)]
    pub pose_convention: Option<FlangeConvention>,
    /// The pose columns of a CSV pose log, in the convention's order (default: x,y,z,q1..q4 | a,b,c | w,p,r | rx,ry,rz | m11..m44).
    #[arg(long, value_delimiter = ',')]
    pub pose_columns: Vec<String>,
    /// Column of the pose id in a single profile file.
    #[arg(long, default_value = "pose")]
    pub pose_column: String,
    /// The tip link of a URDF robot (default: the chain's only end link), e.g. tool0.
    #[arg(long)]
    pub urdf_tip: Option<String>,
    /// The convention of a DH table robot: standard or modified.
    #[arg(long, value_parser = super::parse_dh)]
    pub dh: Option<DhConvention>,
    /// Axis map from the sensor's axes to spherecal's (laser plane x = 0): `auto` (the constant coordinate is the plane's normal) or e.g. `-y,x,z` (spherecal x = -y, y = x, z = z). A mirroring map is refused.
    #[arg(long, default_value = "auto", allow_hyphen_values = true)]
    pub axes: String,
    /// The sensor's no-return value in the profiles (file units), dropped like NaN.
    #[arg(long, allow_hyphen_values = true)]
    pub no_return: Option<f64>,
    /// Key of the point list in OpenCV YAML/JSON profiles (default: scan_line, profile, points, data, or the only list).
    #[arg(long)]
    pub profile_key: Option<String>,
    /// Unit of the joint columns: deg or rad.
    #[arg(long, default_value = "deg", value_parser = parse_angle_unit)]
    pub joint_unit: AngleUnit,
    /// Unit of the profile coordinates: mm, um or m.
    #[arg(long, default_value = "mm", value_parser = parse_length_unit)]
    pub profile_unit: LengthUnit,
}

impl ScanFlags {
    /// The profile flags as the engine's format.
    ///
    /// # Errors
    /// [`CliError`] (status 2) for a bad `--axes` map.
    pub fn profile_format(&self) -> Result<ProfileFormat, CliError> {
        let axes = if self.axes.trim().eq_ignore_ascii_case("auto") {
            None
        } else {
            Some(AxisMap::parse(&self.axes).map_err(|e| CliError::input(format!("--axes: {e}")))?)
        };
        Ok(ProfileFormat {
            unit: self.profile_unit,
            axes,
            no_return: self.no_return,
            key: self.profile_key.clone(),
        })
    }

    /// A robot argument (a JSON file, a URDF, a DH table or a preset key)
    /// read with `--urdf-tip` and `--dh`.
    ///
    /// # Errors
    /// [`CliError`] (status 2) when the text names no robot source.
    pub fn robot_source(&self, text: &str) -> Result<RobotSource, CliError> {
        RobotSource::from_text(text, self.urdf_tip.clone(), self.dh).map_err(CliError::input)
    }

    /// `--pose-columns`, or `None` for the convention's defaults.
    #[must_use]
    pub fn pose_columns(&self) -> Option<Vec<String>> {
        (!self.pose_columns.is_empty()).then(|| self.pose_columns.clone())
    }
}

/// `--pose-format`.
pub(super) fn parse_pose_format(s: &str) -> Result<PoseFormat, String> {
    PoseFormat::parse(s).ok_or_else(|| {
        format!("unknown pose format `{s}`, expected table, json, fanuc-ls, rapid, krl or urscript")
    })
}

/// `--joint-unit`.
fn parse_angle_unit(s: &str) -> Result<AngleUnit, String> {
    AngleUnit::parse(s).ok_or_else(|| format!("unknown joint unit `{s}`, expected `deg` or `rad`"))
}

/// `--profile-unit`.
fn parse_length_unit(s: &str) -> Result<LengthUnit, String> {
    LengthUnit::parse(s)
        .ok_or_else(|| format!("unknown profile unit `{s}`, expected `mm`, `um` or `m`"))
}

/// `--pose-convention` (and the import's `--flange-poses`).
pub(super) fn parse_convention(s: &str) -> Result<FlangeConvention, String> {
    FlangeConvention::parse(s).ok_or_else(|| {
        format!("unknown pose convention `{s}`, expected ABB, KUKA, FANUC, UR or matrix")
    })
}
