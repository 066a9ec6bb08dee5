//! Figures about the window's own work: present times, the smoothed frame
//! interval, the frame log (`--frame-log`, one JSON line per presented
//! frame, with every stage finished since the last line), and the lines of the overlay (timings, camera, light, lens,
//! message).

use super::overlay::OverlayMode;
use super::refine::StageTime;
use lensview::edit::Document;
use lensview::render::worker::Frame;
use std::io::Write;
use std::time::Instant;

pub struct Stats {
    /// When the window opened (the log's `t`; `--exit-after` counts from it).
    pub started: Instant,
    /// Smoothed time between presented frames, ms (0 before the second).
    frame_ms: f64,
    last_present: Option<Instant>,
    present_ms: f64,
    log: Option<std::fs::File>,
}

/// Where a presented frame lies in the window and why it was drawn.
pub struct Presented<'a> {
    pub frame: Option<&'a Frame>,
    /// First framebuffer column of the picture (right of the panel).
    pub x0: u32,
    /// When the input behind the frame's generation happened.
    pub input_time: Instant,
    /// The stages the render thread finished since the last line, drawn or
    /// not (the log's `stages`: throughput counts every one).
    pub stages: &'a [StageTime],
    /// The overlay's form on screen (`OverlayMode::label`).
    pub overlay: &'static str,
}

impl Stats {
    pub fn new(log: Option<std::fs::File>) -> Self {
        Stats {
            started: Instant::now(),
            frame_ms: 0.0,
            last_present: None,
            present_ms: 0.0,
            log,
        }
    }

    /// A frame was presented, its drawing begun at `t0`: updates the
    /// timings and writes the log line.
    pub fn presented(&mut self, t0: Instant, p: Presented) {
        let now = Instant::now();
        self.present_ms = (now - t0).as_secs_f64() * 1e3;
        if let Some(prev) = self.last_present {
            let dt = (now - prev).as_secs_f64() * 1e3;
            self.frame_ms = if self.frame_ms == 0.0 {
                dt
            } else {
                0.9 * self.frame_ms + 0.1 * dt
            };
        }
        self.last_present = Some(now);
        if let (Some(log), Some(f)) = (&mut self.log, p.frame) {
            let line = serde_json::json!({
                "generation": f.generation,
                "level": f.stage.label(),
                "spp": f.spp,
                "width": f.width,
                "height": f.height,
                "x0": p.x0,
                "overlay": p.overlay,
                "ms_since_input": (now - p.input_time).as_secs_f64() * 1e3,
                "render_ms": f.render_ms,
                "queued_ms": f.queued_ms,
                "sent_ms_since_input": f.since_input_ms,
                "present_ms": self.present_ms,
                "photons": f.caustics.photons,
                "photon_ms": f.caustics.photon_ms,
                "gather_ms": f.caustics.gather_ms,
                "camera": [f.camera.0.to_array(), f.camera.1.to_array()],
                "reprojection": f.reprojection.map(|r| serde_json::json!({
                    "first_hits_ms": r.first_hits_s * 1e3,
                    "warp_ms": r.warp_s * 1e3,
                    "splat_ms": r.splat_s * 1e3,
                    "fill_ms": r.fill_s * 1e3,
                    "holes": r.holes,
                    "level": r.level,
                })),
                "t": (now - self.started).as_secs_f64(),
                "stages": p.stages.iter().map(|s| serde_json::json!({
                    "generation": s.generation,
                    "level": s.level,
                    "render_ms": s.render_ms,
                })).collect::<Vec<_>>(),
            });
            let _ = writeln!(log, "{line}");
        }
    }

    /// The timing lines of the overlay: the frame's stage and speed, then
    /// the window's frame rate and present time.
    pub fn timing_lines(&self, frame: Option<&Frame>, paused: bool) -> Vec<String> {
        let Some(f) = frame else {
            return vec!["rendering…".into()];
        };
        let fps = if self.frame_ms > 0.0 {
            1000.0 / self.frame_ms
        } else {
            0.0
        };
        let mut lines = vec![
            format!(
                "{} in {:.0} ms, {:.2} M rays/s",
                stage_text(f, paused),
                f.render_ms,
                f.samples_per_s / 1e6,
            ),
            format!(
                "frame {:.1} ms ({:.0} fps), present {:.1} ms",
                self.frame_ms, fps, self.present_ms
            ),
        ];
        if f.caustics.passes > 0 {
            lines.push(caustics_text(f));
        }
        lines
    }
}

