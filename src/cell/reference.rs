//! The reference cells T1, T2, T3 of SPEC §5, built from the cell files shipped in `cells/`.
//!
//! The files are compiled in, so the built-in cells and the files can never disagree.

use crate::cell::{parse_cell, Cell};

/// The text of the reference cell files, by name.
pub const REFERENCE_CELL_FILES: [(&str, &str); 3] = [
    ("T1", include_str!("../../cells/t1.toml")),
    ("T2", include_str!("../../cells/t2.toml")),
    ("T3", include_str!("../../cells/t3.toml")),
];

/// Reference cell `name` ("T1", "T2" or "T3", any case), or `None`.
pub fn reference_cell(name: &str) -> Option<Cell> {
    REFERENCE_CELL_FILES
        .iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(name))
        .map(|(_, text)| parse_cell(text).expect("shipped reference cell files are valid"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::{ExactChecker, Placement};
    use crate::math::Vec3;
    use crate::robot::RobotModel;
    use std::f64::consts::PI;

    #[test]
    fn reference_cells_follow_spec_section_5() {
        let expect =
            [("T1", 450.0, 0.0, 0.0), ("T2", 400.0, 0.0, 0.0), ("T3", 430.0, 150.0, PI / 6.0)];
        for (name, x, y, alpha) in expect {
            let cell = reference_cell(name).unwrap();
            assert_eq!(cell.robots.len(), 2);
            assert_eq!(cell.robots[0].placement, Placement::IDENTITY);
            let b = &cell.robots[1].placement;
            assert!(
                (b.t - Vec3::new(x, y, 0.0)).norm() < 1e-12 && (b.alpha - alpha).abs() < 1e-15,
                "{name}"
            );
            assert!(cell.robots.iter().all(|r| r.model == RobotModel::THESIS));
            assert_eq!(cell.pairs_that_can_meet(), vec![(0, 1)]);
        }
        assert!(reference_cell("t4").is_none());
    }

    #[test]
    fn robots_reaching_toward_each_other_collide_and_apart_do_not() {
        for name in ["T1", "T2", "T3"] {
            let cell = reference_cell(name).unwrap();
            let pb = cell.robots[1].placement;
            let mut checker = ExactChecker::new(cell);
            // Both TCPs at the midpoint between the bases: certainly a collision.
            let mid = pb.t * 0.5 + Vec3::new(0.0, 0.0, -450.0);
            let v = checker.check(&[mid, pb.to_mcs(&mid)]).unwrap();
            assert!(v.all_reachable() && v.collides(), "{name}");
            // Both far back, away from each other.
            let back = pb.t.normalize() * 200.0;
            let tcp_a = Vec3::new(-back.x, -back.y, -400.0);
            let tcp_b = pb.to_mcs(&(pb.t + back + Vec3::new(0.0, 0.0, -400.0)));
            let v = checker.check(&[tcp_a, tcp_b]).unwrap();
            assert!(v.all_reachable() && !v.collides(), "{name}");
        }
    }
}
