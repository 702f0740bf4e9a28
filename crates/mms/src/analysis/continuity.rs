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
//! exactly by Sturm sequences ([`merges_once`], re-derived by the checker
//! on its own).

use super::frf_type::{Feature, FrfType, Token};
use super::prover::{positive_full_point, substitute, Prover, Substitution};
use super::targeted::{
    linear_solution, nelder_mead_for, short_rational, violation_near, StratumCoefficients,
    PARTIAL_WALL_TERMS,
};
use super::walls::{solve_in_turn, wall_parameters};
use super::MergePath;
use crate::tf::OMEGA;
use poly::{count_roots_in, Poly, Rat, UPoly};
use std::collections::BTreeMap;

/// The path's variable.
pub const PATH_VARIABLE: &str = "s";

/// The coordinate of a cancelled-root chart that stands for the
/// cancelled pole (the model's parameters never take this name).
const CHART_ROOT: &str = "cancelled_root";

/// Charts of block mechanisms tried per split witness, at most.
const MERGE_CHARTS: usize = 8;

/// Halvings of the segment towards one event.
const MERGE_HALVINGS: usize = 12;

/// Exact samples of a segment, to find where the pair leaves the axis.
const SEGMENT_SAMPLES: usize = 32;

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
    !c.is_zero() && u.sign_at(&Rat::ZERO) != 0 && count_roots_in(&u, &Rat::ZERO, &Rat::ONE) == 0
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

/// True when along `path` (every parameter positive on `[0, 1]`) the
/// reduced transfer function keeps its poles simple, apart from each
/// other and from the zeros, none of them reaching `0` or infinity, and
/// its zeros meet exactly once, at an `s` in `(0, 1)` where one pair
/// forms a double zero and no other zero is multiple. Then the type at
/// that `s` is the type at `s = 0` with the pair that leaves the axis by
/// `s = 1` merged.
pub(super) fn merges_once(num: &Poly, den: &Poly, path: &MergePath) -> bool {
    // The condition that fails most often on a long segment first: other
    // zeros meeting too.
    let path = &path.parameters;
    let (n, _) = along(num, path);
    let (d, _) = along(den, path);
    let g = poly::gcd(&n, &d);
    let (Some(n), Some(d)) = (n.div_exact(&g), d.div_exact(&g)) else {
        return false;
    };
    let (n, d) = (without_zero_roots(&n), without_zero_roots(&d));
    if n.degree(OMEGA) < 2 {
        return false;
    }
    let Some((_, disc)) = UPoly::from_poly(&poly::discriminant(&n, OMEGA), PATH_VARIABLE) else {
        return false;
    };
    if disc.sign_at(&Rat::ZERO) == 0
        || disc.sign_at(&Rat::ONE) == 0
        || count_roots_in(&disc, &Rat::ZERO, &Rat::ONE) != 1
    {
        return false;
    }
    if !no_root_on_path(&poly::resultant(&n, &d, OMEGA)) {
        return false;
    }
    let ends = |p: &Poly| {
        let cs = p.coeffs_in(OMEGA);
        [cs[0].clone(), cs[cs.len() - 1].clone()]
    };
    if !ends(&n).iter().chain(&ends(&d)).all(no_root_on_path)
        || (d.degree(OMEGA) >= 2 && !no_root_on_path(&poly::discriminant(&d, OMEGA)))
    {
        return false;
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
        return false;
    }
    // The meeting is of two zeros only: the first principal subresultant
    // coefficient of n and n' is not zero there (their gcd has degree 1).
    if n.degree(OMEGA) >= 3 {
        let psc = poly::psc(&n, &n.derivative(OMEGA), OMEGA);
        let Some((_, p1)) = psc.get(1).and_then(|p| UPoly::from_poly(p, PATH_VARIABLE)) else {
            return false;
        };
        if p1.is_zero() || count_roots_in(&disc.gcd(&p1), &Rat::ZERO, &Rat::ONE) != 0 {
            return false;
        }
    }
    true
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
    MergePath { parameters }
}

/// A wanted type with its two ends ([`merge_ends`]).
struct Merge {
    wanted: FrfType,
    split: FrfType,
    gone: FrfType,
}

