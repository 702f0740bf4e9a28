//! The sign of the numerator at the poles, a certificate on the whole
//! orthant for models whose denominator is one chain block.
//!
//! When the denominator's `Omega`-dependence is the determinant `P` of one
//! unreduced tridiagonal block of `K - Omega*M` (a free block divided by
//! `Omega`), its roots `lambda_1 < ... < lambda_n` are real, simple and
//! positive. The pseudo-remainder `R` of the numerator by `P`
//! (`lc(P)^e * num = q*P + R`) has the numerator's sign at every pole, and
//! for the chains here it often factors into factors of one sign, powers
//! of `Omega`, and *anchors* `K_jj - Omega*M_jj`: a diagonal entry of the
//! block, whose ratio `rho_j = K_jj/M_jj` lies strictly between the
//! block's extreme eigenvalues (a Rayleigh quotient of an unreduced
//! tridiagonal matrix; `0` is the lowest eigenvalue of a free block). For
//! every placement of the anchors among the poles that allows, the signs
//! of the numerator at `0`, at each pole and at infinity fix the parity of
//! the number of antiresonances in every interval between poles; a type
//! with all `n` resonances (none cancelled: a pole where the numerator
//! vanishes cancels) that matches no placement cannot occur anywhere.
//!
//! At four masses this settles the models with the gap before the last
//! mass and the grounded ones with both ports at the ends, where the other
//! methods leave dozens of orderings undecided.
//!
//! [`BlockPoleSigns`] extends the argument to a denominator that is the
//! product of several blocks' pole polynomials `p_B` (both sides of the
//! gap carry springs). The TF is `-Omega * sum_B n_B / d_B`, one term per
//! block, so at a pole of block `B` the numerator has the sign of `n_B`
//! times the other blocks' `p_B'`: those contribute how their spectra
//! interleave with the pole (the blocks share no parameter, so every
//! interleaving is enumerated), and `n_B`, or its pseudo-remainder by
//! `p_B`, factors into signs, `Omega` and determinants of runs of the
//! block's masses (principal minors, the anchors being runs of one),
//! whose eigenvalues interlace the block's (Cauchy). A run at an end of
//! the block is, with the run beyond its neighbour, the block less one
//! mass, whose eigenvalues take one gap between the block's each: the
//! run's own eigenvalues then lie in distinct gaps.

use super::configurations::{BlockEvents, ConfigurationInputs, Configurations, Minor};
use super::frf_type::{Feature, FrfType};
use crate::model::Model;
use crate::tf::OMEGA;
use poly::{det, factor, Poly};
use serde::{Deserialize, Serialize};

/// The data of a pole-sign certificate (see the module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PoleSigns {
    /// `R` as `unit * prod factor^exponent`.
    pub remainder_unit: poly::Rat,
    /// The factors of `R` with their exponents.
    pub remainder_factors: Vec<RemainderFactor>,
}

/// One factor of the remainder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RemainderFactor {
    /// The factor.
    pub factor: Poly,
    /// Its exponent.
    pub exponent: u32,
}

/// The data of a pole-sign certificate for a denominator that is the
/// product of several blocks' determinants (see the module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BlockPoleSigns {
    /// Every block whose term the TF has, in chain order.
    pub blocks: Vec<BlockSign>,
}

/// One block `B` of a [`BlockPoleSigns`] certificate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BlockSign {
    /// The block's masses (1-based, consecutive).
    pub masses: Vec<usize>,
    /// `n_B = c_B^T adj(K_B - Omega*M_B) b_B`, the block's term of the
    /// receptance over its determinant.
    pub numerator: Poly,
    /// Whether the factors below are those of the pseudo-remainder of
    /// `n_B` by the block's pole polynomial (else of `n_B` itself).
    pub remainder: bool,
    /// The factorization: `unit * prod factor^exponent`.
    pub unit: poly::Rat,
    /// Its factors: of one sign, `Omega`, or a multiple of the
    /// determinant of a run of the block's masses (a principal minor).
    pub factors: Vec<RemainderFactor>,
}

