//! The overlay and the key help, drawn by egui over the picture: crisp
//! text at any size, a semi-transparent box at the picture's top-left
//! corner (right of the panel), wrapped to the picture's width so it is
//! never cut off, and the key help (F2) as a window that stays on screen.
//!
//! What the overlay says is a list of lines (`stats::overlay_lines`); a
//! feature that wants a line on it appends to that list.

use super::keys;
use egui::{Align2, Color32, Context, Frame, Id, Order, Rect, RichText, Vec2};

/// How much the overlay shows (F1 cycles off → compact → full).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OverlayMode {
    Off,
    Compact,
    Full,
}

impl OverlayMode {
    pub fn next(self) -> OverlayMode {
        match self {
            OverlayMode::Off => OverlayMode::Compact,
            OverlayMode::Compact => OverlayMode::Full,
            OverlayMode::Full => OverlayMode::Off,
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            OverlayMode::Off => "off",
            OverlayMode::Compact => "compact",
            OverlayMode::Full => "full",
        }
    }
}

/// Text size of the overlay, points.
const TEXT: f32 = 12.0;
/// Space between the picture's edge and the box, points.
const MARGIN: f32 = 6.0;

/// Draws `lines` in a box at the top-left of `picture` (points). The first
/// line is highlighted. The box is as wide as its longest line, at most
/// the picture's width (longer lines wrap), and is not interactive.
pub fn show(ctx: &Context, picture: Rect, lines: &[String]) {
    if lines.is_empty() || picture.width() < 4.0 * MARGIN || picture.height() < 4.0 * MARGIN {
        return;
    }
    let max_w = picture.width() - 2.0 * MARGIN - 12.0;
    egui::Area::new(Id::new("lensview-overlay"))
        .order(Order::Background)
        .interactable(false)
        // Shown in the first present after F1 (a fade would cost a CPU
        // rasterizer a burst of presents).
        .fade_in(false)
        .fixed_pos(picture.min + Vec2::splat(MARGIN))
        .constrain_to(picture)
        .show(ctx, |ui| {
            Frame::new()
                .fill(Color32::from_black_alpha(150))
                .corner_radius(4.0)
                .inner_margin(6.0)
                .show(ui, |ui| {
                    ui.set_max_width(max_w);
                    ui.spacing_mut().item_spacing.y = 1.0;
                    for (i, line) in lines.iter().enumerate() {
                        let colour = if i == 0 {
                            Color32::from_rgb(255, 225, 120)
                        } else {
                            Color32::from_gray(235)
                        };
                        ui.add(egui::Label::new(RichText::new(line).monospace().size(TEXT).color(colour)).wrap());
                    }
                });
        });
}

/// The key help as a window (F2 or its close button hides it), kept inside
/// the screen and scrolling when the screen is short.
pub fn help_window(ctx: &Context, open: &mut bool) {
    let screen = ctx.content_rect();
    egui::Window::new("Keys")
        .open(open)
        .fade_in(false)
        .collapsible(false)
        .resizable(false)
        .anchor(Align2::RIGHT_TOP, Vec2::new(-MARGIN, MARGIN))
        .constrain_to(screen)
        .max_height((screen.height() - 60.0).max(80.0))
        .show(ctx, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                egui::Grid::new("keys").num_columns(2).striped(true).show(ui, |ui| {
                    for (key, text) in keys::help_rows() {
                        ui.label(RichText::new(key).monospace().strong());
                        ui.label(text);
                        ui.end_row();
                    }
                });
            });
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f1_cycles_off_compact_full() {
        let mut m = OverlayMode::Compact;
        let mut seen = Vec::new();
        for _ in 0..3 {
            m = m.next();
            seen.push(m.label());
        }
        assert_eq!(seen, ["full", "off", "compact"]);
    }
}
