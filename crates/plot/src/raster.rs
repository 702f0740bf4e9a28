//! The PNG backend's rasteriser: coverage-based anti-aliasing on an RGB
//! canvas. Lines are unions of round-capped capsules, so joins are round,
//! and each polyline is blended once from a coverage mask (the maximum over
//! its segments) so that dense data does not darken where segments overlap.

use crate::font;
use crate::scene::{Anchor, Color, MarkerShape, Prim, Rect, Scene, Stroke, Text};
use rayon::prelude::*;

type Point = (f64, f64);

// The backends depend on the scene, never the reverse: each adds its own
// output method here.
impl Scene {
    /// The figure as an 8-bit RGB PNG file, drawn at [`PNG_SCALE`] times
    /// the scene's size (an 800-pixel scene becomes 1600 pixels wide). See
    /// [`crate::Bode::to_png`].
    pub fn to_png(&self) -> Vec<u8> {
        let k = PNG_SCALE;
        let (w, h) = (self.width.max(1) * k, self.height.max(1) * k);
        let rgb = render(self, w as usize, h as usize, f64::from(k));
        crate::png::encode(w, h, &rgb)
    }
}

/// Device pixels per scene pixel of a PNG: text and lines as sharp as a
/// screen of twice the density shows them.
pub const PNG_SCALE: u32 = 2;

/// Draws `scene`, scaled by `k`, into `width * height * 3` bytes of RGB,
/// rows top down. Bands of rows are drawn side by side, each with every
/// primitive clipped to it: a pixel's value depends only on the
/// primitives over it, so the bytes do not depend on the bands.
pub(crate) fn render(scene: &Scene, width: usize, height: usize, k: f64) -> Vec<u8> {
    render_in_bands(scene, width, height, k, 128)
}

/// [`render`] in bands of `rows` rows.
fn render_in_bands(scene: &Scene, width: usize, height: usize, k: f64, rows: usize) -> Vec<u8> {
    let bg = scene.background;
    let at = |(x, y): Point| (x * k, y * k);
    let prims: Vec<Prim> = scene
        .primitives()
        .into_iter()
        .map(|prim| match prim {
            Prim::Rect(r, color) => {
                Prim::Rect(Rect::new(r.x * k, r.y * k, r.w * k, r.h * k), color)
            }
            Prim::Path {
                points,
                stroke,
                offset,
            } => Prim::Path {
                points: points.into_iter().map(at).collect(),
                stroke: Stroke {
                    width: stroke.width * k,
                    ..stroke
                },
                offset: offset * k,
            },
            Prim::Marker {
                at: c,
                shape,
                size,
                color,
            } => Prim::Marker {
                at: at(c),
                shape,
                size: size * k,
                color,
            },
            Prim::Text(t) => Prim::Text(Text {
                x: t.x * k,
                y: t.y * k,
                size: t.size * k,
                ..t
            }),
        })
        .collect();
    let mut rgb = [bg.r, bg.g, bg.b].repeat(width * height);
    let rows = rows.max(1);
    rgb.par_chunks_mut((rows * width * 3).max(1))
        .enumerate()
        .for_each(|(i, band)| {
            let mut canvas = Canvas {
                w: width,
                h: band.len() / (3 * width).max(1),
                top: i * rows,
                rgb: band,
            };
            for prim in &prims {
                canvas.draw(prim);
            }
        });
    rgb
}

/// A band of rows of the image: `h` rows from row `top`, in image
/// coordinates.
struct Canvas<'a> {
    w: usize,
    h: usize,
    top: usize,
    rgb: &'a mut [u8],
}

