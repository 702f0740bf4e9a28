//! The backend-independent scene: what a figure shows, in data coordinates
//! inside panels and in pixels outside them, and its lowering to the
//! pixel-space primitives that the SVG and PNG backends both draw. Clipping
//! happens here, geometrically, so that both backends draw the same lines
//! and SVG needs no clip paths (whose ids would clash when several figures
//! are inlined in one HTML page).

use crate::axis::Axis;

/// An sRGB colour with straight (not premultiplied) alpha.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Color {
    /// Red.
    pub r: u8,
    /// Green.
    pub g: u8,
    /// Blue.
    pub b: u8,
    /// Opacity, 255 opaque.
    pub a: u8,
}

impl Color {
    /// Opaque black.
    pub const BLACK: Color = Color::rgb(0, 0, 0);
    /// Opaque white.
    pub const WHITE: Color = Color::rgb(255, 255, 255);

    /// An opaque colour.
    pub const fn rgb(r: u8, g: u8, b: u8) -> Color {
        Color { r, g, b, a: 255 }
    }

    /// A colour with opacity `a` (255 opaque).
    pub const fn rgba(r: u8, g: u8, b: u8, a: u8) -> Color {
        Color { r, g, b, a }
    }
}

/// The Okabe–Ito colour-blind-safe palette, in the order traces get it:
/// blue, vermillion, bluish green, reddish purple, orange, sky blue, black,
/// yellow (last, as it is faint on white).
pub const PALETTE: [Color; 8] = [
    Color::rgb(0, 114, 178),
    Color::rgb(213, 94, 0),
    Color::rgb(0, 158, 115),
    Color::rgb(204, 121, 167),
    Color::rgb(230, 159, 0),
    Color::rgb(86, 180, 233),
    Color::rgb(0, 0, 0),
    Color::rgb(240, 228, 66),
];

/// Line pattern.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Dash {
    /// Continuous.
    #[default]
    Solid,
    /// Dashes 6 and gaps 4 times the width (at least 1 px).
    Dashed,
    /// Round dots, gaps 2 times the width.
    Dotted,
}

impl Dash {
    /// Drawn on and off lengths along the line for a stroke of `width`.
    /// Both backends use round caps, which add half the width at each end
    /// of a dash, so the drawn dash is shorter than the visible one by the
    /// width. A zero dash would vanish in some SVG renderers: keep a hair.
    pub(crate) fn pattern(self, width: f64) -> Option<(f64, f64)> {
        let k = width.max(1.0);
        let (on, off) = match self {
            Dash::Solid => return None,
            Dash::Dashed => (6.0 * k, 4.0 * k),
            Dash::Dotted => (width, 2.0 * k),
        };
        Some(((on - width).max(0.01), off + width))
    }
}

/// How a line is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stroke {
    /// Colour.
    pub color: Color,
    /// Width in pixels.
    pub width: f64,
    /// Pattern.
    pub dash: Dash,
}

/// An axis-aligned rectangle in pixels, y downwards.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    /// Left edge.
    pub x: f64,
    /// Top edge.
    pub y: f64,
    /// Width.
    pub w: f64,
    /// Height.
    pub h: f64,
}

impl Rect {
    /// A rectangle from its top-left corner and size.
    pub const fn new(x: f64, y: f64, w: f64, h: f64) -> Rect {
        Rect { x, y, w, h }
    }

    fn contains(&self, (x, y): (f64, f64)) -> bool {
        x >= self.x && x <= self.x + self.w && y >= self.y && y <= self.y + self.h
    }
}

/// A polyline; a point with a non-finite coordinate (or one its axis cannot
/// show, such as 0 on a log axis) breaks it into separate pieces.
#[derive(Clone, Debug, PartialEq)]
pub struct Line {
    /// Points, in data units inside a panel and pixels in the overlay.
    pub points: Vec<(f64, f64)>,
    /// Appearance.
    pub stroke: Stroke,
}

/// Marker shapes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MarkerShape {
    /// Filled disc.
    Circle,
    /// Filled square.
    Square,
}

