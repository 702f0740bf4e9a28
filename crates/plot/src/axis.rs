//! Axes: scales, ranges and ticks with their labels.

/// How data values map onto an axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// Equal distances for equal differences.
    Linear,
    /// Equal distances for equal ratios (base 10); values `<= 0` are gaps.
    Log,
}

/// One tick: a grid line, a tick mark and an optional label.
#[derive(Clone, Debug, PartialEq)]
pub struct Tick {
    /// Position in data units.
    pub value: f64,
    /// Text drawn next to the tick, if any.
    pub label: Option<String>,
    /// Major ticks get a darker grid line and a longer mark.
    pub major: bool,
}

/// An axis: scale, range (`min` maps to the left or bottom edge of its
/// panel), ticks and a title.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    /// Linear or logarithmic.
    pub scale: Scale,
    /// Value at the left (x) or bottom (y) edge.
    pub min: f64,
    /// Value at the right (x) or top (y) edge.
    pub max: f64,
    /// Ticks, in any order.
    pub ticks: Vec<Tick>,
    /// Axis title, e.g. `"Magnitude [dB]"`; empty for none.
    pub label: String,
}

impl Axis {
    /// A linear axis that shows `lo..=hi` with a 5 % margin on each side,
    /// extended outwards to the next multiple of a nice tick step (1, 2 or
    /// 5 x 10^k, about five intervals). Degenerate input still gives a
    /// usable axis: non-finite bounds fall back to `-1..=1`, swapped bounds
    /// are put in order, and an empty range is widened around its value.
    ///
    /// ```
    /// let axis = plot::Axis::linear(-3.2, 41.0, "Magnitude [dB]");
    /// assert_eq!((axis.min, axis.max), (-10.0, 50.0));
    /// let labels: Vec<_> = axis.ticks.iter().filter_map(|t| t.label.clone()).collect();
    /// assert_eq!(labels, ["-10", "0", "10", "20", "30", "40", "50"]);
    /// ```
    pub fn linear(lo: f64, hi: f64, label: impl Into<String>) -> Axis {
        Axis::linear_with(lo, hi, label, 6)
    }

    /// [`Axis::linear`] with at most `max_intervals` (at least 2) tick
    /// intervals: the smallest nice step that fits, so that the range
    /// wastes little room. Callers that know the axis length in pixels can
    /// allow one interval per 30 px or so.
    ///
    /// ```
    /// let axis = plot::Axis::linear_with(-38.0, 24.0, "", 8);
    /// assert_eq!((axis.min, axis.max, axis.ticks.len()), (-50.0, 30.0, 9));
    /// let axis = plot::Axis::linear_with(-38.0, 24.0, "", 5);
    /// assert_eq!((axis.min, axis.max, axis.ticks.len()), (-60.0, 40.0, 6));
    /// ```
    pub fn linear_with(lo: f64, hi: f64, label: impl Into<String>, max_intervals: usize) -> Axis {
        let (mut lo, mut hi) = ordered(lo, hi).unwrap_or((-1.0, 1.0));
        if hi - lo <= 1e-9 * lo.abs().max(hi.abs()).max(1.0) {
            let half = (0.1 * lo.abs()).max(1.0);
            (lo, hi) = (lo - half, hi + half);
        }
        let pad = 0.05 * (hi - lo);
        let intervals = max_intervals.max(2) as f64;
        let mut step = nice_step((hi - lo + 2.0 * pad) / intervals);
        let (mut min, mut max) = (lo, hi);
        // Rounding the ends outwards can add up to two intervals; two
        // larger steps always fit, and usually the first does.
        for _ in 0..3 {
            min = ((lo - pad) / step).floor() * step;
            max = ((hi + pad) / step).ceil() * step;
            if (max - min) / step <= intervals + 1e-9 {
                break;
            }
            step = nice_step(step * 1.01);
        }
        Axis {
            scale: Scale::Linear,
            min,
            max,
            ticks: linear_ticks(min, max, step),
            label: label.into(),
        }
    }

