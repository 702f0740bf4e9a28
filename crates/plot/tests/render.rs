//! End-to-end checks of both backends: SVG is parsed by a small checker,
//! PNG by a small decoder written here (chunk CRCs, inflate, filter 0 rows),
//! independently of the crate's own encoder.

use num_complex::Complex64;
use plot::{Bode, Color, Panel, Scene, Style, PALETTE};

// ---------------------------------------------------------------- SVG ---

#[derive(Debug)]
struct Element {
    name: String,
    attrs: Vec<(String, String)>,
    text: String,
}

impl Element {
    fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }
}

fn check_entities(s: &str) {
    let mut rest = s;
    while let Some(i) = rest.find('&') {
        rest = &rest[i..];
        let ok = ["&amp;", "&lt;", "&gt;", "&quot;", "&#39;"]
            .iter()
            .any(|e| rest.starts_with(e));
        assert!(ok, "bare '&' in {s:?}");
        rest = &rest[1..];
    }
    assert!(!s.contains('<'), "'<' in {s:?}");
}

/// Parses the SVG subset the crate writes: one root, balanced tags,
/// `name="value"` attributes without duplicates, escaped text. Returns all
/// elements in document order, and checks the attributes each kind needs.
fn check_svg(svg: &str) -> Vec<Element> {
    assert!(
        svg.starts_with("<svg ") && svg.ends_with("</svg>\n"),
        "not a bare <svg> document"
    );
    let mut elements: Vec<Element> = Vec::new();
    let mut open: Vec<(String, usize)> = Vec::new();
    let mut roots = 0;
    let mut rest = svg;
    while let Some(start) = rest.find('<') {
        let text = &rest[..start];
        check_entities(text);
        if let Some((_, index)) = open.last() {
            elements[*index].text.push_str(text);
        } else {
            assert!(text.trim().is_empty(), "text outside the root: {text:?}");
        }
        let end = rest[start..].find('>').expect("unclosed tag") + start;
        let tag = &rest[start + 1..end];
        rest = &rest[end + 1..];
        if let Some(name) = tag.strip_prefix('/') {
            let (expected, _) = open.pop().expect("close without open");
            assert_eq!(name, expected, "mismatched close tag");
            continue;
        }
        let (tag, self_closing) = match tag.strip_suffix('/') {
            Some(t) => (t, true),
            None => (tag, false),
        };
        let name_end = tag.find(|c: char| c.is_whitespace()).unwrap_or(tag.len());
        let name = &tag[..name_end];
        assert!(
            !name.is_empty() && name.chars().all(|c| c.is_ascii_alphabetic()),
            "tag {name:?}"
        );
        let mut attrs: Vec<(String, String)> = Vec::new();
        let mut a = tag[name_end..].trim_start();
        while !a.is_empty() {
            let eq = a
                .find('=')
                .unwrap_or_else(|| panic!("attribute without value in <{tag}>"));
            let key = &a[..eq];
            assert!(
                key.chars()
                    .all(|c| c.is_ascii_alphabetic() || c == '-' || c == ':'),
                "{key:?}"
            );
            assert!(
                a[eq + 1..].starts_with('"'),
                "unquoted attribute in <{tag}>"
            );
            let close = a[eq + 2..].find('"').expect("unterminated attribute") + eq + 2;
            let value = &a[eq + 2..close];
            check_entities(value);
            assert!(
                attrs.iter().all(|(k, _)| k != key),
                "duplicate {key} in <{tag}>"
            );
            attrs.push((key.to_string(), value.to_string()));
            let after = &a[close + 1..];
            assert!(
                after.is_empty() || after.starts_with(' '),
                "no space after attribute in <{tag}>"
            );
            a = after.trim_start();
        }
        if open.is_empty() {
            roots += 1;
        }
        elements.push(Element {
            name: name.to_string(),
            attrs,
            text: String::new(),
        });
        if !self_closing {
            open.push((name.to_string(), elements.len() - 1));
        }
    }
    assert!(open.is_empty(), "unclosed elements {open:?}");
    assert_eq!(roots, 1);

    let number = |v: &str| {
        let n: f64 = v.parse().unwrap_or_else(|_| panic!("not a number: {v:?}"));
        assert!(
            n.is_finite() && v.split('.').nth(1).iter().all(|d| d.len() <= 2),
            "{v:?}"
        );
        n
    };
    for e in &elements {
        let required: &[&str] = match e.name.as_str() {
            "svg" => &["xmlns", "version", "width", "height", "viewBox"],
            "rect" => &["width", "height", "fill"],
            "polyline" => &["points", "stroke", "stroke-width", "fill"],
            "path" => &["d", "stroke", "stroke-width"],
            "text" => &["x", "y", "font-size", "fill"],
            "title" => &[],
            other => panic!("unexpected element <{other}>"),
        };
        for key in required {
            assert!(e.attr(key).is_some(), "<{}> lacks {key}", e.name);
        }
        for key in ["x", "y", "width", "height", "stroke-width", "font-size"] {
            e.attr(key).map(number);
        }
        if let Some(points) = e.attr("points") {
            let coords: Vec<f64> = points.split([' ', ',']).map(number).collect();
            assert!(
                coords.len() >= 4 && coords.chunks_exact(2).remainder().is_empty(),
                "points {points:?}"
            );
        }
    }
    assert_eq!(
        elements[0].attr("xmlns"),
        Some("http://www.w3.org/2000/svg")
    );
    elements
}

