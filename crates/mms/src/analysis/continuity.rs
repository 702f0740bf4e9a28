//! Double zeros shown by continuity.
//!
//! A double antiresonance `A^2` lives where two zeros meet, a variety of
//! codimension one on which rational points are rare when the root
//! conditions are not linear in any two parameters. It need not be hit:
//! on a path from a point showing the split type (`AA` in that gap) to one
//! where the pair has left the real axis (the same type without it), the
//! pair must meet somewhere, and if nothing else happens on the way the
//! type there is the wanted one. The path is a segment in the stratum's
//! free parameters (the cancellation walls through the split witness
//! keep their cancelled poles), each eliminated parameter a rational
//! function of the path's variable `s`; "nothing else happens" is a list
//! of univariate polynomials in `s` without a root in `[0, 1]`, decided
//! exactly by root isolation ([`path_event`], re-derived by the checker on
//! its own).
//!
//! The same holds beside a double zero that stays one along the path: in
//! a chart where two parameters are solved for a double zero at a chosen
//! `Omega` (a coordinate of the chart), a second pair meeting gives two
//! double zeros, and a simple zero crossing the double one a triple zero.

use super::frf_type::{frf_type_at, Feature, FrfType, Token};
use super::prover::{positive_full_point, substitute, Prover, Substitution};
use super::targeted::{
    linear_sets, linear_solution, nelder_mead_for, short_rational, violation_near,
    StratumCoefficients, PARTIAL_WALL_TERMS,
};
use super::walls::{solve_in_turn, wall_parameters};
use super::MergePath;
use crate::tf::OMEGA;
use poly::{Poly, Rat, UPoly};
use std::collections::{BTreeMap, BTreeSet};

/// The path's variable.
pub const PATH_VARIABLE: &str = "s";

/// The coordinate of a cancelled-root chart that stands for the
/// cancelled pole (the model's parameters never take this name).
const CHART_ROOT: &str = "cancelled_root";

/// The coordinate of a double-zero chart that stands for the double zero.
const CHART_ZERO: &str = "double_zero";

/// Charts of block mechanisms tried per split witness, at most.
const MERGE_CHARTS: usize = 8;

/// Double-zero charts tried per split witness, at most.
const DOUBLE_ZERO_CHARTS: usize = 4;

/// Halvings of the segment towards one event.
const MERGE_HALVINGS: usize = 12;

/// Exact samples of a segment, to find where the pair leaves the axis.
const SEGMENT_SAMPLES: usize = 32;

/// The factors by which one coordinate of a double-zero chart is moved
/// in search of a far end, nearest first.
const CHART_MOVES: [(i64, i64); 8] = [
    (2, 1),
    (1, 2),
    (4, 1),
    (1, 4),
    (16, 1),
    (1, 16),
    (256, 1),
    (1, 256),
];

/// Witnesses of other types with one double zero tried as far ends of a
/// double-zero chart's path, at most.
const CHART_TARGETS: usize = 4;

/// Witnesses of other non-minimum-phase types tried as far ends, at most.
const MERGE_TARGETS: usize = 24;

/// Evaluations of the descent from the split witness to the pair's
/// departure from the real axis.
const DEPARTURE_EVALUATIONS: usize = 3000;

/// `t`'s two ends, if `t` has exactly one multiple token, an `A^2` with
/// no other zero in its gap: the split type (`A A` in its place) and the
/// type without the pair (non-minimum phase, the pair off the axis).
pub(super) fn merge_ends(t: &FrfType) -> Option<(FrfType, FrfType)> {
    let multiple: Vec<usize> = (0..t.tokens.len())
        .filter(|&i| t.tokens[i].multiplicity > 1)
        .collect();
    let [i] = multiple.as_slice() else {
        return None;
    };
    let i = *i;
    let zero = |k: Option<&Token>| k.is_some_and(|k| k.feature == Feature::Antiresonance);
    if t.tokens[i].feature != Feature::Antiresonance
        || t.tokens[i].multiplicity != 2
        || zero(t.tokens.get(i + 1))
        || (i > 0 && zero(t.tokens.get(i - 1)))
    {
        return None;
    }
    let simple = Token {
        feature: Feature::Antiresonance,
        multiplicity: 1,
    };
    let mut split = t.clone();
    split.tokens.splice(i..=i, [simple, simple]);
    let mut gone = t.clone();
    gone.tokens.remove(i);
    gone.nonminimum_phase = true;
    Some((split, gone))
}

/// `f` along the path: each variable replaced by its rational function of
/// `s`, `(numerator, denominator)`.
fn along(f: &Poly, path: &BTreeMap<String, [Poly; 2]>) -> (Poly, Poly) {
    let (mut num, mut den) = (f.clone(), Poly::one());
    for (v, [p, q]) in path {
        let d = num.degree(v);
        if d == 0 {
            continue;
        }
        let mut acc = Poly::zero();
        for (k, c) in num.coeffs_in(v).iter().enumerate() {
            if !c.is_zero() {
                acc = &acc + &(&(c * &p.pow(k as u32)) * &q.pow(d - k as u32));
            }
        }
        num = acc;
        den = &den * &q.pow(d);
    }
    (num, den)
}

/// True when `p`, a polynomial in `s`, has no root in `[0, 1]`.
fn no_root_on_path(p: &Poly) -> bool {
    let Some((c, u)) = UPoly::from_poly(p, PATH_VARIABLE) else {
        return false;
    };
    !c.is_zero()
        && u.sign_at(&Rat::ZERO) != 0
        && u.sign_at(&Rat::ONE) != 0
        && roots_in_path(&u) == 0
}

/// The number of distinct roots in `(0, 1)` of `u`, which has none at
/// `0` or `1`: by Descartes' rule with bisection ([`poly::real_roots`]),
/// each isolating interval refined until it lies on one side of `0` and
/// of `1`. (The checker counts by Sturm sequences, another route; these
/// are much faster on the long polynomials of a path.)
fn roots_in_path(u: &UPoly) -> usize {
    let (zero, one) = (Rat::ZERO, Rat::ONE);
    let mut count = 0;
    for mut r in poly::real_roots(u) {
        loop {
            if r.hi <= zero || r.lo >= one {
                break;
            }
            if r.lo >= zero && r.hi <= one {
                count += 1;
                break;
            }
            let half = &r.width() / &Rat::from(2);
            if r.refine(u, &half).is_err() {
                // Not reached for a polynomial without roots at 0 and 1;
                // counted as a root so that the path is refused.
                count += 1;
                break;
            }
        }
    }
    count
}

