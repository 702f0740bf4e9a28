//! Text files: FRF CSV, time-domain CSV and headerless numeric matrices.
//!
//! **CSV** (comma separated): lines starting with `#` (after optional
//! blanks) and blank lines are ignored anywhere; the first other line is a
//! header of column names (trimmed, case-insensitive); every further line
//! holds one number per column. NaN and infinities are errors.
//!
//! * FRF CSV: columns exactly `freq_hz,re,im` or `freq_hz,mag_db,phase_deg`,
//!   each optionally with `coherence` and `std_dev` (the standard deviation
//!   of each line, see [`Frf::with_std_dev`]; `inf` allowed there for a
//!   line without information), in any order. See [`parse_frf_csv`] and the
//!   writer [`write_csv`].
//! * Time-domain CSV: named columns, by default `t,u,y`; the sample rate
//!   comes from the `t` column (checked for uniform spacing) unless given.
//!   See [`time_series_from_table`].
//!
//! **Numeric matrix** (`.dat`, `.txt`): whitespace-separated numbers, no
//! header, `#` or `%` comment lines allowed; columns are picked by number.
//! See [`parse_matrix`].
//!
//! Errors carry the 1-based line of the file ([`CsvError::line`]).
//!
//! ```
//! use frf::csv::{parse_frf_csv, write_csv, CsvLayout};
//!
//! let mut text = String::from("# measured at the motor\nFreq_Hz, re, im, coherence\n");
//! for k in 1..=10 {
//!     text.push_str(&format!("{k},{},-0.5,0.9\n", 1.0 / k as f64));
//! }
//! let frf = parse_frf_csv(&text)?;
//! assert_eq!(frf.len(), 10);
//! assert_eq!(frf.response()[1].re, 0.5);
//! // The writer's output reads back to the same values.
//! assert_eq!(parse_frf_csv(&write_csv(&frf, CsvLayout::ReIm))?, frf);
//! # Ok::<(), frf::csv::CsvError>(())
//! ```

use crate::welch::sample_rate_from_times;
use crate::{Frf, MIN_LINES};
use num_complex::Complex64;
use std::fmt::Write as _;

/// A problem in a text file, with its 1-based line where there is one.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}{message}", match line { Some(l) => format!("line {l}: "), None => String::new() })]
pub struct CsvError {
    /// 1-based line of the file, `None` for the file as a whole.
    pub line: Option<usize>,
    /// What is wrong.
    pub message: String,
}

impl CsvError {
    fn at(line: usize, message: impl Into<String>) -> CsvError {
        CsvError {
            line: Some(line),
            message: message.into(),
        }
    }

    fn file(message: impl Into<String>) -> CsvError {
        CsvError {
            line: None,
            message: message.into(),
        }
    }
}

/// A CSV file read into named numeric columns.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// Column names as written (trimmed).
    pub names: Vec<String>,
    /// One vector per column, in header order.
    pub columns: Vec<Vec<f64>>,
    /// 1-based file line of the header.
    pub header_line: usize,
    /// 1-based file line of each row.
    pub lines: Vec<usize>,
}

impl Table {
    /// Index of the column named `name` (trimmed, case-insensitive).
    pub fn find(&self, name: &str) -> Option<usize> {
        let want = name.trim().to_ascii_lowercase();
        self.names
            .iter()
            .position(|n| n.to_ascii_lowercase() == want)
    }

    /// Number of data rows.
    pub fn rows(&self) -> usize {
        self.lines.len()
    }
}

