//! Robot configuration as the controllers write it, computed from a joint
//! solution: which of a pose's several solutions (branches) a target
//! names, and the turn of each joint.
//!
//! The branch features are geometric, measured on the model (so they do
//! not depend on a joint's sign convention), each relative to the model's
//! zero pose (all readings 0), which on ABB, FANUC and KUKA arms stands
//! with the lower arm up and the upper arm forward:
//!
//! - **front**: the wrist centre on the same side of axis 1 as at the zero
//!   pose (the arm reaches forward, not back over its base);
//! - **elbow up**: the wrist centre on the same side of the lower arm
//!   (the line through axes 2 and 3) as at the zero pose.
//!
//! spherecal's reading of each controller's fields, from its manual:
//!
//! | controller | written | from a solution `q` (deg) |
//! |---|---|---|
//! | ABB RAPID `confdata` | `[cf1, cf4, cf6, cfx]` | `cfN = ⌊qN / 90⌋`; `cfx = 4·(not front) + 2·(not elbow up) + (q5 < 0)` |
//! | KUKA `E6POS` | `S`, `T` | `S = 1·(not front) + 2·(elbow up) + 4·(q5 ≤ 0)`; bit `k` of `T` set when `q(k+1) < 0` |
//! | FANUC `CONFIG` | `'F|N U|D T|B, t1, t4, t6'` | `F` when `q5 > 0`; `U` elbow up; `T` front; `tN` the turn of joint N: `qN` in `(−180 + 360·tN, 180 + 360·tN]` |
//!
//! Joint readings are the model's (the controller's, when the model was
//! made from its data). A written configuration that no solution matches
//! under this reading is kept as written, and the branch is then chosen
//! as for a target without one.

use std::fmt;
use std::ops::Range;

use nalgebra::{Isometry3, Vector3};

use crate::engine::base::geometry::{rot_x, rot_y, rot_z, trans};
use crate::engine::base::robot::Robot;
use crate::engine::base::robot::ik::DOF;

/// Below this (mm², the scale of the elbow and front products on an arm
/// of a metre) a zero-pose feature is degenerate (an arm stretched at its
/// zero pose, as the UR5e): its sign is then taken as positive.
const DEGENERATE_MM2: f64 = 1e-6;

/// The controllers whose configuration fields are read and written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Vendor {
    /// ABB RAPID `[cf1, cf4, cf6, cfx]`.
    Abb,
    /// KUKA KRL `S` (status) and `T` (turn).
    Kuka,
    /// FANUC TP `CONFIG : 'N U T, 0, 0, 0'`.
    Fanuc,
}

/// A configuration as a controller writes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Config {
    /// ABB `[cf1, cf4, cf6, cfx]`.
    Abb([i64; 4]),
    /// KUKA status and turn.
    Kuka {
        /// `S`.
        s: u32,
        /// `T`.
        t: u32,
    },
    /// FANUC flip, elbow, front and the turns of joints 1, 4, 6.
    Fanuc {
        /// `F` (true) or `N`.
        flip: bool,
        /// `U` (true) or `D`.
        up: bool,
        /// `T` (true) or `B`.
        front: bool,
        /// Turn numbers of joints 1, 4 and 6.
        turns: [i64; 3],
    },
}

impl fmt::Display for Config {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Abb(c) => write!(f, "[{},{},{},{}]", c[0], c[1], c[2], c[3]),
            Self::Kuka { s, t } => write!(f, "S {s}, T {t}"),
            Self::Fanuc {
                flip,
                up,
                front,
                turns,
            } => write!(
                f,
                "'{} {} {}, {}, {}, {}'",
                if *flip { 'F' } else { 'N' },
                if *up { 'U' } else { 'D' },
                if *front { 'T' } else { 'B' },
                turns[0],
                turns[1],
                turns[2]
            ),
        }
    }
}

/// The branch features of a solution (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Posture {
    /// The wrist centre on the zero pose's side of axis 1.
    pub front: bool,
    /// The wrist centre on the zero pose's side of the lower arm.
    pub elbow_up: bool,
}

/// The geometric features of one solution: `(front, elbow)` products (mm²).
fn features(robot: &Robot, q: &[f64; DOF]) -> (f64, f64) {
    let j = &robot.joints;
    let fixed = |i: usize| {
        rot_x(j[i].alpha.to_radians()) * trans(j[i].a, 0.0, 0.0) * rot_y(j[i].beta.to_radians())
    };
    let motion = |i: usize| rot_z((q[i] + j[i].theta).to_radians()) * trans(0.0, 0.0, j[i].d);
    let axis = |t: &Isometry3<f64>| (t.translation.vector, t.rotation * Vector3::z());
    let f1 = robot.base * fixed(0);
    let (o1, z1) = axis(&f1);
    let f2 = f1 * motion(0) * fixed(1);
    let (p2, z2) = axis(&f2);
    let f3 = f2 * motion(1) * fixed(2);
    let (p3, _) = axis(&f3);
    let wc = (f3 * motion(2) * fixed(3) * trans(0.0, 0.0, j[3].d))
        .translation
        .vector;
    let front = (wc - o1).dot(&z2.cross(&z1));
    let elbow = (p3 - p2).cross(&(wc - p3)).dot(&z2);
    (front, elbow)
}

