//! Witnesses with several cancelled poles.
//!
//! A pole cancels where its mode does not move the actuator's or the
//! sensor's mass (or the modes of two blocks coincide). Two or three such
//! coincidences at once are out of reach of the walls `x = beta/alpha` of
//! [`Prover::search`] and of the one-at-a-time block construction of
//! [`Prover::cancellation_search`], whose later steps move parameters the
//! earlier ones fixed. Two constructions, each hit classified exactly by
//! [`Prover::record`]:
//!
//! 1. **The mirror-symmetric stratum.** A free block whose parameters read
//!    the same from both ends (`m1 = m5`, `m2 = m4`, `c12 = c45`, `c23 =
//!    c34` for five masses) has modes that are symmetric or antisymmetric
//!    about its centre: the antisymmetric ones leave the centre mass at
//!    rest, and the symmetric ones move mirror masses alike, so a force or
//!    a measurement between them misses them. An actuator or sensor of one
//!    parity then misses every mode of the other. Off the stratum such a
//!    point lies where two sub-chains have equal spectra, of codimension
//!    two or more. The type `R` of `N5-g0-a2.0-s3.0`, with three of four
//!    poles cancelled, is there: `m = (1/2, 1, 1, 1, 1/2)`, every spring 1.
//!    The search samples the stratum and follows its walls as on the
//!    orthant.
//! 2. **Resting masses, one equation per side.** A mode leaves mass `k` of
//!    a block at rest exactly where the sub-chains left and right of `k`
//!    (each with its spring to `k`) share an eigenvalue `r`:
//!    `det(K_L - r M_L) = 0` and `det(K_R - r M_R) = 0`, in disjoint
//!    parameters and free of `m_k`. Every mass and spring enters a chain's
//!    determinant to the first power (a rank-one term), so each equation
//!    is solved for one of its parameters, exactly. Several coincidences
//!    (resting masses at the actuator or the sensor, or two blocks' equal
//!    eigenvalues) are posed together and solved in an order where each
//!    equation's parameter occurs in no equation solved before it, so none
//!    undoes another (or two equations at once, in two parameters in which
//!    they are jointly linear: a block's determinant at two eigenvalues).

use super::frf_type::FrfType;
use super::pole_signs::{block_ranges, run_det};
use super::prover::{Prover, Sampler, SearchLimits, Substitution};
use super::targeted::{linear_sets, solve_linear, Mechanism};
use crate::model::{mass_name, spring_name, Model};
use crate::tf::OMEGA;
use poly::{Poly, Rat};
use std::collections::{BTreeMap, BTreeSet};

/// Trials of the resting-mass construction per model.
const RESTING_TRIALS: usize = 4000;

/// The substitutions that make the free block (masses `gap + 1 ..= N`; the
/// whole chain when `gap = 0`) read the same from both ends, or `None` for
/// a block of one mass. The grounded block has its ground spring at one
/// end only and no such symmetry.
pub(crate) fn free_block_mirror(model: &Model) -> Option<Vec<Substitution>> {
    let (n, g) = (model.n_masses(), model.gap());
    if n - g < 2 {
        return None;
    }
    let mirror = |j: usize| g + 1 + n - j;
    let same = |var: String, as_: String| Substitution {
        var,
        alpha: Poly::one(),
        beta: Poly::var(&as_),
    };
    let mut subs = Vec::new();
    for j in g + 1..=n {
        if j > mirror(j) {
            subs.push(same(mass_name(j), mass_name(mirror(j))));
        }
    }
    // The spring between i and i + 1 mirrors to the one between
    // mirror(i + 1) and mirror(i).
    for i in g + 1..n {
        let m = mirror(i + 1);
        if i > m {
            subs.push(same(spring_name(i), spring_name(m)));
        }
    }
    Some(subs)
}