/// Lines of `text` with their 1-based numbers, without comments and blank
/// lines. `comment` lists the characters that start a comment line.
fn content_lines<'a>(
    text: &'a str,
    comment: &'a [char],
) -> impl Iterator<Item = (usize, &'a str)> + 'a {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    text.lines().enumerate().filter_map(move |(i, l)| {
        let t = l.trim();
        if t.is_empty() || t.starts_with(comment) {
            None
        } else {
            Some((i + 1, t))
        }
    })
}

/// The one column in which `inf` is a value: a line without information.
const STD_DEV: &str = "std_dev";

/// Parses one numeric field; NaN and infinities are errors, except `+inf`
/// where `allow_inf`.
fn number(
    field: &str,
    line: usize,
    allow_inf: bool,
    what: &dyn Fn() -> String,
) -> Result<f64, CsvError> {
    let f = field.trim();
    match f.parse::<f64>() {
        Ok(v) if v.is_finite() || (allow_inf && v == f64::INFINITY) => Ok(v),
        Ok(_) => Err(CsvError::at(
            line,
            format!("{}: '{f}' is not a finite number", what()),
        )),
        Err(_) => Err(CsvError::at(
            line,
            format!("{}: '{f}' is not a number", what()),
        )),
    }
}

/// Reads a comma-separated file with a header line into a [`Table`].
///
/// Errors: no header (empty file, only comments, or a first line of
/// numbers), empty or repeated column names, rows with the wrong number
/// of fields, fields that are not finite numbers, no data rows.
///
/// ```
/// let table = frf::csv::parse_table("t,u,y\n0,1,2\n\n# note\n0.1,3,4\n")?;
/// assert_eq!(table.columns[2], vec![2.0, 4.0]);
/// assert_eq!(table.lines, vec![2, 5]);
/// # Ok::<(), frf::csv::CsvError>(())
/// ```
pub fn parse_table(text: &str) -> Result<Table, CsvError> {
    let mut lines = content_lines(text, &['#']);
    let (header_line, header) = lines
        .next()
        .ok_or_else(|| CsvError::file("empty file: no header line"))?;
    let names: Vec<String> = header.split(',').map(|s| s.trim().to_string()).collect();
    if names.iter().all(|n| n.parse::<f64>().is_ok()) {
        return Err(CsvError::at(
            header_line,
            "no header: the first line holds numbers, expected column names",
        ));
    }
    for (i, n) in names.iter().enumerate() {
        if n.is_empty() {
            return Err(CsvError::at(
                header_line,
                format!("column {} has an empty name", i + 1),
            ));
        }
        if names[..i].iter().any(|m| m.eq_ignore_ascii_case(n)) {
            return Err(CsvError::at(
                header_line,
                format!("column '{n}' appears twice"),
            ));
        }
    }
    let mut columns: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
    let mut row_lines = Vec::new();
    for (line, l) in lines {
        let fields: Vec<&str> = l.split(',').collect();
        if fields.len() != names.len() {
            return Err(CsvError::at(
                line,
                format!(
                    "{} fields, expected {} ({})",
                    fields.len(),
                    names.len(),
                    names.join(",")
                ),
            ));
        }
        for (j, f) in fields.iter().enumerate() {
            let inf = names[j].eq_ignore_ascii_case(STD_DEV);
            columns[j].push(number(f, line, inf, &|| format!("column '{}'", names[j]))?);
        }
        row_lines.push(line);
    }
    if row_lines.is_empty() {
        return Err(CsvError::at(header_line, "no data rows after the header"));
    }
    Ok(Table {
        names,
        columns,
        header_line,
        lines: row_lines,
    })
}

/// Column layout of an FRF CSV.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CsvLayout {
    /// `freq_hz,re,im`: real and imaginary part.
    ReIm,
    /// `freq_hz,mag_db,phase_deg`: `20 log10 |H|` and the phase in degrees.
    MagDbPhaseDeg,
}

/// True if the table's header names an FRF (has a `freq_hz` column).
pub fn is_frf_table(table: &Table) -> bool {
    table.find("freq_hz").is_some()
}

/// Reads an FRF CSV; see the [module documentation](self).
pub fn parse_frf_csv(text: &str) -> Result<Frf, CsvError> {
    frf_from_table(&parse_table(text)?)
}

