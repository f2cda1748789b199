//! The Import view's pose-file preview: the pose file read and paired
//! with the profiles or centres on a background job
//! ([`import::preview_pose_import`], reading no profile), started again
//! whenever the fields it depends on read otherwise; an older scan's
//! answer is dropped.

use crate::engine::files::import::{self, PosePreview};

use super::Core;
use crate::app::error::JobError;
use crate::app::jobs::{ImportMessage, JobMessage};

impl Core {
    /// Starts a scan of the form's pose file (or forgets the last one
    /// when there is nothing to scan).
    pub(super) fn import_scan(&mut self, ctx: &egui::Context) {
        let view = &mut self.state.import;
        view.scan_generation += 1;
        let generation = view.scan_generation;
        let key = self.forms.import.pose_scan_key();
        view.scanned.clone_from(&key);
        let spec = match (self.forms.import.pose_preview_spec(), key) {
            (Ok(spec), Some(_)) => spec,
            (Err(why), _) => {
                view.pose_preview =
                    (!self.forms.import.poses.trim().is_empty()).then_some(Err(why));
                return;
            }
            (Ok(_), None) => {
                view.pose_preview = None;
                return;
            }
        };
        let started = self.spawn(ctx, "import-scan", move |rep| {
            let outcome = import::preview_pose_import(&spec)
                .map(Box::new)
                .map_err(JobError::from);
            rep.send(JobMessage::Import(ImportMessage::Scanned {
                generation,
                outcome,
            }));
        });
        if started {
            self.state.busy.importing += 1;
        }
    }

    /// A scan's answer: kept when it is the latest scan's.
    pub(super) fn on_import_scanned(
        &mut self,
        generation: u64,
        outcome: Result<Box<PosePreview>, JobError>,
    ) {
        let view = &mut self.state.import;
        if generation != view.scan_generation {
            return;
        }
        view.pose_preview = Some(outcome.map(|p| *p).map_err(|e| e.to_string()));
    }
}
