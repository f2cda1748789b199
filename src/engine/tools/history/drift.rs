//! Drift over time: per robot, each parameter's series of results and the
//! jumps between consecutive results beyond `k` combined σ.

use std::collections::HashSet;

use super::entry::coupled_twist;
use super::{
    Combination, DEFAULT_K, DEFAULT_TOP, Entry, HistoryError, Library, Mount, PRIOR_HELD_FRACTION,
    ParamValue, Status, Timestamp, Unit, hand_eye_names,
};
use crate::engine::base::geometry::wrap_deg;
use crate::engine::base::numeric::median;
use crate::engine::base::robot::{Joint, PARAM_IS_ANGLE, PARAMS_PER_JOINT, Robot};
use crate::engine::calibrate::solve::estimate::ANGLE_SCALE_MM;

/// Settings of [`drift`].
#[derive(Debug, Clone, PartialEq)]
pub struct DriftOptions {
    /// Flag a change beyond `k` combined σ ([`DEFAULT_K`]).
    pub k: f64,
    /// Number of main kinematic deviations shown ([`DEFAULT_TOP`]).
    pub top: usize,
    /// Kinematic parameters to show as well (`theta3`, `d4`).
    pub extra: Vec<String>,
}

impl Default for DriftOptions {
    fn default() -> Self {
        Self {
            k: DEFAULT_K,
            top: DEFAULT_TOP,
            extra: Vec::new(),
        }
    }
}

/// Why a series is shown.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SeriesKind {
    /// One of the six sensor values: the hand-eye's, or a fixed sensor's
    /// `base_from_sensor` ([`Drift::mount`]).
    HandEye,
    /// A main kinematic deviation: `rank` 1 is the largest, `score` the
    /// median `|value| / σ` (or the median `|value|` in mm of effect when
    /// no result has a σ, see `by_sigma`).
    Main {
        /// 1-based rank.
        rank: usize,
        /// Ranking score.
        score: f64,
        /// Whether `score` is in σ (else mm of effect).
        by_sigma: bool,
    },
    /// Chosen by the caller ([`DriftOptions::extra`]).
    Chosen,
    /// Not among the above, but a jump was flagged in it.
    Jumped,
}

impl SeriesKind {
    /// In words, for tables and CSV; the sensor values by `mount`
    /// ("hand-eye", "base from sensor").
    #[must_use]
    pub fn label(&self, mount: Mount) -> String {
        match self {
            Self::HandEye => match mount {
                Mount::Flange => "hand-eye".into(),
                Mount::Fixed => "base from sensor".into(),
            },
            Self::Main { rank, .. } => format!("main {rank}"),
            Self::Chosen => "chosen".into(),
            Self::Jumped => "jumped".into(),
        }
    }
}

/// One value of a series.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// Index into [`Library::entries`].
    pub entry: usize,
    /// The entry's date.
    pub date: Timestamp,
    /// Hand-eye: the calibrated value (angles unwrapped along the series,
    /// so a roll near ±180° does not leap by 360°). Kinematic: calibrated
    /// minus [`Drift::reference`].
    pub value: f64,
    /// 1σ when the result has one.
    pub sigma: Option<f64>,
    /// Estimated, fixed or unknown in this result.
    pub status: Status,
    /// Held near nominal by the prior in this result.
    pub prior_held: bool,
}

/// One parameter over time.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// [`HAND_EYE_NAMES`] or a kinematic label.
    pub name: String,
    /// Unit of the values.
    pub unit: Unit,
    /// Why it is shown.
    pub kind: SeriesKind,
    /// One point per result, in date order.
    pub points: Vec<Point>,
}

/// The outcome of one check.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    /// `|change| > k · combined σ`.
    Jump,
    /// Within `k · combined σ`.
    Steady,
    /// No check was possible; the reason.
    NotChecked(String),
}

