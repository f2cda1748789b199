//! The headless calibration engine. It never imports egui, eframe or rfd;
//! the command line and the workbench are two thin callers of it.
//!
//! Five layers, in the order of their use: each uses only the layers
//! above it, and inside a layer each unit uses only the units above it
//! (each layer's own doc lists its units in that order).
//!
//! | layer | holds | units |
//! |---|---|---|
//! | [`base`] | numbers, frames, the robot's MDH model, the session | numeric, geometry, table, limits, robot, session, cell |
//! | [`calibrate`] | the paper's method in the order it runs (eq. 21, 3-9, 20, 10-19) | stripe, handeye, validate, solve |
//! | [`files`] | the doors: FORMAT.md files, robot programs, the import of real cells | format, program, import |
//! | [`tools`] | around the method: views, reports, history, simulation, scoring, planning | result_view, report, history, simulate, evaluate, plan |
//! | [`uses`] | using a calibration: measuring parts, compensating robot programs | measure, compensate |
//!
//! Why this order: the paper's core needs only the model and the session,
//! so it sits alone right after them; the files come after it because a
//! result file carries the solver's report and the import decides the
//! stripe side by calibrating; the tools use the files (a simulated
//! session is written as one, a plan as a program); measuring and
//! compensating use a result and the tools' simulator for their checks.
//! The layers' names sort in this order, so the tree reads as the
//! pipeline.

pub mod base;
pub mod files;
pub mod calibrate;
pub mod assemble;
pub mod tools;
pub mod uses;
