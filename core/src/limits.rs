//! The one set of limits every command obeys (`render`, `converge`,
//! `bench`, `view` and its screenshot), checked before anything is
//! allocated or rendered, each refusal one line naming the size.
//!
//! - A side is 1..=[`MAX_SIDE`]: 16384 is the largest texture side common
//!   GPUs take and far beyond any screen; the memory budget below bounds
//!   the area.
//! - Samples per pixel are 1..=[`MAX_SPP`], as in the scene file.
//! - The buffers a command needs, estimated from its bytes per pixel, stay
//!   within [`MEMORY_BUDGET`] (4 GiB).
//! - The work one command does in all stays within [`MAX_SAMPLES`] camera
//!   samples (2^32 ≈ 4.3·10^9: 1920×1080 at 2048 spp, 4K at 512, for a
//!   scene of one light without caustics; about 11 minutes at the 6.8 M
//!   samples/s of the cubes scene on 2 cores). Work is counted in camera
//!   samples ([`Work::total`]): each light past the first adds
//!   [`LIGHT_WORK`] to a sample (its shadow rays), and each photon traced
//!   for caustics (passes × photons a pass a light × lights) counts
//!   [`PHOTON_WORK`], so no accepted command runs unboundedly long, however
//!   many lights or photon passes it asks for (`render` also cuts its
//!   passes to `render::caustics::MAX_PHOTONS_TRACED` photons).
//! - Input files are read up to a cap: [`SCENE_FILE_CAP`] for scenes,
//!   [`TRACE_INPUT_CAP`] for `lens trace`.

/// Largest image width or height.
pub const MAX_SIDE: u32 = 16384;
/// Largest number of samples per pixel (the scene file's `render.spp` too).
pub const MAX_SPP: u32 = 65536;
/// Largest estimated memory for a command's pixel buffers.
pub const MEMORY_BUDGET: u64 = 4 << 30;
/// Largest work of one command, in camera samples ([`Work::total`]).
pub const MAX_SAMPLES: u64 = 1 << 32;
/// A camera sample's work for each light past the first: measured 0.18
/// (the cubes scene with 10 and 100 point lights, 400×300 at 16 spp: 0.65 s
/// and 5.3 s against 0.28 s with one; AMD EPYC, 2 cores), rounded up.
pub const LIGHT_WORK: f64 = 0.25;
/// A photon's work in camera samples: measured 3.5 (the cubes scene: 1.9 M
/// photons/s against 6.8 M camera samples/s, same machine), rounded up.
pub const PHOTON_WORK: f64 = 4.0;
/// Largest scene file read: 10^6 objects in the short inline form take
/// 70 MB and load in 1.07 GB of peak RSS (0.8 KB of heap an object at the
/// peak, tests/memory.rs, which measures every kind of entry: README,
/// "Memory when loading"); a refusal is placed in about 2 KB an object.
pub const SCENE_FILE_CAP: u64 = 128 << 20;
/// Largest `lens trace` input read (about 400 000 rays' cases).
pub const TRACE_INPUT_CAP: u64 = 64 << 20;
/// Largest number of timed runs (`bench --runs`) or frames (`--frames`).
pub const MAX_RUNS: u32 = 1000;
/// Longest flight, in seconds (a day).
pub const MAX_FLIGHT_SECONDS: f64 = 86400.0;
/// Most frames one `film` may render.
pub const MAX_FILM_FRAMES: u64 = 1 << 22;

/// Bytes a pixel of a rendered image takes: linear RGB in `f64`, plus the
/// 8-bit sRGB copy that is encoded.
pub const IMAGE_BYTES_PER_PIXEL: u64 = 24 + 3;
/// Bytes a pixel of the progressive renderer takes: three `f64` RGB planes
/// (sum, next, preview), two `f32` planes of sums of squares, one of
/// clamped means and two
/// sample counts (adaptive waves), the first hit (16) and the image taken
/// from them.
pub const PROGRESSIVE_BYTES_PER_PIXEL: u64 = 4 * 24 + 3 * 12 + 2 * 4 + 16;

