//! Camera flight: the held keys, mouse-look and the flight speed. The
//! motion itself is two pure functions of the pose, [`step`] (keys held for
//! a time) and [`look`] (a mouse drag), tested below; [`Flight`] keeps the
//! input state around them. Input is coalesced: a drag accumulates and the
//! held keys' time runs on until the viewer takes one step for all of it
//! ([`Flight::tick`], once per frame shown: [`step_due`]). The new pose goes
//! to the document as a merged edit (`Document::fly_camera`), one undo step
//! per gesture.

use super::keys::{self, Action};
use glam::DVec3;
use lensview::camera::Camera;
use lensview::flight::MAX_PITCH;
pub use lensview::flight::look;
use std::collections::HashSet;
use std::time::{Duration, Instant};
use winit::keyboard::KeyCode;

/// A camera pose: position, and rotation in degrees (pitch x, yaw y, roll z).
pub type Pose = (DVec3, DVec3);

/// Degrees per second of arrow-key turning (a drag's degrees per pixel:
/// `lensview::flight::look`, which the web page uses too).
const TURN_RATE: f64 = 60.0;
/// Shift flies this much faster.
const FAST: f64 = 4.0;
/// Longest step in seconds: after a stall the camera does not leap. Steps
/// are taken once per frame shown, so this is also the slowest frame rate
/// (4 a second) at which the flight still keeps its speed.
const MAX_DT: f64 = 0.25;
/// Longest wait for the frame of the last step before the next step goes
/// anyway (a frame that never comes: the window minimised, resized).
pub const STEP_WAIT_LIMIT: Duration = Duration::from_secs(1);

pub struct Flight {
    /// Units per second (the mouse wheel changes it).
    pub speed: f64,
    held: HashSet<KeyCode>,
    last_step: Instant,
    /// Where the left button went down or the drag last moved to.
    dragging: Option<(f64, f64)>,
    cursor: (f64, f64),
    /// Drag (pixels) not yet applied: it goes with the next step.
    look: (f64, f64),
}

impl Flight {
    pub fn new() -> Self {
        Flight {
            speed: 3.0,
            held: HashSet::new(),
            last_step: Instant::now(),
            dragging: None,
            cursor: (0.0, 0.0),
            look: (0.0, 0.0),
        }
    }

    /// A flight key went down (`down`) or up.
    pub fn key(&mut self, code: KeyCode, down: bool) {
        if !down {
            self.held.remove(&code);
        } else if self.held.insert(code) {
            // The first step of a new key covers no time before its press.
            self.last_step = Instant::now();
        }
    }

    /// Stops flying (focus lost, a question asked).
    pub fn release_keys(&mut self) {
        self.held.clear();
    }

    fn held_actions(&self) -> Vec<Action> {
        self.held
            .iter()
            .filter_map(|k| keys::action_for(*k, false, false))
            .filter(|a| a.is_held())
            .collect()
    }

    /// Whether a step is waiting: a flight key held or a drag not applied.
    pub fn wants_step(&self) -> bool {
        self.look != (0.0, 0.0) || !self.held_actions().is_empty()
    }

    /// One step for all the input since the last step: the drag made
    /// meanwhile and the keys held for the time since (at most
    /// [`MAX_DT`]). The new pose, or `None` when there is nothing to do.
    pub fn tick(&mut self, fast: bool, pose: Pose) -> Option<Pose> {
        let now = Instant::now();
        let dt = (now - self.last_step).as_secs_f64().min(MAX_DT);
        self.last_step = now;
        let (dx, dy) = std::mem::take(&mut self.look);
        let held = self.held_actions();
        if held.is_empty() && (dx, dy) == (0.0, 0.0) {
            return None;
        }
        let pose = look(pose, dx, dy);
        let speed = self.speed * if fast { FAST } else { 1.0 };
        Some(step(&held, dt, speed, pose))
    }

    pub fn cursor(&self) -> (f64, f64) {
        self.cursor
    }

    pub fn is_dragging(&self) -> bool {
        self.dragging.is_some()
    }

    /// The left button went down over the picture: dragging looks around.
    pub fn start_drag(&mut self) {
        self.dragging = Some(self.cursor);
    }

    pub fn end_drag(&mut self) {
        self.dragging = None;
    }

    /// The cursor moved to `to`; while dragging, the move is kept for the
    /// next step (true).
    pub fn cursor_moved(&mut self, to: (f64, f64)) -> bool {
        self.cursor = to;
        let Some((x0, y0)) = self.dragging else { return false };
        self.dragging = Some(to);
        self.look.0 += to.0 - x0;
        self.look.1 += to.1 - y0;
        true
    }

    /// The mouse wheel turned by `steps` notches: 20 % faster or slower
    /// each. Returns the new speed.
    pub fn wheel(&mut self, steps: f64) -> f64 {
        self.speed = (self.speed * 1.2f64.powf(steps)).clamp(0.05, 500.0);
        self.speed
    }
}

/// Whether the next flight step may go at `now`: once per frame shown.
/// `last`: when the last step went; `answered`: whether a frame of the
/// picture it asked for has arrived. A step waits at least one display
/// `refresh` and for that frame (at most [`STEP_WAIT_LIMIT`]): a step per
/// input event would cancel every picture before it is drawn.
pub fn step_due(now: Instant, last: Option<Instant>, answered: bool, refresh: Duration) -> bool {
    let Some(last) = last else { return true };
    let since = now.saturating_duration_since(last);
    since >= refresh && (answered || since >= STEP_WAIT_LIMIT)
}

