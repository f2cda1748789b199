//! The session on show: the central view, the selected measurement, and
//! the measurements left out of the next run and of "Save as". Nothing
//! here starts a job.

use super::Core;
use crate::app::commands::ViewCommand;
use crate::app::forms::Tab;
use crate::app::state::Level;

impl Core {
    /// Handles a [`ViewCommand`].
    pub(super) fn view(&mut self, command: ViewCommand) {
        match command {
            ViewCommand::ShowTab(tab) => {
                self.forms.tab = tab;
                if tab == Tab::Results {
                    self.state.result_unseen = false;
                }
            }
            ViewCommand::Select(i) => self.state.selected = Some(i),
            ViewCommand::Inspect(i) => {
                self.state.selected = Some(i);
                self.forms.tab = Tab::Stripe;
            }
            ViewCommand::Step(delta) => self.step(delta),
            ViewCommand::SetIncluded { id, included } => {
                if included {
                    self.state.excluded.remove(&id);
                } else {
                    self.state.excluded.insert(id);
                }
                self.say_excluded();
            }
            ViewCommand::SetStationIncluded { station, included } => {
                if let Some(l) = &self.state.loaded {
                    for m in l
                        .session
                        .measurements
                        .iter()
                        .filter(|m| m.station == station)
                    {
                        if included {
                            self.state.excluded.remove(&m.id);
                        } else {
                            self.state.excluded.insert(m.id.clone());
                        }
                    }
                }
                self.say_excluded();
            }
            ViewCommand::IncludeAll => {
                self.state.excluded.clear();
                self.say_excluded();
            }
            ViewCommand::ShowOutliers => {
                self.forms.tab = Tab::Results;
                self.forms.focus_after_fail = true;
                self.state.result_unseen = false;
                self.state.outliers_seen = true;
            }
            ViewCommand::DismissNotice => self.state.notice = None,
            ViewCommand::DismissIntro => self.state.prefs.intro_dismissed = true,
            ViewCommand::SetSensorRange(range) => {
                if let Some(loaded) = &mut self.state.loaded {
                    loaded.session.sensor_range = range;
                    self.forms.range_edit = None;
                    if range.is_some() {
                        // The planner spreads the sphere over a range it is given.
                        self.forms.plan.request.range = range;
                        self.forms.plan.request.spread = true;
                    }
                }
            }
            ViewCommand::SetTolerance(t) => {
                if t.is_valid() {
                    self.forms.tolerance = t;
                    if let Some(loaded) = &self.state.loaded {
                        self.state
                            .prefs
                            .tolerances
                            .insert(loaded.session.robot.name.clone(), t);
                    }
                }
            }
        }
    }

    /// Selects the measurement `delta` rows away in the table's order
    /// (clamped to the first and last row).
    fn step(&mut self, delta: i32) {
        let rows = self.state.visible_rows(&self.forms);
        if rows.is_empty() {
            return;
        }
        let pos = self
            .state
            .selected
            .and_then(|s| rows.iter().position(|&r| r == s));
        let next = match pos {
            None => 0,
            Some(p) => {
                let last = rows.len() - 1;
                if delta < 0 {
                    p.saturating_sub(delta.unsigned_abs() as usize)
                } else {
                    (p + delta.unsigned_abs() as usize).min(last)
                }
            }
        };
        self.state.selected = Some(rows[next]);
    }

    fn say_excluded(&mut self) {
        let n = self.state.excluded_count();
        if n == 0 {
            self.state.say(Level::Info, "every measurement is used");
        } else {
            self.state.say(
                Level::Info,
                format!("{n} measurement(s) left out: the next run skips them; Save as… keeps the choice"),
            );
        }
    }
}
