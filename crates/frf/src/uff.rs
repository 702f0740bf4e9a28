//! Universal File Format, dataset 58 ("function at nodal DOF"): the ASCII
//! exchange format of modal testing for FRFs, spectra and time histories.
//!
//! A universal file is a sequence of datasets, each between two lines
//! holding `-1` right-justified in columns 1-6. The line after the opening
//! one gives the dataset type (`58`; `58b` for the binary variant). A
//! dataset 58 has 11 header records after that line:
//!
//! | record | content |
//! |---|---|
//! | 1-5 | ID lines (description, run, date, load case, ...) |
//! | 6 | function type (4 = FRF, 6 = coherence, ...), function id, version, load case, response entity/node/direction, reference entity/node/direction: `2(I5,I10),2(1X,10A1,I10,I4)` |
//! | 7 | ordinate data type (2/4 real single/double, 5/6 complex single/double), number of values, abscissa spacing (1 even, 0 uneven), abscissa minimum and increment, z value: `3I10,3E13.5` |
//! | 8-11 | abscissa, ordinate, ordinate denominator and z-axis characteristics: specific data type (17 time, 18 frequency, ...), length/force/temperature unit exponents, axis label, units label: `I10,3I5,2(1X,20A1)` |
//!
//! then the values in fixed-width E fields: `6E13.5` for single precision,
//! `4E20.12` for double precision with even abscissa, and with uneven
//! abscissa each point's x in `E13.5` before its value(s) (`2(E13.5,E20.12)`
//! real, `E13.5,2E20.12` complex).
//!
//! [`parse_uff`] reads every dataset 58 of a file (other dataset types are
//! skipped); [`Uff58::to_frf`] makes an [`Frf`] of one; [`write_uff58`] and
//! [`write_frf_uff`] write complex-double (and, for coherence, real-double)
//! datasets. Binary datasets (58b) are recognised and refused with a clear
//! error. Fields are read by their fixed widths; a line whose fields do not
//! parse that way is read as whitespace-separated numbers (some writers do
//! not keep to the widths).
//!
//! ```
//! use frf::uff::{parse_uff, write_frf_uff, Spacing};
//! use frf::{Complex64, Frf};
//!
//! let freq: Vec<f64> = (1..=16).map(|k| k as f64 * 0.5).collect();
//! let resp: Vec<Complex64> = freq.iter().map(|f| Complex64::new(1.0, -f)).collect();
//! let frf = Frf::new(freq, resp, None).unwrap();
//! let text = write_frf_uff(&frf, Spacing::Even)?;
//! let datasets = parse_uff(text.as_bytes())?;
//! assert_eq!(datasets.len(), 1);
//! assert_eq!(datasets[0].function_type, 4);
//! let back = datasets[0].to_frf()?;
//! assert_eq!(back.freq_hz(), frf.freq_hz());
//! assert!((back.response()[3] - frf.response()[3]).norm() < 1e-12);
//! # Ok::<(), frf::uff::UffError>(())
//! ```

use crate::{Frf, MIN_LINES};
use num_complex::Complex64;
use std::fmt::Write as _;

/// A problem in a universal file, with the dataset (1-based position in
/// the file, counting every dataset) and the 1-based file line.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}{message}", match dataset { Some(d) => format!("dataset {d} (line {line}): "), None => format!("line {line}: ") })]
pub struct UffError {
    /// 1-based position of the dataset in the file, if inside one.
    pub dataset: Option<usize>,
    /// 1-based file line.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

/// A degree of freedom: entity name, node and direction (record 6).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Dof {
    /// Entity name (`NONE` if unused).
    pub entity: String,
    /// Node number.
    pub node: i64,
    /// Direction: 0 scalar, 1/2/3 = +X/+Y/+Z translation, 4/5/6 rotation,
    /// negative for the minus directions.
    pub direction: i32,
}

/// Axis characteristics (records 8-11).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Axis {
    /// Specific data type: 0 unknown, 1 general, 8 displacement, 11
    /// velocity, 12 acceleration, 13 excitation force, 17 time, 18
    /// frequency, 19 rpm, 20 order, ...
    pub data_type: i32,
    /// Length units exponent.
    pub length_exp: i32,
    /// Force units exponent.
    pub force_exp: i32,
    /// Temperature units exponent.
    pub temperature_exp: i32,
    /// Axis label (`NONE` if unused).
    pub label: String,
    /// Units label (`NONE` if unused).
    pub units: String,
}

/// Ordinate values of a dataset.
#[derive(Clone, Debug, PartialEq)]
pub enum Ordinate {
    /// Real values (ordinate data type 2 or 4).
    Real(Vec<f64>),
    /// Complex values (ordinate data type 5 or 6).
    Complex(Vec<Complex64>),
}

impl Ordinate {
    /// Number of points.
    pub fn len(&self) -> usize {
        match self {
            Ordinate::Real(v) => v.len(),
            Ordinate::Complex(v) => v.len(),
        }
    }

    /// True without points.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Abscissa spacing of a written dataset.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spacing {
    /// Even: only the minimum and increment are stored (record 7).
    Even,
    /// Uneven: every point's abscissa is stored before its value.
    Uneven,
}