/// One parameter between two consecutive results.
#[derive(Debug, Clone, PartialEq)]
pub struct JumpCheck {
    /// Parameter name.
    pub parameter: String,
    /// Unit of the values.
    pub unit: Unit,
    /// Index into [`Library::entries`] of the earlier result.
    pub from: usize,
    /// Index of the later result.
    pub to: usize,
    /// Value in the earlier result (as in the series).
    pub before: f64,
    /// Value in the later result.
    pub after: f64,
    /// `after − before` (angles wrapped to ±180°).
    pub change: f64,
    /// 1σ of the earlier value.
    pub sigma_before: Option<f64>,
    /// 1σ of the later value.
    pub sigma_after: Option<f64>,
    /// `sqrt(σ_before² + σ_after²)`.
    pub combined: Option<f64>,
    /// `|change| / combined`.
    pub ratio: Option<f64>,
    /// Jump, steady or not checked.
    pub verdict: Verdict,
    /// Cautions: prior-held, fixed parameters it carries.
    pub notes: Vec<String>,
}

impl JumpCheck {
    /// Whether a jump was flagged.
    #[must_use]
    pub fn is_jump(&self) -> bool {
        self.verdict == Verdict::Jump
    }
}

/// One robot's results over time (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Drift {
    /// Robot name.
    pub robot: String,
    /// Indices into [`Library::entries`], in date order.
    pub entries: Vec<usize>,
    /// Nominal model the kinematic deviations are measured from: the
    /// earliest result's (deg, mm).
    pub reference: Vec<Joint>,
    /// `k` of the jump check.
    pub k: f64,
    /// The mount of the earliest result: the six sensor series are the
    /// hand-eye's (`hand_eye.x` …) or a fixed sensor's `base_from_sensor`
    /// (`base_from_sensor.x` …).
    pub mount: Mount,
    /// Hand-eye series, then main, chosen and jumped kinematic ones.
    pub series: Vec<Series>,
    /// Every check between consecutive results, in date order, hand-eye
    /// first; parameters fixed in both results are not listed.
    pub checks: Vec<JumpCheck>,
    /// Cautions about the whole series (nominal models that differ,
    /// results on the same date, dates from file times).
    pub notes: Vec<String>,
}

impl Drift {
    /// The flagged jumps.
    pub fn jumps(&self) -> impl Iterator<Item = &JumpCheck> {
        self.checks.iter().filter(|c| c.is_jump())
    }

    /// A series by parameter name.
    #[must_use]
    pub fn series(&self, name: &str) -> Option<&Series> {
        self.series.iter().find(|s| s.name == name)
    }
}

/// Value, σ, status and prior flag of parameter `index` of an entry, the
/// kinematic ones measured from `reference`.
pub(super) fn value_from(entry: &Entry, index: usize, reference: &[Joint]) -> Option<ParamValue> {
    let p = entry.params.get(index)?;
    if index < 6 {
        return Some(p.clone());
    }
    let k = index - 6;
    let joint = k / PARAMS_PER_JOINT;
    let which = k % PARAMS_PER_JOINT;
    let value = entry.calibrated.get(joint)?.get(which) - reference.get(joint)?.get(which);
    Some(ParamValue {
        value: if p.unit == Unit::Deg {
            wrap_deg(value)
        } else {
            value
        },
        ..p.clone()
    })
}

/// The labels (`ml`'s, e.g. `he_z`, `theta3`) a parameter goes by in
/// combinations.
pub(super) fn method_labels<'a>(index: usize, name: &'a str, entry: &Entry) -> Vec<&'a str> {
    if index < 6 {
        coupled_twist(&entry.hand_eye.rotation(), index)
    } else {
        vec![name]
    }
}

