use super::*;
use crate::optics::Index;

#[test]
fn projection_inverts_the_camera_ray() {
    let cam = Camera::new(DVec3::new(1.0, 6.0, 10.0), DVec3::new(-28.8, 12.0, 3.0), 45.0);
    for (x, y) in [(10.5, 20.5), (319.5, 239.5), (600.25, 7.75)] {
        let r = cam.ray(x, y, 640, 480);
        let p = project(&cam, r.origin + r.dir * 7.0, (640, 480)).unwrap();
        assert!((p[0] - x).abs() < 1e-9 && (p[1] - y).abs() < 1e-9, "{p:?} vs {x}, {y}");
    }
    assert!(project(&cam, cam.position - cam.forward(), (640, 480)).is_none());
}

fn tilted_lens() -> Lens {
    Lens::new(
        DVec3::new(0.0, 4.3, 6.9),
        DVec3::new(0.0, 0.48, 0.876),
        2.0,
        5.0,
        5.0,
        Index::Constant(1.5),
    )
    .unwrap()
}

#[test]
fn fan_from_infinity_meets_near_the_back_focal_point() {
    let fig = figure(&tilted_lens(), DVec3::Y, None);
    let f_back = fig.marks.iter().find(|m| m.0 == "F'").unwrap().1;
    // The innermost rays (h = ±0.3) cross the axis within the LSA of F′.
    for r in [&fig.rays[2], &fig.rays[4]] {
        let (x, u) = (r[2], (r[3] - r[2]).normalize());
        let closest = x + u * (f_back - x).dot(u);
        assert!((closest - f_back).length() < 0.05, "{closest} vs {f_back}");
    }
    assert_eq!(fig.rays.len(), 7);
    assert_eq!(fig.rings.len(), 2);
}

#[test]
fn a_system_fan_from_infinity_meets_near_its_back_focal_point() {
    // The double Gauss at 1/20 scale, tilted: its inner rays cross the
    // axis within its LSA of F′, and the stop, pupils and principal
    // planes are drawn.
    let text = crate::prescription::preset("double-gauss-50mm").unwrap();
    let rows = crate::prescription::parse("dg", text).unwrap();
    let surfaces = crate::geometry::SurfaceSpec::from_rows(&rows, 0.05);
    let sys = LensSystem::new(DVec3::new(0.5, 1.0, 3.0), DVec3::new(0.0, 0.3, 1.0), surfaces).unwrap();
    let fig = system_figure(&sys, DVec3::Y, None);
    let f_back = fig.marks.iter().find(|m| m.0 == "F'").unwrap().1;
    for r in [&fig.rays[2], &fig.rays[4]] {
        let n = r.len();
        let (x, u) = (r[n - 2], (r[n - 1] - r[n - 2]).normalize());
        let closest = x + u * (f_back - x).dot(u);
        assert!((closest - f_back).length() < 0.02, "{closest} vs {f_back}");
    }
    let names: Vec<&str> = fig.rings.iter().map(|r| r.0).collect();
    assert_eq!(names, ["stop", "EP", "XP", "H", "H'"]);
}

#[test]
fn the_projected_figure_is_the_figure_through_project() {
    // Looking at the lens from before it: every segment's ends are
    // projected points of the figure, the marks keep their order, and a
    // camera looking away sees nothing.
    let lens = tilted_lens();
    let cam = Camera::new(DVec3::new(1.0, 4.3, 30.0), DVec3::ZERO, 50.0);
    let fig = figure(&lens, cam.up(), None);
    let p = Projected::new(&cam, (320, 240), &fig);
    let axis: Vec<[f64; 2]> = fig
        .axis
        .iter()
        .map(|&q| project(&cam, q, (320, 240)).unwrap())
        .collect();
    assert_eq!(p.segments[0], (Role::Axis, axis[0], axis[1]));
    let marks: Vec<&str> = p.labels.iter().filter(|l| l.disc).map(|l| l.text).collect();
    assert_eq!(marks, ["V1", "V2", "F", "F'"]);
    let f_back = fig.marks[3].1;
    assert_eq!(p.labels.last().unwrap().at, project(&cam, f_back, (320, 240)).unwrap());
    assert_eq!(p.label_spots(1.0, 15.0).len(), p.labels.len());
    let away = Camera::new(DVec3::new(1.0, 4.3, 30.0), DVec3::new(0.0, 180.0, 0.0), 50.0);
    assert_eq!(Projected::new(&away, (320, 240), &fig), Projected::default());
}

#[test]
fn css_colours_undo_the_premultiplied_alpha() {
    assert_eq!(Role::BackFocus.css(), "rgba(255,0,255,1.000)");
    assert_eq!(Role::Axis.css(), "rgba(225,225,225,0.667)");
}
