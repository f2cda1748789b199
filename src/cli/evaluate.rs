//! `spherecal evaluate`: the evidence for the `ml` method (the study is
//! [`crate::engine::tools::evaluate::study`]); prints the text report or the
//! README's Markdown table.

use clap::Args;

use super::CliError;
use crate::engine::tools::evaluate::study::{
    SCENARIOS, StudyError, markdown, range_markdown, run_scenario, select, text,
};
use crate::engine::tools::plan::range_study::{
    planned_range_markdown, planned_range_study, planned_range_text,
};

/// `spherecal evaluate`.
#[derive(Debug, Args)]
pub struct EvaluateArgs {
    /// Seeds `1..=N` per scenario.
    #[arg(long, value_name = "N", default_value_t = 5, value_parser = super::values::count(1, MAX_SEEDS))]
    pub seeds: u64,
    /// The scenario to run, or `all`.
    #[arg(long, default_value = "all", value_parser = scenario_parser())]
    pub scenario: String,
    /// Print the tables (Markdown) instead of the text report.
    #[arg(long)]
    pub markdown: bool,
    /// Instead of the scenarios: the IRB 2400 cell planned for an 80 × 80 mm range with and without spreading the sphere over it, simulated with Table 1 and random errors, the error over the range predicted and realised against the floor.
    #[arg(long)]
    pub planned_range: bool,
    /// Instead of the scenarios: target compensation validated in simulation (seeds 1..=N, paper-like IRB 2400 cells): targets near the validate poses and far from them, and ISO 9283 poses, driven by a nominal controller before and after `spherecal compensate`, scored on the true robot (a Markdown table).
    #[arg(long)]
    pub compensation: bool,
}

/// Most seeds a scenario runs: each is a few calibrations.
pub const MAX_SEEDS: u64 = 10_000;

/// `--scenario`: the study's scenarios (each with its title) and `all`.
fn scenario_parser() -> super::values::Keywords<String> {
    super::values::Keywords::new(
        std::iter::once(("all", Some("Every scenario")))
            .chain(SCENARIOS.iter().map(|s| (s.key, Some(s.title))))
            .collect(),
        |s| (s == "all" || SCENARIOS.iter().any(|sc| sc.key == s)).then(|| s.to_owned()),
    )
}

/// `spherecal evaluate`.
///
/// # Errors
/// Bad arguments (status 2) or a failed simulation or calibration (status 1).
pub fn run(args: &EvaluateArgs) -> Result<(), CliError> {
    if args.compensation {
        let mut studies = Vec::new();
        for seed in 1..=args.seeds {
            eprintln!("compensation study, seed {seed}…");
            studies.push(
                crate::engine::uses::compensate::study::run_seed(seed)
                    .map_err(|e| CliError::internal(e.to_string()))?,
            );
        }
        say!(
            "{}",
            crate::engine::uses::compensate::study::markdown(&studies)
        );
        return Ok(());
    }
    if args.planned_range {
        if !args.markdown {
            eprintln!(
                "planning with and without the spread, {} seed(s) each…",
                args.seeds
            );
        }
        let rows =
            planned_range_study(args.seeds).map_err(|e| CliError::internal(e.to_string()))?;
        if args.markdown {
            say!("{}", planned_range_markdown(&rows, args.seeds));
        } else {
            say!("{}", planned_range_text(&rows, args.seeds));
        }
        return Ok(());
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
        if results.iter().any(|r| !r.range_floor.is_empty()) {
            say!("\n{}", range_markdown(&results, args.seeds));
        }
    } else {
        say!("{}", text(&results, args.seeds));
    }
    Ok(())
}
