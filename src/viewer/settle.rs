//! When the window's surface is configured after a resize
//! ([`SurfaceGate`]). Each configuration creates a swapchain, and Mesa
//! lavapipe once blocked for ever inside `vkCreateSwapchainKHR`, waiting
//! on an X reply, during a storm of resizes (`benches/soak.sh`; see
//! `watchdog.rs`). So a new size is configured only once it has held for
//! [`SETTLE`] (a dragged window reconfigures once at the end, not at every
//! step), and never below [`MIN_SIDE`] pixels a side; until then nothing is
//! presented (presenting to a surface of the wrong size spins in pixels'
//! retry loop) and the last picture stays on screen.

use std::time::{Duration, Instant};

/// How long a window size must hold before the surface takes it.
pub const SETTLE: Duration = Duration::from_millis(100);

/// Sides below this many pixels get no surface: nothing is presented to a
/// window that small (zero-area and tiny swapchains are what the drivers
/// mishandle).
pub const MIN_SIDE: u32 = 16;

/// What to do with the surface before presenting.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Gate {
    /// The surface has the window's size: present.
    Ready,
    /// Configure the surface at the window's size, then present.
    Configure,
    /// Do not present; ask again at this instant (`None`: at the next
    /// resize, the window being too small).
    Wait(Option<Instant>),
}

/// The window size that the surface does not have yet, and since when the
/// window has had it.
#[derive(Clone, Copy, Debug, Default)]
pub struct SurfaceGate {
    pending: Option<((u32, u32), Instant)>,
}

impl SurfaceGate {
    /// What to do for a surface of size `surface` in a window of size
    /// `window` at `now`.
    pub fn check(&mut self, surface: (u32, u32), window: (u32, u32), now: Instant) -> Gate {
        if window.0 < MIN_SIDE || window.1 < MIN_SIDE {
            self.pending = None;
            return Gate::Wait(None);
        }
        if window == surface {
            self.pending = None;
            return Gate::Ready;
        }
        let since = match self.pending {
            Some((size, since)) if size == window => since,
            _ => {
                self.pending = Some((window, now));
                now
            }
        };
        if now.duration_since(since) >= SETTLE {
            self.pending = None;
            Gate::Configure
        } else {
            Gate::Wait(Some(since + SETTLE))
        }
    }
}

/// Tries at the surface's next texture per present: a surface still out
/// of date after this many reconfigurations is left for the next present.
pub const ACQUIRE_TRIES: u32 = 3;

/// What one try at the surface's next texture gave.
pub enum Try<T> {
    Got(T),
    /// Out of date, lost or suboptimal (with the texture, dropped before
    /// reconfiguring): configure the surface again and retry.
    Stale(Option<T>),
    /// Nothing to draw on now (occluded, timed out): skip this present.
    Skip,
    Fail(String),
}

/// The surface's next texture, with at most [`ACQUIRE_TRIES`] tries
/// (`reconfigure` between them): `Ok(None)` when none came, and the
/// present is skipped (the caller asks again shortly). pixels' own loop
/// retried without bound, and a resize during a present could spin there.
pub fn acquire<T>(mut get: impl FnMut() -> Try<T>, mut reconfigure: impl FnMut()) -> Result<Option<T>, String> {
    for _ in 0..ACQUIRE_TRIES {
        match get() {
            Try::Got(t) => return Ok(Some(t)),
            Try::Stale(t) => {
                drop(t);
                reconfigure();
            }
            Try::Skip => return Ok(None),
            Try::Fail(e) => return Err(e),
        }
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A surface that stays out of date is tried a bounded number of
    /// times, reconfigured between tries, and the present skipped; one that
    /// comes back on the second try is used; errors and skips pass through.
    #[test]
    fn the_surface_is_acquired_with_a_bounded_retry() {
        let (mut tries, mut configured) = (0, 0);
        let got = acquire::<u8>(
            || {
                tries += 1;
                assert!(tries < 1000, "spins on a stale surface");
                Try::Stale(None)
            },
            || configured += 1,
        );
        assert_eq!(got, Ok(None));
        assert_eq!((tries, configured), (ACQUIRE_TRIES, ACQUIRE_TRIES));
        let mut answers = vec![Try::Got(7u8), Try::Stale(Some(1))];
        assert_eq!(acquire(|| answers.pop().unwrap(), || {}), Ok(Some(7)));
        assert_eq!(acquire::<u8>(|| Try::Skip, || panic!("no retry")), Ok(None));
        assert_eq!(acquire::<u8>(|| Try::Fail("lost".into()), || {}), Err("lost".into()));
    }

    /// A storm of resizes configures the surface once, at its last size,
    /// after that size has held for `SETTLE`; a tiny or empty window is
    /// never configured; a window of the surface's size presents at once.
    #[test]
    fn a_storm_of_resizes_configures_once_at_the_end() {
        let t0 = Instant::now();
        let ms = |m: u64| t0 + Duration::from_millis(m);
        let mut g = SurfaceGate::default();
        let surface = (800, 600);
        assert_eq!(g.check(surface, surface, t0), Gate::Ready);
        // A new size every 20 ms for a second, some of them tiny or empty.
        let mut configured = 0;
        for i in 0..50u32 {
            let size = match i % 5 {
                0 => (0, 0),
                1 => (40, 3),
                _ => (300 + 7 * i, 200 + 3 * i),
            };
            let gate = g.check(surface, size, ms(20 * u64::from(i)));
            configured += usize::from(gate == Gate::Configure);
            match gate {
                Gate::Wait(None) => assert!(size.0 < MIN_SIDE || size.1 < MIN_SIDE, "{size:?}"),
                Gate::Wait(Some(t)) => assert!(t > ms(20 * u64::from(i)) && t <= ms(20 * u64::from(i)) + SETTLE),
                other => panic!("{other:?} in the storm at {size:?}"),
            }
        }
        assert_eq!(configured, 0);
        // The last size holds: waits until SETTLE after it first came.
        let last = (900, 700);
        let Gate::Wait(Some(at)) = g.check(surface, last, ms(1000)) else {
            panic!("a new size waits")
        };
        assert_eq!(at, ms(1000) + SETTLE);
        assert_eq!(g.check(surface, last, ms(1050)), Gate::Wait(Some(at)));
        assert_eq!(g.check(surface, last, at), Gate::Configure);
        // Configured: the surface has the size now.
        assert_eq!(g.check(last, last, ms(1200)), Gate::Ready);
        // Back to a size the surface has, during a wait: ready at once.
        assert!(matches!(g.check(last, (640, 480), ms(1300)), Gate::Wait(Some(_))));
        assert_eq!(g.check(last, last, ms(1310)), Gate::Ready);
        // A minimised window (0×0) never configures, however long.
        assert_eq!(g.check(last, (0, 0), ms(1400)), Gate::Wait(None));
        assert_eq!(g.check(last, (0, 0), ms(90_000)), Gate::Wait(None));
    }
}
