//! The Compensate view's fields: the targets file (a pose table or a
//! robot program), how a table writes a pose, the TCP the targets are
//! poses of, and where the compensated file goes: the inputs of
//! `spherecal compensate` (`--targets`, `--pose-convention`, `--tcp`,
//! `--out`, the flag limits and `--joint-targets`) as the widgets edit
//! them.

use crate::engine::base::robot::controller::FlangeConvention;
use crate::engine::uses::compensate::Options;

/// The TCP the targets are poses of (`--tcp`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TcpChoice {
    /// The calibrated sensor: the result's hand-eye, shown as tool data to
    /// set on the controller.
    #[default]
    Sensor,
    /// The flange (no tool).
    Flange,
    /// A tool of the user's: a JSON file with `flange_from_tcp` (4×4, mm).
    ToolFile,
}

impl TcpChoice {
    /// Every choice, in the order the view lists them.
    pub const ALL: [Self; 3] = [Self::Sensor, Self::Flange, Self::ToolFile];

    /// The radio button's text.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::Sensor => "sensor (calibrated hand-eye)",
            Self::Flange => "flange",
            Self::ToolFile => "tool file",
        }
    }

    /// The command line's `--tcp` spelling; a tool file is given there
    /// by its path, here in words ("tool file").
    #[must_use]
    pub fn key(self) -> &'static str {
        match self {
            Self::Sensor => "sensor",
            Self::Flange => "flange",
            Self::ToolFile => "tool file",
        }
    }
}

/// The Compensate view's fields.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CompensateForm {
    /// The targets file: a pose table, a JSON pose list or a robot
    /// program (RAPID, URScript, KUKA `.src`/`.dat`, FANUC `.ls`).
    pub targets: String,
    /// How a table's or JSON list's numbers write a pose; `None`: from the
    /// file (a program's language fixes its own; a table needs one).
    pub convention: Option<FlangeConvention>,
    /// The TCP the targets are poses of.
    pub tcp: TcpChoice,
    /// The tool file, for [`TcpChoice::ToolFile`].
    pub tool: String,
    /// Where "Write compensated program" writes.
    pub out: String,
    /// The tool the controller holds now (a pose-only result's targets
    /// are rewritten for it: `--current-tool`).
    pub current_tool: String,
    /// What joint targets mean and when a target is flagged
    /// (`--joint-targets`, `--sigma-tolerance`, `--far-joints`,
    /// `--region-margin`).
    pub options: Options,
}

impl CompensateForm {
    /// The convention's name in the view: "from the file" or the
    /// command line's key (`abb`, `kuka`, …).
    #[must_use]
    pub fn convention_label(convention: Option<FlangeConvention>) -> String {
        convention.map_or_else(
            || "from the file (a program's language)".to_string(),
            |c| c.key().to_string(),
        )
    }
}