impl Prover<'_> {
    /// Samples the mirror-symmetric stratum of the free block and its walls
    /// (to the usual depth) for the types in `wanted`; returns how many of
    /// them it witnessed.
    pub(crate) fn symmetric_search(&mut self, wanted: &[FrfType], limits: &SearchLimits) -> usize {
        if wanted.is_empty() {
            return 0;
        }
        let Some(subs) = free_block_mirror(self.model) else {
            return 0;
        };
        let before = self.witnessed(wanted);
        let mut visited = BTreeSet::new();
        let mut rng = Sampler::new(0x0005_E110_FA11);
        // Depth 1: the stratum is sampled as a wall and its own walls are
        // followed one level less deep than the orthant's.
        self.search_in(&subs, limits, 1, &mut visited, &mut rng);
        self.witnessed(wanted) - before
    }

    /// The coincidences that cancel a pole with the actuator's or the
    /// sensor's mass at rest: for each such mass `k` of a block with masses
    /// on both sides, the determinants of the two sides and the masses
    /// each holds (as [`Mechanism`]s, like those of
    /// [`Self::cancellation_mechanisms`]). A mode of one block leaves the
    /// others at rest, so a port between two blocks acts on each block's
    /// modes through its mass there alone; a port within one block is not
    /// at rest when one of its masses is.
    fn resting_mass_mechanisms(&self) -> Vec<Mechanism> {
        let mass = self.model.mass_matrix();
        let stiff = self.model.stiffness_matrix();
        let det_of = |lo: usize, hi: usize| run_det(&mass, &stiff, lo, hi);
        let blocks = block_ranges(&stiff);
        let block_of = |k: usize| blocks.iter().position(|&(lo, hi)| lo <= k && k < hi);
        // Port ends as 0-based masses (0 in a port is the ground).
        let mut resting: Vec<usize> = Vec::new();
        for p in [self.model.actuator(), self.model.sensor()] {
            for (end, other) in [(p.plus, p.minus), (p.minus, p.plus)] {
                if end == 0 {
                    continue;
                }
                let apart = other == 0 || block_of(other - 1) != block_of(end - 1);
                if apart && !resting.contains(&(end - 1)) {
                    resting.push(end - 1);
                }
            }
        }
        let mut mechanisms = Vec::new();
        for &(lo, hi) in &blocks {
            for &k in &resting {
                if lo < k && k + 1 < hi {
                    mechanisms.push((
                        det_of(lo, k),
                        (lo..k).collect(),
                        det_of(k + 1, hi),
                        (k + 1..hi).collect(),
                    ));
                }
            }
        }
        mechanisms
    }

    /// Builds points with several cancelled poles from resting masses and
    /// the block coincidences of [`Self::cancellation_mechanisms`], each
    /// equation solved for a parameter no earlier equation holds (see the
    /// module docs); returns how many of `wanted` it witnessed.
    pub(crate) fn resting_mass_search(&mut self, wanted: &[FrfType], seed: u64) -> usize {
        let degree = self.den.degree(OMEGA);
        let open = wanted
            .iter()
            .filter(|t| t.resonances() < degree && !self.witnesses.contains_key(t))
            .count();
        if open == 0 {
            return 0;
        }
        let before = self.witnessed(wanted);
        // With the coincidences of two blocks' eigenvalues (whole
        // determinants in disjoint parameters) and of a run's with its
        // block's (the second equation holds every parameter of the block,
        // and joins others less often).
        let mut mechanisms = self.resting_mass_mechanisms();
        mechanisms.extend(self.cancellation_mechanisms());
        if mechanisms.is_empty() {
            return 0;
        }
        let mut rng = Sampler::new(seed);
        let most = (degree as usize).max(2);
        for trial in 0..RESTING_TRIALS {
            // Two to `degree` coincidences, in turn.
            let c = 2 + trial % (most - 1);
            let mut equations: Vec<Poly> = Vec::with_capacity(2 * c);
            for _ in 0..c {
                let (d1, _, d2, _) = &mechanisms[rng.index(mechanisms.len())];
                let r = rng.value();
                equations.push(d1.subs(OMEGA, &r));
                equations.push(d2.subs(OMEGA, &r));
            }
            let Some(order) = triangular_order(&equations, &mut rng) else {
                continue;
            };
            let mut point: BTreeMap<String, Rat> = self
                .params
                .iter()
                .map(|p| (p.clone(), rng.value()))
                .collect();
            let solved = order.into_iter().all(|(rows, names)| {
                let known: BTreeMap<String, Rat> = point
                    .iter()
                    .filter(|(p, _)| !names.contains(p))
                    .map(|(p, v)| (p.clone(), v.clone()))
                    .collect();
                let system: Vec<Poly> = rows
                    .iter()
                    .map(|&i| equations[i].subs_point(&known))
                    .collect();
                match solve_linear(&system, &names) {
                    Some(sol) if sol.iter().all(|v| v.signum() > 0) => {
                        point.extend(names.into_iter().zip(sol));
                        true
                    }
                    _ => false,
                }
            });
            if solved {
                self.record(point);
            }
        }
        self.witnessed(wanted) - before
    }
}

