//! `spherecal`: parse the command line, then start the workbench or run a
//! command. All work is in the library.

use std::process::ExitCode;

use spherecal::cli::{self, Cli, CliError, Command};

fn main() -> ExitCode {
    // Ctrl-C or a kill: remove the temporary file of a write under way
    // (the target keeps its old content), then end as interrupted.
    let _ = ctrlc::set_handler(|| {
        spherecal::engine::files::format::remove_pending();
        std::process::exit(130);
    });
    let parsed = Cli::parse_args();
    let outcome = match parsed.command {
        Some(Command::Calibrate(args)) => cli::calibrate_command(&args),
        Some(Command::Simulate(args)) => cli::simulate_fixed::dispatch(&args),
        Some(Command::Gui(args)) => gui(args.session, args.result),
        Some(Command::Evaluate(args)) => cli::evaluate::run(&args),
        Some(Command::ExportModel(args)) => cli::export_model::run(&args),
        Some(Command::Import(args)) => cli::import::run(&args),
        Some(Command::Measure(args)) => cli::measure::run(&args),
        Some(Command::Plan(args)) => cli::plan_fixed::dispatch(&args),
        Some(Command::Report(args)) => cli::html_report::run(&args),
        Some(Command::History(args)) => cli::history::run(&args),
        Some(Command::Compensate(args)) => cli::compensate::run(&args),
        Some(Command::Check(args)) => cli::check::run(&args),
        None => gui(None, None),
    };
    // The text a command printed must have reached its reader.
    let outcome = outcome.and_then(|()| cli::stdout_result());
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        // Interrupted while failing (a write stopped by Ctrl-C): the
        // interruption is the news, with its status.
        Err(_) if spherecal::engine::files::format::interrupted() => ExitCode::from(130),
        Err(e) => {
            eprintln!("error: {}", cli::error_line(&e.message));
            ExitCode::from(u8::try_from(e.status).unwrap_or(1))
        }
    }
}

/// The workbench; without a display, status 2 and one sentence naming
/// DISPLAY/WAYLAND_DISPLAY and the commands that need none. A window
/// that cannot be opened (a display that does not answer) is the same
/// kind of failure: the machine's, not spherecal's.
#[cfg(feature = "gui")]
fn gui(
    session: Option<std::path::PathBuf>,
    result: Option<std::path::PathBuf>,
) -> Result<(), CliError> {
    cli::check_display()?;
    if let Some(shot) = spherecal::screenshots::Request::from_env().map_err(CliError::input)? {
        return spherecal::screenshots::run(shot, session, result).map_err(CliError::input);
    }
    spherecal::app::run(session, result).map_err(CliError::input)
}

#[cfg(not(feature = "gui"))]
fn gui(
    _session: Option<std::path::PathBuf>,
    _result: Option<std::path::PathBuf>,
) -> Result<(), CliError> {
    // Built without the workbench: show what the command line offers.
    let _ = <Cli as clap::CommandFactory>::command().print_help();
    println!();
    Err(CliError::input(
        "this build has no workbench (built without the `gui` feature); use `spherecal calibrate SESSION --out RESULT`",
    ))
}