/// `p` divided by the largest power of `Omega` dividing it.
fn without_zero_roots(p: &Poly) -> Poly {
    let cs = p.coeffs_in(OMEGA);
    let low = cs.iter().position(|c| !c.is_zero()).unwrap_or(0);
    let om = Poly::var(OMEGA);
    cs[low..]
        .iter()
        .enumerate()
        .fold(Poly::zero(), |acc, (k, c)| &acc + &(c * &om.pow(k as u32)))
}

/// What happens at the one event of a path ([`path_event`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum PathEvent {
    /// Two simple zeros meet as a double zero (and leave the axis after).
    PairMeets,
    /// A simple zero crosses a double zero that persists along the path:
    /// a triple zero at the crossing.
    CrossesDoubleZero,
}

/// The one event along `path` (every parameter positive on `[0, 1]`),
/// if exactly one happens. The reduced transfer function's numerator is
/// `h^2 m` with `h` the double zero kept along the path (a chart's; `1`
/// when there is none), and `m` square-free: its poles stay simple, apart
/// from each other and from the zeros, none of them reaches `0` or
/// infinity, `h`'s zero stays apart from the poles, and in `(0, 1)`
/// either two zeros of `m` meet once (and no more than two: the first
/// principal subresultant coefficient of `m` and `m'` is not zero there)
/// or a zero of `m` meets `h`'s once. The type at that `s` is then the
/// type at `s = 0` with the two meeting zeros merged.
///
/// `kept` says whether a double zero is kept along the path; without one,
/// the costly gcd of `n` and `n'` is skipped (a multiple factor then makes
/// the discriminant vanish and the path is refused).
pub(super) fn path_event(
    num: &Poly,
    den: &Poly,
    path: &MergePath,
    kept: bool,
) -> Option<PathEvent> {
    let path = &path.parameters;
    let (n, _) = along(num, path);
    let (d, _) = along(den, path);
    // The transfer function vanishes nowhere on the path (the gcd's content
    // in s could otherwise hide a point where it does).
    if !no_root_on_path(&d.lead_in(OMEGA)) {
        return None;
    }
    let g = poly::gcd(&n, &d);
    let (n, d) = (n.div_exact(&g)?, d.div_exact(&g)?);
    let (n, d) = (without_zero_roots(&n), without_zero_roots(&d));
    let h = if kept {
        poly::gcd(&n, &n.derivative(OMEGA))
    } else {
        Poly::one()
    };
    let (h, m) = match h.degree(OMEGA) {
        0 if !kept => (None, n),
        1 if kept => {
            let cs = h.coeffs_in(OMEGA);
            let h = h.div_exact(&poly::gcd(&cs[0], &cs[1]))?;
            let m = n.div_exact(&(&h * &h))?;
            (Some(h), m)
        }
        _ => return None,
    };
    // Roots in (0, 1) of a polynomial in s, none at the ends.
    let inner_roots = |p: &Poly| -> Option<(usize, UPoly)> {
        let (c, u) = UPoly::from_poly(p, PATH_VARIABLE)?;
        if c.is_zero() || u.sign_at(&Rat::ZERO) == 0 || u.sign_at(&Rat::ONE) == 0 {
            return None;
        }
        Some((roots_in_path(&u), u))
    };
    // The condition that fails most often on a long segment first: other
    // zeros meeting too.
    let (pairs, disc) = if m.degree(OMEGA) >= 2 {
        let (k, u) = inner_roots(&poly::discriminant(&m, OMEGA))?;
        (k, Some(u))
    } else {
        (0, None)
    };
    let crossings = match &h {
        Some(h) => inner_roots(&poly::resultant(h, &m, OMEGA))?.0,
        None => 0,
    };
    let event = match (pairs, crossings) {
        (1, 0) => PathEvent::PairMeets,
        (0, 1) => PathEvent::CrossesDoubleZero,
        _ => return None,
    };
    if !no_root_on_path(&poly::resultant(&m, &d, OMEGA)) {
        return None;
    }
    let ends = |p: &Poly| {
        let cs = p.coeffs_in(OMEGA);
        [cs[0].clone(), cs[cs.len() - 1].clone()]
    };
    let mut polys = vec![&m, &d];
    polys.extend(&h);
    if !polys
        .iter()
        .flat_map(|p| ends(p))
        .all(|c| no_root_on_path(&c))
        || (d.degree(OMEGA) >= 2 && !no_root_on_path(&poly::discriminant(&d, OMEGA)))
        || h.as_ref()
            .is_some_and(|h| !no_root_on_path(&poly::resultant(h, &d, OMEGA)))
    {
        return None;
    }
    // Every parameter positive on the path.
    let sign_at_0 = |p: &Poly| {
        p.subs(PATH_VARIABLE, &Rat::ZERO)
            .as_constant()
            .map(|v| v.signum())
    };
    if path
        .values()
        .any(|[p, q]| !(no_root_on_path(p) && no_root_on_path(q)) || sign_at_0(p) != sign_at_0(q))
    {
        return None;
    }
    // The meeting is of two zeros only: the first principal subresultant
    // coefficient of m and m' is not zero there (their gcd has degree 1).
    if let (PathEvent::PairMeets, Some(disc)) = (event, &disc) {
        if m.degree(OMEGA) >= 3 {
            let psc = poly::psc(&m, &m.derivative(OMEGA), OMEGA);
            let (_, p1) = psc
                .get(1)
                .and_then(|p| UPoly::from_poly(p, PATH_VARIABLE))?;
            let common = disc.gcd(&p1);
            if p1.is_zero() || (!common.is_constant() && roots_in_path(&common) != 0) {
                return None;
            }
        }
    }
    Some(event)
}

