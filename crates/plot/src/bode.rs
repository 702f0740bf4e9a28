//! Bode figures: magnitude and phase over log frequency, optional residual
//! panel, shaded bands and a legend, built into a [`Scene`].

use num_complex::Complex64;
use std::collections::BTreeMap;

use crate::axis::Axis;
use crate::scene::{
    Anchor, Band, Color, Dash, Line, Mark, MarkerShape, Markers, Panel, Rect, Scene, Stroke, Text,
    PALETTE,
};

/// How a trace is drawn. The default is a solid 1.5 px line in the next
/// palette colour.
///
/// ```
/// use plot::{Color, MarkerShape, Style};
/// let measured = Style::points();
/// let model = Style::line().width(2.0);
/// let prior = Style::dashed().color(Color::rgb(0, 0, 0));
/// let both = Style::line().marker(MarkerShape::Square);
/// assert!(measured.marker.is_some() && !measured.line);
/// # let _ = (model, prior, both);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Style {
    /// Colour; `None` takes [`PALETTE`]`[i % 8]` for the i-th trace.
    pub color: Option<Color>,
    /// Line width in pixels.
    pub width: f64,
    /// Line pattern.
    pub dash: Dash,
    /// Whether to connect the points.
    pub line: bool,
    /// Marker at every point, if any.
    pub marker: Option<MarkerShape>,
}

impl Default for Style {
    fn default() -> Style {
        Style::line()
    }
}

impl Style {
    /// A solid line.
    pub fn line() -> Style {
        Style {
            color: None,
            width: 1.5,
            dash: Dash::Solid,
            line: true,
            marker: None,
        }
    }

    /// A dashed line.
    pub fn dashed() -> Style {
        Style {
            dash: Dash::Dashed,
            ..Style::line()
        }
    }

    /// A dotted line.
    pub fn dotted() -> Style {
        Style {
            dash: Dash::Dotted,
            ..Style::line()
        }
    }

    /// Unconnected circles, for measured points.
    pub fn points() -> Style {
        Style {
            line: false,
            marker: Some(MarkerShape::Circle),
            ..Style::line()
        }
    }

    /// The same style in a fixed colour.
    pub fn color(self, color: Color) -> Style {
        Style {
            color: Some(color),
            ..self
        }
    }

    /// The same style with another line width.
    pub fn width(self, width: f64) -> Style {
        Style { width, ..self }
    }

    /// The same style with markers.
    pub fn marker(self, shape: MarkerShape) -> Style {
        Style {
            marker: Some(shape),
            ..self
        }
    }
}

#[derive(Clone, Debug)]
pub(crate) struct Trace {
    pub(crate) label: String,
    freq_hz: Vec<f64>,
    response: Vec<Complex64>,
    pub(crate) style: Style,
    /// Standard deviation of the response per frequency, if shown.
    std_dev: Option<Vec<f64>>,
}

/// A Bode figure under construction.
///
/// Panels, top to bottom: magnitude in dB (`20 log10 |H|`), phase in
/// degrees, and with [`Bode::residual`] the residual in dB. They share a
/// logarithmic frequency axis in Hz that spans the data exactly; the value
/// axes get nice ranges with a margin.
///
/// Phase is unwrapped along each trace (steps over 180 degrees between
/// successive finite points are taken as wraps, across gaps too). The first
/// trace starts in `[-180, 180)` (so a real negative response reads -180,
/// the lagging convention); every other trace is then shifted by the
/// multiple of 360 degrees that brings it closest to the first trace where
/// they start (the turn count most of their common lines agree on in the
/// lower half of their common range in log frequency, or by mean if they
/// do not overlap), so that equal phases plot on top of each other.
///
/// Points whose frequency is not finite and positive, or whose response is
/// not finite or zero, are gaps that break the line. Input never panics:
/// frequency and response are cut to the shorter of the two, and empty or
/// degenerate data gives default or widened ranges.
///
/// ```
/// use num_complex::Complex64;
/// use plot::{Bode, Style};
///
/// let freq: Vec<f64> = (0..200).map(|i| 10f64.powf(i as f64 / 50.0)).collect();
/// let model: Vec<Complex64> = freq
///     .iter()
///     .map(|&f| 1.0 / (Complex64::new(0.0, 2.0 * std::f64::consts::PI * f / 20.0) + 1.0))
///     .collect();
/// let measured: Vec<Complex64> = model.iter().map(|h| h * 1.05).collect();
/// let svg = Bode::new("Axis 1, motor side")
///     .trace("measured", &freq, &measured, Style::points())
///     .trace("fit", &freq, &model, Style::line())
///     .band(300.0, 500.0, "mismatch")
///     .residual()
///     .to_svg();
/// assert!(svg.starts_with("<svg") && svg.contains("mismatch"));
/// ```
#[derive(Clone, Debug)]
#[must_use]
pub struct Bode {
    pub(crate) title: String,
    pub(crate) traces: Vec<Trace>,
    pub(crate) bands: Vec<(f64, f64, String)>,
    residual: bool,
    /// Coherence of the first trace per frequency, if shown.
    pub(crate) coherence: Option<Vec<f64>>,
    size: Option<(u32, u32)>,
    view: Option<(f64, f64)>,
}

