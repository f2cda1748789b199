//! `spherecal evaluate`: the evidence for the `ml` method (the study is
//! [`crate::engine::evaluate::study`]); prints the text report or the
//! README's Markdown table.

use clap::Args;

use super::CliError;
use crate::engine::evaluate::study::{StudyError, markdown, run_scenario, select, text};

/// `spherecal evaluate`.
#[derive(Debug, Args)]
pub struct EvaluateArgs {
    /// Seeds `1..=N` per scenario.
    #[arg(long, default_value_t = 5)]
    pub seeds: u64,
    /// One scenario key (`paper-like`, `random-2x`, `stripe-0.05`,
    /// `outliers-5pct`, `stations-30`) or `all`.
    #[arg(long, default_value = "all")]
    pub scenario: String,
    /// Print the README table (Markdown) instead of the text report.
    #[arg(long)]
    pub markdown: bool,
}

/// `spherecal evaluate`.
///
/// # Errors
/// Bad arguments (status 2) or a failed simulation or calibration (status 1).
pub fn run(args: &EvaluateArgs) -> Result<(), CliError> {
    if args.seeds == 0 {
        return Err(CliError::input("--seeds must be at least 1"));
    }
    let scenarios =
        select(&args.scenario).map_err(|e: StudyError| CliError::input(e.to_string()))?;
    let mut results = Vec::with_capacity(scenarios.len());
    for scenario in &scenarios {
        if !args.markdown {
            eprintln!("running {} over {} seed(s)…", scenario.key, args.seeds);
        }
        results.push(
            run_scenario(scenario, args.seeds).map_err(|e| CliError::internal(e.to_string()))?,
        );
    }
    if args.markdown {
        say!("{}", markdown(&results, args.seeds));
    } else {
        say!("{}", text(&results, args.seeds));
    }
    Ok(())
}
