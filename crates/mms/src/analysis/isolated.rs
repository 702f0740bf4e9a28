//! Witnesses isolated in a box.
//!
//! A type with root coincidences (cancelled poles, multiple zeros) lives on
//! a variety. Where no jointly linear set of parameters poses its
//! conditions, its points are seldom rational, and eliminating down to one
//! unknown (as the number-field witnesses do) meets degrees too high to
//! handle. So the point is not computed but enclosed: the posed roots
//! (`rho` for each cancelled pole, `sigma` of multiplicity `mu` for each
//! multiple zero) and all but as many parameters as there are conditions
//! are fixed at short rationals; the conditions
//!
//! ```text
//! N(rho) = D(rho) = 0,   N^(k)(sigma) = 0 for k < mu
//! ```
//!
//! are then a square polynomial system in the free parameters, and a box
//! around an approximate solution holds exactly one solution if Krawczyk's
//! operator maps the box into its interior:
//!
//! ```text
//! K(X) = c - Y F(c) + (I - Y J(X)) (X - c)  ⊂  int X
//! ```
//!
//! (`c` the box's centre, `Y` any matrix, here a rounded inverse of the
//! Jacobian at `c`, `J(X)` an enclosure of the Jacobian over the box). At
//! that solution `N = (Omega - rho) prod (Omega - sigma)^mu Q` and
//! `D = (Omega - rho) R` exactly, so the type is read from `Q` and `R`,
//! whose coefficients are polynomials in the free parameters, enclosed
//! over the box: a partition of `(0, inf)` at rational points where
//! neither vanishes, each piece holding at most one root of each by
//! Descartes' rule (its sign variations under the Moebius map of the piece
//! to `(0, inf)`, the same for every point of the box), every root of `R`
//! and each `sigma` placed. Every step is exact rational interval
//! arithmetic ([`poly::RatInterval`]), so the reading holds at the one
//! solution in the box, whichever it is: that point is the witness.
//!
//! The approximate points come from the variety sampler
//! ([`super::variety`]): a sampled point whose `f64` reading is a wanted
//! type chooses the free parameters (the best conditioned columns of the
//! conditions' Jacobian), is moved onto the system with the others
//! rounded by Newton's iteration in exact arithmetic, and is kept only if
//! the box's reading is that type.
//!
//! Where `N` and `D` meet tangentially, `N(rho) = D(rho) = 0` has a
//! singular Jacobian and Newton's iteration only halves its error; such a
//! pole is posed instead by two factors that both vanish there, with
//! cofactors showing that `N` and `D` are combinations of them
//! ([`PolePose`]): the blocks' determinants where the chain's gap splits
//! it and the blocks share an eigenvalue (once, or as a pair cancelled
//! together, then with `N'(rho) = 0` too), or the determinants of the
//! runs beside a node of a mode inside a block. At such a pole the
//! sampler's own Jacobian (in `N` and `D`) may drop rank too: those
//! points are tried last, with the free parameters chosen by the posed
//! conditions' Jacobian.

use super::frf_type::{Feature, FrfType, Token};
use super::pole_signs::{block_ranges, run_det};
use super::prover::Prover;
use super::targeted::{nelder_mead_for, positive_roots, short_rational};
use super::variety::{independent_columns, BlockFactors, Variety, VarietyPoint};
use super::{IsolatedWitness, PolePose};
use crate::model::Model;
use crate::tf::{UndampedCoefficients, OMEGA};
use crate::xorshift::XorShift;
use poly::{Poly, Rat, RatInterval};
use std::collections::BTreeMap;

/// Starts of the variety sampler per coincidence structure, at most; it
/// stops after `PATIENCE` starts in a row that show no new type.
const STARTS: usize = 4000;
const PATIENCE: usize = 1000;
/// The sampler's start box, as `mms sample`'s.
const RANGE: f64 = super::SAMPLING_RANGE;
/// Sampled points per type that are tried.
const POINTS: usize = 12;
/// Starts per structure with a type still without a witness, drawn after
/// the rest without patience, and what their seeds differ by.
const PERSISTENT_STARTS: usize = 10_000;
const PERSISTENT_SEED: u64 = 0x5BD1_E995_0000_0001;
/// Projected draws per structure for the descents, descents per type
/// (from the draws nearest to it), Nelder-Mead's evaluations per descent
/// and first step (in logarithms), the score of a point that fits no
/// reading, and what the descents' seeds differ by.
const DESCENT_DRAWS: usize = 4000;
const DESCENTS: usize = 48;
const DESCENT_EVALUATIONS: usize = 600;
const DESCENT_STEP: f64 = 0.3;
const UNFIT: f64 = 1e6;
const DESCENT_SEED: u64 = 0xD35C_E4D0_0000_0001;
/// The moves of [`Prover::split_boxes`] (relative size, significant
/// digits of the moved parameters), points per box and size, and what
/// its seed differs by.
const SPLIT_MOVES: [(f64, i32); 3] = [(1e-3, 9), (1e-5, 11), (1e-7, 13)];
const SPLIT_POINTS: usize = 8;
const SPLIT_SEED: u64 = 0x5B11_7000_0000_0001;
/// Significant digits of the fixed parameters and the posed roots.
const DIGITS: i32 = 6;
/// Bits kept of the coordinates after each Newton step.
const NEWTON_BITS: u32 = 160;
/// Newton steps at most; they stop once a step is below
/// `2^-STEP_BITS` of the coordinates.
const NEWTON_STEPS: usize = 8;
const STEP_BITS: i32 = 120;
/// Bits of the box's centre, and its half-width relative to each
/// coordinate, `2^-RADIUS_BITS`: the centre's rounding is far inside.
const CENTRE_BITS: u32 = 96;
const RADIUS_BITS: i32 = 64;
/// Bits of the entries of Krawczyk's preconditioner.
const PRECONDITIONER_BITS: u32 = 64;
/// Pieces of the partition split at most, one at a time, before a reading
/// is given up.
const SPLITS: usize = 48;
/// A cancelled pole is taken for the blocks' shared eigenvalue where both
/// blocks' determinants are below this there, relative to their terms.
const SHARED: f64 = 1e-4;
/// The farthest a solution may move from its sampled point (relative).
const DRIFT: f64 = 1e-2;

/// Why a box's reading failed.
#[derive(Debug, PartialEq, Eq)]
pub(super) enum Unread {
    /// Piece `i` of the partition (`(t_i, t_{i+1})`, `t_0 = 0`) has more
    /// than one sign variation or an unsettled sign: a finer partition
    /// may settle it.
    Piece(usize),
    /// Anything else: no point of this box is a witness as posed.
    Refused,
}

