//! How often points on a type's own region show it: evidence, never a
//! proof, for the types an analysis leaves unknown.
//!
//! A type with root coincidences lives on a variety that log-uniform
//! points never hit, so each coincidence structure of a model's unknown
//! types (its number of cancelled poles and the multiplicities of its
//! multiple zeros) is sampled on its own variety: the variety sampler's
//! starts, projected onto it and read in `f64` with the posed roots
//! divided out ([`super::variety`]); the generic types (no coincidence)
//! at log-uniform points. Where the chain's gap splits it into two blocks,
//! two cancelled poles may also be one eigenvalue the blocks share, a
//! pair cancelled together: a point where two single cancellations meet,
//! which the single structure's Jacobian drops rank at and so never
//! reads. A structure with two or more cancelled poles is therefore also
//! sampled with one pair, two pairs, ... posed as such
//! ([`Cell::pairs`]). The counts say how many starts reached the
//! variety, how many of those could be read (the conditions' Jacobian of
//! full rank, so not a point where two posed roots are about to meet,
//! which `f64` misreads; no two roots within a relative `1e-6`), and how
//! often each type was read. A type read often
//! is possible in all likelihood and wants a witness; one never read in
//! `10^6` starts lies, if anywhere, in a region thinner than the sampler
//! reaches. A type the table certifies impossible that the sampler reads
//! is a misreading in `f64` or a wrong certificate, and is worth a look.

use super::frf_type::FrfType;
use super::isolated::block_pose;
use super::targeted::root_signature;
use super::variety::{BlockFactors, Variety};
use crate::model::Model;
use crate::tf::{UndampedCoefficients, OMEGA};
use crate::xorshift::XorShift;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The version of the sampler: raised whenever a change can alter its
/// counts, so that stored counts (`mms sample --cache`) made by another
/// version are sampled again. The engine's version does not enter: the
/// counts depend on the model and the cell's structure, not on the
/// verdicts.
pub const SAMPLER_VERSION: u32 = 5;

/// The sampler's start box: parameters log-uniform within
/// `e^-RANGE .. e^RANGE`, as the prover's.
pub const SAMPLING_RANGE: f64 = 3.0;

/// One coincidence structure of a model's types, with the types of it
/// that are asked about.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Cell {
    /// Cancelled poles.
    pub cancelled: u32,
    /// Of the cancelled poles, the pairs cancelled together where the
    /// chain's two blocks share an eigenvalue (`2 * pairs <= cancelled`).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub pairs: u32,
    /// Multiplicities of the multiple zeros, in the order of the type.
    pub multiple: Vec<u32>,
    /// The types asked about.
    pub types: Vec<FrfType>,
}

fn is_zero(n: &u32) -> bool {
    *n == 0
}

/// What the sampler read on one [`Cell`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CellSample {
    /// The cell.
    pub cell: Cell,
    /// Starts drawn.
    pub starts: u64,
    /// Starts projected onto the variety inside the box.
    pub converged: u64,
    /// Points of those read as a type (regular, roots apart).
    pub read: u64,
    /// Every type read, with how often (not only the cell's).
    pub seen: BTreeMap<FrfType, u64>,
}

/// The cells of `types` for `model`: its types grouped by coincidence
/// structure, the generic ones (no coincidence) in the cell with none;
/// where the chain has a gap, a structure with `c >= 2` cancelled poles
/// is also asked about with `1 ..= c / 2` of them cancelled in pairs (the
/// same types, [`Cell::pairs`]).
///
/// ```
/// use mms::analysis::cells;
/// let m = mms::Model::from_id("B2")?;
/// let types = ["RA^2R".parse()?, "ARR".parse()?, "RAR".parse()?];
/// let c = cells(&m, &types);
/// assert_eq!((c[0].cancelled, c[0].multiple.len(), c[0].types.len()), (0, 0, 2));
/// assert_eq!(c[1].multiple, [2]);
/// // A gap between masses 2 and 3: two cancelled poles may be one pair.
/// let m = mms::Model::from_id("N5-g2-a3.1-s3.2")?;
/// let c = cells(&m, &["AARR".parse()?]);
/// assert_eq!(c.iter().map(|c| (c.cancelled, c.pairs)).collect::<Vec<_>>(), [(2, 0), (2, 1)]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn cells(model: &Model, types: &[FrfType]) -> Vec<Cell> {
    let tf = model.undamped_tf();
    let degree = tf.den.degree(OMEGA);
    let mut by: BTreeMap<(u32, Vec<u32>), Vec<FrfType>> = BTreeMap::new();
    for t in types {
        let key = root_signature(t, degree).unwrap_or((0, Vec::new()));
        by.entry(key).or_default().push(t.clone());
    }
    let gap = block_pose(model, &tf.num, &tf.den).is_some();
    let mut out = Vec::new();
    for ((cancelled, multiple), types) in by {
        let most = if gap { cancelled / 2 } else { 0 };
        for pairs in 0..=most {
            out.push(Cell {
                cancelled,
                pairs,
                multiple: multiple.clone(),
                types: types.clone(),
            });
        }
    }
    out
}