/// What the prover keeps for the block certificate: its data and every
/// configuration.
#[derive(Clone, Debug)]
pub(crate) struct BlockSignData {
    pub certificate: BlockPoleSigns,
    /// With each term's direction only where all its zeros lie on one
    /// side of a gap and all its poles on the other.
    pub configurations: Configurations,
    pub inputs: ConfigurationInputs,
    /// Degree of the numerator in `Omega`.
    pub zeros: u32,
}

/// What the prover keeps per model: the certificate data and the parity
/// patterns of every allowed anchor placement.
#[derive(Clone, Debug)]
pub(crate) struct PoleSignData {
    pub certificate: PoleSigns,
    /// Resonances (roots of the block's determinant on the positive axis).
    pub poles: u32,
    /// Degree of the numerator in `Omega`.
    pub zeros: u32,
    /// For every allowed placement: whether the number of antiresonances
    /// in interval `i` (below the first pole, between poles, above the
    /// last) is odd.
    pub parities: Vec<Vec<bool>>,
}

/// `(R, e)` with `lc(b)^e * a = q*b + R`, `deg R < deg b` in `x`.
pub(crate) fn pseudo_remainder(a: &Poly, b: &Poly, x: &str) -> (Poly, u32) {
    let n = b.degree(x);
    let lb = b.coeffs_in(x)[n as usize].clone();
    let mut r = a.clone();
    let mut e = 0;
    let xv = Poly::var(x);
    while !r.is_zero() && r.degree(x) >= n {
        let d = r.degree(x);
        let lr = r.coeffs_in(x)[d as usize].clone();
        r = &(&lb * &r) - &(&(&lr * &xv.pow(d - n)) * b);
        e += 1;
    }
    (r, e)
}

/// The premise and the placements for `model`'s `num/den`, if they hold.
pub(crate) fn pole_sign_data(model: &Model, num: &Poly, den: &Poly) -> Option<PoleSignData> {
    let mass = model.mass_matrix();
    let stiff = model.stiffness_matrix();
    let om = Poly::var(OMEGA);
    for b in &chain_blocks(&stiff) {
        if b.len() < 2 {
            continue;
        }
        let pencil = pencil(&mass, &stiff, b);
        let d = det(&pencil);
        let free = d.subs(OMEGA, &poly::Rat::ZERO).is_zero();
        let p = if free { d.div_exact(&om)? } else { d };
        let q = den.div_exact(&p)?;
        if q.degree(OMEGA) != 0 {
            continue;
        }
        return placements(b, free, num, &p, &mass, &stiff);
    }
    None
}