/// `"caustics: 4096 photons, 2 passes; photons 1.5 ms, gather 3.0 ms"`:
/// the map so far, and what this frame's caustics cost of its time.
pub fn caustics_text(f: &Frame) -> String {
    format!(
        "caustics: {} photons, {} passes; photons {:.1} ms, gather {:.1} ms",
        f.caustics.photons, f.caustics.passes, f.caustics.photon_ms, f.caustics.gather_ms
    )
}

/// `"64 spp (done) (paused)"`: the frame's stage and state.
pub fn stage_text(f: &Frame, paused: bool) -> String {
    // A reprojection says where its time went: the warp, and the pixels
    // it traced (and at which block size).
    let label = match f.reprojection {
        Some(r) => format!(
            "{} (warp {:.0} ms, {:.0}% traced at {}×{})",
            f.stage.label(),
            (r.first_hits_s + r.warp_s) * 1e3,
            100.0 * r.holes as f64 / (f.width as f64 * f.height as f64).max(1.0),
            r.level,
            r.level
        ),
        None => f.stage.label(),
    };
    format!(
        "{}{}{}",
        label,
        if f.last { " (done)" } else { "" },
        if paused { " (paused)" } else { "" }
    )
}

/// The scene lines of the overlay: camera and flight speed, the first
/// light, the first lens with its paraxial data.
pub fn scene_lines(doc: &Document, speed: f64) -> Vec<String> {
    let mut v = Vec::new();
    let scene = doc.built();
    let (p, r) = (scene.camera.position, scene.camera.rotation_deg);
    v.push(format!(
        "camera ({:.2}, {:.2}, {:.2})  speed {:.1}",
        p.x, p.y, p.z, speed
    ));
    v.push(format!(
        "  rot x {:.1} y {:.1} z {:.1}  fov {:.0}",
        r.x, r.y, r.z, scene.camera.fov_y_deg
    ));
    if let Some(l) = doc.scene().lights.first() {
        let p = l.position.or(l.direction).unwrap_or_default();
        v.push(format!(
            "light ({:.2}, {:.2}, {:.2})  intensity {:.1}",
            p[0], p[1], p[2], l.intensity
        ));
        v.push(format!(
            "  colour ({:.2}, {:.2}, {:.2})",
            l.color[0], l.color[1], l.color[2]
        ));
    }
    if let Some(lens) = scene.objects.iter().find_map(|o| o.lens()) {
        let n = lens.index.nominal();
        let px = lens.paraxial(n);
        v.push(format!(
            "lens d {:.3}  r1 {:.3}  r2 {:.3}  n {:.4}",
            lens.d, lens.r1, lens.r2, n
        ));
        v.push(format!("  EFL {:.4}  BFD {:.4}", px.efl, px.bfd));
    }
    v
}

/// The lens camera's focus readout, when the picture is its: the f-number,
/// the distance in focus and the depth of field (near and far, for a
/// circle of confusion of the sensor's diagonal / 1500).
pub fn focus_line(doc: &Document) -> Option<String> {
    let lens = doc.built().lens.as_deref()?;
    let d = |x: f64| if x.is_finite() { format!("{x:.2}") } else { "inf".into() };
    let (near, far) = lens.depth_of_field(lens.circle_of_confusion());
    Some(format!(
        "lens camera f/{:.2}  focus {}  DoF {} - {}",
        lens.f_number,
        d(lens.focus_distance),
        d(near),
        d(far)
    ))
}