/// The pose after the `held` flight actions for `dt` seconds at `speed`
/// units per second: moves along the camera's own forward and right axes
/// and world up; turns at [`TURN_RATE`], pitch kept within ±89°.
pub fn step(held: &[Action], dt: f64, speed: f64, (mut pos, mut rot): Pose) -> Pose {
    let cam = Camera::new(pos, rot, 45.0);
    let (f, r) = (cam.forward(), cam.right());
    let step = speed * dt;
    let turn = TURN_RATE * dt;
    for a in held {
        match a {
            Action::Forward => pos += f * step,
            Action::Back => pos -= f * step,
            Action::Left => pos -= r * step,
            Action::Right => pos += r * step,
            Action::Up => pos += DVec3::Y * step,
            Action::Down => pos -= DVec3::Y * step,
            Action::LookLeft => rot.y += turn,
            Action::LookRight => rot.y -= turn,
            Action::LookUp => rot.x = (rot.x + turn).min(MAX_PITCH),
            Action::LookDown => rot.x = (rot.x - turn).max(-MAX_PITCH),
            _ => {}
        }
    }
    (pos, rot)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-12
    }

    const START: Pose = (DVec3::new(1.0, 2.0, 3.0), DVec3::ZERO);

    #[test]
    fn keys_move_along_the_cameras_own_axes_at_the_speed() {
        // Unturned, the camera looks along −z with +x to its right.
        let (p, r) = step(&[Action::Forward], 0.5, 4.0, START);
        assert!(close(p, START.0 - DVec3::Z * 2.0) && r == START.1, "{p}");
        let (p, _) = step(&[Action::Right, Action::Up], 1.0, 1.0, START);
        assert!(close(p, START.0 + DVec3::X + DVec3::Y), "{p}");
        let (p, _) = step(&[Action::Forward, Action::Back], 1.0, 3.0, START);
        assert!(close(p, START.0), "opposite keys cancel");
        // Turned 90° left, forward is −x.
        let (p, _) = step(&[Action::Forward], 1.0, 1.0, (START.0, DVec3::new(0.0, 90.0, 0.0)));
        assert!(close(p, START.0 - DVec3::X), "{p}");
        assert_eq!(step(&[], 1.0, 5.0, START), START);
    }

    #[test]
    fn turning_keys_turn_at_the_rate_and_pitch_stops_at_89_degrees() {
        let (p, r) = step(&[Action::LookLeft, Action::LookUp], 0.5, 9.0, START);
        assert_eq!((p, r), (START.0, DVec3::new(30.0, 30.0, 0.0)));
        let (_, r) = step(&[Action::LookUp], 10.0, 1.0, START);
        assert_eq!(r.x, MAX_PITCH);
        let (_, r) = step(&[Action::LookDown, Action::LookRight], 10.0, 1.0, START);
        assert_eq!((r.x, r.y), (-MAX_PITCH, -600.0));
    }

    #[test]
    fn flight_holds_keys_drags_and_changes_speed() {
        let mut f = Flight::new();
        assert_eq!(f.tick(false, START), None, "nothing held");
        f.key(KeyCode::KeyW, true);
        std::thread::sleep(std::time::Duration::from_millis(5));
        let (p, _) = f.tick(true, START).unwrap();
        let moved = (START.0 - p).length();
        assert!(moved > 0.0 && moved <= f.speed * FAST * MAX_DT + 1e-12, "{moved}");
        f.key(KeyCode::KeyW, false);
        assert_eq!(f.tick(false, START), None);
        f.key(KeyCode::KeyW, true);
        f.release_keys();
        assert_eq!(f.tick(false, START), None);

        assert!(!f.cursor_moved((10.0, 10.0)) && !f.wants_step());
        f.start_drag();
        // Two moves before a step: one step turns by both.
        assert!(f.cursor_moved((30.0, 10.0)) && f.cursor_moved((50.0, 4.0)));
        assert!(f.wants_step());
        assert_eq!(f.tick(false, START), Some(look(START, 40.0, -6.0)));
        assert!(!f.wants_step() && f.tick(false, START).is_none(), "the drag was taken");
        f.end_drag();
        assert!(!f.is_dragging() && f.cursor() == (50.0, 4.0));

        assert!((f.wheel(1.0) - 3.6).abs() < 1e-12);
        assert_eq!(f.wheel(-100.0), 0.05);
    }

    #[test]
    fn a_held_key_steps_once_per_frame_for_the_time_it_was_held() {
        let mut f = Flight::new();
        f.key(KeyCode::KeyW, true);
        assert!(f.wants_step());
        // No step for 60 ms (the frame was being drawn): the next step
        // covers all of it.
        std::thread::sleep(Duration::from_millis(60));
        let (p, _) = f.tick(false, START).unwrap();
        let moved = (START.0 - p).length();
        assert!(moved >= f.speed * 0.06 - 1e-12 && moved <= f.speed * MAX_DT, "{moved}");
    }

    #[test]
    fn a_step_waits_a_refresh_and_the_frame_of_the_last_step() {
        let t = Instant::now();
        let ms = |n: u64| t + Duration::from_millis(n);
        let hz60 = Duration::from_micros(16_667);
        assert!(step_due(t, None, false, hz60), "the first step goes at once");
        assert!(!step_due(ms(10), Some(t), true, hz60), "within one refresh");
        assert!(step_due(ms(17), Some(t), true, hz60));
        assert!(!step_due(ms(400), Some(t), false, hz60), "its frame has not come");
        assert!(step_due(ms(1000), Some(t), false, hz60), "a frame that never comes");
    }
}
