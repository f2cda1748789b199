//! Every parameter of every result of a drift as CSV.

use std::fmt::Write as _;

use super::Library;
use super::drift::{Drift, value_from};
use crate::engine::base::robot::PARAMS_PER_JOINT;
use crate::engine::files::table::csv_field;

/// The drifts as CSV, one row per result and parameter (every hand-eye and
/// kinematic parameter, not only the shown series), values at full
/// precision: `robot, date, date_source, result, session, method,
/// parameter, unit, value, sigma, status, prior_held, series`. `value` is
/// as in the series (kinematic: calibrated minus the drift's reference
/// nominal); `sigma` is empty when the result has none; `series` says why
/// the drift shows the parameter (`hand-eye`, `main 1`, `chosen`,
/// `jumped`) and is empty when it does not.
#[must_use]
pub fn drift_csv(library: &Library, drifts: &[Drift]) -> String {
    let mut s = String::from(
        "robot,date,date_source,result,session,method,parameter,unit,value,sigma,status,prior_held,series\n",
    );
    for d in drifts {
        let n_params = 6 + PARAMS_PER_JOINT * d.reference.len();
        for &e in &d.entries {
            let entry = &library.entries[e];
            for i in 0..n_params {
                let Some(v) = value_from(entry, i, &d.reference) else {
                    continue;
                };
                let (value, kind) = match d.series(&v.name) {
                    Some(series) => (
                        series
                            .points
                            .iter()
                            .find(|p| p.entry == e)
                            .map_or(v.value, |p| p.value),
                        series.kind.label(d.mount),
                    ),
                    None => (v.value, String::new()),
                };
                let _ = writeln!(
                    s,
                    "{},{},{},{},{},{},{},{},{},{},{},{},{}",
                    csv_field(&d.robot),
                    entry.date,
                    entry.date_source.as_str(),
                    csv_field(&entry.path.display().to_string()),
                    csv_field(&entry.session),
                    csv_field(&entry.method),
                    v.name,
                    v.unit.as_str(),
                    value,
                    v.sigma.map(|x| x.to_string()).unwrap_or_default(),
                    v.status.as_str(),
                    v.prior_held,
                    kind
                );
            }
        }
    }
    s
}