impl Canvas<'_> {
    fn draw(&mut self, prim: &Prim) {
        match prim {
            Prim::Rect(r, color) => self.fill_rect(*r, *color),
            Prim::Path {
                points,
                stroke,
                offset,
            } => self.stroke(points, stroke, *offset),
            Prim::Marker {
                at,
                shape: MarkerShape::Square,
                size,
                color,
            } => {
                let half = size / 2.0;
                self.fill_rect(Rect::new(at.0 - half, at.1 - half, *size, *size), *color);
            }
            Prim::Marker {
                at,
                shape: MarkerShape::Circle,
                size,
                color,
            } => {
                let mut mask = Mask::around(self, &[*at], size / 2.0 + 1.0);
                mask.disc(*at, size / 2.0);
                self.apply(&mask, *color, 1.0);
            }
            Prim::Text(t) => {
                // Horizontal text stays within an em above and below its
                // baseline: bands far from it skip the glyphs.
                let (top, bottom) = (self.top as f64, (self.top + self.h) as f64);
                if t.vertical || (t.y + t.size > top && t.y - 1.5 * t.size < bottom) {
                    self.text(t)
                }
            }
        }
    }

    fn blend(&mut self, x: i64, y: i64, color: Color, coverage: f32) {
        let (top, bottom) = (self.top as i64, (self.top + self.h) as i64);
        if x < 0 || y < top || x >= self.w as i64 || y >= bottom || coverage <= 0.0 {
            return;
        }
        let alpha = coverage.min(1.0) * f32::from(color.a) / 255.0;
        let i = ((y - top) as usize * self.w + x as usize) * 3;
        for (old, new) in self.rgb[i..i + 3]
            .iter_mut()
            .zip([color.r, color.g, color.b])
        {
            let (o, n) = (f32::from(*old), f32::from(new));
            *old = (o + (n - o) * alpha).round() as u8;
        }
    }

    /// Exact area coverage, so fractional edges blend smoothly.
    fn fill_rect(&mut self, r: Rect, color: Color) {
        let (x0, x1) = (r.x.max(0.0), (r.x + r.w).min(self.w as f64));
        let (y0, y1) = (
            r.y.max(self.top as f64),
            (r.y + r.h).min((self.top + self.h) as f64),
        );
        if !(x1 > x0 && y1 > y0) {
            return;
        }
        let overlap = |p: f64, a: f64, b: f64| ((p + 1.0).min(b) - p.max(a)).max(0.0) as f32;
        for py in y0.floor() as i64..y1.ceil() as i64 {
            let cy = overlap(py as f64, y0, y1);
            for px in x0.floor() as i64..x1.ceil() as i64 {
                self.blend(px, py, color, cy * overlap(px as f64, x0, x1));
            }
        }
    }

    fn stroke(&mut self, points: &[Point], stroke: &Stroke, offset: f64) {
        if points.is_empty() || stroke.width.is_nan() || stroke.width <= 0.0 {
            return;
        }
        // Lines thinner than a pixel are drawn one pixel wide but fainter.
        let half = (stroke.width / 2.0).max(0.5);
        let ink = stroke.width.min(1.0) as f32;
        let pieces = match stroke.dash.pattern(stroke.width) {
            None if points.len() == 1 => vec![(points[0], points[0])],
            None => points.windows(2).map(|w| (w[0], w[1])).collect(),
            Some((on, off)) => dashes(points, on, off, offset),
        };
        let mut mask = Mask::around(self, points, half + 1.0);
        for (a, b) in pieces {
            mask.capsule(a, b, half);
        }
        self.apply(&mask, stroke.color, ink);
    }

    fn apply(&mut self, mask: &Mask, color: Color, ink: f32) {
        for (i, &c) in mask.cov.iter().enumerate() {
            let (x, y) = (mask.x0 + (i % mask.w) as i64, mask.y0 + (i / mask.w) as i64);
            self.blend(x, y, color, c * ink);
        }
    }

    /// Anti-aliased text from the bundled font; vertical text is the
    /// horizontal coverage turned by -90 degrees about its origin.
    fn text(&mut self, t: &Text) {
        let size = t.size as f32;
        let shift = match t.anchor {
            Anchor::Start => 0.0,
            Anchor::Middle => font::width(&t.content, size) / 2.0,
            Anchor::End => font::width(&t.content, size),
        };
        if t.vertical {
            let (ox, oy) = (t.x.round() as i64, t.y.round() as i64);
            font::rasterise(&t.content, size, -shift, |along, across, c| {
                self.blend(ox + across, oy - along - 1, t.color, c)
            });
        } else {
            // Whole pixels vertically (a crisp baseline), the fractional
            // start along it.
            let (ox, oy) = (t.x.floor(), t.y.round() as i64);
            let start = (t.x - ox) as f32 - shift;
            font::rasterise(&t.content, size, start, |along, across, c| {
                self.blend(ox as i64 + along, oy + across, t.color, c)
            });
        }
    }
}