    /// A base-10 logarithmic axis over exactly `lo..=hi` (Bode plots end
    /// where the data ends), with a major tick at every decade and minor
    /// ticks at 2..9 times the decade. Decades are labelled "0.1", "1",
    /// "10", "100", "1k", "10k", "1M"; when fewer than three decade ticks
    /// fall in the range, the 2 and 5 ticks are labelled too, and if that
    /// still gives fewer than two labels, all ticks are. Where a stretch
    /// shorter than a decade but longer than a third of the axis would
    /// still have no label, labelled ticks at 1.5 and 2.5 times the decade
    /// are added (then all ticks labelled), and a range too narrow for
    /// any of these gets round linear steps.
    /// Bounds that are not finite and positive fall back to `1..=1000`; a
    /// single value is widened to a factor of 2 either side.
    ///
    /// ```
    /// let axis = plot::Axis::log(5.0, 2000.0, "Frequency [Hz]");
    /// let labels: Vec<_> = axis.ticks.iter().filter_map(|t| t.label.clone()).collect();
    /// assert_eq!(labels, ["10", "100", "1k"]);
    /// ```
    pub fn log(lo: f64, hi: f64, label: impl Into<String>) -> Axis {
        let (mut lo, mut hi) = ordered(lo, hi)
            .filter(|&(lo, hi)| lo > 0.0 && hi < f64::MAX)
            .unwrap_or((1.0, 1000.0));
        if hi / lo < 1.0 + 1e-9 {
            (lo, hi) = (lo / 2.0, hi * 2.0);
        }
        Axis {
            scale: Scale::Log,
            min: lo,
            max: hi,
            ticks: log_ticks(lo, hi),
            label: label.into(),
        }
    }

    /// Where `v` falls between `min` (0) and `max` (1); not finite for
    /// values the axis cannot show (NaN, or `<= 0` on a log axis).
    ///
    /// ```
    /// let axis = plot::Axis::log(1.0, 100.0, "");
    /// assert!((axis.fraction(10.0) - 0.5).abs() < 1e-12);
    /// assert!(!axis.fraction(0.0).is_finite());
    /// ```
    pub fn fraction(&self, v: f64) -> f64 {
        match self.scale {
            Scale::Linear => (v - self.min) / (self.max - self.min),
            Scale::Log if v > 0.0 => {
                (v.log10() - self.min.log10()) / (self.max.log10() - self.min.log10())
            }
            Scale::Log => f64::NAN,
        }
    }
}

fn ordered(a: f64, b: f64) -> Option<(f64, f64)> {
    let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
    // The span must be finite too, or every later step overflows.
    (lo.is_finite() && hi.is_finite() && (hi - lo).is_finite()).then_some((lo, hi))
}

/// The smallest of 1, 2, 5 x 10^k that is at least `raw`.
fn nice_step(raw: f64) -> f64 {
    if !(raw > 0.0 && raw.is_finite()) {
        return 1.0;
    }
    let mag = 10f64.powi(raw.log10().floor() as i32);
    let n = raw / mag;
    let m = if n <= 1.0 {
        1.0
    } else if n <= 2.0 {
        2.0
    } else if n <= 5.0 {
        5.0
    } else {
        10.0
    };
    m * mag
}

fn linear_ticks(min: f64, max: f64, step: f64) -> Vec<Tick> {
    let (first, last) = ((min / step).round(), (max / step).round());
    if !(last - first).is_finite() || last - first > 1000.0 {
        return Vec::new();
    }
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    (first as i64..=last as i64)
        .map(|i| {
            // i * step, not repeated addition, so labels carry no drift;
            // i == 0 gives +0.0 so no label reads "-0".
            let value = i as f64 * step;
            Tick {
                value,
                label: Some(format!("{value:.decimals$}")),
                major: true,
            }
        })
        .collect()
}

