//! The command line's tests, on the real binary: its contract, every
//! subcommand, hostile input, the report in a browser, and the user guide
//! whose every command runs here.

#[path = "../support/mod.rs"]
mod support;

mod calibration_export;
mod cli_help;
mod compensate;
mod contract;
mod doors;
mod guide;
mod history;
mod import_hand_eye;
mod history_fixed;
mod hostile;
mod layout;
mod measure;
mod measure_scans;
mod model_export;
mod no_update;
mod plan;
mod report;
mod report_browser;
mod tracker_cells;
mod volume_check;