impl Prover<'_> {
    /// Double zeros by continuity (see the module docs) for the types of
    /// `wanted` with one `A^2` alone in its gap whose split type has a
    /// witness. From each such witness, segments run to a point reached by
    /// a descent towards the far type, to its witness and to the witnesses
    /// of the other non-minimum-phase types on the same walls; wherever two
    /// neighbouring samples of a segment show the two ends of a wanted
    /// type, the segment is halved until [`merges_once`] holds, and the
    /// path is recorded. Returns how many of `wanted` have a witness or a
    /// path afterwards.
    pub(crate) fn merge_search(&mut self, wanted: &[FrfType]) -> usize {
        let done = |p: &Prover, t: &FrfType| p.witnesses.contains_key(t) || p.paths.contains_key(t);
        let merges: Vec<Merge> = wanted
            .iter()
            .filter(|t| !done(self, t))
            .filter_map(|t| {
                let (split, gone) = merge_ends(t)?;
                Some(Merge {
                    wanted: t.clone(),
                    split,
                    gone,
                })
            })
            .collect();
        for m in &merges {
            if done(self, &m.wanted) {
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
                if done(self, &m.wanted) {
                    break;
                }
                self.scan_segment(&subs, &a, &b, &merges);
            }
            // A cancellation the walls do not hold (a factor linear in no
            // parameter): the chart of a block mechanism, the cancelled
            // root one of its coordinates.
            let kept = s.den.degree(OMEGA) as usize - zero_roots(&s.den);
            if done(self, &m.wanted) || kept == m.split.resonances() as usize || !subs.is_empty() {
                continue;
            }
            for (chart, a) in self.cancelled_root_charts(&start) {
                if done(self, &m.wanted) {
                    break;
                }
                if let Some(b) = self.chart_departure(&chart, &a, &m.gone) {
                    self.scan_segment(&chart, &a, &b, &merges);
                }
            }
        }
        wanted.iter().filter(|t| done(self, t)).count()
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
        let to_chart = |d: &Poly| {
            d.rename(|v| {
                if v == OMEGA {
                    CHART_ROOT.to_string()
                } else {
                    v.to_string()
                }
            })
        };
        let mut out = Vec::new();
        for (d1, _, d2, _) in self.cancellation_mechanisms() {
            if !(d1.subs_point(&at_r).is_zero() && d2.subs_point(&at_r).is_zero()) {
                continue;
            }
            let (in1, in2) = wall_parameters(&d1, &d2, &[]);
            for x in &in1 {
                for y in &in2 {
                    let conditions = [(x.clone(), to_chart(&d1)), (y.clone(), to_chart(&d2))];
                    let Some(solved) = solve_in_turn(&BTreeMap::new(), &conditions) else {
                        continue;
                    };
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
                        .filter(|(k, _)| *k != x && *k != y)
                        .map(|(k, v)| (k.clone(), v.clone()))
                        .collect();
                    a.insert(CHART_ROOT.to_string(), r.clone());
                    if full_point(&chart, &a).as_ref() == Some(point) {
                        out.push((chart, a));
                    }
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
    /// meeting and records the path once [`merges_once`] holds.
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
            if let Some(path) = self.halved_path(subs, from.clone(), to.clone(), &m.split, &m.gone)
            {
                self.paths.insert(m.wanted.clone(), path);
            }
        }
    }

    /// The segment from `a` (of type `split`) to `b` (of type `gone`),
    /// halved towards the pair's meeting until [`merges_once`] holds.
    fn halved_path(
        &mut self,
        subs: &[Substitution],
        mut a: BTreeMap<String, Rat>,
        mut b: BTreeMap<String, Rat>,
        split: &FrfType,
        gone: &FrfType,
    ) -> Option<MergePath> {
        let half = Rat::new(1.into(), 2.into());
        for _ in 0..MERGE_HALVINGS {
            let path = segment(subs, &a, &b);
            if merges_once(&self.num, &self.den, &path) {
                return Some(path);
            }
            let mid = between(&a, &b, &half);
            match full_point(subs, &mid).and_then(|p| self.type_at(&p)) {
                Some(t) if &t == split => a = mid,
                Some(t) if &t == gone => b = mid,
                _ => return None,
            }
        }
        None
    }
}

/// The model's parameters at a point of a stratum or a chart: the
/// eliminated ones from the substitutions (positive, or `None`), the
/// chart's cancelled root left out.
fn full_point(subs: &[Substitution], p: &BTreeMap<String, Rat>) -> Option<BTreeMap<String, Rat>> {
    let mut full = positive_full_point(subs, p)?;
    full.remove(CHART_ROOT);
    Some(full)
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
