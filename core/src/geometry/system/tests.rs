use super::*;
use crate::geometry::{Lens, LensTraceStatus, Pruning};
use crate::optics::{ThickLens, WAVELENGTH_D_UM};

fn surf(radius: f64, thickness: f64, n: f64, a: f64) -> SurfaceSpec {
    SurfaceSpec {
        radius,
        thickness,
        n: Index::Constant(n),
        semi_aperture: a,
        stop: false,
    }
}

/// The biconvex lens of `Lens::new(center, axis, d, r1, r2, n)` as a system.
fn biconvex(center: DVec3, axis: DVec3, d: f64, r1: f64, r2: f64, n: f64) -> (Lens, LensSystem) {
    let lens = Lens::new(center, axis, d, r1, r2, Index::Constant(n)).unwrap();
    let (s1, s2) = (crate::optics::sagitta(r1, d / 2.0), crate::optics::sagitta(r2, d / 2.0));
    let a = axis.normalize();
    let sys = LensSystem::new(
        center + a * s1,
        axis,
        vec![surf(r1, s1 + s2, n, d / 2.0), surf(-r2, 0.0, 1.0, d / 2.0)],
    )
    .unwrap();
    (lens, sys)
}

#[test]
fn a_biconvex_system_traces_as_the_lens_does() {
    let cases = [
        (
            DVec3::new(0.3, -0.2, 1.0),
            DVec3::new(0.0, 0.6, 0.8),
            2.0,
            5.0,
            3.0,
            1.5,
        ),
        (DVec3::ZERO, DVec3::Z, 2.0, 1.0, 1.0, 1.7),
        (
            DVec3::new(1e3, 2e3, -5e2),
            DVec3::new(1.0, 1.0, 1.0),
            1e-3,
            2e-3,
            5e-3,
            1.5,
        ),
    ];
    for (center, axis, d, r1, r2, n) in cases {
        let (lens, sys) = biconvex(center, axis, d, r1, r2, n);
        let a = axis.normalize();
        let (e1, e2) = a.any_orthonormal_pair();
        for i in 0..40 {
            let h = (f64::from(i) / 40.0 - 0.5) * 0.98 * d;
            let tilt = 0.3 * (f64::from(i) * 0.37).sin();
            let start = center + a * (3.0 * d) + e1 * h + e2 * (0.1 * h);
            let dir = (-a + e1 * tilt).normalize();
            let want = lens.trace(start, dir, n);
            let got = sys.trace(start, dir, WAVELENGTH_D_UM);
            match (want.status, want.exit) {
                (LensTraceStatus::Transmitted, Some((_, x, u))) => {
                    assert_eq!(got.status, RayStatus::Transmitted, "{center} {h}");
                    let (_, gx, gu) = got.exit.unwrap();
                    // Both are exact to 1e-9 of the lens (the independent
                    // reference checks each); they agree far closer.
                    let ulps = 4.0 * f64::EPSILON * center.abs().max_element();
                    assert!((gx - x).length() <= 1e-10 * d + ulps, "{gx} {x}");
                    assert!((gu - u).length() <= 1e-10, "{gu} {u}");
                    assert_eq!(got.reflections, want.internal_reflections);
                }
                _ => assert_ne!(got.status, RayStatus::Transmitted),
            }
        }
    }
}

#[test]
fn paraxial_data_of_a_biconvex_system_are_the_thick_lens_formulas() {
    for (d, r1, r2, n) in [(2.0, 5.0, 5.0, 1.5), (20.0, 50.0, 100.0, 1.5168), (2.0, 1.0, 5.0, 1.5)] {
        let (_, sys) = biconvex(DVec3::ZERO, DVec3::Z, d, r1, r2, n);
        let p = sys.paraxial(WAVELENGTH_D_UM);
        let t = ThickLens::new(d, r1, r2, n);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
        assert!(close(p.efl, t.efl), "{} {}", p.efl, t.efl);
        assert!(close(p.bfd, t.bfd), "{} {}", p.bfd, t.bfd);
        assert!(close(p.ffd, t.ffd), "{} {}", p.ffd, t.ffd);
        assert!(close(p.front_principal, t.h1), "{} {}", p.front_principal, t.h1);
        assert!(close(p.rear_principal, t.h2), "{} {}", p.rear_principal, t.h2);
    }
}

