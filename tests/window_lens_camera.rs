//! The lens camera in the real window under Xvfb (issue #32; needs what
//! tests/window.rs needs): F9 switches the cubes' pinhole to the lens
//! camera and the picture becomes the lens camera's; a flight through it
//! shows traced frames, never a pinhole's warp; PgDn stops it down, and
//! the picture follows the f-number (Ctrl+S writes what was set).

use lensview::edit::Document;
use lensview::render::{Image, RenderSettings, render};
use lensview::scene::Scene;
use std::path::PathBuf;

mod window_support;
use window_support::*;

const SW: u32 = 240;
const SH: u32 = 160;

/// Mean absolute difference (8-bit levels) of the two pictures averaged
/// over 4 × 4 blocks: the sampling noise of a few samples a pixel mostly
/// averages out, the blur of a focus does not.
fn block_diff(a: &Image, b: &Image) -> f64 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let (a8, b8) = (a.to_srgb8(), b.to_srgb8());
    let (bw, bh) = (a.width as usize / 4, a.height as usize / 4);
    let mut sum = 0.0;
    for by in 0..bh {
        for bx in 0..bw {
            for c in 0..3 {
                let mut d = 0.0;
                for y in by * 4..by * 4 + 4 {
                    for x in bx * 4..bx * 4 + 4 {
                        let i = (y * a.width as usize + x) * 3 + c;
                        d += a8[i] as f64 - b8[i] as f64;
                    }
                }
                sum += (d / 16.0).abs();
            }
        }
    }
    sum / (bw * bh * 3) as f64
}

fn headless(scene: &Scene) -> Image {
    let s = RenderSettings {
        width: SW,
        height: SH,
        spp: 32,
        seed: 0,
    };
    render(scene, &s, None)
}

#[test]
fn f9_switches_to_the_lens_camera_and_pgdn_stops_it_down() {
    let _one = one_at_a_time();
    let x = Xvfb::start();
    let (dir, _) = test_dir("lens-camera");
    let scene = dir.join("cubes.toml");
    std::fs::copy(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/cubes.toml"),
        &scene,
    )
    .unwrap();
    // What the keys should make, headless: the document's own edits.
    let mut doc = Document::open(&scene).unwrap();
    let pinhole = headless(doc.built());
    doc.toggle_lens_camera().unwrap();
    let wide = headless(doc.built());
    for _ in 0..3 {
        doc.step_f_number(1.0).unwrap().unwrap();
    }
    let stopped = headless(doc.built());
    let n_want = doc.scene().camera.f_number.unwrap();
    // The two f-numbers differ by more than noise (the far row sharpens).
    let apart = block_diff(&wide, &stopped);
    assert!(apart > 1.0, "f/2.8 and f/{n_want} differ by {apart:.2} only");

    let (w, h) = (SW.to_string(), SH.to_string());
    let args = [
        "--no-panel",
        "--width",
        &w,
        "--height",
        &h,
        "--max-spp",
        "16",
        "--exit-after",
        "600",
    ];
    let s = Session::launch(&x, &dir, &scene, &args, dir.join("frames.jsonl"));
    let g1 = s.wait_frame(0, 16, "start");
    s.overlay_to("full");
    s.overlay_to("off");
    let shot = s.screenshot("pinhole.png");
    let d = block_diff(&shot, &pinhole);
    assert!(d < 3.0, "the pinhole picture differs from headless by {d:.2}");

    // F9: the lens camera's picture (its narrower field, its blur).
    s.key("F9");
    let g2 = s.wait_frame(g1, 16, "F9");
    let lens = s.screenshot("lens.png");
    let (to_lens, to_pinhole) = (block_diff(&lens, &wide), block_diff(&lens, &pinhole));
    assert!(
        to_lens < 3.0 && to_pinhole > 3.0 * to_lens,
        "after F9 the window is {to_lens:.2} from the lens camera, {to_pinhole:.2} from the pinhole"
    );

    // A flight through the lens camera: every frame traced, none warped.
    let n = s.frames().len();
    s.hold("w", 600);
    let g3 = s.wait_frame(g2, 16, "W");
    let warped: Vec<_> = s.frames()[n..]
        .iter()
        .filter(|f| !f["reprojection"].is_null())
        .cloned()
        .collect();
    assert!(warped.is_empty(), "lens-camera frames were reprojected: {warped:?}");
    // Back to the pose of the headless pictures.
    s.key("r");
    let mut g = s.wait_frame(g3, 16, "R");

    // PgDn three times: f/2.8 → f/7.9; the picture is the stopped-down one.
    for _ in 0..3 {
        s.key("Next");
        g = s.wait_frame(g, 16, "PgDn");
    }
    let down = s.screenshot("stopped.png");
    let (to_down, to_wide) = (block_diff(&down, &stopped), block_diff(&down, &wide));
    assert!(
        to_down < to_wide,
        "after PgDn the window is {to_down:.2} from f/{n_want:.2}, {to_wide:.2} from f/2.8"
    );
    s.chord("ctrl+s");
    let saved = || Scene::load(&scene).ok().and_then(|(sf, _)| sf.camera.f_number);
    assert!(
        wait_until(std::time::Duration::from_secs(30), || saved() == Some(n_want)),
        "the saved f-number is {:?}, not {n_want}",
        saved()
    );
}
