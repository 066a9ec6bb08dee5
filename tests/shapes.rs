//! Seeded property tests for every shape: a hit lies on the surface, normals
//! are unit and outward, entry comes before exit, and a ray spawned off a
//! surface never re-hits that surface.

use glam::DVec3;
use lensview::geometry::{Cuboid, Lens, Prism, Pyramid, Shape, Sphere};
use lensview::integrator::spawn_ray;
use lensview::math::Ray;
use lensview::optics::Index;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

fn shapes() -> Vec<Shape> {
    vec![
        Shape::Sphere(Sphere::new(0.7)),
        Shape::Cuboid(Cuboid::new(DVec3::new(1.0, 0.3, 2.0))),
        Shape::Prism(Prism::new(1.4, 0.8)),
        Shape::Pyramid(Pyramid::new(1.2, 1.5)),
        Shape::Lens(
            Lens::new(
                DVec3::ZERO,
                DVec3::new(0.2, 1.0, -0.3),
                2.0,
                5.0,
                3.0,
                Index::Constant(1.5),
            )
            .unwrap(),
        ),
        // A ball lens: two hemispheres.
        Shape::Lens(Lens::new(DVec3::ZERO, DVec3::Z, 1.0, 0.5, 0.5, Index::Constant(1.5)).unwrap()),
    ]
}

fn runner() -> TestRunner {
    TestRunner::new_with_rng(
        Config {
            cases: 2000,
            failure_persistence: None,
            ..Config::default()
        },
        TestRng::deterministic_rng(RngAlgorithm::ChaCha),
    )
}

/// A ray from a random point on a sphere of radius 5 toward a random point
/// of the shape's bounding box.
fn ray_strategy() -> impl Strategy<Value = (DVec3, DVec3)> {
    let unit = -1.0f64..1.0;
    (
        (unit.clone(), unit.clone(), unit.clone()),
        (0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0),
    )
        .prop_map(|((a, b, c), (x, y, z))| (DVec3::new(a, b, c), DVec3::new(x, y, z)))
}

fn check_shape(shape: &Shape) {
    let b = shape.bounds();
    let eps = 1e-7 * shape.scale();
    let hits = std::cell::Cell::new(0usize);
    runner()
        .run(&ray_strategy(), |(dir_seed, target)| {
            let from = 5.0 * shape.scale() * dir_seed.try_normalize().unwrap_or(DVec3::X);
            let to = b.min + (b.max - b.min) * target;
            let ray = Ray::new(from, to - from);
            let Some(h) = shape.intersect(&ray, 0.0, f64::INFINITY) else {
                return Ok(());
            };
            hits.set(hits.get() + 1);
            let p = ray.at(h.t);
            let n = shape.normal(p, h.part);
            prop_assert!((n.length() - 1.0).abs() < 1e-12, "normal not unit: {n}");
            // On the surface: inside just below it, outside just above it.
            prop_assert!(
                shape.contains(p - eps * n),
                "{} hit {p} not on surface (below)",
                shape.kind_name()
            );
            prop_assert!(
                !shape.contains(p + eps * n),
                "{} hit {p} not on surface (above)",
                shape.kind_name()
            );
            // Coming from outside, the ray meets the front of the surface.
            prop_assert!(ray.dir.dot(n) <= 1e-12, "entry normal faces away");
            // The exit lies beyond the entry and the chord between is inside.
            let exit = shape.intersect(&ray, h.t, f64::INFINITY);
            prop_assert!(exit.is_some(), "no exit after entry");
            let e = exit.unwrap();
            prop_assert!(e.t >= h.t);
            if e.t - h.t > 1e-6 {
                prop_assert!(shape.contains(ray.at(0.5 * (h.t + e.t))));
                let ne = shape.normal(ray.at(e.t), e.part);
                prop_assert!(ray.dir.dot(ne) >= -1e-12, "exit normal faces the ray");
            }
            // A reflected ray spawned off a convex surface never comes back.
            let r = lensview::optics::reflect(ray.dir, n);
            let spawned = spawn_ray(p, n, r, shape.scale());
            prop_assert!(
                shape.intersect(&spawned, 0.0, f64::INFINITY).is_none(),
                "reflected ray re-hit its surface"
            );
            // A ray spawned inside along the incoming direction finds the exit, not the entry.
            let inside = spawn_ray(p, n, ray.dir, shape.scale());
            let exit_point = ray.at(e.t);
            let offset = (inside.origin - p).length();
            match shape.intersect(&inside, 0.0, f64::INFINITY) {
                Some(x) => {
                    let q = inside.at(x.t);
                    // The spawned ray is shifted off the entry by the offset, so
                    // its exit moves by about offset / cos(angle); it must be
                    // the exit, not the entry it started from.
                    let miss = (q - exit_point).length();
                    prop_assert!(
                        miss < 1e-6 * shape.scale() && miss < (q - p).length(),
                        "inside ray hit {q}, not the exit {exit_point}"
                    );
                }
                None => prop_assert!(e.t - h.t <= 2.0 * offset, "inside ray found no exit"),
            }
            Ok(())
        })
        .unwrap();
    assert!(
        hits.get() > 200,
        "{}: only {} rays hit; the test would prove little",
        shape.kind_name(),
        hits.get()
    );
}

#[test]
fn sphere_properties() {
    check_shape(&shapes()[0]);
}
#[test]
fn cuboid_properties() {
    check_shape(&shapes()[1]);
}
#[test]
fn prism_properties() {
    check_shape(&shapes()[2]);
}
#[test]
fn pyramid_properties() {
    check_shape(&shapes()[3]);
}
#[test]
fn lens_properties() {
    check_shape(&shapes()[4]);
}
#[test]
fn ball_lens_properties() {
    check_shape(&shapes()[5]);
}

#[test]
fn far_away_sphere_is_still_exact() {
    // A sphere 1e6 away: the naive quadratic loses ~1e-4 here; the careful
    // form stays within a few ulp of the distance.
    let s = Sphere::new(1.0);
    let ray = Ray::new(DVec3::new(0.25, 0.0, 1e6), DVec3::NEG_Z);
    let t = s.intersect(&ray, 0.0, f64::INFINITY).unwrap().t;
    let exact = 1e6 - (1.0f64 - 0.0625).sqrt();
    assert!((t - exact).abs() <= 4.0 * f64::EPSILON * 1e6, "{t} vs {exact}");
}

#[test]
fn shape_sizes_match_their_definitions() {
    let prism = Prism::new(2.0, 1.0);
    // Vertices of the equilateral base: one at −z on the circumcircle.
    let circ = 2.0 / 3f64.sqrt();
    let s = Shape::Prism(prism);
    assert!(s.contains(DVec3::new(0.0, 0.0, -circ + 1e-9)));
    assert!(!s.contains(DVec3::new(0.0, 0.0, -circ - 1e-9)));
    assert!(s.contains(DVec3::new(0.999_999, 0.0, circ / 2.0 - 1e-6)));
    assert!(!s.contains(DVec3::new(0.0, 0.500_001, 0.0)));
    let pyr = Shape::Pyramid(Pyramid::new(2.0, 3.0));
    assert!(pyr.contains(DVec3::new(0.0, 1.5 - 1e-9, 0.0)));
    assert!(!pyr.contains(DVec3::new(0.0, 1.5 + 1e-9, 0.0)));
    assert!(pyr.contains(DVec3::new(0.999_999, -1.5 + 1e-9, 0.999_999)));
    assert!(!pyr.contains(DVec3::new(0.5, 0.1, 0.0)) || 0.5 <= (1.5 - 0.1) / 3.0);
}
