//! The headless calibration engine. It never imports egui, eframe or rfd;
//! the command line and the workbench are two thin callers of it.
//!
//! Six layers, in the order of their use: each uses only the layers
//! above it, and inside a layer each unit uses only the units above it
//! (each layer's own doc lists its units in that order).
//!
//! | layer | holds | units |
//! |---|---|---|
//! | [`base`] | numbers, frames, the robot's MDH model, the session, what a calibration records | numeric, control, geometry, limits, robot, session, records, cell |
//! | [`files`] | every file read or written: the capped reader and atomic writer, parsers of outside formats, FORMAT.md files, robot programs, the readers of real cells | table, robot_import, format, program, import |
//! | [`calibrate`] | the paper's method in the order it runs (eq. 21, 3-9, 20, 10-19) | stripe, handeye, validate, solve |
//! | [`assemble`] | a session built from imported data: the initial hand-eye, the stripe side decided by calibrating, the import entry | initial, pose_session, side, preview, entry |
//! | [`tools`] | around the method: views, reports, history, simulation, scoring, planning | result_view, report, history, simulate, evaluate, plan, scene |
//! | [`uses`] | using a calibration: measuring parts, compensating robot programs, the re-check | measure, compensate, check |
//!
//! Why this order: the files come right after the ground because reading
//! and writing need no method (a result file writes the report types of
//! `base::records`, which the solver fills); the paper's core needs only
//! the model, the session and (for its own results) the format; what an
//! import cannot read from the files (the stripe side, a pose file's
//! initial hand-eye) is decided by running the method, so the layer that
//! assembles a session from imported data comes after it; the tools use
//! all of these (a simulated session is written as one, a plan as a
//! program); measuring and compensating use a result and the tools'
//! simulator for their checks. The names say what a layer holds; the
//! order is this list (`tests/cli/layout.rs` checks it).

pub mod base;
pub mod files;
pub mod calibrate;
pub mod assemble;
pub mod tools;
pub mod uses;