fn polylines<'a>(elements: &'a [Element], color: Color) -> Vec<Vec<(f64, f64)>> {
    let hex = format!("#{:02x}{:02x}{:02x}", color.r, color.g, color.b);
    let parse = |e: &'a Element| {
        let pairs = e.attr("points").unwrap().split(' ');
        pairs
            .map(|p| {
                let (x, y) = p.split_once(',').unwrap();
                (x.parse().unwrap(), y.parse().unwrap())
            })
            .collect()
    };
    elements
        .iter()
        .filter(|e| e.name == "polyline" && e.attr("stroke") == Some(&hex))
        .map(parse)
        .collect()
}

// ---------------------------------------------------------------- PNG ---

struct Image {
    w: usize,
    h: usize,
    rgb: Vec<u8>,
}

impl Image {
    fn at(&self, x: usize, y: usize) -> [u8; 3] {
        let i = (y * self.w + x) * 3;
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }
}

/// Bitwise CRC-32, independent of the crate's table-driven one.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

fn decode_png(png: &[u8]) -> Image {
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let mut pos = 8;
    let (mut kinds, mut ihdr, mut idat) = (Vec::new(), Vec::new(), Vec::new());
    while pos < png.len() {
        let len = u32::from_be_bytes(png[pos..pos + 4].try_into().unwrap()) as usize;
        let kind = &png[pos + 4..pos + 8];
        let data = &png[pos + 8..pos + 8 + len];
        let crc = u32::from_be_bytes(png[pos + 8 + len..pos + 12 + len].try_into().unwrap());
        assert_eq!(
            crc,
            crc32(&png[pos + 4..pos + 8 + len]),
            "CRC of {}",
            String::from_utf8_lossy(kind)
        );
        match kind {
            b"IHDR" => ihdr = data.to_vec(),
            b"IDAT" => idat.extend_from_slice(data),
            _ => {}
        }
        kinds.push(String::from_utf8(kind.to_vec()).unwrap());
        pos += 12 + len;
    }
    assert_eq!(pos, png.len());
    assert_eq!(kinds.first().map(String::as_str), Some("IHDR"));
    assert_eq!(kinds.last().map(String::as_str), Some("IEND"));
    assert_eq!(ihdr.len(), 13);
    let w = u32::from_be_bytes(ihdr[0..4].try_into().unwrap()) as usize;
    let h = u32::from_be_bytes(ihdr[4..8].try_into().unwrap()) as usize;
    assert!(w > 0 && h > 0);
    assert_eq!(&ihdr[8..], &[8, 2, 0, 0, 0], "8-bit RGB, no interlace");
    let raw = miniz_oxide::inflate::decompress_to_vec_zlib(&idat).expect("valid zlib stream");
    assert_eq!(raw.len(), h * (1 + 3 * w));
    // Filter types 0 (none) and 2 (up: the byte above is added back).
    let mut rgb: Vec<u8> = Vec::with_capacity(w * h * 3);
    for (i, row) in raw.chunks_exact(1 + 3 * w).enumerate() {
        match row[0] {
            0 => rgb.extend_from_slice(&row[1..]),
            2 => {
                for (j, &b) in row[1..].iter().enumerate() {
                    let above = if i > 0 { rgb[(i - 1) * 3 * w + j] } else { 0 };
                    rgb.push(b.wrapping_add(above));
                }
            }
            f => panic!("filter type {f}"),
        }
    }
    Image { w, h, rgb }
}

// ------------------------------------------------------------- inputs ---