/// One robot's drift: its results in date order, the series to show and
/// every jump check (see the module docs).
///
/// # Errors
/// [`HistoryError::UnknownRobot`] when no result has this robot name
/// (exact; use [`Library::find_robot`] for a partial name),
/// [`HistoryError::InvalidK`], [`HistoryError::UnknownParameter`] for an
/// `extra` name that is not a kinematic parameter of the robot.
pub fn drift(
    library: &Library,
    robot: &str,
    options: &DriftOptions,
) -> Result<Drift, HistoryError> {
    if !(options.k.is_finite() && options.k > 0.0) {
        return Err(HistoryError::InvalidK { k: options.k });
    }
    let entries: Vec<usize> = (0..library.entries.len())
        .filter(|&i| library.entries[i].robot == robot)
        .collect();
    let Some(&first) = entries.first() else {
        return Err(HistoryError::UnknownRobot {
            query: robot.to_string(),
            known: library.robots().into_iter().map(|(n, _)| n).collect(),
        });
    };
    let reference = library.entries[first].nominal.clone();
    let mount = library.entries[first].mount;
    let sensor_names = hand_eye_names(mount);
    let n_params = 6 + PARAMS_PER_JOINT * reference.len();
    let names: Vec<String> = (0..n_params)
        .map(|i| {
            if i < 6 {
                sensor_names[i].to_string()
            } else {
                Robot::param_label(i - 6)
            }
        })
        .collect();
    for extra in &options.extra {
        if !names.iter().skip(6).any(|n| n == extra) {
            return Err(HistoryError::UnknownParameter {
                name: extra.clone(),
                robot: robot.to_string(),
                count: n_params - 6,
            });
        }
    }
    let mut notes = drift_notes(library, &entries, &reference);
    let other_mount = entries
        .iter()
        .filter(|&&e| library.entries[e].mount != mount)
        .count();
    if other_mount > 0 {
        notes.push(format!(
            "{other_mount} of {} results have the sensor {} while the earliest has it {}: their six sensor values ({}) are another transform and are not comparable; keep one mount in the folder",
            entries.len(),
            mount_words(if mount == Mount::Flange { Mount::Fixed } else { Mount::Flange }),
            mount_words(mount),
            if mount == Mount::Flange { "base_from_sensor, not the hand-eye" } else { "the hand-eye, not base_from_sensor" },
        ));
    }

    // Values of every parameter at every entry.
    let values: Vec<Vec<Option<ParamValue>>> = (0..n_params)
        .map(|i| {
            entries
                .iter()
                .map(|&e| value_from(&library.entries[e], i, &reference))
                .collect()
        })
        .collect();

    let checks = jump_checks(library, &entries, &names, &values, options.k);

    // Main kinematic deviations.
    let any_sigma = (6..n_params).any(|i| {
        values[i]
            .iter()
            .flatten()
            .any(|p| p.sigma.is_some() && p.status == Status::Estimated)
    });
    let mut ranked: Vec<(usize, f64)> = (6..n_params)
        .filter_map(|i| {
            let vals = values[i]
                .iter()
                .flatten()
                .filter(|p| p.status != Status::Fixed);
            let scores: Vec<f64> = if any_sigma {
                vals.filter_map(|p| p.sigma.filter(|s| *s > 0.0).map(|s| p.value.abs() / s))
                    .collect()
            } else {
                vals.map(|p| {
                    if p.unit == Unit::Deg {
                        p.value.abs().to_radians() * ANGLE_SCALE_MM
                    } else {
                        p.value.abs()
                    }
                })
                .collect()
            };
            median(&scores).map(|m| (i, m))
        })
        .collect();
    ranked.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));

    let mut chosen: Vec<(usize, SeriesKind)> = (0..6).map(|i| (i, SeriesKind::HandEye)).collect();
    for (rank, &(i, score)) in ranked.iter().take(options.top).enumerate() {
        chosen.push((
            i,
            SeriesKind::Main {
                rank: rank + 1,
                score,
                by_sigma: any_sigma,
            },
        ));
    }
    for extra in &options.extra {
        if let Some(i) = names.iter().position(|n| n == extra)
            && !chosen.iter().any(|(c, _)| *c == i)
        {
            chosen.push((i, SeriesKind::Chosen));
        }
    }
    for c in checks.iter().filter(|c| c.is_jump()) {
        if let Some(i) = names.iter().position(|n| *n == c.parameter)
            && !chosen.iter().any(|(x, _)| *x == i)
        {
            chosen.push((i, SeriesKind::Jumped));
        }
    }
    let series = chosen
        .into_iter()
        .map(|(i, kind)| Series {
            name: names[i].clone(),
            unit: if i < 3 || (i >= 6 && !PARAM_IS_ANGLE[(i - 6) % PARAMS_PER_JOINT]) {
                Unit::Mm
            } else {
                Unit::Deg
            },
            kind,
            points: series_points(library, &entries, &values[i]),
        })
        .collect();
    if entries.len() < 2 {
        notes.push("one result only: nothing to compare yet".into());
    }
    Ok(Drift {
        robot: robot.to_string(),
        entries,
        reference,
        k: options.k,
        mount,
        series,
        checks,
        notes,
    })
}