impl Prover<'_> {
    /// Witnesses isolated in a box (see the module docs) for the types of
    /// `wanted` with root coincidences that are still without a witness,
    /// from points sampled on each coincidence structure's variety.
    /// Returns how many of `wanted` are shown afterwards.
    pub(crate) fn isolated_search(&mut self, wanted: &[FrfType], seed: u64) -> usize {
        let (signatures, derivatives) = self.pencil_signatures(wanted);
        let tf = UndampedCoefficients::new(self.model);
        let blocks = block_pose(self.model, &self.num, &self.den);
        let nodes = node_poses(self.model, &self.num, &self.den);
        let compiled = blocks
            .as_ref()
            .map(|b| BlockFactors::new(&b.factors, &self.params));
        // Each structure with its poles cancelled once, then (with a gap)
        // with one pair, two pairs, ... cancelled where the blocks share
        // an eigenvalue: where the single ones meet, the sampler lands on
        // those pairs, a stratum of its own. The single structures come
        // first and share one stream of draws; each paired one draws from
        // its own seed, so the pairs only add to what the singles show.
        let pairs = |c: u32| {
            if compiled.is_some() {
                c as usize / 2
            } else {
                0
            }
        };
        let singles = signatures
            .iter()
            .map(|((c, mults), types)| (*c as usize, 0, mults, types));
        let paired = signatures.iter().flat_map(|((c, mults), types)| {
            (1..=pairs(*c)).map(move |d| (*c as usize, d, mults, types))
        });
        let poses = (blocks.as_ref(), nodes.as_slice());
        let key = |cancelled: usize, doubles: usize, mults: &[u32]| {
            mults
                .iter()
                .fold((cancelled as u64) << 8 | doubles as u64, |h, &m| {
                    (h ^ u64::from(m)).wrapping_mul(0x0100_0000_01b3)
                })
                .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        };
        let structures: Vec<_> = singles.chain(paired).collect();
        let n_params = self.params.len();
        let mut shared = XorShift::new(seed);
        let mut singular = Vec::new();
        for &(cancelled, doubles, mults, types) in &structures {
            let variety = structure_variety(&tf, n_params, (cancelled, doubles, mults), &compiled);
            let mut own = XorShift::new(seed ^ key(cancelled, doubles, mults));
            let rng = if doubles > 0 { &mut own } else { &mut shared };
            self.draw(
                &variety,
                rng,
                types,
                (STARTS, PATIENCE),
                (&derivatives, poses),
                &mut singular,
            );
        }
        // Types whose points are rare (one start in a thousand or fewer)
        // are passed by the patience above: every structure with a type
        // still without a witness is drawn on once more, without it and
        // from a seed of its own, after all the rest, which keeps the
        // earlier draws.
        for &(cancelled, doubles, mults, types) in &structures {
            if types.iter().all(|t| self.shown(t)) {
                continue;
            }
            let variety = structure_variety(&tf, n_params, (cancelled, doubles, mults), &compiled);
            let mut rng = XorShift::new(seed ^ key(cancelled, doubles, mults) ^ PERSISTENT_SEED);
            self.draw(
                &variety,
                &mut rng,
                types,
                (PERSISTENT_STARTS, PERSISTENT_STARTS),
                (&derivatives, poses),
                &mut singular,
            );
        }
        // Last, the points passed over above where the variety's Jacobian
        // dropped rank, with the free parameters chosen by the posed
        // conditions: a pole where the blocks share an eigenvalue is such
        // a point, and only its pose has full rank.
        for (t, p) in &singular {
            if self.shown(t) {
                continue;
            }
            if let Some(w) = self.isolate(p, None, (&derivatives, poses), t) {
                self.isolated.insert(t.clone(), w);
            }
        }
        // Last of all, a descent on the variety toward each type that no
        // draw showed: types rarer than one start in ten thousand, but
        // next to points the draws do reach.
        for &(cancelled, doubles, mults, types) in &structures {
            if types.iter().all(|t| self.shown(t)) {
                continue;
            }
            let variety = structure_variety(&tf, n_params, (cancelled, doubles, mults), &compiled);
            let mut rng = XorShift::new(seed ^ key(cancelled, doubles, mults) ^ DESCENT_SEED);
            self.descend(&variety, &mut rng, types, (&derivatives, poses));
        }
        self.split_boxes(wanted, seed ^ SPLIT_SEED);
        wanted.iter().filter(|t| self.shown(t)).count()
    }

    /// Rational points next to every box witness, each parameter moved by
    /// a relative `SPLIT_MOVES` at most: off the box's variety its
    /// multiple zeros split (two real zeros on one side of the
    /// discriminant, a complex pair on the other) and its cancelled poles
    /// part, the other roots keep their order, so a generic type next to a
    /// box shows there, however thin its region elsewhere. Each point's
    /// type is read exactly; one of `wanted` still without a witness
    /// keeps it.
    fn split_boxes(&mut self, wanted: &[FrfType], seed: u64) {
        let mut rng = XorShift::new(seed);
        let boxes: Vec<IsolatedWitness> = self.isolated.values().cloned().collect();
        for w in &boxes {
            let centre: BTreeMap<String, f64> = w
                .fixed
                .iter()
                .map(|(k, v)| (k.clone(), v.to_f64()))
                .chain(
                    w.free
                        .iter()
                        .map(|(k, [lo, hi])| (k.clone(), (lo.to_f64() + hi.to_f64()) / 2.0)),
                )
                .collect();
            for &(size, digits) in &SPLIT_MOVES {
                for _ in 0..SPLIT_POINTS {
                    if wanted.iter().all(|t| self.shown(t)) {
                        return;
                    }
                    let point: Option<BTreeMap<String, Rat>> = centre
                        .iter()
                        .map(|(k, v)| {
                            let moved = v * (1.0 + size * (2.0 * rng.uniform() - 1.0));
                            Some((k.clone(), short_rational(moved, digits)?))
                        })
                        .collect();
                    let Some(point) = point else {
                        continue;
                    };
                    if let Some(t) = self.type_at(&point) {
                        if wanted.contains(&t) && !self.shown(&t) {
                            self.witnesses.insert(t, point);
                        }
                    }
                }
            }
        }
    }

    /// For each type of `types` still without a witness: Nelder-Mead in
    /// the unknowns' logarithms, each point projected onto `variety` and
    /// scored by how far it is from reading the type
    /// ([`Variety::violation`]), from the `DESCENTS` best of
    /// `DESCENT_DRAWS` projected draws; where a descent ends at a point
    /// that reads the type, a box is isolated next to it as for a draw.
    fn descend(
        &mut self,
        variety: &Variety,
        rng: &mut XorShift,
        types: &[FrfType],
        context: (&[Poly], (Option<&PolePose>, &[PolePose])),
    ) {
        let mut draws: Vec<Vec<f64>> = Vec::new();
        for _ in 0..DESCENT_DRAWS {
            let Some(mut x) = variety.start(rng, RANGE) else {
                continue;
            };
            if variety.project(&mut x, RANGE) {
                draws.push(x);
            }
        }
        for t in types {
            if self.shown(t) {
                continue;
            }
            let mut near = Vec::new();
            let mut scored: Vec<(f64, usize)> = draws
                .iter()
                .enumerate()
                .filter_map(|(i, x)| Some((variety.violation(&variety.point(x), t, &mut near)?, i)))
                .collect();
            scored.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            for &(_, i) in scored.iter().take(DESCENTS) {
                let mut cost = |x: &[f64]| -> f64 {
                    let mut y = x.to_vec();
                    if !variety.project(&mut y, RANGE) {
                        return UNFIT;
                    }
                    variety
                        .violation(&variety.point(&y), t, &mut near)
                        .unwrap_or(UNFIT)
                };
                let mut y = nelder_mead_for(
                    &mut cost,
                    &draws[i],
                    DESCENT_STEP,
                    f64::MIN_POSITIVE,
                    DESCENT_EVALUATIONS,
                );
                if !variety.project(&mut y, RANGE) {
                    continue;
                }
                let p = variety.point(&y);
                if variety.read(&p).as_ref() != Some(t) {
                    continue;
                }
                let chosen = variety.free_parameters(&y);
                if let Some(w) = self.isolate(&p, chosen.as_deref(), context, t) {
                    self.isolated.insert(t.clone(), w);
                    break;
                }
            }
        }
    }

    /// Draws up to `starts` points of `variety` (stopping after `patience`
    /// in a row that show no new type, or once every type of `types` is
    /// shown) and isolates a witness next to those that read a type of
    /// `types` still without one; those where the variety's Jacobian drops
    /// rank go to `singular` instead, up to `POINTS` per type and draw.
    fn draw(
        &mut self,
        variety: &Variety,
        rng: &mut XorShift,
        types: &[FrfType],
        (starts, patience): (usize, usize),
        context: (&[Poly], (Option<&PolePose>, &[PolePose])),
        singular: &mut Vec<(FrfType, VarietyPoint)>,
    ) {
        let mut tries: BTreeMap<FrfType, usize> = BTreeMap::new();
        let mut kept: BTreeMap<FrfType, usize> = BTreeMap::new();
        let mut barren = 0;
        for _ in 0..starts {
            if types.iter().all(|t| self.shown(t)) || barren >= patience {
                break;
            }
            barren += 1;
            let Some(mut x) = variety.start(rng, RANGE) else {
                continue;
            };
            if !variety.project(&mut x, RANGE) {
                continue;
            }
            let p = variety.point(&x);
            let Some(t) = variety.read(&p) else {
                continue;
            };
            if !types.contains(&t) || self.shown(&t) {
                continue;
            }
            // A point where the conditions' Jacobian drops rank lies on a
            // thinner stratum (two posed roots about to meet), or where a
            // pole is cancelled tangentially: it is kept for a last pass
            // (see `isolated_search`) without spending the type's tries.
            let Some(chosen) = variety.free_parameters(&x) else {
                // Counted per draw, so that the first structures' points
                // do not crowd out those of the pairs and the rare ones.
                let kept = kept.entry(t.clone()).or_default();
                if *kept < POINTS {
                    *kept += 1;
                    singular.push((t, p));
                }
                continue;
            };
            let n = tries.entry(t.clone()).or_default();
            if *n >= POINTS {
                continue;
            }
            *n += 1;
            if let Some(w) = self.isolate(&p, Some(&chosen), context, &t) {
                self.isolated.insert(t, w);
                barren = 0;
            }
        }
    }

    /// An isolated witness of `t` next to the sampled point `p`, with the
    /// parameters of index `chosen` free; `None` where none is found
    /// there.
    fn isolate(
        &self,
        p: &VarietyPoint,
        chosen: Option<&[usize]>,
        (derivatives, (blocks, nodes)): (&[Poly], (Option<&PolePose>, &[PolePose])),
        t: &FrfType,
    ) -> Option<IsolatedWitness> {
        // The poles cancelled once, then those cancelled in pairs.
        let cancelled: Vec<Rat> = p
            .cancelled
            .iter()
            .chain(&p.doubles)
            .map(|&r| short_rational(r, DIGITS))
            .collect::<Option<_>>()?;
        let multiple: Vec<(Rat, u32)> = p
            .multiple
            .iter()
            .map(|&(s, mu)| Some((short_rational(s, DIGITS)?, mu)))
            .collect::<Option<_>>()?;
        // A pole cancelled where the blocks share an eigenvalue: the
        // numerator and the denominator meet tangentially there, so it is
        // posed by the blocks' determinants.
        let sampled: BTreeMap<String, f64> = self
            .params
            .iter()
            .cloned()
            .zip(p.params.iter().copied())
            .collect();
        let vanish = |q: &PolePose, rho: f64| {
            q.factors
                .iter()
                .all(|f| relative_at(f, &sampled, rho).is_some_and(|v| v.abs() < SHARED))
        };
        let mut poses: Vec<PolePose> = Vec::new();
        // Likewise at a node of a mode inside a block, where both runs
        // beside the node vanish.
        for (i, &rho) in p.cancelled.iter().enumerate() {
            if let Some(q) = blocks.into_iter().chain(nodes).find(|q| vanish(q, rho)) {
                poses.push(PolePose {
                    pole: i,
                    ..q.clone()
                });
            }
        }
        if let Some(b) = blocks {
            for i in 0..p.doubles.len() {
                poses.push(PolePose {
                    pole: p.cancelled.len() + i,
                    double: true,
                    ..b.clone()
                });
            }
        } else if !p.doubles.is_empty() {
            return None;
        }
        // The numerator's slope, where a pole is cancelled twice.
        let slope = poses
            .iter()
            .any(|q| q.double)
            .then(|| self.num.derivative(OMEGA));
        let mut conditions = Vec::new();
        for (i, rho) in cancelled.iter().enumerate() {
            match poses.iter().find(|q| q.pole == i) {
                Some(q) => {
                    conditions.extend(q.factors.iter().map(|f| f.subs(OMEGA, rho)));
                    if let (true, Some(slope)) = (q.double, &slope) {
                        conditions.push(slope.subs(OMEGA, rho));
                    }
                }
                None => conditions.extend([self.num.subs(OMEGA, rho), self.den.subs(OMEGA, rho)]),
            }
        }
        for (sigma, mu) in &multiple {
            conditions.extend(
                derivatives[..*mu as usize]
                    .iter()
                    .map(|d| d.subs(OMEGA, sigma)),
            );
        }
        // Where the variety's own Jacobian dropped rank (a pole posed by
        // the blocks is a tangential cancellation, so the numerator's and
        // the denominator's conditions lose a rank there), the free
        // parameters are chosen by the posed conditions' Jacobian.
        let chosen = match chosen {
            Some(c) => c.to_vec(),
            None => posed_free_parameters(&conditions, &self.params, &p.params)?,
        };
        let mut fixed = BTreeMap::new();
        let mut free = Vec::new();
        let mut start = Vec::new();
        for (i, (name, &v)) in self.params.iter().zip(&p.params).enumerate() {
            if chosen.contains(&i) {
                free.push(name.clone());
                start.push(Rat::from_f64(v)?.round_to_bits(53));
            } else {
                fixed.insert(name.clone(), short_rational(v, DIGITS)?);
            }
        }
        let conditions: Vec<Poly> = conditions.iter().map(|e| e.subs_point(&fixed)).collect();
        let system = System::new(conditions, free.clone());
        let centre = system.newton(start.clone())?;
        let near = centre.iter().zip(&start).all(|(c, s)| {
            let (c, s) = (c.to_f64(), s.to_f64());
            c > 0.0 && ((c - s) / s).abs() < DRIFT
        });
        if !near {
            return None;
        }
        let centre: Vec<Rat> = centre
            .iter()
            .map(|c| c.round_to_bits(CENTRE_BITS))
            .collect();
        let ranges: Vec<RatInterval> = centre.iter().map(|c| around(c, RADIUS_BITS)).collect();
        if !system.krawczyk_holds(&centre, &ranges) {
            return None;
        }
        let mut w = IsolatedWitness {
            fixed,
            free: free
                .iter()
                .zip(&ranges)
                .map(|(n, r)| (n.clone(), [r.lo().clone(), r.hi().clone()]))
                .collect(),
            cancelled,
            multiple,
            poses,
            partition: Vec::new(),
        };
        let rests = Rests::new(&self.num, &self.den, &w)?;
        w.partition = rests.first_partition(&centre_point(&free, &centre), &w.multiple)?;
        for _ in 0..=SPLITS {
            match rests.read(&w.partition, &w.multiple) {
                Ok(found) => return (found == *t).then_some(w),
                Err(Unread::Piece(i)) => split(&mut w.partition, i),
                Err(Unread::Refused) => return None,
            }
        }
        None
    }
}

