//! A bound on `--exit-after` that holds even when the main thread cannot
//! return to the event loop. A 10-minute `benches/soak.sh` froze the window
//! at 594 s inside Mesa lavapipe's `create_swapchain`, which waited for ever
//! on an X reply (`xcb_wait_for_reply`, poll without timeout) while pixels
//! reconfigured an out-of-date surface; the loop that would have closed the
//! window at `--exit-after` never ran again. The cause lies in the driver;
//! this makes the window's own promise hold: the process ends, with one
//! line saying why and exit status 1, a few seconds after the limit.
//!
//! The timing is [`watch`], with the clock's sleep and the ending passed
//! in, so that a test runs it without a window and without waiting.

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
        .spawn(move || watch(limit, std::thread::sleep, end_process));
    if let Err(e) = spawned {
        eprintln!("warning: no watchdog for --exit-after: {e}");
    }
}

/// The watchdog's body: sleeps `limit` + [`GRACE_S`] seconds (by `sleep`,
/// in one call), then ends the process through `end` with the line to
/// print. A limit that is not a non-negative finite number of seconds
/// (the command line refuses one) ends it at once rather than never.
pub fn watch(limit: f64, sleep: impl FnOnce(Duration), end: impl FnOnce(&str)) {
    let wait = Duration::try_from_secs_f64(limit + GRACE_S).unwrap_or(Duration::ZERO);
    sleep(wait);
    end(&format!(
        "error: the window did not close {GRACE_S} s after --exit-after {limit} (the main thread is not answering; a graphics driver call may be stuck); ending the process"
    ));
}

/// How the watchdog ends a stuck window: the line on stderr, exit status 1.
fn end_process(line: &str) {
    eprintln!("{line}");
    std::process::exit(1);
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::mpsc;
    use std::time::Instant;

    /// The watchdog sleeps exactly the limit plus the grace, once, then
    /// ends the process with a line naming the limit; with no limit it
    /// does not start.
    #[test]
    fn ends_the_process_grace_seconds_after_the_limit() {
        for limit in [0.0, 2.5, 600.0] {
            let mut slept = Vec::new();
            let mut ended = Vec::new();
            watch(limit, |d| slept.push(d), |line| ended.push(line.to_string()));
            assert_eq!(slept, [Duration::from_secs_f64(limit + GRACE_S)]);
            assert_eq!(ended.len(), 1);
            assert!(ended[0].starts_with("error: ") && ended[0].contains(&format!("--exit-after {limit}")));
            assert!(!ended[0].contains('\n'), "one line");
        }
        // Not a number of seconds: no sleep for ever, and it still ends.
        for limit in [f64::NAN, f64::INFINITY, -20.0] {
            let mut slept = Vec::new();
            let mut ended = 0;
            watch(limit, |d| slept.push(d), |_| ended += 1);
            assert_eq!((slept, ended), (vec![Duration::ZERO], 1), "{limit}");
        }
    }

    /// On a real clock the ending comes after the sleep, on the watchdog's
    /// own thread, while the thread that armed it is blocked: a bound
    /// from below only (no timed assertion on speed).
    #[test]
    fn ends_from_its_own_thread_after_the_sleep() {
        let (tx, rx) = mpsc::channel();
        let start = Instant::now();
        let nap = Duration::from_millis(30);
        std::thread::spawn(move || {
            watch(
                -GRACE_S,
                |_| std::thread::sleep(nap),
                |_| {
                    tx.send(Instant::now()).expect("the test waits");
                },
            )
        });
        let at = rx.recv().expect("the watchdog ends");
        assert!(at.duration_since(start) >= nap);
    }
}