fn log_grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let step = (hi / lo).log10() / (n - 1).max(1) as f64;
    (0..n).map(|i| lo * 10f64.powf(step * i as f64)).collect()
}

/// 1 / (1 + s / (2 pi fc)).
fn first_order(freq: &[f64], fc: f64) -> Vec<Complex64> {
    freq.iter()
        .map(|&f| 1.0 / Complex64::new(1.0, f / fc))
        .collect()
}

fn three_traces(n: usize) -> Bode {
    let f = log_grid(1.0, 5000.0, n);
    let two_mass = |k: f64, d: f64| -> Vec<Complex64> {
        f.iter()
            .map(|&f| {
                let s = Complex64::new(0.0, 2.0 * std::f64::consts::PI * f);
                let (j1, j2) = (1e-3, 2e-3);
                (j2 * s * s + d * s + k) / (s * (j1 * j2 * s * s + (j1 + j2) * (d * s + k)))
            })
            .collect()
    };
    Bode::new("Axis X & Y: <velocity> / torque")
        .trace(
            "measured",
            &f,
            &two_mass(2000.0, 0.05),
            Style::points().width(1.0),
        )
        .trace("fitted model", &f, &two_mass(2300.0, 0.05), Style::line())
        .trace("prior model", &f, &two_mass(1800.0, 0.2), Style::dashed())
        .band(150.0, 260.0, "mismatch")
        .band(1000.0, 1200.0, "mismatch")
        .residual()
}

fn expected_pixel(panel: &Panel, f: f64, v: f64) -> (f64, f64) {
    // From the axis ranges alone, not through the crate's mapping.
    let r = panel.rect;
    let (x, y) = (&panel.x, &panel.y);
    let fx = (f.log10() - x.min.log10()) / (x.max.log10() - x.min.log10());
    let fy = (y.max - v) / (y.max - y.min);
    (r.x + r.w * fx, r.y + r.h * fy)
}

// -------------------------------------------------------------- tests ---

#[test]
fn svg_of_a_full_figure_is_well_formed() {
    let svg = three_traces(500).to_svg();
    let elements = check_svg(&svg);
    let count = |name: &str| elements.iter().filter(|e| e.name == name).count();
    assert_eq!(count("title"), 1);
    assert!(elements
        .iter()
        .any(|e| e.name == "title" && e.text == "Axis X &amp; Y: &lt;velocity&gt; / torque"));
    // Traces: the model in all three panels and the legend.
    assert_eq!(polylines(&elements, PALETTE[1]).len(), 4);
    assert!(elements
        .iter()
        .any(|e| e.attr("stroke-dasharray").is_some()));
    // Measured points: one dot path per panel and one in the legend.
    let dots = elements
        .iter()
        .filter(|e| e.name == "path" && e.attr("stroke") == Some("#0072b2"))
        .count();
    assert_eq!(dots, 4);
    // Tick labels with SI suffixes, axis titles, legend entries (the band
    // label once, though two bands carry it).
    let texts: Vec<&str> = elements
        .iter()
        .filter(|e| e.name == "text")
        .map(|e| e.text.as_str())
        .collect();
    for label in [
        "10",
        "100",
        "1k",
        "Frequency [Hz]",
        "Magnitude [dB]",
        "Phase [deg]",
        "Residual [dB]",
    ] {
        assert!(texts.contains(&label), "{label} missing from {texts:?}");
    }
    assert_eq!(texts.iter().filter(|t| **t == "mismatch").count(), 1);
    // Bands: translucent rectangles in each panel.
    let bands = elements
        .iter()
        .filter(|e| e.name == "rect" && e.attr("fill-opacity").is_some())
        .count();
    assert_eq!(bands, 2 * 3 + 1);
}

