//! The flags that say how to read a raw scan's pose file and profiles,
//! shared by `spherecal import` and `spherecal measure` (flattened into
//! both with `#[command(flatten)]`): the pose file's layout and
//! convention, the profiles' unit, axes, no-return value and key, the
//! joint unit, and how to read a URDF or DH table robot.

use clap::Args;

use crate::engine::files::import::{
    AngleUnit, AxisMap, FlangeConvention, LengthUnit, PoseFormat, ProfileFormat, RobotSource,
};
use crate::engine::files::robot_import::DhConvention;

use super::CliError;
use super::values::Keywords;

/// How to read a raw scan's pose file and profiles (one help text for
/// both commands).
#[derive(Debug, Args)]
pub struct ScanFlags {
    /// Force the pose file's layout [default: detected from the content]
    #[arg(long, value_parser = pose_format_parser())]
    pub pose_format: Option<PoseFormat>,
    /// How a pose table or JSON list writes a pose (a robot program's language fixes its own).
    #[arg(long, value_parser = convention_parser())]
    pub pose_convention: Option<FlangeConvention>,
    /// The pose columns of a pose table, in the convention's order [default: x,y,z,q1..q4 | a,b,c | w,p,r | rx,ry,rz | m11..m44]; without a header, every column in order, `id` the id and `-` one to skip (e.g. id,x,y,z,w,p,r or x,y,z,w,p,r,-)
    #[arg(long, value_delimiter = ',')]
    pub pose_columns: Vec<String>,
    /// Column of the pose id in a single profile file.
    #[arg(long, default_value = "pose")]
    pub pose_column: String,
    /// The tip link of a URDF robot, e.g. tool0 [default: the chain's only end link]
    #[arg(long)]
    pub urdf_tip: Option<String>,
    /// The convention of a DH table robot.
    #[arg(long, value_parser = super::dh_parser())]
    pub dh: Option<DhConvention>,
    /// Axis map from the sensor's axes to spherecal's (laser plane x = 0): `auto` (the constant coordinate is the plane's normal) or e.g. `-y,x,z` (spherecal x = -y, y = x, z = z). A mirroring map is refused.
    #[arg(long, default_value = "auto", allow_hyphen_values = true)]
    pub axes: String,
    /// The sensor's no-return value in the profiles (file units): such points are dropped and counted, as NaN ones are.
    #[arg(long, allow_hyphen_values = true)]
    pub no_return: Option<f64>,
    /// Key of the point list in OpenCV YAML/JSON profiles [default: scan_line, profile, points, data, or the only list]
    #[arg(long)]
    pub profile_key: Option<String>,
    /// Unit of the joint columns.
    #[arg(long, default_value = "deg", value_parser = Keywords::plain(["deg", "rad"], AngleUnit::parse))]
    pub joint_unit: AngleUnit,
    /// Unit of the profile coordinates.
    #[arg(long, default_value = "mm", value_parser = Keywords::plain(["mm", "um", "m"], LengthUnit::parse))]
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

/// `--pose-format`: the engine's layouts.
pub(super) fn pose_format_parser() -> Keywords<PoseFormat> {
    Keywords::new(
        PoseFormat::ALL
            .iter()
            .map(|f| (f.key(), Some(f.describe())))
            .collect(),
        PoseFormat::parse,
    )
}

/// `--pose-convention` (and the import's `--flange-poses`): the engine's
/// conventions, each with what its values are.
pub(super) fn convention_parser() -> Keywords<FlangeConvention> {
    Keywords::new(
        FlangeConvention::ALL
            .iter()
            .map(|c| (c.key(), Some(c.describe())))
            .collect(),
        FlangeConvention::parse,
    )
}