/// A size, sample count or amount of work beyond the limits.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LimitError {
    #[error("{what} {width}×{height} is out of range: each side must be 1..={MAX_SIDE}")]
    Side { what: String, width: u32, height: u32 },
    #[error("{what} {width}×{height} needs {} for its pixel buffers; the limit is {}", bytes(*.needs), bytes(MEMORY_BUDGET))]
    Memory {
        what: String,
        width: u32,
        height: u32,
        needs: u64,
    },
    #[error("{what} is {value}, out of range: it must be 1..={max}")]
    Count { what: String, value: u64, max: u64 },
    #[error("{what} is {}; the limit is {:.2e} (2^32)", work.describe(), MAX_SAMPLES as f64)]
    Work { what: String, work: Work },
}

/// The work of one command: what [`check_work`] bounds.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Work {
    /// Camera samples (pixels × samples per pixel × renderings).
    pub samples: f64,
    /// Lights each camera sample shades (0 or 1 count as 1).
    pub lights: usize,
    /// Photons traced for caustics.
    pub photons: f64,
}

impl Work {
    /// `passes` renderings of `width`×`height` pixels at `spp` samples each,
    /// of one light and no photons.
    pub fn samples(width: u32, height: u32, spp: u64, passes: u64) -> Work {
        Work {
            samples: width as f64 * height as f64 * spp as f64 * passes as f64,
            lights: 1,
            photons: 0.0,
        }
    }

    /// The same samples, shading `lights` lights.
    pub fn with_lights(self, lights: usize) -> Work {
        Work { lights, ..self }
    }

    /// The same, and `photons` photons traced.
    pub fn with_photons(self, photons: f64) -> Work {
        Work { photons, ..self }
    }

    /// The work in camera samples: each light past the first adds
    /// [`LIGHT_WORK`] to a sample, each photon counts [`PHOTON_WORK`].
    pub fn total(&self) -> f64 {
        let per_sample = 1.0 + LIGHT_WORK * self.lights.saturating_sub(1) as f64;
        self.samples * per_sample + PHOTON_WORK * self.photons
    }

    /// The work in words: camera samples alone, or what it is made of.
    fn describe(&self) -> String {
        if self.lights <= 1 && self.photons == 0.0 {
            return format!("{:.2e} camera samples", self.samples);
        }
        let lights = self.lights.max(1);
        format!(
            "{:.2e} camera samples of work ({:.2e} samples shading {lights} light{}, {:.2e} photons; \
             a light past the first adds {LIGHT_WORK} to a sample, a photon counts {PHOTON_WORK})",
            self.total(),
            self.samples,
            if lights == 1 { "" } else { "s" },
            self.photons
        )
    }
}

/// `n` bytes in binary units ("6.0 GiB").
pub fn bytes(n: u64) -> String {
    const UNITS: [&str; 5] = ["bytes", "KiB", "MiB", "GiB", "TiB"];
    let mut v = n as f64;
    let mut i = 0;
    while v >= 1024.0 && i + 1 < UNITS.len() {
        v /= 1024.0;
        i += 1;
    }
    if i == 0 {
        format!("{n} bytes")
    } else {
        format!("{v:.1} {}", UNITS[i])
    }
}

/// Checks a `width`×`height` image (`what` names it in the message) whose
/// buffers take `bytes_per_pixel`: each side in 1..=[`MAX_SIDE`], the memory
/// within [`MEMORY_BUDGET`].
pub fn check_image(what: &str, width: u32, height: u32, bytes_per_pixel: u64) -> Result<(), LimitError> {
    if !(1..=MAX_SIDE).contains(&width) || !(1..=MAX_SIDE).contains(&height) {
        return Err(LimitError::Side {
            what: what.into(),
            width,
            height,
        });
    }
    let needs = width as u64 * height as u64 * bytes_per_pixel;
    if needs > MEMORY_BUDGET {
        return Err(LimitError::Memory {
            what: what.into(),
            width,
            height,
            needs,
        });
    }
    Ok(())
}