/// The types at the two ends of `path` and its event, when
/// [`path_event`] finds one.
pub(super) fn path_ends(
    num: &Poly,
    den: &Poly,
    path: &MergePath,
) -> Option<(FrfType, FrfType, PathEvent)> {
    let at = |s: &Rat| -> Option<FrfType> {
        let point: BTreeMap<String, Rat> = path
            .parameters
            .iter()
            .map(|(k, [p, q])| {
                let v = |f: &Poly| f.subs(PATH_VARIABLE, s).as_constant();
                Some((k.clone(), &v(p)? / &v(q)?))
            })
            .collect::<Option<_>>()?;
        frf_type_at(num, den, OMEGA, &point)
    };
    let (before, after) = (at(&Rat::ZERO)?, at(&Rat::ONE)?);
    let kept = before.tokens.iter().any(|k| k.multiplicity > 1);
    let event = path_event(num, den, path, kept)?;
    Some((before, after, event))
}

/// The type at an event between neighbouring types `before` and `after`
/// of a path: two neighbouring zeros of `before` merged, the simple pair
/// that has left the axis in `after` ([`PathEvent::PairMeets`]) or the
/// simple zero and the double zero that have changed places
/// ([`PathEvent::CrossesDoubleZero`]); `None` unless every such pair gives
/// the same type.
pub(super) fn merged_at_event(
    before: &FrfType,
    after: &FrfType,
    event: PathEvent,
) -> Option<FrfType> {
    let tokens = &before.tokens;
    let mut merged: Option<FrfType> = None;
    for i in 0..tokens.len().saturating_sub(1) {
        let (x, y) = (&tokens[i], &tokens[i + 1]);
        let mut moved = before.clone();
        let multiplicity = match event {
            PathEvent::PairMeets if x.is_zero_of(1) && y.is_zero_of(1) => {
                moved.tokens.drain(i..=i + 1);
                moved.nonminimum_phase = true;
                2
            }
            PathEvent::CrossesDoubleZero
                if (x.is_zero_of(1) && y.is_zero_of(2)) || (x.is_zero_of(2) && y.is_zero_of(1)) =>
            {
                moved.tokens.swap(i, i + 1);
                3
            }
            _ => continue,
        };
        if &moved != after {
            continue;
        }
        let mut t = before.clone();
        t.tokens.splice(
            i..=i + 1,
            [Token {
                feature: Feature::Antiresonance,
                multiplicity,
            }],
        );
        match &merged {
            Some(m) if m != &t => return None,
            _ => merged = Some(t),
        }
    }
    merged
}

/// The ends of a path showing `t` by continuity beside a double zero that
/// persists along it (a chart of [`Prover::double_zero_charts`]): for a
/// triple zero alone among the multiple tokens, its two splits into a
/// double and a simple zero (either order); for an `A^2` beside one other
/// `A^2`, the split type and the type without the pair. Only ends whose
/// event gives back `t` ([`merged_at_event`]).
pub(super) fn chart_merge_ends(t: &FrfType) -> Vec<(FrfType, FrfType, PathEvent)> {
    let multiple: Vec<usize> = (0..t.tokens.len())
        .filter(|&i| t.tokens[i].multiplicity > 1)
        .collect();
    let simple = Token {
        feature: Feature::Antiresonance,
        multiplicity: 1,
    };
    let double = Token {
        feature: Feature::Antiresonance,
        multiplicity: 2,
    };
    let mut out = Vec::new();
    match multiple.as_slice() {
        [i] if t.tokens[*i].is_zero_of(3) => {
            let with = |a: Token, b: Token| {
                let mut u = t.clone();
                u.tokens.splice(*i..=*i, [a, b]);
                u
            };
            let (x, y) = (with(double, simple), with(simple, double));
            out.push((x.clone(), y.clone(), PathEvent::CrossesDoubleZero));
            out.push((y, x, PathEvent::CrossesDoubleZero));
        }
        [i, j] if t.tokens[*i].is_zero_of(2) && t.tokens[*j].is_zero_of(2) => {
            for k in [*i, *j] {
                let mut split = t.clone();
                split.tokens.splice(k..=k, [simple, simple]);
                let mut gone = t.clone();
                gone.tokens.remove(k);
                gone.nonminimum_phase = true;
                out.push((split, gone, PathEvent::PairMeets));
            }
        }
        _ => {}
    }
    out.retain(|(a, b, e)| merged_at_event(a, b, *e).as_ref() == Some(t));
    out
}

/// The segment from `a` to `b` in the free parameters of the stratum of
/// `subs`, the eliminated ones following as rational functions.
fn segment(
    subs: &[Substitution],
    a: &BTreeMap<String, Rat>,
    b: &BTreeMap<String, Rat>,
) -> MergePath {
    let s = Poly::var(PATH_VARIABLE);
    let mut parameters: BTreeMap<String, [Poly; 2]> = a
        .iter()
        .map(|(v, x)| {
            let dx = &b[v] - x;
            (
                v.clone(),
                [&Poly::constant(x.clone()) + &s.scale(&dx), Poly::one()],
            )
        })
        .collect();
    for w in subs.iter().rev() {
        let (an, ad) = along(&w.alpha, &parameters);
        let (bn, bd) = along(&w.beta, &parameters);
        let (p, q) = (&bn * &ad, &bd * &an);
        let g = poly::gcd(&p, &q);
        let (p, q) = match (p.div_exact(&g), q.div_exact(&g)) {
            (Some(p), Some(q)) => (p, q),
            _ => (p, q),
        };
        parameters.insert(w.var.clone(), [p, q]);
    }
    parameters.remove(CHART_ROOT);
    parameters.remove(CHART_ZERO);
    MergePath { parameters }
}

/// A wanted type with its two ends ([`merge_ends`], [`chart_merge_ends`])
/// and the event between them.
struct Merge {
    wanted: FrfType,
    split: FrfType,
    gone: FrfType,
    event: PathEvent,
    /// A double zero kept along the path (in a double-zero chart).
    kept: bool,
}

