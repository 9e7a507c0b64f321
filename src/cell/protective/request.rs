//! One protective call's inputs in one value, as Coal's `CollisionRequest` gathers a query's
//! options: when the TCPs hold ([`TickTime`]), the TCPs, the stop paths a controller knows
//! and a clearance table's bound. [`ProtectiveChecker::check`](super::ProtectiveChecker::check)
//! takes it; a slice of TCPs converts into the request of an untimed call.

use super::clock::TickTime;
use super::lookup::ClearanceBound;
use super::path::StopPath;
use crate::math::Vec3;

/// The inputs of one protective call.
#[derive(Clone, Copy)]
pub struct ProtectiveRequest<'a> {
    /// When the TCPs hold; [`TickTime::Nominal`] for a controller that calls exactly once
    /// per cycle at its nominal time.
    pub time: TickTime,
    /// Robot `j`'s TCP now, in its own MCS.
    pub tcps_mcs: &'a [Vec3],
    /// Per robot, the path its stop will follow (`None`: not known); empty: no paths.
    pub paths: &'a [Option<StopPath<'a>>],
    /// A certified lower bound on the clearance at any TCPs (a clearance table's): table
    /// mode (`protective/lookup.rs`).
    pub table: Option<ClearanceBound<'a>>,
}

impl<'a> ProtectiveRequest<'a> {
    /// An untimed request for `tcps_mcs`, without paths or table.
    pub fn new(tcps_mcs: &'a [Vec3]) -> Self {
        ProtectiveRequest { time: TickTime::Nominal, tcps_mcs, paths: &[], table: None }
    }

    /// This request with the time its TCPs hold.
    pub fn at(self, time: TickTime) -> Self {
        ProtectiveRequest { time, ..self }
    }

    /// This request with the robots' stop paths (one entry per robot).
    pub fn with_paths(self, paths: &'a [Option<StopPath<'a>>]) -> Self {
        ProtectiveRequest { paths, ..self }
    }

    /// This request in table mode with `bound`.
    pub fn with_table(self, bound: ClearanceBound<'a>) -> Self {
        ProtectiveRequest { table: Some(bound), ..self }
    }
}

impl<'a> From<&'a [Vec3]> for ProtectiveRequest<'a> {
    fn from(tcps_mcs: &'a [Vec3]) -> Self {
        ProtectiveRequest::new(tcps_mcs)
    }
}

impl<'a, const N: usize> From<&'a [Vec3; N]> for ProtectiveRequest<'a> {
    fn from(tcps_mcs: &'a [Vec3; N]) -> Self {
        ProtectiveRequest::new(tcps_mcs)
    }
}

impl<'a> From<&'a alloc::vec::Vec<Vec3>> for ProtectiveRequest<'a> {
    fn from(tcps_mcs: &'a alloc::vec::Vec<Vec3>) -> Self {
        ProtectiveRequest::new(tcps_mcs)
    }
}