/// One dataset 58.
#[derive(Clone, Debug)]
pub struct Uff58 {
    /// 1-based position among all datasets of the file (the number used
    /// in error messages and to pick a dataset).
    pub position: usize,
    /// 1-based line of the opening `-1`.
    pub line: usize,
    /// Records 1-5.
    pub id_lines: [String; 5],
    /// Record 6 field 1: 4 FRF, 5 transmissibility, 6 coherence, 1 time
    /// response, 2 auto spectrum, 3 cross spectrum, ...
    pub function_type: i32,
    /// Record 6 field 2.
    pub function_id: i64,
    /// Record 6 field 3.
    pub version: i64,
    /// Record 6 field 4 (0 = single point excitation).
    pub load_case: i64,
    /// Record 6 fields 5-7.
    pub response: Dof,
    /// Record 6 fields 8-10.
    pub reference: Dof,
    /// Record 7 field 1 as read (2, 4, 5 or 6).
    pub ordinate_type: i32,
    /// Record 7 fields 4-5 for evenly spaced abscissa: `(minimum,
    /// increment)`; `None` for uneven spacing.
    pub even: Option<(f64, f64)>,
    /// Record 7 field 6.
    pub z_value: f64,
    /// Record 8.
    pub abscissa: Axis,
    /// Record 9.
    pub ordinate: Axis,
    /// Record 10.
    pub denominator: Axis,
    /// Record 11.
    pub z_axis: Axis,
    /// Abscissa of every point.
    pub x: Vec<f64>,
    /// Ordinate of every point.
    pub values: Ordinate,
    /// 1-based file line of each point (0 for datasets not read from a
    /// file).
    point_lines: Vec<usize>,
}

/// Names of the common function types, for messages.
pub fn function_type_name(t: i32) -> &'static str {
    match t {
        0 => "general",
        1 => "time response",
        2 => "auto spectrum",
        3 => "cross spectrum",
        4 => "frequency response function",
        5 => "transmissibility",
        6 => "coherence",
        7 => "auto correlation",
        8 => "cross correlation",
        9 => "power spectral density",
        12 => "spectrum",
        _ => "other function",
    }
}

impl Uff58 {
    fn error(&self, line: usize, message: impl Into<String>) -> UffError {
        UffError {
            dataset: Some(self.position),
            line,
            message: message.into(),
        }
    }

    /// True if the abscissa is frequency in Hz: specific data type 18, or
    /// unknown/general (0/1) with a units label that is empty, `NONE` or
    /// Hz. Anything else (time, rpm, order, a unit such as rad/s) is not.
    pub fn abscissa_is_hz(&self) -> Result<(), String> {
        let units = self.abscissa.units.trim();
        let hz_units = units.is_empty()
            || units.eq_ignore_ascii_case("none")
            || units.eq_ignore_ascii_case("hz")
            || units.eq_ignore_ascii_case("hertz");
        match self.abscissa.data_type {
            18 | 0 | 1 if hz_units => Ok(()),
            18 | 0 | 1 => Err(format!("abscissa unit '{units}' is not Hz")),
            17 => Err("abscissa is time (specific data type 17), not frequency".into()),
            t => Err(format!(
                "abscissa has specific data type {t}, not frequency (18)"
            )),
        }
    }

    /// The dataset as an [`Frf`]: function type 4, complex ordinate,
    /// abscissa frequency in Hz, and the lines valid for [`Frf::new`]
    /// (at least [`MIN_LINES`]). Errors name the dataset and line.
    pub fn to_frf(&self) -> Result<Frf, UffError> {
        if self.function_type != 4 {
            return Err(self.error(
                self.line,
                format!(
                    "function type {} ({}) is not a frequency response function (4)",
                    self.function_type,
                    function_type_name(self.function_type)
                ),
            ));
        }
        self.abscissa_is_hz()
            .map_err(|m| self.error(self.line, m))?;
        let Ordinate::Complex(values) = &self.values else {
            return Err(self.error(
                self.line,
                "the ordinate is real; an FRF needs complex values",
            ));
        };
        let frf = Frf::new(self.x.clone(), values.clone(), None).map_err(|e| {
            let line = e
                .index()
                .and_then(|i| self.point_lines.get(i).copied())
                .filter(|&l| l > 0)
                .unwrap_or(self.line);
            self.error(line, e.message_without_index())
        })?;
        if frf.len() < MIN_LINES {
            return Err(self.error(
                self.line,
                format!(
                    "only {} frequency lines; at least {MIN_LINES} are needed",
                    frf.len()
                ),
            ));
        }
        Ok(frf)
    }

    /// The real values of a coherence dataset (function type 6) on this
    /// dataset's abscissa, if `other` is one for the same response and
    /// reference DOFs and the same abscissa.
    pub fn coherence_for(&self, other: &Uff58) -> Option<Vec<f64>> {
        (other.function_type == 6)
            .then(|| self.companion(other))
            .flatten()
    }

    /// The standard deviation of each line of this dataset, if `other`
    /// holds it: a real dataset of function type 0 (general) whose first ID
    /// line is `std_dev` (or `standard deviation`), for the same DOFs and
    /// abscissa, in the units of this dataset's ordinate. The dataset type
    /// has no code for it, hence the name. A negative value marks a line
    /// without information (`+inf` in [`Frf::std_dev`]), as a universal
    /// file holds only finite numbers.
    pub fn std_dev_for(&self, other: &Uff58) -> Option<Vec<f64>> {
        let name = other.id_lines[0].trim().to_ascii_lowercase();
        let named = name == STD_DEV_ID || name == "standard deviation";
        (other.function_type == 0 && named)
            .then(|| self.companion(other))
            .flatten()
            .map(|v| {
                v.into_iter()
                    .map(|s| if s < 0.0 { f64::INFINITY } else { s })
                    .collect()
            })
    }

