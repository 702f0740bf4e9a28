//! Witnesses along one block's scale.
//!
//! When the gap splits the chain into two blocks that both carry a term of
//! the TF, scaling one block's masses and springs by `s` keeps its
//! eigenvalues and divides its term by `s`: with `n_B / d_B` the terms,
//! `n_2 -> s^(k-1) n_2` and `d_2 -> s^k d_2` for a block of `k` masses, so
//! the numerator `n_1 d_2 + n_2 d_1` becomes `s^(k-1) (s A + B)`, `A = n_1
//! d_2`, `B = n_2 d_1`: linear in `s`, a coordinate no parameter is (it
//! moves every parameter of the block at once). Two uses:
//!
//! - The scale line: as `s` runs over `(0, inf)` the zeros are where
//!   `-B/A = s`, so the type changes only at the critical values of
//!   `-B/A`, and one `s` between every two of them shows every type of
//!   the line. A pole the blocks share stays shared along it. At random
//!   points over orders of magnitude this reaches thin regions: three
//!   zeros below the first resonance of N5-g3-a4.3-s5.3 with its shared
//!   pole cancelled once.
//! - Merged zeros: `s` shares no monomial with the other block's
//!   parameters, so it joins them in a jointly linear set where no
//!   parameter of its own block could (they multiply each other in
//!   `d_2`), and the cancellation of a shared pole takes one condition,
//!   `num(lambda) = 0`. From a witness of the split type the merged zeros
//!   are posed between the split ones and solved for over Q, or one or
//!   two parameters short of a linear set over a real number field.
//!   N5-g3-a4.1-s5.1: a double zero beside a simple one below the first
//!   resonance takes `s` of m4-m5, `c1` and `m1`; the triple zero one
//!   parameter more.

use super::algebraic::algebraic_points_up_to;
use super::frf_type::{Feature, FrfType, Token};
use super::prover::Prover;
use super::targeted::{horner, positive_roots, short_rational, MERGE_FRACTIONS};
use super::targeted::{
    linear_sets, multiple_antiresonances, solve_linear, split_type, zero_groups,
};
use crate::tf::OMEGA;
use crate::xorshift::XorShift;
use poly::{Poly, Rat};
use std::collections::{BTreeMap, BTreeSet};

/// The name of the block's scale in the conditions (no parameter's).
const SCALE: &str = "block_scale";
/// Parameter sets tried per merged root and scaled block, at most.
const SCALE_SETS: usize = 8;
/// Choices of the one or two parameters a set is short of, per set, at
/// most.
const SHORT_TRIES: usize = 6;
/// Fields (and two short eliminants) of degree up to this: a triple zero
/// beside a shared pole, two parameters short of `s` and one more, has a
/// Bezout bound of 18 (N5-g3-a4.3-s5.3); the search runs on a few types.
const SCALE_FIELD_DEGREE: usize = 24;
/// Random points per cancellation count along the scale lines.
const SWEEP_TRIALS: usize = 20_000;
/// The range of the sweep's parameters: the regions it is for lie where
/// the parameters differ by orders of magnitude.
const SWEEP_LOW: f64 = 1e-4;
const SWEEP_HIGH: f64 = 1e4;
/// The seed of the sweep's draws.
const SWEEP_SEED: u64 = 0x5CA1_E5EE;
/// Random points per tie, cancellation count and round of the tied
/// sweep, its parameters' range and its seed.
const TIE_TRIALS: usize = 400;
const TIE_LOW: f64 = 1e-2;
const TIE_HIGH: f64 = 1e2;
const TIE_SEED: u64 = 0x71E5_CA1E;

