//! The initial hand-eye of an imported session whose file gives no uses:
//! every pose becomes `identify`, and the session carries an initial
//! hand-eye (FORMAT.md: without one, a session needs translation and
//! rotation groups).
//!
//! In order: the guess given (`--hand-eye`); else the paper's eq. 6-9
//! when the poses hold a group of one orientation (within
//! [`SAME_ORIENTATION_DEG`]: at least 3, and 2 others); else the general
//! solution ([`crate::engine::calibrate::handeye::general`]) on all poses at once.
//! When both can be had, both are printed with the scatter of the sphere
//! centres each gives, and eq. 6-9's is kept. No calibration runs here.

use std::collections::HashMap;
use std::path::Path;

use nalgebra::{Isometry3, Point3, Vector3};

use crate::engine::base::numeric::approx;
use crate::engine::base::session::{Session, Use};
use crate::engine::calibrate::handeye::general::{
    GeneralHandEye, GeneralSighting, general_hand_eye,
};
use crate::engine::calibrate::handeye::{Sighting, initial_hand_eye};
use crate::engine::calibrate::solve::plausible::{MAX_PLAUSIBLE_SCATTER_MM, check_scatter};
use crate::engine::calibrate::solve::{Analysis, analyse};
use crate::engine::files::import::{ImportError, ProfileReport};

/// Largest orientation difference (deg) between poses counted as "the
/// same orientation" when the translation group is found: controllers
/// report a kept orientation to a few thousandths of a degree.
pub const SAME_ORIENTATION_DEG: f64 = 0.1;

/// Poses of one orientation eq. 6-7 need: they solve the sensor's
/// rotation from the moves between these poses, and two independent
/// moves take three poses.
pub const MIN_TRANSLATIONS: usize = 3;

/// Poses of other orientations eq. 8-9 need: they solve the sensor's
/// translation, and one turn leaves its component along the turn's axis
/// open.
pub const MIN_ROTATIONS: usize = 2;

/// The translation group: the poses sharing the most common orientation
/// (within [`SAME_ORIENTATION_DEG`]), in session order.
fn translation_group(poses: &[Isometry3<f64>]) -> Vec<usize> {
    let mut best: Vec<usize> = Vec::new();
    for a in poses {
        let group: Vec<usize> = poses
            .iter()
            .enumerate()
            .filter(|(_, b)| a.rotation.angle_to(&b.rotation).to_degrees() <= SAME_ORIENTATION_DEG)
            .map(|(i, _)| i)
            .collect();
        if group.len() > best.len() {
            best = group;
        }
    }
    best
}

/// No group of one orientation for eq. 6-9: the sizes found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error(
    "no group of one orientation for eq. 6-9: the largest set of poses with one orientation (within {SAME_ORIENTATION_DEG}°) has {translations} poses and {others} others change orientation; eq. 6-9 need at least {MIN_TRANSLATIONS} of the one and {MIN_ROTATIONS} of the other"
)]
pub struct Eq69Error {
    /// Poses of the largest group of one orientation.
    pub translations: usize,
    /// The other poses.
    pub others: usize,
}

/// The poses (flange poses `bT_e`, mm) of the group of one orientation
/// the paper's eq. 6-9 start from, when there is one: at least
/// [`MIN_TRANSLATIONS`] poses of one orientation (within
/// [`SAME_ORIENTATION_DEG`]) and [`MIN_ROTATIONS`] others.
///
/// # Errors
/// [`Eq69Error`]: no such group (the sizes found).
pub fn eq69_group(poses: &[Isometry3<f64>]) -> Result<Vec<usize>, Eq69Error> {
    let group = translation_group(poses);
    let others = poses.len() - group.len();
    if group.len() >= MIN_TRANSLATIONS && others >= MIN_ROTATIONS {
        Ok(group)
    } else {
        Err(Eq69Error {
            translations: group.len(),
            others,
        })
    }
}