impl Prover<'_> {
    /// Double zeros by continuity (see the module docs) for the types of
    /// `wanted` with one `A^2` alone in its gap whose split type has a
    /// witness. From each such witness, segments run to a point reached by
    /// a descent towards the far type, to its witness and to the witnesses
    /// of the other non-minimum-phase types on the same walls; wherever two
    /// neighbouring samples of a segment show the two ends of a wanted
    /// type, the segment is halved until [`path_event`] finds its event, and the
    /// path is recorded. Returns how many of `wanted` have a witness or a
    /// path afterwards.
    pub(crate) fn merge_search(&mut self, wanted: &[FrfType]) -> usize {
        let merges: Vec<Merge> = wanted
            .iter()
            .filter(|t| !self.shown(t))
            .filter_map(|t| {
                let (split, gone) = merge_ends(t)?;
                Some(Merge {
                    wanted: t.clone(),
                    split,
                    gone,
                    event: PathEvent::PairMeets,
                    kept: false,
                })
            })
            .collect();
        for m in &merges {
            if self.shown(&m.wanted) {
                continue;
            }
            let Some(start) = self.witnesses.get(&m.split).cloned() else {
                continue;
            };
            let subs = self.walls_through(&start);
            let s = self.stratum(&subs);
            let on_walls = |w: &BTreeMap<String, Rat>| -> Option<BTreeMap<String, Rat>> {
                let b: BTreeMap<String, Rat> =
                    s.vars.iter().map(|v| (v.clone(), w[v].clone())).collect();
                (positive_full_point(&subs, &b).as_ref() == Some(w)).then_some(b)
            };
            let a = on_walls(&start).expect("a point on the walls through it");
            let mut ends: Vec<BTreeMap<String, Rat>> = Vec::new();
            ends.extend(
                StratumCoefficients::new(&s, &self.params)
                    .and_then(|c| self.departure(&subs, &c, &s.vars, &a, &m.gone)),
            );
            ends.extend(self.witnesses.get(&m.gone).and_then(&on_walls));
            ends.extend(
                self.witnesses
                    .iter()
                    .filter(|(t, _)| t.nonminimum_phase && *t != &m.gone)
                    .filter_map(|(_, w)| on_walls(w))
                    .take(MERGE_TARGETS),
            );
            for b in ends {
                if self.shown(&m.wanted) {
                    break;
                }
                self.scan_segment(&subs, &a, &b, &merges);
            }
            // A cancellation the walls do not hold (a factor linear in no
            // parameter): the chart of a block mechanism, the cancelled
            // root one of its coordinates.
            let kept = s.den.degree(OMEGA) as usize - zero_roots(&s.den);
            if self.shown(&m.wanted) || kept == m.split.resonances() as usize || !subs.is_empty() {
                continue;
            }
            for (chart, a) in self.cancelled_root_charts(&start) {
                if self.shown(&m.wanted) {
                    break;
                }
                if let Some(b) = self.chart_departure(&chart, &a, &m.gone) {
                    self.scan_segment(&chart, &a, &b, &merges);
                }
            }
        }
        wanted.iter().filter(|t| self.shown(t)).count()
    }

    /// Double and triple zeros by continuity beside a double zero that
    /// stays one (see the module docs) for the types of `wanted` with an
    /// `A^3` or two `A^2` ([`chart_merge_ends`]) and every pole: from the
    /// split type's witness, in each of its double-zero charts
    /// ([`Self::double_zero_charts`]), segments run to the far type's
    /// witness and to the witnesses of other types with one double zero
    /// in the same chart, and are sampled and halved as in
    /// [`Self::merge_search`]. Returns how many of `wanted` have a witness
    /// or a path afterwards.
    pub(crate) fn double_zero_chart_search(&mut self, wanted: &[FrfType]) -> usize {
        let degree = self.kept_poles();
        let merges: Vec<Merge> = wanted
            .iter()
            .filter(|t| !self.shown(t) && t.resonances() == degree)
            .flat_map(|t| {
                chart_merge_ends(t)
                    .into_iter()
                    .map(|(split, gone, event)| Merge {
                        wanted: t.clone(),
                        split,
                        gone,
                        event,
                        kept: true,
                    })
            })
            .collect();
        for m in &merges {
            if self.shown(&m.wanted) {
                continue;
            }
            let Some(start) = self.witnesses.get(&m.split).cloned() else {
                continue;
            };
            for (chart, a) in self.double_zero_charts(&start) {
                if self.shown(&m.wanted) {
                    break;
                }
                let a = self.shortened(&chart, a, &m.split);
                let on_chart = |w: &BTreeMap<String, Rat>| -> Option<BTreeMap<String, Rat>> {
                    let z = self.double_zero(w)?;
                    let mut b: BTreeMap<String, Rat> = w
                        .iter()
                        .filter(|(k, _)| !chart.iter().any(|c| &c.var == *k))
                        .map(|(k, v)| (k.clone(), v.clone()))
                        .collect();
                    b.insert(CHART_ZERO.to_string(), z);
                    (full_point(&chart, &b).as_ref() == Some(w)).then_some(b)
                };
                // First the far type one coordinate away, then legs
                // towards witnesses one coordinate at a time: a segment's
                // polynomials in s stay of low degree when few coordinates
                // move on it.
                let mut segments: Vec<(BTreeMap<String, Rat>, BTreeMap<String, Rat>)> = a
                    .keys()
                    .filter_map(|c| {
                        CHART_MOVES.iter().find_map(|&factor| {
                            let b = moved(&a, c, factor);
                            let t = full_point(&chart, &b).and_then(|f| self.type_at(&f));
                            (t.as_ref() == Some(&m.gone)).then(|| (a.clone(), b))
                        })
                    })
                    .collect();
                let mut far: Vec<(FrfType, BTreeMap<String, Rat>)> = Vec::new();
                far.extend(
                    self.witnesses
                        .get(&m.gone)
                        .and_then(&on_chart)
                        .map(|b| (m.gone.clone(), b)),
                );
                far.extend(
                    self.witnesses
                        .iter()
                        .filter(|(t, _)| {
                            *t != &m.gone
                                && *t != &m.split
                                && t.resonances() == degree
                                && double_zero_gap(t).is_some()
                        })
                        .filter_map(|(t, w)| Some((t.clone(), on_chart(w)?)))
                        .take(CHART_TARGETS),
                );
                for (t, b) in far {
                    let b = self.shortened(&chart, b, &t);
                    let mut at = a.clone();
                    for (c, v) in &b {
                        if &at[c] != v {
                            let from = at.clone();
                            at.insert(c.clone(), v.clone());
                            segments.push((from, at.clone()));
                        }
                    }
                }
                for (from, to) in segments {
                    if self.shown(&m.wanted) {
                        break;
                    }
                    self.scan_segment(&chart, &from, &to, &merges);
                }
            }
        }
        wanted.iter().filter(|t| self.shown(t)).count()
    }

    /// Points with a double zero beside other zeros (`A^2A`, `AA^2`, ...):
    /// at every point of a double-zero chart the double zero is exact, so
    /// the types with one `A^2` of `wanted` (every pole) are looked for at
    /// the points one move of one coordinate away ([`CHART_MOVES`]) from
    /// the witnesses of types with one `A^2` in the same gap, in their
    /// charts. Returns how many of `wanted` have a witness or a path
    /// afterwards.
    pub(crate) fn double_zero_chart_points(&mut self, wanted: &[FrfType]) -> usize {
        let degree = self.kept_poles();
        let gap_of_double = |t: &FrfType| double_zero_gap(t).filter(|_| t.resonances() == degree);
        let gaps: BTreeSet<usize> = wanted
            .iter()
            .filter(|t| !self.shown(t))
            .filter_map(gap_of_double)
            .collect();
        if gaps.is_empty() {
            return wanted.iter().filter(|t| self.shown(t)).count();
        }
        let starts: Vec<BTreeMap<String, Rat>> = self
            .witnesses
            .iter()
            .filter(|(t, _)| gap_of_double(t).is_some_and(|g| gaps.contains(&g)))
            .map(|(_, w)| w.clone())
            .take(CHART_TARGETS)
            .collect();
        for start in starts {
            for (chart, a) in self.double_zero_charts(&start) {
                for c in a.keys() {
                    for &factor in &CHART_MOVES {
                        if let Some(f) = full_point(&chart, &moved(&a, c, factor)) {
                            self.record(f);
                        }
                    }
                }
            }
        }
        wanted.iter().filter(|t| self.shown(t)).count()
    }

    /// A point of the chart of `subs` near `p` with short coordinates and
    /// the same type `t` (else `p`): the path's polynomials in `s` grow
    /// with the digits of its ends.
    fn shortened(
        &self,
        subs: &[Substitution],
        p: BTreeMap<String, Rat>,
        t: &FrfType,
    ) -> BTreeMap<String, Rat> {
        for digits in [2, 3, 4, 6] {
            let q: Option<BTreeMap<String, Rat>> = p
                .iter()
                .map(|(k, v)| Some((k.clone(), short_rational(v.to_f64(), digits)?)))
                .collect();
            let Some(q) = q else { continue };
            if full_point(subs, &q).and_then(|f| self.type_at(&f)).as_ref() == Some(t) {
                return q;
            }
        }
        p
    }

    /// The number of poles of the reduced transfer function (its positive
    /// roots: the orthant's denominator without its roots at `Omega = 0`).
    fn kept_poles(&mut self) -> u32 {
        let top = self.stratum(&[]);
        top.den.degree(OMEGA) - zero_roots(&top.den) as u32
    }

    /// The one positive double zero of the numerator at `point`, if it has
    /// exactly one multiple root (then rational: the root of
    /// `gcd(num, num')`, of degree one).
    fn double_zero(&self, point: &BTreeMap<String, Rat>) -> Option<Rat> {
        let n = self.num.subs_point(point);
        let g = poly::gcd(&n, &n.derivative(OMEGA));
        if g.degree(OMEGA) != 1 {
            return None;
        }
        let cs = g.coeffs_in(OMEGA);
        let z = -(&cs[0].as_constant()? / &cs[1].as_constant()?);
        (z.signum() > 0).then_some(z)
    }

    /// The charts in which `point`'s one double zero stays double: for
    /// each pair of parameters in which the numerator is jointly linear,
    /// `num(z) = 0` and `num'(z) = 0` solved for them in turn
    /// ([`solve_in_turn`]) as substitutions in the other parameters and
    /// [`CHART_ZERO`] (standing for `z`), with `point`'s coordinates in the
    /// chart.
    fn double_zero_charts(
        &mut self,
        point: &BTreeMap<String, Rat>,
    ) -> Vec<(Vec<Substitution>, BTreeMap<String, Rat>)> {
        let Some(z) = self.double_zero(point) else {
            return Vec::new();
        };
        let (value, slope) = (
            with_omega_as(&self.num, CHART_ZERO),
            with_omega_as(&self.num.derivative(OMEGA), CHART_ZERO),
        );
        let mut out = Vec::new();
        for vars in linear_sets(&[&self.num], &self.params, 2) {
            let [x, y] = vars.as_slice() else { continue };
            let conditions = [(x.clone(), value.clone()), (y.clone(), slope.clone())];
            out.extend(chart_through(point, &conditions, CHART_ZERO, &z));
            if out.len() >= DOUBLE_ZERO_CHARTS {
                break;
            }
        }
        out
    }

    /// The charts in which `point`'s one cancelled pole stays cancelled:
    /// for each block mechanism whose two determinants vanish there at the
    /// cancelled root `r`, and each pair of parameters they are solved for
    /// ([`solve_in_turn`]), the two solutions as substitutions in the other
    /// parameters and [`CHART_ROOT`] (standing for `r`), with `point`'s
    /// coordinates in the chart.
    fn cancelled_root_charts(
        &mut self,
        point: &BTreeMap<String, Rat>,
    ) -> Vec<(Vec<Substitution>, BTreeMap<String, Rat>)> {
        let common = poly::gcd(&self.num.subs_point(point), &self.den.subs_point(point));
        let roots: Vec<Rat> = UPoly::from_poly(&common, OMEGA)
            .map(|(_, u)| poly::rational_roots(&u))
            .unwrap_or_default()
            .into_iter()
            .filter(|r| r.signum() > 0)
            .collect();
        let [r] = roots.as_slice() else {
            return Vec::new();
        };
        let mut at_r = point.clone();
        at_r.insert(OMEGA.to_string(), r.clone());
        let mut out = Vec::new();
        for (d1, _, d2, _) in self.cancellation_mechanisms() {
            if !(d1.subs_point(&at_r).is_zero() && d2.subs_point(&at_r).is_zero()) {
                continue;
            }
            let (in1, in2) = wall_parameters(&d1, &d2, &[]);
            for x in &in1 {
                for y in &in2 {
                    let conditions = [
                        (x.clone(), with_omega_as(&d1, CHART_ROOT)),
                        (y.clone(), with_omega_as(&d2, CHART_ROOT)),
                    ];
                    out.extend(chart_through(point, &conditions, CHART_ROOT, r));
                    if out.len() >= MERGE_CHARTS {
                        return out;
                    }
                }
            }
        }
        out
    }

    /// [`Self::departure`] in a chart of [`Self::cancelled_root_charts`]:
    /// the transfer function with the solved parameters substituted and
    /// its cancelled factor `Omega - r` divided out.
    fn chart_departure(
        &mut self,
        chart: &[Substitution],
        a: &BTreeMap<String, Rat>,
        gone: &FrfType,
    ) -> Option<BTreeMap<String, Rat>> {
        let vars: Vec<String> = a.keys().cloned().collect();
        let names: Vec<String> = vars
            .iter()
            .chain(chart.iter().map(|w| &w.var))
            .cloned()
            .collect();
        let factor = &Poly::var(OMEGA) - &Poly::var(CHART_ROOT);
        let reduced = |p: &Poly| {
            chart
                .iter()
                .fold(p.clone(), |q, w| substitute(&q, w))
                .div_exact(&factor)
        };
        let (num, den) = (reduced(&self.num)?, reduced(&self.den)?);
        let coefficients = StratumCoefficients::of(&num, &den, &vars, chart, &names)?;
        self.departure(chart, &coefficients, &vars, a, gone)
    }

    /// The end of a Nelder-Mead descent of `cost` from `lx0` (logarithms of
    /// the coordinates `names` of the stratum or chart of `subs`), rounded
    /// to a short rational point, if the exact type there is `gone`.
    fn descended(
        &self,
        subs: &[Substitution],
        names: &[String],
        lx0: &[f64],
        cost: &mut impl FnMut(&[f64]) -> f64,
        gone: &FrfType,
    ) -> Option<BTreeMap<String, Rat>> {
        let best = nelder_mead_for(cost, lx0, 0.5, f64::MIN_POSITIVE, DEPARTURE_EVALUATIONS);
        [3, 4, 6, 9].into_iter().find_map(|digits| {
            let b: BTreeMap<String, Rat> = names
                .iter()
                .zip(&best)
                .map(|(v, x)| {
                    Some((
                        v.clone(),
                        short_rational(x.clamp(-30.0, 30.0).exp(), digits)?,
                    ))
                })
                .collect::<Option<_>>()?;
            let full = full_point(subs, &b)?;
            (self.type_at(&full).as_ref() == Some(gone)).then_some(b)
        })
    }

    /// The cancellation walls through `point`, nested as the strata are.
    fn walls_through(&mut self, point: &BTreeMap<String, Rat>) -> Vec<Substitution> {
        let mut subs: Vec<Substitution> = Vec::new();
        while subs.len() < self.params.len() {
            let s = self.stratum(&subs);
            // A wall, or a partial one (the path's positivity is checked)
            // of a size the strata's factorizations can afford.
            let next = s.factors.iter().filter(|f| f.cancels).find_map(|f| {
                if !f.poly.subs_point(point).is_zero() {
                    return None;
                }
                f.wall.clone().or_else(|| {
                    linear_solution(&f.poly, &s.vars)
                        .filter(|w| w.alpha.num_terms() + w.beta.num_terms() <= PARTIAL_WALL_TERMS)
                })
            });
            let Some(w) = next else { break };
            subs.push(w);
            if self.partial_wall_too_large(&subs) {
                subs.pop();
                break;
            }
        }
        subs
    }

    /// A point of type `gone` on the stratum or chart of `subs` (its free
    /// variables `vars`, whose transfer function `coefficients` computes)
    /// reached by a descent from `a`, if the exact type confirms it.
    fn departure(
        &self,
        subs: &[Substitution],
        coefficients: &StratumCoefficients,
        vars: &[String],
        a: &BTreeMap<String, Rat>,
        gone: &FrfType,
    ) -> Option<BTreeMap<String, Rat>> {
        let lx0: Vec<f64> = vars.iter().map(|v| a[v].to_f64().ln()).collect();
        let mut near = Vec::new();
        let mut cost = |lx: &[f64]| -> f64 {
            coefficients
                .at(lx)
                .and_then(|(n, d)| violation_near(gone, &n, &d, &mut near))
                .unwrap_or(1e3)
        };
        self.descended(subs, vars, &lx0, &mut cost, gone)
    }

    /// Samples the segment from `a` to `b` (free parameters of the
    /// stratum of `subs`) exactly; where two neighbouring samples show the
    /// two ends of a type of `merges` not yet shown, halves towards the
    /// meeting and records the path once [`path_event`] finds its event.
    fn scan_segment(
        &mut self,
        subs: &[Substitution],
        a: &BTreeMap<String, Rat>,
        b: &BTreeMap<String, Rat>,
        merges: &[Merge],
    ) {
        let samples: Vec<BTreeMap<String, Rat>> = (0..=SEGMENT_SAMPLES)
            .map(|k| {
                between(
                    a,
                    b,
                    &Rat::new((k as i64).into(), (SEGMENT_SAMPLES as i64).into()),
                )
            })
            .collect();
        let types: Vec<Option<FrfType>> = samples
            .iter()
            .map(|p| full_point(subs, p).and_then(|p| self.type_at(&p)))
            .collect();
        for k in 0..SEGMENT_SAMPLES {
            let (Some(x), Some(y)) = (&types[k], &types[k + 1]) else {
                continue;
            };
            let Some(m) = merges.iter().find(|m| {
                ((x, y) == (&m.split, &m.gone) || (y, x) == (&m.split, &m.gone))
                    && !self.witnesses.contains_key(&m.wanted)
                    && !self.paths.contains_key(&m.wanted)
            }) else {
                continue;
            };
            let (from, to) = if x == &m.split {
                (&samples[k], &samples[k + 1])
            } else {
                (&samples[k + 1], &samples[k])
            };
            if let Some(path) = self.halved_path(subs, from.clone(), to.clone(), m) {
                self.paths.insert(m.wanted.clone(), path);
            }
        }
    }

    /// The segment from `a` (of `m`'s split type) to `b` (of its far
    /// type), halved towards the event until [`path_event`] finds `m`'s.
    fn halved_path(
        &mut self,
        subs: &[Substitution],
        mut a: BTreeMap<String, Rat>,
        mut b: BTreeMap<String, Rat>,
        m: &Merge,
    ) -> Option<MergePath> {
        let half = Rat::new(1.into(), 2.into());
        for _ in 0..MERGE_HALVINGS {
            let path = segment(subs, &a, &b);
            if path_event(&self.num, &self.den, &path, m.kept) == Some(m.event) {
                return Some(path);
            }
            let mid = between(&a, &b, &half);
            match full_point(subs, &mid).and_then(|p| self.type_at(&p)) {
                Some(t) if t == m.split => a = mid,
                Some(t) if t == m.gone => b = mid,
                _ => return None,
            }
        }
        None
    }
}