/// Fills of band groups (bands sharing a label), in order of first use.
const BAND_FILLS: [Color; 4] = [
    Color::rgba(128, 128, 128, 56),
    Color::rgba(240, 228, 66, 96),
    Color::rgba(86, 180, 233, 64),
    Color::rgba(204, 121, 167, 64),
];

impl Bode {
    /// An empty figure with a title (may be empty).
    ///
    /// ```
    /// let png = plot::Bode::new("nothing yet").to_png();
    /// assert_eq!(&png[1..4], b"PNG");
    /// ```
    pub fn new(title: impl Into<String>) -> Bode {
        let title = title.into();
        Bode {
            title,
            traces: Vec::new(),
            bands: Vec::new(),
            view: None,
            residual: false,
            coherence: None,
            size: None,
        }
    }

    /// Adds a trace: a label for the legend (empty for no entry),
    /// frequencies in Hz, the complex response at them, and how to draw
    /// it. The first trace is the phase and residual reference.
    ///
    /// ```
    /// use num_complex::Complex64;
    /// let f = [1.0, 10.0, 100.0];
    /// let h = [Complex64::new(1.0, 0.0), Complex64::new(0.5, -0.5), Complex64::new(0.0, -0.1)];
    /// let bode = plot::Bode::new("").trace("H", &f, &h, plot::Style::line());
    /// assert_eq!(bode.scene().panels[0].lines.len(), 1);
    /// ```
    pub fn trace(
        mut self,
        label: impl Into<String>,
        freq_hz: &[f64],
        response: &[Complex64],
        style: Style,
    ) -> Bode {
        let n = freq_hz.len().min(response.len());
        let (freq_hz, response) = (freq_hz[..n].to_vec(), response[..n].to_vec());
        self.traces.push(Trace {
            label: label.into(),
            freq_hz,
            response,
            style,
            std_dev: None,
        });
        self
    }

    /// Shows the standard deviation of the last trace's response (one per
    /// frequency, as `frf::Frf::std_dev` gives it) as a light bar at each
    /// frequency: in magnitude from `|H| - s` to `|H| + s` (down to 60 dB
    /// below `|H|` where `s` reaches it), in phase `asin(s / |H|)` either
    /// way (the whole turn where `s >= |H|`).
    ///
    /// ```
    /// use num_complex::Complex64;
    /// let f = [1.0, 10.0];
    /// let h = [Complex64::new(1.0, 0.0); 2];
    /// let scene = plot::Bode::new("").trace("H", &f, &h, plot::Style::points())
    ///     .uncertainty(&[0.5, 0.1])
    ///     .scene();
    /// // Magnitude bars: 20 log10(0.5) to 20 log10(1.5) dB at 1 Hz.
    /// let bar = &scene.panels[0].spreads[0].points;
    /// assert!((bar[0].1 - 20.0 * 0.5f64.log10()).abs() < 1e-9);
    /// assert!((bar[1].1 - 20.0 * 1.5f64.log10()).abs() < 1e-9);
    /// // Phase bars: +-30 degrees where s = |H| / 2.
    /// let bar = &scene.panels[1].spreads[0].points;
    /// assert!((bar[1].1 - bar[0].1 - 60.0).abs() < 1e-9);
    /// ```
    pub fn uncertainty(mut self, std_dev: &[f64]) -> Bode {
        if let Some(t) = self.traces.last_mut() {
            t.std_dev = Some(std_dev.to_vec());
        }
        self
    }

    /// Adds a coherence panel (0 to 1) at the bottom: `gamma2` is the
    /// squared coherence at each frequency of the first trace, drawn in its
    /// style. A low coherence marks lines whose estimate noise or
    /// nonlinearity dominates.
    ///
    /// ```
    /// use num_complex::Complex64;
    /// let f = [1.0, 10.0, 100.0];
    /// let h = [Complex64::new(1.0, 0.0); 3];
    /// let scene = plot::Bode::new("").trace("H", &f, &h, plot::Style::points())
    ///     .coherence(&[0.99, 0.5, 0.9])
    ///     .scene();
    /// let panel = scene.panels.last().unwrap();
    /// assert_eq!(panel.y.label, "Coherence");
    /// assert_eq!((panel.y.min, panel.y.max), (0.0, 1.0));
    /// assert_eq!(panel.markers[0].points[1], (10.0, 0.5));
    /// ```
    pub fn coherence(mut self, gamma2: &[f64]) -> Bode {
        self.coherence = Some(gamma2.to_vec());
        self
    }

    /// Shades the frequencies between `lo_hz` and `hi_hz` in every panel,
    /// e.g. where model and measurement disagree. Bands with the same label
    /// share a colour and one legend entry; an empty label has no entry.
    ///
    /// ```
    /// let bode = plot::Bode::new("").band(40.0, 60.0, "mismatch").band(200.0, 210.0, "mismatch");
    /// assert!(bode.to_svg().matches("mismatch").count() == 1);
    /// ```
    pub fn band(mut self, lo_hz: f64, hi_hz: f64, label: impl Into<String>) -> Bode {
        self.bands.push((lo_hz, hi_hz, label.into()));
        self
    }