/// Per-pixel coverage over a window of the canvas.
struct Mask {
    x0: i64,
    y0: i64,
    w: usize,
    h: usize,
    cov: Vec<f32>,
}

impl Mask {
    /// A window holding `points` grown by `margin`, cut to the canvas.
    fn around(canvas: &Canvas, points: &[Point], margin: f64) -> Mask {
        let (mut lo, mut hi) = ((f64::MAX, f64::MAX), (f64::MIN, f64::MIN));
        for &(x, y) in points {
            lo = (lo.0.min(x), lo.1.min(y));
            hi = (hi.0.max(x), hi.1.max(y));
        }
        let clamp = |v: f64, min: usize, max: usize| v.clamp(min as f64, max as f64) as i64;
        let (x0, x1) = (
            clamp((lo.0 - margin).floor(), 0, canvas.w),
            clamp((hi.0 + margin).ceil(), 0, canvas.w),
        );
        let (top, bottom) = (canvas.top, canvas.top + canvas.h);
        let (y0, y1) = (
            clamp((lo.1 - margin).floor(), top, bottom),
            clamp((hi.1 + margin).ceil(), top, bottom),
        );
        let (w, h) = ((x1 - x0).max(0) as usize, (y1 - y0).max(0) as usize);
        Mask {
            x0,
            y0,
            w,
            h,
            cov: vec![0.0; w * h],
        }
    }