/// The value of `f` at the parameters `point` and `Omega = omega`, over
/// the sum of its terms' moduli there.
fn relative_at(f: &Poly, point: &BTreeMap<String, f64>, omega: f64) -> Option<f64> {
    let (value, scale) = value_and_scale(f, point, omega)?;
    (scale > 0.0 && value.is_finite()).then(|| value / scale)
}

/// As many of the parameters as there are `conditions` (polynomials in
/// the parameters alone), in whose logarithms the conditions' Jacobian at
/// `values` is best conditioned, each row relative to the sum of its
/// condition's terms' moduli; `None` where it drops rank there too.
fn posed_free_parameters(
    conditions: &[Poly],
    names: &[String],
    values: &[f64],
) -> Option<Vec<usize>> {
    let point: BTreeMap<String, f64> = names.iter().cloned().zip(values.iter().copied()).collect();
    let rows: Vec<Vec<f64>> = conditions
        .iter()
        .map(|c| {
            // The conditions are free of `Omega`: the posed roots are in.
            let (_, scale) = value_and_scale(c, &point, 0.0)?;
            if !(scale > 0.0 && scale.is_finite()) {
                return None;
            }
            names
                .iter()
                .zip(values)
                .map(|(n, &v)| {
                    let (slope, _) = value_and_scale(&c.derivative(n), &point, 0.0)?;
                    slope.is_finite().then_some(slope * v / scale)
                })
                .collect()
        })
        .collect::<Option<_>>()?;
    independent_columns(&rows, conditions.len())
}

