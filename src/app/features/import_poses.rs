//! The Import view's pose-file preview: the pose file read and paired
//! with the profiles or centres on a background job
//! ([`import::preview_pose_import`], reading no profile), started again
//! whenever the fields it depends on read otherwise; a scan started
//! since replaces the last (whose answer is dropped).

use crate::engine::files::import::{self, PosePreview};

use super::Core;
use crate::app::error::JobError;
use crate::app::job::{Job, Slot};
use crate::app::ledger::Artefact;

impl Core {
    /// Starts a scan of the form's pose file (or forgets the last one
    /// when there is nothing to scan).
    pub(super) fn import_scan(&mut self, ctx: &egui::Context) {
        let stamp = self.state.ledger.stamp(Artefact::PoseScan);
        let view = &mut self.state.import;
        let form = &self.forms.import;
        let spec = match (form.pose_preview_spec(), form.pose_scan_key()) {
            (Ok(spec), Some(_)) => spec,
            (spec, _) => {
                // Nothing to read: why, or nothing at all.
                view.pose_preview = match spec {
                    Err(why) if !form.poses.trim().is_empty() => Some(Err(why)),
                    _ => None,
                };
                self.state.jobs.cancel(&Slot::PoseScan);
                self.state
                    .ledger
                    .record(Artefact::PoseScan, stamp, "nothing");
                return;
            }
        };
        self.start(ctx, Slot::PoseScan, stamp, move |_| {
            import::preview_pose_import(&spec)
                .map(Box::new)
                .map_err(JobError::from)
        });
    }

    /// The latest scan's answer.
    pub(super) fn on_import_scanned(
        &mut self,
        job: &Job,
        outcome: Result<Box<PosePreview>, JobError>,
    ) {
        let what = "the pose file's preview";
        self.state
            .ledger
            .record(Artefact::PoseScan, job.stamp.clone(), what);
        self.state.import.pose_preview = Some(outcome.map(|p| *p).map_err(|e| e.to_string()));
    }
}
