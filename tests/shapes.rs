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
        Shape::Lens(Box::new(
            Lens::new(
                DVec3::ZERO,
                DVec3::new(0.2, 1.0, -0.3),
                2.0,
                5.0,
                3.0,
                Index::Constant(1.5),
            )
            .unwrap(),
        )),
        // A ball lens: two hemispheres.
        Shape::Lens(Box::new(
            Lens::new(DVec3::ZERO, DVec3::Z, 1.0, 0.5, 0.5, Index::Constant(1.5)).unwrap(),
        )),
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

/// The README's rotation, written out here: `R = Ry·Rx·Rz`, degrees.
fn rotate(deg: [f64; 3], v: DVec3) -> DVec3 {
    let [x, y, z] = deg.map(f64::to_radians);
    let rz = DVec3::new(v.x * z.cos() - v.y * z.sin(), v.x * z.sin() + v.y * z.cos(), v.z);
    let rx = DVec3::new(rz.x, rz.y * x.cos() - rz.z * x.sin(), rz.y * x.sin() + rz.z * x.cos());
    DVec3::new(rx.x * y.cos() + rx.z * y.sin(), rx.y, -rx.x * y.sin() + rx.z * y.cos())
}

/// The solid as half-spaces made from its vertices (the README's
/// definitions, not the library's planes): each face is given by three of
/// its vertices, and its outward normal is the one pointing away from the
/// centroid of all vertices. Returns (unit normal, offset) pairs.
fn half_spaces(vertices: &[DVec3], faces: &[[usize; 3]]) -> Vec<(DVec3, f64)> {
    let centroid = vertices.iter().sum::<DVec3>() / vertices.len() as f64;
    faces
        .iter()
        .map(|&[a, b, c]| {
            let (a, b, c) = (vertices[a], vertices[b], vertices[c]);
            let mut n = (b - a).cross(c - a).normalize();
            if n.dot(centroid - a) > 0.0 {
                n = -n;
            }
            (n, n.dot(a))
        })
        .collect()
}

/// Cyrus–Beck: the interval of `t ≥ 0` where the ray is inside every half-space.
fn clip(planes: &[(DVec3, f64)], ray: &Ray) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (0.0f64, f64::INFINITY);
    for &(n, d) in planes {
        let (dn, s) = (ray.dir.dot(n), d - ray.origin.dot(n));
        if dn.abs() < 1e-300 {
            if s < 0.0 {
                return None;
            }
        } else if dn > 0.0 {
            hi = hi.min(s / dn);
        } else {
            lo = lo.max(s / dn);
        }
    }
    (lo <= hi).then_some((lo, hi))
}

/// One prism or pyramid placed by the scene file (position and rotation),
/// hit by seeded random rays; the library's first hit must be where the
/// independent half-space clip enters, and a miss must be a miss there.
fn check_against_half_spaces(kind: &str, side: f64, height: f64, pos: [f64; 3], rot: [f64; 3]) {
    let (h, s) = (0.5 * height, side);
    let (verts, faces): (Vec<DVec3>, Vec<[usize; 3]>) = if kind == "prism" {
        // Equilateral base, one vertex on the circumcircle toward −z.
        let (r, x) = (s / 3f64.sqrt(), 0.5 * s);
        let base = [
            DVec3::new(0.0, 0.0, -r),
            DVec3::new(x, 0.0, 0.5 * r),
            DVec3::new(-x, 0.0, 0.5 * r),
        ];
        let v: Vec<DVec3> = [-h, h].iter().flat_map(|&y| base.map(|b| b + DVec3::Y * y)).collect();
        (v, vec![[0, 1, 2], [3, 4, 5], [0, 1, 3], [1, 2, 4], [2, 0, 5]])
    } else {
        // Square base at y = −h/2, apex at y = +h/2.
        let x = 0.5 * s;
        let v = vec![
            DVec3::new(-x, -h, -x),
            DVec3::new(x, -h, -x),
            DVec3::new(x, -h, x),
            DVec3::new(-x, -h, x),
            DVec3::new(0.0, h, 0.0),
        ];
        (v, vec![[0, 1, 2], [0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    };
    let p = DVec3::from(pos);
    let world: Vec<DVec3> = verts.iter().map(|&v| p + rotate(rot, v)).collect();
    let planes = half_spaces(&world, &faces);
    let text = format!(
        "[camera]\nposition = [0, 0, 50]\n[[objects]]\ntype = \"{kind}\"\nside = {side}\nheight = {height}\n\
         position = {pos:?}\nrotation = {rot:?}\n"
    );
    let (_, scene) = lensview::scene::Scene::parse("solid.toml", &text).unwrap();
    // SplitMix64, uniform in [−1, 1).
    let mut state = 0x9e37_79b9_7f4a_7c15u64 ^ side.to_bits();
    let mut unit = || {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    };
    let (mut hits, mut misses) = (0, 0);
    for _ in 0..4000 {
        let from = p + 4.0 * side.max(height) * DVec3::new(unit(), unit(), unit()).normalize();
        let to = p + side.max(height) * 0.6 * DVec3::new(unit(), unit(), unit());
        let ray = Ray::new(from, (to - from).normalize());
        let want = clip(&planes, &ray);
        let got = lensview::trace::closest_hit(&scene, &ray, f64::INFINITY).map(|(_, hit)| hit.t);
        match (want, got) {
            (Some((t0, t1)), Some(t)) => {
                assert!(
                    (t - t0).abs() < 1e-9,
                    "{kind} {rot:?}: hit at {t}, half-spaces enter at {t0}"
                );
                hits += usize::from(t1 - t0 > 1e-6);
            }
            // Grazing an edge or corner: either answer is right.
            (Some((t0, t1)), None) => assert!(t1 - t0 < 1e-9, "{kind} {rot:?}: missed a chord {t0}..{t1}"),
            (None, Some(t)) => {
                let q = ray.at(t);
                let out = planes.iter().map(|&(n, d)| q.dot(n) - d).fold(f64::MIN, f64::max);
                assert!(out < 1e-9, "{kind} {rot:?}: hit at {q}, {out} outside the solid");
            }
            (None, None) => misses += 1,
        }
    }
    assert!(hits > 500 && misses > 200, "{kind}: {hits} hits, {misses} misses");
}

#[test]
fn prisms_and_pyramids_match_half_spaces_made_from_their_vertices() {
    for kind in ["prism", "pyramid"] {
        check_against_half_spaces(kind, 1.4, 0.8, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]);
        check_against_half_spaces(kind, 2.0, 3.0, [1.5, -2.0, 0.5], [30.0, 0.0, 0.0]);
        check_against_half_spaces(kind, 0.7, 1.9, [-3.0, 1.0, 2.0], [17.0, -63.0, 41.0]);
        check_against_half_spaces(kind, 1.2, 1.5, [0.0, 4.0, -1.0], [90.0, 45.0, -120.0]);
    }
}
