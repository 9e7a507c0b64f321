//! The labelling's progress bar on stderr: the library reports rows done
//! ([`delta_collide::cspace::Progress::Rows`]) and prints nothing itself.

use indicatif::{ProgressBar, ProgressStyle};
use std::sync::Mutex;

/// The bar of the labelling pass under way, if any.
static BAR: Mutex<Option<ProgressBar>> = Mutex::new(None);

/// Shows `done` of `rows` rows of A labelled; the pass's last row clears the bar. Reports come
/// from the labelling's worker threads, so the position only ever moves forward.
pub fn labelling_rows(done: u64, rows: u64) {
    let Ok(mut slot) = BAR.lock() else { return };
    let bar = slot.get_or_insert_with(|| {
        let bar = ProgressBar::new(rows);
        if let Ok(style) = ProgressStyle::with_template(
            "labelling {bar:40} {pos}/{len} rows of A, {elapsed} (eta {eta})",
        ) {
            bar.set_style(style);
        }
        bar
    });
    bar.set_position(bar.position().max(done));
    if done >= rows {
        bar.finish_and_clear();
        *slot = None;
    }
}
