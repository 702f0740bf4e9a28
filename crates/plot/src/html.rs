//! The interactive backend: a Bode figure as a self-contained HTML
//! fragment (a canvas, the figure's data as JSON, and the script in
//! `bode.js`), with zoom (drag across a panel; double-click resets), a
//! readout of frequency, magnitude and phase of every trace under the
//! pointer, and a legend whose entries toggle their trace. No network, no
//! library: the page works from a file.

use crate::bode::Bode;
use std::fmt::Write;

/// The script every interactive figure of a page shares; a page includes
/// it once, after its figures ([`Bode::to_html`] with `script` true).
const SCRIPT: &str = include_str!("bode.js");

impl Bode {
    /// The figure as an HTML fragment: a `<div class="mms-bode">` with a
    /// canvas, its data and, if `script`, the script that draws it (a page
    /// with several figures passes `true` for the last one only). Same
    /// input, same bytes. The SVG of [`Bode::to_svg`] is the static view;
    /// this one is for the browser.
    ///
    /// ```
    /// use num_complex::Complex64;
    /// let f = [1.0, 10.0, 100.0];
    /// let h = [Complex64::new(1.0, 0.0), Complex64::new(0.0, -1.0), Complex64::new(-0.01, 0.0)];
    /// let html = plot::Bode::new("H").trace("measured", &f, &h, plot::Style::points()).to_html("fig1", true);
    /// assert!(html.starts_with("<div class=\"mms-bode\" id=\"fig1\">"));
    /// // Magnitude in dB and unwrapped phase in degrees, per trace.
    /// assert!(html.contains("\"db\":[0,0,-40]"));
    /// assert!(html.contains("\"deg\":[0,-90,-180]"));
    /// assert!(html.contains("<script>"));
    /// ```
    pub fn to_html(&self, id: &str, script: bool) -> String {
        let id = escape_attr(id);
        let mut s = format!("<div class=\"mms-bode\" id=\"{id}\">\n");
        let _ = writeln!(
            s,
            "<div class=\"mms-legend\"></div><canvas width=\"800\" height=\"600\"></canvas>\
             <div class=\"mms-readout\">&nbsp;</div>"
        );
        let _ = writeln!(
            s,
            "<script type=\"application/json\" class=\"mms-data\">{}</script>",
            self.json_data()
        );
        s.push_str("</div>\n");
        if script {
            let _ = writeln!(s, "<script>\n{SCRIPT}</script>");
        }
        s
    }

    /// The data the script draws: title, view, traces (label, colour,
    /// style, frequencies, dB, degrees aligned as in the SVG), bands, the
    /// coherence, and the static figure's axes (ranges and tick labels of
    /// each panel).
    fn json_data(&self) -> String {
        let (curves, colors) = self.curves_and_colors();
        let mut s = String::from("{");
        let _ = write!(s, "\"title\":{}", json_str(&self.title));
        let (lo, hi) = self.range_hz(&curves);
        let _ = write!(s, ",\"view\":[{},{}]", num(lo), num(hi));
        s.push_str(",\"traces\":[");
        for (i, (t, c)) in self.traces.iter().zip(&curves).enumerate() {
            if i > 0 {
                s.push(',');
            }
            let color = colors[i];
            let style = match (t.style.line, t.style.dash, t.style.marker) {
                (false, _, _) => "points",
                (true, crate::Dash::Dashed, _) => "dashed",
                (true, crate::Dash::Dotted, _) => "dotted",
                (true, _, _) => "line",
            };
            let _ = write!(
                s,
                "{{\"label\":{},\"color\":\"#{:02x}{:02x}{:02x}\",\"style\":\"{style}\",\
                 \"f\":{},\"db\":{},\"deg\":{}}}",
                json_str(&t.label),
                color.r,
                color.g,
                color.b,
                array(&c.f),
                array(&c.db),
                array(&c.deg)
            );
        }
        s.push_str("],\"bands\":[");
        for (i, (lo, hi, label)) in self.bands.iter().enumerate() {
            if i > 0 {
                s.push(',');
            }
            let _ = write!(s, "[{},{},{}]", num(*lo), num(*hi), json_str(label));
        }
        s.push(']');
        if let Some(g) = &self.coherence {
            let _ = write!(s, ",\"coherence\":{}", array(g));
        }
        // The static figure's axes, as drawn (a reader of the data can
        // check what the SVG and PNG show).
        s.push_str(",\"axes\":[");
        for (i, p) in self.scene_of(&curves, &colors).panels.iter().enumerate() {
            if i > 0 {
                s.push(',');
            }
            // The values of the labelled ticks.
            let labels = |a: &crate::Axis, shown: bool| {
                let v: Vec<f64> = (a.ticks.iter())
                    .filter(|t| shown && t.label.is_some())
                    .map(|t| t.value)
                    .collect();
                array(&v)
            };
            let _ = write!(
                s,
                "{{\"title\":{},\"x\":[{},{}],\"x_labelled\":{},\"y\":[{},{}],\"y_labelled\":{}}}",
                json_str(&p.y.label),
                num(p.x.min),
                num(p.x.max),
                labels(&p.x, p.x_tick_labels),
                num(p.y.min),
                num(p.y.max),
                labels(&p.y, true)
            );
        }
        s.push_str("]}");
        s
    }
}

/// A JSON array of numbers, `null` for NaN or infinities.
fn array(v: &[f64]) -> String {
    let mut s = String::with_capacity(12 * v.len() + 2);
    s.push('[');
    for (i, x) in v.iter().enumerate() {
        if i > 0 {
            s.push(',');
        }
        s.push_str(&num(*x));
    }
    s.push(']');
    s
}

/// The shortest decimal that reads back as `x` (Rust's `Display`), `null`
/// if not finite.
fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x}")
    } else {
        "null".to_string()
    }
}

/// A JSON string literal, safe inside a `<script>` element.
fn json_str(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '<' => out.push_str("\\u003c"),
            '>' => out.push_str("\\u003e"),
            '&' => out.push_str("\\u0026"),
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

fn escape_attr(s: &str) -> String {
    s.chars()
        .filter(|c| c.is_ascii_alphanumeric() || *c == '-' || *c == '_')
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_cannot_close_the_script() {
        let s = json_str("</script><b>\"x\"\n");
        assert!(!s.contains('<') && !s.contains('>'), "{s}");
        assert_eq!(
            s,
            "\"\\u003c/script\\u003e\\u003cb\\u003e\\\"x\\\"\\u000a\""
        );
    }
}