    /// Adds the coverage `f(distance)` of every pixel centre near `a..b`.
    fn add(&mut self, a: Point, b: Point, reach: f64, f: impl Fn(f64) -> f32) {
        let x_range =
            (a.0.min(b.0) - reach).floor() as i64..(a.0.max(b.0) + reach).ceil() as i64 + 1;
        let y_range =
            (a.1.min(b.1) - reach).floor() as i64..(a.1.max(b.1) + reach).ceil() as i64 + 1;
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let len2 = dx * dx + dy * dy;
        for py in y_range.start.max(self.y0)..y_range.end.min(self.y0 + self.h as i64) {
            for px in x_range.start.max(self.x0)..x_range.end.min(self.x0 + self.w as i64) {
                let (cx, cy) = (px as f64 + 0.5 - a.0, py as f64 + 0.5 - a.1);
                let t = if len2 > 0.0 {
                    ((cx * dx + cy * dy) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let d = ((cx - t * dx).powi(2) + (cy - t * dy).powi(2)).sqrt();
                let i = (py - self.y0) as usize * self.w + (px - self.x0) as usize;
                self.cov[i] = self.cov[i].max(f(d));
            }
        }
    }

    /// A segment of half-width `half` with round ends: coverage is
    /// approximated by how far the pixel centre lies inside the edge, which
    /// is exact for straight edges and one pixel of smoothing.
    fn capsule(&mut self, a: Point, b: Point, half: f64) {
        self.add(a, b, half + 1.0, |d| {
            (half + 0.5 - d).clamp(0.0, 1.0) as f32
        });
    }

    fn disc(&mut self, at: Point, radius: f64) {
        self.capsule(at, at, radius);
    }
}

/// The "on" pieces of a dash pattern along a polyline, starting at phase
/// `offset`. Dash `k` covers arc lengths `[k p, k p + on]` with period `p`;
/// iterating over `k` rather than stepping a running phase cannot stall on
/// rounding.
fn dashes(points: &[Point], on: f64, off: f64, offset: f64) -> Vec<(Point, Point)> {
    let period = on + off;
    let mut out = Vec::new();
    let mut s = offset;
    for w in points.windows(2) {
        let (a, b) = (w[0], w[1]);
        let len = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
        if !(len > 0.0 && len.is_finite()) {
            continue;
        }
        let at = |d: f64| {
            let t = (d - s) / len;
            (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1))
        };
        for k in (s / period).floor() as i64..=((s + len) / period).floor() as i64 {
            let start = (k as f64 * period).max(s);
            let end = (k as f64 * period + on).min(s + len);
            if end >= start {
                out.push((at(start), at(end)));
            }
        }
        s += len;
    }
    if points.len() >= 2 && points.windows(2).all(|w| w[0] == w[1]) {
        // A dot-sized run: one dot, as SVG draws it.
        out.push((points[0], points[0]));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Dash;

    #[test]
    fn dashes_follow_the_pattern() {
        let pieces = dashes(&[(0.0, 0.0), (10.0, 0.0), (10.0, 10.0)], 3.0, 2.0, 0.0);
        let spans: Vec<_> = pieces.iter().map(|(a, b)| (a.0 + a.1, b.0 + b.1)).collect();
        // Along the arc: [0,3] [5,8] [10,10] on the first leg, then the
        // second leg starts at arc 10 (coordinates sum to arc length).
        assert_eq!(spans[..3], [(0.0, 3.0), (5.0, 8.0), (10.0, 10.0)]);
        assert_eq!(spans[3..], [(10.0, 13.0), (15.0, 18.0), (20.0, 20.0)]);
        // A phase shifts the pattern.
        let shifted = dashes(&[(0.0, 0.0), (10.0, 0.0)], 3.0, 2.0, 1.0);
        assert_eq!(shifted[0], ((0.0, 0.0), (2.0, 0.0)));
    }

    /// A figure with lines, markers, bands and text across band edges
    /// gives the same bytes in one band, in bands of 128 rows and in bands
    /// of 7 rows.
    #[test]
    fn bands_do_not_change_the_pixels() {
        let f: Vec<f64> = (0..300).map(|i| 10f64.powf(i as f64 / 100.0)).collect();
        let h: Vec<num_complex::Complex64> = f
            .iter()
            .map(|&f| {
                1.0 / num_complex::Complex64::new(1.0 - (f / 100.0).powi(2), 0.05 * f / 100.0)
            })
            .collect();
        let scene = crate::Bode::new("bands")
            .trace("data", &f, &h, crate::Style::points())
            .trace("model", &f, &h, crate::Style::line())
            .band(20.0, 60.0, "mismatch")
            .residual()
            .scene();
        let (w, ht) = (scene.width as usize * 2, scene.height as usize * 2);
        let one = render_in_bands(&scene, w, ht, 2.0, ht);
        assert_eq!(render_in_bands(&scene, w, ht, 2.0, 128), one);
        assert_eq!(render_in_bands(&scene, w, ht, 2.0, 7), one);
    }

    #[test]
    fn a_horizontal_line_covers_its_rows() {
        let scene = Scene::new(20, 10);
        let mut rgb = render(&scene, 20, 10, 1.0);
        let mut canvas = Canvas {
            w: 20,
            h: 10,
            top: 0,
            rgb: &mut rgb,
        };
        let stroke = Stroke {
            color: Color::BLACK,
            width: 2.0,
            dash: Dash::Solid,
        };
        canvas.stroke(&[(2.0, 5.0), (18.0, 5.0)], &stroke, 0.0);
        let px = |x: usize, y: usize| canvas.rgb[(y * 20 + x) * 3];
        // Rows 4 and 5 are fully inside y in [4, 6]; rows 3 and 6 barely.
        assert_eq!((px(10, 4), px(10, 5)), (0, 0));
        assert_eq!((px(10, 2), px(10, 7)), (255, 255));
        assert!(px(10, 3) > 127 && px(10, 6) > 127);
    }
}