/// RMS 3-D distance of each measurement's base-frame centre under
/// `flange_from_sensor` from its station's mean, mm.
fn scatter(
    poses: &[Isometry3<f64>],
    centres: &[Option<Vector3<f64>>],
    stations: &[usize],
    flange_from_sensor: &Isometry3<f64>,
) -> f64 {
    let points: Vec<Option<Vector3<f64>>> = poses
        .iter()
        .zip(centres)
        .map(|(p, c)| c.map(|c| (p * flange_from_sensor * Point3::from(c)).coords))
        .collect();
    let n_stations = stations.iter().max().map_or(0, |m| m + 1);
    let mut sums = vec![(Vector3::zeros(), 0.0); n_stations];
    for (x, &s) in points.iter().zip(stations) {
        if let Some(x) = x {
            sums[s].0 += x;
            sums[s].1 += 1.0;
        }
    }
    let (mut ss, mut n) = (0.0, 0.0);
    for (x, &s) in points.iter().zip(stations) {
        if let Some(x) = x {
            ss += (x - sums[s].0 / sums[s].1).norm_squared();
            n += 1.0;
        }
    }
    if n > 0.0 { (ss / n).sqrt() } else { f64::NAN }
}

/// Each measurement's base-from-flange pose (the session's robot), the
/// stripes' analysis, each measurement's station index (in order of first
/// appearance) and the number of stations.
fn sightings_of(session: &Session) -> (Vec<Isometry3<f64>>, Analysis, Vec<usize>, usize) {
    let robot = session.robot.clone();
    let poses = (0..session.measurements.len())
        .map(|i| session.base_from_flange(&robot, i))
        .collect();
    let mut station_index: HashMap<&str, usize> = HashMap::new();
    let stations = session
        .measurements
        .iter()
        .map(|m| {
            let next = station_index.len();
            *station_index.entry(m.station.as_str()).or_insert(next)
        })
        .collect();
    (poses, analyse(session), stations, station_index.len())
}

/// Each measurement's sphere centre in the sensor frame, where its stripe
/// gave one.
fn centres_of(analysis: &Analysis) -> Vec<Option<Vector3<f64>>> {
    analysis
        .measurements
        .iter()
        .map(|m| m.as_ref().ok().map(|p| p.centre_in_sensor))
        .collect()
}

/// The centres' scatter (3-D rms about each station's mean, mm) under
/// the session's initial hand-eye, when calibrate's verdict refuses it
/// ([`check_scatter`]): the finished import's last check, a refusal for a
/// pose-only session (its start is its verdict: no kinematic error can
/// bring the centres together). `None` when plausible or without a
/// hand-eye.
pub(crate) fn implausible_start(
    session: &Session,
) -> Option<crate::engine::calibrate::solve::plausible::ImplausibleScatter> {
    let he = session.hand_eye?;
    let (poses, analysis, stations, _) = sightings_of(session);
    let centres = centres_of(&analysis);
    check_scatter(
        scatter(&poses, &centres, &stations, &he),
        session.pose_only(),
    )
    .err()
}

/// Names, shortened: "p1, p2, …, p15 (15)".
fn names(ids: &[&str]) -> String {
    if ids.len() <= 8 {
        ids.join(", ")
    } else {
        format!(
            "{}, …, {} ({})",
            ids[..3].join(", "),
            ids[ids.len() - 1],
            ids.len()
        )
    }
}