    /// The real values of `other` if it describes this dataset's DOFs on
    /// its abscissa.
    fn companion(&self, other: &Uff58) -> Option<Vec<f64>> {
        let Ordinate::Real(c) = &other.values else {
            return None;
        };
        let same_x = other.x.len() == self.x.len()
            && other
                .x
                .iter()
                .zip(&self.x)
                .all(|(a, b)| (a - b).abs() <= 1e-6 * b.abs().max(1e-12));
        (other.response == self.response && other.reference == self.reference && same_x)
            .then(|| c.clone())
    }

    /// A dataset holding an FRF (function type 4, complex ordinate,
    /// abscissa frequency in Hz). With [`Spacing::Even`] the frequencies
    /// must be evenly spaced (within 1e-9 of the span).
    pub fn from_frf(frf: &Frf, spacing: Spacing) -> Result<Uff58, UffError> {
        let x = frf.freq_hz().to_vec();
        let even = match spacing {
            Spacing::Uneven => None,
            Spacing::Even => Some(even_grid(&x).ok_or_else(|| UffError {
                dataset: None,
                line: 0,
                message: "frequencies are not evenly spaced: write with uneven spacing".into(),
            })?),
        };
        let n = x.len();
        Ok(Uff58 {
            position: 0,
            line: 0,
            id_lines: [
                "frequency response function".into(),
                "NONE".into(),
                "NONE".into(),
                "NONE".into(),
                "NONE".into(),
            ],
            function_type: 4,
            function_id: 1,
            version: 0,
            load_case: 0,
            response: Dof {
                entity: "NONE".into(),
                node: 1,
                direction: 0,
            },
            reference: Dof {
                entity: "NONE".into(),
                node: 1,
                direction: 0,
            },
            ordinate_type: 6,
            even,
            z_value: 0.0,
            abscissa: Axis {
                data_type: 18,
                label: "Frequency".into(),
                units: "Hz".into(),
                ..Axis::default()
            },
            ordinate: Axis {
                data_type: 1,
                label: "Response".into(),
                units: "NONE".into(),
                ..Axis::default()
            },
            denominator: Axis {
                data_type: 1,
                label: "Excitation".into(),
                units: "NONE".into(),
                ..Axis::default()
            },
            z_axis: Axis {
                label: "NONE".into(),
                units: "NONE".into(),
                ..Axis::default()
            },
            x,
            values: Ordinate::Complex(frf.response().to_vec()),
            point_lines: vec![0; n],
        })
    }
}

/// `(minimum, increment)` if `x` is evenly spaced within 1e-9 of its span.
fn even_grid(x: &[f64]) -> Option<(f64, f64)> {
    let n = x.len();
    if n == 1 {
        return Some((x[0], 0.0));
    }
    let (first, last) = (*x.first()?, *x.last()?);
    let inc = (last - first) / (n - 1) as f64;
    let tol = 1e-9 * last.abs().max(inc.abs());
    x.iter()
        .enumerate()
        .all(|(k, &v)| (v - (first + k as f64 * inc)).abs() <= tol)
        .then_some((first, inc))
}

/// A line of the file without its line terminator, with its 1-based number.
struct Line<'a> {
    number: usize,
    bytes: &'a [u8],
}

impl Line<'_> {
    fn text(&self) -> String {
        String::from_utf8_lossy(self.bytes).into_owned()
    }
}

fn split_lines(bytes: &[u8]) -> Vec<Line<'_>> {
    let mut lines: Vec<Line<'_>> = bytes
        .split(|&b| b == b'\n')
        .enumerate()
        .map(|(i, l)| Line {
            number: i + 1,
            bytes: l.strip_suffix(b"\r").unwrap_or(l),
        })
        .collect();
    // A final newline does not start another line.
    if lines.last().is_some_and(|l| l.bytes.is_empty()) {
        lines.pop();
    }
    lines
}

/// `-1` right-justified in columns 1-6 (or anywhere within them).
fn is_delimiter(l: &[u8]) -> bool {
    let t = l.trim_ascii_end();
    t.len() <= 6 && t.trim_ascii_start() == b"-1"
}

/// Reads a Fortran real: `E` or `D` exponent; a blank field is 0.
fn fortran_real(field: &[u8]) -> Option<f64> {
    let s = std::str::from_utf8(field).ok()?.trim();
    if s.is_empty() {
        return Some(0.0);
    }
    let s = s.replace(['D', 'd'], "E");
    s.parse::<f64>().ok()
}

/// Reads a Fortran integer; a blank field is 0.
fn fortran_int(field: &[u8]) -> Option<i64> {
    let s = std::str::from_utf8(field).ok()?.trim();
    if s.is_empty() {
        return Some(0);
    }
    s.parse::<i64>().ok()
}

/// Cuts `line` into fields of the given widths (missing columns are
/// blank fields).
fn fixed<'a>(line: &'a [u8], widths: &[usize]) -> Vec<&'a [u8]> {
    let mut out = Vec::with_capacity(widths.len());
    let mut at = 0;
    for &w in widths {
        let start = at.min(line.len());
        let end = (at + w).min(line.len());
        out.push(&line[start..end]);
        at += w;
    }
    out
}

/// Parses a header record of integers and reals by fixed widths, falling
/// back to whitespace-separated tokens. `kinds` is `i` (integer), `r`
/// (real) or `s` (string, fixed width only) per field.
enum Field {
    Int(i64),
    Real(f64),
    Str(String),
}

