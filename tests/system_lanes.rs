//! The lens camera's sensor rays in lanes (`LensSystem::pass_lanes`,
//! `LensCamera::local_rays`, the renderer's lens-camera bands) against the
//! scalar pass, and the trees of scene rays into a system in lanes
//! (`LensSystem::branches_lanes`, the packet kernel's) against the scalar
//! tree, bit for bit, on every instruction set this CPU runs.

use glam::DVec3;
use lensview::camera::LensCamera;
use lensview::geometry::{EventKind, LaneTrees, LensSystem, Pruning, RayStatus, SystemBranch};
use lensview::integrator::{GHOST_ROULETTE, LENS_MIN_WEIGHT};
use lensview::optics::WAVELENGTH_D_UM;
use lensview::render::{RenderSettings, render, render_pixel};
use lensview::scene::Scene;
use lensview::simd::{Isa, LANES, force_isa};
use std::path::Path;

/// The builds of the lane code this CPU runs.
fn isas() -> Vec<Isa> {
    [Isa::Portable, Isa::Avx2, Isa::Avx512]
        .into_iter()
        .filter(|&i| i as u8 <= Isa::detected() as u8)
        .collect()
}

fn load(file: &str) -> Scene {
    Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(file))
        .unwrap()
        .1
}

fn camera_dgauss() -> Scene {
    load("scenes/camera-dgauss.toml")
}

fn lens(s: &Scene) -> &LensCamera {
    s.lens.as_deref().expect("a lens camera")
}

/// A small generator (SplitMix64), so that the rays are the same each run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next()
    }
}

/// Rays of every kind about the camera's system (camera space, its axis
/// along `−z`, the sensor behind at `+z`): from the sensor toward the rear
/// element and well beyond its aperture, nearly along the surfaces
/// (grazing), from the front, and from inside; `kind` picks.
fn ray(rng: &mut Rng, s: &LensSystem, kind: u32) -> (DVec3, DVec3) {
    let len = s.length();
    let r = s.surfaces.iter().map(|f| f.semi_aperture).fold(0.0, f64::max);
    let front = s.vertex.z;
    let rear = front + len;
    match kind % 4 {
        0 => {
            let o = DVec3::new(rng.range(-r, r), rng.range(-r, r), rear + rng.range(0.2, 1.0) * len);
            let p = DVec3::new(rng.range(-1.6, 1.6) * r, rng.range(-1.6, 1.6) * r, rear);
            (o, p - o)
        }
        1 => {
            let o = DVec3::new(rng.range(-r, r), rng.range(-r, r), rng.range(front, rear));
            let d = DVec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-0.05, 0.05));
            (o - 3.0 * r * d, d)
        }
        2 => {
            let o = DVec3::new(rng.range(-r, r), rng.range(-r, r), front - rng.range(0.2, 1.0) * len);
            let p = DVec3::new(rng.range(-1.2, 1.2) * r, rng.range(-1.2, 1.2) * r, rear);
            (o, p - o)
        }
        _ => {
            let o = DVec3::new(
                rng.range(-0.5, 0.5) * r,
                rng.range(-0.5, 0.5) * r,
                rng.range(front, rear),
            );
            let d = DVec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
            (o, d)
        }
    }
}

fn bits(p: Option<(DVec3, DVec3)>) -> Option<[u64; 6]> {
    p.map(|(a, b)| [a.x, a.y, a.z, b.x, b.y, b.z].map(f64::to_bits))
}

