//! The egui workbench (being built; see issue "The workbench").

/// Opens the workbench window.
///
/// # Errors
/// Always, until the workbench lands.
pub fn run(
    _session: Option<std::path::PathBuf>,
    _result: Option<std::path::PathBuf>,
) -> Result<(), String> {
    Err("the workbench is not built yet; use `spherecal calibrate`".into())
}