/// The model's parameters at a point of a stratum or a chart: the
/// eliminated ones from the substitutions (positive, or `None`), the
/// chart's cancelled root or double zero left out.
fn full_point(subs: &[Substitution], p: &BTreeMap<String, Rat>) -> Option<BTreeMap<String, Rat>> {
    let mut full = positive_full_point(subs, p)?;
    full.remove(CHART_ROOT);
    full.remove(CHART_ZERO);
    Some(full)
}

/// The gap (the number of poles below it) of `t`'s double zero, if an
/// `A^2` is `t`'s only multiple token.
fn double_zero_gap(t: &FrfType) -> Option<usize> {
    let multiple: Vec<usize> = (0..t.tokens.len())
        .filter(|&i| t.tokens[i].multiplicity > 1)
        .collect();
    let [i] = multiple.as_slice() else {
        return None;
    };
    t.tokens[*i].is_zero_of(2).then(|| {
        t.tokens[..*i]
            .iter()
            .filter(|k| k.feature == Feature::Resonance)
            .count()
    })
}

/// `a` with its coordinate `c` multiplied by `p / q`.
fn moved(a: &BTreeMap<String, Rat>, c: &str, (p, q): (i64, i64)) -> BTreeMap<String, Rat> {
    let mut b = a.clone();
    b.insert(c.to_string(), &a[c] * &Rat::new(p.into(), q.into()));
    b
}