/// The posture of solution `q` (deg) of a 6-axis `robot`.
#[must_use]
pub fn posture(robot: &Robot, q: &[f64; DOF]) -> Posture {
    let (front0, elbow0) = features(robot, &[0.0; DOF]);
    let (front, elbow) = features(robot, q);
    let sign = |v: f64| {
        if v.abs() < DEGENERATE_MM2 {
            1.0
        } else {
            v.signum()
        }
    };
    Posture {
        front: front * sign(front0) >= 0.0,
        elbow_up: elbow * sign(elbow0) >= 0.0,
    }
}

/// `⌊q / 90⌋`: ABB's quadrant of a joint reading (deg).
fn quadrant(q: f64) -> i64 {
    (q / 90.0).floor() as i64
}

/// FANUC's turn number: `t` with `q` in `(−180 + 360·t, 180 + 360·t]`.
fn turn(q: f64) -> i64 {
    ((q - 180.0) / 360.0).ceil() as i64
}

impl Vendor {
    /// The configuration of solution `q` (deg) with posture `p`.
    #[must_use]
    pub fn config(self, q: &[f64; DOF], p: Posture) -> Config {
        match self {
            Self::Abb => Config::Abb([
                quadrant(q[0]),
                quadrant(q[3]),
                quadrant(q[5]),
                4 * i64::from(!p.front) + 2 * i64::from(!p.elbow_up) + i64::from(q[4] < 0.0),
            ]),
            Self::Kuka => Config::Kuka {
                s: u32::from(!p.front) + 2 * u32::from(p.elbow_up) + 4 * u32::from(q[4] <= 0.0),
                t: q.iter()
                    .enumerate()
                    .map(|(k, v)| u32::from(*v < 0.0) << k)
                    .sum(),
            },
            Self::Fanuc => Config::Fanuc {
                flip: q[4] > 0.0,
                up: p.elbow_up,
                front: p.front,
                turns: [turn(q[0]), turn(q[3]), turn(q[5])],
            },
        }
    }

    /// Reads a configuration as written (the text of
    /// [`Target::config`](crate::engine::files::program::Target::config)'s range:
    /// `[0,-1,0,1]`, `6,T 27` or `'B110',T 'B011011'`, `N U T, 0, 0, -1`);
    /// `None` when it is not one.
    #[must_use]
    pub fn parse(self, text: &str) -> Option<Config> {
        let tokens: Vec<&str> = tokens(text).into_iter().map(|r| &text[r]).collect();
        match self {
            Self::Abb => {
                let v: Vec<i64> = tokens
                    .iter()
                    .map(|t| t.parse().ok())
                    .collect::<Option<_>>()?;
                Some(Config::Abb(v.try_into().ok()?))
            }
            Self::Kuka => match tokens.as_slice() {
                [s, key, t] if key.eq_ignore_ascii_case("T") => Some(Config::Kuka {
                    s: kuka_value(s)?,
                    t: kuka_value(t)?,
                }),
                _ => None,
            },
            Self::Fanuc => {
                let letter = |k: usize, yes: &str, no: &str| match tokens.get(k) {
                    Some(t) if t.eq_ignore_ascii_case(yes) => Some(true),
                    Some(t) if t.eq_ignore_ascii_case(no) => Some(false),
                    _ => None,
                };
                let turns: Vec<i64> = tokens
                    .get(3..)?
                    .iter()
                    .map(|t| t.parse().ok())
                    .collect::<Option<_>>()?;
                Some(Config::Fanuc {
                    flip: letter(0, "F", "N")?,
                    up: letter(1, "U", "D")?,
                    front: letter(2, "T", "B")?,
                    turns: turns.try_into().ok()?,
                })
            }
        }
    }
}

/// A KUKA status or turn: decimal, or binary `'B0110'`.
fn kuka_value(t: &str) -> Option<u32> {
    let t = t.trim_matches('\'');
    match t.strip_prefix(['B', 'b']) {
        Some(bits) => u32::from_str_radix(bits, 2).ok(),
        None => t.parse().ok(),
    }
}

/// The value tokens of a configuration's text: maximal runs of letters,
/// digits, signs and quotes (`-1`, `T`, `'B110'`).
fn tokens(text: &str) -> Vec<Range<usize>> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, c) in text
        .char_indices()
        .chain(std::iter::once((text.len(), ' ')))
    {
        let part = c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '\'');
        match (start, part) {
            (None, true) => start = Some(i),
            (Some(s), false) => {
                out.push(s..i);
                start = None;
            }
            _ => {}
        }
    }
    out
}