/// Interprets a [`Table`] as an FRF: checks the columns, converts
/// magnitude/phase, and validates the lines (finite, non-negative,
/// strictly increasing frequencies, coherence in `[0, 1]`, at least
/// [`MIN_LINES`] lines), each error naming its file line.
pub fn frf_from_table(table: &Table) -> Result<Frf, CsvError> {
    const KNOWN: [&str; 7] = [
        "freq_hz",
        "re",
        "im",
        "mag_db",
        "phase_deg",
        "coherence",
        STD_DEV,
    ];
    let h = table.header_line;
    for n in &table.names {
        if !KNOWN.contains(&n.to_ascii_lowercase().as_str()) {
            return Err(CsvError::at(
                h,
                format!(
                    "unknown column '{n}' (expected freq_hz,re,im or freq_hz,mag_db,phase_deg, optionally coherence and std_dev)"
                ),
            ));
        }
    }
    let col = |name: &str| table.find(name);
    let freq = col("freq_hz").ok_or_else(|| CsvError::at(h, "missing column 'freq_hz'"))?;
    let cartesian = col("re").is_some() || col("im").is_some();
    let polar = col("mag_db").is_some() || col("phase_deg").is_some();
    let need =
        |name: &str| col(name).ok_or_else(|| CsvError::at(h, format!("missing column '{name}'")));
    let response: Vec<Complex64> = match (cartesian, polar) {
        (true, true) => {
            return Err(CsvError::at(
                h,
                "columns re/im and mag_db/phase_deg are mixed: use one pair",
            ))
        }
        (false, false) => {
            return Err(CsvError::at(
                h,
                "missing columns: expected re,im or mag_db,phase_deg",
            ))
        }
        (true, false) => {
            let (re, im) = (need("re")?, need("im")?);
            table.columns[re]
                .iter()
                .zip(&table.columns[im])
                .map(|(&a, &b)| Complex64::new(a, b))
                .collect()
        }
        (false, true) => {
            let (mag, ph) = (need("mag_db")?, need("phase_deg")?);
            let mut out = Vec::with_capacity(table.rows());
            for (i, (&db, &deg)) in table.columns[mag]
                .iter()
                .zip(&table.columns[ph])
                .enumerate()
            {
                let z = Complex64::from_polar(10f64.powf(db / 20.0), deg.to_radians());
                if !(z.re.is_finite() && z.im.is_finite()) {
                    return Err(CsvError::at(
                        table.lines[i],
                        format!("magnitude {db} dB is out of range"),
                    ));
                }
                out.push(z);
            }
            out
        }
    };
    let coherence = col("coherence").map(|c| table.columns[c].clone());
    let at_line = |e: crate::FrfError| match e.index() {
        Some(i) => CsvError::at(table.lines[i], e.message_without_index()),
        None => CsvError::file(e.to_string()),
    };
    let mut frf = Frf::new(table.columns[freq].clone(), response, coherence).map_err(at_line)?;
    if let Some(c) = col(STD_DEV) {
        frf = frf
            .with_std_dev(table.columns[c].clone())
            .map_err(at_line)?;
    }
    if frf.len() < MIN_LINES {
        return Err(CsvError::file(format!(
            "only {} frequency lines; at least {MIN_LINES} are needed",
            frf.len()
        )));
    }
    Ok(frf)
}

/// Writes an FRF as CSV with a header (`freq_hz,re,im` or
/// `freq_hz,mag_db,phase_deg`, plus `coherence` and `std_dev` when
/// present).
///
/// Numbers use Rust's shortest round-trip exponent format (`{:e}`), so the
/// output is deterministic and [`parse_frf_csv`] reads back exactly the
/// same values in the `ReIm` layout (in the polar layout up to the
/// rounding of the conversion).
pub fn write_csv(frf: &Frf, layout: CsvLayout) -> String {
    let mut out = String::new();
    out.push_str(match layout {
        CsvLayout::ReIm => "freq_hz,re,im",
        CsvLayout::MagDbPhaseDeg => "freq_hz,mag_db,phase_deg",
    });
    let coh = frf.coherence();
    if coh.is_some() {
        out.push_str(",coherence");
    }
    let sd = frf.std_dev();
    if sd.is_some() {
        out.push_str(",std_dev");
    }
    out.push('\n');
    for (i, (&f, &h)) in frf.freq_hz().iter().zip(frf.response()).enumerate() {
        let (a, b) = match layout {
            CsvLayout::ReIm => (h.re, h.im),
            CsvLayout::MagDbPhaseDeg => (20.0 * h.norm().log10(), h.arg().to_degrees()),
        };
        // A zero response has no finite dB value; write the smallest
        // finite one instead so the file stays readable.
        let a = if a.is_finite() { a } else { f64::MIN };
        let _ = write!(out, "{f:e},{a:e},{b:e}");
        if let Some(c) = coh {
            let _ = write!(out, ",{:e}", c[i]);
        }
        if let Some(s) = sd {
            let _ = write!(out, ",{:e}", s[i]);
        }
        out.push('\n');
    }
    out
}

/// Samples of a time-domain recording.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeSeries {
    /// Sample rate in Hz.
    pub fs: f64,
    /// Input samples.
    pub u: Vec<f64>,
    /// Output samples.
    pub y: Vec<f64>,
}

