//! The page's optics overlay (F6) and analysis panel (F7), without the
//! browser: for the lens or lens system the panel selects (the first lens
//! when none is, else the first system, as the desktop's panel shows), the
//! library's overlay figure (`lens_tools::overlay`) seen by the scene's
//! camera, as JSON segments and labels that `www/main.js` strokes on a
//! canvas over the picture; and the library's analysis
//! (`lens_tools::analysis`) as the HTML fragment of SVG figures that
//! `lens_tools::chart` writes. Display only: nothing here changes the
//! scene or the picture.

use crate::panel::Target;
use lensview::edit::Item;
use lensview::lens_tools::analysis::{Settings, lens_figures, system_figures};
use lensview::lens_tools::chart::{escape, figures_html};
use lensview::lens_tools::overlay::{Projected, scene_figure};
use lensview::scene::Scene;
use serde::Serialize;

/// What the overlay and the analysis show: (lens index, system index),
/// the system when one is selected or the scene has no lens.
pub fn subject(scene: &Scene, selected: &str) -> (usize, Option<usize>) {
    let lenses = scene.objects.iter().filter(|o| o.lens().is_some()).count();
    match Target::parse(selected) {
        Some(Target::Item(Item::System(i))) => (0, Some(i)),
        Some(Target::Item(Item::Lens(i))) if i < lenses => (i, None),
        _ if lenses == 0 => (0, Some(0)),
        _ => (0, None),
    }
}

/// One label: its text, its point, where its text goes (left, baseline),
/// its colour, and whether its point gets a marker's disc.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Label {
    pub text: &'static str,
    pub at: [f64; 2],
    pub spot: [f64; 2],
    pub colour: String,
    pub disc: bool,
}

/// The overlay for the canvas, in picture pixels: each segment with its
/// colour and width, and the labels.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Overlay {
    pub segments: Vec<([f64; 4], String, f64)>,
    pub labels: Vec<Label>,
}

/// The labels' font size on the canvas, in picture pixels.
pub const FONT_PX: f64 = 13.0;

/// The overlay of `scene`'s selected lens or system in a `size` picture;
/// empty when the scene has neither.
pub fn overlay(scene: &Scene, selected: &str, size: (u32, u32), object_distance: Option<f64>) -> Overlay {
    let (lens, system) = subject(scene, selected);
    let Some(fig) = scene_figure(scene, lens, system, object_distance) else {
        return Overlay::default();
    };
    let p = Projected::new(&scene.camera, size, &fig);
    let segments = (p.segments.iter())
        .map(|(role, a, b)| ([a[0], a[1], b[0], b[1]], role.css(), role.width()))
        .collect();
    let labels = (p.labels.iter().zip(p.label_spots(1.0, FONT_PX)))
        .map(|(l, spot)| Label {
            text: l.text,
            at: l.at,
            spot,
            colour: l.role.css(),
            disc: l.disc,
        })
        .collect();
    Overlay { segments, labels }
}

/// The analysis of `scene`'s selected lens or system as HTML (`width`
/// pixels wide): its name, then the figures, or the library's refusal.
pub fn analysis(scene: &Scene, selected: &str, settings: &Settings, width: f64) -> String {
    let (lens, system) = subject(scene, selected);
    let figures = match system {
        Some(i) => (scene.objects.iter().filter_map(|o| o.system()).nth(i))
            .map(|s| (format!("lens system {i}"), system_figures(s, settings))),
        None => (scene.objects.iter().filter_map(|o| o.lens()).nth(lens))
            .map(|l| (format!("lens {lens}"), lens_figures(l, settings))),
    };
    match figures {
        None => r#"<p class="header">No lens in this scene.</p>"#.into(),
        Some((name, Ok(f))) => format!(r#"<p class="name">{name}</p>{}"#, figures_html(&f, width)),
        Some((name, Err(e))) => format!(r#"<p class="name">{name}</p><p class="error">{}</p>"#, escape(&e)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::view::View;
    use lensview::lens_tools::overlay::project;

    #[test]
    fn the_overlay_is_the_desktop_projection_of_the_first_lens() {
        // The default scene: its first lens seen by its camera, every
        // label's point the desktop's `project` of the figure's mark.
        let view = View::new(None, (320, 240), 1, 1).unwrap();
        let scene = view.scene();
        let o = overlay(scene, "", (320, 240), None);
        let lens = scene.objects.iter().find_map(|ob| ob.lens()).unwrap();
        let fig = lensview::lens_tools::overlay::figure(lens, scene.camera.up(), None);
        let f_back = fig.marks.iter().find(|m| m.0 == "F'").unwrap().1;
        let at = project(&scene.camera, f_back, (320, 240)).unwrap();
        let label = o.labels.iter().find(|l| l.text == "F'").unwrap();
        assert_eq!(label.at, at);
        assert_eq!(label.colour, "rgba(255,0,255,1.000)");
        assert!(o.segments.len() > 20, "{} segments", o.segments.len());
        // The axis comes toward the camera (cut at its near plane): its
        // first segment ends at the projection of its far end.
        let far = project(&scene.camera, fig.axis[1], (320, 240));
        assert_eq!(Some([o.segments[0].0[2], o.segments[0].0[3]]), far);
        let segments = Projected::new(&scene.camera, (320, 240), &fig).segments;
        let ends: Vec<[f64; 4]> = segments.iter().map(|(_, a, b)| [a[0], a[1], b[0], b[1]]).collect();
        assert_eq!(
            ends,
            o.segments.iter().map(|s| s.0).collect::<Vec<_>>(),
            "the desktop's segments"
        );
        assert_eq!(
            o,
            overlay(scene, "camera", (320, 240), None),
            "the camera selected: the first lens"
        );
    }

    #[test]
    fn a_selected_system_and_a_scene_without_lenses() {
        let view = View::new(Some("achromat"), (160, 120), 1, 1).unwrap();
        let scene = view.scene();
        assert_eq!(subject(scene, ""), (0, Some(0)));
        assert_eq!(subject(scene, "system:1"), (0, Some(1)));
        let o = overlay(scene, "system:0", (160, 120), None);
        let names: Vec<&str> = o.labels.iter().map(|l| l.text).collect();
        assert!(names.contains(&"stop") && names.contains(&"F'"), "{names:?}");
    }

    #[test]
    fn the_analysis_of_the_default_scene_has_its_figures() {
        let view = View::new(None, (160, 120), 1, 1).unwrap();
        let html = analysis(view.scene(), "", &Settings::default(), 600.0);
        assert!(
            html.starts_with(r#"<p class="name">lens 0</p><p class="header">EFL "#),
            "{html:.80}"
        );
        assert_eq!(html.matches("<svg").count(), 4, "sketch, LSA, spot, distortion");
        for title in [
            "Longitudinal spherical aberration",
            "Spot, field 0°",
            "Distortion",
            "RMS",
        ] {
            assert!(html.contains(title), "{title}");
        }
        let off = Settings {
            field_deg: 5.0,
            ..Settings::default()
        };
        let html = analysis(view.scene(), "", &off, 600.0);
        assert!(html.contains("Spot, field 5°") && html.matches("<svg").count() == 5);
        let far = Settings {
            object_distance: Some(-1.0),
            ..Settings::default()
        };
        assert!(analysis(view.scene(), "", &far, 600.0).contains("class=\"error\""));
    }
}