#[test]
fn a_plano_convex_condenser_focuses_a_paraxial_ray_at_its_bfd() {
    // Flat side first, then R = −50: f = R/(n − 1) = 100.
    let sys = LensSystem::new(
        DVec3::ZERO,
        DVec3::Z,
        vec![surf(0.0, 5.0, 1.5, 10.0), surf(-50.0, 0.0, 1.0, 10.0)],
    )
    .unwrap();
    let p = sys.paraxial(WAVELENGTH_D_UM);
    assert!((p.efl - 100.0).abs() < 1e-12 * 100.0, "{}", p.efl);
    // H′ lies on the curved face's vertex, H at t/n inside the flat one.
    assert!((p.bfd - 100.0).abs() < 1e-12 * 100.0, "{}", p.bfd);
    assert!((p.ffd - (100.0 - 5.0 / 1.5)).abs() < 1e-12 * 100.0, "{}", p.ffd);
    let h = 1e-4;
    let r = sys.trace(DVec3::new(h, 0.0, 10.0), -DVec3::Z, WAVELENGTH_D_UM);
    let (_, x, u) = r.exit.unwrap();
    // Light travels along −z: the last vertex is at z = −5.
    let z_cross = x.z - x.x / u.x * u.z;
    assert!(((-5.0 - z_cross) - p.bfd).abs() < 1e-6 * p.bfd, "{z_cross}");
}

#[test]
fn a_ray_beyond_the_stop_is_absorbed_and_an_edge_ray_too() {
    let sys = LensSystem::new(
        DVec3::ZERO,
        DVec3::Z,
        vec![
            SurfaceSpec {
                stop: true,
                ..surf(0.0, 5.0, 1.0, 2.0)
            },
            surf(30.0, 4.0, 1.6, 6.0),
            surf(-30.0, 0.0, 1.0, 6.0),
        ],
    )
    .unwrap();
    let through = sys.trace(DVec3::new(1.0, 0.0, 5.0), -DVec3::Z, WAVELENGTH_D_UM);
    assert_eq!(through.status, RayStatus::Transmitted);
    let blocked = sys.trace(DVec3::new(3.0, 0.0, 5.0), -DVec3::Z, WAVELENGTH_D_UM);
    assert_eq!(blocked.status, RayStatus::Absorbed);
    assert_eq!(sys.piece_name(blocked.events[0].piece), "stop");
    // From the side, at the element's edge.
    let edge = sys.trace(DVec3::new(20.0, 0.0, -7.0), -DVec3::X, WAVELENGTH_D_UM);
    assert_eq!(edge.status, RayStatus::Absorbed);
    assert_eq!(sys.piece_name(edge.events[0].piece), "edge");
}

#[test]
fn the_tree_keeps_the_light_that_is_not_absorbed() {
    let sys = LensSystem::new(
        DVec3::ZERO,
        DVec3::Z,
        vec![
            surf(40.0, 6.0, 1.5168, 10.0),
            surf(-30.0, 2.5, 1.67, 10.0),
            surf(-120.0, 0.0, 1.0, 10.0),
        ],
    )
    .unwrap();
    for h in [0.0, 3.0, 7.5] {
        let mut sum = 0.0;
        let mut count = 0;
        let dropped = sys.branches(
            DVec3::new(h, 0.5, 20.0),
            -DVec3::Z,
            WAVELENGTH_D_UM,
            &Pruning::NONE,
            &mut |b| {
                sum += b.weight;
                count += 1;
            },
        );
        assert!(count > 3, "{count}");
        // Light reflected back to the edge or rings is absorbed: the sum is
        // below 1 by little.
        assert!(sum + dropped <= 1.0 + 1e-12 && sum + dropped > 0.99, "{sum} {dropped}");
    }
}

