//! The photon map's tests (beside `mod.rs`, which they would push past
//! its size).

use super::*;

pub(super) fn photon(x: f64, y: f64, power: f64) -> Photon {
    Photon::new(DVec3::new(x, y, 0.0), -DVec3::Z, Rgb::splat(power))
}

/// One photon of power 1 at the origin: within the radius the estimate
/// is 1/(πr²) on the side it arrived on (to `f32`: a photon's share is
/// stored so), zero outside or behind.
#[test]
fn one_photon_gives_its_power_over_the_disc() {
    let mut m = PhotonMap::new(0.5);
    m.add_pass(&[photon(0.0, 0.0, 1.0)]);
    let e = m.irradiance(DVec3::new(0.3, 0.2, 0.0), DVec3::Z);
    let want = 1.0 / (std::f64::consts::PI * 0.25);
    assert!((e.x / want - 1.0).abs() < 1e-7, "{e}");
    assert_eq!(m.irradiance(DVec3::new(0.5, 0.1, 0.0), DVec3::Z), Rgb::ZERO);
    assert_eq!(m.irradiance(DVec3::ZERO, -DVec3::Z), Rgb::ZERO);
}

/// The radius shrinks by level as `(2^L)^((α−1)/2)`, and the estimate is
/// the mean over passes: a second pass with nothing near halves it.
#[test]
fn radius_schedule_and_mean_over_passes() {
    assert_eq!(PhotonMap::radius_of_pass(1.0, 1), 1.0);
    let r2 = PhotonMap::radius_of_pass(1.0, 2);
    assert!((r2 - 2f64.powf(-1.0 / 6.0)).abs() < 1e-15);
    assert_eq!(PhotonMap::radius_of_pass(1.0, 3), r2);
    assert!(PhotonMap::radius_of_pass(1.0, 4) < r2);
    let mut m = PhotonMap::new(0.5);
    m.add_pass(&[photon(0.0, 0.0, 1.0)]);
    let e1 = m.irradiance(DVec3::ZERO, DVec3::Z);
    m.add_pass(&[photon(5.0, 0.0, 1.0)]);
    assert_eq!(m.irradiance(DVec3::ZERO, DVec3::Z), e1 / 2.0);
    assert_eq!(m.passes(), 2);
    assert_eq!(m.photons(), 2);
}

/// Photons across cell boundaries are all found: a uniform grid of
/// photons gives its density everywhere inside.
#[test]
fn a_uniform_field_gives_its_density() {
    let mut v = Vec::new();
    let h = 0.01;
    for i in -200..200 {
        for j in -200..200 {
            v.push(photon((i as f64 + 0.5) * h, (j as f64 + 0.5) * h, h * h));
        }
    }
    let mut m = PhotonMap::new(0.1);
    m.add_pass(&v);
    for x in [DVec3::ZERO, DVec3::new(0.7, -0.33, 0.0), DVec3::new(-1.2, 1.1, 0.0)] {
        let e = m.irradiance(x, DVec3::Z).x;
        assert!((e - 1.0).abs() < 0.03, "{x}: {e}");
    }
}

/// Twenty passes (five levels, two groups of cells) against the sum
/// over every photon of every pass, each within its pass's radius.
#[test]
fn many_passes_give_the_brute_force_estimate() {
    let mut rng = crate::sampling::Sampler::new(1, 2, 3);
    let mut m = PhotonMap::new(0.2);
    let (mut all, mut passes) = (Vec::new(), Vec::new());
    for k in 1..=20u32 {
        let pass: Vec<Photon> = (0..300)
            .map(|_| {
                let (u, v) = rng.next_2d();
                let dir = if rng.next_f64() < 0.8 { -DVec3::Z } else { DVec3::Z };
                Photon::new(DVec3::new(u - 0.5, v - 0.5, 0.0), dir, Rgb::splat(1e-3))
            })
            .collect();
        m.add_pass(&pass);
        all.extend(pass.iter().map(|&p| (p, PhotonMap::radius_of_pass(0.2, k))));
        passes.push(pass);
    }
    assert!(m.groups.len() == 2, "{} groups", m.groups.len());
    // The same passes added in batches (one across the groups' border)
    // give the same map, bit for bit.
    let mut b = PhotonMap::new(0.2);
    for batch in [0..1, 1..4, 4..9, 9..20] {
        b.add_passes(&passes[batch].iter().map(Vec::as_slice).collect::<Vec<_>>());
    }
    for i in 0..50 {
        let x = DVec3::new(0.02 * i as f64 - 0.5, 0.3 - 0.011 * i as f64, 0.0);
        let want: f64 = all
            .iter()
            .filter(|(p, r)| (p.p - x).length() < *r && p.dir[2] < 0.0)
            .map(|(p, r)| p.power[0] as f64 / (std::f64::consts::PI * r * r))
            .sum::<f64>()
            / 20.0;
        let got = m.irradiance(x, DVec3::Z).x;
        assert!((got - want).abs() <= 1e-5 * want, "{x}: {got} vs {want}");
        assert_eq!(b.irradiance(x, DVec3::Z).x.to_bits(), got.to_bits(), "{x}");
    }
}