/// Where the sensor stands, in words.
fn mount_words(mount: Mount) -> &'static str {
    match mount {
        Mount::Flange => "on the flange",
        Mount::Fixed => "fixed in the cell",
    }
}

pub(super) fn series_points(
    library: &Library,
    entries: &[usize],
    values: &[Option<ParamValue>],
) -> Vec<Point> {
    let mut out: Vec<Point> = Vec::with_capacity(entries.len());
    for (&e, v) in entries.iter().zip(values) {
        let Some(v) = v else { continue };
        let value = match (v.unit, out.last()) {
            (Unit::Deg, Some(prev)) => prev.value + wrap_deg(v.value - prev.value),
            _ => v.value,
        };
        out.push(Point {
            entry: e,
            date: library.entries[e].date,
            value,
            sigma: v.sigma,
            status: v.status,
            prior_held: v.prior_held,
        });
    }
    out
}

pub(super) fn drift_notes(
    library: &Library,
    entries: &[usize],
    reference: &[Joint],
) -> Vec<String> {
    let mut notes = Vec::new();
    let differs: Vec<String> = entries
        .iter()
        .map(|&e| &library.entries[e])
        .filter(|e| {
            e.nominal.len() != reference.len()
                || e.nominal
                    .iter()
                    .zip(reference)
                    .any(|(a, b)| (0..PARAMS_PER_JOINT).any(|k| (a.get(k) - b.get(k)).abs() > 1e-9))
        })
        .map(|e| e.date.to_string())
        .collect();
    if !differs.is_empty() {
        notes.push(format!(
            "the nominal model differs in the results of {}: kinematic deviations are measured from the earliest result's nominal model",
            differs.join(", ")
        ));
    }
    let from_files = entries
        .iter()
        .filter(|&&e| !library.entries[e].date_source.is_from_name())
        .count();
    if from_files > 0 {
        notes.push(format!(
            "{from_files} of {} dates come from file times, which change when files are copied; put the date in the session name (YYYY-MM-DD)",
            entries.len()
        ));
    }
    let mut shared: Vec<String> = entries
        .windows(2)
        .map(|w| (&library.entries[w[0]], &library.entries[w[1]]))
        .filter(|(a, b)| a.date == b.date)
        .map(|(a, _)| a.date.to_string())
        .collect();
    shared.dedup();
    if !shared.is_empty() {
        notes.push(format!(
            "several results share a date ({}): among themselves they are in file path order",
            shared.join(", ")
        ));
    }
    notes
}

/// Fixed parameters that differ between two results, and every label that
/// belongs to a combination with one of them.
pub(super) fn differing_fixed(a: &Entry, b: &Entry) -> (Vec<String>, HashSet<String>) {
    if a.estimated.is_empty() || b.estimated.is_empty() {
        // A method that does not say what it estimated: nothing to compare.
        return (Vec::new(), HashSet::new());
    }
    let fa: HashSet<&String> = a.fixed.iter().collect();
    let fb: HashSet<&String> = b.fixed.iter().collect();
    let mut diff: Vec<String> = fa.symmetric_difference(&fb).map(|s| (*s).clone()).collect();
    diff.sort();
    let mut involved: HashSet<String> = diff.iter().cloned().collect();
    for c in a.combinations.iter().chain(&b.combinations) {
        if c.fixed.iter().any(|f| diff.contains(f)) {
            involved.extend(c.partners.iter().cloned());
            involved.extend(c.fixed.iter().cloned());
        }
    }
    (diff, involved)
}

/// Whether a value can be judged against another: estimated, with a σ.
pub(super) fn comparable(p: &ParamValue) -> bool {
    p.status != Status::Fixed && p.sigma.is_some()
}