#[test]
fn impossible_systems_are_refused_naming_the_field() {
    let bad = |s: Vec<SurfaceSpec>| LensSystem::new(DVec3::ZERO, DVec3::Z, s).unwrap_err();
    let e = bad(vec![surf(5.0, 1.0, 1.5, 6.0), surf(-5.0, 0.0, 1.0, 5.0)]);
    assert_eq!((e.surface, e.field), (Some(0), "radius"));
    // Biconvex too thin at the edge.
    let e = bad(vec![surf(10.0, 1.0, 1.5, 5.0), surf(-10.0, 0.0, 1.0, 5.0)]);
    assert_eq!((e.surface, e.field), (Some(0), "thickness"));
    let e = bad(vec![surf(10.0, 5.0, 1.5, 5.0), surf(-10.0, 0.0, 1.6, 5.0)]);
    assert_eq!((e.surface, e.field), (Some(1), "n"));
    let e = bad(vec![surf(10.0, -1.0, 1.5, 5.0), surf(-10.0, 0.0, 1.0, 5.0)]);
    assert_eq!(e.field, "thickness");
    let e = bad(vec![
        SurfaceSpec {
            stop: true,
            ..surf(10.0, 5.0, 1.0, 5.0)
        },
        surf(0.0, 0.0, 1.0, 5.0),
    ]);
    assert_eq!(e.field, "stop");
    // Two elements whose faces cross in the gap.
    let e = bad(vec![
        surf(20.0, 3.0, 1.5, 5.0),
        surf(20.0, 0.1, 1.0, 5.0),
        surf(-8.0, 3.0, 1.5, 5.0),
        surf(-20.0, 0.0, 1.0, 5.0),
    ]);
    assert_eq!((e.surface, e.field), (Some(1), "thickness"));
}

/// The light a grid of rays across the double Gauss sends out, by number
/// of reflections (3: three or more), and the rays out, for `prune`.
fn light_by_reflections(prune: &Pruning) -> ([f64; 4], usize) {
    let text = crate::prescription::preset("double-gauss-50mm").unwrap();
    let rows = crate::prescription::parse("dg", text).unwrap();
    let sys = LensSystem::new(DVec3::ZERO, DVec3::Z, SurfaceSpec::from_rows(&rows, 0.08)).unwrap();
    let (r, m) = (sys.radius(), 60);
    let (mut by, mut rays) = ([0.0; 4], 0);
    for i in 0..m {
        for j in 0..m {
            let at = |k: usize| (k as f64 / (m - 1) as f64 - 0.5) * r;
            let dir = DVec3::new(0.01, 0.02, 1.0).normalize();
            sys.branches(DVec3::new(at(i), at(j), -10.0), dir, WAVELENGTH_D_UM, prune, &mut |b| {
                by[b.reflections.min(3) as usize] += b.weight * prune.scale / (m * m) as f64;
                rays += 1;
            });
        }
    }
    (by, rays)
}

/// Russian roulette on the ghosts of a many-surface system keeps their
/// light in expectation (against the tree without it, neither pruned by
/// weight),
/// leaves the rays with fewer reflections alone, walks far fewer ghosts, and
/// gives the same ray the same tree.
#[test]
fn ghosts_play_a_roulette_that_keeps_their_light() {
    let prune = |roulette| Pruning {
        scale: 0.5,
        min: 0.0,
        max_reflections: 3,
        roulette,
    };
    let (exact, all) = light_by_reflections(&prune(0.0));
    let (played, kept) = light_by_reflections(&prune(1.0 / 64.0));
    assert_eq!(light_by_reflections(&prune(1.0 / 64.0)), (played, kept));
    assert_eq!(exact[..2], played[..2]);
    let ghosts = |v: [f64; 4]| v[2] + v[3];
    assert!(ghosts(exact) > 0.01, "{exact:?}");
    let rel = ghosts(played) / ghosts(exact) - 1.0;
    eprintln!(
        "ghost light {:.5} with the roulette, {:.5} without ({rel:+.4}); rays out {kept} against {all}",
        ghosts(played),
        ghosts(exact)
    );
    assert!(
        rel.abs() < 0.05,
        "ghosts {} against {} ({rel:+.3})",
        ghosts(played),
        ghosts(exact)
    );
    assert!(2 * kept < all, "{kept} rays out against {all}");
}