#[test]
fn first_order_corner_lands_at_minus_3_db_and_minus_45_degrees() {
    let fc = 100.0;
    // Not symmetric about the corner: the phase of 1/(1+s) is point
    // symmetric there, and collinear points would be simplified away.
    let f = [fc / 10.0, fc, fc * 3.0, fc * 10.0];
    let bode = Bode::new("1/(1+s)").trace("H", &f, &first_order(&f, fc), Style::line());
    let scene = bode.scene();
    let elements = check_svg(&bode.to_svg());
    let lines = polylines(&elements, PALETTE[0]);
    assert_eq!(lines.len(), 3, "magnitude, phase, legend");
    let minus_3_db = 20.0 * 0.5f64.sqrt().log10();
    assert!((minus_3_db + 3.0103).abs() < 1e-4);
    for (panel, line, value) in [
        (&scene.panels[0], &lines[0], minus_3_db),
        (&scene.panels[1], &lines[1], -45.0),
    ] {
        assert!(panel.y.min < value && value < panel.y.max);
        let (x, y) = expected_pixel(panel, fc, value);
        // The corner is the second point; SVG keeps two decimals.
        assert_eq!(line.len(), 4);
        let (px, py) = line[1];
        assert!(
            (px - x).abs() <= 0.0051 && (py - y).abs() <= 0.0051,
            "({px}, {py}) vs ({x}, {y})"
        );
        // The frequency axis spans the data exactly.
        assert!((line[0].0 - panel.rect.x).abs() < 0.01);
        assert!((line[3].0 - (panel.rect.x + panel.rect.w)).abs() < 0.01);
    }
}

#[test]
fn output_is_deterministic() {
    let (a, b) = (three_traces(300), three_traces(300));
    assert_eq!(a.to_svg(), b.to_svg());
    assert_eq!(a.to_png(), b.to_png());
    assert_eq!(a.to_png(), a.clone().to_png());
}

#[test]
fn png_pixels_show_lines_background_band_and_legend() {
    let f = log_grid(1.0, 1000.0, 50);
    let half = vec![Complex64::new(0.5, 0.0); f.len()];
    let double = vec![Complex64::new(0.0, 2.0); f.len()];
    let bode = Bode::new("levels")
        .trace("at -6 dB", &f, &half, Style::line().width(2.0))
        .trace("at +6 dB", &f, &double, Style::line().width(2.0))
        .band(20.0, 50.0, "band");
    let scene = bode.scene();
    let img = decode_png(&bode.to_png());
    // The PNG is drawn at PNG_SCALE device pixels per scene pixel.
    let k = plot::PNG_SCALE as usize;
    let kf = k as f64;
    assert_eq!(
        (img.w, img.h),
        (k * scene.width as usize, k * scene.height as usize)
    );
    assert!(img.w >= 1600, "{} px wide", img.w);

    let white = [255, 255, 255];
    assert_eq!(img.at(0, 0), white);
    assert_eq!(img.at(img.w - 1, img.h - 1), white);
    assert_eq!(
        img.at(img.w / 2, k * (scene.panels[0].rect.y as usize - 2)),
        white,
        "between title and panel"
    );

    let mag = &scene.panels[0];
    let rgb = |c: Color| [c.r, c.g, c.b];
    for (db, color) in [
        (20.0 * 0.5f64.log10(), PALETTE[0]),
        (20.0 * 2f64.log10(), PALETTE[1]),
    ] {
        // A 2 px line (4 device pixels) centred on y fully covers the
        // pixel row whose centre is within a pixel of y: floor(y).
        let (x, y) = expected_pixel(mag, 3.0, db);
        let (x, row) = ((kf * x).round() as usize, (kf * y).floor() as usize);
        assert_eq!(img.at(x, row), rgb(color), "row {row} at {db} dB");
        assert_ne!(img.at(x, row - 4), rgb(color));
        assert_ne!(img.at(x, row + 4), rgb(color));
    }

    // Inside the band, away from lines and grid: grey over white.
    let (bx, _) = expected_pixel(mag, 31.0, 0.0);
    let (_, by) = expected_pixel(mag, 31.0, (mag.y.min + 3.0 * mag.y.max) / 4.0);
    let [r, g, b] = img.at(
        (kf * bx).round() as usize,
        (kf * (by + 3.0)).round() as usize,
    );
    assert!(r == g && g == b && r < 240 && r > 150, "band pixel {r}");

    // The legend: ink where each label is, white right after it (the
    // font advances less than 0.7 em per character of these labels).
    let legend: Vec<&plot::Text> = scene
        .overlay
        .iter()
        .filter_map(|m| match m {
            plot::Mark::Text(t) if t.content.starts_with("at ") || t.content == "band" => Some(t),
            _ => None,
        })
        .collect();
    assert_eq!(legend.len(), 3);
    for t in legend {
        let (x0, y0) = ((kf * t.x) as usize, (kf * t.y) as usize);
        let width = (kf * 0.7 * t.size * t.content.len() as f64) as usize;
        let above = (kf * 0.8 * t.size) as usize;
        let ink = |xs: std::ops::Range<usize>| {
            xs.flat_map(|x| (y0 - above..y0).map(move |y| (x, y)))
                .filter(|&(x, y)| img.at(x, y)[0] < 128)
                .count()
        };
        assert!(
            ink(x0..x0 + width) >= 5 * t.content.len(),
            "no text for {:?}",
            t.content
        );
        assert_eq!(ink(x0 + width..(x0 + width + 20).min(img.w)), 0);
    }
}

