//! Layer 4, a session built from imported data: what the files of a real
//! cell do not say and must be decided from the data by the method of
//! layer 3 — the initial hand-eye of a pose file's session (the paper's
//! eq. 6-9 group or the general solution, [`initial`]), the stripe side
//! (both sides calibrated, the better kept, [`side`]) — the preview of a
//! pose import, and the one import entry the command line and the
//! workbench call ([`entry`]).
//!
//! | unit | holds |
//! |---|---|
//! | [`initial`] | the initial hand-eye of an imported session, the uses settled, the start's plausibility |
//! | [`pose_session`] | a pose file's session: measurements on their side, uses and the initial hand-eye settled, the rules checked |
//! | [`side`] | the stripe side decided by calibrating both, the pose import that runs it |
//! | [`preview`] | what a pose import will read and pair, before it runs |
//! | [`entry`] | the import use case in one entry, and the joint log's preview |
//! | [`choices`] | every choice of an import with its default and checks, filled by the CLI's flags and the workbench's form |

pub mod initial;
pub mod pose_session;
pub mod side;
pub mod preview;
pub mod entry;
pub mod choices;

pub use choices::{HandEyeChoice, ImportChoices, LogKind, ObservationKind, ProfilesKind};
pub use entry::{ImportRequest, PoseLog, import_session, preview_joint_log};
pub use pose_session::build_pose_session;
pub use preview::{PairingPreview, PosePreview, preview_pose_import};
pub use side::{decide_side, import_poses, import_poses_with};
