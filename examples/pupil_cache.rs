//! What the lens camera's pupil search costs the viewer's edits: the time
//! to its first camera ray (the exit pupil's boxes and the exposure) after
//! each of a camera move, a cube's edit, a new f-number and a step back to
//! the first f-number, as `Document` makes them for the window.
//!
//!     cargo build --release --example pupil_cache
//!     target/release/examples/pupil_cache [SCENE]
//!
//! (default `scenes/camera-dgauss.toml`). An edit whose lens, sensor and
//! focus were seen before finds the boxes kept ([`lensview::camera`]); the
//! others search (what every edit cost before they were kept).

use glam::DVec3;
use lensview::edit::Document;
use std::time::Instant;

fn main() {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "scenes/camera-dgauss.toml".into());
    let mut doc = Document::open(std::path::Path::new(&path)).expect("a scene with a lens camera");
    let first_ray = |doc: &Document, what: &str| {
        let lens = doc.built().lens.clone().expect("a lens camera");
        let t = Instant::now();
        let boxes = lens.pupil_boxes().len();
        println!(
            "{what:<32} {:>9.3} ms to the first ray ({boxes} boxes)",
            t.elapsed().as_secs_f64() * 1e3
        );
    };
    first_ray(&doc, "opened");
    let lens = doc.built().lens.clone().expect("a lens camera");
    let (near, far) = lens.depth_of_field(lens.circle_of_confusion());
    println!(
        "f/{:.2}, in focus at {:.2}: depth of field {near:.2} to {far:.2}",
        lens.f_number, lens.focus_distance
    );
    let (p, r) = doc.camera_pose();
    doc.fly_camera(p + DVec3::new(0.3, 0.0, -0.5), r + DVec3::new(0.0, 2.0, 0.0))
        .unwrap();
    first_ray(&doc, "camera moved");
    doc.edit("move a cube", |sf| sf.objects[1].position[0] += 0.25).unwrap();
    first_ray(&doc, "a cube moved");
    doc.set_f_number(Some(5.6)).unwrap();
    first_ray(&doc, "f/5.6 (new)");
    doc.set_focus_distance(Some(8.0)).unwrap();
    first_ray(&doc, "focus 8 (new)");
    doc.undo().unwrap();
    doc.undo().unwrap();
    first_ray(&doc, "undone twice (seen before)");
}
