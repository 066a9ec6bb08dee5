//! `lens fan`, `lens spot` and `lens distortion` agree on when a lens forms
//! a real image to measure on (no image plane given): on seeded random
//! lenses and objects, n = 1 and objects inside the front focal point
//! among them, all three measure or all three refuse, naming the same
//! field; an object inside F (a magnifier) is measured by all three in its
//! virtual image; a refusal never names `object-distance` when no object
//! distance was given.

use lensview::lens_tools::{Setup, distortion, fan, spot_diagram};
use lensview::optics::Index;

struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn fan_spot_and_distortion_give_one_verdict() {
    let mut rng = Rng(29);
    let (mut measured, mut refused, mut magnifiers) = (0, 0, 0);
    for case in 0..600 {
        let d = 0.5 + 3.0 * rng.unit();
        let r = |rng: &mut Rng| d / 2.0 * (1.0 + 20.0 * rng.unit() * rng.unit());
        let (r1, r2) = (r(&mut rng), r(&mut rng));
        let n = match case % 5 {
            0 => 1.0,
            _ => 1.0 + 2.5 * rng.unit(),
        };
        let object = match case % 3 {
            0 => None,
            _ => Some(0.05 + 30.0 * rng.unit() * rng.unit()),
        };
        let Ok(setup) = Setup::new(d, r1, r2, Index::Constant(n), object, 5.0) else {
            continue;
        };
        let dist = distortion(&setup, 10.0, 3);
        let magnifier = dist.as_ref().is_ok_and(|d| d.virtual_image);
        let fan = fan(&setup, 5, None);
        let spot = spot_diagram(&setup, None, 2);
        // A magnifier is measured by all three in its virtual image, before V2.
        if magnifier {
            let (f, s) = (fan.as_ref().unwrap(), spot.as_ref().unwrap());
            let plane = dist.as_ref().unwrap().image_plane_from_v2;
            assert!(f.virtual_image && s.virtual_image && plane < 0.0, "case {case}");
            assert_eq!(
                (f.image_plane_from_v2, s.image_plane_from_v2),
                (plane, plane),
                "case {case}"
            );
        }
        let verdicts = [fan.map(|_| ()), spot.map(|_| ()), dist.map(|_| ())];
        let fields: Vec<Option<&str>> = verdicts.iter().map(|v| v.as_ref().err().map(|e| e.field)).collect();
        let what = format!("case {case}: d {d} r1 {r1} r2 {r2} n {n} object {object:?}: {verdicts:?}");
        assert!(fields.iter().all(|f| *f == fields[0]), "{what}");
        if object.is_none() {
            assert_ne!(fields[0], Some("object-distance"), "{what}");
        }
        if n == 1.0 {
            assert_eq!(fields[0], Some("n"), "{what}");
        }
        assert!(!magnifier || object.is_some(), "{what}");
        magnifiers += usize::from(magnifier);
        match fields[0] {
            None => measured += 1,
            Some(_) => refused += 1,
        }
    }
    assert!(
        measured > 100 && refused > 100 && magnifiers > 20,
        "{measured} measured, {refused} refused, {magnifiers} magnifiers"
    );
}
