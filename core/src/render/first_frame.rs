//! The first picture of a job, the answer to an input. After a camera move
//! there are two: the previous picture reprojected (its pixels moved, the
//! rest traced: [`super::progressive::Progressive::reproject`]) or a fresh
//! block level. Neither always wins: a reprojection is sharp where it can
//! move pixels, but its warp costs about a fifth of a 1-spp frame whatever
//! the view, and through a lens that fills the view it moves nothing and
//! traces nearly every pixel. [`Costs::choose`] predicts both from what
//! this machine measured and takes the sharper that fits the budget.

use super::progressive::{ReprojectTimes, Stage};

/// Time the first frame after an input may take (a 60 Hz frame less the
/// viewer's own share), or a third of a 1-spp frame where that is more
/// ([`Costs::budget`]).
pub const FIRST_FRAME_BUDGET_S: f64 = 0.012;

/// A flight shows at least this many pictures a second where the machine
/// allows: the first picture after a camera move may take what is left of
/// such a frame after the window's present (with a margin: predictions
/// are means).
pub const FLIGHT_RATE: f64 = 20.0;
const FLIGHT_MARGIN: f64 = 0.9;

/// How much more a pixel left by a reprojection costs to trace than the
/// average camera sample: most are seen through the lens (measured on
/// cubes.toml at 1280×720, docs/performance.md: about 4.5).
const HOLE_COST: f64 = 4.0;

/// The block size at which a reprojection traces the `holes` pixels it
/// could not move: the finest whose predicted time fits the first frame's
/// budget (2×2 blocks, ≥ 45 dB on cubes.toml, when nothing is measured).
pub fn hole_level(holes: usize, seconds_per_sample: Option<f64>) -> u32 {
    let Some(sps) = seconds_per_sample else { return 2 };
    hole_level_within(holes, sps, FIRST_FRAME_BUDGET_S)
}

/// The finest block size at which `holes` pixels are traced within
/// `budget_s` (8 if none).
fn hole_level_within(holes: usize, sps: f64, budget_s: f64) -> u32 {
    [1, 2, 4, 8]
        .into_iter()
        .find(|&n| holes as f64 / (n * n) as f64 * sps * HOLE_COST <= budget_s)
        .unwrap_or(8)
}

/// What this machine measured, for predicting a first frame's time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Costs {
    /// Seconds per camera sample (running mean over the stages below).
    pub sample_s: Option<f64>,
    /// The same per stage that samples every pixel alike: 8×8, 4×4 and
    /// 2×2 blocks and the first full-resolution sample (a block's sample
    /// costs more than a full frame's: its packets are less coherent).
    pub level_s: [Option<f64>; 4],
    /// Seconds per pixel of a reprojection's warp, first hits included
    /// (running mean).
    pub warp_px_s: Option<f64>,
    /// Share of the pixels the last reprojection left to trace.
    pub holes: f64,
}

/// How a job starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum First {
    /// The previous picture reprojected.
    Reproject,
    /// Afresh, at this stage of the schedule.
    Fresh(usize),
}

/// Running mean, a quarter weight on the newest: on two cores a stage
/// that shares them with a present takes up to twice its time, and a
/// choice that followed every such stage would flip between levels.
fn blend(old: Option<f64>, new: f64) -> f64 {
    old.map_or(new, |o| 0.75 * o + 0.25 * new)
}

impl Costs {
    /// Which of [`Self::level_s`] a stage is.
    fn level(stage: Stage) -> Option<usize> {
        match stage {
            Stage::Blocks(8) => Some(0),
            Stage::Blocks(4) => Some(1),
            Stage::Blocks(2) => Some(2),
            Stage::Samples(1) => Some(3),
            _ => None,
        }
    }

    /// `stage`, of `cost` samples, took `dt` s (under 1000 samples, or a
    /// stage that samples only some pixels, say little).
    pub fn sampled(&mut self, stage: Stage, dt: f64, cost: u64) {
        if let Some(i) = Self::level(stage)
            && cost >= 1000
        {
            let s = dt / cost as f64;
            self.sample_s = Some(blend(self.sample_s, s));
            self.level_s[i] = Some(blend(self.level_s[i], s));
        }
    }

    /// Predicted seconds for `stage` of a `w × h` picture: its
    /// [`Stage::cost`] at the level's measured time a sample. A block
    /// level refined at edges counts its refinement at the cap (the
    /// samples measured are those cast), so where a scene has fewer edges
    /// the prediction is high by at most that share ([`super::edges`]).
    pub fn predict(&self, stage: Stage, (w, h): (u32, u32)) -> Option<f64> {
        let per = Self::level(stage).and_then(|i| self.level_s[i]).or(self.sample_s)?;
        Some(stage.cost(w, h, 0) as f64 * per)
    }