/// A set of markers of one look, e.g. the measured points of an FRF.
#[derive(Clone, Debug, PartialEq)]
pub struct Markers {
    /// Centres; non-finite ones are skipped.
    pub points: Vec<(f64, f64)>,
    /// Shape.
    pub shape: MarkerShape,
    /// Diameter or side in pixels.
    pub size: f64,
    /// Fill colour.
    pub color: Color,
}

/// A shaded x interval spanning the full height of its panel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Band {
    /// One end, in data units (order does not matter).
    pub lo: f64,
    /// The other end.
    pub hi: f64,
    /// Fill, usually translucent.
    pub fill: Color,
}

/// Horizontal alignment of text relative to its anchor point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Anchor {
    /// Text starts at the point.
    #[default]
    Start,
    /// Text is centred on the point.
    Middle,
    /// Text ends at the point.
    End,
}

/// A single line of text in pixels.
#[derive(Clone, Debug, PartialEq)]
pub struct Text {
    /// Anchor x.
    pub x: f64,
    /// Baseline y (for vertical text: the baseline's x is `x`, and `y` is
    /// the anchor along it).
    pub y: f64,
    /// The text; the PNG backend's font has Latin-1, Greek and common
    /// symbols, and draws other characters as `?`.
    pub content: String,
    /// Font size in pixels (the em, as SVG's `font-size`).
    pub size: f64,
    /// Alignment.
    pub anchor: Anchor,
    /// Colour.
    pub color: Color,
    /// Rotated by -90 degrees (reads upwards), for y-axis titles.
    pub vertical: bool,
}

impl Text {
    /// Black, horizontal text starting at `(x, y)`.
    pub fn new(x: f64, y: f64, content: impl Into<String>, size: f64) -> Text {
        let content = content.into();
        Text {
            x,
            y,
            content,
            size,
            anchor: Anchor::Start,
            color: Color::BLACK,
            vertical: false,
        }
    }

    /// The same text with another alignment.
    pub fn anchor(self, anchor: Anchor) -> Text {
        Text { anchor, ..self }
    }
}

/// A plotting area: a pixel rectangle with two axes, the data drawn in it
/// (clipped to it) and its frame, grid, ticks and axis titles.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// Where the plotting area is, in pixels.
    pub rect: Rect,
    /// Horizontal axis.
    pub x: Axis,
    /// Vertical axis.
    pub y: Axis,
    /// Whether to draw x tick labels and the x title (off for panels that
    /// share the x axis of the panel below them).
    pub x_tick_labels: bool,
    /// Shaded intervals, drawn first.
    pub bands: Vec<Band>,
    /// The data's uncertainty: polylines (usually one vertical bar per
    /// line, separated by NaN breaks), drawn over the grid and under the
    /// markers.
    pub spreads: Vec<Line>,
    /// Polylines, drawn over the grid.
    pub lines: Vec<Line>,
    /// Markers, drawn over the lines.
    pub markers: Vec<Markers>,
}

impl Panel {
    /// An empty panel.
    pub fn new(rect: Rect, x: Axis, y: Axis) -> Panel {
        Panel {
            rect,
            x,
            y,
            x_tick_labels: true,
            bands: vec![],
            spreads: vec![],
            lines: vec![],
            markers: vec![],
        }
    }

    /// The pixel position of a data point (not clipped).
    ///
    /// ```
    /// use plot::{Axis, Panel, Rect};
    /// let panel = Panel::new(
    ///     Rect::new(100.0, 50.0, 300.0, 200.0),
    ///     Axis::log(1.0, 1000.0, ""),
    ///     Axis::linear(-40.0, 0.0, ""),
    /// );
    /// let (x, y) = panel.to_pixel(10.0, panel.y.max);
    /// assert!((x - 200.0).abs() < 1e-9 && (y - 50.0).abs() < 1e-9);
    /// ```
    pub fn to_pixel(&self, x: f64, y: f64) -> (f64, f64) {
        let r = &self.rect;
        (
            r.x + r.w * self.x.fraction(x),
            r.y + r.h * (1.0 - self.y.fraction(y)),
        )
    }
}

/// Something drawn in pixel coordinates over the whole figure (titles,
/// legends), in order, without clipping.
#[derive(Clone, Debug, PartialEq)]
pub enum Mark {
    /// A filled rectangle.
    Rect(Rect, Color),
    /// A polyline.
    Line(Line),
    /// Markers.
    Markers(Markers),
    /// Text.
    Text(Text),
}