/// No photon within reach is missed, nor one out of reach let in:
/// around queries in a cell, on a cell's corner and near a face,
/// photons just inside the radius in every direction are all counted
/// and those just outside none.
#[test]
fn photons_just_inside_the_radius_are_all_found() {
    let r = 0.25;
    let queries = [
        DVec3::new(0.2, 0.3, 0.1),
        DVec3::new(0.5, 0.5, 0.5),
        DVec3::new(0.49, -0.01, 0.26),
    ];
    for (k, &q) in queries.iter().enumerate() {
        let mut rng = crate::sampling::Sampler::new(7, k as u64, 0);
        let mut pass = Vec::new();
        for i in 0..400 {
            let (u, v) = rng.next_2d();
            let (z, phi) = (2.0 * u - 1.0, 2.0 * std::f64::consts::PI * v);
            let s = (1.0 - z * z).sqrt();
            let dir = DVec3::new(s * phi.cos(), s * phi.sin(), z);
            let reach = if i % 2 == 0 { 1.0 - 1e-5 } else { 1.0 + 1e-5 };
            pass.push(Photon::new(q + dir * (r * reach), -DVec3::Z, Rgb::ONE));
        }
        let mut m = PhotonMap::new(r);
        m.add_pass(&pass);
        let want = 200.0 / (std::f64::consts::PI * r * r);
        let e = m.irradiance(q, DVec3::Z).x;
        assert!((e / want - 1.0).abs() < 1e-6, "{q}: {e} vs {want}");
    }
}

/// A later pass that occupies new cells of the same group is found
/// there: its cells' blocks are marked as it is added.
#[test]
fn a_later_pass_in_new_cells_is_found() {
    let r = 0.3;
    let mut m = PhotonMap::new(r);
    m.add_pass(&[photon(0.0, 0.0, 1.0)]);
    m.add_pass(&[photon(5.0, 5.0, 1.0)]);
    assert_eq!(m.groups.len(), 1, "both passes share a group");
    let r2 = PhotonMap::radius_of_pass(r, 2);
    let at = |x: f64| m.irradiance(DVec3::new(x, 5.0, 0.0), DVec3::Z).x;
    let want = 1.0 / (std::f64::consts::PI * r2 * r2) as f32 as f64 / 2.0;
    assert!(
        (at(5.0 + 0.9 * r2) / want - 1.0).abs() < 1e-6,
        "{} vs {want}",
        at(5.0 + 0.9 * r2)
    );
    assert_eq!(at(5.0 + 1.1 * r2), 0.0);
}

/// Sparse photons (most queries' blocks of cells hold none, and the
/// group's bit says so): queries just inside a photon's radius still
/// find it, from any side and across cells, those just outside and
/// those in empty space get exactly zero, and the bit does turn most
/// of the empty-space queries away.
#[test]
fn sparse_photons_are_found_and_empty_space_is_turned_away() {
    let r = 0.3;
    let mut rng = crate::sampling::Sampler::new(5, 0, 9);
    let mut point = |scale: f64| {
        let (u, v) = rng.next_2d();
        let (w, _) = rng.next_2d();
        DVec3::new(u - 0.5, v - 0.5, w - 0.5) * scale
    };
    let pass: Vec<Photon> = (0..60).map(|_| Photon::new(point(10.0), -DVec3::Z, Rgb::ONE)).collect();
    let mut m = PhotonMap::new(r);
    m.add_pass(&pass);
    let want_at = |x: DVec3| -> f64 {
        let n = pass.iter().filter(|p| (p.p - x).length() < r).count();
        n as f64 / (std::f64::consts::PI * r * r)
    };
    let mut queries = Vec::new();
    for p in &pass {
        for i in 0..8 {
            let d = (point(2.0) + DVec3::splat(1e-3)).normalize();
            let reach = if i % 2 == 0 { 1.0 - 1e-4 } else { 1.0 + 1e-4 };
            queries.push(p.p + d * r * reach);
        }
    }
    let (mut found, mut empty, mut turned_away) = (0, 0, 0);
    for _ in 0..2000 {
        let x = point(10.0);
        empty += usize::from(want_at(x) == 0.0);
        turned_away += usize::from(m.groups.iter().all(|g| g.reach(x).is_none()));
        queries.push(x);
    }
    for &x in &queries {
        let (got, want) = (m.irradiance(x, DVec3::Z).x, want_at(x));
        if want == 0.0 {
            assert_eq!(got, 0.0, "{x}");
        } else {
            found += 1;
            assert!((got / want - 1.0).abs() < 1e-6, "{x}: {got} vs {want}");
        }
    }
    assert!(found >= 240, "{found} queries within reach");
    assert!(
        turned_away * 10 > empty * 6,
        "{turned_away} of {empty} empty queries turned away"
    );
}