#[test]
fn nan_and_bad_frequencies_break_the_line() {
    let f = [1.0, 2.0, 3.0, 4.0, 0.0, 6.0, 7.0, 8.0, 9.0, 10.0];
    let mut h = first_order(&f, 3.0);
    h[2] = Complex64::new(f64::NAN, 0.0);
    h[7] = Complex64::new(0.0, 0.0);
    let svg = Bode::new("").trace("gappy", &f, &h, Style::line()).to_svg();
    let elements = check_svg(&svg);
    // Runs: [1, 2], [4], [6, 7], [9, 10], in magnitude and phase, + legend.
    let lines = polylines(&elements, PALETTE[0]);
    assert_eq!(lines.len(), 4 + 4 + 1);
    // The lone point at 4 Hz is a zero-length run, drawn as a dot.
    assert_eq!(lines[1].len(), 2);
    assert_eq!(lines[1][0], lines[1][1]);
}

#[test]
fn degenerate_input_renders_without_panic() {
    let nan = Complex64::new(f64::NAN, f64::NAN);
    let one = Complex64::new(1.0, 0.0);
    let cases: Vec<(&str, Bode)> = vec![
        ("nothing", Bode::new("")),
        ("empty residual", Bode::new("").residual()),
        (
            "empty trace",
            Bode::new("t")
                .trace("empty", &[], &[], Style::line())
                .residual(),
        ),
        (
            "all nan",
            Bode::new("t").trace("nan", &[1.0, 2.0], &[nan, nan], Style::points()),
        ),
        (
            "nan freq",
            Bode::new("t").trace("nan", &[f64::NAN, -1.0, 0.0], &[one; 3], Style::line()),
        ),
        (
            "single point",
            Bode::new("t")
                .trace("one", &[50.0], &[one], Style::line())
                .residual(),
        ),
        (
            "single point dashed",
            Bode::new("t").trace("one", &[50.0], &[one], Style::dotted()),
        ),
        (
            "constant",
            Bode::new("t")
                .trace("c", &[1.0, 10.0, 100.0], &[one; 3], Style::line())
                .residual(),
        ),
        (
            "zeros",
            Bode::new("t").trace(
                "0",
                &[1.0, 10.0],
                &[Complex64::new(0.0, 0.0); 2],
                Style::line(),
            ),
        ),
        (
            "lengths differ",
            Bode::new("t").trace("short", &[1.0, 2.0, 3.0], &[one], Style::line()),
        ),
        (
            "infinite",
            Bode::new("t").trace(
                "inf",
                &[1.0, f64::INFINITY],
                &[one, Complex64::new(f64::INFINITY, 0.0)],
                Style::line(),
            ),
        ),
        (
            "huge range",
            Bode::new("t")
                .trace(
                    "tiny",
                    &[1e-9, 1e12],
                    &[Complex64::new(1e-300, 0.0), Complex64::new(1e300, 1.0)],
                    Style::line(),
                )
                .residual(),
        ),
        (
            "zero-width band",
            Bode::new("t")
                .trace("c", &[1.0, 10.0], &[one; 2], Style::line())
                .band(5.0, 5.0, "zero"),
        ),
        (
            "odd bands",
            Bode::new("t")
                .band(f64::NAN, 3.0, "nan")
                .band(300.0, 30.0, "")
                .band(-5.0, 0.0, "neg")
                .band(1e-20, 1e20, "all"),
        ),
        (
            "bad widths",
            Bode::new("t")
                .trace("nan", &[1.0, 2.0], &[one; 2], Style::line().width(f64::NAN))
                .trace("neg", &[1.0, 2.0], &[one; 2], Style::points().width(-1.0))
                .trace("", &[1.0, 2.0], &[one; 2], Style::dashed().width(0.0)),
        ),
        (
            "tiny figure",
            Bode::new("t")
                .trace("c", &[1.0, 10.0], &[one; 2], Style::line())
                .size(0, 0),
        ),
        (
            "odd labels",
            Bode::new("\u{3b1} < \u{3b2} & \u{1}")
                .trace("\u{b0} \" ' > &amp;", &[1.0, 2.0], &[one; 2], Style::line())
                .trace("x".repeat(300), &[1.0, 2.0], &[one; 2], Style::line()),
        ),
    ];
    for (name, bode) in cases {
        let svg = bode.to_svg();
        check_svg(&svg);
        let png = decode_png(&bode.to_png());
        assert!(png.w >= 200 && png.h >= 160, "{name}");
        assert_eq!(svg, bode.to_svg(), "{name}");
    }
}