    /// The first stage of `stages` worth drawing: the finest block level
    /// (or the first full-resolution sample) whose predicted time fits
    /// `budget_s`; the coarsest when nothing is measured or none fits.
    pub fn first_stage(&self, stages: &[Stage], size: (u32, u32), budget_s: f64) -> usize {
        let mut pick = 0;
        for (i, &st) in stages.iter().enumerate() {
            if Self::level(st).is_none() {
                break;
            }
            match self.predict(st, size) {
                Some(t) if t <= budget_s => pick = i,
                _ => break,
            }
        }
        pick
    }

    /// A reprojection of `pixels` pixels took `t`.
    pub fn reprojected(&mut self, t: &ReprojectTimes, pixels: usize) {
        if pixels >= 1000 {
            let px = (t.first_hits_s + t.warp_s) / pixels as f64;
            self.warp_px_s = Some(blend(self.warp_px_s, px));
            self.holes = t.holes as f64 / pixels as f64;
        }
    }

    /// The first frame's budget for `pixels` pixels: [`FIRST_FRAME_BUDGET_S`]
    /// or a third of a 1-spp frame, whichever is more.
    pub fn budget(&self, pixels: usize) -> f64 {
        let third = self.frame_sample_s().map_or(0.0, |s| s * pixels as f64 / 3.0);
        FIRST_FRAME_BUDGET_S.max(third)
    }

    /// Seconds per sample of a full-resolution frame, as far as measured.
    fn frame_sample_s(&self) -> Option<f64> {
        self.level_s[3].or(self.sample_s)
    }

    /// The first picture's budget after a camera move, for `size` pixels
    /// and presents of `present_s`: what a [`FLIGHT_RATE`] frame leaves
    /// after the present, with a margin, and at least [`Self::budget`].
    pub fn move_budget(&self, (w, h): (u32, u32), present_s: f64) -> f64 {
        let left = (1.0 / FLIGHT_RATE - present_s.max(0.0)) * FLIGHT_MARGIN;
        self.budget(w as usize * h as usize).max(left)
    }

    /// The block size at which a reprojection traces its `holes` within
    /// `budget_s` (2×2 when nothing is measured).
    pub fn hole_level(&self, holes: usize, budget_s: f64) -> u32 {
        match self.frame_sample_s() {
            Some(sps) => hole_level_within(holes, sps, budget_s),
            None => 2,
        }
    }