impl Prover<'_> {
    /// Witnesses of the `wanted` types not yet shown with at most one
    /// cancelled pole and simple resonances: along the scale lines, then
    /// their multiple zeros merged from their split types' witnesses (see
    /// the module docs). Runs after every other search, on what they leave
    /// open. Returns how many of `wanted` are shown.
    pub(crate) fn block_scale_search(&mut self, wanted: &[FrfType]) -> usize {
        let blocks = self.parameter_blocks();
        if blocks.len() != 2 {
            return 0;
        }
        self.scale_sweep(wanted, &blocks);
        self.scale_merge(wanted, &blocks);
        self.tie_sweep(wanted, &blocks);
        wanted.iter().filter(|t| self.shown(t)).count()
    }

    /// Along the scale of one block at random points (with a pole the two
    /// blocks share posed, where a type needs one cancelled): the zeros
    /// are those of `s A + B` (`A = n_1 d_2`, `B = n_2 d_1`), so as `s`
    /// runs over `(0, inf)` the type changes only where `s = -B/A` has a
    /// critical value, at the roots of `A B' - A' B`. One `s` between every
    /// two critical values shows every type of the line. The targets are
    /// the wanted types with simple tokens and the split types of those
    /// with multiple zeros, which [`Self::scale_merge`] starts from; a
    /// point whose `f64` reading is a target is read exactly.
    fn scale_sweep(&mut self, wanted: &[FrfType], blocks: &[BTreeSet<String>]) {
        let degree = self.den.degree(OMEGA);
        let mut targets: BTreeSet<(u32, Vec<Feature>)> = BTreeSet::new();
        for t in wanted.iter().filter(|t| !self.shown(t)) {
            let split = split_type(t);
            if t.has_multiple_resonance() || self.witnesses.contains_key(&split) {
                continue;
            }
            match degree.checked_sub(t.resonances()) {
                Some(c) if c <= 1 => {
                    targets.insert((c, split.tokens.iter().map(|k| k.feature).collect()));
                }
                _ => {}
            }
        }
        if targets.is_empty() {
            return;
        }
        let (mass, stiff) = (self.model.mass_matrix(), self.model.stiffness_matrix());
        let masses = super::pole_signs::chain_blocks(&stiff);
        let dets: Vec<Poly> = masses
            .iter()
            .map(|b| poly::det(&super::pole_signs::pencil(&mass, &stiff, b)))
            .collect();
        let lines = scale_lines(&self.num, blocks);
        let mut rng = XorShift::new(SWEEP_SEED);
        let draw = |rng: &mut XorShift| short_rational(rng.log_uniform(SWEEP_LOW, SWEEP_HIGH), 3);
        for _ in 0..SWEEP_TRIALS {
            // Until every target is shown.
            let cancellations: BTreeSet<u32> = targets.iter().map(|(c, _)| *c).collect();
            if cancellations.is_empty() {
                return;
            }
            for c in cancellations {
                let Some(mut point) = random_point(&self.params, &mut rng, draw) else {
                    continue;
                };
                let mut shared = None;
                if c == 1 {
                    // One mass of each block solved so that `lambda` is an
                    // eigenvalue of both (a block's determinant is linear
                    // in each of its masses).
                    let Some(lambda) = draw(&mut rng) else {
                        continue;
                    };
                    let solved = masses.iter().zip(&dets).all(|(b, d)| {
                        let m = format!("m{}", b[(rng.next_u64() % b.len() as u64) as usize] + 1);
                        match solve_mass(d, &m, &point, &lambda) {
                            Some(v) => {
                                point.insert(m, v);
                                true
                            }
                            None => false,
                        }
                    });
                    if !solved {
                        continue;
                    }
                    shared = Some(lambda);
                }
                for (b, (a_poly, b_poly)) in blocks.iter().zip(&lines) {
                    for t in self.sweep_line(&point, b, (a_poly, b_poly), shared.as_ref(), &targets)
                    {
                        let c = degree.saturating_sub(t.resonances());
                        targets.remove(&(c, t.tokens.iter().map(|k| k.feature).collect()));
                    }
                }
            }
        }
    }

    /// The types along the scale of `block` at `point` (see
    /// [`Self::scale_sweep`]): the targets among them are recorded, and
    /// returned as the exact reading has them.
    fn sweep_line(
        &mut self,
        point: &BTreeMap<String, Rat>,
        block: &BTreeSet<String>,
        (a, b): (&Poly, &Poly),
        shared: Option<&Rat>,
        targets: &BTreeSet<(u32, Vec<Feature>)>,
    ) -> Vec<FrfType> {
        let mut shown = Vec::new();
        let univariate = |p: &Poly| -> Option<Poly> {
            let u = p.subs_point(point);
            match shared {
                Some(l) => u.div_exact(&(&Poly::var(OMEGA) - &Poly::constant(l.clone()))),
                None => Some(u),
            }
        };
        let (Some(a), Some(b), Some(den)) = (univariate(a), univariate(b), univariate(&self.den))
        else {
            return shown;
        };
        let Some(LineFloats {
            a: fa,
            b: fb,
            poles,
            critical,
        }) = line_floats(&a, &b, &den)
        else {
            return shown;
        };
        let mut values: Vec<f64> = critical
            .into_iter()
            .map(|x| -horner(&fb, x) / horner(&fa, x))
            .filter(|s| *s > 0.0 && s.is_finite())
            .collect();
        values.sort_by(f64::total_cmp);
        let mut scales: Vec<f64> = values.windows(2).map(|w| (w[0] * w[1]).sqrt()).collect();
        match (values.first(), values.last()) {
            (Some(lo), Some(hi)) => scales.extend([lo / 4.0, hi * 4.0]),
            _ => scales.push(1.0),
        }
        let cancelled = u32::from(shared.is_some());
        for s in scales {
            let line: Vec<f64> = (0..fa.len().max(fb.len()))
                .map(|k| s * fa.get(k).unwrap_or(&0.0) + fb.get(k).unwrap_or(&0.0))
                .collect();
            let Some(zeros) = positive_roots(&line) else {
                continue;
            };
            let mut tokens: Vec<(f64, Feature)> = zeros
                .iter()
                .map(|&z| (z, Feature::Antiresonance))
                .chain(poles.iter().map(|&p| (p, Feature::Resonance)))
                .collect();
            tokens.sort_by(|x, y| x.0.total_cmp(&y.0));
            let features: Vec<Feature> = tokens.into_iter().map(|t| t.1).collect();
            if !targets.contains(&(cancelled, features)) {
                continue;
            }
            let Some(s) = short_rational(s, 4) else {
                continue;
            };
            let scaled: BTreeMap<String, Rat> = point
                .iter()
                .map(|(p, v)| {
                    let v = if block.contains(p) { v * &s } else { v.clone() };
                    (p.clone(), v)
                })
                .collect();
            if let Some(t) = self.type_at(&scaled) {
                self.offer(t.clone(), scaled);
                shown.push(t);
            }
        }
        shown
    }

    /// The multiple zeros of the wanted types merged from a witness of
    /// each one's split type with one block scaled (see the module docs).
    fn scale_merge(&mut self, wanted: &[FrfType], blocks: &[BTreeSet<String>]) {
        let degree = self.den.degree(OMEGA);
        for t in wanted {
            let mults = multiple_antiresonances(t);
            if mults.is_empty() || t.has_multiple_resonance() || self.shown(t) {
                continue;
            }
            let Some(cancelled) = degree.checked_sub(t.resonances()) else {
                continue;
            };
            let Some(w) = self.witnesses.get(&split_type(t)).cloned() else {
                continue;
            };
            let Some((shared, zeros)) = self.split_zeros(&w, cancelled) else {
                continue;
            };
            let (groups, all) = zero_groups(t, &zeros);
            if !all {
                continue;
            }
            'found: for scaled in blocks {
                let num = scaled_numerator(&self.num, scaled);
                let derivatives: Vec<Poly> = (0..mults.iter().max().copied().unwrap_or(1))
                    .scan(num.clone(), |d, _| {
                        let out = d.clone();
                        *d = d.derivative(OMEGA);
                        Some(out)
                    })
                    .collect();
                let mut free: Vec<String> = vec![SCALE.to_string()];
                free.extend(self.params.iter().filter(|p| !scaled.contains(*p)).cloned());
                let size = shared.len() + mults.iter().sum::<u32>() as usize;
                let with_scale = |size: usize| -> Vec<Vec<String>> {
                    linear_sets(&[&num], &free, size)
                        .into_iter()
                        .filter(|v| v.iter().any(|p| p == SCALE))
                        .take(SCALE_SETS)
                        .collect()
                };
                // Over Q where a set holds every condition, else one
                // parameter short of it over a real number field.
                let Some((short, sets)) = (0..=2.min(size - 1))
                    .map(|k| (k, with_scale(size - k)))
                    .find(|(_, sets)| !sets.is_empty())
                else {
                    continue;
                };
                for frac in MERGE_FRACTIONS {
                    let Some(posed) = groups
                        .iter()
                        .map(|&(a, b, k)| Some((short_rational((a + frac * (b - a)).exp(), 4)?, k)))
                        .collect::<Option<Vec<(Rat, u32)>>>()
                    else {
                        continue;
                    };
                    for vars in &sets {
                        let mut equations: Vec<Poly> =
                            shared.iter().map(|l| num.subs(OMEGA, l)).collect();
                        for (r, k) in &posed {
                            equations.extend(
                                derivatives[..*k as usize].iter().map(|d| d.subs(OMEGA, r)),
                            );
                        }
                        for xs in short_choices(&free, vars, short).iter().take(SHORT_TRIES) {
                            self.solve_merge(
                                wanted,
                                &w,
                                (vars, xs),
                                &equations,
                                scaled,
                                (&shared, &posed),
                            );
                            if self.shown(t) {
                                break 'found;
                            }
                        }
                    }
                }
            }
        }
    }

    /// Solves the merge's `equations` for `vars` (with `s` among them)
    /// and, where `xs` is not empty, the parameters `xs` a set is short
    /// of, the rest at the split type's witness `w`: over Q, or over a real
    /// number field; records the point with the scaled block's parameters
    /// multiplied by `s`.
    fn solve_merge(
        &mut self,
        wanted: &[FrfType],
        w: &BTreeMap<String, Rat>,
        (vars, xs): (&[String], &[String]),
        equations: &[Poly],
        scaled: &BTreeSet<String>,
        posed: (&[Rat], &[(Rat, u32)]),
    ) {
        let fixed: BTreeMap<String, Rat> = w
            .iter()
            .filter(|(p, _)| !vars.contains(p) && !xs.contains(p))
            .map(|(p, v)| (p.clone(), v.clone()))
            .collect();
        let equations: Vec<Poly> = equations.iter().map(|e| e.subs_point(&fixed)).collect();
        if !xs.is_empty() {
            for (field, mut point) in
                algebraic_points_up_to(&equations, vars, xs, SCALE_FIELD_DEGREE)
            {
                let Some(s) = point.remove(SCALE) else {
                    continue;
                };
                // The scaled block's parameters over the field, the others
                // as they were.
                let mut rest = fixed.clone();
                for p in scaled {
                    if let Some(v) = rest.remove(p) {
                        point.insert(p.clone(), field.scale(&s, &v));
                    }
                }
                self.record_algebraic(wanted, &rest, posed, field, point);
            }
            return;
        }
        let Some(solution) = solve_linear(&equations, vars) else {
            return;
        };
        if solution.iter().any(|v| v.signum() <= 0) {
            return;
        }
        let solved: BTreeMap<&String, &Rat> = vars.iter().zip(&solution).collect();
        let s = solved[&SCALE.to_string()];
        let point: BTreeMap<String, Rat> = w
            .iter()
            .map(|(p, v)| {
                let v = match solved.get(p) {
                    Some(x) => (*x).clone(),
                    None if scaled.contains(p) => v * s,
                    None => v.clone(),
                };
                (p.clone(), v)
            })
            .collect();
        self.record(point);
    }

    /// Double zeros beside a pole the block's own runs cancel: the two
    /// runs at the ends of a block with one mass between them, both with
    /// the eigenvalue `lambda_2`, make it an eigenvalue of the block on
    /// which `n_B` vanishes twice (the determinant expanded across the
    /// middle mass), so the pole cancels; with one pole of both blocks
    /// posed too where the type needs two cancelled. Along the scale line
    /// a double zero sits at every critical point `x` of `-B/A` with `s =
    /// -B(x)/A(x) > 0`; where the type there, read in `f64`, is wanted,
    /// the double zero is posed at a rational point next to `x` and solved
    /// for `s`, one parameter `q` of the other block over the real number
    /// field of the eliminant, and the mass that keeps the shared pole
    /// (see [`Self::solve_tie`]). N5-g3-a4.2-s5.2: `RRA^2` with `m1`'s and
    /// `m3`'s eigenvalues on the middle pole of `m1-m2-m3` and the free
    /// pair's on its lowest, cancelled once.
    fn tie_sweep(&mut self, wanted: &[FrfType], blocks: &[BTreeSet<String>]) {
        let degree = self.den.degree(OMEGA);
        let mut targets: BTreeSet<FrfType> = wanted
            .iter()
            .filter(|t| {
                let double = multiple_antiresonances(t) == [2];
                let cancelled = degree.checked_sub(t.resonances());
                double
                    && !t.has_multiple_resonance()
                    && matches!(cancelled, Some(1 | 2))
                    && !self.shown(t)
            })
            .cloned()
            .collect();
        if targets.is_empty() {
            return;
        }
        let (mass, stiff) = (self.model.mass_matrix(), self.model.stiffness_matrix());
        let chains = super::pole_signs::chain_blocks(&stiff);
        let det_of = |idx: &[usize]| poly::det(&super::pole_signs::pencil(&mass, &stiff, idx));
        let dets: Vec<Poly> = chains.iter().map(|b| det_of(b)).collect();
        let mut ties: Vec<Tie> = Vec::new();
        for (x, chain) in chains.iter().enumerate() {
            for middle in 1..chain.len().saturating_sub(1) {
                let runs = [&chain[..middle], &chain[middle + 1..]]
                    .iter()
                    .map(|run| (det_of(run), format!("m{}", run[0] + 1)))
                    .collect();
                ties.push(Tie {
                    block: x,
                    runs,
                    middle: format!("m{}", chain[middle] + 1),
                });
            }
        }
        if ties.is_empty() {
            return;
        }
        let lines = scale_lines(&self.num, blocks);
        let mut rng = XorShift::new(TIE_SEED);
        let draw = |rng: &mut XorShift| short_rational(rng.log_uniform(TIE_LOW, TIE_HIGH), 3);
        for _ in 0..TIE_TRIALS {
            let cancellations: BTreeSet<u32> = targets
                .iter()
                .filter_map(|t| degree.checked_sub(t.resonances()))
                .collect();
            if cancellations.is_empty() {
                return;
            }
            for c in cancellations {
                for tie_at in &ties {
                    let (x, runs, middle) = (&tie_at.block, &tie_at.runs, &tie_at.middle);
                    let Some(mut point) = random_point(&self.params, &mut rng, draw) else {
                        continue;
                    };
                    let Some(tie) = draw(&mut rng) else {
                        continue;
                    };
                    let tied = runs
                        .iter()
                        .all(|(d, m)| match solve_mass(d, m, &point, &tie) {
                            Some(v) => {
                                point.insert(m.clone(), v);
                                true
                            }
                            None => false,
                        });
                    if !tied || !dets[*x].subs(OMEGA, &tie).subs_point(&point).is_zero() {
                        continue;
                    }
                    let mut cancelled = vec![tie];
                    // The mass of each block that keeps the shared pole:
                    // the middle one in the tied block.
                    let mut keepers: Vec<String> = Vec::new();
                    if c == 2 {
                        let Some(lambda) = draw(&mut rng) else {
                            continue;
                        };
                        let solved = chains.iter().enumerate().all(|(b, chain)| {
                            let m = if b == *x {
                                middle.clone()
                            } else {
                                format!(
                                    "m{}",
                                    chain[(rng.next_u64() % chain.len() as u64) as usize] + 1
                                )
                            };
                            match solve_mass(&dets[b], &m, &point, &lambda) {
                                Some(v) => {
                                    point.insert(m.clone(), v);
                                    keepers.push(m);
                                    true
                                }
                                None => false,
                            }
                        });
                        if !solved || cancelled.contains(&lambda) {
                            continue;
                        }
                        cancelled.push(lambda);
                    }
                    for (y, (a_poly, b_poly)) in lines.iter().enumerate() {
                        let found = self.tie_line(
                            &point,
                            (y, blocks, &dets),
                            (a_poly, b_poly),
                            &cancelled,
                            (tie_at, &keepers),
                            &targets,
                        );
                        for t in found {
                            targets.remove(&t);
                        }
                    }
                }
            }
        }
    }

    /// The critical points of `-B/A` along the scale of block `y` at
    /// `point` whose double zero makes a target (read in `f64`), each
    /// solved exactly ([`Self::solve_tie`]); returns the types shown.
    fn tie_line(
        &mut self,
        point: &BTreeMap<String, Rat>,
        scaled: (usize, &[BTreeSet<String>], &[Poly]),
        (a, b): (&Poly, &Poly),
        cancelled: &[Rat],
        tie: (&Tie, &[String]),
        targets: &BTreeSet<FrfType>,
    ) -> Vec<FrfType> {
        let mut shown = Vec::new();
        let divide = |p: &Poly| -> Option<Poly> {
            cancelled.iter().try_fold(p.subs_point(point), |u, l| {
                u.div_exact(&(&Poly::var(OMEGA) - &Poly::constant(l.clone())))
            })
        };
        let (Some(a_at), Some(b_at), Some(den)) = (divide(a), divide(b), divide(&self.den)) else {
            return shown;
        };
        let Some(line) = line_floats(&a_at, &b_at, &den) else {
            return shown;
        };
        let (fa, fb, poles) = (&line.a, &line.b, &line.poles);
        for &x in &line.critical {
            let s = -horner(fb, x) / horner(fa, x);
            if !(s > 0.0 && s.is_finite()) {
                continue;
            }
            let line: Vec<f64> = (0..fa.len().max(fb.len()))
                .map(|k| s * fa.get(k).unwrap_or(&0.0) + fb.get(k).unwrap_or(&0.0))
                .collect();
            // The rest after the double root at `x`.
            let Some(rest) = deflate(&line, x).and_then(|q| deflate(&q, x)) else {
                continue;
            };
            let Some(zeros) = positive_roots(&rest) else {
                continue;
            };
            let degree = line.iter().rposition(|v| *v != 0.0).unwrap_or(0);
            let mut tokens: Vec<(f64, Token)> = zeros
                .iter()
                .map(|&z| (z, Feature::Antiresonance, 1))
                .chain(std::iter::once((x, Feature::Antiresonance, 2)))
                .chain(poles.iter().map(|&p| (p, Feature::Resonance, 1)))
                .map(|(v, feature, multiplicity)| {
                    (
                        v,
                        Token {
                            feature,
                            multiplicity,
                        },
                    )
                })
                .collect();
            tokens.sort_by(|p, q| p.0.total_cmp(&q.0));
            let t = FrfType {
                tokens: tokens.into_iter().map(|k| k.1).collect(),
                nonminimum_phase: zeros.len() + 2 < degree,
            };
            if !targets.contains(&t) || self.shown(&t) {
                continue;
            }
            for digits in [3, 5, 7] {
                let Some(r) = short_rational(x, digits) else {
                    continue;
                };
                self.solve_tie(point, scaled, (a, b), &r, cancelled, tie, targets);
                if self.shown(&t) {
                    shown.push(t);
                    break;
                }
            }
        }
        shown
    }

    /// The double zero posed at `r` along the scale of block `y` (the
    /// numerator `s A + B`): `num(r) = num'(r) = 0` (and the other block's
    /// determinant, of `dets`, at the shared pole, if one is posed, `0`)
    /// solved for `s`, the mass that keeps the shared pole, and one
    /// parameter `q` of the other block over a real number field; where
    /// `q` is in a tied run, the run's first mass follows it (a run's
    /// determinant is linear in each mass, with a constant coefficient for
    /// a one-mass run) so the tie holds.
    #[allow(clippy::too_many_arguments)]
    fn solve_tie(
        &mut self,
        point: &BTreeMap<String, Rat>,
        (y, blocks, dets): (usize, &[BTreeSet<String>], &[Poly]),
        (a, b): (&Poly, &Poly),
        r: &Rat,
        cancelled: &[Rat],
        (tie, keepers): (&Tie, &[String]),
        targets: &BTreeSet<FrfType>,
    ) {
        let (x, runs) = (tie.block, &tie.runs);
        let scaled = &blocks[y];
        let num = &(&Poly::var(SCALE) * a) + b;
        let other = 1 - y;
        let mut vars = vec![SCALE.to_string()];
        let mut equations = vec![num.subs(OMEGA, r), num.derivative(OMEGA).subs(OMEGA, r)];
        if cancelled.len() == 2 {
            let Some(keeper) = keepers.get(other) else {
                return;
            };
            vars.push(keeper.clone());
            equations.push(dets[other].subs(OMEGA, &cancelled[1]));
        }
        let run_masses: Vec<&String> = runs.iter().map(|(_, m)| m).collect();
        let wanted: Vec<FrfType> = targets.iter().cloned().collect();
        for q in blocks[other].iter() {
            let mut free = vars.clone();
            free.push(q.clone());
            if vars.contains(q) || run_masses.contains(&q) {
                continue;
            }
            // The tied runs' masses as polynomials in `q` (in the other
            // block only; a run of the scaled block scales with it).
            let mut follow: BTreeMap<String, Poly> = BTreeMap::new();
            if x == other {
                for (d, m) in runs {
                    let mut rest = point.clone();
                    rest.remove(m);
                    rest.remove(q);
                    let k = d.subs(OMEGA, &cancelled[0]).subs_point(&rest).coeffs_in(m);
                    let Some(lead) = k.get(1).and_then(Poly::as_constant) else {
                        break;
                    };
                    if k.len() != 2 || lead.signum() == 0 {
                        break;
                    }
                    follow.insert(m.clone(), k[0].scale(&-(Rat::ONE / lead)));
                }
                if follow.len() != runs.len() {
                    continue;
                }
            }
            let fixed: BTreeMap<String, Rat> = point
                .iter()
                .filter(|(p, _)| !free.contains(p) && !follow.contains_key(*p))
                .map(|(p, v)| (p.clone(), v.clone()))
                .collect();
            let eqs: Vec<Poly> = equations
                .iter()
                .map(|e| {
                    let e = follow.iter().fold(e.clone(), |e, (m, f)| e.subs_poly(m, f));
                    e.subs_point(&fixed)
                })
                .collect();
            let q = std::slice::from_ref(q);
            for (field, mut at) in algebraic_points_up_to(&eqs, &vars, q, SCALE_FIELD_DEGREE) {
                let Some(s) = at.remove(SCALE) else {
                    continue;
                };
                let mut ok = true;
                for (m, f) in &follow {
                    match field.eval(f, &at) {
                        Ok(v) if field.sign(&v) > 0 => {
                            at.insert(m.clone(), v);
                        }
                        _ => ok = false,
                    }
                }
                if !ok || field.sign(&s) <= 0 {
                    continue;
                }
                let mut rest = fixed.clone();
                for p in scaled {
                    if let Some(v) = rest.remove(p) {
                        at.insert(p.clone(), field.scale(&s, &v));
                    }
                }
                self.record_algebraic(&wanted, &rest, (cancelled, &[(r.clone(), 2)]), field, at);
            }
        }
    }

    /// The parameters of each block of the chain that the gap splits it
    /// into (masses joined by springs), by the masses whose diagonal
    /// entries they appear in.
    fn parameter_blocks(&self) -> Vec<BTreeSet<String>> {
        let (mass, stiff) = (self.model.mass_matrix(), self.model.stiffness_matrix());
        super::pole_signs::chain_blocks(&stiff)
            .iter()
            .map(|b| {
                self.params
                    .iter()
                    .filter(|p| {
                        b.iter()
                            .any(|&i| mass[i][i].has_var(p) || stiff[i][i].has_var(p))
                    })
                    .cloned()
                    .collect()
            })
            .collect()
    }

    /// At the split type's witness `w` with `cancelled` poles: the
    /// cancelled poles (rational, each a common root of the numerator and
    /// the denominator) and the positive zeros of the reduced numerator in
    /// increasing order.
    fn split_zeros(
        &self,
        w: &BTreeMap<String, Rat>,
        cancelled: u32,
    ) -> Option<(Vec<Rat>, Vec<f64>)> {
        let num = self.num.subs_point(w);
        let den = self.den.subs_point(w);
        let common = poly::gcd(&num, &den);
        if cancelled > 1 || common.degree(OMEGA) != cancelled {
            return None;
        }
        let mut shared = Vec::new();
        if cancelled == 1 {
            let c = common.coeffs_in(OMEGA);
            let (a, b) = (c[0].as_constant()?, c[1].as_constant()?);
            let l = -(&a / &b);
            if l.signum() <= 0 {
                return None;
            }
            shared.push(l);
        }
        let reduced = if cancelled == 0 {
            num
        } else {
            num.div_exact(&common)?
        };
        Some((shared, positive_roots(&float_coefficients(&reduced)?)?))
    }
}