fn record(line: &[u8], widths: &[usize], kinds: &[u8]) -> Option<Vec<Field>> {
    let by_width = |fields: Vec<&[u8]>| -> Option<Vec<Field>> {
        fields
            .iter()
            .zip(kinds)
            .map(|(f, k)| match k {
                b'i' => fortran_int(f).map(Field::Int),
                b'r' => fortran_real(f).map(Field::Real),
                _ => Some(Field::Str(String::from_utf8_lossy(f).trim().to_string())),
            })
            .collect()
    };
    if let Some(v) = by_width(fixed(line, widths)) {
        return Some(v);
    }
    // Whitespace fallback: numbers in order, string fields take one token.
    let tokens: Vec<&[u8]> = line
        .split(|b| b.is_ascii_whitespace())
        .filter(|t| !t.is_empty())
        .collect();
    let mut padded = tokens.clone();
    padded.resize(kinds.len(), b"");
    by_width(padded)
}

fn int(f: &Field) -> i64 {
    match f {
        Field::Int(v) => *v,
        Field::Real(v) => *v as i64,
        Field::Str(_) => 0,
    }
}

fn real(f: &Field) -> f64 {
    match f {
        Field::Real(v) => *v,
        Field::Int(v) => *v as f64,
        Field::Str(_) => 0.0,
    }
}

fn string(f: &Field) -> String {
    match f {
        Field::Str(s) => s.clone(),
        _ => String::new(),
    }
}

fn small(v: i64) -> i32 {
    v.clamp(i32::MIN as i64, i32::MAX as i64) as i32
}

/// Reads every dataset 58 of a universal file; other dataset types are
/// skipped. Errors: a binary dataset 58b, malformed header records,
/// values that are not finite numbers, a wrong number of values, a
/// dataset without its closing `-1`.
pub fn parse_uff(bytes: &[u8]) -> Result<Vec<Uff58>, UffError> {
    let lines = split_lines(bytes);
    let mut out = Vec::new();
    let mut i = 0;
    let mut position = 0;
    while i < lines.len() {
        let l = &lines[i];
        if l.bytes.trim_ascii().is_empty() {
            i += 1;
            continue;
        }
        if !is_delimiter(l.bytes) {
            return Err(UffError {
                dataset: None,
                line: l.number,
                message: "expected '    -1' opening a dataset".into(),
            });
        }
        position += 1;
        let open = l.number;
        let here = |line: usize, message: String| UffError {
            dataset: Some(position),
            line,
            message,
        };
        let type_line = lines
            .get(i + 1)
            .ok_or_else(|| here(open, "no dataset type after '-1'".into()))?;
        let t = type_line.bytes;
        let head = &t[..t.len().min(6)];
        let kind = std::str::from_utf8(head)
            .ok()
            .and_then(|s| s.trim().parse::<i64>().ok())
            .ok_or_else(|| {
                here(
                    type_line.number,
                    format!("'{}' is not a dataset type", type_line.text().trim()),
                )
            })?;
        let binary = t.get(6).is_some_and(|b| b.eq_ignore_ascii_case(&b'b'));
        if kind == 58 && binary {
            return Err(here(
                type_line.number,
                "binary dataset 58b is not supported: export as ASCII dataset 58".into(),
            ));
        }
        // The block runs to the next delimiter.
        let close = (i + 2..lines.len())
            .find(|&j| is_delimiter(lines[j].bytes))
            .ok_or_else(|| here(open, format!("dataset {kind} has no closing '    -1' line")))?;
        if kind == 58 {
            out.push(parse_58(
                &lines[i + 2..close],
                position,
                open,
                type_line.number,
            )?);
        }
        i = close + 1;
    }
    Ok(out)
}