/// The session with its uses and initial hand-eye settled (see the module
/// doc), and what was decided, in words.
///
/// # Errors
/// No initial hand-eye can be had: both reasons named (no group of one
/// orientation; the general solution's degeneracy).
pub(crate) fn settle(
    mut session: Session,
    auto_uses: bool,
    given: Option<Isometry3<f64>>,
    poses_file: &Path,
    profiles: &ProfileReport,
) -> Result<(Session, Vec<String>), ImportError> {
    if let Some(he) = given {
        return Ok(given_guess(session, he, auto_uses));
    }
    if !auto_uses {
        return Ok((session, Vec::new()));
    }
    for m in &mut session.measurements {
        m.usage = Use::Identify;
    }
    let (poses, analysis, stations, n_stations) = sightings_of(&session);
    let centres = centres_of(&analysis);
    let ids: Vec<&str> = session.measurements.iter().map(|m| m.id.as_str()).collect();
    // A stripe that gives no sphere centre is bad input: named with its
    // profile file, before any hand-eye is tried.
    reject_bad_stripe(&session, &analysis, poses_file, profiles)?;
    // The general solution, on every pose whose stripe gave a centre.
    let sightings: Vec<GeneralSighting> = poses
        .iter()
        .zip(&centres)
        .zip(&stations)
        .zip(&ids)
        .filter_map(|(((p, c), &s), id)| {
            c.map(|c| GeneralSighting {
                id: (*id).to_string(),
                station: s,
                base_from_flange: *p,
                centre_in_sensor: c,
            })
        })
        .collect();
    let general: Result<GeneralHandEye, String> =
        general_hand_eye(&sightings, n_stations).map_err(|e| e.to_string());
    // Eq. 6-9 when one station holds a group of one orientation.
    let paper = paper_hand_eye(&session, &poses, &centres, &stations, &ids);
    let mut notes = Vec::new();
    let describe = |g: &GeneralHandEye| describe_general(g, sightings.len());
    let chosen = match (&paper, &general) {
        (Ok((he, groups)), general) => {
            let own = scatter(&poses, &centres, &stations, he);
            notes.push(format!(
                "initial hand-eye by the paper's eq. 6-9 ({groups}): centres scatter {own:.3} mm rms; written to the session"
            ));
            match general {
                Ok(g) => notes.push(format!(
                    "  beside it, {}; {:.3} mm and {:.3}° from eq. 6-9's",
                    describe(g),
                    (g.flange_from_sensor.translation.vector - he.translation.vector).norm(),
                    g.flange_from_sensor
                        .rotation
                        .angle_to(&he.rotation)
                        .to_degrees()
                )),
                Err(e) => notes.push(format!("  the general solution failed beside it: {e}")),
            }
            *he
        }
        (Err(no_group), Ok(g)) => {
            notes.push(format!(
                "initial hand-eye by {}; written to the session ({no_group})",
                describe(g)
            ));
            g.flange_from_sensor
        }
        (Err(no_group), Err(general)) => {
            return Err(ImportError::NoInitialHandEye {
                path: poses_file.to_path_buf(),
                message: format!(
                    "no initial hand-eye can be had from these poses: {no_group}; and {general}. Give a guess with --hand-eye FILE (a 4×4, or a session or result file), or add poses that turn the flange about two different axes"
                ),
            });
        }
    };
    // Calibrate's verdict, before calibrating: poses and centres that no
    // hand-eye brings together are misread, not a cell. A warning, not a
    // refusal: the side decision tries the wrong side on purpose, and
    // `calibrate` refuses such a session unless told to accept it.
    let own = scatter(&poses, &centres, &stations, &chosen);
    if let Err(e) = check_scatter(own, session.pose_only()) {
        notes.push(format!(
            "warning: with the initial hand-eye that fits them best the sphere centres scatter by {} mm (3-D rms about each station's mean), beyond what any sensor and robot give (at most {MAX_PLAUSIBLE_SCATTER_MM} mm): `calibrate` will refuse this session; likely causes: {}, or poses and centres that do not belong together (another unit, another session) ({})",
            approx(own),
            e.causes,
            poses_file.display()
        ));
    }
    session.hand_eye = Some(chosen);
    notes.push("every pose is `identify`".to_string());
    Ok((session, notes))
}

/// The session with the guess `he` as its initial hand-eye, and the note
/// saying so (every pose `identify` with `auto_uses`).
fn given_guess(
    mut session: Session,
    he: Isometry3<f64>,
    auto_uses: bool,
) -> (Session, Vec<String>) {
    session.hand_eye = Some(he);
    let t = he.translation.vector;
    (
        session,
        vec![format!(
            "initial hand-eye: the guess given (translation [{:.2}, {:.2}, {:.2}] mm){}",
            t.x,
            t.y,
            t.z,
            if auto_uses {
                "; every pose is `identify`"
            } else {
                ""
            }
        )],
    )
}