    /// Adds a third panel with each trace's magnitude relative to the first
    /// trace, `20 log10 |H_i / H_0|` in dB, where the first trace's dB
    /// value is interpolated linearly over log frequency at the other
    /// trace's frequencies (gaps outside its range).
    ///
    /// ```
    /// use num_complex::Complex64;
    /// let f = [1.0, 10.0];
    /// let bode = plot::Bode::new("")
    ///     .trace("measured", &f, &[Complex64::new(1.0, 0.0); 2], plot::Style::points())
    ///     .trace("model", &f, &[Complex64::new(2.0, 0.0); 2], plot::Style::line())
    ///     .residual();
    /// let residual = &bode.scene().panels[2];
    /// let (_, db) = residual.lines[0].points[1];
    /// assert!((db - 20.0 * 2f64.log10()).abs() < 1e-12);
    /// ```
    pub fn residual(mut self) -> Bode {
        self.residual = true;
        self
    }

    /// Figure size in pixels; the default is 800 x 560, or 800 x 700 with
    /// a residual panel. Sizes below 200 x 160 are raised to that.
    ///
    /// ```
    /// let scene = plot::Bode::new("small").size(480, 360).scene();
    /// assert_eq!((scene.width, scene.height), (480, 360));
    /// ```
    pub fn size(mut self, width: u32, height: u32) -> Bode {
        self.size = Some((width, height));
        self
    }

    /// Shows the lines from `lo_hz` to `hi_hz` (the analysed band) with a
    /// little context either side (a factor 1.3), within the data: the
    /// value axes fit what is shown, so poorly excited lines far outside
    /// the band (whose unwrapped phase wanders by turns) do not squeeze
    /// it. Lines outside stay in the figure, clipped.
    ///
    /// ```
    /// use num_complex::Complex64;
    /// let f: Vec<f64> = (1..=1000).map(f64::from).collect();
    /// let h: Vec<Complex64> = f.iter().map(|&f| Complex64::new(1.0 / f, 0.0)).collect();
    /// let scene = plot::Bode::new("").trace("H", &f, &h, plot::Style::line()).view(10.0, 100.0).scene();
    /// let x = &scene.panels[0].x;
    /// assert!(x.min <= 10.0 / 1.3 && x.max >= 100.0 * 1.3 && x.max < 1000.0);
    /// // The magnitude axis fits 10-100 Hz (-20 to -40 dB) with context,
    /// // not the -60 dB at 1 kHz.
    /// assert!(scene.panels[0].y.min > -50.0);
    /// ```
    pub fn view(mut self, lo_hz: f64, hi_hz: f64) -> Bode {
        if lo_hz > 0.0 && hi_hz > lo_hz && hi_hz.is_finite() {
            self.view = Some((lo_hz, hi_hz));
        }
        self
    }

    /// The figure as SVG 1.1 text: deterministic, without ids or an XML
    /// declaration, so it can be written to a `.svg` file or pasted inline
    /// into HTML or Markdown as is.
    ///
    /// ```
    /// use num_complex::Complex64;
    /// let f: Vec<f64> = (1..=100).map(f64::from).collect();
    /// let h: Vec<Complex64> = f.iter().map(|&f| Complex64::new(0.0, -1.0 / f)).collect();
    /// let bode = plot::Bode::new("integrator").trace("1/s", &f, &h, Default::default());
    /// let svg = bode.to_svg();
    /// assert!(svg.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\""));
    /// assert_eq!(svg, bode.to_svg());
    /// std::fs::write(std::env::temp_dir().join("integrator.svg"), &svg)?;
    /// # Ok::<(), std::io::Error>(())
    /// ```
    pub fn to_svg(&self) -> String {
        self.scene().to_svg()
    }

    /// The figure as an 8-bit RGB PNG file: own rasteriser and bitmap
    /// font, deterministic bytes.
    ///
    /// ```
    /// use num_complex::Complex64;
    /// let f: Vec<f64> = (1..=100).map(f64::from).collect();
    /// let h: Vec<Complex64> = f.iter().map(|&f| Complex64::new(0.0, -1.0 / f)).collect();
    /// let png = plot::Bode::new("integrator").trace("1/s", &f, &h, Default::default()).to_png();
    /// assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    /// std::fs::write(std::env::temp_dir().join("integrator.png"), &png)?;
    /// # Ok::<(), std::io::Error>(())
    /// ```
    pub fn to_png(&self) -> Vec<u8> {
        self.scene().to_png()
    }

    /// The backend-independent scene, for inspection or further drawing.
    /// Panels are magnitude, phase and (if requested) residual; their lines
    /// hold the plotted values in data units, and all of the legend and
    /// title are in [`Scene::overlay`].
    ///
    /// ```
    /// let scene = plot::Bode::new("").residual().scene();
    /// assert_eq!(scene.panels.len(), 3);
    /// assert_eq!(scene.panels[1].y.label, "Phase [deg]");
    /// ```
    pub fn scene(&self) -> Scene {
        let (curves, colors) = self.curves_and_colors();
        self.scene_of(&curves, &colors)
    }

