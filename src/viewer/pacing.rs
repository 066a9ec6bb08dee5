//! When the window presents. A present is never repeated for nothing (the
//! same frame and an unchanged UI), happens at most once per display
//! refresh, and, when the adapter is a CPU rasterizer (Mesa lavapipe,
//! llvmpipe: presenting takes the tracer's cores), the refining frames of a
//! generation after its first are shown at least [`CPU_PACE`] apart, and
//! further apart when presents would take more than [`PRESENT_SHARE`] of
//! the machine's CPU time. The
//! first frame of a new generation (the answer to an input) goes at once;
//! a UI change made by that input (the message line, the overlay's figures)
//! waits for it, up to [`AWAIT_LIMIT`], so the two share one present.
//!
//! Pure bookkeeping over instants given by the caller: the shell tells it
//! what happened and asks [`Pacer::decide`] on every redraw request.

use std::time::{Duration, Instant};

/// Least time between two refining frames on a CPU rasterizer: 10 a second.
pub const CPU_PACE: Duration = Duration::from_millis(100);
/// On a CPU rasterizer, the share of the machine's CPU time that presenting
/// refining frames may take: a present costing `c` on `n` cores is
/// followed by at least `c / (PRESENT_SHARE · n)` (2 cores, 27 ms: 270 ms).
pub const PRESENT_SHARE: f64 = 0.05;
/// How long a UI change waits for the first frame of the generation its
/// input started.
pub const AWAIT_LIMIT: Duration = Duration::from_millis(100);

/// What to do with a redraw request.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Decision {
    /// Nothing changed since the last present.
    Skip,
    Now,
    /// Ask again at this instant (the frame or UI change stays pending).
    At(Instant),
}

pub struct Pacer {
    /// Presents cost the CPU the tracer uses.
    cpu: bool,
    /// The display's refresh period.
    refresh: Duration,
    last: Option<Instant>,
    /// A frame arrived that is not on screen yet; `Some(true)` when one of
    /// them was the first of its generation.
    new_frame: Option<bool>,
    /// Something besides the picture changed (UI, overlay, an expose).
    ui: bool,
    /// When a new generation was asked for whose first frame has not come.
    awaiting: Option<Instant>,
    /// The generation of the newest frame that arrived.
    generation: Option<u64>,
    /// Smoothed time a present takes, and the machine's cores.
    present_cost: Duration,
    cores: u32,
}

impl Pacer {
    pub fn new(cpu: bool, refresh: Duration, cores: u32) -> Self {
        Pacer {
            present_cost: Duration::ZERO,
            cores: cores.max(1),
            cpu,
            refresh,
            last: None,
            new_frame: None,
            ui: false,
            awaiting: None,
            generation: None,
        }
    }

    /// The refresh period of a monitor at `millihertz` (30–240 Hz; 60 Hz
    /// when unknown).
    pub fn refresh_period(millihertz: Option<u32>) -> Duration {
        let hz = millihertz.map_or(60.0, |m| m as f64 / 1000.0);
        let hz = if hz.is_finite() && hz > 0.0 {
            hz.clamp(30.0, 240.0)
        } else {
            60.0
        };
        Duration::from_secs_f64(1.0 / hz)
    }

    /// What a present takes (smoothed).
    pub fn present_cost(&self) -> Duration {
        self.present_cost
    }

    /// The display's refresh period.
    pub fn refresh(&self) -> Duration {
        self.refresh
    }

    /// A new generation was submitted (an input changed the picture).
    pub fn submitted(&mut self, now: Instant) {
        self.awaiting = Some(now);
    }

    /// A frame of `generation` arrived.
    pub fn frame_arrived(&mut self, generation: u64) {
        let first = self.generation != Some(generation);
        self.generation = Some(generation);
        if first {
            self.awaiting = None;
        }
        self.new_frame = Some(self.new_frame.unwrap_or(false) || first);
    }

    /// The UI or the overlay changed, or the window must be drawn again.
    pub fn ui_changed(&mut self) {
        self.ui = true;
    }

    /// Whether a redraw request at `now` presents now, later or not at all.
    pub fn decide(&self, now: Instant) -> Decision {
        let Some(first) = self.new_frame.or(self.ui.then_some(false)) else {
            return Decision::Skip;
        };
        let Some(last) = self.last else {
            return Decision::Now;
        };
        let mut at = last + self.refresh;
        if self.new_frame.is_some() {
            if self.cpu && !first && !self.ui {
                at = at.max(last + self.cpu_pace());
            }
        } else if let Some(t) = self.awaiting {
            at = at.max(t + AWAIT_LIMIT);
        }
        if at <= now { Decision::Now } else { Decision::At(at) }
    }

    /// Least time between refining frames on a CPU rasterizer: 10 a
    /// second, or longer when presents cost more than their share.
    fn cpu_pace(&self) -> Duration {
        let share = self.present_cost.as_secs_f64() / (PRESENT_SHARE * self.cores as f64);
        CPU_PACE.max(Duration::from_secs_f64(share.min(1.0)))
    }

    /// Whether a frame arrived that is not on screen yet.
    pub fn has_new_frame(&self) -> bool {
        self.new_frame.is_some()
    }