/// Picks the input and output columns `u` and `y` (names, trimmed,
/// case-insensitive) of a time-domain CSV table. The sample rate is `fs`
/// when given, otherwise it comes from the column `t`, whose steps must
/// be uniform within [`crate::welch::TIME_STEP_TOLERANCE`].
///
/// ```
/// use frf::csv::{parse_table, time_series_from_table};
/// let table = parse_table("t,force,pos\n0,1,0\n0.5,2,1\n1.0,3,1\n")?;
/// let ts = time_series_from_table(&table, "force", "pos", None)?;
/// assert_eq!(ts.fs, 2.0);
/// assert_eq!(ts.u, vec![1.0, 2.0, 3.0]);
/// # Ok::<(), frf::csv::CsvError>(())
/// ```
pub fn time_series_from_table(
    table: &Table,
    u: &str,
    y: &str,
    fs: Option<f64>,
) -> Result<TimeSeries, CsvError> {
    let h = table.header_line;
    let pick = |name: &str| {
        table.find(name).ok_or_else(|| {
            CsvError::at(
                h,
                format!(
                    "missing column '{}' (columns: {})",
                    name.trim(),
                    table.names.join(",")
                ),
            )
        })
    };
    let (ui, yi) = (pick(u)?, pick(y)?);
    let fs = match fs {
        Some(fs) => fs,
        None => {
            let ti = table.find("t").ok_or_else(|| {
                CsvError::at(
                    h,
                    format!(
                        "no column 't' to take the sample rate from (columns: {}); give the sample rate",
                        table.names.join(",")
                    ),
                )
            })?;
            sample_rate_from_times(&table.columns[ti])
                .map_err(|e| CsvError::at(table.lines[e.index], format!("column 't': {e}")))?
        }
    };
    if !(fs.is_finite() && fs > 0.0) {
        return Err(CsvError::file(format!(
            "sample rate {fs} Hz is not a positive finite number"
        )));
    }
    Ok(TimeSeries {
        fs,
        u: table.columns[ui].clone(),
        y: table.columns[yi].clone(),
    })
}

/// A headerless numeric matrix, stored by columns.
#[derive(Clone, Debug, PartialEq)]
pub struct Matrix {
    /// Number of rows.
    pub rows: usize,
    /// Number of columns.
    pub cols: usize,
    /// Column-major values (`cols` vectors of `rows` values each).
    pub columns: Vec<Vec<f64>>,
    /// 1-based file line of each row.
    pub lines: Vec<usize>,
}

impl Matrix {
    /// Column `number`, counted from 1.
    pub fn column(&self, number: usize) -> Option<&[f64]> {
        number
            .checked_sub(1)
            .and_then(|j| self.columns.get(j))
            .map(|c| c.as_slice())
    }
}