/// A whole figure, ready for [`Scene::to_svg`] or [`Scene::to_png`].
///
/// ```
/// use plot::{Axis, Color, Dash, Line, Mark, Panel, Rect, Scene, Stroke, Text};
///
/// let mut scene = Scene::new(400, 300);
/// let mut panel = Panel::new(
///     Rect::new(60.0, 20.0, 320.0, 220.0),
///     Axis::linear(0.0, 10.0, "time [s]"),
///     Axis::linear(-1.0, 1.0, "position [mm]"),
/// );
/// let points = (0..=100).map(|i| (f64::from(i) / 10.0, (f64::from(i) / 10.0).sin())).collect();
/// let stroke = Stroke { color: Color::rgb(0, 114, 178), width: 1.5, dash: Dash::Solid };
/// panel.lines.push(Line { points, stroke });
/// scene.panels.push(panel);
/// scene.overlay.push(Mark::Text(Text::new(60.0, 14.0, "step response", 12.0)));
/// assert!(scene.to_svg().contains("step response"));
/// assert_eq!(&scene.to_png()[1..4], b"PNG");
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Background fill.
    pub background: Color,
    /// Accessible name (the SVG `<title>`); not drawn.
    pub title: String,
    /// Plotting areas, drawn in order.
    pub panels: Vec<Panel>,
    /// Drawn last, over the panels.
    pub overlay: Vec<Mark>,
}

/// Pixel-space drawing commands, the common input of both backends.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Prim {
    Rect(Rect, Color),
    /// At least two points; `offset` is the dash phase at the first one.
    Path {
        points: Vec<(f64, f64)>,
        stroke: Stroke,
        offset: f64,
    },
    Marker {
        at: (f64, f64),
        shape: MarkerShape,
        size: f64,
        color: Color,
    },
    Text(Text),
}

impl Prim {
    fn drawable(&self) -> bool {
        let positive = |v: f64| v.is_finite() && v > 0.0;
        match self {
            Prim::Rect(r, _) => {
                r.x.is_finite() && r.y.is_finite() && positive(r.w) && positive(r.h)
            }
            Prim::Path { stroke, offset, .. } => positive(stroke.width) && offset.is_finite(),
            Prim::Marker { size, .. } => positive(*size),
            Prim::Text(t) => t.x.is_finite() && t.y.is_finite() && positive(t.size),
        }
    }
}

const GRID_MAJOR: Color = Color::rgb(208, 208, 208);
const GRID_MINOR: Color = Color::rgb(236, 236, 236);
const INK: Color = Color::rgb(34, 34, 34);
const TICK_SIZE: f64 = 10.0;
const LABEL_SIZE: f64 = 11.0;

impl Scene {
    /// An empty white figure.
    pub fn new(width: u32, height: u32) -> Scene {
        let (panels, overlay) = (Vec::new(), Vec::new());
        Scene {
            width,
            height,
            background: Color::WHITE,
            title: String::new(),
            panels,
            overlay,
        }
    }

    pub(crate) fn primitives(&self) -> Vec<Prim> {
        let mut out = Vec::new();
        for panel in &self.panels {
            lower_panel(panel, &mut out);
        }
        for mark in &self.overlay {
            match mark {
                Mark::Rect(r, c) => out.push(Prim::Rect(*r, *c)),
                Mark::Line(line) => {
                    push_runs(&mut out, line.points.iter().copied(), None, line.stroke)
                }
                Mark::Markers(m) => push_markers(&mut out, m, m.points.iter().copied(), None),
                Mark::Text(t) => out.push(Prim::Text(t.clone())),
            }
        }
        // Hand-built scenes may hold NaN sizes or positions: drop what
        // cannot be drawn rather than write "NaN" into the SVG.
        out.retain(Prim::drawable);
        out
    }
}