fn placements(
    block: &[usize],
    free: bool,
    num: &Poly,
    p: &Poly,
    mass: &[Vec<Poly>],
    stiff: &[Vec<Poly>],
) -> Option<PoleSignData> {
    let poles = p.degree(OMEGA);
    let zeros = num.degree(OMEGA);
    let lc_p = p.coeffs_in(OMEGA)[poles as usize].orthant_sign()?;
    let num_at_zero = num.subs(OMEGA, &poly::Rat::ZERO).orthant_sign()?;
    let num_at_inf = num.coeffs_in(OMEGA)[zeros as usize].orthant_sign()?;
    let (r, e) = pseudo_remainder(num, p, OMEGA);
    if r.is_zero() {
        return None;
    }
    let f = factor(&r);
    // Sign of R at a pole, as a constant times the anchors' signs.
    let mut sign = f.unit.signum();
    // Each anchor: the sign of the factor is `s * sign(rho - lambda)`.
    let mut anchors: Vec<i32> = Vec::new();
    for (g, k) in &f.factors {
        let d = g.degree(OMEGA);
        if d == 0 {
            let s = g.orthant_sign()?;
            sign *= s.pow(*k);
        } else if *g == Poly::var(OMEGA) {
            // Positive at every pole.
        } else if d == 1 && *k == 1 {
            let s = block.iter().find_map(|&j| {
                let diag = &stiff[j][j] - &(&Poly::var(OMEGA) * &mass[j][j]);
                ratio_sign(g, &diag)
            })?;
            anchors.push(s);
        } else {
            return None;
        }
    }
    let at_pole = sign * lc_p.pow(e);
    // Anchor placements: the number of poles below rho.
    let lowest = if free { 0 } else { 1 };
    if poles < 1 || (!anchors.is_empty() && lowest > poles - 1) {
        return None;
    }
    let mut parities: Vec<Vec<bool>> = Vec::new();
    let mut pos = vec![lowest; anchors.len()];
    loop {
        let mut ends = vec![num_at_zero];
        for i in 0..poles {
            let mut v = at_pole;
            for (s, k) in anchors.iter().zip(&pos) {
                // lambda_i lies above rho iff i >= k.
                v *= s * if i >= *k { -1 } else { 1 };
            }
            ends.push(v);
        }
        ends.push(num_at_inf);
        let par: Vec<bool> = ends.windows(2).map(|w| w[0] != w[1]).collect();
        if !parities.contains(&par) {
            parities.push(par);
        }
        // Next placement (odometer over lowest..poles).
        let mut i = 0;
        loop {
            if i == pos.len() {
                parities.sort();
                return Some(PoleSignData {
                    certificate: PoleSigns {
                        remainder_unit: f.unit.clone(),
                        remainder_factors: listed(&f),
                    },
                    poles,
                    zeros,
                    parities,
                });
            }
            pos[i] += 1;
            if pos[i] < poles {
                break;
            }
            pos[i] = lowest;
            i += 1;
        }
    }
}

/// A factorization's factors as a certificate lists them.
fn listed(f: &poly::Factorization) -> Vec<RemainderFactor> {
    f.factors
        .iter()
        .map(|(g, k)| RemainderFactor {
            factor: g.clone(),
            exponent: *k,
        })
        .collect()
}

/// `g = c * h` with `c` a nonzero rational: the sign of `c`.
fn ratio_sign(g: &Poly, h: &Poly) -> Option<i32> {
    let (a, b) = (g.terms().first()?, h.terms().first()?);
    let c = &a.coef / &b.coef;
    (h.scale(&c) == *g).then(|| c.signum())
}

/// Whether `t` (all `poles` resonances, simple) matches one of the
/// placements: the antiresonance count in every interval has the parity
/// the signs force, and the positive zeros are all the numerator's zeros
/// exactly when `t` is not `(nm)`.
pub(crate) fn type_fits(data: &PoleSignData, t: &FrfType) -> bool {
    let mut counts = vec![0u32; data.poles as usize + 1];
    let mut j = 0;
    for tok in &t.tokens {
        match tok.feature {
            Feature::Resonance => j += 1,
            Feature::Antiresonance => counts[j.min(data.poles as usize)] += tok.multiplicity,
        }
    }
    let total: u32 = counts.iter().sum();
    if total > data.zeros || (total == data.zeros) == t.nonminimum_phase {
        return false;
    }
    data.parities
        .iter()
        .any(|par| par.iter().zip(&counts).all(|(odd, c)| *odd == (c % 2 == 1)))
}

/// `K - Omega*M` restricted to the masses `idx` (0-based).
pub(crate) fn pencil(mass: &[Vec<Poly>], stiff: &[Vec<Poly>], idx: &[usize]) -> Vec<Vec<Poly>> {
    let om = Poly::var(OMEGA);
    idx.iter()
        .map(|&i| {
            idx.iter()
                .map(|&j| &stiff[i][j] - &(&om * &mass[i][j]))
                .collect()
        })
        .collect()
}

