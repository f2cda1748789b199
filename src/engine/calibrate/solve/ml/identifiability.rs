//! Which parameters the data identify: QR with column pivoting of the
//! whitened, centre-projected Jacobian of all `6 + 5n` parameters, with the
//! standard minimal model preferred among exact redundancies, and the
//! combination each fixed parameter forms with the estimated ones.

use nalgebra::{DMatrix, DVector, Vector3};

use super::SETUP_CHECK;
use super::problem::Obs;
use crate::engine::base::numeric::as_written;
pub use crate::engine::base::records::ml::{Inseparable, Partner};
use crate::engine::calibrate::handeye::Sighting;
use crate::engine::calibrate::solve::estimate::unknown_scale;
use crate::engine::calibrate::solve::estimate::{
    Estimate, sensitivity, unknown_is_angle, unknown_label,
};

/// Default relative pivot tolerance of the identifiability QR: exact
/// redundancies of the model (rigid motions, `d6 ~ he_z`) leave pivots of
/// ~1e-12 |R_11|, the weakest real direction on the IRB 2400 (hand-eye
/// rotation) ~1e-3; 1e-7 separates them with margin on both sides.
pub const DEFAULT_RANK_TOLERANCE: f64 = 1e-7;

/// Columns of the identifiability QR whose norms agree to this relative
/// amount are a tie; the lower index (hand-eye first, then base to flange)
/// is kept.
pub(super) const PIVOT_TIE_REL: f64 = 1e-6;

/// Weight of a "conventionally redundant" parameter's column in the pivot
/// choice (see [`pivot_preference`]). Exact redundancies tie the columns
/// of a group; the weight makes the QR fix this member, without moving
/// any real direction below the rank tolerance (the weakest real pivot,
/// ~6e-3, stays ~1e4 × above it).
pub(super) const REDUNDANT_WEIGHT: f64 = 1e-3;

/// `|sin(alpha)|` below this counts as parallel consecutive axes (Hayati's
/// `beta` is the right parameter there, `d` of the previous joint is not).
pub(super) const PARALLEL_SIN: f64 = 0.1;

/// A fixed parameter's column shorter than this fraction of `|R_11|` moves
/// no distance at all (a rigid motion); otherwise it is named with the
/// estimated parameters that compensate it.
pub(super) const NO_EFFECT_REL: f64 = 1e-9;

/// A compensating parameter is named when its share (scaled, mm of motion)
/// is at least this fraction of the largest share.
pub(super) const SHOWN_SHARE: f64 = 0.1;

/// The identifiability analysis of the parameters.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Identifiability {
    /// Estimated unknowns (indices into ΔY), ascending.
    pub(super) estimated: Vec<usize>,
    /// Fixed unknowns, ascending.
    pub(super) fixed: Vec<usize>,
    /// Pivot order with `|R_kk| / |R_11|`.
    pub(super) pivots: Vec<(usize, f64)>,
    /// Named combinations that cannot be separated.
    pub(super) inseparable: Vec<Inseparable>,
}

/// The sensitivity of [`sensitivity`] for a sighting whose sensor-frame
/// centre is moved to where `point` (base frame, mm) appears in its pose:
/// the Jacobian of a model that fits the station exactly. At a start far
/// from the truth a station's sightings scatter by millimetres, which makes
/// a rigid motion of the base look weakly visible (it rotates the
/// residuals without changing the cost); at the station's point it is
/// exactly null, as it is for distances, and every exact redundancy of
/// the model (`theta6` with the hand-eye, say) stays exact.
pub(super) fn sensitivity_at(est: &Estimate, s: &Sighting, point: &Vector3<f64>) -> DMatrix<f64> {
    let station_from_sensor = est.station_from_sensor(&s.base_from_flange(&est.robot));
    let moved = Sighting {
        id: s.id.clone(),
        joints: s.joints.clone(),
        flange: s.flange,
        centre_in_sensor: station_from_sensor
            .inverse_transform_point(&nalgebra::Point3::from(*point))
            .coords,
    };
    sensitivity(est, &moved).1
}

