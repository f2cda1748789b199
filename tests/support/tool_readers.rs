//! Readers of the controllers' tool-data syntaxes, written from the
//! vendors' documentation (not from the writer's code): the CLI's and the
//! workbench's export tests read the tool data back with them.

use std::collections::BTreeMap;

use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};

// Rotations from elementary matrices, as the vendors define them.
pub fn rx(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}
pub fn ry(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}
pub fn rz(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}
pub fn pose(t: [f64; 3], r: Matrix3<f64>) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(t[0], t[1], t[2]),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r)),
    )
}
/// Unit quaternion (w, x, y, z) → matrix, the textbook formula.
pub fn quat_matrix(w: f64, x: f64, y: f64, z: f64) -> Matrix3<f64> {
    Matrix3::new(
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y - w * z),
        2.0 * (x * z + w * y),
        2.0 * (x * y + w * z),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - w * x),
        2.0 * (x * z - w * y),
        2.0 * (y * z + w * x),
        1.0 - 2.0 * (x * x + y * y),
    )
}
/// Rotation vector → matrix (Rodrigues).
pub fn rotvec_matrix(v: Vector3<f64>) -> Matrix3<f64> {
    let angle = v.norm();
    if angle == 0.0 {
        return Matrix3::identity();
    }
    let k = v / angle;
    let kx = Matrix3::new(0.0, -k.z, k.y, k.z, 0.0, -k.x, -k.y, k.x, 0.0);
    Matrix3::identity() + kx * angle.sin() + kx * kx * (1.0 - angle.cos())
}
/// URDF / ROS rpy: fixed-axis roll, pitch, yaw, `Rz(y)·Ry(p)·Rx(r)`.
pub fn rpy_matrix(r: f64, p: f64, y: f64) -> Matrix3<f64> {
    rz(y) * ry(p) * rx(r)
}

pub fn assert_same(a: &Isometry3<f64>, b: &Isometry3<f64>, mm: f64, rad: f64, what: &str) {
    let dt = (a.translation.vector - b.translation.vector).norm();
    let dr = a.rotation.angle_to(&b.rotation);
    assert!(dt <= mm && dr <= rad, "{what}: {dt:e} mm, {dr:e} rad");
}

/// RAPID: `PERS tooldata name := [robhold,[[x,y,z],[q1,q2,q3,q4]],[load]];`
/// (Technical reference manual, RAPID Instructions, Functions and Data
/// types: tooldata = robhold, tframe (pose: trans pos, rot orient),
/// tload), read as a bracketed aggregate.
pub fn read_rapid_tooldata(text: &str) -> Isometry3<f64> {
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with("PERS tooldata"))
        .unwrap();
    let value = line
        .split(":=")
        .nth(1)
        .unwrap()
        .trim()
        .trim_end_matches(';');
    // Parse nested [ , ] into a tree.
    #[derive(Debug)]
    enum Agg {
        Leaf(String),
        List(Vec<Agg>),
    }
    fn parse(s: &[u8], i: &mut usize) -> Agg {
        if s[*i] == b'[' {
            *i += 1;
            let mut items = Vec::new();
            loop {
                items.push(parse(s, i));
                match s[*i] {
                    b',' => *i += 1,
                    b']' => {
                        *i += 1;
                        return Agg::List(items);
                    }
                    c => panic!("unexpected {}", c as char),
                }
            }
        }
        let start = *i;
        while s[*i] != b',' && s[*i] != b']' {
            *i += 1;
        }
        Agg::Leaf(String::from_utf8(s[start..*i].to_vec()).unwrap())
    }
    let mut i = 0;
    let Agg::List(top) = parse(value.as_bytes(), &mut i) else {
        panic!()
    };
    assert!(matches!(&top[0], Agg::Leaf(s) if s == "TRUE"), "robhold");
    let Agg::List(tframe) = &top[1] else { panic!() };
    let nums = |a: &Agg| -> Vec<f64> {
        let Agg::List(v) = a else { panic!() };
        v.iter()
            .map(|x| match x {
                Agg::Leaf(s) => s.parse().unwrap(),
                Agg::List(_) => panic!(),
            })
            .collect()
    };
    let t = nums(&tframe[0]);
    let q = nums(&tframe[1]);
    assert!(q[0] >= 0.0, "ABB writes q1 ≥ 0");
    pose([t[0], t[1], t[2]], quat_matrix(q[0], q[1], q[2], q[3]))
}