/// `det(K - Omega*M)` of the run of masses `lo..hi` (0-based).
pub(crate) fn run_det(mass: &[Vec<Poly>], stiff: &[Vec<Poly>], lo: usize, hi: usize) -> Poly {
    poly::det(&pencil(mass, stiff, &(lo..hi).collect::<Vec<_>>()))
}

/// The chain's blocks as ranges `first..last + 1` of masses (0-based).
pub(crate) fn block_ranges(stiff: &[Vec<Poly>]) -> Vec<(usize, usize)> {
    chain_blocks(stiff)
        .iter()
        .map(|b| (b[0], b[b.len() - 1] + 1))
        .collect()
}

/// The chain's blocks: maximal runs of masses joined by springs (0-based).
pub(crate) fn chain_blocks(stiff: &[Vec<Poly>]) -> Vec<Vec<usize>> {
    let mut blocks: Vec<Vec<usize>> = Vec::new();
    for i in 0..stiff.len() {
        match blocks.last_mut() {
            Some(b) if !stiff[i - 1][i].is_zero() => b.push(i),
            _ => blocks.push(vec![i]),
        }
    }
    blocks
}

/// The premise and the configurations for a denominator that is a
/// product of block pole polynomials (see [`BlockPoleSigns`]), if they
/// hold.
///
/// The TF is `-Omega * sum_B n_B / d_B` with `d_B` the determinant of
/// block `B` and `p_B` its pole polynomial (`d_B`, or `d_B/Omega` for a
/// free block). If `den = c * Omega^delta * prod_B p_B` with `c` free of
/// `Omega` and of one sign, then, with two blocks `B`, `B'`,
/// `num * Omega^(f_B + f_B') = -c Omega^(1+delta) (Omega^f_B' n_B p_B' +
/// Omega^f_B n_B' p_B)`: at a pole of `B` the numerator has the sign of
/// `-c n_B p_B'`, at a zero of `n_B` that of `-c p_B n_B'`, and the signs
/// of `p_B'` and `n_B` follow from how the spectra and the minors'
/// eigenvalues lie (see [`super::configurations`]).
pub(crate) fn block_pole_sign_data(model: &Model, num: &Poly, den: &Poly) -> Option<BlockSignData> {
    let mass = model.mass_matrix();
    let stiff = model.stiffness_matrix();
    let (b, c) = (model.input_vector(), model.output_vector());
    let om = Poly::var(OMEGA);
    let pencil_of = |idx: &[usize]| pencil(&mass, &stiff, idx);
    // (indices, d_B, p_B, free, n_B) of every block the TF has a term of.
    let mut parts = Vec::new();
    for blk in chain_blocks(&stiff) {
        let pencil = pencil_of(&blk);
        let adj = poly::adjugate(&pencil);
        let mut n_b = Poly::zero();
        for (ii, &i) in blk.iter().enumerate() {
            for (jj, &j) in blk.iter().enumerate() {
                if c[i] != 0 && b[j] != 0 {
                    n_b = &n_b + &adj[ii][jj].scale(&poly::Rat::from(c[i] * b[j]));
                }
            }
        }
        if n_b.is_zero() {
            continue;
        }
        let d = det(&pencil);
        let free = d.subs(OMEGA, &poly::Rat::ZERO).is_zero();
        let p = if free { d.div_exact(&om)? } else { d.clone() };
        parts.push((blk, d, p, free, n_b));
    }
    if parts.is_empty() || parts.len() > 2 {
        return None;
    }
    let prod_p = parts.iter().fold(Poly::one(), |acc, q| &acc * &q.2);
    // `den = c * prod p_B` with `c` free of Omega: every chain here has
    // one free block, whose `Omega` the normal form divides out, so a
    // power of `Omega` left over (which would shift the degree and (nm)
    // rules) does not occur; it is refused rather than handled.
    let rest = den.div_exact(&prod_p)?.coeffs_in(OMEGA);
    if rest.len() != 1 {
        return None;
    }
    let c_sign = rest[0].orthant_sign()?;
    // The identity num * prod d_B = -Omega * den * sum_B n_B prod_{B' != B} d_B'.
    let prod_d = parts.iter().fold(Poly::one(), |acc, q| &acc * &q.1);
    let mut sum = Poly::zero();
    for (k, q) in parts.iter().enumerate() {
        let others = parts
            .iter()
            .enumerate()
            .filter(|(l, _)| *l != k)
            .fold(Poly::one(), |acc, (_, r)| &acc * &r.1);
        sum = &sum + &(&q.4 * &others);
    }
    if num * &prod_d != -(&(&om * den) * &sum) {
        return None;
    }
    let at_zero_poly = num.subs(OMEGA, &poly::Rat::ZERO);
    let zeros = num.degree(OMEGA);
    let num_at_inf = num.coeffs_in(OMEGA)[zeros as usize].orthant_sign()?;
    let mut events = Vec::new();
    let mut blocks = Vec::new();
    for (blk, _, p, free, n_b) in &parts {
        let poles = p.degree(OMEGA) as usize;
        let lead = p.coeffs_in(OMEGA)[poles].orthant_sign()?;
        // The determinants of the block's proper runs (principal minors).
        let mut runs = Vec::new();
        for start in 0..blk.len() {
            for end in start + 1..=blk.len() {
                if end - start < blk.len() {
                    runs.push((start, end - start, det(&pencil_of(&blk[start..end]))));
                }
            }
        }
        let (f, (base, minors), remainder) = match signed_factors(n_b, &runs) {
            Some(x) => (factor(n_b), x, false),
            None if poles > 0 => {
                let (r, e) = pseudo_remainder(n_b, p, OMEGA);
                if r.is_zero() {
                    return None;
                }
                let (s, m) = signed_factors(&r, &runs)?;
                (factor(&r), (s * lead.pow(e), m), true)
            }
            None => return None,
        };
        blocks.push(BlockSign {
            masses: blk.iter().map(|i| i + 1).collect(),
            numerator: n_b.clone(),
            remainder,
            unit: f.unit.clone(),
            factors: listed(&f),
        });
        // The block seen as driven: c_B = +-b_B (both nonzero, as n_B is).
        let collocated = [1i64, -1]
            .into_iter()
            .find(|&s| blk.iter().all(|&i| c[i] == s * b[i]))
            .unwrap_or(0) as i32;
        let omega_power = n_b
            .coeffs_in(OMEGA)
            .iter()
            .position(|q| !q.is_zero())
            .unwrap_or(0) as u32;
        events.push(BlockEvents {
            size: blk.len(),
            free: *free,
            lead,
            direct: !remainder,
            base,
            minors,
            collocated,
            omega_power,
            degree: n_b.degree(OMEGA),
        });
    }
    // The numerator's sign at 0 (a zero there only matters in exact mode,
    // which needs no sign).
    let exact = events.len() == 1 && events[0].direct;
    let (at_zero, nm_exact) = match at_zero_poly.orthant_sign() {
        Some(s) => (s, false),
        None if exact && at_zero_poly.is_zero() => (0, true),
        None => return None,
    };
    let inputs = ConfigurationInputs {
        blocks: events,
        scale: -c_sign,
        at_zero,
        at_inf: num_at_inf,
        nm_exact,
    };
    Some(BlockSignData {
        certificate: BlockPoleSigns { blocks },
        configurations: inputs.configurations(false)?,
        inputs,
        zeros,
    })
}