/// The choices of the `short` parameters (none, one or two) among `free`
/// outside `vars` that a set is short of, in order.
fn short_choices(free: &[String], vars: &[String], short: usize) -> Vec<Vec<String>> {
    let others: Vec<&String> = free.iter().filter(|p| !vars.contains(p)).collect();
    match short {
        0 => vec![Vec::new()],
        1 => others.iter().map(|x| vec![(*x).clone()]).collect(),
        _ => others
            .iter()
            .enumerate()
            .flat_map(|(i, x)| {
                others[i + 1..]
                    .iter()
                    .map(move |y| vec![(*x).clone(), (*y).clone()])
            })
            .collect(),
    }
}

/// A value of `draw` for every parameter, in order; `None` at the first
/// that has none.
fn random_point(
    params: &[String],
    rng: &mut XorShift,
    draw: impl Fn(&mut XorShift) -> Option<Rat>,
) -> Option<BTreeMap<String, Rat>> {
    params
        .iter()
        .map(|p| Some((p.clone(), draw(rng)?)))
        .collect()
}

/// Each block's scale line: the numerator's coefficients `(A, B)` of
/// `s^1` and `s^0` with the block scaled by `s`.
fn scale_lines(num: &Poly, blocks: &[BTreeSet<String>]) -> Vec<(Poly, Poly)> {
    blocks
        .iter()
        .map(|b| {
            let c = scaled_numerator(num, b).coeffs_in(SCALE);
            let at = |k: usize| c.get(k).cloned().unwrap_or_else(Poly::zero);
            (at(1), at(0))
        })
        .collect()
}