/// `p` with `Omega` renamed to a chart's coordinate `name`.
fn with_omega_as(p: &Poly, name: &str) -> Poly {
    p.rename(|v| {
        if v == OMEGA {
            name.to_string()
        } else {
            v.to_string()
        }
    })
}

/// The chart in which `conditions` (each of degree one in its parameter,
/// solved in turn) hold, with `coordinate` at `value` and the other
/// parameters free, and `point`'s coordinates in it, if `point` is the
/// chart's point there.
fn chart_through(
    point: &BTreeMap<String, Rat>,
    conditions: &[(String, Poly)],
    coordinate: &str,
    value: &Rat,
) -> Option<(Vec<Substitution>, BTreeMap<String, Rat>)> {
    let solved = solve_in_turn(&BTreeMap::new(), conditions)?;
    let chart: Vec<Substitution> = solved
        .into_iter()
        .map(|(var, p, q)| Substitution {
            var,
            alpha: q,
            beta: p,
        })
        .collect();
    let mut a: BTreeMap<String, Rat> = point
        .iter()
        .filter(|(k, _)| !conditions.iter().any(|(x, _)| x == *k))
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect();
    a.insert(coordinate.to_string(), value.clone());
    (full_point(&chart, &a).as_ref() == Some(point)).then_some((chart, a))
}

