//! Points on the variety of a type with coincident roots, in `f64`.
//!
//! A type with cancelled poles or multiple zeros lives on a variety: a
//! pole cancelled at `rho` needs `N(rho) = D(rho) = 0`, an `A^mu` at
//! `sigma` needs `N` and its first `mu - 1` derivatives to vanish there.
//! Log-uniform points never land on it, so the sampler projects them onto
//! it. The unknowns are the logarithms of the parameters, of every
//! cancelled pole and of every multiple zero; each condition is divided by
//! the sum of its terms' moduli, so that `1e-13` means zero in `f64`. From
//! a log-uniform start, with the poles and zeros at roots of the start's
//! denominator and numerator, a min-norm Gauss-Newton step
//! `dx = -J^T (J J^T)^-1 F` (the Jacobian exact in the logarithms, the
//! normalisation held constant) moves onto the variety.
//!
//! A converged point's type is read without the ill-conditioned multiple
//! roots: the posed ones are divided out of numerator and denominator
//! (composite deflation, so that a large root does not swamp the small
//! ones), the rests' positive roots bracketed, and the point is skipped
//! when two of all its positive roots lie within a relative
//! [`SEPARATION`] (a point of a thinner stratum, or one `f64` cannot
//! order). The reading is a prediction, not a proof: the prover turns a
//! point into a witness by isolating a solution of the conditions in a
//! box next to it ([`super::isolated`]), and the checker reads that
//! witness by exact arithmetic.

use super::frf_type::{Feature, FrfType, Token};
use super::targeted::{positive_roots, zeros_near_the_axis, VIOLATION_GAP};
use crate::tf::{self, Compiled, Gradients, UndampedCoefficients, OMEGA};
use crate::xorshift::XorShift;
use poly::Poly;

/// Gauss-Newton steps before a start is given up.
const ITERATIONS: usize = 40;
/// Largest normalised residual of a point on the variety.
const TOLERANCE: f64 = 1e-13;
/// Relative distance below which two roots count as one.
pub(crate) const SEPARATION: f64 = 1e-6;
/// How far (in logarithms) a converged point may leave the start box.
const BOX_MARGIN: f64 = 2.0;
/// A projection whose parameters go this much further out is given up:
/// it would have to come back to count, and at 5 masses none did (of
/// the points that converged inside, the farthest went 0.46 beyond).
/// A quarter to a third of the steps were spent on such starts.
const ESCAPE: f64 = 1.0;

/// The variety of `cancelled` cancelled poles and multiple zeros of the
/// multiplicities `multiple` of one model's undamped inertance; of the
/// cancelled poles, `2 * doubles` may be cancelled in pairs where the
/// chain's two blocks share an eigenvalue (the denominator's double root
/// there, and the numerator's).
pub(crate) struct Variety<'a> {
    tf: &'a UndampedCoefficients,
    params: usize,
    cancelled: usize,
    doubles: usize,
    blocks: Option<&'a BlockFactors>,
    multiple: &'a [u32],
}

/// The two blocks' determinants of a chain with a gap (`det A` and
/// `det B / Omega`, whose product is the denominator up to a constant),
/// compiled: where both vanish at `rho`, the denominator has a double root
/// and the numerator a root there, so a pole cancelled twice is posed as
/// both factors and the numerator's derivative vanishing at `rho`.
pub(crate) struct BlockFactors {
    coeffs: [Vec<Compiled>; 2],
}

impl BlockFactors {
    pub(crate) fn new(factors: &[Poly; 2], names: &[String]) -> BlockFactors {
        let compile = |f: &Poly| -> Vec<Compiled> {
            f.coeffs_in(OMEGA)
                .iter()
                .map(|c| Compiled::new(c, names))
                .collect()
        };
        BlockFactors {
            coeffs: [compile(&factors[0]), compile(&factors[1])],
        }
    }

    /// Each factor's coefficients at `x` with their derivatives in the
    /// logarithms of the parameters.
    fn eval_with_log_gradients(&self, x: &[f64]) -> [(Vec<f64>, Gradients); 2] {
        self.coeffs
            .each_ref()
            .map(|cs| tf::eval_with_log_gradients(cs, x))
    }
}

