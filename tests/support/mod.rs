//! What the test binaries share: running the real binary, the simulated
//! sessions the tests start from, and driving the workbench. Each binary
//! (`tests/engine`, `tests/cli`, `tests/ui`) includes this module by path
//! and uses part of it, hence `dead_code` allowed here only.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

pub mod bin;
pub mod measure;
pub mod one_station;
pub mod pose;
pub mod sim;
pub mod tool_readers;
#[cfg(feature = "gui")]
pub mod ui;