fn lower_panel(panel: &Panel, out: &mut Vec<Prim>) {
    let r = panel.rect;
    let (left, top, right, bottom) = (r.x, r.y, r.x + r.w, r.y + r.h);
    let x_px = |v: f64| left + r.w * panel.x.fraction(v);
    let y_px = |v: f64| bottom - r.h * panel.y.fraction(v);

    for band in &panel.bands {
        let (a, b) = (x_px(band.lo), x_px(band.hi));
        if a.is_finite() && b.is_finite() {
            let (a, b) = (a.min(b).max(left), a.max(b).min(right));
            if b > a {
                out.push(Prim::Rect(Rect::new(a, top, b - a, r.h), band.fill));
            }
        }
    }

    // Grid and tick lines sit on pixel centres, so 1-px lines stay crisp.
    let snap = |v: f64| v.floor() + 0.5;
    let hair = |color| Stroke {
        color,
        width: 1.0,
        dash: Dash::Solid,
    };
    let segment = |points, color| Prim::Path {
        points,
        stroke: hair(color),
        offset: 0.0,
    };
    // Ticks on the edges (the usual case for nice ranges) snap onto the
    // frame, which sits on the outermost pixel rows and columns.
    let place = |v: f64, lo: f64, hi: f64| {
        // max/min rather than clamp: a panel under a pixel wide must not panic.
        (v >= lo - 0.01 && v <= hi + 0.01).then(|| snap(v).min(snap(hi - 1.0)).max(snap(lo)))
    };
    let x_ticks: Vec<_> = panel
        .x
        .ticks
        .iter()
        .filter_map(|t| Some((place(x_px(t.value), left, right)?, t)))
        .collect();
    let y_ticks: Vec<_> = panel
        .y
        .ticks
        .iter()
        .filter_map(|t| Some((place(y_px(t.value), top, bottom)?, t)))
        .collect();
    // Minor grid lines first, so that major ones stay on top.
    for major in [false, true] {
        let color = if major { GRID_MAJOR } else { GRID_MINOR };
        for (x, _) in x_ticks.iter().filter(|(_, t)| t.major == major) {
            out.push(segment(vec![(*x, top), (*x, bottom)], color));
        }
        for (y, _) in y_ticks.iter().filter(|(_, t)| t.major == major) {
            out.push(segment(vec![(left, *y), (right, *y)], color));
        }
    }

    for spread in &panel.spreads {
        let points = spread.points.iter().map(|&(x, y)| (x_px(x), y_px(y)));
        push_runs(out, points, Some(r), spread.stroke);
    }
    // Markers (measured points) first and lines (models) over them: a
    // model under thousands of dense points could not be seen.
    for m in &panel.markers {
        let points = m.points.iter().map(|&(x, y)| (x_px(x), y_px(y)));
        push_markers(out, m, points, Some(r));
    }
    for line in &panel.lines {
        let points = line.points.iter().map(|&(x, y)| (x_px(x), y_px(y)));
        push_runs(out, points, Some(r), line.stroke);
    }

    let (l, t, rt, b) = (snap(left), snap(top), snap(right - 1.0), snap(bottom - 1.0));
    out.push(segment(vec![(l, t), (rt, t), (rt, b), (l, b), (l, t)], INK));

    let text = |x, y, s: &str, size, anchor| Text {
        color: INK,
        anchor,
        ..Text::new(x, y, s, size)
    };
    for (x, tick) in &x_ticks {
        let len = if tick.major { 5.0 } else { 3.0 };
        out.push(segment(vec![(*x, b), (*x, b + len)], INK));
        if let (true, Some(label)) = (panel.x_tick_labels, &tick.label) {
            out.push(Prim::Text(text(
                *x,
                bottom + 16.0,
                label,
                TICK_SIZE,
                Anchor::Middle,
            )));
        }
    }
    for (y, tick) in &y_ticks {
        let len = if tick.major { 5.0 } else { 3.0 };
        out.push(segment(vec![(l - len, *y), (l, *y)], INK));
        if let Some(label) = &tick.label {
            out.push(Prim::Text(text(
                left - 8.0,
                y + 3.5,
                label,
                TICK_SIZE,
                Anchor::End,
            )));
        }
    }
    if panel.x_tick_labels && !panel.x.label.is_empty() {
        let title = text(
            left + r.w / 2.0,
            bottom + 34.0,
            &panel.x.label,
            LABEL_SIZE,
            Anchor::Middle,
        );
        out.push(Prim::Text(title));
    }
    if !panel.y.label.is_empty() {
        let title = text(
            left - 48.0,
            top + r.h / 2.0,
            &panel.y.label,
            LABEL_SIZE,
            Anchor::Middle,
        );
        out.push(Prim::Text(Text {
            vertical: true,
            ..title
        }));
    }
}