/// A point of a [`Variety`]: parameters, poles cancelled once and in
/// pairs, and multiple zeros (with multiplicities), all in linear units.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct VarietyPoint {
    pub params: Vec<f64>,
    pub cancelled: Vec<f64>,
    pub doubles: Vec<f64>,
    pub multiple: Vec<(f64, u32)>,
}

impl<'a> Variety<'a> {
    /// The variety with every cancelled pole cancelled once.
    pub(crate) fn new(
        tf: &'a UndampedCoefficients,
        params: usize,
        cancelled: usize,
        multiple: &'a [u32],
    ) -> Variety<'a> {
        Variety {
            tf,
            params,
            cancelled,
            doubles: 0,
            blocks: None,
            multiple,
        }
    }

    /// The same structure with `doubles` pairs of its cancelled poles
    /// cancelled where the blocks share an eigenvalue.
    pub(crate) fn with_doubles(self, doubles: usize, blocks: &'a BlockFactors) -> Variety<'a> {
        Variety {
            cancelled: self.cancelled - 2 * doubles,
            doubles,
            blocks: Some(blocks),
            ..self
        }
    }

    /// Conditions in all.
    fn conditions(&self) -> usize {
        2 * self.cancelled + 3 * self.doubles + self.multiple.iter().sum::<u32>() as usize
    }

    /// Unknowns in all: parameters, cancelled poles (once, in pairs),
    /// multiple zeros.
    fn unknowns(&self) -> usize {
        self.params + self.cancelled + self.doubles + self.multiple.len()
    }

    /// A log-uniform start in `[-range, range]` per parameter, its posed
    /// poles at distinct poles of the start and its multiple zeros at
    /// positive zeros (at poles where it has none); `None` where the start
    /// has too few poles.
    pub(crate) fn start(&self, rng: &mut XorShift, range: f64) -> Option<Vec<f64>> {
        let mut x: Vec<f64> = (0..self.params)
            .map(|_| range * (2.0 * rng.uniform() - 1.0))
            .collect();
        let values: Vec<f64> = x.iter().map(|v| v.exp()).collect();
        let (n, d) = self.tf.eval(&values);
        let mut poles = positive_roots(&d)?;
        if poles.len() < self.cancelled + self.doubles || poles.is_empty() {
            return None;
        }
        let zeros = positive_roots(&n)?;
        let all_poles = poles.clone();
        for _ in 0..self.cancelled + self.doubles {
            let p = poles.remove(index(rng, poles.len()));
            x.push(p.ln());
        }
        let pool = if zeros.is_empty() { &all_poles } else { &zeros };
        for _ in self.multiple {
            x.push(pool[index(rng, pool.len())].ln());
        }
        Some(x)
    }

    /// The normalised conditions at `x` and, if asked, their Jacobian in
    /// `x` (row after row of [`Self::unknowns`] entries, in one buffer);
    /// `None` where a value is not finite.
    fn residual(&self, x: &[f64], jacobian: Option<&mut Vec<f64>>) -> Option<Vec<f64>> {
        let k = self.params;
        let values: Vec<f64> = x[..k].iter().map(|v| v.exp()).collect();
        let c = self.tf.eval_with_log_gradients(&values);
        let blocks = match (self.doubles, self.blocks) {
            (0, _) => None,
            (_, Some(b)) => Some(b.eval_with_log_gradients(&values)),
            (_, None) => return None,
        };
        let mut f = Vec::with_capacity(self.conditions());
        let width = self.unknowns();
        let mut rows: Vec<f64> = Vec::with_capacity(self.conditions() * width);
        let mut condition = |coeffs: &[f64], gradient: &Gradients, order: usize, at: f64, col| {
            // The `order`-th derivative at `at`, its scale, its slope in
            // log `at` and its gradient in the log parameters.
            let mut value = 0.0;
            let mut scale = 0.0;
            let mut slope = 0.0;
            let start = rows.len();
            rows.resize(start + width, 0.0);
            let row = &mut rows[start..];
            for (i, a) in coeffs.iter().enumerate().skip(order) {
                let falling = falling(i, order);
                let power = tf::power(at, (i - order) as i32);
                value += a * falling * power;
                scale += (a * falling).abs() * power;
                slope += a * falling * (i - order) as f64 * power;
                for (j, g) in gradient.row(i).iter().enumerate() {
                    row[j] += g * falling * power;
                }
            }
            if scale.is_nan() || scale <= 0.0 || !value.is_finite() || !scale.is_finite() {
                return None;
            }
            row[col] += slope;
            for r in row.iter_mut() {
                *r /= scale;
            }
            f.push(value / scale);
            Some(())
        };
        for i in 0..self.cancelled {
            let at = x[k + i].exp();
            condition(&c.num, &c.num_gradient, 0, at, k + i)?;
            condition(&c.den, &c.den_gradient, 0, at, k + i)?;
        }
        if let Some([(f0, g0), (f1, g1)]) = &blocks {
            for i in 0..self.doubles {
                let col = k + self.cancelled + i;
                let at = x[col].exp();
                condition(f0, g0, 0, at, col)?;
                condition(f1, g1, 0, at, col)?;
                condition(&c.num, &c.num_gradient, 1, at, col)?;
            }
        }
        for (j, &mu) in self.multiple.iter().enumerate() {
            let col = k + self.cancelled + self.doubles + j;
            let at = x[col].exp();
            for order in 0..mu as usize {
                condition(&c.num, &c.num_gradient, order, at, col)?;
            }
        }
        if rows.iter().any(|v| !v.is_finite()) {
            return None;
        }
        if let Some(j) = jacobian {
            *j = rows;
        }
        Some(f)
    }

    /// As many parameters as there are conditions, in whose logarithms
    /// the conditions' Jacobian at `x` is best conditioned (see
    /// [`independent_columns`]), by index; `None` where it drops rank: a
    /// point of a thinner stratum (two posed roots about to meet), whose
    /// `f64` reading is not to be trusted either (a witness tried there
    /// is read again, exactly, on its box).
    pub(crate) fn free_parameters(&self, x: &[f64]) -> Option<Vec<usize>> {
        let mut jac = Vec::new();
        self.residual(x, Some(&mut jac))?;
        let rows: Vec<Vec<f64>> = jac
            .chunks(self.unknowns())
            .map(|row| row[..self.params].to_vec())
            .collect();
        independent_columns(&rows, self.conditions())
    }

    /// Projects `x` onto the variety; `true` when it converged within the
    /// box `[-range - 2, range + 2]` of the parameters' logarithms.
    pub(crate) fn project(&self, x: &mut [f64], range: f64) -> bool {
        let mut jac = Vec::new();
        let far = range + BOX_MARGIN + ESCAPE;
        for _ in 0..ITERATIONS {
            if x[..self.params].iter().any(|v| v.abs() > far) {
                return false;
            }
            let Some(f) = self.residual(x, Some(&mut jac)) else {
                return false;
            };
            if f.iter().all(|v| v.abs() < TOLERANCE) {
                return x[..self.params]
                    .iter()
                    .all(|v| v.abs() <= range + BOX_MARGIN);
            }
            // J J^T, regularised by a trace fraction as the script does.
            let e = f.len();
            let row = |i: usize| &jac[i * x.len()..(i + 1) * x.len()];
            let mut a: Vec<Vec<f64>> = (0..e)
                .map(|i| (0..e).map(|j| dot(row(i), row(j))).collect())
                .collect();
            let trace: f64 = (0..e).map(|i| a[i][i]).sum();
            for (i, row) in a.iter_mut().enumerate() {
                row[i] += 1e-14 * trace;
            }
            let Some(y) = solve(a, f) else {
                return false;
            };
            let mut step = vec![0.0; x.len()];
            for (row, yi) in jac.chunks(x.len()).zip(&y) {
                for (s, j) in step.iter_mut().zip(row) {
                    *s += j * yi;
                }
            }
            // A long step leaves the basin: at most 1 in log units.
            let norm = step.iter().fold(1.0f64, |m, s| m.max(s.abs()));
            if !norm.is_finite() {
                return false;
            }
            for (xi, s) in x.iter_mut().zip(&step) {
                *xi -= s / norm;
            }
        }
        false
    }

    /// The point `x` in linear units.
    pub(crate) fn point(&self, x: &[f64]) -> VarietyPoint {
        let k = self.params;
        let c = self.cancelled;
        let d = self.doubles;
        VarietyPoint {
            params: x[..k].iter().map(|v| v.exp()).collect(),
            cancelled: x[k..k + c].iter().map(|v| v.exp()).collect(),
            doubles: x[k + c..k + c + d].iter().map(|v| v.exp()).collect(),
            multiple: x[k + c + d..]
                .iter()
                .zip(self.multiple)
                .map(|(v, &mu)| (v.exp(), mu))
                .collect(),
        }
    }

    /// The type at a converged point, or `None` where it is not read (two
    /// roots within [`SEPARATION`], a pole off the positive axis, values
    /// not finite).
    pub(crate) fn read(&self, p: &VarietyPoint) -> Option<FrfType> {
        self.read_apart(p, |_| SEPARATION)
    }

    /// [`Self::read`], with the marks next to a multiple zero of
    /// multiplicity `mu` kept `apart(mu)` (relative) instead.
    pub(crate) fn read_apart(
        &self,
        p: &VarietyPoint,
        apart: impl Fn(u32) -> f64,
    ) -> Option<FrfType> {
        self.read_marks(p, apart, false)
    }

    /// [`Self::read_apart`], with the rests' roots polished on the whole
    /// numerator and denominator. Dividing out a posed multiple zero
    /// leaves the rest's roots off by about the posed zero's own error
    /// (the `mu`-th root of the residual), far more than a simple root of
    /// the undivided polynomial is off: at 10^4 starts a zero of
    /// N6-g2-a3.1-s4.1 within `2.5e-6` (relative) of a pole was read on
    /// the wrong side of it after two double zeros were divided out.
    pub(crate) fn read_polished(
        &self,
        p: &VarietyPoint,
        apart: impl Fn(u32) -> f64,
    ) -> Option<FrfType> {
        self.read_marks(p, apart, true)
    }

    fn read_marks(
        &self,
        p: &VarietyPoint,
        apart: impl Fn(u32) -> f64,
        polish: bool,
    ) -> Option<FrfType> {
        let (whole_n, whole_d) = self.tf.eval(&p.params);
        let (n, d) = divided_out(p, &whole_n, &whole_d);
        let mut zeros = positive_roots(&n)?;
        let mut poles = positive_roots(&d)?;
        if polish {
            zeros = polished(&whole_n, &zeros)?;
            poles = polished(&whole_d, &poles)?;
        }
        if poles.len() + 1 != d.len() {
            return None;
        }
        let simple = |feature| Token {
            feature,
            multiplicity: 1,
        };
        let mut marks: Vec<(f64, Option<Token>)> = Vec::new();
        marks.extend(
            zeros
                .iter()
                .map(|&z| (z, Some(simple(Feature::Antiresonance)))),
        );
        marks.extend(poles.iter().map(|&z| (z, Some(simple(Feature::Resonance)))));
        marks.extend(p.multiple.iter().map(|&(s, mu)| {
            let tok = Token {
                feature: Feature::Antiresonance,
                multiplicity: mu,
            };
            (s, Some(tok))
        }));
        marks.extend(p.cancelled.iter().chain(&p.doubles).map(|&r| (r, None)));
        if marks.iter().any(|(v, _)| !v.is_finite()) {
            return None;
        }
        marks.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mu = |m: &(f64, Option<Token>)| m.1.as_ref().map_or(1, |t| t.multiplicity);
        if marks.windows(2).any(|w| {
            let sep = apart(mu(&w[0]).max(mu(&w[1]))).max(SEPARATION);
            w[1].0 - w[0].0 <= sep * (w[0].0.abs() + w[1].0.abs())
        }) {
            return None;
        }
        Some(FrfType {
            tokens: marks.into_iter().filter_map(|m| m.1).collect(),
            nonminimum_phase: zeros.len() + 1 < n.len(),
        })
    }

    /// The numerator and the denominator at `p` with its posed roots
    /// divided out ([`divided_out`]).
    fn rests(&self, p: &VarietyPoint) -> (Vec<f64>, Vec<f64>) {
        let (n, d) = self.tf.eval(&p.params);
        divided_out(p, &n, &d)
    }

    /// How far the converged point `p` is from reading `t`: zero where the
    /// rests' roots and the posed zeros stand in `t`'s order with log-gaps
    /// of at least [`VIOLATION_GAP`]; `None` where the denominator's rest
    /// has other than `t`'s resonances, all real and positive, or the
    /// numerator's rest fits neither `t`'s simple antiresonances nor its
    /// phase. As for a generic type (`targeted::violation_near`), every
    /// shortfall adds: the simple antiresonances are the rest's zeros
    /// nearest the positive axis by angle, each adding its angle, the
    /// other zeros keep off the axis, and each pair of neighbouring tokens
    /// adds how far its log-gap falls short; the posed zeros of one
    /// multiplicity stand for `t`'s tokens of that multiplicity in
    /// ascending order. Each cancelled pole adds how far it falls short of
    /// the gap from every antiresonance and every other cancelled pole, as
    /// a point where it meets another root is not read (a resonance may
    /// stand on it: the blocks' shared eigenvalue). `near` holds the
    /// rest's zeros at a nearby point, where the iteration for them
    /// starts, and afterwards those found here.
    pub(crate) fn violation(
        &self,
        p: &VarietyPoint,
        t: &FrfType,
        near: &mut Vec<(f64, f64)>,
    ) -> Option<f64> {
        let (n, d) = self.rests(p);
        let poles = positive_roots(&d)?;
        if poles.len() + 1 != d.len() || poles.len() as u32 != t.resonances() {
            return None;
        }
        let simple = t
            .tokens
            .iter()
            .filter(|k| k.feature == Feature::Antiresonance && k.multiplicity == 1)
            .count();
        let (mut cost, moduli) = zeros_near_the_axis(&n, simple, t.nonminimum_phase, near)?;
        let mut posed = p.multiple.clone();
        posed.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (mut moduli, mut poles) = (moduli.into_iter(), poles.into_iter());
        let mut seq = Vec::with_capacity(t.tokens.len());
        for tok in &t.tokens {
            let v = match (tok.feature, tok.multiplicity) {
                (Feature::Resonance, _) => poles.next()?,
                (Feature::Antiresonance, 1) => moduli.next()?,
                (Feature::Antiresonance, mu) => {
                    let i = posed.iter().position(|s| s.1 == mu)?;
                    posed.remove(i).0
                }
            };
            seq.push(v.max(f64::MIN_POSITIVE).ln());
        }
        cost += seq
            .windows(2)
            .map(|w| (VIOLATION_GAP - (w[1] - w[0])).max(0.0))
            .sum::<f64>();
        // Each cancelled pole apart from every zero and every other
        // cancelled pole, not from the resonances: where the blocks share
        // an eigenvalue, a pole cancelled once leaves a resonance there.
        let cancelled: Vec<f64> = p
            .cancelled
            .iter()
            .chain(&p.doubles)
            .map(|r| r.max(f64::MIN_POSITIVE).ln())
            .collect();
        let antiresonances: Vec<f64> = t
            .tokens
            .iter()
            .zip(&seq)
            .filter(|(k, _)| k.feature == Feature::Antiresonance)
            .map(|(_, v)| *v)
            .collect();
        for (i, r) in cancelled.iter().enumerate() {
            cost += antiresonances
                .iter()
                .chain(&cancelled[i + 1..])
                .map(|v| (VIOLATION_GAP - (v - r).abs()).max(0.0))
                .sum::<f64>();
        }
        cost.is_finite().then_some(cost)
    }
}

