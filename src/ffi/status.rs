//! What the library says of itself: the text of a status, its version.

use super::types::*;
use std::ffi::{c_char, CStr};

/// Each status and its text.
const STATUS_TEXT: [(DcStatus, &CStr); 28] = [
    (DC_STATUS_OK, c"ok"),
    (DC_STATUS_NULL_POINTER, c"a required pointer argument is NULL"),
    (DC_STATUS_NON_FINITE, c"an input number is NaN or infinite"),
    (DC_STATUS_UNREACHABLE, c"a TCP is outside its robot's reach or motor limits"),
    (DC_STATUS_INVALID_CONFIG, c"a configuration value is out of range"),
    (DC_STATUS_WRONG_ROBOT_COUNT, c"the number of TCPs differs from the number of robots"),
    (DC_STATUS_IO, c"a file could not be read"),
    (DC_STATUS_PARSE, c"the cell file is not valid TOML or does not follow the schema"),
    (DC_STATUS_PANIC, c"internal error caught at the library boundary; destroy the handle"),
    (DC_STATUS_INVALID_ARGUMENT, c"an argument is malformed (path not UTF-8, capacity too small)"),
    (DC_STATUS_TABLE_TRUNCATED, c"the table is truncated: copy the whole table file again"),
    (DC_STATUS_TABLE_BAD_MAGIC, c"not a delta-collide table (bad magic): check that the right file or buffer is given"),
    (DC_STATUS_TABLE_UNSUPPORTED_VERSION, c"the table's format version is not supported: rebuild it with `delta-collide build`"),
    (DC_STATUS_TABLE_WRONG_ENDIANNESS, c"the table is big-endian, this library reads little-endian tables: rebuild it with `delta-collide build`"),
    (DC_STATUS_TABLE_CORRUPT, c"the table is corrupt (checksum or a field): rebuild it or copy it again"),
    (DC_STATUS_TABLE_WRONG_CELL, c"the table was built for another cell: rebuild it with `delta-collide build --cell ...` for this cell"),
    (DC_STATUS_TABLE_NOT_TWO_ROBOTS, c"a table serves a cell of two or more robots: use dc_init (exact mode) for this cell"),
    (DC_STATUS_IMPLAUSIBLE_MOTION, c"a TCP moved further or changed its velocity more in one tick than its stopping model allows"),
    (DC_STATUS_TABLE_MISSING_PAIR, c"the table bundle holds no table for a pair that can meet: rebuild it with `delta-collide build --cell ...`"),
    (DC_STATUS_TABLE_WRONG_PAIR, c"the table bundle's table for a pair was built for another spacing: rebuild it with `delta-collide build --cell ...`"),
    (DC_STATUS_TIME_REPEATED, c"the same cycle as the last protective call, with other TCPs"),
    (DC_STATUS_TIME_BACKWARDS, c"a cycle or timestamp before the last protective call's"),
    (DC_STATUS_TIME_JUMP, c"more than DC_MAX_INTERVAL_TICKS ticks since the last protective call"),
    (DC_STATUS_TIME_EARLY, c"a timestamp less than half a tick after the last protective call's"),
    (DC_STATUS_CLOCK_CHANGED, c"a cycle counter after a timestamp, or a timestamp after a cycle counter"),
    (DC_STATUS_BUSY, c"the handle is in use by another call: give each task its own handle"),
    (DC_STATUS_INVALID_PROGRAMME, c"a programme has no points or more than DC_MAX_PROGRAMME_POINTS, stride_ticks 0, or first_tick not a multiple of stride_ticks"),
    (DC_STATUS_PROGRESS_OUT_OF_RANGE, c"a programme's progress lies outside its points' ticks, or its override_now outside [0, 1]"),
];

/// A static, NUL-terminated English description of `status`; never NULL.
#[no_mangle]
pub extern "C" fn dc_status_str(status: DcStatus) -> *const c_char {
    let text = STATUS_TEXT.iter().find(|(s, _)| *s == status).map_or(c"unknown status", |(_, t)| t);
    text.as_ptr()
}

/// The library version, a static NUL-terminated string such as "0.1.0".
#[no_mangle]
pub extern "C" fn dc_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}