/// Checks a samples-per-pixel value against 1..=[`MAX_SPP`].
pub fn check_spp(what: &str, spp: u32) -> Result<(), LimitError> {
    check_count(what, spp as u64, MAX_SPP as u64)
}

/// Checks a count against 1..=`max`.
pub fn check_count(what: &str, value: u64, max: u64) -> Result<(), LimitError> {
    if (1..=max).contains(&value) {
        Ok(())
    } else {
        Err(LimitError::Count {
            what: what.into(),
            value,
            max,
        })
    }
}

/// Checks the total work of a command: `passes` renderings of
/// `width`×`height` pixels at `spp` samples each within [`MAX_SAMPLES`]
/// (of a scene of one light; [`check_total`] for more).
pub fn check_work(what: &str, width: u32, height: u32, spp: u64, passes: u64) -> Result<(), LimitError> {
    check_total(what, Work::samples(width, height, spp, passes))
}

/// Checks the total work of a command ([`Work::total`]) within
/// [`MAX_SAMPLES`].
pub fn check_total(what: &str, work: Work) -> Result<(), LimitError> {
    if work.total() > MAX_SAMPLES as f64 {
        return Err(LimitError::Work {
            what: what.into(),
            work,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sides_memory_counts_and_work() {
        assert!(check_image("image", 1, 1, IMAGE_BYTES_PER_PIXEL).is_ok());
        assert!(check_image("image", MAX_SIDE, 1, IMAGE_BYTES_PER_PIXEL).is_ok());
        assert!(matches!(check_image("image", 0, 5, 1), Err(LimitError::Side { .. })));
        assert!(matches!(
            check_image("image", 5, MAX_SIDE + 1, 1),
            Err(LimitError::Side { .. })
        ));
        // 16384² at 27 bytes a pixel is 6.75 GiB.
        assert_eq!(
            check_image("image", MAX_SIDE, MAX_SIDE, IMAGE_BYTES_PER_PIXEL)
                .unwrap_err()
                .to_string(),
            "image 16384×16384 needs 6.8 GiB for its pixel buffers; the limit is 4.0 GiB"
        );
        // Exactly at the budget passes, one byte over does not.
        assert!(check_image("image", 16384, 16384, 16).is_ok());
        assert!(check_image("image", 16384, 16384, 17).is_err());
        assert!(check_spp("--spp", MAX_SPP).is_ok());
        assert_eq!(
            check_spp("--spp", MAX_SPP + 1).unwrap_err().to_string(),
            "--spp is 65537, out of range: it must be 1..=65536"
        );
        assert!(check_spp("--spp", 0).is_err());
        assert!(check_work("w", 1024, 1024, 1 << 12, 1).is_ok());
        assert!(check_work("w", 1024, 1024, 1 << 12, 2).is_err());
        // Issue 30.2: lights and photons count. 2^30 photons are the whole
        // budget; a light past the first adds a quarter to each sample.
        let one = Work::samples(1, 1, 1, 1);
        assert!(check_total("r", one.with_photons((1u64 << 30) as f64 - 1.0)).is_ok());
        assert_eq!(
            check_total("the render", one.with_photons((1u64 << 32) as f64))
                .unwrap_err()
                .to_string(),
            "the render is 1.72e10 camera samples of work (1.00e0 samples shading 1 light, 4.29e9 photons; \
             a light past the first adds 0.25 to a sample, a photon counts 4); the limit is 4.29e9 (2^32)"
        );
        let big = Work::samples(1024, 1024, 1 << 11, 1);
        assert!(check_total("w", big.with_lights(5)).is_ok());
        assert!(check_total("w", big.with_lights(6)).is_err());
        assert_eq!(big.with_lights(0).total(), big.total());
        assert_eq!(bytes(512), "512 bytes");
        assert_eq!(bytes(3 << 20), "3.0 MiB");
    }
}
