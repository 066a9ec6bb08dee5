//! `render -o X.exr`: linear RGB OpenEXR holding exactly the library's
//! linear radiance (as `f32`, unclamped), and the PNG of the same render is
//! that EXR clamped and sRGB-encoded.

use lensview::color::to_srgb8;
use lensview::render::caustics::{CausticSettings, caustic_map, render_photons};
use lensview::render::{RenderSettings, render};
use lensview::scene::Scene;
use std::process::Command;

/// A floor under a strong point light (radiance well above 1 under it),
/// the lens between it and the camera.
fn scene_text() -> String {
    let cubes = include_str!("../scenes/cubes.toml");
    format!("{cubes}\n[[lights]]\ntype = \"point\"\nposition = [0, 1.2, 6]\ncolor = [1, 0.9, 0.8]\nintensity = 400\n")
}

/// Reads the layout `render/exr.rs` writes (single part, scanline, one
/// line a chunk, uncompressed, channels B, G, R as f32), checking each
/// header field it relies on: width, height and RGB values.
fn decode(bytes: &[u8]) -> (usize, usize, Vec<[f32; 3]>) {
    assert_eq!(bytes[..8], [0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0], "magic and version");
    let i32_at = |at: usize| i32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
    let cstr = |at: &mut usize| {
        let end = *at + bytes[*at..].iter().position(|&b| b == 0).unwrap();
        let s = String::from_utf8(bytes[*at..end].to_vec()).unwrap();
        *at = end + 1;
        s
    };
    let (mut at, mut window, mut channels) = (8, None, Vec::new());
    while bytes[at] != 0 {
        let (name, _) = (cstr(&mut at), cstr(&mut at));
        let size = i32_at(at) as usize;
        at += 4;
        match name.as_str() {
            "compression" => assert_eq!(bytes[at], 0, "uncompressed"),
            "dataWindow" => window = Some([0, 1, 2, 3].map(|i| i32_at(at + 4 * i))),
            "channels" => {
                let mut c = at;
                while bytes[c] != 0 {
                    let n = cstr(&mut c);
                    assert_eq!(i32_at(c), 2, "FLOAT channel {n}");
                    channels.push(n);
                    c += 16;
                }
            }
            _ => {}
        }
        at += size;
    }
    assert_eq!(channels, ["B", "G", "R"]);
    let [x0, y0, x1, y1] = window.expect("a data window");
    let (w, h) = ((x1 - x0 + 1) as usize, (y1 - y0 + 1) as usize);
    let table = at + 1;
    let mut px = vec![[0f32; 3]; w * h];
    for y in 0..h {
        let chunk = u64::from_le_bytes(bytes[table + 8 * y..table + 8 * y + 8].try_into().unwrap()) as usize;
        assert_eq!((i32_at(chunk), i32_at(chunk + 4) as usize), (y as i32, 12 * w));
        let f = |i: usize| f32::from_le_bytes(bytes[chunk + 8 + 4 * i..chunk + 12 + 4 * i].try_into().unwrap());
        for x in 0..w {
            px[y * w + x] = [f(2 * w + x), f(w + x), f(x)];
        }
    }
    (w, h, px)
}

#[test]
fn exr_is_the_linear_radiance_and_png_its_clamped_encoding() {
    let dir = tempfile::tempdir().unwrap();
    let scene_path = dir.path().join("bright.toml");
    std::fs::write(&scene_path, scene_text()).unwrap();
    let run = |out: &str| {
        let st = Command::new(env!("CARGO_BIN_EXE_lensview"))
            .args(["render", scene_path.to_str().unwrap(), "-o", out])
            .args(["--width", "40", "--height", "30", "--spp", "2"])
            .status()
            .unwrap();
        assert!(st.success());
    };
    let (exr, png) = (dir.path().join("a.EXR"), dir.path().join("a.png"));
    run(exr.to_str().unwrap());
    run(png.to_str().unwrap());
    let (_, scene) = Scene::parse("bright.toml", &scene_text()).unwrap();
    let settings = RenderSettings {
        width: 40,
        height: 30,
        spp: 2,
        seed: 0,
    };
    // As the command does: the photon passes for 40×30 at 2 spp, then the
    // render.
    let caustic = CausticSettings {
        seed: 0,
        ..CausticSettings::default()
    };
    let (passes, _) = render_photons(&scene, (40, 30), 2, caustic);
    let map = caustic_map(&scene, passes, caustic);
    let img = render(lensview::integrator::Lit::new(&scene, map.as_ref()), &settings, None);
    let (w, h, px) = decode(&std::fs::read(&exr).unwrap());
    assert_eq!((w, h), (40, 30));
    let mut above_one = 0;
    for (got, want) in px.iter().zip(&img.pixels) {
        assert_eq!(*got, [want.x as f32, want.y as f32, want.z as f32]);
        above_one += usize::from(want.max_element() > 1.0);
    }
    assert!(
        above_one > 10,
        "only {above_one} pixels above 1: the test needs unclamped values"
    );
    // The PNG: the EXR's values clamped and encoded.
    let decoded = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png).unwrap()));
    let mut reader = decoded.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    reader.next_frame(&mut buf).unwrap();
    let from_exr: Vec<u8> = px
        .iter()
        .flat_map(|p| to_srgb8(glam::DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)))
        .collect();
    assert_eq!(buf[..from_exr.len()], from_exr[..]);
}

#[test]
fn an_unknown_extension_is_one_line_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("a.tiff");
    let o = Command::new(env!("CARGO_BIN_EXE_lensview"))
        .args([
            "render",
            "-o",
            out.to_str().unwrap(),
            "--width",
            "8",
            "--height",
            "8",
            "--spp",
            "1",
        ])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8(o.stderr).unwrap();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("a.tiff") && err.contains(".exr"), "{err}");
    assert!(!out.exists());
}
