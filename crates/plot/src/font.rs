//! The PNG backend's text: DejaVu Sans, bundled as a subset (printable
//! ASCII, Latin-1, Greek and a few symbols; `fonts/LICENSE-DejaVu.txt`,
//! made by `scripts/subset-font.sh`), its outlines rasterised with
//! anti-aliasing by ab_glyph. The SVG backend names the same family first,
//! so a browser that has it draws the same letters.

use ab_glyph::{point, Font, FontRef, Glyph, PxScale, ScaleFont};
use std::sync::OnceLock;

static BYTES: &[u8] = include_bytes!("../fonts/DejaVuSans-mms.ttf");

/// The font family the SVG backend asks for, in order of preference.
pub(crate) const FAMILY: &str = "DejaVu Sans, Verdana, Arial, sans-serif";

fn face() -> &'static FontRef<'static> {
    static FACE: OnceLock<FontRef<'static>> = OnceLock::new();
    // The bytes are part of the crate; `the_bundled_font_parses` tests them.
    FACE.get_or_init(|| FontRef::try_from_slice(BYTES).expect("the bundled font parses"))
}

/// The glyphs of `text` at an em of `size` pixels (a CSS `font-size`),
/// laid out along the baseline from `x = 0`, and their total advance.
/// A character the font lacks is drawn as `?`.
fn layout(text: &str, size: f32) -> (Vec<Glyph>, f32) {
    let font = face();
    let em = font.units_per_em().unwrap_or(2048.0);
    let scale = PxScale::from(size * font.height_unscaled() / em);
    let scaled = font.as_scaled(scale);
    let (mut x, mut prev, mut glyphs) = (0.0, None, Vec::new());
    for c in text.chars() {
        let mut id = font.glyph_id(c);
        if id.0 == 0 {
            id = font.glyph_id('?');
        }
        if let Some(p) = prev {
            x += scaled.kern(p, id);
        }
        glyphs.push(id.with_scale_and_position(scale, point(x, 0.0)));
        x += scaled.h_advance(id);
        prev = Some(id);
    }
    (glyphs, x)
}

/// The advance width of `text` at an em of `size` pixels.
pub(crate) fn width(text: &str, size: f32) -> f32 {
    layout(text, size).1
}

/// Calls `ink(dx, dy, coverage)` for every pixel that `text` (at an em of
/// `size` pixels, starting `start` pixels along the baseline, which may
/// be fractional) covers, in whole-pixel offsets from the origin: `dx`
/// along the baseline, `dy` down from it.
pub(crate) fn rasterise(text: &str, size: f32, start: f32, mut ink: impl FnMut(i64, i64, f32)) {
    let (glyphs, _) = layout(text, size);
    for mut g in glyphs {
        g.position.x += start;
        let Some(outline) = face().outline_glyph(g) else {
            continue; // a space
        };
        let min = outline.px_bounds().min;
        let (x0, y0) = (min.x as i64, min.y as i64);
        outline.draw(|x, y, c| ink(x0 + i64::from(x), y0 + i64::from(y), c));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bundled_font_parses() {
        assert!(FontRef::try_from_slice(BYTES).is_ok());
        // Every printable ASCII character and the symbols the reports
        // write have a glyph of their own.
        for c in (' '..='~').chain(['°', 'µ', '±', '·', '−', '–', 'ω', 'γ', '²']) {
            assert_ne!(face().glyph_id(c).0, 0, "{c:?}");
        }
    }

    #[test]
    fn text_is_as_wide_as_its_advances() {
        // DejaVu Sans's digits advance 0.636 em; a space 0.318 em.
        let w = width("10 Hz", 10.0);
        assert!(w > 25.0 && w < 35.0, "{w}");
        assert!((width("00", 20.0) - 2.0 * width("0", 20.0)).abs() < 1e-3);
        // Letters ink pixels above the baseline, a comma below it.
        let mut rows = Vec::new();
        rasterise("E,", 20.0, 0.0, |_, dy, c| {
            if c > 0.5 {
                rows.push(dy)
            }
        });
        assert!(rows.iter().any(|&y| y < -10) && rows.iter().any(|&y| y > 0));
    }
}
