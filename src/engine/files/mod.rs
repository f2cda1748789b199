//! Layer 2, the doors: every byte read or written (the capped reader and
//! the atomic writer of [`format`](mod@format)), the CSV table reader, the
//! robot models of outside formats (URDF, DH tables), the files of
//! FORMAT.md (sessions, and results with the report types of
//! [`crate::engine::base::records`]), robot programs read and written in
//! place, and the readers of what real cells publish (joint logs, pose
//! files, profile folders, a fixed sensor's points). Nothing here runs the
//! solver.
//!
//! | unit | holds |
//! |---|---|
//! | [`table`] | CSV tables as the engine reads them (line numbers for messages) |
//! | [`robot_import`] | robot models from a URDF or a DH table |
//! | [`format`](mod@format) | session and result files (typed both ways), JSON text, the capped reader, atomic and transactional writes |
//! | [`program`] | robot programs and pose tables (FANUC `.ls`, RAPID, KRL, URScript, tables): poses read with their spans, rewritten in place |
//! | [`import`] | joint logs, pose files, profiles and a fixed sensor's points read: pairing, units and axes, a joint log's session |

pub mod table;
pub mod robot_import;
pub mod format;
pub mod program;
pub mod import;