fn parse_58(
    body: &[Line<'_>],
    position: usize,
    open: usize,
    type_line: usize,
) -> Result<Uff58, UffError> {
    let here = |line: usize, message: String| UffError {
        dataset: Some(position),
        line,
        message,
    };
    if body.len() < 11 {
        let last = body.last().map_or(type_line, |l| l.number);
        return Err(here(
            last,
            format!("dataset 58 header has {} of its 11 records", body.len()),
        ));
    }
    let id_lines: [String; 5] = std::array::from_fn(|k| body[k].text().trim_end().to_string());

    let r6 = &body[5];
    let f6 = record(
        r6.bytes,
        // 1X and the 10A1 entity name read as one 11-wide field.
        &[5, 10, 5, 10, 11, 10, 4, 11, 10, 4],
        b"iiiisiisii",
    )
    .ok_or_else(|| {
        here(
            r6.number,
            "record 6 (DOF identification) is malformed".into(),
        )
    })?;
    let r7 = &body[6];
    let f7 = record(r7.bytes, &[10, 10, 10, 13, 13, 13], b"iiirrr")
        .ok_or_else(|| here(r7.number, "record 7 (data form) is malformed".into()))?;
    let axis = |l: &Line<'_>, what: &str| -> Result<Axis, UffError> {
        let f = record(l.bytes, &[10, 5, 5, 5, 21, 21], b"iiiiss").ok_or_else(|| {
            here(
                l.number,
                format!("record {what} (axis characteristics) is malformed"),
            )
        })?;
        Ok(Axis {
            data_type: small(int(&f[0])),
            length_exp: small(int(&f[1])),
            force_exp: small(int(&f[2])),
            temperature_exp: small(int(&f[3])),
            label: string(&f[4]),
            units: string(&f[5]),
        })
    };
    let abscissa = axis(&body[7], "8")?;
    let ordinate = axis(&body[8], "9")?;
    let denominator = axis(&body[9], "10")?;
    let z_axis = axis(&body[10], "11")?;

    let ordinate_type = small(int(&f7[0]));
    let n = int(&f7[1]);
    let spacing = int(&f7[2]);
    let (complex, double) = match ordinate_type {
        2 => (false, false),
        4 => (false, true),
        5 => (true, false),
        6 => (true, true),
        t => {
            return Err(here(
                r7.number,
                format!("ordinate data type {t} is not 2, 4, 5 or 6"),
            ))
        }
    };
    let even = match spacing {
        1 => true,
        0 => false,
        s => {
            return Err(here(
                r7.number,
                format!("abscissa spacing {s} is not 0 or 1"),
            ))
        }
    };
    if n < 0 {
        return Err(here(r7.number, format!("negative number of values {n}")));
    }
    let n = n as usize;
    let per_point = usize::from(!even) + if complex { 2 } else { 1 };
    // Field widths of one data line per record 12's cases.
    let widths: &[usize] = match (double, even, complex) {
        (false, _, _) => &[13; 6],
        (true, true, _) => &[20; 4],
        (true, false, false) => &[13, 20, 13, 20],
        (true, false, true) => &[13, 20, 20],
    };
    let data = &body[11..];
    // Every value needs at least one character: this bounds `n` by the
    // bytes present before anything is allocated for it.
    let available: usize = data.iter().map(|l| l.bytes.len()).sum();
    let needed = n
        .checked_mul(per_point)
        .filter(|&v| v <= available)
        .ok_or_else(|| {
            here(
                r7.number,
                format!("{n} values do not fit in the {available} bytes of data"),
            )
        })?;
    let mut values: Vec<f64> = Vec::with_capacity(needed);
    let mut value_lines: Vec<usize> = Vec::with_capacity(needed);
    for l in data {
        let parsed = data_line(l.bytes, widths).ok_or_else(|| {
            here(
                l.number,
                format!("'{}' is not a line of numbers", l.text().trim()),
            )
        })?;
        if let Some(k) = parsed.iter().position(|v| !v.is_finite()) {
            return Err(here(
                l.number,
                format!("value {} on this line is not finite", k + 1),
            ));
        }
        if values.len() + parsed.len() > needed {
            return Err(here(
                l.number,
                format!("more values than the {n} points of record 7"),
            ));
        }
        value_lines.resize(value_lines.len() + parsed.len(), l.number);
        values.extend(parsed);
    }
    if values.len() != needed {
        let last = data.last().map_or(body[10].number, |l| l.number);
        return Err(here(
            last,
            format!(
                "{} values found, record 7 announces {n} points ({needed} values)",
                values.len()
            ),
        ));
    }
    let (xmin, dx) = (real(&f7[3]), real(&f7[4]));
    let point_lines: Vec<usize> = (0..n).map(|p| value_lines[p * per_point]).collect();
    let x: Vec<f64> = if even {
        (0..n).map(|k| xmin + k as f64 * dx).collect()
    } else {
        (0..n).map(|p| values[p * per_point]).collect()
    };
    let off = usize::from(!even);
    let ordinate_values = if complex {
        Ordinate::Complex(
            (0..n)
                .map(|p| {
                    Complex64::new(values[p * per_point + off], values[p * per_point + off + 1])
                })
                .collect(),
        )
    } else {
        Ordinate::Real((0..n).map(|p| values[p * per_point + off]).collect())
    };
    Ok(Uff58 {
        position,
        line: open,
        id_lines,
        function_type: small(int(&f6[0])),
        function_id: int(&f6[1]),
        version: int(&f6[2]),
        load_case: int(&f6[3]),
        response: Dof {
            entity: string(&f6[4]),
            node: int(&f6[5]),
            direction: small(int(&f6[6])),
        },
        reference: Dof {
            entity: string(&f6[7]),
            node: int(&f6[8]),
            direction: small(int(&f6[9])),
        },
        ordinate_type,
        even: even.then_some((xmin, dx)),
        z_value: real(&f7[5]),
        abscissa,
        ordinate,
        denominator,
        z_axis,
        x,
        values: ordinate_values,
        point_lines,
    })
}

/// The numbers of one data line: fixed-width fields (cycling through
/// `widths`) up to the first blank field, or whitespace-separated tokens
/// if that fails. `None` if neither reading works.
fn data_line(line: &[u8], widths: &[usize]) -> Option<Vec<f64>> {
    let line = line.trim_ascii_end();
    let mut out = Vec::new();
    let mut at = 0;
    let mut ok = true;
    'fields: for w in widths.iter().cycle() {
        if at >= line.len() {
            break 'fields;
        }
        let end = (at + w).min(line.len());
        let field = line[at..end].trim_ascii();
        if field.is_empty() || field.contains(&b' ') {
            ok = false;
            break 'fields;
        }
        match fortran_real(field) {
            Some(v) => out.push(v),
            None => {
                ok = false;
                break 'fields;
            }
        }
        at = end;
    }
    if ok {
        return Some(out);
    }
    line.split(|b| b.is_ascii_whitespace())
        .filter(|t| !t.is_empty())
        .map(fortran_real)
        .collect()
}

/// Fortran `Ew.d`: `d` decimals, exponent with sign and at least two
/// digits, right-justified in `w` characters; fewer decimals if the
/// number would not fit (three-digit exponents).
fn fortran_e(x: f64, w: usize, d: usize) -> String {
    for decimals in (0..=d).rev() {
        let s = format!("{x:.decimals$e}");
        let (mant, exp) = s.split_once('e').unwrap_or((&s, "0"));
        let exp: i32 = exp.parse().unwrap_or(0);
        let sign = if exp < 0 { '-' } else { '+' };
        let out = format!("{mant}E{sign}{:02}", exp.unsigned_abs());
        if out.len() <= w {
            return format!("{out:>w$}");
        }
    }
    format!("{:>w$}", format!("{x:e}"))
}

