//! The lens camera (issue #32), checked against computations of its own.

use lensview::scene::Scene;

fn scene(text: &str) -> Scene {
    Scene::parse("test", text).unwrap().1
}

#[test]
fn debug_boxes() {
    for f in [2.8, 64.0] {
        let t = include_str!("../scenes/camera-dgauss.toml").replace("f_number = 2.8", &format!("f_number = {f}"));
        let s = scene(&t);
        let l = s.lens.as_ref().unwrap();
        eprintln!(
            "f/{f}: share {} fov {} sd {}",
            l.pass_share(300, 200),
            l.fov_y_deg(),
            l.sensor_distance
        );
        for (i, b) in l.pupil_boxes().iter().enumerate().step_by(8) {
            eprintln!("{i}: {:?} area {}", b, b.area());
        }
    }
}

#[test]
fn debug_flat() {
    use lensview::render::{RenderSettings, render};
    let t = "[render]\nbackground = [1, 1, 1]\n[camera]\nposition = [0, 0, 0]\nlens = { preset = \"double-gauss-50mm\", scale = 0.01 }\nf_number = 2.8\n";
    let s = scene(t);
    for spp in [1, 16, 64] {
        let img = render(
            &s,
            &RenderSettings {
                width: 12,
                height: 8,
                spp,
                seed: 0,
            },
            None,
        );
        for y in 0..8 {
            let row: Vec<String> = (0..12).map(|x| format!("{:.3}", img.get(x, y).x)).collect();
            eprintln!("{spp}: {}", row.join(" "));
        }
    }
}

#[test]
fn debug_map() {
    let t = "[render]\nbackground = [1, 1, 1]\n[camera]\nposition = [0, 0, 0]\nlens = { preset = \"double-gauss-50mm\", scale = 0.01 }\nf_number = 2.8\n";
    let s = scene(t);
    let l = s.lens.as_ref().unwrap();
    for at in [(6.0, 4.0), (1.0, 1.0)] {
        for j in 0..24 {
            let row: String = (0..48)
                .map(|i| {
                    let u = ((i as f64 + 0.5) / 48.0, (j as f64 + 0.5) / 24.0);
                    if l.local_ray(at, (12, 8), u, 1).is_some() {
                        '#'
                    } else {
                        '.'
                    }
                })
                .collect();
            eprintln!("{row}");
        }
    }
}
