//! How often points on a type's own region show it: evidence, never a
//! proof, for the types an analysis leaves unknown.
//!
//! A type with root coincidences lives on a variety that log-uniform
//! points never hit, so each coincidence structure of a model's unknown
//! types (its number of cancelled poles and the multiplicities of its
//! multiple zeros) is sampled on its own variety: the variety sampler's
//! starts, projected onto it and read in `f64` with the posed roots
//! divided out ([`super::variety`]); the generic types (no coincidence)
//! at log-uniform points. The counts say how many starts reached the
//! variety, how many of those could be read (the conditions' Jacobian of
//! full rank, so not a point where two posed roots are about to meet,
//! which `f64` misreads; no two roots within a relative `1e-6`), and how
//! often each type was read. A type read often
//! is possible in all likelihood and wants a witness; one never read in
//! `10^6` starts lies, if anywhere, in a region thinner than the sampler
//! reaches. A type the table certifies impossible that the sampler reads
//! is a misreading in `f64` or a wrong certificate, and is worth a look.

use super::frf_type::FrfType;
use super::targeted::root_signature;
use super::variety::Variety;
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
pub const SAMPLER_VERSION: u32 = 1;

/// The sampler's start box: parameters log-uniform within
/// `e^-RANGE .. e^RANGE`, as the prover's.
pub const SAMPLING_RANGE: f64 = 3.0;

/// One coincidence structure of a model's types, with the types of it
/// that are asked about.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Cell {
    /// Cancelled poles.
    pub cancelled: u32,
    /// Multiplicities of the multiple zeros, in the order of the type.
    pub multiple: Vec<u32>,
    /// The types asked about.
    pub types: Vec<FrfType>,
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
/// structure, the generic ones (no coincidence) in the cell with none.
///
/// ```
/// use mms::analysis::cells;
/// let m = mms::Model::from_id("B2")?;
/// let types = ["RA^2R".parse()?, "ARR".parse()?, "RAR".parse()?];
/// let c = cells(&m, &types);
/// assert_eq!((c[0].cancelled, c[0].multiple.len(), c[0].types.len()), (0, 0, 2));
/// assert_eq!(c[1].multiple, [2]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn cells(model: &Model, types: &[FrfType]) -> Vec<Cell> {
    let degree = model.undamped_tf().den.degree(OMEGA);
    let mut by: BTreeMap<(u32, Vec<u32>), Vec<FrfType>> = BTreeMap::new();
    for t in types {
        let key = root_signature(t, degree).unwrap_or((0, Vec::new()));
        by.entry(key).or_default().push(t.clone());
    }
    by.into_iter()
        .map(|((cancelled, multiple), types)| Cell {
            cancelled,
            multiple,
            types,
        })
        .collect()
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
    let params = model.undamped_parameters().len();
    let variety = Variety::new(&tf, params, cell.cancelled as usize, &cell.multiple);
    let mut rng = XorShift::new(seed);
    let mut out = CellSample {
        cell: cell.clone(),
        starts,
        converged: 0,
        read: 0,
        seen: BTreeMap::new(),
    };
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
        if let Some(t) = variety.read(&variety.point(&x)) {
            out.read += 1;
            *out.seen.entry(t).or_default() += 1;
        }
    }
    progress(starts);
    out
}