/// Every check of every parameter: each result against the latest earlier
/// result in which the parameter is comparable (so a `paper` result in
/// between does not break the chain of `ml` results), or, when the result
/// itself is not comparable, against the result just before it (a "not
/// checked" row). Sorted by the later result, then parameter order.
pub(super) fn jump_checks(
    library: &Library,
    entries: &[usize],
    names: &[String],
    values: &[Vec<Option<ParamValue>>],
    k: f64,
) -> Vec<JumpCheck> {
    let mut out: Vec<(usize, usize, JumpCheck)> = Vec::new();
    for (i, name) in names.iter().enumerate() {
        let mut last: Option<usize> = None;
        let mut prev: Option<usize> = None;
        for (w, v) in values[i].iter().enumerate() {
            let Some(b) = v else { continue };
            let from = if comparable(b) { last.or(prev) } else { prev };
            // Nothing identifiable to compare: fixed in one result and not
            // estimated in the other (fixed too, or a method that does not say).
            let identifiable = |p: &ParamValue| p.status == Status::Estimated;
            if let Some(wa) = from
                && let Some(a) = &values[i][wa]
                && !((a.status == Status::Fixed || b.status == Status::Fixed)
                    && !(identifiable(a) || identifiable(b)))
            {
                let between = (wa + 1..w).filter(|&x| values[i][x].is_some()).count();
                let pair = (&library.entries[entries[wa]], &library.entries[entries[w]]);
                let mut c = check(pair, (entries[wa], entries[w]), name, i, (a, b), k);
                if between > 0 {
                    c.notes.push(format!(
                        "compared with the result of {}: the {} between have no σ for it",
                        pair.0.date,
                        if between == 1 {
                            "result".to_string()
                        } else {
                            format!("{between} results")
                        }
                    ));
                }
                out.push((w, i, c));
            }
            if comparable(b) {
                last = Some(w);
            }
            prev = Some(w);
        }
    }
    out.sort_by_key(|(w, i, _)| (*w, *i));
    out.into_iter().map(|(_, _, c)| c).collect()
}

/// One check of parameter `name` (index `i`) from result `a` to `b`.
pub(super) fn check(
    (ea, eb): (&Entry, &Entry),
    (ia, ib): (usize, usize),
    name: &str,
    i: usize,
    (a, b): (&ParamValue, &ParamValue),
    k: f64,
) -> JumpCheck {
    let change = if a.unit == Unit::Deg {
        wrap_deg(b.value - a.value)
    } else {
        b.value - a.value
    };
    let labels = method_labels(i, name, ea);
    let (diff, involved) = differing_fixed(ea, eb);
    let mut notes = Vec::new();
    if a.prior_held || b.prior_held {
        notes.push(format!(
            "held near nominal by the ml prior (σ ≥ {PRIOR_HELD_FRACTION} × prior σ): the data barely see it, so a real change is shrunk"
        ));
    }
    let mut carried: Vec<&Combination> = eb
        .combinations
        .iter()
        .filter(|c| c.partners.iter().any(|p| labels.contains(&p.as_str())))
        .collect();
    carried.dedup_by(|x, y| x.text == y.text);
    for c in carried {
        notes.push(format!(
            "may also be a change of {} (fixed; {})",
            c.fixed.join(", "),
            c.text
        ));
    }
    let not_checked = if a.status == Status::Fixed || b.status == Status::Fixed {
        Some("estimated in one result, fixed in the other".to_string())
    } else if a.sigma.is_none() || b.sigma.is_none() {
        let mut methods: Vec<&str> = [(ea, a), (eb, b)]
            .iter()
            .filter(|(_, p)| p.sigma.is_none())
            .map(|(e, _)| e.method.as_str())
            .collect();
        methods.dedup();
        Some(format!(
            "no uncertainty in the result ({} method): a change cannot be judged",
            methods.join(" and ")
        ))
    } else if !diff.is_empty() && labels.iter().any(|l| involved.contains(*l)) {
        Some(format!(
            "the results fixed different parameters ({}), so this value carries different combinations",
            diff.join(", ")
        ))
    } else {
        None
    };
    let combined = match (a.sigma, b.sigma) {
        (Some(sa), Some(sb)) => Some(sa.hypot(sb)),
        _ => None,
    };
    let ratio = combined.filter(|c| *c > 0.0).map(|c| change.abs() / c);
    let verdict = match (not_checked, ratio) {
        (Some(reason), _) => Verdict::NotChecked(reason),
        (None, Some(r)) if r > k => Verdict::Jump,
        (None, Some(_)) => Verdict::Steady,
        (None, None) => Verdict::NotChecked("zero uncertainty".into()),
    };
    JumpCheck {
        parameter: name.to_string(),
        unit: a.unit,
        from: ia,
        to: ib,
        before: a.value,
        after: a.value + change,
        change,
        sigma_before: a.sigma,
        sigma_after: b.sigma,
        combined,
        ratio,
        verdict,
        notes,
    }
}