    /// [`Bode::scene`] from the curves and colours of
    /// [`Bode::curves_and_colors`].
    pub(crate) fn scene_of(&self, curves: &[Curve], colors: &[Color]) -> Scene {
        let mut groups: Vec<(&str, Color)> = Vec::new();
        for (_, _, label) in &self.bands {
            if !groups.iter().any(|(l, _)| l == label) {
                groups.push((label, BAND_FILLS[groups.len() % BAND_FILLS.len()]));
            }
        }

        let (w, h) = self.size.unwrap_or((
            800,
            560 + if self.residual { 140 } else { 0 }
                + if self.coherence.is_some() { 130 } else { 0 },
        ));
        let (w, h) = (w.max(200), h.max(160));
        let mut scene = Scene::new(w, h);
        scene.title = self.title.clone();

        // The legend column is as wide as its longest label, within limits.
        let legend_labels = (self.traces.iter().map(|t| t.label.as_str()))
            .chain(groups.iter().map(|g| g.0))
            .filter(|l| !l.is_empty());
        let max_legend = 0.4 * f64::from(w);
        let max_chars = ((max_legend - 40.0) / (0.6 * LEGEND_SIZE)).max(4.0) as usize;
        let longest = legend_labels
            .map(|l| l.chars().count().min(max_chars))
            .max();
        let legend_w = longest.map_or(0.0, |n| {
            (n as f64 * 0.6 * LEGEND_SIZE + 40.0).clamp(80.0, max_legend)
        });
        let (left, right, top) = (70.0, (f64::from(w) - 16.0 - legend_w).round(), 44.0);

        let panels = self.panel_values(curves);
        let (f_lo, f_hi) = self.range_hz(curves);
        let shown = |f: f64| f >= f_lo * (1.0 - 1e-12) && f <= f_hi * (1.0 + 1e-12);
        let (gap, bottom_margin) = (12.0, 44.0);
        let avail = f64::from(h) - top - bottom_margin - gap * (panels.len() - 1) as f64;
        let total: f64 = panels.iter().map(|p| p.2).sum();
        let mut y = top;
        let count = panels.len();
        for (k, (values, name, weight)) in panels.into_iter().enumerate() {
            let height = (avail * weight / total).round().max(10.0);
            // The value range of what is shown.
            let visible = curves.iter().zip(&values).flat_map(|(c, ys)| {
                c.f.iter()
                    .zip(ys)
                    .filter(|(f, _)| shown(**f))
                    .map(|(_, y)| *y)
            });
            let (lo, hi) = match (finite_range(visible), k) {
                (Some(range), 0 | 1) => range,
                // Zero is the residual's point of reference: always show it.
                (Some((lo, hi)), _) => (lo.min(0.0), hi.max(0.0)),
                (None, 0) => (-20.0, 20.0),
                (None, 1) => (-180.0, 180.0),
                (None, _) => (0.0, 0.0),
            };
            // One tick interval per 30 px keeps the labels apart; the
            // coherence shows exactly 0 to 1.
            let y_axis = if name == COHERENCE {
                unit_axis(name, height)
            } else {
                Axis::linear_with(lo, hi, name, (height / 30.0) as usize)
            };
            let x_axis = Axis::log(f_lo, f_hi, "Frequency [Hz]");
            let mut panel = Panel::new(Rect::new(left, y, right - left, height), x_axis, y_axis);
            y += height + gap;
            panel.x_tick_labels = k + 1 == count;
            for (lo, hi, label) in &self.bands {
                let fill = groups
                    .iter()
                    .find(|g| g.0 == label)
                    .map_or(BAND_FILLS[0], |g| g.1);
                panel.bands.push(Band {
                    lo: *lo,
                    hi: *hi,
                    fill,
                });
            }
            for (i, (c, ys)) in curves.iter().zip(&values).enumerate() {
                if let (Some(s), true) = (&self.traces[i].std_dev, k < 2) {
                    panel.spreads.push(spread(c, s, k == 0, colors[i]));
                }
                let points: Vec<(f64, f64)> = c.f.iter().copied().zip(ys.iter().copied()).collect();
                let (style, color) = (self.traces[i].style, colors[i]);
                if let Some(shape) = style.marker {
                    let (points, size) = (points.clone(), marker_size(style.width));
                    panel.markers.push(Markers {
                        points,
                        shape,
                        size,
                        color,
                    });
                }
                if style.line {
                    let stroke = Stroke {
                        color,
                        width: style.width,
                        dash: style.dash,
                    };
                    panel.lines.push(Line { points, stroke });
                }
            }
            scene.panels.push(panel);
        }

        let title = Text::new((left + right) / 2.0, 26.0, &self.title, 16.0);
        scene.overlay.push(Mark::Text(title.anchor(Anchor::Middle)));
        // Legend rows: traces, then band groups; unlabelled ones have none.
        let traces = (self.traces.iter().zip(colors))
            .map(|(t, &c)| (t.label.as_str(), Swatch::Trace(t.style, c)));
        let bands = groups
            .iter()
            .map(|&(label, fill)| (label, Swatch::Band(fill)));
        let entries = traces.chain(bands).filter(|e| !e.0.is_empty());
        push_legend(&mut scene, entries, (right + 16.0, top + 8.0), max_chars);
        scene
    }

