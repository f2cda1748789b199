//! A result's tables as CSV for spreadsheets: every sphere centre
//! (sensor frame, base frame before and after) and the distance errors
//! (reference distances and within-station distances), the workbench's
//! Centres CSV and Distances CSV exports.

use std::fmt::Write as _;

use crate::engine::calibrate::validate::DistanceRecord;
use crate::engine::files::format::ResultFile;
use crate::engine::files::format::result::CentreRecord;
use crate::engine::files::table::csv_field;
use crate::engine::tools::result_view::{PairDistance, ResultFigures};

/// CSV of every sphere centre: sensor frame and base frame before and
/// after, mm.
#[must_use]
pub fn centres_csv(result: &ResultFile) -> String {
    let header = "measurement,station,use,sensor_x_mm,sensor_y_mm,sensor_z_mm,before_x_mm,before_y_mm,before_z_mm,after_x_mm,after_y_mm,after_z_mm\n";
    header.to_string() + &centres_rows(&result.centres)
}

/// The rows of [`centres_csv`], one a centre.
fn centres_rows(centres: &[CentreRecord]) -> String {
    let mut s = String::new();
    for c in centres {
        let _ = write!(
            s,
            "{},{},{}",
            csv_field(&c.measurement),
            csv_field(&c.station),
            c.usage.as_str()
        );
        for v in c.sensor.iter().chain(&c.before).chain(&c.after) {
            let _ = write!(s, ",{v}");
        }
        s.push('\n');
    }
    s
}

/// CSV of the distance errors: the reference distances (paper Fig. 6,
/// `kind` = `reference`, error = measured − reference) and the
/// within-station centre distances (Fig. 5, `kind` = `within_station`,
/// reference 0), mm.
#[must_use]
pub fn distances_csv(shown: &ResultFigures) -> String {
    let header =
        "kind,from,to,pose,reference_mm,before_mm,after_mm,error_before_mm,error_after_mm\n";
    header.to_string() + &distances_rows(&shown.distances, &shown.within)
}

/// The rows of [`distances_csv`]: the reference distances, then the
/// within-station pairs.
fn distances_rows(distances: &[DistanceRecord], within: &[PairDistance]) -> String {
    let mut s = String::new();
    for d in distances {
        let _ = writeln!(
            s,
            "reference,{},{},{},{},{},{},{},{}",
            csv_field(&d.from),
            csv_field(&d.to),
            d.pose,
            d.reference,
            d.before,
            d.after,
            d.error_before(),
            d.error_after()
        );
    }
    for p in within {
        let _ = writeln!(
            s,
            "within_station,{},{},{}/{},0,{},{},{},{}",
            csv_field(&p.station),
            csv_field(&p.station),
            csv_field(&p.ids.0),
            csv_field(&p.ids.1),
            p.before,
            p.after,
            p.before,
            p.after
        );
    }
    s
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::engine::base::session::Use;

    #[test]
    fn the_centres_are_one_row_each_with_nine_coordinates() {
        let centres = [CentreRecord {
            measurement: "m,1".into(),
            station: "P1".into(),
            usage: Use::Identify,
            sensor: [1.0, 2.0, 3.0],
            before: [4.0, 5.0, 6.5],
            after: [7.0, 8.0, 9.25],
        }];
        let rows = centres_rows(&centres);
        assert_eq!(rows, "\"m,1\",P1,identify,1,2,3,4,5,6.5,7,8,9.25\n");
    }

    #[test]
    fn the_distances_are_the_reference_errors_then_the_within_station_pairs() {
        let distances = [DistanceRecord {
            from: "V1".into(),
            to: "V2".into(),
            pose: 2,
            reference: 100.0,
            before: 100.5,
            after: 99.75,
        }];
        let within = [PairDistance {
            station: "P1".into(),
            ids: ("a".into(), "b".into()),
            before: 0.5,
            after: 0.25,
        }];
        let rows = distances_rows(&distances, &within);
        assert_eq!(
            rows,
            "reference,V1,V2,2,100,100.5,99.75,0.5,-0.25\nwithin_station,P1,P1,a/b,0,0.5,0.25,0.5,0.25\n"
        );
    }
}