/// A stripe that gives no sphere centre is bad input: the error names
/// the pose and its profile file (the poses file when it has none).
fn reject_bad_stripe(
    session: &Session,
    analysis: &Analysis,
    poses_file: &Path,
    profiles: &ProfileReport,
) -> Result<(), ImportError> {
    if let Some((i, e)) = analysis.failures().next() {
        let id = &session.measurements[i].id;
        let file = profiles
            .poses
            .iter()
            .find(|p| p.id == *id)
            .map_or_else(|| poses_file.to_path_buf(), |p| p.file.clone());
        return Err(ImportError::File {
            path: file,
            message: format!("pose {id}: {e}"),
        });
    }
    Ok(())
}

/// The paper's eq. 6-9 hand-eye when one station holds a group of one
/// orientation (its translations; the other poses at that station its
/// rotations), with the groups in words; else why not.
fn paper_hand_eye(
    session: &Session,
    poses: &[Isometry3<f64>],
    centres: &[Option<Vector3<f64>>],
    stations: &[usize],
    ids: &[&str],
) -> Result<(Isometry3<f64>, String), String> {
    let robot = &session.robot;
    eq69_group(poses)
        .map_err(|e| e.to_string())
        .and_then(|group| {
            let sight = |i: usize| -> Option<Sighting> {
                let m = &session.measurements[i];
                centres[i].map(|c| Sighting {
                    id: m.id.clone(),
                    joints: m.joints.clone(),
                    flange: m.flange,
                    centre_in_sensor: c,
                })
            };
            let in_group: Vec<bool> = (0..poses.len()).map(|i| group.contains(&i)).collect();
            let translations: Vec<Sighting> = group.iter().filter_map(|&i| sight(i)).collect();
            let rotations: Vec<Sighting> = (0..poses.len())
                .filter(|&i| !in_group[i] && stations[i] == stations[group[0]])
                .filter_map(sight)
                .collect();
            let t_ids: Vec<&str> = group.iter().map(|&i| ids[i]).collect();
            let r_ids: Vec<&str> = (0..poses.len())
                .filter(|&i| !in_group[i])
                .map(|i| ids[i])
                .collect();
            initial_hand_eye(robot, &translations, &rotations)
                .map(|h| {
                    (
                        h.flange_from_sensor,
                        format!(
                            "translation group {} (one orientation), rotation {}",
                            names(&t_ids),
                            names(&r_ids)
                        ),
                    )
                })
                .map_err(|e| e.to_string())
        })
}

/// The general solution from `n` poses in words: its orientation span,
/// scatter and weakest translation.
fn describe_general(g: &GeneralHandEye, n: usize) -> String {
    format!(
        "the general solution (all {} poses at once, orientations spanning {:.1}°): centres scatter {:.3} mm rms; weakest translation ±{:.2} mm along ({:.2}, {:.2}, {:.2}) per {} mm of centre noise",
        n,
        g.orientation_span_deg,
        g.rms_mm,
        g.weakest_translation.0,
        g.weakest_translation.1.x,
        g.weakest_translation.1.y,
        g.weakest_translation.1.z,
        crate::engine::calibrate::handeye::general::ASSUMED_CENTRE_NOISE_MM
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    #[test]
    fn the_largest_group_of_one_orientation() {
        let r = UnitQuaternion::from_euler_angles(0.1, 0.2, 0.3);
        let turned = UnitQuaternion::from_euler_angles(0.1, 0.25, 0.3);
        let at = |x: f64, q: UnitQuaternion<f64>| {
            Isometry3::from_parts(Translation3::new(x, 0.0, 0.0), q)
        };
        let poses = [at(0.0, r), at(10.0, turned), at(20.0, r), at(30.0, r)];
        assert_eq!(translation_group(&poses), vec![0, 2, 3]);
    }
}
