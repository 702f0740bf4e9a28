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
    /// still gives fewer than two labels, all ticks are.
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
    ticks
        .into_iter()
        .map(|(m, e)| Tick {
            value: f64::from(m) * 10f64.powi(e),
            label: labelled.contains(&m).then(|| si_label(m, e)),
            major: m == 1,
        })
        .collect()
}

/// `m x 10^e` written with an SI suffix: "200", "1k", "50k", "0.02".
fn si_label(m: u32, e: i32) -> String {
    let (suffix, shift) = match e {
        13.. | ..=-7 => return format!("{m}e{e}"),
        9..=12 => ("G", 9),
        6..=8 => ("M", 6),
        3..=5 => ("k", 3),
        _ => ("", 0),
    };
    let e = e - shift;
    if e >= 0 {
        format!("{m}{}{suffix}", "0".repeat(e as usize))
    } else {
        format!("0.{}{m}", "0".repeat((-e - 1) as usize))
    }
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
        assert_eq!(
            labels(&Axis::log(0.05, 2.0, "")),
            ["0.05", "0.1", "0.2", "0.5", "1", "2"]
        );
        assert_eq!(
            labels(&Axis::log(0.5, 10.0, "")),
            ["0.5", "1", "2", "5", "10"]
        );
        assert_eq!(labels(&Axis::log(15.0, 60.0, "")), ["20", "50"]);
        assert_eq!(labels(&Axis::log(2.1, 4.5, "")), ["3", "4"]);
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
    }
}
