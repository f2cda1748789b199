//! Ordering the poses for short robot moves: stations in nearest-neighbour
//! order of their positions, each group by nearest neighbour then 2-opt on
//! a weighted joint distance, readings unwrapped to the nearest turn (see
//! the parent module's docs).

use nalgebra::Vector3;

use super::{Candidate, Group, Site, StationRole};
use crate::engine::base::geometry::wrap_deg;
use crate::engine::base::robot::JointLimit;
use crate::engine::base::robot::ik::DOF;
use crate::engine::base::session::Use;

/// Bound on the 2-opt passes over one group: each pass strictly shortens
/// the path, and a group of tens of poses settles in a handful.
const MAX_TWO_OPT_PASSES: usize = 100;

/// The weighted joint distance of the ordering.
pub(super) struct Metric<'a> {
    pub(super) weights: &'a [f64],
    pub(super) limits: &'a [JointLimit],
}

impl Metric<'_> {
    /// `b`'s reading of joint `i` nearest to `a` among `b ± 360°` within
    /// the limit.
    fn nearest(&self, i: usize, a: f64, b: f64) -> f64 {
        let l = self.limits[i];
        [b, b + 360.0, b - 360.0]
            .into_iter()
            .filter(|v| *v >= l.min && *v <= l.max)
            .min_by(|x, y| (x - a).abs().total_cmp(&(y - a).abs()))
            .unwrap_or(b)
    }

    /// `max_i w_i·|a_i − b_i|`, the difference taken modulo a turn on
    /// joints whose range spans one. Symmetric, as 2-opt needs (the
    /// nearest equivalent *within the limits* is not: 150° to −170° on a
    /// ±200° axis is 40° one way and 320° the other).
    fn distance(&self, a: &[f64; DOF], b: &[f64; DOF]) -> f64 {
        (0..DOF)
            .map(|i| {
                let l = self.limits[i];
                let d = if l.max - l.min >= 360.0 {
                    wrap_deg(a[i] - b[i])
                } else {
                    a[i] - b[i]
                };
                self.weights[i] * d.abs()
            })
            .fold(0.0, f64::max)
    }

    /// The readings the robot would take along `path`: each pose's
    /// equivalents nearest the previous pose.
    pub(super) fn unwrap_path(&self, path: &[[f64; DOF]]) -> Vec<[f64; DOF]> {
        let mut out: Vec<[f64; DOF]> = Vec::with_capacity(path.len());
        for q in path {
            let next = match out.last() {
                Some(prev) => std::array::from_fn(|i| self.nearest(i, prev[i], q[i])),
                None => *q,
            };
            out.push(next);
        }
        out
    }

    /// Sum of the plain weighted distances along a realised path, deg.
    pub(super) fn path(&self, path: &[[f64; DOF]]) -> f64 {
        path.windows(2)
            .map(|w| {
                (0..DOF)
                    .map(|i| self.weights[i] * (w[1][i] - w[0][i]).abs())
                    .fold(0.0, f64::max)
            })
            .sum()
    }

    /// Nearest neighbour from `start` (or from the first pose), then 2-opt
    /// with `start` fixed before the path and the end open.
    fn order(&self, start: Option<&[f64; DOF]>, poses: Vec<Candidate>) -> Vec<Candidate> {
        if poses.len() < 2 {
            return poses;
        }
        let mut left = poses;
        let mut path: Vec<Candidate> = Vec::with_capacity(left.len());
        let mut current: Option<[f64; DOF]> = start.copied();
        while !left.is_empty() {
            let i = match current {
                Some(q) => (0..left.len())
                    .min_by(|&a, &b| {
                        self.distance(&q, &left[a].joints)
                            .total_cmp(&self.distance(&q, &left[b].joints))
                    })
                    .unwrap_or(0),
                None => 0,
            };
            let next = left.remove(i);
            current = Some(next.joints);
            path.push(next);
        }
        // 2-opt on [start, p_0 … p_{n−1}]: reversing p_i..p_j changes the
        // edges (p_{i−1}, p_i) and (p_j, p_{j+1}).
        let n = path.len();
        let before = |path: &[Candidate], i: usize| -> Option<[f64; DOF]> {
            if i == 0 {
                start.copied()
            } else {
                Some(path[i - 1].joints)
            }
        };
        let mut improved = true;
        let mut passes = 0;
        while improved && passes < MAX_TWO_OPT_PASSES {
            improved = false;
            passes += 1;
            for i in 0..n - 1 {
                for j in i + 1..n {
                    let prev = before(&path, i);
                    let old_in = prev.map_or(0.0, |p| self.distance(&p, &path[i].joints));
                    let new_in = prev.map_or(0.0, |p| self.distance(&p, &path[j].joints));
                    let (old_out, new_out) = if j + 1 < n {
                        (
                            self.distance(&path[j].joints, &path[j + 1].joints),
                            self.distance(&path[i].joints, &path[j + 1].joints),
                        )
                    } else {
                        (0.0, 0.0)
                    };
                    if new_in + new_out < old_in + old_out - 1e-9 {
                        path[i..=j].reverse();
                        improved = true;
                    }
                }
            }
        }
        path
    }
}

/// Groups in visit order: `P0`'s translations then rotations, identify
/// stations then validate stations, each role in nearest-neighbour order
/// of the positions; every group ordered from the previous one's last pose.
pub(super) fn order_groups(sites: &[Site], groups: Vec<Group>, metric: &Metric<'_>) -> Vec<Group> {
    let mut hand_eye: Vec<Group> = Vec::new();
    let mut identify: Vec<Group> = Vec::new();
    let mut validate: Vec<Group> = Vec::new();
    for g in groups {
        match sites[g.site].role {
            StationRole::HandEye => hand_eye.push(g),
            StationRole::Identify => identify.push(g),
            StationRole::Validate => validate.push(g),
        }
    }
    let mut at: Option<Vector3<f64>> = hand_eye.first().map(|g| sites[g.site].position);
    let visit = |mut list: Vec<Group>, at: &mut Option<Vector3<f64>>| -> Vec<Group> {
        let mut out = Vec::with_capacity(list.len());
        while !list.is_empty() {
            let i = match at {
                Some(p) => (0..list.len())
                    .min_by(|&a, &b| {
                        (sites[list[a].site].position - *p)
                            .norm()
                            .total_cmp(&(sites[list[b].site].position - *p).norm())
                    })
                    .unwrap_or(0),
                None => 0,
            };
            let g = list.remove(i);
            *at = Some(sites[g.site].position);
            out.push(g);
        }
        out
    };
    let mut ordered = hand_eye;
    ordered.extend(visit(identify, &mut at));
    ordered.extend(visit(validate, &mut at));
    let mut last: Option<[f64; DOF]> = None;
    ordered
        .into_iter()
        .map(|mut g| {
            // The translation group keeps its order (one branch, small moves).
            if g.usage != Use::Translation {
                g.poses = metric.order(last.as_ref(), g.poses);
            }
            last = g.poses.last().map(|c| c.joints);
            g
        })
        .collect()
}