/// `config` written in the style of `original` (the written text it
/// replaces: its separators and spacing kept, a KUKA binary value kept
/// binary with at least as many digits).
#[must_use]
pub fn render(config: &Config, original: &str) -> String {
    let spans = tokens(original);
    let values: Vec<String> = match config {
        Config::Abb(c) => c.iter().map(ToString::to_string).collect(),
        Config::Kuka { s, t } => {
            let style = |k: usize, v: u32| {
                let old = spans.get(k).map_or("", |r| &original[r.clone()]);
                let bare = old.trim_matches('\'');
                if let Some(bits) = bare.strip_prefix(['B', 'b']) {
                    format!("'{}{:0width$b}'", &bare[..1], v, width = bits.len())
                } else {
                    v.to_string()
                }
            };
            vec![style(0, *s), "T".to_string(), style(2, *t)]
        }
        Config::Fanuc {
            flip,
            up,
            front,
            turns,
        } => {
            let mut v = vec![
                if *flip { "F" } else { "N" }.to_string(),
                if *up { "U" } else { "D" }.to_string(),
                if *front { "T" } else { "B" }.to_string(),
            ];
            v.extend(turns.iter().map(ToString::to_string));
            v
        }
    };
    if spans.len() != values.len() {
        return match config {
            Config::Fanuc { .. } => config.to_string().trim_matches('\'').to_string(),
            Config::Kuka { s, t } => format!("{s},T {t}"),
            Config::Abb(_) => config.to_string(),
        };
    }
    let mut out = String::with_capacity(original.len() + 4);
    let mut at = 0;
    for (span, value) in spans.iter().zip(&values) {
        out.push_str(&original[at..span.start]);
        out.push_str(value);
        at = span.end;
    }
    out.push_str(&original[at..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::base::robot::ik::Chain;
    use crate::engine::base::robot::irb2400;

    #[test]
    fn written_configurations_read_and_render_in_place() {
        let abb = Vendor::Abb.parse("[0,-1, 0,1]").unwrap();
        assert_eq!(abb, Config::Abb([0, -1, 0, 1]));
        assert_eq!(
            render(&Config::Abb([1, -1, 0, 5]), "[0,-1, 0,1]"),
            "[1,-1, 0,5]"
        );
        let kuka = Vendor::Kuka.parse("6,T 27").unwrap();
        assert_eq!(kuka, Config::Kuka { s: 6, t: 27 });
        assert_eq!(render(&Config::Kuka { s: 2, t: 3 }, "6,T 27"), "2,T 3");
        let bin = Vendor::Kuka.parse("'B110',T 'B011011'").unwrap();
        assert_eq!(bin, Config::Kuka { s: 6, t: 27 });
        assert_eq!(
            render(&Config::Kuka { s: 2, t: 1 }, "'B110',T 'B011011'"),
            "'B010',T 'B000001'"
        );
        let fanuc = Vendor::Fanuc.parse("N U T, 0, 0, -1").unwrap();
        assert_eq!(
            fanuc,
            Config::Fanuc {
                flip: false,
                up: true,
                front: true,
                turns: [0, 0, -1]
            }
        );
        let flipped = Config::Fanuc {
            flip: true,
            up: true,
            front: false,
            turns: [0, 1, -1],
        };
        assert_eq!(render(&flipped, "N U T, 0, 0, -1"), "F U B, 0, 1, -1");
        assert!(Vendor::Fanuc.parse("X U T, 0, 0, 0").is_none());
        assert!(Vendor::Abb.parse("[0,0,0]").is_none());
    }

    #[test]
    fn turns_and_quadrants() {
        assert_eq!(quadrant(-0.5), -1);
        assert_eq!(quadrant(90.0), 1);
        assert_eq!(turn(180.0), 0);
        assert_eq!(turn(180.5), 1);
        assert_eq!(turn(-180.0), -1);
        assert_eq!(turn(-179.0), 0);
    }

    /// Every branch of a pose has its own ABB configuration (cfx tells
    /// the 8 branches of a spherical-wrist arm apart), and the zero pose's
    /// neighbourhood is front and elbow up.
    #[test]
    fn branches_have_distinct_configurations() {
        let preset = irb2400();
        let robot = preset.robot;
        let p = posture(&robot, &[10.0, 20.0, 10.0, 30.0, 50.0, 15.0]);
        assert!(p.front && p.elbow_up);
        let chain = Chain::new(&robot).unwrap();
        let target = robot.base_from_flange(&[20.0, 30.0, 10.0, 30.0, 50.0, 15.0]);
        let guesses = chain.arm_guess_grid(&target, &preset.limits);
        let all = chain.solutions(&target, &guesses, &preset.limits, 1.0);
        assert!(all.len() >= 2, "{all:?}");
        let cfx: Vec<i64> = all
            .iter()
            .map(|q| match Vendor::Abb.config(q, posture(&robot, q)) {
                Config::Abb(c) => c[3],
                _ => unreachable!(),
            })
            .collect();
        for (i, a) in cfx.iter().enumerate() {
            assert!(!cfx[i + 1..].contains(a), "{cfx:?} of {all:?}");
        }
        let taught = all
            .iter()
            .position(|q| (q[1] - 30.0).abs() < 1e-6 && (q[4] - 50.0).abs() < 1e-6)
            .unwrap();
        assert_eq!(cfx[taught], 0, "{all:?}");
    }
}