/// A scale line at a point in `f64`: `A` and `B`'s coefficients, the
/// positive poles and the positive critical points of `-B/A` (the roots
/// of `A B' - A' B`).
struct LineFloats {
    a: Vec<f64>,
    b: Vec<f64>,
    poles: Vec<f64>,
    critical: Vec<f64>,
}

/// [`LineFloats`] of `A`, `B` and the denominator, polynomials in `Omega`
/// alone.
fn line_floats(a: &Poly, b: &Poly, den: &Poly) -> Option<LineFloats> {
    let critical = (a * &b.derivative(OMEGA)) - (&a.derivative(OMEGA) * b);
    Some(LineFloats {
        a: float_coefficients(a)?,
        b: float_coefficients(b)?,
        poles: positive_roots(&float_coefficients(den)?)?,
        critical: positive_roots(&float_coefficients(&critical)?).unwrap_or_default(),
    })
}

/// The positive value of the mass `m` at which `d` (linear in it, as a
/// determinant is in each mass) vanishes at `Omega = at`, the other
/// parameters at `point`.
fn solve_mass(d: &Poly, m: &str, point: &BTreeMap<String, Rat>, at: &Rat) -> Option<Rat> {
    let mut rest = point.clone();
    rest.remove(m);
    let k = d.subs(OMEGA, at).subs_point(&rest).coeffs_in(m);
    let (a, b) = (k.first()?.as_constant()?, k.get(1)?.as_constant()?);
    let root = -(&a / &b);
    (k.len() == 2 && root.signum() > 0).then_some(root)
}