/// How far (relative) the sampler keeps a multiple zero of multiplicity
/// `mu` from the other roots before it reads a point: the projection
/// leaves residuals of about `1e-13`, which place an `mu`-fold zero only
/// to about their `mu`-th root, so closer than a hundred times that its
/// order against a pole is not known (at 10^6 starts a double zero within
/// `1e-5` of a pole of N5-g1-a2.1-s5.1 read as a certified type, while
/// the exact type at the point rounded to twelve digits was another).
fn multiple_apart(mu: u32) -> f64 {
    if mu < 2 {
        0.0
    } else {
        100.0 * 1e-13f64.powf(1.0 / f64::from(mu))
    }
}

/// Samples `cell` of `model` at `starts` starts from the seed `seed`,
/// calling `progress` with the number of starts done after every 1000.
/// The same arguments give the same counts.
///
/// ```
/// use mms::analysis::{cells, sample_cell};
/// let m = mms::Model::from_id("B2")?;
/// // Points on the variety of B2's double zeros read as types with one.
/// let types = ["RA^2R".parse()?, "ARR".parse()?];
/// let c = cells(&m, &types);
/// let s = sample_cell(&m, &c[1], 2000, 1, |_| {});
/// assert!(s.converged > 0);
/// assert!(s.seen.keys().any(|t| t.to_string().contains("A^2")));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn sample_cell(
    model: &Model,
    cell: &Cell,
    starts: u64,
    seed: u64,
    mut progress: impl FnMut(u64),
) -> CellSample {
    let tf = UndampedCoefficients::new(model);
    let names = model.undamped_parameters();
    let params = names.len();
    let mut out = CellSample {
        cell: cell.clone(),
        starts,
        converged: 0,
        read: 0,
        seen: BTreeMap::new(),
    };
    let undamped = model.undamped_tf();
    let blocks = match cell.pairs {
        0 => None,
        _ => match block_pose(model, &undamped.num, &undamped.den) {
            Some(pose) if 2 * cell.pairs <= cell.cancelled => {
                Some(BlockFactors::new(&pose.factors, &names))
            }
            // No pair of this size can be posed: no point.
            _ => {
                progress(starts);
                return out;
            }
        },
    };
    let variety = Variety::new(&tf, params, cell.cancelled as usize, &cell.multiple);
    let variety = match &blocks {
        Some(b) => variety.with_doubles(cell.pairs as usize, b),
        None => variety,
    };
    let mut rng = XorShift::new(seed);
    for i in 0..starts {
        if i > 0 && i % 1000 == 0 {
            progress(i);
        }
        let Some(mut x) = variety.start(&mut rng, SAMPLING_RANGE) else {
            continue;
        };
        if !variety.project(&mut x, SAMPLING_RANGE) {
            continue;
        }
        out.converged += 1;
        if variety.free_parameters(&x).is_none() {
            continue;
        }
        if let Some(t) = variety.read_polished(&variety.point(&x), multiple_apart) {
            out.read += 1;
            *out.seen.entry(t).or_default() += 1;
        }
    }
    progress(starts);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_cancelled_together_read_what_single_cancellations_cannot() {
        // `AR` of N4-g2-a3.1-s3.2 cancels two of its three poles, and the
        // 4-mass table has an exact witness for it (which `mms check`
        // reads): the blocks share an eigenvalue there. Every point the
        // single structure reaches is such a point, where its Jacobian
        // drops rank, so it reads none; the pair posed reads them.
        let m = Model::from_id("N4-g2-a3.1-s3.2").unwrap();
        let ar: FrfType = "AR".parse().unwrap();
        let c = cells(&m, std::slice::from_ref(&ar));
        assert_eq!(
            c.iter().map(|c| (c.cancelled, c.pairs)).collect::<Vec<_>>(),
            [(2, 0), (2, 1)]
        );
        let single = sample_cell(&m, &c[0], 3000, 7, |_| {});
        let paired = sample_cell(&m, &c[1], 3000, 7, |_| {});
        assert!(single.converged > 100 && single.read == 0, "{single:?}");
        assert!(
            paired.seen.get(&ar).copied().unwrap_or(0) > 1000,
            "{paired:?}"
        );
        // Without a gap no pair can be posed: no point, not a panic.
        let collocated = Model::from_id("N4-g0-a1.0-s1.0").unwrap();
        let s = sample_cell(&collocated, &c[1], 100, 7, |_| {});
        assert_eq!((s.converged, s.read), (0, 0));
    }

    /// A point of N5-g1-a2.1-s5.1's double-zero cell found at 10^6 starts:
    /// its double zero `sigma` sits about `1e-5` from a pole, and read with
    /// the plain separation it is `RRRA^2R (nm)`, a type the table
    /// certifies impossible. The exact type at the point rounded to twelve
    /// digits (which splits the double zero by about `1e-6`) is another:
    /// the order of `sigma` and the pole is beyond `f64` there, and the
    /// sampler's wider guard leaves the point unread.
    #[test]
    fn a_double_zero_next_to_a_pole_is_not_read() {
        let m = Model::from_id("N5-g1-a2.1-s5.1").unwrap();
        let double: FrfType = "A^2RRRRAA".parse().unwrap();
        let cell = &cells(&m, &[double])[0];
        let tf = UndampedCoefficients::new(&m);
        let names = m.undamped_parameters();
        let variety = Variety::new(&tf, names.len(), 0, &cell.multiple);
        let params = vec![
            0.29288697961548177,
            0.1353561654402633,
            1.0767677647371494,
            4.964209868747783,
            0.15499435484408172,
            8.457894448010936,
            3.471283391656509,
            0.057099655354693295,
            4.340171791211278,
        ];
        let p = super::super::variety::VarietyPoint {
            params: params.clone(),
            cancelled: vec![],
            doubles: vec![],
            multiple: vec![(28.87737663243921, 2)],
        };
        let certified: FrfType = "RRRA^2R (nm)".parse().unwrap();
        assert_eq!(variety.read(&p), Some(certified.clone()));
        assert_eq!(variety.read_apart(&p, multiple_apart), None);
        let undamped = m.undamped_tf();
        let point: BTreeMap<String, poly::Rat> = names
            .iter()
            .zip(&params)
            .map(|(n, v)| {
                let scaled = (v * 1e12).round() as i64;
                (
                    n.clone(),
                    poly::Rat::new(scaled.into(), 1_000_000_000_000i64.into()),
                )
            })
            .collect();
        let exact = crate::analysis::frf_type_at(&undamped.num, &undamped.den, OMEGA, &point);
        assert_ne!(exact.unwrap(), certified);
    }

    /// A point of N6-g2-a3.1-s4.1's cell of two double zeros, found at
    /// 10^4 starts: its highest zero lies `2.5e-6` (relative) above the
    /// highest pole, and read from the numerator with the two double zeros
    /// divided out it falls below it: `RRA^2A^2RRAR`, a type the 6-mass
    /// table certifies impossible. Polished on the whole numerator it is
    /// above, as the exact type at the point says (the double zeros split
    /// there into a close real pair and a complex one, hence `(nm)`; the
    /// highest zero and pole stay where they are).
    #[test]
    fn a_zero_beside_a_pole_is_read_from_the_whole_numerator() {
        let m = Model::from_id("N6-g2-a3.1-s4.1").unwrap();
        let tf = UndampedCoefficients::new(&m);
        let names = m.undamped_parameters();
        let variety = Variety::new(&tf, names.len(), 0, &[2, 2]);
        let params = vec![
            0.27986903558340004,
            0.29447829409731147,
            0.382944676869866,
            0.1359599115451032,
            0.09977152672009296,
            0.07191326874249464,
            0.6232317077392437,
            0.15734851778187134,
            0.06726316983237396,
            0.09185920864332643,
            1.395357235604004,
        ];
        let p = super::super::variety::VarietyPoint {
            params: params.clone(),
            cancelled: vec![],
            doubles: vec![],
            multiple: vec![(0.688816755504153, 2), (0.6923987104334317, 2)],
        };
        let misread: FrfType = "RRA^2A^2RRAR".parse().unwrap();
        assert_eq!(variety.read_apart(&p, multiple_apart), Some(misread));
        let polished = variety.read_polished(&p, multiple_apart).unwrap();
        assert_eq!(polished.to_string(), "RRA^2A^2RRRA");
        let undamped = m.undamped_tf();
        let point: BTreeMap<String, poly::Rat> = names
            .iter()
            .zip(&params)
            .map(|(n, &v)| (n.clone(), poly::Rat::from_f64(v).unwrap()))
            .collect();
        let exact = crate::analysis::frf_type_at(&undamped.num, &undamped.den, OMEGA, &point);
        assert_eq!(exact.unwrap().to_string(), "RRAARRRA (nm)");
    }
}