fn log_ticks(lo: f64, hi: f64) -> Vec<Tick> {
    let (e0, e1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let decades = e1 - e0;
    // Over very wide ranges minor ticks would be a grey smear and decade
    // labels would collide: keep every stride-th decade only.
    let stride = if decades > 12 { (decades + 9) / 10 } else { 1 };
    let inside = |v: f64| v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9);
    let mut ticks: Vec<(u32, i32)> = Vec::new();
    for e in e0..=e1 {
        let ms: &[u32] = if stride > 1 {
            &[1]
        } else {
            &[1, 2, 3, 4, 5, 6, 7, 8, 9]
        };
        for &m in ms {
            if (stride == 1 || e.rem_euclid(stride) == 0) && inside(f64::from(m) * 10f64.powi(e)) {
                ticks.push((m, e));
            }
        }
    }
    let count = |set: &[u32]| ticks.iter().filter(|(m, _)| set.contains(m)).count();
    let labelled: &[u32] = if count(&[1]) >= 3 {
        &[1]
    } else if count(&[1, 2, 5]) >= 2 {
        &[1, 2, 5]
    } else {
        &[1, 2, 3, 4, 5, 6, 7, 8, 9]
    };
    // Ticks as (mantissa in tenths, exponent): 15 is 1.5 x 10^e.
    let mut ticks: Vec<(u32, i32, bool)> = ticks
        .into_iter()
        .map(|(m, e)| (10 * m, e, labelled.contains(&m)))
        .collect();
    // A short range can leave a long stretch without a label (54-194 Hz:
    // nothing between 100 and 194): labelled half steps fill such a gap,
    // so that no more than a third of the axis goes unlabelled, apart from
    // whole decades between labelled decades.
    if stride == 1 {
        let span = (hi / lo).log10();
        let at = |t: &(u32, i32, bool)| f64::from(t.0) / 10.0 * 10f64.powi(t.1);
        let largest_gap = |ticks: &[(u32, i32, bool)]| {
            let mut marks: Vec<f64> = ticks.iter().filter(|t| t.2).map(at).collect();
            marks.push(lo);
            marks.push(hi);
            marks.sort_by(f64::total_cmp);
            marks
                .windows(2)
                .map(|w| (w[1] / w[0]).log10())
                .filter(|&d| d < 1.0 - 1e-9)
                .map(|d| d / span)
                .fold(0.0, f64::max)
        };
        if largest_gap(&ticks) > 1.0 / 3.0 {
            for e in e0..=e1 {
                for m in [15, 25] {
                    if inside(f64::from(m) / 10.0 * 10f64.powi(e)) {
                        ticks.push((m, e, true));
                    }
                }
            }
            // Every integer mantissa labelled too where that is all the
            // range holds.
            if largest_gap(&ticks) > 1.0 / 3.0 {
                ticks.iter_mut().for_each(|t| t.2 = true);
            }
            ticks.sort_by(|a, b| at(a).total_cmp(&at(b)));
        }
    }
    // A range within one step of the mantissas (105-118 Hz): round linear
    // steps, as a linear axis of the same range would have.
    let at = |t: &(u32, i32, bool)| f64::from(t.0) / 10.0 * 10f64.powi(t.1);
    let mut marks: Vec<f64> = ticks.iter().filter(|t| t.2).map(at).collect();
    let sparse = marks.len() < 3 || {
        marks.extend([lo, hi]);
        marks.sort_by(f64::total_cmp);
        let span = (hi / lo).log10();
        marks.windows(2).any(|w| {
            let d = (w[1] / w[0]).log10();
            d < 1.0 - 1e-9 && d / span > 1.0 / 3.0
        })
    };
    if sparse {
        // The largest step of 1, 2 or 5 x 10^k that gives four ticks.
        let mut step = nice_step((hi - lo) / 4.0);
        for _ in 0..4 {
            let within: Vec<Tick> = linear_ticks(lo, hi, step)
                .into_iter()
                .filter(|t| inside(t.value))
                .collect();
            if within.len() >= 4 {
                return within;
            }
            step = nice_step(step / 2.6);
        }
    }
    ticks
        .into_iter()
        .map(|(m, e, labelled)| Tick {
            value: f64::from(m) / 10.0 * 10f64.powi(e),
            label: labelled.then(|| si_label(m, e - 1)),
            major: m == 10,
        })
        .collect()
}