fn push_markers(
    out: &mut Vec<Prim>,
    m: &Markers,
    points: impl Iterator<Item = (f64, f64)>,
    clip: Option<Rect>,
) {
    for at in points {
        let shown = at.0.is_finite() && at.1.is_finite() && clip.iter().all(|r| r.contains(at));
        if shown {
            out.push(Prim::Marker {
                at,
                shape: m.shape,
                size: m.size,
                color: m.color,
            });
        }
    }
}

/// Splits a pixel-space polyline at non-finite points, clips it to `clip`
/// if given and pushes the visible runs, each with the dash phase it starts at so
/// that dashes continue across the cut. A lone visible point becomes a
/// zero-length run, which both backends draw as a dot.
fn push_runs(
    out: &mut Vec<Prim>,
    points: impl Iterator<Item = (f64, f64)>,
    clip: Option<Rect>,
    stroke: Stroke,
) {
    let mut run: Vec<(f64, f64)> = Vec::new();
    let mut offset = 0.0;
    let mut flush = |run: &mut Vec<(f64, f64)>, offset: f64| {
        match run.len() {
            0 => return,
            1 => run.push(run[0]),
            _ => {}
        }
        out.push(Prim::Path {
            points: simplify(std::mem::take(run)),
            stroke,
            offset,
        });
    };
    let mut arc = 0.0;
    let mut prev: Option<(f64, f64)> = None;
    for p in points {
        if !(p.0.is_finite() && p.1.is_finite()) {
            flush(&mut run, offset);
            prev = None;
            continue;
        }
        match prev {
            None if clip.iter().all(|r| r.contains(p)) => {
                run.push(p);
                offset = arc;
            }
            None => {}
            Some(q) => {
                let len = ((p.0 - q.0).powi(2) + (p.1 - q.1).powi(2)).sqrt();
                let inside = clip.map_or(Some((0.0, 1.0)), |r| clip_segment(q, p, r));
                match inside {
                    Some((t0, t1)) => {
                        let at = |t: f64| (q.0 + t * (p.0 - q.0), q.1 + t * (p.1 - q.1));
                        if t0 > 0.0 {
                            flush(&mut run, offset);
                        }
                        if run.is_empty() {
                            run.push(at(t0));
                            offset = arc + t0 * len;
                        }
                        run.push(at(t1));
                        if t1 < 1.0 {
                            flush(&mut run, offset);
                        }
                    }
                    None => flush(&mut run, offset),
                }
                if len.is_finite() {
                    arc += len;
                }
            }
        }
        prev = Some(p);
    }
    flush(&mut run, offset);
}

/// Drops points that lie within 0.1 px of the line through their kept
/// neighbours (Douglas–Peucker, with an explicit stack): dense measured
/// data has several points per pixel column, which add bytes and drawing
/// time but no visible detail.
fn simplify(points: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    const TOLERANCE: f64 = 0.1;
    let n = points.len();
    if n <= 2 {
        return points;
    }
    let mut keep = vec![false; n];
    (keep[0], keep[n - 1]) = (true, true);
    let mut stack = vec![(0, n - 1)];
    while let Some((a, b)) = stack.pop() {
        let (far, dist) = (a + 1..b)
            .map(|i| (i, segment_distance(points[i], points[a], points[b])))
            .fold(
                (a, 0.0),
                |best, cur| if cur.1 > best.1 { cur } else { best },
            );
        if dist > TOLERANCE {
            keep[far] = true;
            stack.extend([(a, far), (far, b)]);
        }
    }
    points
        .into_iter()
        .zip(keep)
        .filter_map(|(p, k)| k.then_some(p))
        .collect()
}

/// Distance from `p` to the segment `a..b` (not the line: data may turn back).
fn segment_distance(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((p.0 - a.0 - t * dx).powi(2) + (p.1 - a.1 - t * dy).powi(2)).sqrt()
}

