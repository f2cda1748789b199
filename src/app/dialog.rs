//! The native file dialogs, one mechanism for every Browse… button: what
//! each is for ([`Purpose`]), what it offers ([`Ask`]), and the call
//! itself ([`show`]), made on a job thread (the UI never waits). `rfd`
//! answers `None` both when the operator cancels and when no dialog can
//! open (no desktop portal): the status line then says both
//! ([`NO_DIALOG`]) and the view notes it beside the button.

use std::path::PathBuf;

/// What the status line says when a file dialog returned nothing.
pub const NO_DIALOG: &str = "no file chosen — or no file dialog is available on this machine (no desktop portal); type the path instead";

/// The extensions the targets dialog offers: tables, JSON pose lists,
/// RAPID modules, KUKA files, FANUC TP programs, URScript.
pub const TARGET_EXTENSIONS: &[&str] = &[
    "csv", "txt", "json", "rob", "mod", "modx", "prg", "src", "dat", "ls", "script", "urscript",
];

/// What a file dialog is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Purpose {
    /// Open a session or result file.
    Open,
    /// Where to save the edited session.
    SaveSession,
    /// The export folder.
    ExportFolder,
    /// Import: the joint log CSV.
    ImportJoints,
    /// Import: the pose file (a program, a table, `.rob`).
    ImportPoses,
    /// Import: the profiles folder (or file, as the form says).
    ImportProfiles,
    /// Import: the reference distances CSV.
    ImportReferences,
    /// Import: the sphere centres the sensor reported.
    ImportCentres,
    /// Import: a hand-eye guess file (4×4 JSON, session or result).
    ImportHandEye,
    /// History: the library folder.
    HistoryFolder,
    /// Compensate: the targets file.
    CompensateTargets,
    /// Compensate: the tool file (`flange_from_tcp`).
    CompensateTool,
    /// Compensate: where the compensated file goes (writes once chosen).
    CompensateOut,
    /// Measure: the session file to measure.
    MeasureSession,
    /// Measure: a raw scan's pose log.
    MeasureLog,
    /// Measure: a raw scan's profiles folder.
    MeasureProfiles,
    /// Measure: the workpiece frame file.
    MeasureFrame,
    /// Measure: a sphere artefact's reference distances.
    MeasureReferences,
    /// Measure: where the cloud goes (writes once chosen).
    MeasureExport,
    /// Re-check: the check's session.
    CheckSession,
    /// Compensate: the tool the controller holds now (pose-only result).
    CompensateCurrentTool,
    /// Results: the URDF the robot came from.
    UrdfSource,
}

/// Pose logs and programs a dialog offers.
const POSE_FILES: &[&str] = &[
    "ls", "mod", "modx", "prg", "dat", "src", "script", "urscript", "rob", "json", "csv", "txt",
];

impl Purpose {
    /// Whether it chooses where a file is written (a save dialog, which
    /// asks about replacing a file itself).
    #[must_use]
    pub fn saves(self) -> bool {
        matches!(
            self,
            Self::SaveSession | Self::CompensateOut | Self::MeasureExport
        )
    }

    /// The file types it offers, `(name, extensions)`.
    fn filters(self) -> &'static [(&'static str, &'static [&'static str])] {
        match self {
            Self::Open => &[("spherecal session or result", &["json"])],
            Self::SaveSession => &[("spherecal session", &["json"])],
            Self::ImportJoints
            | Self::ImportReferences
            | Self::ImportProfiles
            | Self::MeasureReferences => &[("CSV", &["csv", "txt"])],
            Self::ImportPoses | Self::MeasureLog => {
                &[("pose file", POSE_FILES), ("any file", &["*"])]
            }
            Self::ImportCentres => &[("centres table", &["csv", "txt"]), ("any file", &["*"])],
            Self::ImportHandEye => &[("4×4 JSON, session or result", &["json"])],
            Self::CompensateTargets => &[
                ("pose table or robot program", TARGET_EXTENSIONS),
                ("all files", &["*"]),
            ],
            Self::CompensateTool => &[("tool (JSON)", &["json"])],
            Self::MeasureSession | Self::MeasureFrame | Self::CheckSession => {
                &[("JSON", &["json"])]
            }
            Self::CompensateCurrentTool => &[
                ("tool (JSON or values)", &["json", "txt"]),
                ("any file", &["*"]),
            ],
            Self::UrdfSource => &[("URDF", &["urdf", "xml"])],
            Self::MeasureExport => &[("PLY", &["ply"]), ("E57", &["e57"]), ("CSV", &["csv"])],
            Self::ExportFolder
            | Self::HistoryFolder
            | Self::MeasureProfiles
            | Self::CompensateOut => &[],
        }
    }
}

/// A dialog to show: its purpose, where it opens, the file name it
/// offers, and whether it picks a folder.
#[derive(Debug, Clone, PartialEq)]
pub struct Ask {
    /// What it is for.
    pub purpose: Purpose,
    /// The folder it opens in, when that exists.
    pub folder: Option<PathBuf>,
    /// The file name a save dialog offers.
    pub file_name: Option<String>,
    /// It picks a folder, not a file.
    pub folder_only: bool,
}

/// Shows the dialog (blocks: call it on a job thread). `None` when it
/// chose nothing or could not open.
#[must_use]
pub fn show(ask: &Ask) -> Option<PathBuf> {
    let mut dialog = rfd::FileDialog::new();
    if let Some(dir) = ask.folder.as_ref().filter(|d| d.is_dir()) {
        dialog = dialog.set_directory(dir);
    }
    if ask.folder_only {
        return dialog.pick_folder();
    }
    for (name, extensions) in ask.purpose.filters() {
        dialog = dialog.add_filter(*name, extensions);
    }
    if !ask.purpose.saves() {
        return dialog.pick_file();
    }
    if let Some(name) = &ask.file_name {
        dialog = dialog.set_file_name(name);
    }
    dialog.save_file()
}