/// Every lane of `pass_lanes` is `pass` bit for bit, on rays of every
/// kind mixed in one packet (each packet also with lanes left out), and
/// the rays include passes, vignetting, total internal reflection,
/// misses and grazing rays.
#[test]
fn lanes_pass_as_the_scalar_pass_does() {
    let scene = camera_dgauss();
    let s = &lens(&scene).system;
    let (mut passed, mut reflected, mut absorbed, mut missed) = (0, 0, 0, 0);
    for isa in isas() {
        assert!(force_isa(Some(isa)));
        for lambda in [WAVELENGTH_D_UM, 0.4861] {
            let media = s.media(lambda);
            let mut rng = Rng(7);
            for packet in 0..3000u32 {
                let rays: [(DVec3, DVec3); LANES] = std::array::from_fn(|l| {
                    // Whole packets of one kind, and packets of all kinds.
                    let kind = if packet % 2 == 0 { packet / 2 } else { packet + l as u32 };
                    ray(&mut rng, s, kind)
                });
                let live: [bool; LANES] = std::array::from_fn(|l| packet % 7 != 0 || l % 3 != 0);
                let (mut o, mut d) = ([[0.0; LANES]; 3], [[0.0; LANES]; 3]);
                for (l, (a, b)) in rays.iter().enumerate() {
                    for k in 0..3 {
                        (o[k][l], d[k][l]) = (a[k], b[k]);
                    }
                }
                let lanes = s.pass_lanes(&o, &d, live, &media);
                for (l, &(a, b)) in rays.iter().enumerate() {
                    let want = if live[l] { s.pass(a, b, &media) } else { None };
                    assert_eq!(
                        bits(lanes[l]),
                        bits(want),
                        "{isa:?}, λ {lambda}, packet {packet}, lane {l}: {a} along {b}"
                    );
                    if isa == Isa::Portable && lambda == WAVELENGTH_D_UM && live[l] {
                        let t = s.trace(a, b, lambda);
                        passed += usize::from(want.is_some());
                        reflected += usize::from(t.events.iter().any(|e| e.kind == EventKind::Reflect));
                        absorbed += usize::from(t.status == RayStatus::Absorbed);
                        missed += usize::from(t.status == RayStatus::Miss);
                    }
                }
            }
        }
    }
    force_isa(None);
    // The rays are of every kind.
    assert!(passed > 1000, "{passed} passed");
    assert!(reflected > 50, "{reflected} reflected (TIR)");
    assert!(absorbed > 1000, "{absorbed} absorbed");
    assert!(missed > 100, "{missed} missed");
}

/// The camera's rays of a packet of pixels (`local_rays`) are its rays
/// one by one (`local_ray`), weights included, across the whole picture
/// (the vignetted corners too) and for packets not full.
#[test]
fn a_packet_of_camera_rays_is_its_rays_one_by_one() {
    let scene = camera_dgauss();
    let cam = lens(&scene);
    let size = (96u32, 64u32);
    let mut rng = Rng(11);
    let (mut some, mut none) = (0, 0);
    for isa in isas() {
        assert!(force_isa(Some(isa)));
        for packet in 0..400 {
            let at = std::array::from_fn(|_| (rng.range(0.0, 96.0), rng.range(0.0, 64.0)));
            let u = std::array::from_fn(|_| (rng.next(), rng.next()));
            let n = 1 + packet % LANES;
            let rays = cam.local_rays(&at, size, &u, n, 1);
            for l in 0..LANES {
                let want = if l < n {
                    cam.local_ray(at[l], size, u[l], 1)
                } else {
                    None
                };
                let key = |r: &Option<lensview::camera::LocalRay>| {
                    r.as_ref().map(|r| (bits(Some((r.origin, r.dir))), r.weight.to_bits()))
                };
                assert_eq!(key(&rays[l]), key(&want), "{isa:?}, packet {packet}, lane {l}");
                some += usize::from(want.is_some());
                none += usize::from(l < n && want.is_none());
            }
        }
    }
    force_isa(None);
    assert!(some > 500 && none > 100, "{some} rays, {none} stopped");
}

/// The renderer's lens-camera bands (eight sensor rays through the lens at
/// once) give each pixel exactly the mean of its samples traced one by one.
#[test]
fn a_lens_camera_picture_is_its_pixels_one_by_one() {
    let s = RenderSettings {
        width: 37,
        height: 23,
        spp: 2,
        seed: 3,
    };
    assert_pixels_one_by_one(&camera_dgauss(), &s, "camera-dgauss");
}

/// `render`'s picture of `scene` is each pixel's `render_pixel` (the
/// scalar kernel, one sample after another), bit for bit, on every ISA.
fn assert_pixels_one_by_one(scene: &Scene, s: &RenderSettings, name: &str) {
    for isa in isas() {
        assert!(force_isa(Some(isa)));
        let img = render(scene, s, None);
        for y in 0..s.height {
            for x in 0..s.width {
                let want = render_pixel(scene, x, y, s);
                let got = img.get(x, y);
                assert!(
                    (0..3).all(|c| got[c].to_bits() == want[c].to_bits()),
                    "{name}, {isa:?}: pixel ({x}, {y}): {got:?} against {want:?}"
                );
            }
        }
    }
    force_isa(None);
}

/// A ray out of a tree as bits.
fn branch_bits(b: &SystemBranch) -> [u64; 11] {
    let v = [b.point, b.dir, b.normal].map(|v| v.to_array().map(f64::to_bits));
    let [p, d, n] = v;
    [
        p[0],
        p[1],
        p[2],
        d[0],
        d[1],
        d[2],
        n[0],
        n[1],
        n[2],
        b.weight.to_bits(),
        u64::from(b.reflections),
    ]
}