/// KRL: `TOOL_DATA[1]={X x,Y y,Z z,A a,B b,C c}` (FRAME structure, KUKA
/// System Software: components by name in any order; A about z, B about
/// the new y, C about the new x: `Rz(A)·Ry(B)·Rx(C)`).
pub fn read_krl_tool(text: &str) -> Isometry3<f64> {
    let line = text.lines().find(|l| l.starts_with("TOOL_DATA[")).unwrap();
    let body = &line[line.find('{').unwrap() + 1..line.rfind('}').unwrap()];
    let mut f = BTreeMap::new();
    for part in body.split(',') {
        let mut it = part.split_whitespace();
        let (k, v) = (it.next().unwrap(), it.next().unwrap());
        f.insert(k.to_string(), v.parse::<f64>().unwrap());
    }
    let g = |k: &str| f[k];
    pose(
        [g("X"), g("Y"), g("Z")],
        rz(g("A").to_radians()) * ry(g("B").to_radians()) * rx(g("C").to_radians()),
    )
}

/// FANUC TP: `PR[1,i]=v ;` for i = 1..6 (X Y Z W P R) then
/// `UTOOL[1]=PR[1] ;`; W P R fixed-axis about x, y, z: `Rz(R)·Ry(P)·Rx(W)`.
/// The screen values (`!   X: v`) must be the same numbers.
pub fn read_fanuc_utool(text: &str) -> Isometry3<f64> {
    let mut pr = [f64::NAN; 6];
    let mut screen = BTreeMap::new();
    for l in text.lines() {
        if let Some(rest) = l.strip_prefix("PR[1,") {
            let k: usize = rest[..rest.find(']').unwrap()].parse().unwrap();
            let v = rest[rest.find('=').unwrap() + 1..rest.find(';').unwrap()].trim();
            pr[k - 1] = v.parse().unwrap();
        } else if let Some(rest) = l.strip_prefix("!   ") {
            let (k, v) = rest.split_once(':').unwrap();
            screen.insert(k.to_string(), v.trim().parse::<f64>().unwrap());
        }
    }
    assert!(text.lines().any(|l| l.trim() == "UTOOL[1]=PR[1] ;"));
    for (k, name) in ["X", "Y", "Z", "W", "P", "R"].iter().enumerate() {
        assert_eq!(screen[*name], pr[k], "screen value {name}");
    }
    pose(
        [pr[0], pr[1], pr[2]],
        rz(pr[5].to_radians()) * ry(pr[4].to_radians()) * rx(pr[3].to_radians()),
    )
}

/// URScript: `set_tcp(p[x, y, z, rx, ry, rz])`, m and a rotation vector.
pub fn read_ur_tcp(text: &str) -> Isometry3<f64> {
    let line = text.lines().find(|l| l.starts_with("set_tcp(p[")).unwrap();
    let v: Vec<f64> = line["set_tcp(p[".len()..line.find("])").unwrap()]
        .split(',')
        .map(|s| s.trim().parse().unwrap())
        .collect();
    pose(
        [v[0] * 1000.0, v[1] * 1000.0, v[2] * 1000.0],
        rotvec_matrix(Vector3::new(v[3], v[4], v[5])),
    )
}

/// ROS 2 `static_transform_publisher --x … --roll … --frame-id tool0
/// --child-frame-id sensor` and the URDF joint, read by `urdf-rs`; both
/// must give the same pose.
pub fn read_ros(text: &str) -> Isometry3<f64> {
    let line = text
        .lines()
        .find(|l| l.starts_with("ros2 run tf2_ros static_transform_publisher"))
        .unwrap();
    let words: Vec<&str> = line.split_whitespace().collect();
    let arg = |k: &str| words[words.iter().position(|w| *w == k).unwrap() + 1];
    let num = |k: &str| arg(k).parse::<f64>().unwrap();
    assert_eq!(arg("--frame-id"), "tool0");
    assert_eq!(arg("--child-frame-id"), "sensor");
    let tf = pose(
        [num("--x") * 1e3, num("--y") * 1e3, num("--z") * 1e3],
        rpy_matrix(num("--roll"), num("--pitch"), num("--yaw")),
    );
    let xml: String = text
        .lines()
        .filter(|l| l.trim_start().starts_with('<'))
        .collect::<Vec<_>>()
        .join("\n");
    let robot = urdf_rs::read_from_string(&format!(
        "<robot name=\"t\"><link name=\"tool0\"/>{xml}</robot>"
    ))
    .unwrap();
    let j = robot
        .joints
        .iter()
        .find(|j| j.name == "sensor_joint")
        .unwrap();
    assert_eq!(j.parent.link, "tool0");
    assert_eq!(j.child.link, "sensor");
    let [x, y, z] = j.origin.xyz.0;
    let [r, p, yw] = j.origin.rpy.0;
    let urdf = pose([x * 1e3, y * 1e3, z * 1e3], rpy_matrix(r, p, yw));
    assert_same(&tf, &urdf, 1e-9, 1e-12, "ROS line and URDF joint");
    tf
}