#[test]
fn phase_of_later_traces_sits_near_the_first() {
    // A double integrator is at -180 deg; the same response times -1 is at
    // 0 deg. A pure delay lags without bound and is unwrapped.
    let f = log_grid(1.0, 100.0, 40);
    let plant: Vec<Complex64> = f
        .iter()
        .map(|&f| Complex64::new(-1.0 / (f * f), 0.0))
        .collect();
    let delay: Vec<Complex64> = f
        .iter()
        .map(|&f| Complex64::from_polar(1.0, -2.0 * std::f64::consts::PI * f * 0.01))
        .collect();
    let scene = Bode::new("")
        .trace("plant", &f, &plant, Style::line())
        .trace("delay", &f, &delay, Style::line())
        .scene();
    let phase = &scene.panels[1];
    assert!(phase.lines[0]
        .points
        .iter()
        .all(|&(_, d)| (d + 180.0).abs() < 1e-9));
    let delay_deg: Vec<f64> = phase.lines[1].points.iter().map(|p| p.1).collect();
    for (d, f) in delay_deg.iter().zip(&f) {
        assert!((d + 360.0 * f * 0.01).abs() < 1e-6, "{d} at {f} Hz");
    }
}

#[test]
fn a_scene_of_its_own_renders() {
    let mut scene = Scene::new(320, 200);
    scene
        .overlay
        .push(plot::Mark::Text(plot::Text::new(10.0, 20.0, "hello", 10.0)));
    scene.overlay.push(plot::Mark::Rect(
        plot::Rect::new(10.25, 30.125, 50.0, 20.0),
        Color::rgba(0, 0, 0, 128),
    ));
    let img = decode_png(&scene.to_png());
    // At two device pixels per scene pixel the rectangle starts at x =
    // 20.5, y = 60.25. Black at alpha 128/255 over white; edges by covered
    // area: half of column 20, three quarters of row 60.
    assert_eq!(plot::PNG_SCALE, 2);
    assert_eq!(img.at(60, 80), [127, 127, 127]);
    assert_eq!(img.at(19, 80), [255, 255, 255]);
    assert_eq!(img.at(20, 70), [191, 191, 191]);
    assert_eq!(img.at(60, 60), [159, 159, 159]);
    // "hello" at (10, 20), an em of 10: dark ink above the baseline at y =
    // 40 device pixels.
    let ink = (20..80)
        .flat_map(|x| (26..40).map(move |y| (x, y)))
        .filter(|&(x, y)| img.at(x, y)[0] < 64);
    assert!(ink.count() > 30);
    let elements = check_svg(&scene.to_svg());
    assert!(elements
        .iter()
        .any(|e| e.name == "text" && e.text == "hello"));

    // Hand-built oddities: a sliver of a panel, an empty axis range, NaN
    // text and sizes are skipped, not drawn as "NaN" or panics.
    let mut scene = Scene::new(0, 0);
    let empty = plot::Axis {
        min: 1.0,
        max: 1.0,
        ..plot::Axis::linear(0.0, 1.0, "")
    };
    let x = plot::Axis::linear(0.0, 1.0, "x");
    let mut panel = Panel::new(plot::Rect::new(5.0, 5.0, 0.3, 0.2), x, empty);
    let stroke = plot::Stroke {
        color: Color::BLACK,
        width: 1.0,
        dash: plot::Dash::Dashed,
    };
    panel.lines.push(plot::Line {
        points: vec![(0.0, 0.0), (1.0, 1.0)],
        stroke,
    });
    scene.panels.push(panel);
    scene.overlay.push(plot::Mark::Text(plot::Text::new(
        f64::NAN,
        1.0,
        "nan",
        10.0,
    )));
    scene.overlay.push(plot::Mark::Text(plot::Text::new(
        1.0,
        1.0,
        "tiny",
        f64::NAN,
    )));
    let svg = scene.to_svg();
    check_svg(&svg);
    assert!(!svg.contains("NaN") && !svg.contains("inf"));
    let img = decode_png(&scene.to_png());
    let k = plot::PNG_SCALE as usize;
    assert_eq!((img.w, img.h), (k, k));
}