/// A photon of a family listed two half octaves up is gathered within
/// twice the map's radius, weighed over that disc; one of another family
/// within the map's; neither past its own. A later pass shrinks both
/// radii by the same schedule.
#[test]
fn each_family_is_gathered_within_its_own_radius() {
    let mut m = PhotonMap::with_families(0.5, &[(3, 2)]);
    let wide = Photon::new(DVec3::ZERO, -DVec3::Z, Rgb::ONE).with_family(3);
    let narrow = Photon::new(DVec3::new(5.0, 0.0, 0.0), -DVec3::Z, Rgb::ONE).with_family(4);
    m.add_pass(&[wide, narrow]);
    let pi = std::f64::consts::PI;
    let at = |m: &PhotonMap, x: f64| m.irradiance(DVec3::new(x, 0.1, 0.0), DVec3::Z).x;
    let close = |got: f64, want: f64| (got / want - 1.0).abs() < 1e-6;
    assert!(close(at(&m, 0.9), 1.0 / pi), "{}", at(&m, 0.9));
    assert_eq!(at(&m, 1.0), 0.0);
    assert!(close(at(&m, 5.4), 1.0 / (pi * 0.25)), "{}", at(&m, 5.4));
    assert_eq!(at(&m, 5.5), 0.0);
    m.add_pass(&[wide, narrow]);
    let r2 = PhotonMap::radius_of_pass(0.5, 2);
    let mean = |r: f64| (1.0 / (pi * 4.0 * 0.25) + 1.0 / (pi * 4.0 * r * r)) / 2.0;
    assert!(close(at(&m, 2.0 * r2 - 0.01), mean(r2)), "{}", at(&m, 2.0 * r2 - 0.01));
    assert!(close(at(&m, 0.5), 1.0 / pi / 2.0 + 1.0 / (pi * 4.0 * r2 * r2) / 2.0));
}

/// A wide, thin caustic beside a dense spot (a convex mirror's reflection
/// beside a lens's focus): with each family's radius from its own spacing
/// ([`family_scales`]) the thin one's irradiance is found several times
/// more closely than with the one radius the mixture's median gives, and
/// without bias; the spot's is the same to the bit.
#[test]
fn a_thin_wide_family_is_found_more_closely_with_its_own_radius() {
    let mut rng = crate::sampling::Sampler::new(5, 0, 1);
    let mut photon_at = |family: u32, lo: f64, side: f64| {
        let (u, v) = rng.next_2d();
        let p = DVec3::new(lo + side * u, side * v, 0.0);
        Photon::new(p, -DVec3::Z, Rgb::ONE).with_family(family)
    };
    // The spot: 30 000 a unit area; the field: 625, spaced 7 times as
    // widely (gathered within 4 times the spot's radius, the most).
    let mut pass: Vec<Photon> = (0..30_000).map(|_| photon_at(1, 0.0, 1.0)).collect();
    pass.extend((0..10_000).map(|_| photon_at(2, 2.0, 4.0)));
    let r0 = initial_radius(&pass, 24, 0.0).unwrap();
    let listed = family_scales(&pass, 24, r0);
    assert_eq!(listed, vec![(2, family::MOST_HALF_OCTAVES)], "r0 {r0}");
    let (mut one, mut own) = (PhotonMap::new(r0), PhotonMap::with_families(r0, &listed));
    one.add_pass(&pass);
    own.add_pass(&pass);
    let (mut err_one, mut err_own, mut sum_own, n) = (0.0, 0.0, 0.0, 2_000);
    for i in 0..n {
        let (u, v) = (((i % 40) as f64 + 0.5) / 40.0, ((i / 40) as f64 + 0.5) / 50.0);
        let x = DVec3::new(2.5 + 3.0 * u, 0.5 + 3.0 * v, 0.0);
        let (a, b) = (one.irradiance(x, DVec3::Z).x, own.irradiance(x, DVec3::Z).x);
        err_one += (a / 625.0 - 1.0).powi(2);
        err_own += (b / 625.0 - 1.0).powi(2);
        sum_own += b;
        let s = DVec3::new(0.2 + 0.6 * u, 0.2 + 0.6 * v, 0.0);
        let (a, b) = (one.irradiance(s, DVec3::Z), own.irradiance(s, DVec3::Z));
        assert_eq!(a.x.to_bits(), b.x.to_bits(), "the spot at {s}");
    }
    let (rms_one, rms_own) = ((err_one / n as f64).sqrt(), (err_own / n as f64).sqrt());
    assert!(
        rms_own < rms_one / 3.0,
        "relative RMS {rms_own} with its own radius, {rms_one} with one"
    );
    let mean = sum_own / n as f64 / 625.0;
    assert!((mean - 1.0).abs() < 0.05, "mean {mean} of the field's density");
}
