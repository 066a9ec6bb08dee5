//! The lens keys applied to a lens system (`[[systems]]`) selected in the
//! panel: move it (along its axis, sideways, up and down), turn it, and
//! reshape what its kind has — the diameter `d` (a preset's or
//! prescription's `scale`), the front and back radii (`r1`, and `r2` or a
//! doublet's `r3`; `r` of a plano kind) and the index `n`. Values
//! are stepped, not clamped to what the system allows: a result that does
//! not validate is refused by the document, which says why.

use super::{Edit, MIN_DIAMETER, clamp_point, edit_index, fmt3, said, turn_axis};
use crate::scene::file::SystemFile;
use glam::DVec3;

/// Applies a lens key edit to `s`; returns a line saying what changed.
pub fn apply_system(s: &mut SystemFile, edit: Edit) -> String {
    match edit {
        Edit::LensMove(_) | Edit::LensAlongAxis(_) => {
            let step = match edit {
                Edit::LensMove(d) => d,
                Edit::LensAlongAxis(t) => DVec3::from(s.axis).normalize_or(DVec3::Z) * t,
                _ => DVec3::ZERO,
            };
            let (key, at) = match (&mut s.center, &mut s.vertex) {
                (Some(c), _) => ("centre", c),
                (None, Some(v)) => ("vertex", v),
                (None, None) => return "the system has no position".into(),
            };
            let (p, clamped) = clamp_point(DVec3::from(*at) + step);
            *at = p.to_array();
            said(format!("{key} {}", fmt3(*at)), clamped)
        }
        Edit::LensTurn { yaw, pitch } => {
            s.axis = turn_axis(s.axis, yaw, pitch);
            format!("axis {}", fmt3(s.axis))
        }
        Edit::LensDiameter(delta) => diameter(s, delta),
        Edit::LensR1(delta) | Edit::LensR2(delta) => radius(s, matches!(edit, Edit::LensR1(_)), delta),
        Edit::LensIndex(delta) => match &mut s.n {
            Some(n) => edit_index(n, delta).replacen("lens ", "", 1),
            None => format!("kind `{}` has no `n` (edit its surfaces in the panel)", s.kind),
        },
        _ => String::new(),
    }
}

/// `d` changed by `delta` (at least [`MIN_DIAMETER`]), or for a preset or
/// prescription its scale by `(2 + delta) / 2` (as if 2 units across).
fn diameter(s: &mut SystemFile, delta: f64) -> String {
    if let Some(d) = &mut s.d {
        *d = (*d + delta).max(MIN_DIAMETER);
        return format!("d = {:.4}", *d);
    }
    if matches!(s.kind.as_str(), "preset" | "prescription") {
        let scale = s.scale.get_or_insert(1.0);
        *scale *= ((2.0 + delta) / 2.0).max(0.1);
        return format!("scale = {:.6}", *scale);
    }
    format!("kind `{}` has no `d` (edit its semi-apertures in the panel)", s.kind)
}

/// The front (`first`) or back radius changed by `delta` in magnitude,
/// its sign kept: `r1`/`r2` (`r3`, the back, of a doublet), or `r` (either
/// key) of a plano kind.
fn radius(s: &mut SystemFile, first: bool, delta: f64) -> String {
    let grow = |r: &mut f64| *r += if *r < 0.0 { -delta } else { delta };
    let mut changed = Vec::new();
    if let Some(r) = &mut s.r {
        grow(r);
        changed.push(format!("r = {:.4}", *r));
    } else {
        let (k, r) = match (first, s.kind.as_str()) {
            (true, _) => ("r1", &mut s.r1),
            (false, "doublet") => ("r3", &mut s.r3),
            (false, _) => ("r2", &mut s.r2),
        };
        if let Some(r) = r {
            grow(r);
            changed.push(format!("{k} = {:.4}", *r));
        }
    }
    if changed.is_empty() {
        format!("kind `{}` has no radius key (edit it in the panel)", s.kind)
    } else {
        changed.join(", ")
    }
}