/// An order in which to solve `equations` so that no equation's unknowns
/// occur in an equation solved before it (solving it then leaves those
/// satisfied): peeled from the back, the last step is one equation with a
/// parameter no other holds, or else two equations with two such
/// parameters in which both are jointly linear (a block's determinant at
/// two eigenvalues, say `det(K - r M)` in `c1` and `m1`, which share one
/// diagonal entry). Ties are broken at random; `None` when no such order
/// exists.
fn triangular_order(
    equations: &[Poly],
    rng: &mut Sampler,
) -> Option<Vec<(Vec<usize>, Vec<String>)>> {
    let mut left: Vec<usize> = (0..equations.len()).collect();
    let mut order = Vec::with_capacity(left.len());
    while !left.is_empty() {
        // Parameters held by no remaining equation but those in `own`.
        let alone = |v: &String, own: &[usize], left: &[usize]| {
            left.iter()
                .all(|j| own.contains(j) || !equations[*j].has_var(v))
        };
        let mut singles: Vec<(usize, &String)> = Vec::new();
        for &i in &left {
            for v in equations[i].vars() {
                if alone(v, &[i], &left) {
                    singles.push((i, v));
                }
            }
        }
        let step = if singles.is_empty() {
            let mut pairs: Vec<([usize; 2], [&String; 2])> = Vec::new();
            for (a, &i) in left.iter().enumerate() {
                for &j in &left[a + 1..] {
                    let own = [i, j];
                    let mut vars: Vec<&String> = equations[i]
                        .vars()
                        .iter()
                        .chain(equations[j].vars())
                        .filter(|v| alone(v, &own, &left))
                        .collect();
                    vars.sort();
                    vars.dedup();
                    for (b, x) in vars.iter().enumerate() {
                        for y in &vars[b + 1..] {
                            let xy = [(*x).clone(), (*y).clone()];
                            let polys = [&equations[i], &equations[j]];
                            if linear_sets(&polys, &xy, 2).len() == 1 {
                                pairs.push((own, [*x, *y]));
                            }
                        }
                    }
                }
            }
            if pairs.is_empty() {
                return None;
            }
            let (own, xy) = pairs[rng.index(pairs.len())];
            (own.to_vec(), vec![xy[0].clone(), xy[1].clone()])
        } else {
            let (i, v) = singles[rng.index(singles.len())];
            (vec![i], vec![v.clone()])
        };
        left.retain(|i| !step.0.contains(i));
        order.push(step);
    }
    order.reverse();
    Some(order)
}

#[cfg(test)]
mod tests {
    use super::*;
    use poly::{adjugate, det, UPoly};

    /// The reduced TF at `point` by another route than the prover's
    /// continuants: `c^T adj(K - Omega M) b / det(K - Omega M)` from the
    /// chain's matrices, divided by its gcd.
    fn reduced_by_matrices(model: &Model, point: &BTreeMap<String, Rat>) -> (UPoly, UPoly) {
        let at = |p: &Poly| p.eval_except(OMEGA, point).unwrap();
        let pencil: Vec<Vec<Poly>> = model
            .stiffness_matrix()
            .iter()
            .zip(model.mass_matrix())
            .map(|(k, m)| {
                k.iter()
                    .zip(&m)
                    .map(|(k, m)| &at(k) - &(&at(m) * &Poly::var(OMEGA)))
                    .collect()
            })
            .collect();
        let adj = adjugate(&pencil);
        let (b, c) = (model.input_vector(), model.output_vector());
        let mut num = Poly::zero();
        for (i, row) in adj.iter().enumerate() {
            for (j, a) in row.iter().enumerate() {
                num = &num + &a.scale(&Rat::from(c[i] * b[j]));
            }
        }
        let up = |p: &Poly| UPoly::from_poly(p, OMEGA).unwrap().1;
        let (num, den) = (up(&num), up(&det(&pencil)));
        let g = num.gcd(&den);
        (num.div_exact(&g).unwrap(), den.div_exact(&g).unwrap())
    }

