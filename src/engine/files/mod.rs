//! Layer 3, the doors: the files of FORMAT.md (sessions and results,
//! which carry the solver's report of layer 2), robot programs read and
//! written in place, and the import of what real cells publish (joint
//! logs, pose files, profile folders) into a session.
//!
//! | unit | holds |
//! |---|---|
//! | [`format`](mod@format) | session and result files (typed both ways), JSON text, atomic and transactional writes |
//! | [`program`] | robot programs and pose tables (FANUC `.ls`, RAPID, KRL, URScript, tables): poses read with their spans, rewritten in place |
//! | [`import`] | joint logs, pose files and profiles into a session: pairing, units and axes, the side decision, the initial hand-eye |

pub mod table;
pub mod robot_import;
pub mod format;
pub mod program;
pub mod import;