/// `count` columns of `rows` chosen one at a time, each the one with the
/// largest part orthogonal to those chosen before (Gram-Schmidt with
/// column pivoting); `None` where a pivot falls below `1e-8` of the
/// first, i.e. the columns span less than `count` dimensions in `f64`.
pub(crate) fn independent_columns(rows: &[Vec<f64>], count: usize) -> Option<Vec<usize>> {
    if count == 0 {
        return Some(Vec::new());
    }
    let width = rows.first()?.len();
    let mut columns: Vec<Vec<f64>> = (0..width)
        .map(|j| rows.iter().map(|r| r[j]).collect())
        .collect();
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let mut chosen: Vec<usize> = Vec::new();
    let mut first = 0.0;
    for _ in 0..count {
        let best = (0..width)
            .filter(|j| !chosen.contains(j))
            .max_by(|&a, &b| norm(&columns[a]).total_cmp(&norm(&columns[b])))?;
        let size = norm(&columns[best]);
        if chosen.is_empty() {
            first = size;
        }
        if size.is_nan() || size <= 1e-8 * first || !size.is_finite() {
            return None;
        }
        let unit: Vec<f64> = columns[best].iter().map(|x| x / size).collect();
        for column in columns.iter_mut() {
            let along: f64 = column.iter().zip(&unit).map(|(a, b)| a * b).sum();
            for (x, u) in column.iter_mut().zip(&unit) {
                *x -= along * u;
            }
        }
        chosen.push(best);
    }
    chosen.sort_unstable();
    Some(chosen)
}