/// The lines of the overlay in `mode`: compact, the frame's stage and
/// speed, the camera and the message; full, the title, both timing lines,
/// camera, light and lens, and the message. A feature with something to
/// show appends its lines to these.
pub fn overlay_lines(
    mode: OverlayMode,
    title: String,
    timing: Vec<String>,
    doc: &Document,
    speed: f64,
    message: &str,
) -> Vec<String> {
    let mut v = Vec::new();
    match mode {
        OverlayMode::Off => return v,
        OverlayMode::Compact => {
            v.extend(timing.into_iter().take(1));
            v.extend(scene_lines(doc, speed).into_iter().take(1));
            v.extend(focus_line(doc));
        }
        OverlayMode::Full => {
            v.push(title);
            v.extend(timing);
            v.extend(scene_lines(doc, speed));
            v.extend(focus_line(doc));
        }
    }
    v.push(format!("> {message}"));
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use lensview::render::caustics::CausticStats;

    #[test]
    fn the_overlay_shows_camera_light_lens_and_message_full_or_compact() {
        let doc = Document::preset("cubes").unwrap();
        let stats = Stats::new(None);
        let timing = stats.timing_lines(None, false);
        assert_eq!(timing, ["rendering…"]);
        let lines = overlay_lines(OverlayMode::Full, "t".into(), timing.clone(), &doc, 3.0, "hello");
        assert_eq!(lines[0], "t");
        assert_eq!(lines[2], "camera (0.00, 6.00, 10.00)  speed 3.0");
        assert_eq!(lines[4], "light (5.00, 10.00, 6.00)  intensity 500.0");
        assert!(
            lines[6].starts_with("lens d 2.000  r1 5.000  r2 5.000  n 1.5000"),
            "{lines:?}"
        );
        assert_eq!(lines.last().unwrap(), "> hello");
        let compact = overlay_lines(OverlayMode::Compact, "t".into(), timing.clone(), &doc, 3.0, "hello");
        assert_eq!(
            compact,
            ["rendering…", "camera (0.00, 6.00, 10.00)  speed 3.0", "> hello"]
        );
        assert!(overlay_lines(OverlayMode::Off, "t".into(), timing, &doc, 3.0, "hello").is_empty());
    }

    /// With the lens camera, both modes read its focus and depth of field
    /// (the library's figures); switched to the pinhole, no such line.
    #[test]
    fn the_overlay_reads_the_lens_cameras_focus() {
        let mut doc = Document::preset("lens camera").unwrap();
        let lens = doc.built().lens.clone().unwrap();
        let (near, far) = lens.depth_of_field(lens.circle_of_confusion());
        let want = format!("lens camera f/2.80  focus 11.40  DoF {near:.2} - {far:.2}");
        assert!(near < 11.4 && far > 11.4 && far.is_finite());
        for mode in [OverlayMode::Compact, OverlayMode::Full] {
            let lines = overlay_lines(mode, "t".into(), vec![], &doc, 3.0, "m");
            assert!(lines.contains(&want), "{lines:?}");
        }
        doc.toggle_lens_camera().unwrap();
        let lines = overlay_lines(OverlayMode::Full, "t".into(), vec![], &doc, 3.0, "m");
        assert!(!lines.iter().any(|l| l.starts_with("lens camera")), "{lines:?}");
    }

    /// Every field of a frame-log line, from a frame whose figures are known.
    #[test]
    fn the_frame_log_writes_every_field_of_every_presented_frame() {
        use lensview::render::progressive::Stage;
        use std::time::Duration;
        let path = std::env::temp_dir().join(format!("lensview-frames-{}.jsonl", std::process::id()));
        let mut stats = Stats::new(Some(std::fs::File::create(&path).unwrap()));
        let frame = |generation, spp| Frame {
            generation,
            stage: Stage::Samples(spp),
            spp,
            width: 320,
            height: 200,
            rgba: Vec::new(),
            render_ms: 12.5,
            queued_ms: 1.25,
            since_input_ms: 20.0,
            samples_per_s: 1e6,
            last: false,
            caustics: CausticStats {
                passes: 2,
                photons: 4096,
                photon_ms: 1.5,
                gather_ms: 3.0,
            },
            camera: (glam::DVec3::new(1.0, 2.0, 3.0), glam::DVec3::new(0.0, 90.0, 0.0)),
            reprojection: None,
        };
        let input_time = Instant::now() - Duration::from_millis(80);
        let t0 = Instant::now();
        std::thread::sleep(Duration::from_millis(30));
        let f = frame(7, 4);
        let stage = |level: &str, render_ms| StageTime {
            generation: 7,
            level: level.into(),
            render_ms,
        };
        let stages = [stage("1 spp", 40.0), stage("2 spp", 30.0), stage("4 spp", 12.5)];
        stats.presented(
            t0,
            Presented {
                frame: Some(&f),
                x0: 360,
                input_time,
                stages: &stages,
                overlay: "compact",
            },
        );
        // A redraw with no frame writes no line; a second frame does.
        stats.presented(
            Instant::now(),
            Presented {
                frame: None,
                x0: 0,
                input_time,
                stages: &[],
                overlay: "off",
            },
        );
        let g = frame(8, 0);
        let g = Frame {
            stage: Stage::Blocks(4),
            ..g
        };
        stats.presented(
            Instant::now(),
            Presented {
                frame: Some(&g),
                x0: 0,
                input_time,
                stages: &[],
                overlay: "off",
            },
        );
        let text = std::fs::read_to_string(&path).unwrap();
        let _ = std::fs::remove_file(&path);
        let lines: Vec<serde_json::Value> = text.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
        assert_eq!(lines.len(), 2, "{text}");
        let l = &lines[0];
        let keys: Vec<&str> = l.as_object().unwrap().keys().map(|k| k.as_str()).collect();
        assert_eq!(keys.len(), 19, "{keys:?}");
        assert_eq!(l["camera"], serde_json::json!([[1.0, 2.0, 3.0], [0.0, 90.0, 0.0]]));
        assert_eq!(
            (l["overlay"].as_str(), lines[1]["overlay"].as_str()),
            (Some("compact"), Some("off"))
        );
        let st = l["stages"].as_array().unwrap();
        let got: Vec<_> = st
            .iter()
            .map(|x| (x["level"].as_str().unwrap(), x["render_ms"].as_f64().unwrap()))
            .collect();
        assert_eq!(got, [("1 spp", 40.0), ("2 spp", 30.0), ("4 spp", 12.5)]);
        assert!(st.iter().all(|x| x["generation"] == 7));
        assert!(lines[1]["stages"].as_array().unwrap().is_empty());
        assert_eq!(l["photons"], 4096);
        assert_eq!(l["gather_ms"], 3.0);
        assert_eq!(
            caustics_text(&f),
            "caustics: 4096 photons, 2 passes; photons 1.5 ms, gather 3.0 ms"
        );
        assert_eq!(l["generation"], 7);
        assert_eq!(l["level"], "4 spp");
        assert_eq!(l["spp"], 4);
        assert_eq!(
            (l["width"].as_u64(), l["height"].as_u64(), l["x0"].as_u64()),
            (Some(320), Some(200), Some(360))
        );
        assert_eq!(l["render_ms"], 12.5);
        assert_eq!(l["queued_ms"], 1.25);
        assert_eq!(l["sent_ms_since_input"], 20.0);
        let num = |l: &serde_json::Value, k: &str| l[k].as_f64().unwrap();
        // The input was 80 ms before t0, and presenting took the 30 ms slept.
        assert!(
            num(l, "ms_since_input") >= 110.0 && num(l, "ms_since_input") < 10_000.0,
            "{l}"
        );
        assert!(num(l, "present_ms") >= 30.0 && num(l, "present_ms") < 10_000.0, "{l}");
        assert!(num(l, "t") >= 0.03 && num(l, "t") < num(&lines[1], "t"), "{text}");
        assert_eq!(
            (lines[1]["generation"].as_u64(), lines[1]["level"].as_str()),
            (Some(8), Some("4×4 blocks"))
        );
        assert!(num(&lines[1], "present_ms") < num(l, "present_ms"), "{text}");
    }
}
