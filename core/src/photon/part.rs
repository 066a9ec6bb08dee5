//! The parts of a photon map: each pass's photons dealt into [`PARTS`]
//! parts, photon `i` of a pass into part `i mod PARTS`, each part a map of
//! its own (`PhotonMap::for_sample`). A camera sample gathers one part,
//! chosen by its index, and weighs it `PARTS` times: the photons
//! of a pass are independent draws, so a part is an unbiased estimate of
//! the whole map with `1/PARTS` of its photons, and the `PARTS` samples
//! `i … i + PARTS − 1` of a pixel, lying a fraction of the gather radius
//! apart, together count every photon once, as one gather of the whole
//! map does. A sample then tests an eighth of the photons, in cells an
//! eighth as full (more of them empty, skipped on their bits): what the
//! gathers cost where caustics are dense or the passes many (the sums grow
//! with the photons within the radius, as the passes' count to the 2/3,
//! and the samples with it: ARCHITECTURE.md, "Caustics").

/// How many parts a map's photons are dealt into: a power of two, so that
/// weighing a part by it is exact. Eight: at 16 samples a pixel each part
/// is gathered twice; four parts cut rim-lens's frame (640×360, 16 spp)
/// as much as eight, and eight cut primitives' more (docs/performance.md,
/// round 22).
pub const PARTS: usize = 8;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::Rgb;
    use crate::photon::{Photon, PhotonMap};

    /// The part sample `i` gathers.
    fn part(m: &PhotonMap, i: u32) -> &PhotonMap {
        m.for_sample(i)
    }
    use crate::sampling::Sampler;
    use glam::DVec3;

    /// Over passes of several levels and groups (and a pass of fewer
    /// photons than parts), the mean of the parts' estimates is the whole
    /// map's, to rounding; the parts differ from one another (each holds
    /// its own photons); each part's photons are its share of the whole's.
    #[test]
    fn the_parts_average_to_the_whole_map() {
        let mut rng = Sampler::new(3, 1, 4);
        let mut m = PhotonMap::new(0.08);
        let sizes: Vec<usize> = (0..20).map(|pass| if pass == 3 { 5 } else { 700 }).collect();
        for &count in &sizes {
            let photons: Vec<Photon> = (0..count)
                .map(|_| {
                    let (u, v) = rng.next_2d();
                    let p = DVec3::new(u - 0.5, v - 0.5, 0.0);
                    Photon::new(p, -DVec3::Z, DVec3::new(1.0, 0.5 + u, 2.0 * v))
                })
                .collect();
            m.add_pass(&photons);
        }
        let (mut distinct, mut lit) = (0, 0);
        for k in 0..200 {
            let (u, v) = rng.next_2d();
            let x = DVec3::new(1.2 * (u - 0.5), 1.2 * (v - 0.5), 0.0);
            let whole = m.irradiance(x, DVec3::Z);
            let parts: Vec<Rgb> = (0..PARTS as u32).map(|p| part(&m, p).irradiance(x, DVec3::Z)).collect();
            let mean = parts.iter().fold(Rgb::ZERO, |a, &b| a + b) / PARTS as f64;
            assert!(
                (mean - whole).abs().max_element() <= 1e-12 * whole.max_element(),
                "query {k}: mean of parts {mean} vs whole {whole}"
            );
            // A part is its own part; sample i + PARTS gathers sample i's.
            let third = part(&m, 3);
            assert_eq!(third.for_sample(5).irradiance(x, DVec3::Z), parts[3]);
            assert_eq!(part(&m, PARTS as u32 + 3).irradiance(x, DVec3::Z), parts[3]);
            lit += usize::from(whole.x > 0.0);
            distinct += usize::from(parts.iter().any(|&p| p != parts[0]));
        }
        assert!(
            lit > 100 && distinct > 100,
            "{lit} lit, {distinct} with parts that differ"
        );
        let counts: Vec<usize> = m.parts.iter().map(PhotonMap::photons).collect();
        assert_eq!(counts.iter().sum::<usize>(), m.photons());
        let dealt: Vec<usize> = (0..PARTS)
            .map(|k| sizes.iter().map(|n| n.saturating_sub(k).div_ceil(PARTS)).sum())
            .collect();
        assert_eq!(counts, dealt);
        assert_eq!(dealt[0] - dealt[7], 20, "passes of 700 and of 5 deal unevenly");
        assert_eq!(m.parts.iter().map(PhotonMap::passes).collect::<Vec<_>>(), [20; PARTS]);
    }
}