/// Two runs at the ends of a block with one mass between them, whose
/// common eigenvalue is a pole of the block that cancels.
struct Tie {
    /// The block's index among the chain's blocks.
    block: usize,
    /// Each run's determinant and the mass solved for the tie.
    runs: Vec<(Poly, String)>,
    /// The mass between the runs.
    middle: String,
}

/// `c` (coefficients lowest first) divided by `Omega - x`, the remainder
/// dropped: the quotient by synthetic division.
fn deflate(c: &[f64], x: f64) -> Option<Vec<f64>> {
    let (&lead, rest) = c.split_last()?;
    let mut out = vec![lead];
    for &v in rest.iter().rev().take(rest.len().saturating_sub(1)) {
        out.push(v + x * out.last().copied().unwrap_or(0.0));
    }
    out.reverse();
    Some(out)
}

/// The coefficients in `Omega` of a polynomial in `Omega` alone, in
/// `f64`, lowest first.
fn float_coefficients(p: &Poly) -> Option<Vec<f64>> {
    p.coeffs_in(OMEGA)
        .iter()
        .map(|c| c.as_constant().map(|c| c.to_f64()))
        .collect()
}

/// The numerator with the parameters of `block` scaled by [`SCALE`] and
/// the power of it common to every term divided out.
fn scaled_numerator(num: &Poly, block: &BTreeSet<String>) -> Poly {
    let s = Poly::var(SCALE);
    let scaled = block
        .iter()
        .fold(num.clone(), |n, p| n.subs_poly(p, &(&Poly::var(p) * &s)));
    let content = scaled.monomial_content();
    let only_scale: Vec<u32> = scaled
        .vars()
        .iter()
        .zip(&content)
        .map(|(v, &e)| if v == SCALE { e } else { 0 })
        .collect();
    scaled.div_monomial(&only_scale)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Model;
    use serde_json::{json, Value};

    fn point(values: &[(&str, &str)]) -> BTreeMap<String, Rat> {
        values
            .iter()
            .map(|(p, v)| (p.to_string(), v.parse().unwrap()))
            .collect()
    }

    /// The verdicts of `model` that `prover` shows among `types`, as the
    /// independent checker reads a table's model (the witnesses' types
    /// derived again from the chain).
    fn checked(model: &Model, prover: &Prover, types: &[FrfType]) -> usize {
        let tf = model.undamped_tf();
        let port = |p: crate::Port| json!([p.plus, p.minus]);
        let verdicts: Vec<Value> = types
            .iter()
            .filter_map(|t| {
                let t_text = t.to_string();
                if let Some(w) = prover.witnesses.get(t) {
                    let w: BTreeMap<&String, String> =
                        w.iter().map(|(p, v)| (p, v.to_string())).collect();
                    return Some(json!({"type": t_text, "status": "possible", "witness": w}));
                }
                let a = prover.algebraic.get(t)?;
                Some(json!({"type": t_text, "status": "possible",
                    "algebraic": serde_json::to_value(a).unwrap()}))
            })
            .collect();
        let id = model.to_string();
        let m = json!({"id": id, "generic_id": id, "masses": model.masses().len(),
            "gap": model.gap(), "actuator": port(model.actuator()),
            "sensor": port(model.sensor()), "numerator": tf.num.to_string(),
            "denominator": tf.den.to_string(), "types": verdicts});
        crate::check::check_analysis(&m).unwrap();
        m["types"].as_array().map_or(0, Vec::len)
    }

    /// N5-g3-a4.1-s5.1 (the grounded m1-m2-m3 driven at m1, the free
    /// m4-m5 driven at m4, both seen against m1) with the free pair's
    /// eigenvalue `c45 (m4 + m5) / (m4 m5) = 321/25` on the chain's second:
    /// from a witness of `AAARRR` (three simple zeros below the first
    /// resonance, that pole cancelled once), scaling m4-m5 merges two of
    /// the zeros over Q (with `c1` and `m1`) and all three over a number
    /// field (one parameter more, short of a linear set). The checker,
    /// which shares no code with the search, reads every point's type.
    #[test]
    fn a_scaled_block_merges_zeros_beside_a_shared_pole() {
        let model = Model::from_id("N5-g3-a4.1-s5.1").unwrap();
        let tf = model.undamped_tf();
        let mut prover = Prover::new(&model, tf.num.clone(), tf.den.clone());
        let parent = point(&[
            ("c1", "12000"),
            ("c12", "90"),
            ("c23", "19/100"),
            ("c45", "38/5"),
            ("m1", "5622250/28141"),
            ("m2", "7"),
            ("m3", "1/50"),
            ("m4", "3400"),
            ("m5", "64600/109121"),
        ]);
        let split: FrfType = "AAARRR".parse().unwrap();
        assert_eq!(prover.type_at(&parent), Some(split.clone()));
        prover.witnesses.insert(split, parent);
        let wanted: Vec<FrfType> = ["AA^2RRR", "A^2ARRR", "A^3RRR"]
            .iter()
            .map(|t| t.parse().unwrap())
            .collect();
        assert_eq!(prover.block_scale_search(&wanted), 3);
        assert!(prover.witnesses.contains_key(&wanted[0]));
        assert!(prover.witnesses.contains_key(&wanted[1]));
        assert!(prover.algebraic.contains_key(&wanted[2]));
        assert_eq!(checked(&model, &prover, &wanted), 3);
    }

    /// N5-g3-a4.3-s5.3 (the same blocks, driven and seen at m3): at a point
    /// where m1-m2-m3 (m2 solved) and m4-m5 share the eigenvalue
    /// `2 c45 / m4`, the zeros along the scale of m4-m5 are where
    /// `Omega (lambda - Omega) T_L(Omega)` meets a level set by the scale;
    /// below the first resonance it rises, falls and rises again, so one
    /// scale between its two critical values shows three zeros there with
    /// the pole cancelled once, which the parameters of either block
    /// alone, drawn at random, almost never show.
    #[test]
    fn the_scale_line_crosses_a_thin_region() {
        let model = Model::from_id("N5-g3-a4.3-s5.3").unwrap();
        let tf = model.undamped_tf();
        let mut prover = Prover::new(&model, tf.num.clone(), tf.den.clone());
        let at = point(&[
            ("c1", "5701"),
            ("c12", "1046/25"),
            ("c23", "427/2000"),
            ("c45", "3881169/20000000"),
            ("m1", "1246/25"),
            ("m2", "118012820405114363/465267782220253200"),
            ("m3", "1269/5000000"),
            ("m4", "4637/2000000"),
            ("m5", "4637/2000000"),
        ]);
        let lambda = &(&at["c45"] * &Rat::from(2)) / &at["m4"];
        let blocks = prover.parameter_blocks();
        let free_pair = &blocks[1];
        assert!(free_pair.contains("m5") && free_pair.len() == 3);
        let c = scaled_numerator(&prover.num, free_pair).coeffs_in(SCALE);
        let wanted: FrfType = "AAARRR".parse().unwrap();
        let features: Vec<Feature> = wanted.tokens.iter().map(|k| k.feature).collect();
        let targets = BTreeSet::from([(1, features)]);
        let shown = prover.sweep_line(&at, free_pair, (&c[1], &c[0]), Some(&lambda), &targets);
        assert_eq!(shown, vec![wanted.clone()]);
        assert_eq!(checked(&model, &prover, &[wanted]), 1);
    }

    /// N5-g3-a4.2-s5.2 (the grounded m1-m2-m3 and the free m4-m5, driven
    /// between m4 and m2 and seen between m5 and m2): `RRA^2` needs two
    /// poles cancelled and a double zero above both resonances. With m1's
    /// and m3's own eigenvalues equal, the chain's middle pole is theirs
    /// and cancels; the free pair's eigenvalue on the chain's lowest
    /// cancels once more; along the pair's scale the double zero is a
    /// critical point of `-B/A`. Two physical facts of the witness are
    /// checked by hand, apart from the search: the runs' eigenvalues
    /// `(c1 + c12)/m1` and `c23/m3` agree, and the pair's `c45 (m4 + m5) /
    /// (m4 m5)` is a root of the chain's determinant; the checker reads
    /// the type.
    #[test]
    fn a_double_zero_beside_a_pole_the_end_runs_cancel() {
        let model = Model::from_id("N5-g3-a4.2-s5.2").unwrap();
        let tf = model.undamped_tf();
        let mut prover = Prover::new(&model, tf.num.clone(), tf.den.clone());
        let wanted: FrfType = "RRA^2".parse().unwrap();
        assert_eq!(prover.block_scale_search(std::slice::from_ref(&wanted)), 1);
        assert_eq!(checked(&model, &prover, std::slice::from_ref(&wanted)), 1);
        let w = &prover.witnesses[&wanted];
        assert_eq!(&(&w["c1"] + &w["c12"]) / &w["m1"], &w["c23"] / &w["m3"]);
        let pair = &(&w["c45"] * &(&w["m4"] + &w["m5"])) / &(&w["m4"] * &w["m5"]);
        // det(K - l M) of m1-m2-m3, expanded along the first row.
        let d = |i: &str, k: &Rat| &w[i] * k;
        let (k11, k22, k33) = (
            &(&w["c1"] + &w["c12"]) - &d("m1", &pair),
            &(&w["c12"] + &w["c23"]) - &d("m2", &pair),
            &w["c23"] - &d("m3", &pair),
        );
        let minor = &(&k22 * &k33) - &(&w["c23"] * &w["c23"]);
        let det = &(&k11 * &minor) - &(&(&w["c12"] * &w["c12"]) * &k33);
        assert_eq!(det, Rat::ZERO);
    }

    /// Synthetic division against a product expanded by hand: `(x - 2)(x^2
    /// + 3x - 1) = x^3 + x^2 - 7x + 2`.
    #[test]
    fn deflation_divides_out_a_root() {
        let q = deflate(&[2.0, -7.0, 1.0, 1.0], 2.0).unwrap();
        assert_eq!(q, vec![-1.0, 3.0, 1.0]);
    }
}