/// ASCII text of at most `n` characters (non-ASCII replaced by `?`).
fn ascii(s: &str, n: usize) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii() && !c.is_ascii_control() {
                c
            } else {
                '?'
            }
        })
        .take(n)
        .collect()
}

fn write_axis(out: &mut String, a: &Axis) {
    let label = if a.label.is_empty() { "NONE" } else { &a.label };
    let units = if a.units.is_empty() { "NONE" } else { &a.units };
    let _ = writeln!(
        out,
        "{:10}{:5}{:5}{:5} {:<20} {:<20}",
        a.data_type,
        a.length_exp,
        a.force_exp,
        a.temperature_exp,
        ascii(label, 20),
        ascii(units, 20)
    );
}

/// Writes datasets 58 as ASCII: complex values as complex double
/// (ordinate type 6), real values as real double (4); even or uneven
/// abscissa as each dataset's [`Uff58::even`] says.
///
/// Abscissa values (minimum, increment, or each x with uneven spacing) go
/// into `E13` fields, written with 7 significant digits; ordinates into
/// `E20.12` fields (13 significant digits).
pub fn write_uff58(datasets: &[Uff58]) -> String {
    let mut out = String::new();
    for d in datasets {
        out.push_str("    -1\n    58\n");
        for id in &d.id_lines {
            let id = if id.trim().is_empty() { "NONE" } else { id };
            let _ = writeln!(out, "{}", ascii(id, 80));
        }
        let ent = |e: &str| {
            if e.is_empty() {
                "NONE".to_string()
            } else {
                ascii(e, 10)
            }
        };
        let _ = writeln!(
            out,
            "{:5}{:10}{:5}{:10} {:<10}{:10}{:4} {:<10}{:10}{:4}",
            d.function_type,
            d.function_id,
            d.version,
            d.load_case,
            ent(&d.response.entity),
            d.response.node,
            d.response.direction,
            ent(&d.reference.entity),
            d.reference.node,
            d.reference.direction
        );
        let complex = matches!(d.values, Ordinate::Complex(_));
        let (xmin, dx) = d.even.unwrap_or((0.0, 0.0));
        let _ = writeln!(
            out,
            "{:10}{:10}{:10}{}{}{}",
            if complex { 6 } else { 4 },
            d.values.len(),
            i32::from(d.even.is_some()),
            fortran_e(xmin, 13, 6),
            fortran_e(dx, 13, 6),
            fortran_e(d.z_value, 13, 6)
        );
        for a in [&d.abscissa, &d.ordinate, &d.denominator, &d.z_axis] {
            write_axis(&mut out, a);
        }
        // Fields of each point, then lines of at most 80 characters.
        let mut fields: Vec<String> = Vec::new();
        for p in 0..d.values.len() {
            if d.even.is_none() {
                fields.push(fortran_e(d.x.get(p).copied().unwrap_or(0.0), 13, 6));
            }
            match &d.values {
                Ordinate::Complex(v) => {
                    fields.push(fortran_e(v[p].re, 20, 12));
                    fields.push(fortran_e(v[p].im, 20, 12));
                }
                Ordinate::Real(v) => fields.push(fortran_e(v[p], 20, 12)),
            }
        }
        let per_line = match (d.even.is_some(), complex) {
            (true, _) => 4,
            (false, true) => 3,
            (false, false) => 4,
        };
        for chunk in fields.chunks(per_line) {
            out.push_str(&chunk.concat());
            out.push('\n');
        }
        out.push_str("    -1\n");
    }
    out
}

/// The first ID line of the dataset that holds the standard deviation of
/// an FRF's lines ([`Uff58::std_dev_for`]).
pub const STD_DEV_ID: &str = "std_dev";