/// Liang–Barsky: the parameter interval of the segment `p + t (q - p)`,
/// `t` in `[0, 1]`, that lies inside `r`, if any.
fn clip_segment(p: (f64, f64), q: (f64, f64), r: Rect) -> Option<(f64, f64)> {
    let (dx, dy) = (q.0 - p.0, q.1 - p.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    let sides = [
        (-dx, p.0 - r.x),
        (dx, r.x + r.w - p.0),
        (-dy, p.1 - r.y),
        (dy, r.y + r.h - p.1),
    ];
    for (pk, qk) in sides {
        if pk == 0.0 {
            if qk < 0.0 {
                return None;
            }
        } else {
            let t = qk / pk;
            if pk < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    // NaN (from overflowing spans) fails this comparison and drops the piece.
    (t0 <= t1).then_some((t0, t1))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn runs(points: &[(f64, f64)]) -> Vec<(Vec<(f64, f64)>, f64)> {
        let mut out = Vec::new();
        let stroke = Stroke {
            color: Color::BLACK,
            width: 1.0,
            dash: Dash::Solid,
        };
        let clip = Some(Rect::new(0.0, 0.0, 10.0, 10.0));
        push_runs(&mut out, points.iter().copied(), clip, stroke);
        out.into_iter()
            .map(|p| match p {
                Prim::Path { points, offset, .. } => (points, offset),
                _ => unreachable!(),
            })
            .collect()
    }

    #[test]
    fn clipping_and_gaps() {
        // Leaves at x = 10, comes back in: two runs, the second with the
        // arc length at which it re-enters as its dash phase.
        let r = runs(&[(5.0, 5.0), (15.0, 5.0), (15.0, 6.0), (5.0, 6.0)]);
        assert_eq!(r.len(), 2);
        assert_eq!(r[0], (vec![(5.0, 5.0), (10.0, 5.0)], 0.0));
        assert_eq!(r[1], (vec![(10.0, 6.0), (5.0, 6.0)], 16.0));
        // A NaN breaks the line; a lone point becomes a dot.
        let r = runs(&[(1.0, 1.0), (2.0, 2.0), (f64::NAN, 0.0), (3.0, 3.0)]);
        assert_eq!(r.len(), 2);
        assert_eq!(r[1].0, vec![(3.0, 3.0), (3.0, 3.0)]);
        // Entirely outside, or crossing a corner region: nothing / one piece.
        assert!(runs(&[(-5.0, -5.0), (-1.0, 20.0)]).is_empty());
        let r = runs(&[(-5.0, 5.0), (20.0, 5.0)]);
        assert_eq!(r[0].0, vec![(0.0, 5.0), (10.0, 5.0)]);
        assert!(runs(&[]).is_empty());
    }

    #[test]
    fn simplification_keeps_shape() {
        // A straight dense line collapses to its ends; a corner stays.
        let line: Vec<_> = (0..=100)
            .map(|i| (f64::from(i) * 0.05, 2.0 + f64::from(i) * 0.01))
            .collect();
        assert_eq!(simplify(line), [(0.0, 2.0), (5.0, 3.0)]);
        let corner = vec![
            (0.0, 0.0),
            (1.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (2.0, 2.0),
            (1.0, 1.0),
        ];
        assert_eq!(
            simplify(corner),
            [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (1.0, 1.0)]
        );
        // A spike of 0.2 px survives, jitter of 0.05 px does not.
        let spike = vec![(0.0, 0.0), (1.0, 0.2), (2.0, 0.0), (3.0, 0.05), (4.0, 0.0)];
        assert_eq!(
            simplify(spike),
            [(0.0, 0.0), (1.0, 0.2), (2.0, 0.0), (4.0, 0.0)]
        );
    }

    #[test]
    fn dash_patterns_account_for_round_caps() {
        assert_eq!(Dash::Solid.pattern(2.0), None);
        assert_eq!(Dash::Dashed.pattern(2.0), Some((10.0, 10.0)));
        let (on, off) = Dash::Dotted.pattern(1.5).unwrap();
        assert!(on > 0.0 && on < 0.1 && off == 4.5);
    }
}
