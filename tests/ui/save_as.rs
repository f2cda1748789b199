//! Issue 34: after an import from a read-only folder, Save as proposed a
//! file in that folder, which could not be written. The proposal is the
//! pose log's folder when a file can be written there, else a writable
//! one (the current folder, else the home folder).

use std::os::unix::fs::PermissionsExt as _;
use std::path::{Path, PathBuf};

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable as _;
use spherecal::app::WorkbenchApp;
use spherecal::engine::files::format::can_write_in;

use crate::support::ui::{demo_app, settle};
use crate::workbench::write_import_files;

/// Imports `logs`' joint log and profiles with the guessed mapping; the
/// Save-as path the workbench proposes then.
fn import_from(h: &mut Harness<'_, WorkbenchApp>, logs: &Path) -> PathBuf {
    {
        let form = &mut h.state_mut().forms_mut().import;
        form.joints = logs.join("joints.csv").display().to_string().into();
        form.profiles = logs.join("profiles").display().to_string().into();
    }
    h.get_by_label("Import").click();
    h.run();
    h.get_by_label("Guess mapping").click();
    settle(h);
    h.get_by_label("Import and open").click();
    settle(h);
    let outcome = &h.state().state().import.outcome;
    assert!(matches!(outcome, Some(Ok(_))), "{outcome:?}");
    PathBuf::from(&h.state().forms().save_path)
}

#[test]
fn save_as_after_an_import_from_a_read_only_folder_proposes_a_writable_one() {
    let dir = tempfile::tempdir().expect("temp dir");
    let logs = dir.path().join("logs");
    std::fs::create_dir(&logs).expect("logs folder");
    write_import_files(&logs);
    let mode = |m: u32| std::fs::Permissions::from_mode(m);

    // Writable: beside the joint log, as before.
    let mut h = demo_app();
    let save = import_from(&mut h, &logs);
    assert_eq!(save, logs.join("joints.json"));

    // Read-only (no write bit, which refuses root too): elsewhere.
    std::fs::set_permissions(&logs, mode(0o555)).expect("read-only");
    assert!(!can_write_in(&logs));
    let mut h = demo_app();
    let save = import_from(&mut h, &logs);
    std::fs::set_permissions(&logs, mode(0o755)).expect("writable again");
    assert!(!save.starts_with(&logs), "{}", save.display());
    assert_eq!(save.file_name(), Some("joints.json".as_ref()));
    let folder = save.parent().expect("a folder");
    assert!(can_write_in(folder), "{}", folder.display());
    assert!(
        h.query_all_by_label_contains("not saved yet").count() > 0,
        "the imported session is open"
    );
}