/// Writes an FRF as a universal file: one dataset 58 with the response
/// (function type 4); if the FRF has a coherence, a second one with it
/// (function type 6, real); if it has a standard deviation per line, a
/// dataset of function type 0 named [`STD_DEV_ID`] (see
/// [`Uff58::std_dev_for`]); all on the same abscissa.
pub fn write_frf_uff(frf: &Frf, spacing: Spacing) -> Result<String, UffError> {
    let main = Uff58::from_frf(frf, spacing)?;
    let mut sets = vec![main.clone()];
    if let Some(c) = frf.coherence() {
        let mut coh = main.clone();
        coh.function_type = 6;
        coh.function_id = 2;
        coh.id_lines[0] = "coherence".into();
        coh.ordinate = Axis {
            data_type: 1,
            label: "Coherence".into(),
            units: "NONE".into(),
            ..Axis::default()
        };
        coh.denominator = Axis {
            label: "NONE".into(),
            units: "NONE".into(),
            ..Axis::default()
        };
        coh.values = Ordinate::Real(c.to_vec());
        sets.push(coh);
    }
    if let Some(sd) = frf.std_dev() {
        let mut set = main;
        set.function_type = 0;
        set.function_id = 3;
        set.id_lines[0] = STD_DEV_ID.into();
        set.values = Ordinate::Real(
            sd.iter()
                .map(|&s| if s.is_finite() { s } else { -1.0 })
                .collect(),
        );
        sets.push(set);
    }
    Ok(write_uff58(&sets))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_frf(n: usize, coherence: bool) -> Frf {
        let freq: Vec<f64> = (1..=n).map(|k| k as f64 * 0.25).collect();
        let resp: Vec<Complex64> = freq
            .iter()
            .map(|&f| Complex64::new(1.0, 0.0) / Complex64::new(100.0 - f * f, 0.3 * f))
            .collect();
        let coh = coherence.then(|| freq.iter().map(|f| 1.0 / (1.0 + 0.01 * f)).collect());
        Frf::new(freq, resp, coh).unwrap()
    }

    fn close(a: &Frf, b: &Frf) {
        assert_eq!(a.len(), b.len());
        for (x, y) in a.freq_hz().iter().zip(b.freq_hz()) {
            // E13 fields with 7 significant digits; these grids are exact.
            assert_eq!(x, y);
        }
        for (x, y) in a.response().iter().zip(b.response()) {
            // E20.12: 13 significant digits.
            assert!((x - y).norm() <= 1e-12 * y.norm(), "{x} vs {y}");
        }
    }

    #[test]
    fn fortran_e_format() {
        assert_eq!(fortran_e(0.48828125, 13, 6), " 4.882812E-01");
        assert_eq!(fortran_e(-1.5, 20, 12), " -1.500000000000E+00");
        assert_eq!(fortran_e(0.0, 13, 6), " 0.000000E+00");
        assert_eq!(fortran_e(-1e-120, 13, 6), "-1.00000E-120");
        assert_eq!(fortran_e(-1e-120, 13, 6).len(), 13);
    }

    #[test]
    fn round_trip_even_and_uneven() {
        for spacing in [Spacing::Even, Spacing::Uneven] {
            let frf = sample_frf(37, true);
            let text = write_frf_uff(&frf, spacing).unwrap();
            let sets = parse_uff(text.as_bytes()).unwrap();
            assert_eq!(sets.len(), 2);
            assert_eq!(sets[0].even.is_some(), spacing == Spacing::Even);
            assert_eq!(sets[0].abscissa.data_type, 18);
            assert_eq!(sets[0].abscissa.units, "Hz");
            assert_eq!((sets[0].position, sets[1].position), (1, 2));
            close(&sets[0].to_frf().unwrap(), &frf);
            let c = sets[0].coherence_for(&sets[1]).unwrap();
            for (a, b) in c.iter().zip(frf.coherence().unwrap()) {
                assert!((a - b).abs() <= 1e-12);
            }
            // Every line within 80 columns.
            assert!(text.lines().all(|l| l.len() <= 80));
        }
    }

    fn record6(function_type: i32) -> String {
        format!(
            "{:5}{:10}{:5}{:10} {:<10}{:10}{:4} {:<10}{:10}{:4}",
            function_type, 1, 1, 0, "BEAM", 2, 3, "BEAM", 1, -3
        )
    }

    fn record7(n: i64) -> String {
        format!("{:10}{:10}{:10}{}", 5, n, 0, "  0.00000E+00".repeat(3))
    }

    fn axis(t: i32, label: &str, units: &str) -> String {
        format!("{t:10}{:5}{:5}{:5} {label:<20} {units:<20}", 0, 0, 0)
    }

    /// A dataset as another program would write it: single-precision
    /// complex (type 5, 6E13.5), uneven abscissa, with other datasets
    /// (151 header, 15 nodes) before it, CRLF line ends. Lines: 11 opens
    /// the dataset 58, 18 is record 6, 19 record 7, 20 record 8, 24-29
    /// hold the 12 points (two per line), 30 closes.
    fn foreign_file() -> String {
        let mut s = String::new();
        s.push_str("    -1\n   151\nmodel\ndescription\nprogram\n    -1\n");
        s.push_str("    -1\n    15\n         1         0         0         1 0.00000E+00 0.00000E+00 0.00000E+00\n    -1\n");
        s.push_str("    -1\n    58\nH_1_2\nNONE\n01-JAN-24 12:00:00\nNONE\nNONE\n");
        s.push_str(&format!("{}\n{}\n", record6(4), record7(12)));
        s.push_str(&format!("{}\n", axis(18, "Frequency", "Hz")));
        s.push_str(&format!("{}\n", axis(12, "Acceleration", "m/s^2")));
        s.push_str(&format!("{}\n", axis(13, "Force", "N")));
        s.push_str(&format!("{}\n", axis(0, "NONE", "NONE")));
        for k in 0..12 {
            let x = 10.0 + 2.5 * k as f64;
            s.push_str(&format!(
                "{}{}{}",
                fortran_e(x, 13, 5),
                fortran_e(0.5 * k as f64, 13, 5),
                fortran_e(-1.0, 13, 5)
            ));
            if k % 2 == 1 {
                s.push('\n');
            }
        }
        s.push_str("    -1\n");
        s.replace('\n', "\r\n")
    }

    #[test]
    fn reads_single_precision_uneven_among_other_datasets() {
        let sets = parse_uff(foreign_file().as_bytes()).unwrap();
        assert_eq!(sets.len(), 1);
        let d = &sets[0];
        assert_eq!(d.position, 3);
        assert_eq!(d.line, 11);
        assert_eq!(d.id_lines[0], "H_1_2");
        assert_eq!(d.function_type, 4);
        assert_eq!(d.ordinate_type, 5);
        assert_eq!(d.even, None);
        assert_eq!(
            d.response,
            Dof {
                entity: "BEAM".into(),
                node: 2,
                direction: 3
            }
        );
        assert_eq!(
            d.reference,
            Dof {
                entity: "BEAM".into(),
                node: 1,
                direction: -3
            }
        );
        assert_eq!(d.ordinate.label, "Acceleration");
        assert_eq!(d.ordinate.data_type, 12);
        assert_eq!(d.denominator.units, "N");
        let frf = d.to_frf().unwrap();
        assert_eq!(frf.len(), 12);
        assert_eq!(frf.freq_hz()[11], 37.5);
        assert_eq!(frf.response()[4], Complex64::new(2.0, -1.0));
    }

    #[test]
    fn errors_name_dataset_and_line() {
        let good = foreign_file().replace("\r\n", "\n");
        let set_line = |n: usize, text: &str| {
            let mut ls: Vec<String> = good.lines().map(String::from).collect();
            ls[n - 1] = text.to_string();
            ls.join("\n") + "\n"
        };
        // Line 27 holds points k = 6 and 7.
        let e = parse_uff(set_line(27, "  2.50000E+01  NaN  -1.00000E+00").as_bytes()).unwrap_err();
        assert_eq!((e.dataset, e.line), (Some(3), 27));
        assert!(e.message.contains("not finite"), "{e}");
        let e = parse_uff(set_line(27, "  2.50000E+01  xyz").as_bytes()).unwrap_err();
        assert_eq!((e.dataset, e.line), (Some(3), 27));
        assert!(e.message.contains("not a line of numbers"), "{e}");
        // Point k = 6 at 5 Hz after 22.5 Hz: does not increase.
        let bad_x = format!(
            "{}{}{}{}{}{}",
            fortran_e(5.0, 13, 5),
            fortran_e(1.0, 13, 5),
            fortran_e(1.0, 13, 5),
            fortran_e(27.5, 13, 5),
            fortran_e(1.0, 13, 5),
            fortran_e(1.0, 13, 5)
        );
        let e = parse_uff(set_line(27, &bad_x).as_bytes()).unwrap()[0]
            .to_frf()
            .unwrap_err();
        assert_eq!((e.dataset, e.line), (Some(3), 27));
        assert!(e.message.contains("does not increase"), "{e}");
        // Wrong count in record 7.
        let e = parse_uff(set_line(19, &record7(13)).as_bytes()).unwrap_err();
        assert!(e.message.contains("announces 13 points"), "{e}");
        // Absurd count: refused before allocating.
        let e = parse_uff(set_line(19, &record7(9_999_999_999)).as_bytes()).unwrap_err();
        assert_eq!((e.dataset, e.line), (Some(3), 19));
        assert!(e.message.contains("do not fit"), "{e}");
        // Unknown ordinate type.
        let e = parse_uff(
            set_line(19, &record7(12).replacen("         5", "         3", 1)).as_bytes(),
        )
        .unwrap_err();
        assert!(e.message.contains("ordinate data type 3"), "{e}");
        // Abscissa in seconds.
        let e = parse_uff(set_line(20, &axis(17, "Time", "s")).as_bytes()).unwrap()[0]
            .to_frf()
            .unwrap_err();
        assert!(e.message.contains("time"), "{e}");
        // Abscissa in rad/s.
        let e = parse_uff(set_line(20, &axis(18, "Frequency", "rad/s")).as_bytes()).unwrap()[0]
            .to_frf()
            .unwrap_err();
        assert!(e.message.contains("rad/s"), "{e}");
        // A coherence is not an FRF.
        let e = parse_uff(set_line(18, &record6(6)).as_bytes()).unwrap()[0]
            .to_frf()
            .unwrap_err();
        assert!(e.message.contains("coherence"), "{e}");
        // Missing closing delimiter.
        let cut: String = good.lines().take(29).collect::<Vec<_>>().join("\n");
        let e = parse_uff(cut.as_bytes()).unwrap_err();
        assert_eq!((e.dataset, e.line), (Some(3), 11));
        assert!(e.message.contains("closing"), "{e}");
        // Garbage between datasets.
        let e = parse_uff(format!("hello\n{good}").as_bytes()).unwrap_err();
        assert_eq!((e.dataset, e.line), (None, 1));
        // Too few lines.
        let text = write_frf_uff(&sample_frf(5, false), Spacing::Even).unwrap();
        let e = parse_uff(text.as_bytes()).unwrap()[0].to_frf().unwrap_err();
        assert!(e.message.contains("only 5"), "{e}");
    }

    #[test]
    fn binary_58b_is_refused() {
        let mut bytes =
            b"    -1\n    58b     1     2    11        96     0     0           0           0\n"
                .to_vec();
        bytes.extend_from_slice(&[0xff, 0x00, 0x13, 0x80]);
        bytes.extend_from_slice(b"\n    -1\n");
        let e = parse_uff(&bytes).unwrap_err();
        assert_eq!((e.dataset, e.line), (Some(1), 2));
        assert!(e.message.contains("58b"), "{e}");
    }

    #[test]
    fn truncated_and_garbled_never_panic() {
        let text = write_frf_uff(&sample_frf(20, true), Spacing::Uneven).unwrap();
        let bytes = text.as_bytes();
        for cut in 0..bytes.len() {
            if let Ok(sets) = parse_uff(&bytes[..cut]) {
                for s in sets {
                    let _ = s.to_frf();
                }
            }
        }
        let mut rng = 0x9e37_79b9_7f4a_7c15u64;
        for i in 0..bytes.len() {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            let mut b = bytes.to_vec();
            b[i] = rng as u8;
            if let Ok(sets) = parse_uff(&b) {
                for s in sets {
                    let _ = s.to_frf();
                }
            }
        }
    }
}