/// Reads whitespace-separated numbers, one row per line, every row with
/// the same number of values; lines starting with `#` or `%` and blank
/// lines are skipped.
///
/// ```
/// let m = frf::csv::parse_matrix("% torque accel\n 1.0e-1  2\n-3 4.5\n")?;
/// assert_eq!((m.rows, m.cols), (2, 2));
/// assert_eq!(m.column(2), Some(&[2.0, 4.5][..]));
/// assert_eq!(m.column(3), None);
/// # Ok::<(), frf::csv::CsvError>(())
/// ```
pub fn parse_matrix(text: &str) -> Result<Matrix, CsvError> {
    let mut columns: Vec<Vec<f64>> = Vec::new();
    let mut lines = Vec::new();
    for (line, l) in content_lines(text, &['#', '%']) {
        let fields: Vec<&str> = l.split_whitespace().collect();
        if lines.is_empty() {
            columns = vec![Vec::new(); fields.len()];
        } else if fields.len() != columns.len() {
            return Err(CsvError::at(
                line,
                format!(
                    "{} values, expected {} as in the first row",
                    fields.len(),
                    columns.len()
                ),
            ));
        }
        for (j, f) in fields.iter().enumerate() {
            columns[j].push(number(f, line, false, &|| format!("column {}", j + 1))?);
        }
        lines.push(line);
    }
    if lines.is_empty() {
        return Err(CsvError::file("empty file: no numbers"));
    }
    Ok(Matrix {
        rows: lines.len(),
        cols: columns.len(),
        columns,
        lines,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frf_text(header: &str, rows: usize) -> String {
        let mut t = format!("{header}\n");
        for k in 1..=rows {
            t.push_str(&format!(
                "{},{},{}\n",
                k as f64 * 0.5,
                1.0 / k as f64,
                -(k as f64)
            ));
        }
        t
    }

    #[test]
    fn reads_re_im_in_any_order_with_comments() {
        let mut text = String::from("\n# exported\n  # indented comment\nIM , Freq_Hz,re\n");
        for k in 1..=12 {
            text.push_str(&format!(
                "{},{},{}\n",
                -(k as f64),
                k as f64,
                2.0 * k as f64
            ));
            if k == 6 {
                text.push_str("# halfway\n\n");
            }
        }
        let frf = parse_frf_csv(&text).unwrap();
        assert_eq!(frf.len(), 12);
        assert_eq!(frf.freq_hz()[0], 1.0);
        assert_eq!(frf.response()[11], Complex64::new(24.0, -12.0));
        assert!(frf.coherence().is_none());
    }

    #[test]
    fn reads_mag_db_phase_deg() {
        // 20 dB at -90 degrees is 10 * exp(-i pi/2) = -10 i.
        let mut text = String::from("phase_deg,mag_db,freq_hz,coherence\n");
        for k in 1..=10 {
            text.push_str(&format!("-90,20,{k},0.5\n"));
        }
        let frf = parse_frf_csv(&text).unwrap();
        let h = frf.response()[3];
        assert!((h - Complex64::new(0.0, -10.0)).norm() < 1e-12);
        assert_eq!(frf.coherence().unwrap()[0], 0.5);
    }

    #[test]
    fn column_errors_name_the_column() {
        let e = parse_frf_csv(&frf_text("freq_hz,re,imag", 10)).unwrap_err();
        assert_eq!(e.line, Some(1));
        assert!(e.message.contains("'imag'"), "{e}");
        let e = parse_frf_csv(&frf_text("freq_hz,re,coherence", 10)).unwrap_err();
        assert!(e.message.contains("missing column 'im'"), "{e}");
        let e = parse_frf_csv(&frf_text("f,re,im", 10)).unwrap_err();
        assert!(e.message.contains("'f'"), "{e}");
        let e = parse_frf_csv(&frf_text("freq_hz,re,mag_db", 10)).unwrap_err();
        assert!(e.message.contains("mixed"), "{e}");
        let e = parse_frf_csv(&frf_text("freq_hz,re,RE", 10)).unwrap_err();
        assert!(e.message.contains("twice"), "{e}");
    }

    #[test]
    fn no_header_and_empty_file() {
        let e = parse_frf_csv("1,2,3\n2,3,4\n").unwrap_err();
        assert_eq!(e.line, Some(1));
        assert!(e.message.contains("no header"), "{e}");
        let e = parse_frf_csv("").unwrap_err();
        assert_eq!(e.line, None);
        assert!(e.message.contains("empty"), "{e}");
        let e = parse_frf_csv("# only a comment\n\n").unwrap_err();
        assert!(e.message.contains("empty"), "{e}");
        let e = parse_frf_csv("freq_hz,re,im\n").unwrap_err();
        assert!(e.message.contains("no data"), "{e}");
    }

    #[test]
    fn value_errors_name_the_file_line() {
        // Line numbers count comments and blank lines: header on line 2.
        let base = frf_text("# c\nfreq_hz,re,im", 12);
        let with = |line: usize, replacement: &str| {
            let mut ls: Vec<String> = base.lines().map(String::from).collect();
            ls[line - 1] = replacement.to_string();
            ls.join("\n")
        };
        for (bad, needle) in [
            ("3.5,NaN,1", "not a finite number"),
            ("3.5,1,inf", "not a finite number"),
            ("3.5,1,-Infinity", "not a finite number"),
            ("3.5,abc,1", "not a number"),
            ("3.5,1", "2 fields, expected 3"),
        ] {
            let e = parse_frf_csv(&with(9, bad)).unwrap_err();
            assert_eq!(e.line, Some(9), "{bad}: {e}");
            assert!(e.message.contains(needle), "{bad}: {e}");
        }
        // Line 9 holds the 7th row (3.5 Hz); 1.0 Hz there does not increase.
        let e = parse_frf_csv(&with(9, "1.0,1,1")).unwrap_err();
        assert_eq!(e.line, Some(9));
        assert!(e.message.contains("does not increase"), "{e}");
        let e = parse_frf_csv(&with(3, "-0.5,1,1")).unwrap_err();
        assert_eq!(e.line, Some(3));
        assert!(e.message.contains("negative"), "{e}");
        let e = parse_frf_csv(&frf_text("freq_hz,re,im", 9)).unwrap_err();
        assert!(e.message.contains("only 9 frequency lines"), "{e}");
        let mut coh = String::from("freq_hz,re,im,coherence\n");
        for k in 1..=10 {
            coh.push_str(&format!("{k},1,1,{}\n", if k == 4 { 1.5 } else { 0.9 }));
        }
        let e = parse_frf_csv(&coh).unwrap_err();
        assert_eq!(e.line, Some(5));
        assert!(e.message.contains("outside [0, 1]"), "{e}");
    }

    #[test]
    fn writer_round_trips() {
        let freq: Vec<f64> = (1..=20).map(|k| k as f64 * 0.48828125).collect();
        let resp: Vec<Complex64> = (1..=20)
            .map(|k| Complex64::from_polar(1.0 / (k as f64).powf(1.7), -0.1 * k as f64 - 1e-3))
            .collect();
        let coh: Vec<f64> = (1..=20).map(|k| 1.0 - 1.0 / (k as f64 + 3.0)).collect();
        let frf = Frf::new(freq, resp, Some(coh)).unwrap();
        let text = write_csv(&frf, CsvLayout::ReIm);
        assert!(text.starts_with("freq_hz,re,im,coherence\n"));
        // Shortest round-trip formatting reproduces every bit.
        assert_eq!(parse_frf_csv(&text).unwrap(), frf);
        let polar = parse_frf_csv(&write_csv(&frf, CsvLayout::MagDbPhaseDeg)).unwrap();
        assert_eq!(polar.freq_hz(), frf.freq_hz());
        for (a, b) in polar.response().iter().zip(frf.response()) {
            // dB and degree conversions cost a few ulps.
            assert!((a - b).norm() <= 1e-14 * b.norm(), "{a} vs {b}");
        }
        // Deterministic: the same FRF gives the same bytes.
        assert_eq!(write_csv(&frf, CsvLayout::ReIm), text);
    }

    #[test]
    fn time_series_from_t_column() {
        let mut text = String::from("# logger\nt,u,y,extra\n");
        for n in 0..50 {
            // Six decimals, as loggers print them: steps are not exact.
            text.push_str(&format!("{:.6},{},{},0\n", n as f64 / 3000.0, n, 2 * n));
        }
        let table = parse_table(&text).unwrap();
        let ts = time_series_from_table(&table, "u", "Y", None).unwrap();
        // Rounding t[49] = 0.0163333.. to six decimals shifts the span by
        // 3.3e-7 s of 0.0163 s: 2e-5 relative.
        assert!((ts.fs - 3000.0).abs() < 3000.0 * 5e-5, "{}", ts.fs);
        assert_eq!(ts.y[10], 20.0);
        let ts = time_series_from_table(&table, "extra", "u", Some(10.0)).unwrap();
        assert_eq!(ts.fs, 10.0);
        let e = time_series_from_table(&table, "force", "y", None).unwrap_err();
        assert_eq!(e.line, Some(2));
        assert!(e.message.contains("'force'"), "{e}");
    }

    #[test]
    fn non_uniform_time_is_an_error_at_its_line() {
        let mut text = String::from("t,u,y\n");
        for n in 0..20 {
            // One late sample: steps 1.5 and 0.5 around it.
            let t = if n == 12 { 12.5 } else { n as f64 };
            text.push_str(&format!("{t},1,2\n"));
        }
        let table = parse_table(&text).unwrap();
        let e = time_series_from_table(&table, "u", "y", None).unwrap_err();
        // Sample 12 (0-based) is on file line 14.
        assert_eq!(e.line, Some(14));
        assert!(e.message.contains("non-uniform"), "{e}");
        // Without a t column the rate must be given.
        let table = parse_table("u,y\n1,2\n3,4\n").unwrap();
        let e = time_series_from_table(&table, "u", "y", None).unwrap_err();
        assert!(e.message.contains("no column 't'"), "{e}");
    }

    #[test]
    fn matrix_errors() {
        let e = parse_matrix("1 2\n3\n").unwrap_err();
        assert_eq!(e.line, Some(2));
        let e = parse_matrix("1 2\n3 nan\n").unwrap_err();
        assert!(e.message.contains("column 2"), "{e}");
        assert!(parse_matrix("  \n% nothing\n").is_err());
    }
}
