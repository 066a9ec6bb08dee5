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
//! - The camera samples one command renders in all stay within
//!   [`MAX_SAMPLES`] (2^32 ≈ 4.3·10^9: 1920×1080 at 2048 spp, 4K at 512;
//!   about 15 minutes at 5 M samples/s).
//! - Input files are read up to a cap: [`SCENE_FILE_CAP`] for scenes,
//!   [`TRACE_INPUT_CAP`] for `lens trace`.

/// Largest image width or height.
pub const MAX_SIDE: u32 = 16384;
/// Largest number of samples per pixel (the scene file's `render.spp` too).
pub const MAX_SPP: u32 = 65536;
/// Largest estimated memory for a command's pixel buffers.
pub const MEMORY_BUDGET: u64 = 4 << 30;
/// Largest number of camera samples one command renders.
pub const MAX_SAMPLES: u64 = 1 << 32;
/// Largest scene file read: 10^6 objects in the short inline form take
/// 70 MB and load in about 0.8 GB (under 1 KB an object, tests/memory.rs);
/// a refusal of a file this large is placed in about 2 KB an object.
pub const SCENE_FILE_CAP: u64 = 128 << 20;
/// Largest `lens trace` input read (about 400 000 rays' cases).
pub const TRACE_INPUT_CAP: u64 = 64 << 20;
/// Largest number of timed runs (`bench --runs`) or frames (`--frames`).
pub const MAX_RUNS: u32 = 1000;

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
    #[error("{what} is {samples:.2e} camera samples; the limit is {:.2e} (2^32)", MAX_SAMPLES as f64)]
    Work { what: String, samples: f64 },
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
/// `width`×`height` pixels at `spp` samples each within [`MAX_SAMPLES`].
pub fn check_work(what: &str, width: u32, height: u32, spp: u64, passes: u64) -> Result<(), LimitError> {
    let samples = width as f64 * height as f64 * spp as f64 * passes as f64;
    if samples > MAX_SAMPLES as f64 {
        return Err(LimitError::Work {
            what: what.into(),
            samples,
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
        assert_eq!(bytes(512), "512 bytes");
        assert_eq!(bytes(3 << 20), "3.0 MiB");
    }
}
