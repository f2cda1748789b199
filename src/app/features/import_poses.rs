//! The Import view's pose-file preview: the pose file read and paired
//! with the profiles or centres on a background job
//! ([`import::preview_pose_import`], reading no profile), started again
//! whenever the fields it depends on read otherwise; a scan started
//! since replaces the last (whose answer is dropped).

use crate::engine::files::import::{self, PosePreview};

use super::Core;
use crate::app::error::JobError;
use crate::app::job::Slot;
use crate::app::provenance::Stamp;

impl Core {
    /// Starts a scan of the form's pose file (or forgets the last one
    /// when there is nothing to scan).
    pub(super) fn import_scan(&mut self, ctx: &egui::Context) {
        let key = self.forms.import.pose_scan_key();
        let view = &mut self.state.import;
        view.scanned.clone_from(&key);
        let spec = match (self.forms.import.pose_preview_spec(), key) {
            (Ok(spec), Some(_)) => spec,
            (Err(why), _) => {
                view.pose_preview =
                    (!self.forms.import.poses.trim().is_empty()).then_some(Err(why));
                self.state.jobs.cancel(&Slot::PoseScan);
                return;
            }
            (Ok(_), None) => {
                view.pose_preview = None;
                self.state.jobs.cancel(&Slot::PoseScan);
                return;
            }
        };
        self.start(ctx, Slot::PoseScan, Stamp::default(), move |_| {
            import::preview_pose_import(&spec)
                .map(Box::new)
                .map_err(JobError::from)
        });
    }

    /// The latest scan's answer.
    pub(super) fn on_import_scanned(&mut self, outcome: Result<Box<PosePreview>, JobError>) {
        self.state.import.pose_preview = Some(outcome.map(|p| *p).map_err(|e| e.to_string()));
    }
}