    fn prover_for(model: &Model) -> Prover<'_> {
        let tf = model.undamped_tf();
        Prover::new(model, tf.num.clone(), tf.den.clone())
    }

    /// The symmetric stratum gives the type `R` of N5-g0-a2.0-s3.0 (three
    /// of four poles cancelled), which sampling and the walls of the
    /// orthant miss. At its witness the TF from the matrices has one pole
    /// besides the rigid body's and no zero.
    #[test]
    fn three_cancellations_on_the_symmetric_stratum() {
        let model = Model::from_id("N5-g0-a2.0-s3.0").unwrap();
        let mut prover = prover_for(&model);
        let r: FrfType = "R".parse().unwrap();
        let found = prover.symmetric_search(std::slice::from_ref(&r), &SearchLimits::default());
        assert_eq!(found, 1);
        let point = &prover.witnesses[&r];
        // Symmetric: m1 = m5, m2 = m4, c12 = c45, c23 = c34.
        assert_eq!(point["m1"], point["m5"]);
        assert_eq!(point["c23"], point["c34"]);
        let (num, den) = reduced_by_matrices(&model, point);
        assert_eq!(num.degree(), Some(0), "no zero left");
        // The rigid-body pole at 0 and one resonance.
        assert_eq!(den.degree(), Some(2));
        assert!(den.coeff(0).is_zero());
    }

    /// Two resting masses at once: `RR` of N5-g0-a2.0-s4.0 needs one mode
    /// with the actuator's mass 2 at rest and another with the sensor's
    /// mass 4 at rest, two cancellations in parameters that overlap
    /// (`m3`, `c23`, `c34` enter both); not symmetric, since mirrored the
    /// two would be one mode. The witness, by the matrices' route: two
    /// resonances, no zero. And the mechanics: the numerator's zeros are
    /// the eigenvalues of mass 1 alone (`c12/m1`) and of mass 5 alone
    /// (`c45/m5`); each is cancelled only where the sub-chain on the other
    /// side of the port's mass has it too, a mode with that mass at rest.
    #[test]
    fn two_resting_masses_at_once() {
        let model = Model::from_id("N5-g0-a2.0-s4.0").unwrap();
        let mut prover = prover_for(&model);
        let rr: FrfType = "RR".parse().unwrap();
        assert_eq!(
            prover.resting_mass_search(std::slice::from_ref(&rr), 0x2E57_1A55),
            1
        );
        let point = prover.witnesses[&rr].clone();
        let (num, den) = reduced_by_matrices(&model, &point);
        assert_eq!(num.degree(), Some(0), "no zero left");
        assert_eq!(den.degree(), Some(3), "the rigid body and two resonances");
        // Sub-chain spectra: m1 alone (c12/m1) lies in the spectrum of
        // m3..m5, and m5 alone (c45/m5) in that of m1..m3.
        let stiff = model.stiffness_matrix();
        let mass = model.mass_matrix();
        let side = |lo: usize, hi: usize, r: &Rat| {
            let mut p: BTreeMap<String, Rat> = point.clone();
            p.insert(OMEGA.to_string(), r.clone());
            run_det(&mass, &stiff, lo, hi).eval(&p).unwrap()
        };
        let r2 = &point["c12"] / &point["m1"];
        let r4 = &point["c45"] / &point["m5"];
        assert!(side(2, 5, &r2).is_zero(), "mass 2 at rest at {r2}");
        assert!(side(0, 3, &r4).is_zero(), "mass 4 at rest at {r4}");
        assert_ne!(r2, r4);
    }

    #[test]
    fn equations_are_peeled_into_a_triangular_order() {
        let p = |s: &str| s.parse::<Poly>().unwrap();
        let mut rng = Sampler::new(1);
        // x only in the first: it is solved last, after y.
        let order = triangular_order(&[p("x - 2*y"), p("y - 3")], &mut rng).unwrap();
        assert_eq!(
            order,
            [
                (vec![1], vec!["y".to_string()]),
                (vec![0], vec!["x".to_string()])
            ]
        );
        // Both in both, jointly linear: one step of two.
        let order = triangular_order(&[p("a + b - 3"), p("a - b - 1")], &mut rng).unwrap();
        assert_eq!(order.len(), 1);
        assert_eq!(order[0].1, ["a", "b"]);
        // A product of the two: no order.
        assert!(triangular_order(&[p("a*b - 1"), p("a*b + a - 2")], &mut rng).is_none());
    }

    #[test]
    fn mirror_of_the_free_block() {
        let text = |m: &str| -> Vec<String> {
            free_block_mirror(&Model::from_id(m).unwrap())
                .unwrap()
                .iter()
                .map(|s| format!("{}={}", s.var, s.beta))
                .collect()
        };
        assert_eq!(
            text("N5-g0-a2.0-s3.0"),
            ["m4=m2", "m5=m1", "c34=c23", "c45=c12"]
        );
        // Gap 2: the free block is m3..m5, the grounded one m1, m2.
        assert_eq!(text("N5-g2-a3.1-s4.2"), ["m5=m3", "c45=c34"]);
        assert!(free_block_mirror(&Model::from_id("N4-g3-a4.1-s4.2").unwrap()).is_none());
    }
}
