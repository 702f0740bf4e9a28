//! SVG 1.1 backend. The output has no XML declaration, ids, timestamps or
//! styles, so it works both saved as a `.svg` file and inlined in HTML
//! (where a prolog would be a stray node and ids could clash), and the same
//! scene always gives the same bytes: coordinates are written with at most
//! two decimals.

use std::fmt::Write;

use crate::scene::{Anchor, Color, MarkerShape, Prim, Scene};

// The backends depend on the scene, never the reverse: each adds its own
// output method here.
impl Scene {
    /// The figure as standalone SVG 1.1 text, also valid inline in HTML.
    /// See [`crate::Bode::to_svg`].
    pub fn to_svg(&self) -> String {
        render(self)
    }
}

fn render(scene: &Scene) -> String {
    let (w, h) = (scene.width, scene.height);
    let family = crate::font::FAMILY;
    let mut s = String::new();
    // Writing to a String cannot fail, hence the ignored results below.
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="{family}">"#
    );
    if !scene.title.is_empty() {
        let _ = writeln!(s, "<title>{}</title>", escape(&scene.title));
    }
    let _ = writeln!(
        s,
        r#"<rect width="{w}" height="{h}"{}/>"#,
        paint("fill", scene.background)
    );
    // Consecutive round markers of one look share a path of zero-length
    // round-capped subpaths, which SVG 1.1 draws as dots (section 11.4):
    // a fifth of the bytes of one <circle> each.
    let mut dots: Option<(f64, Color)> = None;
    for prim in scene.primitives() {
        let dot = match prim {
            Prim::Marker {
                shape: MarkerShape::Circle,
                size,
                color,
                ..
            } => Some((size, color)),
            _ => None,
        };
        if dots.is_some() && dots != dot {
            s.push_str("\"/>\n");
            dots = None;
        }
        match prim {
            Prim::Rect(r, color) => {
                let (x, y, rw, rh) = (num(r.x), num(r.y), num(r.w), num(r.h));
                let fill = paint("fill", color);
                let _ = writeln!(
                    s,
                    r#"<rect x="{x}" y="{y}" width="{rw}" height="{rh}"{fill}/>"#
                );
            }
            Prim::Path {
                points,
                stroke,
                offset,
            } => {
                s.push_str(r#"<polyline points=""#);
                let mut last = String::new();
                let mut written = 0;
                for (x, y) in &points {
                    // Points that round to the same spot add bytes, not ink.
                    let pair = format!("{},{}", num(*x), num(*y));
                    if pair != last {
                        if written > 0 {
                            s.push(' ');
                        }
                        s.push_str(&pair);
                        written += 1;
                        last = pair;
                    }
                }
                if written == 1 {
                    // A zero-length run: SVG draws its round caps as a dot
                    // only when the polyline has two points.
                    let _ = write!(s, " {last}");
                }
                let _ = write!(
                    s,
                    r#"" fill="none"{} stroke-width="{}" stroke-linecap="round" stroke-linejoin="round""#,
                    paint("stroke", stroke.color),
                    num(stroke.width)
                );
                if let Some((on, off)) = stroke.dash.pattern(stroke.width) {
                    let (on, off, phase) = (num(on), num(off), num(offset));
                    let _ = write!(
                        s,
                        r#" stroke-dasharray="{on} {off}" stroke-dashoffset="{phase}""#
                    );
                }
                s.push_str("/>\n");
            }
            Prim::Marker {
                at: (x, y),
                shape: MarkerShape::Circle,
                size,
                color,
            } => {
                if dots.is_none() {
                    let stroke = paint("stroke", color);
                    let _ = write!(
                        s,
                        r#"<path fill="none"{stroke} stroke-width="{}" stroke-linecap="round" d=""#,
                        num(size)
                    );
                    dots = dot;
                }
                let _ = write!(s, "M{} {}h0", num(x), num(y));
            }
            Prim::Marker {
                at: (x, y),
                shape: MarkerShape::Square,
                size,
                color,
            } => {
                let fill = paint("fill", color);
                let (x, y, a) = (num(x - size / 2.0), num(y - size / 2.0), num(size));
                let _ = writeln!(
                    s,
                    r#"<rect x="{x}" y="{y}" width="{a}" height="{a}"{fill}/>"#
                );
            }
            Prim::Text(t) => {
                let (x, y) = (num(t.x), num(t.y));
                let _ = write!(s, r#"<text x="{x}" y="{y}" font-size="{}""#, num(t.size));
                match t.anchor {
                    Anchor::Start => {}
                    Anchor::Middle => s.push_str(r#" text-anchor="middle""#),
                    Anchor::End => s.push_str(r#" text-anchor="end""#),
                }
                s.push_str(&paint("fill", t.color));
                if t.vertical {
                    let _ = write!(s, r#" transform="rotate(-90 {x} {y})""#);
                }
                let _ = writeln!(s, ">{}</text>", escape(&t.content));
            }
        }
    }
    if dots.is_some() {
        s.push_str("\"/>\n");
    }
    s.push_str("</svg>\n");
    s
}

/// A coordinate with at most two decimals and no "-0".
fn num(v: f64) -> String {
    let s = format!("{v:.2}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

/// ` fill="#rrggbb"` (or stroke), with an opacity attribute when needed.
fn paint(attr: &str, c: Color) -> String {
    let mut s = format!(r##" {attr}="#{:02x}{:02x}{:02x}""##, c.r, c.g, c.b);
    if c.a < 255 {
        let _ = write!(s, r#" {attr}-opacity="{}""#, num(f64::from(c.a) / 255.0));
    }
    s
}

/// Text content and attribute values: the five XML entities, and no
/// control characters (not allowed in XML 1.0).
fn escape(text: &str) -> String {
    let mut s = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '"' => s.push_str("&quot;"),
            '\'' => s.push_str("&#39;"),
            c if c.is_control() && !matches!(c, '\t' | '\n' | '\r') => {}
            c => s.push(c),
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers() {
        assert_eq!(num(1.0), "1");
        assert_eq!(num(1.5), "1.5");
        assert_eq!(num(-0.001), "0");
        assert_eq!(num(123.456), "123.46");
        assert_eq!(num(-2.10), "-2.1");
        assert_eq!(num(100.0), "100");
    }

    #[test]
    fn escaping_and_paint() {
        assert_eq!(
            escape("a<b & \"c\" 'd'>\u{1}"),
            "a&lt;b &amp; &quot;c&quot; &#39;d&#39;&gt;"
        );
        assert_eq!(
            paint("fill", Color::rgb(0, 114, 178)),
            r##" fill="#0072b2""##
        );
        assert_eq!(
            paint("stroke", Color::rgba(255, 0, 0, 51)),
            r##" stroke="#ff0000" stroke-opacity="0.2""##
        );
    }
}