/// The value of `f` at the parameters `point` and `Omega = omega`, and
/// the sum of its terms' moduli there (`0` for the zero polynomial).
fn value_and_scale(f: &Poly, point: &BTreeMap<String, f64>, omega: f64) -> Option<(f64, f64)> {
    let x: Vec<f64> = f
        .vars()
        .iter()
        .map(|v| {
            if v == OMEGA {
                Some(omega)
            } else {
                point.get(v).copied()
            }
        })
        .collect::<Option<_>>()?;
    let (mut value, mut scale) = (0.0, 0.0);
    for t in f.terms() {
        let term = t
            .exps
            .iter()
            .zip(&x)
            .fold(t.coef.to_f64(), |acc, (&e, v)| acc * v.powi(e as i32));
        value += term;
        scale += term.abs();
    }
    Some((value, scale))
}

/// The variety of a structure: `cancelled` poles (of which `doubles`
/// pairs are cancelled together, by the `blocks`) and zeros of the
/// multiplicities `mults`.
fn structure_variety<'a>(
    tf: &'a UndampedCoefficients,
    params: usize,
    (cancelled, doubles, mults): (usize, usize, &'a [u32]),
    blocks: &'a Option<BlockFactors>,
) -> Variety<'a> {
    let variety = Variety::new(tf, params, cancelled, mults);
    match blocks {
        Some(b) if doubles > 0 => variety.with_doubles(doubles, b),
        _ => variety,
    }
}

/// The cancellations at a node of a mode: inside a block, where the runs
/// on the two sides of one mass share an eigenvalue, that mass stands
/// still in the mode (the two runs' springs pull on it in balance); where
/// the ports do not both see the mode (one of them meets the block only
/// at that mass), the numerator and the denominator vanish with both
/// runs' determinants. Which pairs do is decided exactly: posed by the two
/// determinants, the cofactors from dividing by each in a variable it
/// holds linearly with a constant coefficient and the other lacks (a
/// Gröbner basis, so a remainder means the pair does not pose the pole);
/// runs of one mass have one (the spring to the far side), longer runs
/// none, and are not posed.
fn node_poses(model: &Model, num: &Poly, den: &Poly) -> Vec<PolePose> {
    let (mass, stiff) = (model.mass_matrix(), model.stiffness_matrix());
    let mut poses = Vec::new();
    for (lo, hi) in block_ranges(&stiff) {
        for node in lo + 1..hi.saturating_sub(1) {
            let f0 = run_det(&mass, &stiff, lo, node);
            let f1 = run_det(&mass, &stiff, node + 1, hi);
            let (Some(v0), Some(v1)) = (lead_variable(&f0, &f1), lead_variable(&f1, &f0)) else {
                continue;
            };
            let cofactors = |x: &Poly| -> Option<[Poly; 2]> {
                let (q0, r0) = x.div_rem_linear(&v0, &f0)?;
                let (q1, r1) = r0.div_rem_linear(&v1, &f1)?;
                r1.is_zero().then_some([q0, q1])
            };
            if let (Some(n), Some(d)) = (cofactors(num), cofactors(den)) {
                poses.push(PolePose {
                    pole: 0,
                    double: false,
                    factors: [f0, f1],
                    numerator: n,
                    denominator: d,
                });
            }
        }
    }
    poses
}

/// A variable of `f` of degree one with a constant coefficient, absent
/// from `other`.
fn lead_variable(f: &Poly, other: &Poly) -> Option<String> {
    f.vars()
        .iter()
        .find(|v| {
            *v != OMEGA
                && !other.has_var(v)
                && matches!(f.coeffs_in(v).as_slice(), [_, a] if a.is_constant())
        })
        .cloned()
}

/// The cancellations by the blocks' shared eigenvalue, for a chain whose
/// gap splits it into a grounded block `A` (masses `1..=g`) and a free
/// block `B`: `K - Omega M` is block diagonal, so the receptance's
/// numerator is `p = n_A det(B) + n_B det(A)` (`n_X` the block's own
/// `c^T adj(X) b`), and with `det(B) = Omega q_B` the normalised
/// `num = -k p`, `den = k q` give `num = (-k n_B) det(A) + (-k Omega n_A)
/// q_B` and `den = (k q_B) det(A)`. The pose's `pole` is left at 0;
/// `None` without a gap, or if the identities do not come out.
pub(super) fn block_pose(model: &Model, num: &Poly, den: &Poly) -> Option<PolePose> {
    let g = model.gap();
    let n = model.n_masses();
    if g == 0 || g >= n {
        return None;
    }
    let omega = Poly::var(OMEGA);
    let (mass, stiff) = (model.mass_matrix(), model.stiffness_matrix());
    let (input, output) = (model.input_vector(), model.output_vector());
    let block = |lo: usize, hi: usize| -> (Poly, Poly) {
        let m: Vec<Vec<Poly>> = (lo..hi)
            .map(|i| {
                (lo..hi)
                    .map(|j| &stiff[i][j] - &(&omega * &mass[i][j]))
                    .collect()
            })
            .collect();
        let adj = poly::adjugate(&m);
        let mut own = Poly::zero();
        for (i, row) in adj.iter().enumerate() {
            for (j, a) in row.iter().enumerate() {
                let w = output[lo + i] * input[lo + j];
                if w != 0 {
                    own = &own + &a.scale(&Rat::from(w));
                }
            }
        }
        (poly::det(&m), own)
    };
    let (det_a, n_a) = block(0, g);
    let (det_b, n_b) = block(g, n);
    let q_b = det_b.div_exact(&omega)?;
    let p = &(&n_a * &det_b) + &(&n_b * &det_a);
    let k = &num.leading_coef() / &(-&p).leading_coef();
    let k_neg = -&k;
    if (-&p).scale(&k) != *num || (&det_a * &q_b).scale(&k) != *den {
        return None;
    }
    Some(PolePose {
        pole: 0,
        double: false,
        numerator: [n_b.scale(&k_neg), (&omega * &n_a).scale(&k_neg)],
        denominator: [q_b.scale(&k), Poly::zero()],
        factors: [det_a, q_b],
    })
}