/// Pivot weight of ΔY unknown `u` for the nominal `robot`: 1, or
/// [`REDUNDANT_WEIGHT`] for the parameters that the standard minimal
/// model leaves out, so that within an exactly dependent group these are
/// the ones fixed: Hayati's `beta_i` where axis `i` is not parallel to
/// axis `i−1`, `d_{i−1}` where it is (the position along a parallel axis
/// is arbitrary), and the last joint's `theta_n` and `d_n` (the hand-eye
/// duplicates them). Fixing the conventional member keeps the estimated
/// values close to the physical deviations, which is what a prior on them
/// assumes; a different member would have to absorb e.g. a 0.76° `theta3`
/// as `beta4` and 1.8 mm of `d4`.
pub(super) fn pivot_preference(robot: &crate::engine::base::robot::Robot, u: usize) -> f64 {
    if u < 6 {
        return 1.0;
    }
    let k = u - 6;
    let (joint, which) = (
        k / crate::engine::base::robot::PARAMS_PER_JOINT,
        k % crate::engine::base::robot::PARAMS_PER_JOINT,
    );
    let n = robot.joints.len();
    let parallel_to_previous =
        |j: usize| j > 0 && robot.joints[j].alpha.to_radians().sin().abs() < PARALLEL_SIN;
    let redundant = match which {
        // beta
        2 => joint > 0 && !parallel_to_previous(joint),
        // theta
        3 => joint + 1 == n,
        // d
        4 => joint + 1 == n || (joint + 1 < n && parallel_to_previous(joint + 1)),
        _ => false,
    };
    if redundant { REDUNDANT_WEIGHT } else { 1.0 }
}

/// [`pivot_preference`] for the estimate's mount. With a fixed sensor the
/// first joint's five parameters (the frame before the first moving axis)
/// are exactly what `bT_s` already holds (a sensor standing in the cell
/// cannot tell a shifted base from a shifted sensor), so they are the
/// members fixed and `base_from_sensor` is estimated.
pub(super) fn pivot_weight(est: &Estimate, u: usize) -> f64 {
    let first_joint = (6..6 + crate::engine::base::robot::PARAMS_PER_JOINT).contains(&u);
    if est.mount == crate::engine::base::session::Mount::Fixed && first_joint {
        REDUNDANT_WEIGHT
    } else {
        pivot_preference(&est.robot, u)
    }
}

