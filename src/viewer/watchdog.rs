//! A bound on `--exit-after` that holds even when the main thread cannot
//! return to the event loop. A 10-minute `benches/soak.sh` froze the window
//! at 594 s inside Mesa lavapipe's `create_swapchain`, which waited for ever
//! on an X reply (`xcb_wait_for_reply`, poll without timeout) while pixels
//! reconfigured an out-of-date surface; the loop that would have closed the
//! window at `--exit-after` never ran again. The cause lies in the driver;
//! this makes the window's own promise hold: the process ends, with one
//! line saying why and exit status 1, a few seconds after the limit.

use std::time::Duration;

/// Seconds after `--exit-after` at which a window that has not closed is
/// ended.
pub const GRACE_S: f64 = 10.0;

/// Starts the watchdog for `exit_after` seconds (none without a limit).
pub fn arm(exit_after: Option<f64>) {
    let Some(limit) = exit_after else {
        return;
    };
    let spawned = std::thread::Builder::new()
        .name("lensview-watchdog".into())
        .spawn(move || {
            std::thread::sleep(Duration::from_secs_f64(limit + GRACE_S));
            eprintln!(
                "error: the window did not close {GRACE_S} s after --exit-after {limit} (the main thread is not answering; a graphics driver call may be stuck); ending the process"
            );
            std::process::exit(1);
        });
    if let Err(e) = spawned {
        eprintln!("warning: no watchdog for --exit-after: {e}");
    }
}
