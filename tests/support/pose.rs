//! Pose-file writers shared by the pose-file tests (`pose_files`, the
//! command line and the engine) and the workbench's Import view test
//! (`ui_import_poses`): a FANUC TP program and a headerless table, both
//! of flange poses in FANUC's x y z W P R (mm, degrees).

#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use std::fmt::Write as _;

use nalgebra::Isometry3;
use spherecal::engine::base::session::{Observation, Session};
use spherecal::engine::files::import::FlangeConvention;
use spherecal::engine::tools::simulate::Truth;

/// The true flange poses (`base_from_flange`, mm) and the stripes (`[y, z]`
/// in the laser plane, mm) of a simulated session's measurements of
/// `station`, in the session's order.
pub fn station_poses(
    session: &Session,
    truth: &Truth,
    station: &str,
) -> (Vec<Isometry3<f64>>, Vec<Vec<[f64; 2]>>) {
    let robot = truth.true_robot();
    let (mut poses, mut stripes) = (Vec::new(), Vec::new());
    for m in session.measurements.iter().filter(|m| m.station == station) {
        poses.push(robot.base_from_flange(&m.joints));
        let Observation::Stripe(p) = &m.observation else {
            panic!("stripes expected")
        };
        stripes.push(p.clone());
    }
    (poses, stripes)
}

/// A FANUC TP program: positions in `/POS` (GP1, and a GP2 block), moved
/// through by `/MN`, recorded in user frame 0 with tool `tool` (any tool
/// but 0 draws the importer's warning).
pub fn fanuc_ls(poses: &[Isometry3<f64>], tool: u32) -> String {
    let mut t = format!(
        "/PROG  CALIB_SPH\n/ATTR\nOWNER\t\t= MNEDITOR;\nCOMMENT\t\t= \"\";\nDEFAULT_GROUP\t= 1,1,*,*,*;\n/MN\n   1:  UFRAME_NUM=0 ;\n   2:  UTOOL_NUM={tool} ;\n",
    );
    for k in 0..poses.len() {
        writeln!(t, "{:>4}:J P[{}] 100% FINE    ;", k + 3, k + 1).unwrap();
    }
    t.push_str("/POS\n");
    for (k, p) in poses.iter().enumerate() {
        let v = FlangeConvention::FanucWpr.values_from_pose(p);
        writeln!(
            t,
            "P[{}]{{\n   GP1:\n\tUF : 0, UT : {tool},\t\tCONFIG : 'N U T, 0, 0, -1',\n\tX = {:>12.6}  mm,\tY = {:>12.6}  mm,\tZ = {:>12.6}  mm,\n\tW = {:>12.9} deg,\tP = {:>12.9} deg,\tR = {:>12.9} deg\n   GP2:\n\tUF : 0, UT : {tool},\t\n\tJ1=     6.207 deg\n}};",
            k + 1, v[0], v[1], v[2], v[3], v[4], v[5]
        )
        .unwrap();
    }
    t.push_str("/END\n");
    t
}

/// Six numbers a line, separated by spaces, no header (FANUC x y z W P R).
pub fn headerless_table(poses: &[Isometry3<f64>]) -> String {
    let mut t = String::new();
    for p in poses {
        let v = FlangeConvention::FanucWpr.values_from_pose(p);
        let cells: Vec<String> = v.iter().map(|x| format!("{x:.9}")).collect();
        writeln!(t, "{}", cells.join("   ")).unwrap();
    }
    t
}