    /// The first picture after a camera move with a picture to move (`stages`:
    /// the schedule, `w × h` pixels, `budget` seconds). Each is predicted by the measured
    /// costs and scored by the coarsest detail it shows, in pixels: a fresh
    /// level of `b × b` blocks scores `b`; a reprojection scores 1 where
    /// it moves pixels and its hole level elsewhere, weighted by the share
    /// of holes last time. The better score among those that fit the budget
    /// wins (ties: the reprojection); if neither fits, the cheaper. Nothing
    /// measured yet: the reprojection.
    pub fn choose(&self, stages: &[Stage], (w, h): (u32, u32), budget: f64) -> First {
        let (Some(sps), Some(warp)) = (self.frame_sample_s(), self.warp_px_s) else {
            return First::Reproject;
        };
        let n = w as usize * h as usize;
        let fresh = self.first_stage(stages, (w, h), budget);
        let fresh_cost = self.predict(stages[fresh], (w, h)).unwrap_or(f64::INFINITY);
        let fresh_score = match stages[fresh] {
            Stage::Blocks(b) => b as f64,
            _ => 1.0,
        };
        let holes = (self.holes * n as f64).round() as usize;
        let level = hole_level_within(holes, sps, budget - warp * n as f64);
        let cost = warp * n as f64 + holes as f64 / (level * level) as f64 * sps * HOLE_COST;
        let score = self.holes * level as f64 + (1.0 - self.holes);
        let fits = (cost <= budget, fresh_cost <= budget);
        let reproject = match fits {
            (true, true) => score <= fresh_score,
            (true, false) => true,
            (false, true) => false,
            (false, false) => cost <= fresh_cost,
        };
        if reproject {
            First::Reproject
        } else {
            First::Fresh(fresh)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::progressive::schedule;

    fn costs(sample_s: f64, warp_px_s: f64, holes: f64) -> Costs {
        Costs {
            sample_s: Some(sample_s),
            level_s: [None; 4],
            warp_px_s: Some(warp_px_s),
            holes,
        }
    }

    /// With one rate for every level (`sample_s` alone), the first stage is
    /// the finest whose samples fit the budget.
    #[test]
    fn first_stage_fits_the_budget() {
        let st = schedule(64);
        let at = |s: Option<f64>| Costs {
            sample_s: s,
            ..Costs::default()
        };
        assert_eq!(at(None).first_stage(&st, (1280, 720), 0.016), 0);
        // 10 µs a sample: 8×8 blocks (14 400 samples) take 0.144 s: still the coarsest.
        assert_eq!(at(Some(1e-5)).first_stage(&st, (1280, 720), 0.016), 0);
        // 50 ns a sample: 2×2 (230 400 samples, 258 048 with its edges at
        // the cap) takes 12.9 ms; full res 46 ms.
        assert_eq!(at(Some(5e-8)).first_stage(&st, (1280, 720), 0.016), 2);
        assert_eq!(at(Some(1e-9)).first_stage(&st, (1280, 720), 0.016), 3);
    }

    #[test]
    fn nothing_measured_reprojects() {
        let st = schedule(16);
        assert_eq!(Costs::default().choose(&st, (1280, 720), 0.012), First::Reproject);
    }

    #[test]
    fn a_cheap_warp_with_few_holes_reprojects() {
        // 1-spp frame 40 ms (budget 13 ms); warp 5 ms; 10 % holes.
        let n = 1280.0 * 720.0;
        let c = costs(0.040 / n, 0.005 / n, 0.1);
        let budget = c.budget(n as usize);
        assert_eq!(c.choose(&schedule(16), (1280, 720), budget), First::Reproject);
    }

    #[test]
    fn a_warp_over_the_budget_gives_way_to_the_finest_fresh_level_that_fits() {
        let n = 1280.0 * 720.0;
        let st = schedule(16);
        // The warp alone 20 ms, over a 13 ms budget; 2×2 blocks take 11 ms.
        let c = costs(0.040 / n, 0.020 / n, 0.1);
        assert_eq!(c.choose(&st, (1280, 720), c.budget(n as usize)), First::Fresh(2));
        assert_eq!(st[2], Stage::Blocks(2));
        // With a 30 ms budget (about a flight frame less a cheap present) it fits.
        assert_eq!(c.choose(&st, (1280, 720), 0.030), First::Reproject);
        assert!((c.move_budget((1280, 720), 0.010) - 0.036).abs() < 1e-12);
        assert_eq!(
            c.move_budget((1280, 720), 0.2),
            c.budget(n as usize),
            "at least the tap's"
        );
    }

    #[test]
    fn a_view_all_through_glass_is_traced_afresh() {
        // Warp 5 ms fits, but 95 % of the pixels are holes, traced at 8×8
        // within the budget: 2×2 fresh blocks show finer detail.
        let n = 1280.0 * 720.0;
        let c = costs(0.040 / n, 0.005 / n, 0.95);
        let level = c.hole_level((0.95 * n) as usize, c.budget(n as usize) - 0.005);
        assert!(level >= 4, "{level}");
        assert_eq!(
            c.choose(&schedule(16), (1280, 720), c.budget(n as usize)),
            First::Fresh(2)
        );
    }

    #[test]
    fn measurements_are_running_means() {
        let mut c = Costs::default();
        c.sampled(Stage::Samples(1), 1.0, 999);
        c.sampled(Stage::Samples(2), 1.0, 100_000);
        assert_eq!(c.sample_s, None, "too few samples, or only some pixels");
        c.sampled(Stage::Samples(1), 0.002, 1000);
        c.sampled(Stage::Samples(1), 0.004, 1000);
        assert!((c.sample_s.unwrap() - 2.5e-6).abs() < 1e-12);
        // Each level keeps its own: a block's sample costs more.
        c.sampled(Stage::Blocks(8), 0.010, 1000);
        assert_eq!(c.level_s[0], Some(1e-5));
        assert_eq!(c.predict(Stage::Blocks(8), (80, 80)), Some(100.0 * 1e-5));
        let one = c.predict(Stage::Samples(1), (80, 80)).unwrap();
        assert!((one - 6400.0 * 2.5e-6).abs() < 1e-12);
        // 4×4 blocks, not measured, take the overall mean.
        assert!(c.predict(Stage::Blocks(4), (80, 80)).unwrap() > 400.0 * 2.5e-6);
        let t = ReprojectTimes {
            first_hits_s: 0.001,
            warp_s: 0.003,
            splat_s: 0.001,
            fill_s: 0.5,
            holes: 500,
            level: 2,
        };
        c.reprojected(&t, 2000);
        assert_eq!((c.warp_px_s, c.holes), (Some(2e-6), 0.25));
        let budget = c.budget(1_000_000);
        assert!((budget - 2.5 / 3.0).abs() < 1e-9, "a third of 2.5 s: {budget}");
        assert_eq!(c.first_stage(&schedule(4), (1000, 1000), 0.5), 1, "4×4 blocks fit");
        assert_eq!(c.first_stage(&schedule(4), (1000, 1000), 0.1), 0, "none fits");
        assert_eq!(Costs::default().budget(10), FIRST_FRAME_BUDGET_S);
    }
}
