//! Helpers shared by the `measure` tests: simulated sessions with their
//! results, the binary, the CSV cloud reader.

#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use spherecal::engine::base::session::Session;
use spherecal::engine::calibrate::solve::{self, Method, Options};
use spherecal::engine::files::format::{self, ResultFile};
use spherecal::engine::tools::simulate::{self, SimConfig, Truth};

pub fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_spherecal")
}

pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("spherecal-measure-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A simulated session, its truth and its result (`ml` unless `method`).
pub fn calibrated(config: &SimConfig, method: Method) -> (Session, Truth, ResultFile) {
    let (session, truth) = simulate::simulate(config).unwrap();
    let mut options = Options::from_session(&session);
    options.method = method;
    options.ml.cross_validation = false;
    let (_, cal) = solve::calibrate(&session, &options).unwrap();
    let result = ResultFile::from_calibration(&session, &cal);
    (session, truth, result)
}

pub fn seed(seed: u64) -> SimConfig {
    SimConfig {
        seed,
        ..SimConfig::default()
    }
}

/// Writes a session and its result, returns their paths.
pub fn files(dir: &Path, session: &Session, result: &ResultFile) -> (PathBuf, PathBuf) {
    let (s, r) = (dir.join("s.json"), dir.join("r.json"));
    format::save_session(session, &s).unwrap();
    format::save_result(result, &r).unwrap();
    (s, r)
}

pub fn run(args: &[&str]) -> std::process::Output {
    super::bin::spherecal().args(args).output().unwrap()
}

pub fn csv_cloud(path: &Path) -> Vec<(String, [f64; 3], f64)> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    assert_eq!(
        reader.headers().unwrap().iter().collect::<Vec<_>>(),
        ["id", "x", "y", "z", "sigma_mm"]
    );
    reader
        .records()
        .map(|r| {
            let r = r.unwrap();
            let f = |k: usize| r[k].parse::<f64>().unwrap();
            (r[0].to_string(), [f(1), f(2), f(3)], f(4))
        })
        .collect()
}

pub fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}
