//! The Delta3 kinematics for a controller or a harness to cross-check its own (SPEC
//! section 2).

use super::convert;
use super::handle::boundary;
use super::types::*;

/// Elbow-out inverse kinematics (SPEC section 2) of `tcp_mcs`, for a controller or a test harness
/// to cross-check its own kinematics. Writes `out_theta[0..3]` (rad) on success.
/// Statuses: `DC_STATUS_NULL_POINTER`, `DC_STATUS_NON_FINITE`, `DC_STATUS_INVALID_CONFIG`
/// (bad geometry), `DC_STATUS_UNREACHABLE`.
///
/// # Safety
/// `geometry` must be NULL or valid; `out_theta` must be NULL or hold 3 writable doubles.
#[no_mangle]
pub unsafe extern "C" fn dc_delta3_inverse_kinematics(
    geometry: *const DcDelta3,
    tcp_mcs: DcVec3,
    out_theta: *mut f64,
) -> DcStatus {
    boundary(|| {
        // SAFETY: the caller guarantees `geometry` is NULL or valid.
        let Some(g) = (unsafe { geometry.as_ref() }) else { return DC_STATUS_NULL_POINTER };
        if out_theta.is_null() {
            return DC_STATUS_NULL_POINTER;
        }
        if !tcp_mcs.is_finite() {
            return DC_STATUS_NON_FINITE;
        }
        let d = match convert::delta3_from_c(g) {
            Ok(d) => d,
            Err(s) => return s,
        };
        match d.inverse_kinematics(&tcp_mcs.to_vec3()) {
            Ok(sol) => {
                // SAFETY: non-null, and the caller guarantees 3 writable doubles.
                unsafe { std::ptr::copy_nonoverlapping(sol.theta.as_ptr(), out_theta, 3) };
                DC_STATUS_OK
            }
            Err(_) => DC_STATUS_UNREACHABLE,
        }
    })
}

/// Forward kinematics (SPEC section 2): the TCP for motor angles `theta[0..3]` (rad), written to
/// `*out_tcp`. Statuses: `DC_STATUS_NULL_POINTER`, `DC_STATUS_NON_FINITE`,
/// `DC_STATUS_INVALID_CONFIG`, `DC_STATUS_UNREACHABLE` (the three spheres do not meet).
///
/// # Safety
/// `geometry` must be NULL or valid; `theta` NULL or 3 readable doubles; `out_tcp` NULL or
/// writable.
#[no_mangle]
pub unsafe extern "C" fn dc_delta3_forward_kinematics(
    geometry: *const DcDelta3,
    theta: *const f64,
    out_tcp: *mut DcVec3,
) -> DcStatus {
    boundary(|| {
        // SAFETY: the caller guarantees `geometry` is NULL or valid.
        let Some(g) = (unsafe { geometry.as_ref() }) else { return DC_STATUS_NULL_POINTER };
        if theta.is_null() || out_tcp.is_null() {
            return DC_STATUS_NULL_POINTER;
        }
        // SAFETY: non-null, and the caller guarantees 3 readable doubles.
        let theta: [f64; 3] = unsafe { std::ptr::read_unaligned(theta.cast()) };
        if !theta.iter().all(|t| t.is_finite()) {
            return DC_STATUS_NON_FINITE;
        }
        let d = match convert::delta3_from_c(g) {
            Ok(d) => d,
            Err(s) => return s,
        };
        match d.forward_kinematics(&theta) {
            Some(p) => {
                // SAFETY: non-null; the caller guarantees it is writable.
                unsafe { *out_tcp = DcVec3::from_vec3(&p) };
                DC_STATUS_OK
            }
            None => DC_STATUS_UNREACHABLE,
        }
    })
}