/// `c` with each coordinate as a map from the free parameters' names.
fn centre_point(free: &[String], centre: &[Rat]) -> BTreeMap<String, Rat> {
    free.iter().cloned().zip(centre.iter().cloned()).collect()
}

/// `[c - |c| 2^-bits, c + |c| 2^-bits]`.
fn around(c: &Rat, bits: i32) -> RatInterval {
    let r = &c.abs() * &Rat::from(2).pow(-bits);
    RatInterval::around(c, &r).expect("a radius is not negative")
}

/// Inserts a point into piece `i` of `partition` (`(t_i, t_{i+1})`,
/// `t_0 = 0`, the last piece unbounded): its middle, half the first end,
/// twice the last.
fn split(partition: &mut Vec<Rat>, i: usize) {
    let point = match (i.checked_sub(1).map(|k| &partition[k]), partition.get(i)) {
        (Some(a), Some(b)) => &(a + b) / &Rat::from(2),
        (None, Some(b)) => b / &Rat::from(2),
        (Some(a), None) => a * &Rat::from(2),
        (None, None) => Rat::ONE,
    };
    partition.insert(i, point);
}

/// The posed conditions as a square system in the free parameters.
struct System {
    conditions: Vec<Poly>,
    jacobian: Vec<Vec<Poly>>,
    free: Vec<String>,
}

impl System {
    fn new(conditions: Vec<Poly>, free: Vec<String>) -> System {
        let jacobian = conditions
            .iter()
            .map(|c| free.iter().map(|v| c.derivative(v)).collect())
            .collect();
        System {
            conditions,
            jacobian,
            free,
        }
    }

    fn values(&self, x: &[Rat]) -> Option<(Vec<Rat>, Vec<Vec<Rat>>)> {
        let at = centre_point(&self.free, x);
        let f = self
            .conditions
            .iter()
            .map(|c| c.eval(&at).ok())
            .collect::<Option<Vec<Rat>>>()?;
        let j = self
            .jacobian
            .iter()
            .map(|row| row.iter().map(|d| d.eval(&at).ok()).collect())
            .collect::<Option<Vec<Vec<Rat>>>>()?;
        Some((f, j))
    }

    /// Newton's iteration in exact arithmetic from `x`, each iterate
    /// rounded to [`NEWTON_BITS`] bits; `None` if the system is not square,
    /// its Jacobian singular, or the steps do not shrink below
    /// `2^-STEP_BITS` of the coordinates.
    fn newton(&self, mut x: Vec<Rat>) -> Option<Vec<Rat>> {
        if self.conditions.len() != self.free.len() || x.len() != self.free.len() {
            return None;
        }
        let tiny = Rat::from(2).pow(-STEP_BITS);
        for _ in 0..NEWTON_STEPS {
            let (f, j) = self.values(&x)?;
            let step = poly::solve_rat(&j, &f)?;

            let small = step
                .iter()
                .zip(&x)
                .all(|(s, v)| s.abs() <= &tiny * &v.abs());
            x = x
                .iter()
                .zip(&step)
                .map(|(v, s)| (v - s).round_to_bits(NEWTON_BITS))
                .collect();
            if small {
                return Some(x);
            }
        }
        None
    }

    /// Krawczyk's test: the box `ranges` (around `centre`, in the
    /// positive orthant) holds exactly one solution if
    /// `c - Y F(c) + (I - Y J(X)) (X - c)` lies in its interior.
    fn krawczyk_holds(&self, centre: &[Rat], ranges: &[RatInterval]) -> bool {
        if ranges.iter().any(|r| r.lo().signum() <= 0) {
            return false;
        }
        let Some((f, j)) = self.values(centre) else {
            return false;
        };
        let Some(inverse) = poly::inverse_rat(&j) else {
            return false;
        };
        let y: Vec<Vec<Rat>> = inverse
            .iter()
            .map(|row| {
                row.iter()
                    .map(|v| v.round_to_bits(PRECONDITIONER_BITS))
                    .collect()
            })
            .collect();
        let boxed: BTreeMap<String, RatInterval> = self
            .free
            .iter()
            .cloned()
            .zip(ranges.iter().cloned())
            .collect();
        let Some(enclosed) = self
            .jacobian
            .iter()
            .map(|row| row.iter().map(|d| d.enclose(&boxed).ok()).collect())
            .collect::<Option<Vec<Vec<RatInterval>>>>()
        else {
            return false;
        };
        let n = centre.len();
        let offsets: Vec<RatInterval> = ranges
            .iter()
            .zip(centre)
            .map(|(r, c)| r - &RatInterval::point(c.clone()))
            .collect();
        (0..n).all(|i| {
            let mut k = RatInterval::point(centre[i].clone());
            for (yk, fk) in y[i].iter().zip(&f) {
                k = &k - &RatInterval::point(yk * fk);
            }
            for (jj, offset) in offsets.iter().enumerate() {
                let mut m = RatInterval::point(if i == jj { Rat::ONE } else { Rat::ZERO });
                for (kk, yk) in y[i].iter().enumerate() {
                    m = &m - &enclosed[kk][jj].scale(yk);
                }
                k = &k + &(&m * offset);
            }
            k.inside(&ranges[i])
        })
    }
}

/// The numerator and denominator at an isolated witness with the posed
/// roots divided out, each coefficient a polynomial in the free
/// parameters, and those coefficients enclosed over the box.
struct Rests {
    q: Vec<Poly>,
    r: Vec<Poly>,
    q_ranges: Vec<RatInterval>,
    r_ranges: Vec<RatInterval>,
}

impl Rests {
    fn new(num: &Poly, den: &Poly, w: &IsolatedWitness) -> Option<Rests> {
        let boxed: BTreeMap<String, RatInterval> = w
            .free
            .iter()
            .map(|(k, [lo, hi])| Some((k.clone(), RatInterval::new(lo.clone(), hi.clone())?)))
            .collect::<Option<_>>()?;
        let mut q = num.subs_point(&w.fixed).coeffs_in(OMEGA);
        let mut r = den.subs_point(&w.fixed).coeffs_in(OMEGA);
        for (i, rho) in w.cancelled.iter().enumerate() {
            let twice = w.poses.iter().any(|p| p.pole == i && p.double);
            for _ in 0..1 + usize::from(twice) {
                q = divided(&q, rho);
                r = divided(&r, rho);
            }
        }
        for (sigma, mu) in &w.multiple {
            for _ in 0..*mu {
                q = divided(&q, sigma);
            }
        }
        let enclose = |cs: &[Poly]| -> Option<Vec<RatInterval>> {
            cs.iter().map(|c| c.enclose(&boxed).ok()).collect()
        };
        let q_ranges = enclose(&q)?;
        let r_ranges = enclose(&r)?;
        Some(Rests {
            q,
            r,
            q_ranges,
            r_ranges,
        })
    }