/// The number of roots at `Omega = 0` of `p`.
fn zero_roots(p: &Poly) -> usize {
    p.coeffs_in(OMEGA)
        .iter()
        .take_while(|c| c.is_zero())
        .count()
}

/// The point `a + f (b - a)`.
fn between(a: &BTreeMap<String, Rat>, b: &BTreeMap<String, Rat>, f: &Rat) -> BTreeMap<String, Rat> {
    a.iter()
        .map(|(v, x)| (v.clone(), x + &(&(&b[v] - x) * f)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ends_of_a_double_zero() {
        let t: FrfType = "RA^2R".parse().unwrap();
        let (split, gone) = merge_ends(&t).unwrap();
        assert_eq!(split.to_string(), "RAAR");
        assert_eq!(gone, "RR (nm)".parse().unwrap());
        // A zero beside the pair, two multiple tokens, a triple zero: none.
        for t in ["RAA^2R", "A^2RA^2R", "RA^3R", "R^2A"] {
            assert!(merge_ends(&t.parse().unwrap()).is_none(), "{t}");
        }
    }

    #[test]
    fn the_ends_beside_a_kept_double_zero() {
        let ty = |s: &str| s.parse::<FrfType>().unwrap();
        let ends = |t: &str| -> Vec<(String, String, PathEvent)> {
            chart_merge_ends(&ty(t))
                .into_iter()
                .map(|(a, b, e)| (a.to_string(), b.to_string(), e))
                .collect()
        };
        // A triple zero: a simple zero crosses the double one, either way.
        assert_eq!(
            ends("RA^3R"),
            [
                (
                    "RA^2AR".into(),
                    "RAA^2R".into(),
                    PathEvent::CrossesDoubleZero
                ),
                (
                    "RAA^2R".into(),
                    "RA^2AR".into(),
                    PathEvent::CrossesDoubleZero
                ),
            ]
        );
        // Two double zeros in one gap: either pair may be the one that meets.
        assert_eq!(
            ends("RA^2A^2R"),
            [
                ("RAAA^2R".into(), "RA^2R (nm)".into(), PathEvent::PairMeets),
                ("RA^2AAR".into(), "RA^2R (nm)".into(), PathEvent::PairMeets),
            ]
        );
        assert_eq!(ends("A^2RA^2R").len(), 2);
        // A lone double zero (no chart needed), one beside a simple zero, a
        // quadruple zero, three multiple tokens: none.
        for t in ["RA^2R", "RAA^2R", "RA^4R", "A^2RA^2RA^2"] {
            assert!(ends(t).is_empty(), "{t}");
        }
    }

    #[test]
    fn the_type_at_an_event_is_unambiguous() {
        let ty = |s: &str| s.parse::<FrfType>().unwrap();
        let at = |a: &str, b: &str, e| merged_at_event(&ty(a), &ty(b), e).map(|t| t.to_string());
        assert_eq!(
            at("RAAR", "RR (nm)", PathEvent::PairMeets).as_deref(),
            Some("RA^2R")
        );
        // Three simple zeros in a gap, one pair gone: which pair met is
        // not known.
        assert_eq!(at("RAAAR", "RAR (nm)", PathEvent::PairMeets), None);
        assert_eq!(
            at("RA^2AAR", "RA^2R (nm)", PathEvent::PairMeets).as_deref(),
            Some("RA^2A^2R")
        );
        assert_eq!(
            at("RA^2AR", "RAA^2R", PathEvent::CrossesDoubleZero).as_deref(),
            Some("RA^3R")
        );
        assert_eq!(
            at("RAA^2AR", "RA^2AAR", PathEvent::CrossesDoubleZero).as_deref(),
            Some("RA^3AR")
        );
        // Ends that no one event joins.
        assert_eq!(at("RA^2AR", "RA^2AR", PathEvent::CrossesDoubleZero), None);
        assert_eq!(at("RA^2AR", "RAA^2R", PathEvent::PairMeets), None);
    }

    #[test]
    fn events_beside_a_kept_double_zero() {
        let p = |s: &str| s.parse::<Poly>().unwrap();
        let path = |pairs: &[(&str, &str)]| MergePath {
            parameters: pairs
                .iter()
                .map(|(k, v)| (k.to_string(), [p(v), p("1")]))
                .collect(),
        };
        // The zero b = 1 + 2 s crosses the double zero at z = 2 at s = 1/2.
        let num = p("(Omega - z)^2*(Omega - b)");
        let crossing = path(&[("z", "2"), ("b", "1 + 2*s")]);
        assert_eq!(
            path_event(&num, &p("Omega - 10"), &crossing, true),
            Some(PathEvent::CrossesDoubleZero)
        );
        // Without the kept factor divided out the discriminant vanishes
        // all along: refused.
        assert_eq!(path_event(&num, &p("Omega - 10"), &crossing, false), None);
        // The double zero crosses the pole at 4 (z = 3 + 2 s): refused.
        let moving = path(&[("z", "3 + 2*s"), ("b", "1 + 2*s")]);
        assert_eq!(path_event(&num, &p("Omega - 4"), &moving, true), None);
        // Beside the double zero at 5, a pair meets at b = sqrt 3.
        let num = p("(Omega - z)^2*(Omega^2 - 2*b*Omega + c)");
        let pair = path(&[("z", "5"), ("b", "2 - s"), ("c", "3")]);
        assert_eq!(
            path_event(&num, &p("Omega - 10"), &pair, true),
            Some(PathEvent::PairMeets)
        );
        // With the double zero at 2 between the pair (zeros 1 and 3 at
        // s = 0), the upper zero crosses it before the pair meets: two
        // events, refused.
        let straddled = path(&[("z", "2"), ("b", "2 - s"), ("c", "3")]);
        assert_eq!(path_event(&num, &p("Omega - 10"), &straddled, true), None);
    }

    /// Every point of a double-zero chart has its double zero at the
    /// chart's coordinate: checked at points one move away from a
    /// witness of N5-g1-a3.1-s4.1 (`AARRRRA^2`), by substituting that
    /// coordinate into the numerator and its derivative (both vanish) and
    /// by the gcd of the two (degree one).
    #[test]
    fn double_zero_charts_keep_their_double_zero() {
        use crate::Model;
        let m = Model::from_id("N5-g1-a3.1-s4.1").unwrap();
        let tf = m.undamped_tf();
        let mut prover = Prover::new(&m, tf.num.clone(), tf.den.clone());
        let w: BTreeMap<String, Rat> = [
            ("c1", "993427/10000"),
            ("c23", "350773/10000000"),
            ("c34", "34551/2500"),
            ("c45", "127731/100000"),
            ("m1", "167020834154375189354794109511689111109606421/14998185942844685253047268561680386572000000"),
            ("m2", "6271/500000"),
            ("m3", "5861/2000"),
            ("m4", "772720182485754442304050993073470641479/196072273249939474117559205766953477750"),
            ("m5", "229763/500000"),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v.parse().unwrap()))
        .collect();
        assert_eq!(prover.type_at(&w).unwrap().to_string(), "AARRRRA^2");
        let charts = prover.double_zero_charts(&w);
        assert!(!charts.is_empty());
        let mut checked = 0;
        for (chart, a) in &charts {
            for c in a.keys() {
                let mut b = a.clone();
                b.insert(c.clone(), &a[c] * &Rat::from(2));
                let Some(f) = full_point(chart, &b) else {
                    continue;
                };
                let n = tf.num.subs_point(&f);
                let z = &b[CHART_ZERO];
                assert!(n.subs(OMEGA, z).is_zero());
                assert!(n.derivative(OMEGA).subs(OMEGA, z).is_zero());
                assert_eq!(poly::gcd(&n, &n.derivative(OMEGA)).degree(OMEGA), 1);
                checked += 1;
            }
        }
        assert!(checked >= 4, "{checked}");
    }

    #[test]
    fn a_quadratic_family_merges_once() {
        let p = |s: &str| s.parse::<Poly>().unwrap();
        // The path b(s), c(s) with denominators 1.
        let path = |b: &str, c: &str| MergePath {
            parameters: [
                ("b".to_string(), [p(b), p("1")]),
                ("c".to_string(), [p(c), p("1")]),
            ]
            .into_iter()
            .collect(),
        };
        let num = p("Omega^2 - 2*b*Omega + c");
        // One pair meeting, no double zero kept.
        let merges_once = |num: &Poly, den: &Poly, path: &MergePath| {
            path_event(num, den, path, false) == Some(PathEvent::PairMeets)
        };
        // Along b = 2 - s, c = 3 the discriminant 4 (b^2 - c) vanishes once
        // in (0, 1), at b = sqrt 3; the pole at 10 stays above both zeros.
        assert!(merges_once(&num, &p("Omega - 10"), &path("2 - s", "3")));
        // Along b = 3 - 2 s the pair still meets at b = sqrt 3, but first
        // the larger zero b + sqrt(b^2 - 3) (5.45 at s = 0) crosses the
        // pole at 4.
        assert!(!merges_once(&num, &p("Omega - 4"), &path("3 - 2*s", "3")));
        // A parameter that turns negative on the path.
        assert!(!merges_once(
            &num,
            &p("Omega - 10"),
            &path("2 - s", "3 - 4*s")
        ));
    }
}
