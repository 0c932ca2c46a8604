//! Text for the PNG pictures: `DejaVu Sans` (Bitstream Vera licence, see `fonts/LICENSE-DejaVu.txt`)
//! embedded in the binary and rasterised with `ab_glyph`, antialiased, mixed case. Sizes are
//! CSS-like font sizes in pixels (pixels per em), the same number the SVG output uses.

use std::sync::OnceLock;

use ab_glyph::{Font, FontRef, PxScale, ScaleFont};
use tiny_skia::Pixmap;

static FONT_BYTES: &[u8] = include_bytes!("../fonts/DejaVuSans.ttf");

fn font() -> &'static FontRef<'static> {
    static FONT: OnceLock<FontRef<'static>> = OnceLock::new();
    FONT.get_or_init(|| {
        FontRef::try_from_slice(FONT_BYTES).expect("the embedded DejaVuSans.ttf is a valid font")
    })
}

/// The `ab_glyph` scale of a font size given in pixels per em.
fn scale(px: f32) -> PxScale {
    let f = font();
    let upem = f.units_per_em().unwrap_or(2048.0);
    PxScale::from(px * f.height_unscaled() / upem)
}

/// Distance from the top of a line to its baseline at font size `px`.
pub fn ascent(px: f32) -> f32 {
    font().as_scaled(scale(px)).ascent()
}

/// Recommended distance between baselines at font size `px`.
pub fn line_height(px: f32) -> f32 {
    (px * 1.25).ceil()
}

/// Advance width of `text` at font size `px`, in pixels.
pub fn text_width(text: &str, px: f32) -> f32 {
    let sf = font().as_scaled(scale(px));
    let mut w = 0.0;
    let mut prev = None;
    for ch in text.chars() {
        let id = sf.glyph_id(ch);
        if let Some(p) = prev {
            w += sf.kern(p, id);
        }
        w += sf.h_advance(id);
        prev = Some(id);
    }
    w
}

/// Draws `text` with the top of its line box at `(x, y)` at font size `px`, blending
/// antialiased coverage onto the (premultiplied) pixmap; returns the x just after the text.
pub fn draw_text(pm: &mut Pixmap, x: f32, y: f32, px: f32, text: &str, rgb: [u8; 3]) -> f32 {
    let f = font();
    let sf = f.as_scaled(scale(px));
    let baseline = (y + sf.ascent()).round();
    let (w, h) = (i64::from(pm.width()), i64::from(pm.height()));
    let data = pm.data_mut();
    let mut cx = x;
    let mut prev = None;
    for ch in text.chars() {
        let id = sf.glyph_id(ch);
        if let Some(p) = prev {
            cx += sf.kern(p, id);
        }
        let glyph = id.with_scale_and_position(sf.scale(), ab_glyph::point(cx, baseline));
        cx += sf.h_advance(id);
        prev = Some(id);
        let Some(outline) = f.outline_glyph(glyph) else {
            continue;
        };
        let b = outline.px_bounds();
        let (ox, oy) = (b.min.x as i64, b.min.y as i64);
        outline.draw(|gx, gy, c| {
            let px_x = ox + i64::from(gx);
            let px_y = oy + i64::from(gy);
            if px_x < 0 || px_y < 0 || px_x >= w || px_y >= h || c <= 0.0 {
                return;
            }
            let a = c.min(1.0);
            let o = ((px_y * w + px_x) * 4) as usize;
            for k in 0..3 {
                let d = f32::from(data[o + k]);
                data[o + k] = (f32::from(rgb[k]) * a + d * (1.0 - a)).round() as u8;
            }
            let d = f32::from(data[o + 3]);
            data[o + 3] = (255.0 * a + d * (1.0 - a)).round() as u8;
        });
    }
    cx
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mixed_case_text_is_drawn_antialiased_and_measured() {
        let mut pm = Pixmap::new(200, 40).unwrap();
        pm.fill(tiny_skia::Color::WHITE);
        let end = draw_text(&mut pm, 4.0, 4.0, 16.0, "Ba-star R=0.15", [0, 0, 0]);
        assert!((end - 4.0 - text_width("Ba-star R=0.15", 16.0)).abs() < 1e-3);
        // Lower case is narrower than upper case (a real proportional font).
        assert!(text_width("abc", 16.0) < text_width("ABC", 16.0));
        let px = pm.data();
        let grey = px.chunks(4).filter(|p| p[0] > 20 && p[0] < 235).count();
        let dark = px.chunks(4).filter(|p| p[0] <= 20).count();
        assert!(dark > 40, "glyph cores are drawn ({dark})");
        assert!(grey > 40, "edges are antialiased ({grey})");
    }
}