    /// Points between the positive roots of the rests at `centre` (in
    /// `f64`), and the multiple zeros: a first partition.
    fn first_partition(
        &self,
        centre: &BTreeMap<String, Rat>,
        multiple: &[(Rat, u32)],
    ) -> Option<Vec<Rat>> {
        let at = |cs: &[Poly]| -> Option<Vec<f64>> {
            cs.iter()
                .map(|c| Some(c.eval(centre).ok()?.to_f64()))
                .collect()
        };
        let mut marks: Vec<(f64, Option<Rat>)> = Vec::new();
        marks.extend(
            positive_roots(&at(&self.q)?)?
                .into_iter()
                .map(|z| (z, None)),
        );
        marks.extend(
            positive_roots(&at(&self.r)?)?
                .into_iter()
                .map(|z| (z, None)),
        );
        marks.extend(multiple.iter().map(|(s, _)| (s.to_f64(), Some(s.clone()))));
        marks.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut partition = Vec::new();
        for pair in marks.windows(2) {
            match (&pair[0].1, &pair[1].1) {
                (Some(s), _) => partition.push(s.clone()),
                (None, Some(_)) => {}
                (None, None) => {
                    let (a, b) = (pair[0].0, pair[1].0);
                    let between = short_rational((a * b).sqrt(), 12)?;
                    let v = between.to_f64();
                    if !(a < v && v < b) {
                        return None;
                    }
                    partition.push(between);
                }
            }
        }
        if let Some((_, Some(s))) = marks.last() {
            partition.push(s.clone());
        }
        Some(partition)
    }

    /// The type at the solution in the box, read with `partition` (see the
    /// module docs): each piece holds at most one root of each rest and
    /// not one of both, no point is a root, every root of the
    /// denominator's rest is placed, and the multiple zeros are points of
    /// the partition.
    fn read(&self, partition: &[Rat], multiple: &[(Rat, u32)]) -> Result<FrfType, Unread> {
        let positive = partition.iter().all(|t| t.signum() > 0);
        let increasing = partition.windows(2).all(|w| w[0] < w[1]);
        let placed = multiple.iter().all(|(s, _)| partition.contains(s));
        let lead = |c: &[RatInterval]| c.last().and_then(RatInterval::sign).is_some();
        if !positive || !increasing || !placed || !lead(&self.q_ranges) || !lead(&self.r_ranges) {
            return Err(Unread::Refused);
        }
        for t in partition {
            if value_at(&self.q_ranges, t).sign().is_none()
                || value_at(&self.r_ranges, t).sign().is_none()
            {
                return Err(Unread::Refused);
            }
        }
        let mut tokens = Vec::new();
        let (mut zeros, mut poles) = (0usize, 0usize);
        for i in 0..=partition.len() {
            let a = if i == 0 {
                Rat::ZERO
            } else {
                partition[i - 1].clone()
            };
            let b = partition.get(i);
            let vq = variations(&moebius(&self.q_ranges, &a, b)).ok_or(Unread::Piece(i))?;
            let vr = variations(&moebius(&self.r_ranges, &a, b)).ok_or(Unread::Piece(i))?;
            match (vq, vr) {
                (0, 0) => {}
                (1, 0) => {
                    zeros += 1;
                    tokens.push(simple(Feature::Antiresonance));
                }
                (0, 1) => {
                    poles += 1;
                    tokens.push(simple(Feature::Resonance));
                }
                _ => return Err(Unread::Piece(i)),
            }
            if let Some((_, mu)) = b.and_then(|b| multiple.iter().find(|(s, _)| s == b)) {
                tokens.push(Token {
                    feature: Feature::Antiresonance,
                    multiplicity: *mu,
                });
            }
        }
        if poles + 1 != self.r_ranges.len() {
            return Err(Unread::Refused);
        }
        Ok(FrfType {
            tokens,
            nonminimum_phase: zeros + 1 < self.q_ranges.len(),
        })
    }
}

fn simple(feature: Feature) -> Token {
    Token {
        feature,
        multiplicity: 1,
    }
}

/// The quotient of `sum c[i] x^i` by `x - r` (ascending coefficients), the
/// remainder dropped.
fn divided(c: &[Poly], r: &Rat) -> Vec<Poly> {
    let mut q = vec![Poly::zero(); c.len().saturating_sub(1)];
    let mut carry = Poly::zero();
    for i in (1..c.len()).rev() {
        carry = &c[i] + &carry.scale(r);
        q[i - 1] = carry.clone();
    }
    q
}

/// `sum c[i] t^i` in interval arithmetic.
fn value_at(c: &[RatInterval], t: &Rat) -> RatInterval {
    c.iter()
        .rev()
        .fold(RatInterval::point(Rat::ZERO), |acc, ci| &acc.scale(t) + ci)
}

/// The coefficients of `(1 + y)^d P((a + b y) / (1 + y))` for a piece
/// `(a, b)`, or of `P(a + y)` for `(a, inf)`: the roots of `P` in the
/// piece are the positive roots of the result.
fn moebius(p: &[RatInterval], a: &Rat, b: Option<&Rat>) -> Vec<RatInterval> {
    let d = p.len().saturating_sub(1);
    let mut out = vec![RatInterval::point(Rat::ZERO); p.len()];
    for (i, pi) in p.iter().enumerate() {
        // (a + b y)^i (1 + y)^(d - i), or (a + y)^i.
        let mut w = vec![Rat::ONE];
        let lead = b.cloned().unwrap_or(Rat::ONE);
        for _ in 0..i {
            w = times_linear(&w, a, &lead);
        }
        if b.is_some() {
            for _ in i..d {
                w = times_linear(&w, &Rat::ONE, &Rat::ONE);
            }
        }
        for (k, wk) in w.iter().enumerate() {
            out[k] = &out[k] + &pi.scale(wk);
        }
    }
    out
}

/// `w (c0 + c1 y)`, ascending coefficients.
fn times_linear(w: &[Rat], c0: &Rat, c1: &Rat) -> Vec<Rat> {
    let mut out = vec![Rat::ZERO; w.len() + 1];
    for (k, wk) in w.iter().enumerate() {
        out[k] = &out[k] + &(wk * c0);
        out[k + 1] = &out[k + 1] + &(wk * c1);
    }
    out
}