/// QR with column pivoting of the projected, scaled, whitened Jacobian of
/// all `6 + 5n` parameters (modified Gram-Schmidt, re-orthogonalised), and
/// the naming of the fixed parameters. `go_on` is asked every
/// [`SETUP_CHECK`] measurements and at every pivot; `None` when it
/// says stop.
pub(super) fn identifiability(
    obs: &[Obs],
    n_stations: usize,
    est: &Estimate,
    tol: f64,
    go_on: &mut dyn FnMut() -> bool,
) -> Option<Identifiability> {
    let n_unknowns = 6 + est.robot.n_params();
    // Projected Jacobian, station by station.
    let mut blocks: Vec<DMatrix<f64>> = Vec::new();
    // Each station's observations, grouped once (a scan per station is
    // quadratic: half a second at 3,000 stations).
    let mut members: Vec<Vec<&Obs>> = vec![Vec::new(); n_stations];
    for o in obs {
        if let Some(m) = members.get_mut(o.station) {
            m.push(o);
        }
    }
    let mut unchecked = 0;
    for mine in members {
        unchecked += mine.len();
        if unchecked >= SETUP_CHECK {
            unchecked = 0;
            if !go_on() {
                return None;
            }
        }
        if mine.is_empty() {
            continue;
        }
        let rows = 3 * mine.len();
        let mut jp = DMatrix::zeros(rows, n_unknowns);
        let mut jc = DMatrix::zeros(rows, 3);
        let point = mine
            .iter()
            .map(|o| est.centre_in_base(&o.sighting))
            .sum::<Vector3<f64>>()
            / mine.len() as f64;
        for (i, o) in mine.iter().enumerate() {
            let a = sensitivity_at(est, &o.sighting, &point);
            for u in 0..n_unknowns {
                let col: Vector3<f64> = o.whiten * a.fixed_view::<3, 1>(0, u) / unknown_scale(u);
                jp.fixed_view_mut::<3, 1>(3 * i, u).copy_from(&col);
            }
            jc.view_mut((3 * i, 0), (3, 3)).copy_from(&(-o.whiten));
        }
        let ctc = jc.transpose() * &jc;
        let Some(inv) = ctc.try_inverse() else {
            continue;
        };
        let projected = &jp - &jc * (inv * (jc.transpose() * &jp));
        blocks.push(projected);
    }
    let rows: usize = blocks.iter().map(DMatrix::nrows).sum();
    let mut j = DMatrix::zeros(rows.max(1), n_unknowns);
    let mut r0 = 0;
    for b in &blocks {
        j.view_mut((r0, 0), (b.nrows(), n_unknowns)).copy_from(b);
        r0 += b.nrows();
    }
    // Pivoted modified Gram-Schmidt on the preference-weighted columns.
    let mut work: Vec<DVector<f64>> = (0..n_unknowns)
        .map(|u| j.column(u) * pivot_weight(est, u))
        .collect();
    let mut remaining: Vec<usize> = (0..n_unknowns).collect();
    let mut pivots = Vec::with_capacity(n_unknowns);
    let mut r11 = 0.0_f64;
    while !remaining.is_empty() {
        if !go_on() {
            return None;
        }
        let best = remaining
            .iter()
            .map(|&u| work[u].norm())
            .fold(0.0_f64, f64::max);
        let pos = remaining
            .iter()
            .position(|&u| work[u].norm() >= best * (1.0 - PIVOT_TIE_REL))
            .unwrap_or(0);
        let u = remaining.remove(pos);
        let r = work[u].norm();
        // The unweighted pivot decides the rank.
        let r_plain = r / pivot_weight(est, u);
        if pivots.is_empty() {
            r11 = r_plain;
        }
        pivots.push((u, if r11 > 0.0 { r_plain / r11 } else { 0.0 }));
        if r > 0.0 {
            let q = &work[u] / r;
            for _ in 0..2 {
                for &v in &remaining {
                    let c = q.dot(&work[v]);
                    work[v] -= &q * c;
                }
            }
        }
    }
    let mut estimated: Vec<usize> = pivots.iter().filter(|p| p.1 >= tol).map(|p| p.0).collect();
    let mut fixed: Vec<usize> = pivots.iter().filter(|p| p.1 < tol).map(|p| p.0).collect();
    estimated.sort_unstable();
    fixed.sort_unstable();
    let inseparable = name_inseparable(&j, &estimated, &fixed, r11);
    Some(Identifiability {
        estimated,
        fixed,
        pivots,
        inseparable,
    })
}

/// Raw units (rad or mm) per file unit.
pub(super) fn raw_per_file_unit(k: usize) -> f64 {
    if unknown_is_angle(k) {
        1.0_f64.to_radians()
    } else {
        1.0
    }
}