    /// Each trace's magnitude and phase (phases aligned to the first
    /// trace's) and colour.
    pub(crate) fn curves_and_colors(&self) -> (Vec<Curve>, Vec<Color>) {
        let curves = align_phases(self.traces.iter().map(Curve::new).collect());
        let colors = (self.traces.iter().enumerate())
            .map(|(i, t)| t.style.color.unwrap_or(PALETTE[i % PALETTE.len()]))
            .collect();
        (curves, colors)
    }

    /// The frequencies the figure shows: the view with some context, or
    /// all the data (without data, the bands').
    pub(crate) fn range_hz(&self, curves: &[Curve]) -> (f64, f64) {
        let all_f = finite_range(curves.iter().flat_map(|c| c.f.iter().copied()));
        let band_f = finite_range(
            self.bands
                .iter()
                .flat_map(|b| [b.0, b.1])
                .filter(|f| *f > 0.0),
        );
        let (mut f_lo, mut f_hi) = all_f.or(band_f).unwrap_or((1.0, 1000.0));
        if let Some((lo, hi)) = self.view {
            (f_lo, f_hi) = ((lo / 1.3).max(f_lo), (hi * 1.3).min(f_hi));
            if f_lo >= f_hi {
                (f_lo, f_hi) = (lo, hi);
            }
        }
        (f_lo, f_hi)
    }

    /// Values of each panel (one vector per trace, aligned with its
    /// frequencies), its y title and its share of the height.
    fn panel_values(&self, curves: &[Curve]) -> Vec<(Vec<Vec<f64>>, &'static str, f64)> {
        let mut panels = vec![
            (
                curves.iter().map(|c| c.db.clone()).collect(),
                "Magnitude [dB]",
                3.0,
            ),
            (
                curves.iter().map(|c| c.deg.clone()).collect(),
                "Phase [deg]",
                2.0,
            ),
        ];
        if self.residual {
            let residuals = match curves.first() {
                Some(reference) => {
                    let at = Interp::new(&reference.f, &reference.db);
                    let residual = |c: &Curve| {
                        c.f.iter()
                            .zip(&c.db)
                            .map(|(&f, db)| db - at.at(f))
                            .collect()
                    };
                    curves.iter().map(residual).collect()
                }
                None => Vec::new(),
            };
            panels.push((residuals, "Residual [dB]", 1.6));
        }
        if let Some(gamma2) = &self.coherence {
            // The first trace's lines only.
            let values = curves
                .iter()
                .enumerate()
                .map(|(i, c)| {
                    (0..c.f.len())
                        .map(|j| match (i, gamma2.get(j)) {
                            (0, Some(&g)) => g,
                            _ => f64::NAN,
                        })
                        .collect()
                })
                .collect();
            panels.push((values, COHERENCE, 1.3));
        }
        panels
    }
}

/// Legend rows down from `(x0, y0)`: a swatch 24 px wide, then the label,
/// cut to `max_chars`.
fn push_legend<'a>(
    scene: &mut Scene,
    entries: impl Iterator<Item = (&'a str, Swatch)>,
    (x0, y0): (f64, f64),
    max_chars: usize,
) {
    for (k, (label, swatch)) in entries.enumerate() {
        let row = y0 + 18.0 * k as f64;
        match swatch {
            Swatch::Trace(style, color) => {
                if style.line {
                    let stroke = Stroke {
                        color,
                        width: style.width,
                        dash: style.dash,
                    };
                    let points = vec![(x0, row), (x0 + 24.0, row)];
                    scene.overlay.push(Mark::Line(Line { points, stroke }));
                }
                if let Some(shape) = style.marker {
                    let (points, size) = (vec![(x0 + 12.0, row)], marker_size(style.width));
                    scene.overlay.push(Mark::Markers(Markers {
                        points,
                        shape,
                        size,
                        color,
                    }));
                }
            }
            Swatch::Band(fill) => {
                scene
                    .overlay
                    .push(Mark::Rect(Rect::new(x0, row - 6.0, 24.0, 12.0), fill));
            }
        }
        let label: String = if label.chars().count() <= max_chars {
            label.to_string()
        } else {
            label
                .chars()
                .take(max_chars - 3)
                .chain("...".chars())
                .collect()
        };
        scene.overlay.push(Mark::Text(Text::new(
            x0 + 30.0,
            row + 4.0,
            label,
            LEGEND_SIZE,
        )));
    }
}

/// The coherence panel's title.
const COHERENCE: &str = "Coherence";

/// The axis from exactly 0 to 1, ticks every 0.5 (0.25 on a panel tall
/// enough for five labels).
fn unit_axis(label: &str, height: f64) -> Axis {
    let step: f64 = if height >= 150.0 { 0.25 } else { 0.5 };
    let n = (1.0 / step).round() as usize;
    Axis {
        scale: crate::Scale::Linear,
        min: 0.0,
        max: 1.0,
        ticks: (0..=n)
            .map(|i| {
                let value = i as f64 * step;
                crate::Tick {
                    value,
                    label: Some(format!("{value}")),
                    major: true,
                }
            })
            .collect(),
        label: label.to_string(),
    }
}

