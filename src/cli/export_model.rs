//! `spherecal export-model`: writes the calibrated model of a result file
//! as the FORMAT.md `robot` block (JSON), a CSV table of MDH parameters or
//! a URDF fragment, atomically. A thin caller of
//! [`crate::engine::tools::report::model`].

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use super::CliError;
use crate::engine::files::format;
use crate::engine::tools::report::model::{self, ModelFormat};

/// Output format (`--format`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FormatArg {
    /// The FORMAT.md `robot` block (deg, mm), pasteable into a session.
    Json,
    /// The MDH table with calibrated − nominal, then base, flange and hand-eye (deg, mm).
    Csv,
    /// A URDF fragment with the calibrated joint origins (m, rad).
    Urdf,
}

impl FormatArg {
    /// How the format is called in messages.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Json => "JSON robot-block",
            Self::Csv => "MDH CSV",
            Self::Urdf => "URDF",
        }
    }
}

impl From<FormatArg> for ModelFormat {
    fn from(f: FormatArg) -> Self {
        match f {
            FormatArg::Json => Self::Json,
            FormatArg::Csv => Self::Csv,
            FormatArg::Urdf => Self::Urdf,
        }
    }
}

/// `spherecal export-model`.
#[derive(Debug, Args)]
pub struct ExportModelArgs {
    /// Result file (FORMAT.md `spherecal-result`).
    pub result: PathBuf,
    /// Output format.
    #[arg(long, value_enum)]
    pub format: FormatArg,
    /// Where to write the model.
    #[arg(long, short)]
    pub out: PathBuf,
    /// `-q`: [`QUIET_HELP`](super::QUIET_HELP).
    #[arg(long, short, help = super::QUIET_HELP)]
    pub quiet: bool,
}

/// Loads the result, exports its model and writes it atomically.
///
/// # Errors
/// [`CliError`] with status 2 when the result file cannot be read or is
/// not a valid result, or the output is refused or cannot be written.
pub fn run(args: &ExportModelArgs) -> Result<(), CliError> {
    CliError::guard_output(&args.out, &[&args.result])?;
    let result = format::load_result(&args.result).map_err(|e| CliError::from_file(&e, true))?;
    let source = args.result.display().to_string();
    let text = model::export(&result, args.format.into(), &source)
        .map_err(|e| CliError::input(format!("{e} ({source})")))?;
    format::write_atomic(&args.out, text.as_bytes()).map_err(|e| CliError::from_file(&e, false))?;
    if args.quiet {
        return Ok(());
    }
    sayln!(
        "wrote the {} model of {} to {}",
        args.format.name(),
        args.result.display(),
        args.out.display()
    );
    Ok(())
}