/// Every lane of `branches_lanes` is `branches` bit for bit (its rays out in
/// order, and the weight it dropped): the systems of the shipped scenes
/// (singlets of every kind, the achromat, the double Gauss, whether or
/// not the renderer walks them in lanes), rays of every kind mixed in a
/// packet with lanes left out, each lane pruned its own way (nearly exact, the
/// renderer's pruning with the ghosts' roulette, few reflections).
#[test]
fn lane_trees_are_the_scalar_trees() {
    let scenes = [
        "scenes/achromat.toml",
        "scenes/lens-family.toml",
        "benches/systems/double-gauss.toml",
    ];
    let systems: Vec<LensSystem> = scenes
        .iter()
        .flat_map(|f| {
            load(f)
                .objects
                .iter()
                .filter_map(|o| o.system().cloned())
                .collect::<Vec<_>>()
        })
        .collect();
    assert_eq!(systems.len(), 6);
    let prunes = [
        Pruning {
            scale: 1.0,
            min: 1e-6,
            max_reflections: 4,
            roulette: 0.0,
        },
        Pruning {
            scale: 0.9,
            min: LENS_MIN_WEIGHT,
            max_reflections: 6,
            roulette: GHOST_ROULETTE,
        },
        Pruning {
            scale: 0.3,
            min: LENS_MIN_WEIGHT,
            max_reflections: 1,
            roulette: GHOST_ROULETTE,
        },
    ];
    let mut trees = LaneTrees::default();
    let (mut rays_out, mut ghosts, mut dropped) = (0usize, 0usize, 0usize);
    for isa in isas() {
        assert!(force_isa(Some(isa)));
        for (k, s) in systems.iter().enumerate() {
            let mut rng = Rng(13 + k as u64);
            for packet in 0..300u32 {
                let rays: [(DVec3, DVec3); LANES] = std::array::from_fn(|l| {
                    let kind = if packet % 2 == 0 { packet / 2 } else { packet + l as u32 };
                    let (o, d) = ray(&mut rng, s, kind);
                    (o, d.normalize())
                });
                let live: [bool; LANES] = std::array::from_fn(|l| packet % 5 != 0 || l % 3 != 1);
                let prune: [Pruning; LANES] = std::array::from_fn(|l| prunes[(packet as usize + l) % 3]);
                let (mut o, mut d) = ([[0.0; LANES]; 3], [[0.0; LANES]; 3]);
                for (l, (a, b)) in rays.iter().enumerate() {
                    for c in 0..3 {
                        (o[c][l], d[c][l]) = (a[c], b[c]);
                    }
                }
                let lambda = if packet % 3 == 0 { 0.4861 } else { WAVELENGTH_D_UM };
                let lost = s.branches_lanes(&o, &d, live, lambda, &prune, &mut trees);
                for (l, &(a, b)) in rays.iter().enumerate() {
                    let mut want = Vec::new();
                    let want_lost = if live[l] {
                        s.branches(a, b, lambda, &prune[l], &mut |r| want.push(r))
                    } else {
                        0.0
                    };
                    let at = format!("{isa:?}, system {k}, packet {packet}, lane {l}: {a} along {b}");
                    let got: Vec<_> = trees.out[l].iter().map(branch_bits).collect();
                    assert_eq!(got, want.iter().map(branch_bits).collect::<Vec<_>>(), "{at}");
                    assert_eq!(lost[l].to_bits(), want_lost.to_bits(), "{at}");
                    rays_out += want.len();
                    ghosts += want.iter().filter(|r| r.reflections >= 2).count();
                    dropped += usize::from(want_lost > 0.0);
                }
            }
        }
    }
    force_isa(None);
    // The trees are of every kind: many rays out, ghosts, pruned branches.
    assert!(rays_out > 20_000, "{rays_out} rays out");
    assert!(ghosts > 2_000, "{ghosts} ghosts");
    assert!(dropped > 1_000, "{dropped} trees pruned");
}

/// The packet kernel's pictures of scene systems (the achromat and the
/// singlet in lanes, the double Gauss one ray at a time) are their pixels
/// traced one by one by the scalar kernel.
#[test]
fn a_picture_through_scene_systems_is_its_pixels_one_by_one() {
    for file in ["scenes/achromat.toml", "benches/systems/double-gauss.toml"] {
        let s = RenderSettings {
            width: 29,
            height: 21,
            spp: 2,
            seed: 5,
        };
        assert_pixels_one_by_one(&load(file), &s, file);
    }
}