/// Bars of `c`'s standard deviation `std_dev` in its magnitude (`db`) or
/// phase panel, in a light `color`, one per frequency, separated by NaN
/// breaks.
fn spread(c: &Curve, std_dev: &[f64], db: bool, color: Color) -> Line {
    let mut points = Vec::with_capacity(3 * c.f.len());
    for (j, (&f, &s)) in c.f.iter().zip(std_dev).enumerate() {
        let (m_db, deg) = (c.db[j], c.deg[j]);
        if !(f.is_finite() && m_db.is_finite() && deg.is_finite() && s.is_finite() && s >= 0.0) {
            continue;
        }
        let m = 10f64.powf(m_db / 20.0);
        let (lo, hi) = if db {
            let lo = (m - s).max(m * 1e-3);
            (20.0 * lo.log10(), 20.0 * (m + s).log10())
        } else {
            let half = if s < m {
                (s / m).asin().to_degrees()
            } else {
                180.0
            };
            (deg - half, deg + half)
        };
        points.extend([(f, lo), (f, hi), (f64::NAN, f64::NAN)]);
    }
    Line {
        points,
        stroke: Stroke {
            color: Color::rgba(color.r, color.g, color.b, 70),
            width: 1.0,
            dash: Dash::Solid,
        },
    }
}

/// What a legend row shows left of its label.
enum Swatch {
    Trace(Style, Color),
    Band(Color),
}

/// Smallest and largest finite value, if any.
fn finite_range(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .filter(|v| v.is_finite())
        .fold(None, |range, v| match range {
            None => Some((v, v)),
            Some((lo, hi)) => Some((v.min(lo), v.max(hi))),
        })
}

const LEGEND_SIZE: f64 = 11.0;

fn marker_size(line_width: f64) -> f64 {
    (2.5 * line_width).max(4.0)
}

/// One trace in plotted units; every vector has the trace's length, with
/// NaN for gaps (a NaN frequency gaps all three).
pub(crate) struct Curve {
    pub(crate) f: Vec<f64>,
    pub(crate) db: Vec<f64>,
    pub(crate) deg: Vec<f64>,
}

impl Curve {
    fn new(trace: &Trace) -> Curve {
        let n = trace.freq_hz.len();
        let (mut f, mut db, mut deg) = (vec![f64::NAN; n], vec![f64::NAN; n], vec![f64::NAN; n]);
        let mut last: Option<f64> = None;
        for (i, (&fi, h)) in trace.freq_hz.iter().zip(&trace.response).enumerate() {
            if !(fi > 0.0 && fi.is_finite()) {
                continue;
            }
            f[i] = fi;
            let mag = h.norm();
            if !(mag > 0.0 && mag.is_finite()) {
                continue;
            }
            db[i] = 20.0 * mag.log10();
            let raw = h.arg().to_degrees();
            let value = match last {
                // Start in [-180, 180): atan2 gives (-180, 180].
                None if raw >= 180.0 - 1e-9 => raw - 360.0,
                None => raw,
                Some(prev) => raw + 360.0 * ((prev - raw) / 360.0).round(),
            };
            deg[i] = value;
            last = Some(value);
        }
        Curve { f, db, deg }
    }
}

