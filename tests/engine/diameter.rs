//! Issue 34: a wrong sphere diameter is said as such ("check the sphere
//! diameter", with the circle radii), in the engine message `import`
//! and the workbench share, not only as an undecidable side.

#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use spherecal::engine::assemble::side::diameter_misfit;
use spherecal::engine::tools::simulate::{self, SimConfig};

fn session() -> spherecal::engine::base::session::Session {
    simulate::simulate(&SimConfig {
        n_identify: 3,
        n_validate: 0,
        ..SimConfig::default()
    })
    .unwrap()
    .0
}

#[test]
fn circle_radii_tell_a_wrong_diameter() {
    let mut s = session();
    let right = s.sphere_diameter;
    assert_eq!(diameter_misfit(&s), None, "the right diameter fits");
    // Too large (80 for a 25.4 mm ball is the same ratio).
    s.sphere_diameter = right * 80.0 / 25.4;
    let said = diameter_misfit(&s).expect("too large is said");
    assert!(said.contains("check the sphere diameter"), "{said}");
    assert!(said.contains("% of the sphere radius"), "{said}");
    // Too small: the circles are larger than the sphere.
    s.sphere_diameter = right * 0.6;
    let said = diameter_misfit(&s).expect("too small is said");
    assert!(said.contains("larger than the sphere"), "{said}");
    assert!(said.contains("check the sphere diameter"), "{said}");
    // A little off is not in doubt (the side and the fit tell the rest).
    s.sphere_diameter = right * 1.1;
    assert_eq!(diameter_misfit(&s), None);
}