fn index(rng: &mut XorShift, n: usize) -> usize {
    (rng.next_u64() % n as u64) as usize
}

/// `i! / (i - order)!`.
fn falling(i: usize, order: usize) -> f64 {
    (i + 1 - order..=i).map(|v| v as f64).product()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `a y = b` by Gaussian elimination with partial pivoting; `None` where
/// `a` is singular in `f64`.
fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let n = b.len();
    for col in 0..n {
        let pivot = (col..n).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        let size = a[pivot][col].abs();
        if size.is_nan() || size == 0.0 {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        let (top, rest) = a.split_at_mut(col + 1);
        let pivot_row = &top[col];
        for (offset, row) in rest.iter_mut().enumerate() {
            let m = row[col] / pivot_row[col];
            for (v, p) in row[col..n].iter_mut().zip(&pivot_row[col..n]) {
                *v -= m * p;
            }
            b[col + 1 + offset] -= m * b[col];
        }
    }
    let mut y = vec![0.0; n];
    for row in (0..n).rev() {
        let s: f64 = (row + 1..n).map(|k| a[row][k] * y[k]).sum();
        y[row] = (b[row] - s) / a[row][row];
    }
    y.iter().all(|v| v.is_finite()).then_some(y)
}

/// The numerator `n` and the denominator `d` at `p` with its posed roots
/// divided out: each cancelled pole from both (twice where cancelled in a
/// pair), each multiple zero from the numerator as often as its
/// multiplicity.
fn divided_out(p: &VarietyPoint, n: &[f64], d: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let (mut n, mut d) = (n.to_vec(), d.to_vec());
    for &r in p.cancelled.iter().chain(&p.doubles).chain(&p.doubles) {
        n = deflate(&n, r);
        d = deflate(&d, r);
    }
    for &(s, mu) in &p.multiple {
        for _ in 0..mu {
            n = deflate(&n, s);
        }
    }
    (n, d)
}

/// The simple roots `roots` of a rest refined by Newton's iteration on
/// the whole polynomial `c` (ascending coefficients); `None` where one
/// does not settle to a relative `1e-9` (far below [`SEPARATION`]), or
/// settles farther than a relative `1e-3` from where it started (a root
/// that far off was not the rest's root to begin with).
fn polished(c: &[f64], roots: &[f64]) -> Option<Vec<f64>> {
    roots
        .iter()
        .map(|&r0| {
            let mut r = r0;
            let mut settled = false;
            for _ in 0..20 {
                let (mut v, mut dv) = (0.0, 0.0);
                for &a in c.iter().rev() {
                    dv = dv * r + v;
                    v = v * r + a;
                }
                if dv == 0.0 || !dv.is_finite() {
                    return None;
                }
                let step = v / dv;
                r -= step;
                if step.abs() <= 1e-9 * r.abs() {
                    settled = true;
                    break;
                }
            }
            (settled && r.is_finite() && (r - r0).abs() <= 1e-3 * r0.abs()).then_some(r)
        })
        .collect()
}

/// The quotient of `c` (ascending) by `x - r`, the remainder dropped.
/// Composite deflation: the quotient's high part by the forward
/// recurrence, its low part by the backward one, split at the dominant
/// term `|c_i r^i|`, so that a large root does not swamp the small ones.
pub(crate) fn deflate(c: &[f64], r: f64) -> Vec<f64> {
    let d = c.len().saturating_sub(1);
    if d == 0 {
        return Vec::new();
    }
    let mut forward = vec![0.0; d];
    forward[d - 1] = c[d];
    for i in (1..d).rev() {
        forward[i - 1] = c[i] + r * forward[i];
    }
    let mut backward = vec![0.0; d];
    backward[0] = -c[0] / r;
    for i in 1..d {
        backward[i] = (backward[i - 1] - c[i]) / r;
    }
    let split = (0..=d)
        .max_by(|&i, &j| {
            let size = |k: usize| c[k].abs() * r.abs().powi(k as i32);
            size(i).total_cmp(&size(j))
        })
        .unwrap_or(0);
    (0..d)
        .map(|i| if i >= split { forward[i] } else { backward[i] })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deflation_keeps_small_roots_beside_a_large_one() {
        // (x - 1e-4)(x - 2)(x - 1e6), divided by x - 1e6.
        let roots = [1e-4, 2.0, 1e6];
        let mut c = vec![1.0];
        for r in roots {
            let mut next = vec![0.0; c.len() + 1];
            for (i, a) in c.iter().enumerate() {
                next[i] -= r * a;
                next[i + 1] += a;
            }
            c = next;
        }
        let q = deflate(&c, 1e6);
        let found = positive_roots(&q).unwrap();
        assert_eq!(found.len(), 2);
        assert!((found[0] / 1e-4 - 1.0).abs() < 1e-9, "{found:?}");
        assert!((found[1] / 2.0 - 1.0).abs() < 1e-9, "{found:?}");
    }

    /// The descent's score against the reading, by their own routes (the
    /// reading sorts the marks, the score assigns the tokens in the type's
    /// order): on points of two structures, one with two cancelled poles
    /// and one with a cancelled pole and a double zero, a point scores
    /// zero only for the type it reads, and most points read score zero
    /// for their type (the rest have two marks closer than the gap).
    #[test]
    fn a_point_scores_zero_only_for_the_type_it_reads() {
        for (id, cancelled, multiple) in [
            ("N5-g3-a4.2-s5.2", 2, vec![]),
            ("N5-g1-a2.1-s5.1", 1, vec![2]),
        ] {
            let m = crate::Model::from_id(id).unwrap();
            let tf = UndampedCoefficients::new(&m);
            let names = m.undamped_parameters();
            let variety = Variety::new(&tf, names.len(), cancelled, &multiple);
            let mut rng = XorShift::new(17);
            let mut points = Vec::new();
            for _ in 0..3000 {
                let Some(mut x) = variety.start(&mut rng, 3.0) else {
                    continue;
                };
                if variety.project(&mut x, 3.0) {
                    let p = variety.point(&x);
                    if let Some(t) = variety.read(&p) {
                        points.push((p, t));
                    }
                }
            }
            let types: std::collections::BTreeSet<FrfType> =
                points.iter().map(|(_, t)| t.clone()).collect();
            assert!(
                points.len() > 50 && types.len() > 1,
                "{id}: {} points, {} types",
                points.len(),
                types.len()
            );
            let mut zero = 0;
            for (p, read) in &points {
                for t in &types {
                    let score = variety.violation(p, t, &mut Vec::new());
                    if t == read {
                        assert!(score.is_some_and(|s| s >= 0.0), "{id} {t}");
                        zero += usize::from(score == Some(0.0));
                    } else {
                        assert!(score != Some(0.0), "{id}: reads {read}, scores 0 for {t}");
                    }
                }
            }
            assert!(2 * zero > points.len(), "{id}: {zero} of {}", points.len());
        }
    }

    #[test]
    fn columns_are_chosen_by_their_independent_parts() {
        // The second column repeats the first; the third is independent.
        let rows = vec![vec![1.0, 2.0, 0.0], vec![1.0, 2.0, 1.0]];
        assert_eq!(independent_columns(&rows, 2), Some(vec![1, 2]));
        assert_eq!(independent_columns(&rows, 3), None);
        assert_eq!(independent_columns(&rows, 0), Some(vec![]));
    }

    #[test]
    fn a_small_system_is_solved() {
        let a = vec![vec![0.0, 2.0], vec![4.0, 1.0]];
        let y = solve(a, vec![2.0, 9.0]).unwrap();
        assert!((y[0] - 2.0).abs() < 1e-15 && (y[1] - 1.0).abs() < 1e-15);
        assert!(solve(vec![vec![1.0, 2.0], vec![2.0, 4.0]], vec![1.0, 1.0]).is_none());
    }
}