/// `p`'s factorization read as signs: the sign of everything but the
/// minors, and the minors with their exponents. `None` if a factor is none
/// of: of one sign, `Omega`, a rational multiple of a run's determinant.
fn signed_factors(p: &Poly, runs: &[(usize, usize, Poly)]) -> Option<(i32, Vec<Minor>)> {
    let f = factor(p);
    let mut sign = f.unit.signum();
    let mut minors = Vec::new();
    let om = Poly::var(OMEGA);
    for (g, k) in &f.factors {
        if g.degree(OMEGA) == 0 {
            sign *= g.orthant_sign()?.pow(*k);
        } else if *g != om {
            let (start, len, s) = runs
                .iter()
                .find_map(|(st, l, m)| ratio_sign(g, m).map(|s| (*st, *l, s)))?;
            minors.push(Minor {
                start,
                len,
                sign: s,
                exponent: *k,
            });
        }
    }
    Some((sign, minors))
}
#[cfg(test)]
mod tests {
    use crate::analysis::frf_type_at;
    use crate::xorshift::XorShift;
    use crate::{enumerate, Model, OMEGA};
    use poly::{det, Poly, Rat};
    use std::collections::BTreeMap;

    /// A second route to every block pole-sign configuration: the type at
    /// random exact points (each classified by exact root isolation) must
    /// fit some configuration, for every model of four masses and some of
    /// five. A sign slip in the configurations (say, a block without poles
    /// left out of the product) excludes types that occur.
    #[test]
    fn observed_types_fit_some_configuration() {
        let mut models: Vec<Model> = enumerate::degradation_free_models(4).unwrap();
        models.extend(
            enumerate::degradation_free_models(5)
                .unwrap()
                .into_iter()
                .step_by(9),
        );
        // Where Rolle's bound across resonances decides types, and one
        // order lower (also for the zeros' inverses).
        for id in [
            "N5-g1-a2.1-s5.1",
            "N5-g4-a5.1-s5.4",
            "N5-g3-a4.1-s5.3",
            "N5-g3-a4.3-s5.1",
        ] {
            models.push(Model::from_id(id).unwrap());
        }
        let mut rng = XorShift::new(97);
        let mut checked = 0;
        for m in &models {
            let tf = m.undamped_tf();
            let Some(d) = super::block_pole_sign_data(m, &tf.num, &tf.den) else {
                continue;
            };
            let Some(late) = d.inputs.configurations(true) else {
                continue;
            };
            for _ in 0..150 {
                let point: BTreeMap<String, Rat> = m
                    .undamped_parameters()
                    .into_iter()
                    .map(|p| {
                        let v = rng.log_uniform(1.0 / 64.0, 64.0);
                        (
                            p,
                            Rat::new(((v * 1000.0).round() as i64).into(), 1000.into()),
                        )
                    })
                    .collect();
                let t = frf_type_at(&tf.num, &tf.den, OMEGA, &point).unwrap();
                assert!(
                    late.fits(&t, d.zeros),
                    "{m}: {t} at {point:?} fits no configuration"
                );
                checked += 1;
            }
        }
        assert!(checked >= 1000, "{checked}");
    }