/// Shifts every trace after the first by the multiple of 360 degrees that
/// brings it nearest the first one.
fn align_phases(mut curves: Vec<Curve>) -> Vec<Curve> {
    let Some((first, rest)) = curves.split_first_mut() else {
        return curves;
    };
    let reference = Interp::new(&first.f, &first.deg);
    // The reference's phase with its line-to-line noise filtered, for
    // following its turns.
    let smooth = Interp::new(&first.f, &running_median(&first.deg, 4));
    let mean = |v: &mut dyn Iterator<Item = f64>| {
        let (sum, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
        (n > 0).then(|| sum / n as f64)
    };
    let first_mean = mean(&mut first.deg.iter().copied().filter(|v| v.is_finite()));
    for c in rest {
        // Compared where the traces start: unwrapping accumulates its
        // errors upward (noise between poorly excited lines adds turns),
        // so the lower half of the common frequencies (in log frequency)
        // decides, by the turn count most of its lines agree on.
        let diffs: Vec<(f64, f64)> =
            c.f.iter()
                .zip(&c.deg)
                .map(|(&f, &d)| (f, d - reference.at(f)))
                .filter(|(f, d)| f.is_finite() && d.is_finite())
                .collect();
        let shift = (!diffs.is_empty()).then(|| {
            let (lo, hi) = diffs.iter().fold((f64::INFINITY, 0.0f64), |(a, b), d| {
                (a.min(d.0), b.max(d.0))
            });
            let mid = (lo * hi).sqrt();
            let mut turns: BTreeMap<i64, usize> = BTreeMap::new();
            for (_, d) in diffs.iter().filter(|(f, _)| *f <= mid) {
                *turns.entry((d / 360.0).round() as i64).or_default() += 1;
            }
            // The most lines; a tie goes to the fewest turns.
            let best = turns
                .iter()
                .max_by(|a, b| a.1.cmp(b.1).then(b.0.abs().cmp(&a.0.abs())))
                .map_or(0, |(t, _)| *t);
            360.0 * best as f64
        });
        let offset = shift.or_else(|| {
            let own = mean(&mut c.deg.iter().copied().filter(|v| v.is_finite()));
            Some(own? - first_mean?)
        });
        if let Some(offset) = offset {
            let turns = (offset / 360.0).round();
            c.deg.iter_mut().for_each(|d| *d -= 360.0 * turns);
        }
        follow_turns(c, &smooth);
    }
    curves
}

/// Where the reference's unwrapped phase gains or loses whole turns that
/// the trace `c` does not (a measured phase through poorly excited lines,
/// or dynamics the model lacks), the trace follows it by whole turns, so it
/// is never drawn a multiple of 360 degrees away from the data: a turn is
/// taken where the trace is more than 240 degrees from the reference's
/// running median (the margin keeps noise from flipping it), and the trace
/// breaks there (that point's phase is left out).
fn follow_turns(c: &mut Curve, reference: &Interp) {
    let mut turns = 0.0;
    for (f, d) in c.f.iter().zip(c.deg.iter_mut()) {
        let r = reference.at(*f);
        if !(d.is_finite() && r.is_finite()) {
            continue;
        }
        let off = *d + 360.0 * turns - r;
        if off.abs() > 240.0 {
            turns -= (off / 360.0).round();
            *d = f64::NAN;
            continue;
        }
        *d += 360.0 * turns;
    }
}

/// The running median of `y` over `2 * half + 1` finite neighbours in
/// order (NaN where `y` is NaN).
fn running_median(y: &[f64], half: usize) -> Vec<f64> {
    let finite: Vec<(usize, f64)> = y
        .iter()
        .copied()
        .enumerate()
        .filter(|p| p.1.is_finite())
        .collect();
    let mut out = vec![f64::NAN; y.len()];
    for (k, &(i, _)) in finite.iter().enumerate() {
        let lo = k.saturating_sub(half);
        let hi = (k + half + 1).min(finite.len());
        let mut w: Vec<f64> = finite[lo..hi].iter().map(|p| p.1).collect();
        w.sort_by(f64::total_cmp);
        out[i] = w[w.len() / 2];
    }
    out
}

/// Linear interpolation over log frequency, NaN outside the data or next
/// to a gap.
struct Interp {
    points: Vec<(f64, f64)>,
}

impl Interp {
    fn new(f: &[f64], y: &[f64]) -> Interp {
        let mut points: Vec<(f64, f64)> = f
            .iter()
            .zip(y)
            .filter(|(f, _)| f.is_finite())
            .map(|(f, y)| (f.log10(), *y))
            .collect();
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        Interp { points }
    }

    fn at(&self, f: f64) -> f64 {
        let x = f.log10();
        let i = self.points.partition_point(|p| p.0 < x);
        match (self.points.get(i), i.checked_sub(1).map(|j| self.points[j])) {
            (Some(&(xi, yi)), _) if xi == x => yi,
            (Some(&(x1, y1)), Some((x0, y0))) => y0 + (y1 - y0) * (x - x0) / (x1 - x0),
            _ => f64::NAN,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The models' lines are drawn after (over) the measured points in
    /// every panel, whichever order the traces were added in.
    #[test]
    fn models_are_drawn_over_the_data() {
        let f: Vec<f64> = (1..200).map(f64::from).collect();
        let h: Vec<Complex64> = f.iter().map(|&f| Complex64::new(1.0 / f, -0.1)).collect();
        let mut scene = Bode::new("")
            .trace("model", &f, &h, Style::line())
            .trace("recording", &f, &h, Style::points())
            .scene();
        // The legend, drawn last, holds a marker of its own.
        scene.overlay.clear();
        let prims = scene.primitives();
        let last_marker = prims
            .iter()
            .rposition(|p| matches!(p, crate::scene::Prim::Marker { .. }))
            .expect("markers");
        let model = PALETTE[0];
        let first_model_line = prims
            .iter()
            .position(
                |p| matches!(p, crate::scene::Prim::Path { stroke, .. } if stroke.color == model),
            )
            .expect("model line");
        let first_marker = prims
            .iter()
            .position(|p| matches!(p, crate::scene::Prim::Marker { .. }))
            .unwrap();
        assert!(
            first_model_line > first_marker,
            "{first_model_line} {first_marker}"
        );
        // The last panel's markers come before its model line too.
        let last_model_line = prims
            .iter()
            .rposition(
                |p| matches!(p, crate::scene::Prim::Path { stroke, .. } if stroke.color == model),
            )
            .unwrap();
        assert!(
            last_model_line > last_marker,
            "{last_model_line} {last_marker}"
        );
    }

    fn trace(f: &[f64], h: &[Complex64]) -> Trace {
        Trace {
            label: String::new(),
            freq_hz: f.to_vec(),
            response: h.to_vec(),
            style: Style::line(),
            std_dev: None,
        }
    }

    /// A measured phase that loses a whole turn halfway (two poles the
    /// model lacks, or noise through poorly excited lines) takes the
    /// model's drawn phase with it: never more than 240 degrees from the
    /// data, with one break where it turns.
    #[test]
    fn models_follow_the_turns_of_the_data() {
        let f: Vec<f64> = (1..=200).map(|k| k as f64).collect();
        let data: Vec<Complex64> = f
            .iter()
            .map(|&f| {
                // 170 degrees, falling by a whole turn between 90 and 110 Hz.
                let turn = ((f - 90.0) / 20.0).clamp(0.0, 1.0);
                polar(170.0 - 360.0 * turn + 3.0 * (f * 0.7).sin())
            })
            .collect();
        let model = vec![polar(179.0); f.len()];
        let curves = align_phases(vec![
            Curve::new(&trace(&f, &data)),
            Curve::new(&trace(&f, &model)),
        ]);
        let (d, m) = (&curves[0].deg, &curves[1].deg);
        let breaks = m.iter().filter(|v| v.is_nan()).count();
        assert_eq!(breaks, 1);
        for (a, b) in d.iter().zip(m).filter(|p| p.1.is_finite()) {
            assert!((a - b).abs() < 240.0, "{a} against {b}");
        }
        // Above the turn the model is drawn 360 degrees lower than below.
        assert!(
            (m[10] - m[190] - 360.0).abs() < 1e-9,
            "{} {}",
            m[10],
            m[190]
        );
    }

    fn polar(deg: f64) -> Complex64 {
        Complex64::from_polar(1.0, deg.to_radians())
    }

    #[test]
    fn phase_is_unwrapped_and_starts_lagging() {
        let f = [1.0, 2.0, 3.0, 4.0, 5.0];
        let h: Vec<_> = [-170.0, -190.0, -260.0, -350.0, -370.0].map(polar).to_vec();
        let c = Curve::new(&trace(&f, &h));
        let expected = [-170.0, -190.0, -260.0, -350.0, -370.0];
        assert!(
            c.deg
                .iter()
                .zip(expected)
                .all(|(a, b)| (a - b).abs() < 1e-9),
            "{:?}",
            c.deg
        );
        // A real negative response starts at -180, not +180.
        let c = Curve::new(&trace(&[1.0], &[Complex64::new(-1.0, 0.0)]));
        assert_eq!(c.deg, [-180.0]);
    }

    #[test]
    fn a_model_is_never_a_turn_away_from_noisy_data() {
        // Data: a dead time over 1-2000 Hz whose upper decade is noise, so
        // its unwrapped phase gains turns there; the model: the same dead
        // time. Aligned where they start, the model sits on the data at
        // every line below the noise, not a multiple of 360 deg away.
        let f: Vec<f64> = (1..=2000).map(|k| k as f64).collect();
        let mut state = 3u64;
        let mut noise = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 360.0 - 180.0
        };
        let delay = |f: f64| -360.0 * f * 2e-4;
        let data: Vec<Complex64> = f
            .iter()
            .map(|&f| polar(delay(f) + if f > 200.0 { noise() } else { 0.0 }))
            .collect();
        let model: Vec<Complex64> = f.iter().map(|&f| polar(delay(f))).collect();
        let curves = align_phases(vec![
            Curve::new(&trace(&f, &data)),
            Curve::new(&trace(&f, &model)),
        ]);
        for ((f, m), d) in f.iter().zip(&curves[1].deg).zip(&curves[0].deg).take(200) {
            assert!((m - d).abs() < 1e-6, "line {f}: {m} vs {d}");
        }
    }

    #[test]
    fn gaps_are_nan_and_unwrapping_spans_them() {
        let f = [1.0, 2.0, 0.0, 4.0, f64::NAN, 6.0];
        let h = [
            polar(170.0),
            polar(179.0),
            polar(0.0),
            Complex64::new(f64::NAN, 0.0),
            polar(0.0),
            polar(-170.0),
        ];
        let c = Curve::new(&trace(&f, &h));
        assert!(c.f[2].is_nan() && c.f[4].is_nan() && c.db[3].is_nan() && c.deg[3].is_nan());
        assert!((c.deg[5] - 190.0).abs() < 1e-9);
    }

    #[test]
    fn later_traces_move_next_to_the_first() {
        let f = [1.0, 10.0, 100.0];
        let first = Curve::new(&trace(&f, &[-170.0, -185.0, -200.0].map(polar)));
        // Starts at +175 on its own: the same as -185, one turn away.
        let second = Curve::new(&trace(&f, &[175.0, 170.0, 165.0].map(polar)));
        // Does not overlap the first trace: compared by means.
        let third = Curve::new(&trace(&[1e4, 1e5], &[100.0, 90.0].map(polar)));
        let aligned = align_phases(vec![first, second, third]);
        assert!(
            (aligned[1].deg[0] + 185.0).abs() < 1e-9,
            "{:?}",
            aligned[1].deg
        );
        assert!(
            (aligned[2].deg[0] + 260.0).abs() < 1e-9,
            "{:?}",
            aligned[2].deg
        );
    }

    #[test]
    fn interpolation_over_log_frequency() {
        let at = Interp::new(&[100.0, 1.0, 10.0, f64::NAN], &[2.0, 0.0, 1.0, 5.0]);
        assert_eq!(at.at(10.0), 1.0);
        assert!((at.at(10f64.sqrt()) - 0.5).abs() < 1e-12);
        assert!(at.at(0.5).is_nan() && at.at(1000.0).is_nan() && at.at(-1.0).is_nan());
    }
}