/// Names each fixed parameter's combination: the estimated parameters that
/// undo its effect on the distances (least squares on the projected
/// columns), in file units; parameters with no effect at all are grouped.
pub(super) fn name_inseparable(
    j: &DMatrix<f64>,
    estimated: &[usize],
    fixed: &[usize],
    r11: f64,
) -> Vec<Inseparable> {
    let mut out = Vec::new();
    let mut no_effect = Vec::new();
    let mut je = DMatrix::zeros(j.nrows(), estimated.len());
    for (slot, &u) in estimated.iter().enumerate() {
        je.set_column(slot, &j.column(u));
    }
    let svd = nalgebra::SVD::try_new(
        je.clone(),
        true,
        true,
        f64::EPSILON,
        crate::engine::base::numeric::MAX_DECOMPOSITION_SWEEPS,
    );
    for &f in fixed {
        let col = j.column(f).into_owned();
        if col.norm() <= NO_EFFECT_REL * r11 {
            no_effect.push(unknown_label(f));
            continue;
        }
        let Some(Ok(c)) = svd.as_ref().map(|d| d.solve(&col, 1e-12 * r11)) else {
            out.push(Inseparable::Unresolved(unknown_label(f)));
            continue;
        };
        let unexplained = (&col - &je * &c).norm() / col.norm();

        // Scaled null direction: z_f = 1, z_k = −c_k. One file unit of f.
        let zf = raw_per_file_unit(f) * unknown_scale(f);
        let biggest = c.amax();
        let mut parts: Vec<(usize, f64)> = estimated
            .iter()
            .zip(c.iter())
            .filter(|(_, ck)| ck.abs() >= SHOWN_SHARE * biggest)
            .map(|(&u, &ck)| (u, ck))
            .collect();
        parts.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
        out.push(Inseparable::Combination {
            fixed: unknown_label(f),
            partners: parts
                .iter()
                .map(|&(u, ck)| Partner {
                    parameter: unknown_label(u),
                    undo: as_written(-ck * zf / unknown_scale(u) / raw_per_file_unit(u), 3),
                })
                .collect(),
            explained_pct: (unexplained > 1e-3).then(|| as_written(100.0 * (1.0 - unexplained), 1)),
        });
    }
    if !no_effect.is_empty() {
        out.insert(0, Inseparable::NoEffect(no_effect));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sentence as the format module reads it, checked to be written back
    /// as read.
    fn parsed(text: &str) -> Inseparable {
        let i: Inseparable = serde_json::from_value(serde_json::Value::from(text)).unwrap();
        assert_eq!(i.to_string(), text, "written back as read");
        i
    }

    /// The fixed and partner names, as history reads them.
    struct Names {
        fixed: Vec<String>,
        partners: Vec<String>,
    }

    fn names_of(i: &Inseparable) -> Names {
        Names {
            fixed: i.fixed().into_iter().map(str::to_string).collect(),
            partners: i.partners().into_iter().map(str::to_string).collect(),
        }
    }

    #[test]
    fn combinations_are_parsed() {
        let c = names_of(&parsed("d6 ~ he_z: d6 +1 mm is undone by he_z +0.999 mm"));
        assert_eq!(c.fixed, ["d6"]);
        assert_eq!(c.partners, ["he_z"]);
        let c = names_of(&parsed(
            "beta4 ~ theta3, d4: beta4 +1° is undone by theta3 +1.000°, d4 -2.356 mm",
        ));
        assert_eq!(c.fixed, ["beta4"]);
        assert_eq!(c.partners, ["theta3", "d4"]);
        let c = names_of(&parsed(
            "alpha1, a1, beta1, theta1, d1: no effect on any centre distance (a rigid motion)",
        ));
        assert_eq!(c.fixed, ["alpha1", "a1", "beta1", "theta1", "d1"]);
        assert!(c.partners.is_empty());
    }

    #[test]
    fn combinations_are_written_as_before() {
        let c = Inseparable::Combination {
            fixed: "beta4".into(),
            partners: vec![
                Partner {
                    parameter: "theta3".into(),
                    undo: 1.000_2,
                },
                Partner {
                    parameter: "d4".into(),
                    undo: -2.356_4,
                },
            ],
            explained_pct: Some(99.94),
        };
        let text = c.to_string();
        assert_eq!(
            text,
            "beta4 ~ theta3, d4: beta4 +1° is undone by theta3 +1.000°, d4 -2.356 mm (to 99.9 % of its effect)"
        );
        assert_eq!(names_of(&parsed(&text)).partners, ["theta3", "d4"]);
    }
}