/// `m x 10^e` written with an SI suffix: "200", "1k", "50k", "0.02",
/// "150", "1.5k" (`m` a positive integer of one or more digits).
fn si_label(m: u32, e: i32) -> String {
    let digits = m.to_string();
    // The exponent of the leading digit decides the suffix.
    let lead = e + digits.len() as i32 - 1;
    let (suffix, shift) = match lead {
        13.. | ..=-7 => {
            let rest = digits[1..].trim_end_matches('0');
            let point = if rest.is_empty() { "" } else { "." };
            return format!("{}{point}{rest}e{lead}", &digits[..1]);
        }
        9..=12 => ("G", 9),
        6..=8 => ("M", 6),
        3..=5 => ("k", 3),
        _ => ("", 0),
    };
    let k = e - shift;
    let text = if k >= 0 {
        format!("{digits}{}", "0".repeat(k as usize))
    } else {
        let point = digits.len() as i32 + k;
        let s = if point > 0 {
            format!(
                "{}.{}",
                &digits[..point as usize],
                &digits[point as usize..]
            )
        } else {
            format!("0.{}{digits}", "0".repeat((-point) as usize))
        };
        // 1.50 reads 1.5; 2.0 reads 2.
        let s = s.trim_end_matches('0');
        s.trim_end_matches('.').to_string()
    };
    format!("{text}{suffix}")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(axis: &Axis) -> Vec<String> {
        axis.ticks.iter().filter_map(|t| t.label.clone()).collect()
    }

    #[test]
    fn nice_steps() {
        assert_eq!(nice_step(0.7), 1.0);
        assert_eq!(nice_step(1.3), 2.0);
        assert_eq!(nice_step(16.0), 20.0);
        assert_eq!(nice_step(45.0), 50.0);
        assert_eq!(nice_step(0.03), 0.05);
        assert_eq!(nice_step(7.0), 10.0);
        assert_eq!(nice_step(f64::NAN), 1.0);
    }

    #[test]
    fn linear_axes() {
        let a = Axis::linear(-181.0, 0.0, "");
        assert_eq!((a.min, a.max), (-200.0, 50.0));
        assert_eq!(labels(&a), ["-200", "-150", "-100", "-50", "0", "50"]);
        let a = Axis::linear(0.1, 0.9, "");
        assert_eq!(labels(&a)[..3], ["0.0", "0.2", "0.4"]);
        // Degenerate: constant, swapped, non-finite.
        let a = Axis::linear(3.0, 3.0, "");
        assert!(a.min < 3.0 && a.max > 3.0 && a.ticks.len() >= 2);
        assert_eq!(Axis::linear(5.0, 1.0, ""), Axis::linear(1.0, 5.0, ""));
        let a = Axis::linear(f64::NAN, f64::INFINITY, "");
        assert!(a.min < 0.0 && a.max > 0.0);
        let a = Axis::linear(-f64::MAX, f64::MAX, "");
        assert!(a.min.is_finite() && a.max.is_finite());
    }

    #[test]
    fn log_axes() {
        assert_eq!(
            labels(&Axis::log(1.0, 1e4, "")),
            ["1", "10", "100", "1k", "10k"]
        );
        let cases: [(f64, f64, &[&str]); 5] = [
            (0.05, 2.0, &["0.05", "0.1", "0.2", "0.5", "1", "2"]),
            (0.5, 10.0, &["0.5", "1", "2", "5", "10"]),
            (15.0, 60.0, &["15", "20", "25", "30", "40", "50", "60"]),
            (2.1, 4.5, &["2.5", "3.0", "3.5", "4.0", "4.5"]),
            (
                105.0,
                118.0,
                &["106", "108", "110", "112", "114", "116", "118"],
            ),
        ];
        for (lo, hi, expected) in cases {
            assert_eq!(labels(&Axis::log(lo, hi, "")), expected, "{lo}-{hi}");
        }
        assert_eq!(Axis::log(1.0, 1000.0, "").ticks.len(), 28);
        let wide = Axis::log(1e-30, 1e30, "");
        assert!(wide.ticks.len() <= 11 && wide.ticks.iter().all(|t| t.major));
        let single = Axis::log(50.0, 50.0, "");
        assert_eq!((single.min, single.max), (25.0, 100.0));
        assert_eq!(Axis::log(-1.0, 0.0, "").min, 1.0);
    }

    #[test]
    fn si_labels() {
        let cases = [
            (1, 0, "1"),
            (1, 1, "10"),
            (2, 2, "200"),
            (1, 3, "1k"),
            (5, 4, "50k"),
        ];
        for (m, e, s) in cases {
            assert_eq!(si_label(m, e), s);
        }
        assert_eq!(si_label(1, 6), "1M");
        assert_eq!(si_label(1, -1), "0.1");
        assert_eq!(si_label(2, -2), "0.02");
        assert_eq!(si_label(1, 15), "1e15");
        assert_eq!(si_label(15, 1), "150");
        assert_eq!(si_label(15, 2), "1.5k");
        assert_eq!(si_label(25, -2), "0.25");
        assert_eq!(si_label(15, -4), "0.0015");
        assert_eq!(si_label(10, 0), "10");
        assert_eq!(si_label(10, -1), "1");
        assert_eq!(si_label(15, 14), "1.5e15");
    }

    /// The ranges of real plots (a diagnosis band of 54-194 Hz, the F16
    /// band of 2-15 Hz, a discrete-time axis of 0.004-0.3 cycles/sample,
    /// and others): every decade the range reaches has a labelled tick, the
    /// axis has at least 3 labels, no third of it goes unlabelled (but for
    /// whole decades between labelled decades), and the labels read their
    /// tick's value.
    #[test]
    fn log_axes_are_labelled_over_short_and_long_ranges() {
        for (lo, hi) in [
            (54.0, 194.0),
            (2.0, 15.0),
            (0.004, 0.3),
            (0.9766, 258.8),
            (105.0, 118.0),
            (1.0, 1e4),
            (0.12, 2000.0),
            (40.0, 60.0),
        ] {
            let axis = Axis::log(lo, hi, "");
            let marks: Vec<&Tick> = axis.ticks.iter().filter(|t| t.label.is_some()).collect();
            assert!(marks.len() >= 3, "{lo}-{hi}: {:?}", labels(&axis));
            for t in &marks {
                let text = t.label.as_ref().unwrap();
                let read: f64 = match text.strip_suffix('k') {
                    Some(v) => v.parse::<f64>().unwrap() * 1e3,
                    None => text.parse().unwrap(),
                };
                assert!(
                    (read / t.value - 1.0).abs() < 1e-12,
                    "{text} at {}",
                    t.value
                );
            }
            let (e0, e1) = (
                lo.log10().floor() as i32,
                (hi.log10() - 1e-12).floor() as i32,
            );
            for e in e0..=e1 {
                let (a, b) = (10f64.powi(e).max(lo), 10f64.powi(e + 1).min(hi));
                // A decade of which the range holds more than a fifth.
                if (b / a).log10() > 0.2 {
                    assert!(
                        marks
                            .iter()
                            .any(|t| t.value >= a * (1.0 - 1e-9) && t.value <= b * (1.0 + 1e-9)),
                        "{lo}-{hi}: no label in {a}-{b}: {:?}",
                        labels(&axis)
                    );
                }
            }
            let mut at: Vec<f64> = marks.iter().map(|t| t.value).collect();
            at.extend([lo, hi]);
            at.sort_by(f64::total_cmp);
            let span = (hi / lo).log10();
            let gap = at
                .windows(2)
                .map(|w| (w[1] / w[0]).log10())
                .filter(|&d| d < 1.0 - 1e-9)
                .map(|d| d / span)
                .fold(0.0, f64::max);
            assert!(
                gap <= 1.0 / 3.0 + 1e-9,
                "{lo}-{hi}: gap {gap}: {:?}",
                labels(&axis)
            );
        }
    }
}