    /// The same second route where the configurations matter most: on
    /// the varieties where the two blocks share an eigenvalue (the
    /// cancellations), which random points of the orthant never hit. Each
    /// point puts a rational `lambda` on both blocks exactly, one mass of
    /// each solved for (a block's determinant is linear in each of its
    /// masses); its type, with the cancelled pole, must fit some
    /// configuration. The bounds across the eigenvalues between samples
    /// exclude types here (three zeros below a shared first pole of
    /// N5-g2-a3.1-s3.2); a slip in them would show.
    #[test]
    fn types_on_shared_eigenvalues_fit_some_configuration() {
        let mut models: Vec<Model> = enumerate::degradation_free_models(4).unwrap();
        models.extend(enumerate::degradation_free_models(5).unwrap());
        let mut rng = XorShift::new(2027);
        let (mut checked, mut cancelled, mut twice) = (0, 0, 0);
        for m in &models {
            let tf = m.undamped_tf();
            let Some(d) = super::block_pole_sign_data(m, &tf.num, &tf.den) else {
                continue;
            };
            let (mass, stiff) = (m.mass_matrix(), m.stiffness_matrix());
            let blocks = super::chain_blocks(&stiff);
            if blocks.len() != 2 || d.inputs.blocks.len() != 2 {
                continue;
            }
            let Some(late) = d.inputs.configurations(true) else {
                continue;
            };
            let dets: Vec<Poly> = blocks
                .iter()
                .map(|b| det(&super::pencil(&mass, &stiff, b)))
                .collect();
            let params = m.undamped_parameters();
            for _ in 0..40 {
                let draw = |rng: &mut XorShift| {
                    let v = rng.log_uniform(1.0 / 16.0, 16.0);
                    Rat::new(((v * 1000.0).round() as i64).into(), 1000.into())
                };
                let lambda = draw(&mut rng);
                let solved: Vec<String> = blocks
                    .iter()
                    .map(|b| format!("m{}", b[(rng.next_u64() % b.len() as u64) as usize] + 1))
                    .collect();
                let mut point: BTreeMap<String, Rat> = params
                    .iter()
                    .filter(|p| !solved.contains(p))
                    .map(|p| (p.clone(), draw(&mut rng)))
                    .collect();
                let mut ok = true;
                for (k, x) in solved.iter().enumerate() {
                    // det_B(lambda) = a + b x, linear in the mass x.
                    let mut q = dets[k].subs(OMEGA, &lambda);
                    for (p, v) in &point {
                        q = q.subs(p, v);
                    }
                    let c = q.coeffs_in(x);
                    let (a, b) = (c[0].as_constant().unwrap(), c[1].as_constant().unwrap());
                    let root = &(-&a) / &b;
                    ok &= root > Rat::ZERO;
                    point.insert(x.clone(), root);
                }
                if !ok {
                    continue;
                }
                let t = frf_type_at(&tf.num, &tf.den, OMEGA, &point).unwrap();
                let poles = tf.den.degree(OMEGA) as usize;
                cancelled += usize::from((t.resonances() as usize) < poles);
                assert!(
                    late.fits(&t, d.zeros),
                    "{m}: {t} at {point:?} fits no configuration"
                );
                checked += 1;
                // The shared pole cancelled twice: scaling block 0's masses
                // and springs by `s` keeps its eigenvalues and divides its
                // term by `s`, so one `s` makes the residues at `lambda`
                // add up to zero, where the numerator's derivative
                // vanishes too.
                let scaled: BTreeMap<String, Poly> = point
                    .iter()
                    .map(|(p, v)| {
                        let mass = p[1..2].parse::<usize>().unwrap() - 1;
                        let c = Poly::constant(v.clone());
                        let c = if blocks[0].contains(&mass) {
                            &c * &Poly::var("s")
                        } else {
                            c
                        };
                        (p.clone(), c)
                    })
                    .collect();
                let mut slope = tf.num.derivative(OMEGA).subs(OMEGA, &lambda);
                for (p, q) in &scaled {
                    slope = slope.subs_poly(p, q);
                }
                let slope = slope.div_monomial(&slope.monomial_content());
                let c = slope.coeffs_in("s");
                if c.len() != 2 {
                    continue;
                }
                let s = -&(&c[0].as_constant().unwrap() / &c[1].as_constant().unwrap());
                if s <= Rat::ZERO {
                    continue;
                }
                let at: BTreeMap<String, Rat> = scaled
                    .iter()
                    .map(|(p, q)| (p.clone(), q.subs("s", &s).as_constant().unwrap()))
                    .collect();
                let once = t;
                let t = frf_type_at(&tf.num, &tf.den, OMEGA, &at).unwrap();
                twice += usize::from(t.resonances() < once.resonances());
                assert!(
                    late.fits(&t, d.zeros),
                    "{m}: {t} at {at:?} (cancelled twice) fits no configuration"
                );
            }
        }
        assert!(
            checked >= 1000 && cancelled >= 500 && twice >= 300,
            "{checked} {cancelled} {twice}"
        );
    }
}
