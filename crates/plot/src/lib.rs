//! # plot: small, deterministic figures for `mms` reports
//!
//! The reports of `mms identify` and `mms diagnose` show measured FRFs,
//! fitted models and their residuals as Bode plots. This crate draws them
//! as SVG (for HTML and Markdown) and PNG (for anything else) without a
//! plotting or image stack: its own scene model, SVG writer,
//! anti-aliasing rasteriser and PNG encoder, with a bundled font (DejaVu
//! Sans, rasterised by `ab_glyph`), `num-complex` and `miniz_oxide`
//! (deflate) underneath. The same input always gives the same bytes, so
//! reports can be diffed and snapshotted.
//!
//! - [`Bode`] builds a figure from traces (frequency in Hz, complex
//!   response), shaded [bands](Bode::band) and an optional
//!   [residual](Bode::residual) panel, then renders it with
//!   [`Bode::to_svg`] or [`Bode::to_png`].
//! - [`Scene`] is the backend-independent description underneath (panels
//!   with [`Axis`] pairs, lines, markers, bands, text), usable for other
//!   plots too.
//!
//! ```
//! use num_complex::Complex64;
//! use plot::{Bode, Style};
//!
//! // A two-mass system's velocity response and a slightly detuned model.
//! let freq: Vec<f64> = (0..400).map(|i| 10f64.powf(0.5 + i as f64 / 160.0)).collect();
//! let two_mass = |k: f64| {
//!     move |f: &f64| {
//!         let s = Complex64::new(0.0, 2.0 * std::f64::consts::PI * f);
//!         let (j1, j2, d) = (1e-3, 2e-3, 0.05);
//!         (j2 * s * s + d * s + k) / (s * (j1 * j2 * s * s + (j1 + j2) * (d * s + k)))
//!     }
//! };
//! let measured: Vec<Complex64> = freq.iter().map(two_mass(2000.0)).collect();
//! let model: Vec<Complex64> = freq.iter().map(two_mass(2300.0)).collect();
//! let bode = Bode::new("Axis X: velocity / torque")
//!     .trace("measured", &freq, &measured, Style::points())
//!     .trace("fitted model", &freq, &model, Style::line())
//!     .band(150.0, 260.0, "mismatch")
//!     .residual();
//! let svg: String = bode.to_svg();
//! let png: Vec<u8> = bode.to_png();
//! assert!(svg.ends_with("</svg>\n"));
//! assert_eq!(&png[1..4], b"PNG");
//! assert_eq!(png, bode.to_png());
//! ```

#![warn(missing_docs)]

mod axis;
mod bode;
mod font;
mod html;
mod png;
mod raster;
mod scene;
mod svg;

pub use axis::{Axis, Scale, Tick};
pub use bode::{Bode, Style};
pub use num_complex::Complex64;
pub use raster::PNG_SCALE;
pub use scene::{
    Anchor, Band, Color, Dash, Line, Mark, MarkerShape, Markers, Panel, Rect, Scene, Stroke, Text,
    PALETTE,
};