/// Sign variations of a sequence of intervals, exact zeros skipped;
/// `None` if one holds zero without being zero.
fn variations(c: &[RatInterval]) -> Option<usize> {
    let mut last = 0;
    let mut count = 0;
    for ci in c {
        let s = match ci.sign() {
            Some(s) => s,
            None if ci.lo().is_zero() && ci.hi().is_zero() => continue,
            None => return None,
        };
        if last != 0 && s != last {
            count += 1;
        }
        last = s;
    }
    Some(count)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::frf_type::frf_type_at_algebraic;
    use poly::{RealField, UPoly};

    fn p(s: &str) -> Poly {
        s.parse().unwrap()
    }

    fn r(s: &str) -> Rat {
        s.parse().unwrap()
    }

    /// Numerator and denominator combinations of two block determinants
    /// `a - 1` and `b - 1` with proportional cofactors: at `a = b = 1` their
    /// gradients are parallel, so no two parameters can be solved for
    /// them, while the determinants themselves pose the pole with `a` and
    /// `b` free.
    #[test]
    fn free_parameters_are_chosen_by_the_pose_where_the_plain_conditions_drop_rank() {
        let names: Vec<String> = ["a", "b", "c"].iter().map(|v| v.to_string()).collect();
        let at = [1.0, 1.0, 2.0];
        let plain = [p("a*c + b*c - 2*c"), p("2*a + 2*b - 4")];
        assert_eq!(posed_free_parameters(&plain, &names, &at), None);
        let posed = [p("a - 1"), p("b - 1")];
        assert_eq!(posed_free_parameters(&posed, &names, &at), Some(vec![0, 1]));
        // One condition in `c` alone leaves only `c` to solve for.
        assert_eq!(
            posed_free_parameters(&[p("c - 2")], &names, &at),
            Some(vec![2])
        );
    }

    /// Next to the box of B2's double zero (`A^2RR`, the poles at 3/2 and
    /// 2), the moves split the zero into two real ones on one side of the
    /// discriminant and a complex pair on the other: both `AARR` and
    /// `RR (nm)` get rational witnesses, and at each the numerator's
    /// discriminant, in `f64`, has the sign its type needs.
    #[test]
    fn moves_off_a_box_split_its_double_zero() {
        let (w, _) = b2_double_zero_box();
        let model = crate::Model::from_id("B2").unwrap();
        let tf = model.undamped_tf();
        let mut prover = Prover::new(&model, tf.num.clone(), tf.den.clone());
        let double: FrfType = "A^2RR".parse().unwrap();
        prover.isolated.insert(double, w);
        let split: Vec<FrfType> = ["AARR", "RR (nm)"]
            .iter()
            .map(|t| t.parse().unwrap())
            .collect();
        prover.split_boxes(&split, 5);
        for (t, sign) in split.iter().zip([1.0, -1.0]) {
            let point = prover.witnesses.get(t).unwrap_or_else(|| panic!("{t}"));
            let v = |k: &str| point[k].to_f64();
            // N = m2 m3 W^2 - c23 (m1 + m2 + m3) W + c1 c23.
            let b = v("c23") * (v("m1") + v("m2") + v("m3"));
            let discriminant = b * b - 4.0 * v("m2") * v("m3") * v("c1") * v("c23");
            assert!(discriminant * sign > 0.0, "{t}: {discriminant}");
        }
    }

    /// `RRRA^3` of N5-g2-a3.2-s4.2 (a pole cancelled, a triple zero):
    /// `mms sample` reads it about once in 20000 starts on its structure,
    /// and one search's draws show it not; the descent from the best of
    /// its own draws reaches it, and the checker's own reading of the box
    /// agrees.
    #[test]
    fn the_descent_reaches_a_type_the_draws_miss() {
        let model = crate::Model::from_id("N5-g2-a3.2-s4.2").unwrap();
        let tf = model.undamped_tf();
        let mut prover = Prover::new(&model, tf.num.clone(), tf.den.clone());
        let t: FrfType = "RRRA^3".parse().unwrap();
        let (_, derivatives) = prover.pencil_signatures(std::slice::from_ref(&t));
        let coeffs = UndampedCoefficients::new(&model);
        let mults = [3];
        let variety = Variety::new(&coeffs, prover.params.len(), 1, &mults);
        let blocks = block_pose(&model, &tf.num, &tf.den);
        let nodes = node_poses(&model, &tf.num, &tf.den);
        let context = (&derivatives[..], (blocks.as_ref(), nodes.as_slice()));
        let types = std::slice::from_ref(&t);
        let mut singular = Vec::new();
        let mut rng = XorShift::new(3);
        prover.draw(
            &variety,
            &mut rng,
            types,
            (STARTS, STARTS),
            context,
            &mut singular,
        );
        assert!(!prover.shown(&t));
        prover.descend(&variety, &mut XorShift::new(3), types, context);
        let w = prover.isolated.get(&t).expect("the descent finds a box");
        let json = serde_json::to_value(w).unwrap();
        let read = crate::check::isolated_type(&tf.num, &tf.den, &prover.params, &json);
        assert_eq!(read, Ok(t.to_string()));
    }

    #[test]
    fn krawczyk_isolates_the_one_root_and_refuses_a_box_without_it() {
        // x^2 + y^2 = 4, x = y: the positive root (sqrt 2, sqrt 2).
        let system = System::new(
            vec![p("x^2 + y^2 - 4"), p("x - y")],
            vec!["x".into(), "y".into()],
        );
        let centre = system.newton(vec![r("7/5"), r("3/2")]).unwrap();
        // Newton's iterate agrees with sqrt 2 far below the box's width.
        let error = (&(&centre[0] * &centre[0]) - &Rat::from(2)).abs();
        assert!(error < Rat::from(2).pow(-110), "{}", error.to_f64());
        let ranges: Vec<RatInterval> = centre.iter().map(|c| around(c, RADIUS_BITS)).collect();
        assert!(system.krawczyk_holds(&centre, &ranges));
        // The box holds sqrt 2: its ends' squares straddle 2.
        assert!((ranges[0].lo() * ranges[0].lo()) < Rat::from(2));
        assert!((ranges[0].hi() * ranges[0].hi()) > Rat::from(2));
        // Beside the root, and around it but reaching zero.
        let beside = vec![r("3/2"), r("3/2")];
        let small: Vec<RatInterval> = beside.iter().map(|c| around(c, 10)).collect();
        assert!(!system.krawczyk_holds(&beside, &small));
        let wide: Vec<RatInterval> = centre.iter().map(|c| around(c, 0)).collect();
        assert!(!system.krawczyk_holds(&centre, &wide));
    }

    /// B2's numerator `m2 m3 W^2 - c23 (m1 + m2 + m3) W + c1 c23` has a
    /// double zero at 1 for c1 = 2, c23 = 1/2, m1 = 1 where m2 m3 = 1 and
    /// m2 + m3 = 3 (by hand: N(1) = N'(1) = 0), i.e. m2 = (3 + sqrt 5)/2;
    /// there the denominator is W^2 - 7/2 W + 3 = (W - 3/2)(W - 2).
    /// The box of B2's double zero (see the next test), with its centre.
    fn b2_double_zero_box() -> (IsolatedWitness, Vec<Rat>) {
        let model = crate::Model::from_id("B2").unwrap();
        let tf = model.undamped_tf();
        let fixed = BTreeMap::from([
            ("c1".to_string(), r("2")),
            ("c23".to_string(), r("1/2")),
            ("m1".to_string(), r("1")),
        ]);
        let n = tf.num.subs_point(&fixed);
        let sigma = Rat::ONE;
        let conditions = vec![
            n.subs(OMEGA, &sigma),
            n.derivative(OMEGA).subs(OMEGA, &sigma),
        ];
        let free = vec!["m2".to_string(), "m3".to_string()];
        let system = System::new(conditions, free.clone());
        let centre = system.newton(vec![r("13/5"), r("2/5")]).unwrap();
        let ranges: Vec<RatInterval> = centre.iter().map(|c| around(c, RADIUS_BITS)).collect();
        assert!(system.krawczyk_holds(&centre, &ranges));
        let w = IsolatedWitness {
            fixed: fixed.clone(),
            free: free
                .iter()
                .zip(&ranges)
                .map(|(k, v)| (k.clone(), [v.lo().clone(), v.hi().clone()]))
                .collect(),
            cancelled: Vec::new(),
            multiple: vec![(sigma.clone(), 2)],
            poses: Vec::new(),
            partition: Vec::new(),
        };
        (w, centre)
    }

    #[test]
    fn a_box_reads_the_type_the_number_field_gives() {
        let (w, centre) = b2_double_zero_box();
        let tf = crate::Model::from_id("B2").unwrap().undamped_tf();
        let fixed = w.fixed.clone();
        let free: Vec<String> = w.free.keys().cloned().collect();
        let rests = Rests::new(&tf.num, &tf.den, &w).unwrap();
        let partition = rests
            .first_partition(&centre_point(&free, &centre), &w.multiple)
            .unwrap();
        let boxed = rests.read(&partition, &w.multiple).unwrap();
        // The other route: the exact point over Q(sqrt 5).
        let k = RealField::real_roots_of(&UPoly::from_i64s(&[-5, 0, 1]))
            .into_iter()
            .find(|f| f.to_f64(&f.generator()) > 0.0)
            .unwrap();
        let half = r("1/2");
        let m2 = k.add(
            &k.from_rat(&r("3/2")),
            &k.mul(&k.from_rat(&half), &k.generator()),
        );
        let m3 = k.sub(&k.from_rat(&r("3")), &m2);
        let mut point: BTreeMap<String, _> = fixed
            .iter()
            .map(|(a, b)| (a.clone(), k.from_rat(b)))
            .collect();
        point.insert("m2".into(), m2);
        point.insert("m3".into(), m3);
        let exact = frf_type_at_algebraic(&tf.num, &tf.den, OMEGA, &k, &point).unwrap();
        assert_eq!(exact.to_string(), "A^2RR");
        assert_eq!(boxed, exact);
        // The same box claimed without the double zero among the
        // partition's points is refused.
        assert_eq!(rests.read(&[r("7/4")], &w.multiple), Err(Unread::Refused));
    }

    /// B2's type C (every pole cancelled) only comes with its two poles
    /// cancelled together: `num = -c23 det(A) + Omega q_B` and `den =
    /// det(A) q_B` (by hand from the paper's Num and Den), so at a root of
    /// `det(A)` the numerator vanishes only where `q_B` does too, and two
    /// different poles cannot both cancel. The search must find the pair.
    #[test]
    fn a_pair_of_poles_cancelled_together_shows_a_constant() {
        let model = crate::Model::from_id("B2").unwrap();
        let tf = model.undamped_tf();
        let mut prover = Prover::new(&model, tf.num.clone(), tf.den.clone());
        let c: FrfType = "C".parse().unwrap();
        assert_eq!(prover.isolated_search(std::slice::from_ref(&c), 7), 1);
        let w = &prover.isolated[&c];
        assert_eq!(w.cancelled.len(), 1);
        assert!(w.poses.iter().all(|q| q.double), "{:?}", w.poses);
        // The other route: the chain's equations solved in f64 at the
        // box's centre (dampers zero) give a flat inertance, away from
        // the cancelled pole to within the box's width.
        let values: Vec<f64> = model
            .parameters()
            .iter()
            .map(|name| match (w.fixed.get(name), w.free.get(name)) {
                (Some(v), _) => v.to_f64(),
                (_, Some([lo, hi])) => (lo.to_f64() + hi.to_f64()) / 2.0,
                _ => 0.0,
            })
            .collect();
        let pole_hz = w.cancelled[0].to_f64().sqrt() / (2.0 * std::f64::consts::PI);
        let response = crate::response::ChainResponse::new(&model, crate::Output::Acceleration);
        let g: Vec<f64> = [0.1, 0.5, 2.0, 10.0]
            .iter()
            .map(|k| response.eval(&values, k * pole_hz).unwrap().re)
            .collect();
        for v in &g {
            assert!((v / g[0] - 1.0).abs() < 1e-9, "{g:?}");
        }
    }

    /// N5-g3-a4.2-s5.2: block A is masses 1 to 3, and both ports meet it at
    /// mass 2. Where the runs beside it, `c1 + c12 - m1 Omega` (mass 1)
    /// and `c23 - m3 Omega` (mass 3), vanish together, mass 2 is a node of
    /// a mode of block A that the force never excites.
    #[test]
    fn a_node_of_a_mode_poses_a_cancelled_pole() {
        let model = crate::Model::from_id("N5-g3-a4.2-s5.2").unwrap();
        let tf = model.undamped_tf();
        let poses = node_poses(&model, &tf.num, &tf.den);
        assert_eq!(poses.len(), 1, "{poses:?}");
        let q = &poses[0];
        assert_eq!(q.factors, [p("c1 + c12 - m1*Omega"), p("c23 - m3*Omega")]);
        let combine = |c: &[Poly; 2]| &(&c[0] * &q.factors[0]) + &(&c[1] * &q.factors[1]);
        assert_eq!(combine(&q.numerator), tf.num);
        assert_eq!(combine(&q.denominator), tf.den);
        // At Omega = 2 with m1 = m3 = c12 = 1, c1 = 1, c23 = 2 (and block
        // B's mode at 2 c45 = 6, away from it), the chain's
        // equations solved in f64 show no resonance there: the inertance
        // near sqrt(2) rad/s stays within a few times its value far off.
        let values: Vec<f64> = model
            .parameters()
            .iter()
            .map(|n| match n.as_str() {
                "c23" => 2.0,
                "c45" => 3.0,
                n if n.starts_with('d') => 0.0,
                _ => 1.0,
            })
            .collect();
        let response = crate::response::ChainResponse::new(&model, crate::Output::Acceleration);
        let pole_hz = 2f64.sqrt() / (2.0 * std::f64::consts::PI);
        let near = response
            .eval(&values, pole_hz * (1.0 + 1e-9))
            .unwrap()
            .norm();
        let off = response.eval(&values, pole_hz * 1.3).unwrap().norm();
        assert!(near < 10.0 * off, "{near} against {off}");
        // Both ports at mass 1, which moves in that mode: no node pose.
        let other = crate::Model::from_id("N5-g3-a4.1-s5.1").unwrap();
        let tf = other.undamped_tf();
        assert!(node_poses(&other, &tf.num, &tf.den).is_empty());
    }

    #[test]
    fn the_blocks_pose_a_shared_eigenvalue() {
        // N5-g1-a2.1-s4.1: block A is m1 on c1, so its determinant is
        // c1 - m1 Omega, and the cofactors multiply out to num and den.
        let model = crate::Model::from_id("N5-g1-a2.1-s4.1").unwrap();
        let tf = model.undamped_tf();
        let pose = block_pose(&model, &tf.num, &tf.den).unwrap();
        let f0 = &pose.factors[0];
        assert!(
            *f0 == p("c1 - m1*Omega") || *f0 == p("m1*Omega - c1"),
            "{f0}"
        );
        let combine = |c: &[Poly; 2]| &(&c[0] * &pose.factors[0]) + &(&c[1] * &pose.factors[1]);
        assert_eq!(combine(&pose.numerator), tf.num);
        assert_eq!(combine(&pose.denominator), tf.den);
        // Without a gap there are no blocks to pose by.
        let whole = crate::Model::from_id("N5-g0-a1.0-s2.0").unwrap();
        let tf = whole.undamped_tf();
        assert!(block_pose(&whole, &tf.num, &tf.den).is_none());
    }
}