    /// The UI pass asked for looked the same as the one on screen: no
    /// present (the same picture is never presented twice).
    pub fn unchanged(&mut self) {
        self.ui = false;
    }

    /// A present that took `cost` ended at `now`: everything pending is on
    /// screen.
    pub fn presented(&mut self, now: Instant, cost: Duration) {
        self.present_cost = if self.last.is_none() {
            cost
        } else {
            self.present_cost.mul_f64(0.8) + cost.mul_f64(0.2)
        };
        self.last = Some(now);
        self.new_frame = None;
        self.ui = false;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HZ60: Duration = Duration::from_micros(16_667);

    fn ms(t: Instant, ms: u64) -> Instant {
        t + Duration::from_millis(ms)
    }

    #[test]
    fn nothing_new_is_never_presented_and_one_present_per_refresh() {
        let t = Instant::now();
        let mut p = Pacer::new(false, HZ60, 2);
        assert_eq!(p.decide(t), Decision::Skip, "nothing to show yet");
        p.frame_arrived(1);
        assert_eq!(p.decide(t), Decision::Now);
        p.presented(t, Duration::ZERO);
        assert_eq!(p.decide(ms(t, 1)), Decision::Skip, "the same frame twice");
        // A refining frame 5 ms later waits for the next refresh.
        p.frame_arrived(1);
        assert_eq!(p.decide(ms(t, 5)), Decision::At(t + HZ60));
        assert_eq!(p.decide(ms(t, 17)), Decision::Now, "a GPU is not paced");
        p.presented(ms(t, 17), Duration::ZERO);
        p.ui_changed();
        assert_eq!(p.decide(ms(t, 40)), Decision::Now);
    }

    #[test]
    fn on_a_cpu_rasterizer_refinement_is_paced_but_the_first_frame_is_not() {
        let t = Instant::now();
        let mut p = Pacer::new(true, HZ60, 2);
        p.frame_arrived(1);
        p.presented(t, Duration::ZERO);
        p.frame_arrived(1);
        assert_eq!(p.decide(ms(t, 30)), Decision::At(t + CPU_PACE));
        // Another refining frame replaces it: still one present at the pace.
        p.frame_arrived(1);
        assert_eq!(p.decide(ms(t, 60)), Decision::At(t + CPU_PACE));
        assert_eq!(p.decide(ms(t, 100)), Decision::Now);
        // An input's new generation: its first frame goes at the refresh.
        p.submitted(ms(t, 50));
        p.frame_arrived(2);
        assert_eq!(p.decide(ms(t, 60)), Decision::Now);
        p.presented(ms(t, 60), Duration::ZERO);
        p.frame_arrived(2);
        p.ui_changed();
        assert_eq!(p.decide(ms(t, 80)), Decision::Now, "a UI change is not paced");
    }

    #[test]
    fn costly_presents_are_spaced_to_their_share_of_the_cpu() {
        let t = Instant::now();
        // 27 ms presents on 2 cores: 5 % of the CPU allows one per 270 ms.
        let mut p = Pacer::new(true, HZ60, 2);
        p.frame_arrived(1);
        p.presented(t, Duration::from_millis(27));
        p.frame_arrived(1);
        assert_eq!(p.decide(ms(t, 100)), Decision::At(ms(t, 270)));
        // On 16 cores the 10-a-second pace is the bound.
        let mut p = Pacer::new(true, HZ60, 16);
        p.frame_arrived(1);
        p.presented(t, Duration::from_millis(27));
        p.frame_arrived(1);
        assert_eq!(p.decide(ms(t, 50)), Decision::At(t + CPU_PACE));
    }

    #[test]
    fn a_ui_change_waits_for_the_first_frame_of_its_generation() {
        let t = Instant::now();
        let mut p = Pacer::new(true, HZ60, 2);
        p.frame_arrived(1);
        p.presented(t, Duration::ZERO);
        // A key at 500 ms: the message changed and a generation started.
        p.ui_changed();
        p.submitted(ms(t, 500));
        assert_eq!(p.decide(ms(t, 500)), Decision::At(ms(t, 500) + AWAIT_LIMIT));
        // Its frame comes 15 ms later: both go in one present, at once.
        p.frame_arrived(2);
        assert_eq!(p.decide(ms(t, 515)), Decision::Now);
        p.presented(ms(t, 515), Duration::ZERO);
        // A frame that never comes does not hold the UI back for ever.
        p.ui_changed();
        p.submitted(ms(t, 900));
        assert_eq!(p.decide(ms(t, 1000)), Decision::Now);
    }

    #[test]
    fn the_refresh_period_comes_from_the_monitor_within_bounds() {
        assert_eq!(Pacer::refresh_period(None), Duration::from_secs_f64(1.0 / 60.0));
        assert_eq!(
            Pacer::refresh_period(Some(144_000)),
            Duration::from_secs_f64(1.0 / 144.0)
        );
        assert_eq!(Pacer::refresh_period(Some(0)), Duration::from_secs_f64(1.0 / 60.0));
        assert_eq!(Pacer::refresh_period(Some(1_000)), Duration::from_secs_f64(1.0 / 30.0));
    }
}
