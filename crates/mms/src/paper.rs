//! The paper's printed tables, as data: what reports compare against and
//! tests check the derived results with. Typed in from the paper once;
//! nothing in the analysis reads them.

/// Tab. 1: (masses, basic models, degradation-free, after rule (3)).
pub const TAB1: [(usize, usize, usize, usize); 5] = [
    (1, 1, 1, 1),
    (2, 8, 5, 3),
    (3, 34, 17, 11),
    (4, 104, 50, 29),
    (5, 259, 129, 73),
];

/// Tab. 3: (ID, possible FRF types), in the paper's order.
pub const TAB3: [(&str, &[&str]); 11] = [
    ("A1", &["ARAR"]),
    ("A2", &["ARR", "RAR", "R"]),
    ("A3", &["RR"]),
    ("A4", &["ARAR", "AR"]),
    ("A5", &["ARR", "RAR", "R"]),
    ("B1", &["ARAR", "AR"]),
    (
        "B2",
        &[
            "RRAA", "AARR", "RA", "ARRA", "RR (nm)", "AR", "A^2RR", "RRA^2", "C",
        ],
    ),
    ("C1", &["ARAR"]),
    ("C2", &["ARRA"]),
    ("C3", &["ARAR"]),
    ("C4", &["ARRA"]),
];

/// Tab. 5: (ID, determinable parameters, not identically constant moment
/// invariants); 5 parameters each.
pub const TAB5: [(&str, usize, usize); 11] = [
    ("A1", 5, 5),
    ("A2", 4, 4),
    ("A3", 3, 3),
    ("A4", 5, 5),
    ("A5", 4, 4),
    ("B1", 5, 5),
    ("B2", 4, 5),
    ("C1", 5, 5),
    ("C2", 4, 5),
    ("C3", 5, 5),
    ("C4", 4, 5),
];

/// Tab. 4: the generating model A2 and the paper's model to be built, A5,
/// as printed: masses m1 m2 m3, then the springs and dampers of each model
/// in the order of [`crate::Model::parameters`] (A2: c12 c23 d12 d23; A5
/// has no ground spring, so the printed c1 = 444 and d1 = 0.039 are read as
/// its c12 and d12). The printed A5 is not an exact match of A2's FRF (its
/// masses add up to 0.088 kg, A2's to 0.04 kg): see `docs/identification.md`.
pub const TAB4: [(&str, [f64; 7]); 2] = [
    ("A2", [0.01, 0.01, 0.02, 100.0, 100.0, 0.01, 0.01]),
    ("A5", [0.063, 0.015, 0.010, 444.0, 173.0, 0.039, 0.016]),
];

/// Tab. 6: the generating model B2 and the paper's optimised C2, as
/// printed, in the order of [`crate::Model::parameters`] (B2: c1 c23 d1
/// d23; C2: c1 c12 d1 d12).
pub const TAB6: [(&str, [f64; 7]); 2] = [
    ("B2", [0.01, 0.01, 0.01, 100.0, 200.0, 0.01, 0.01]),
    ("C2", [0.011, 0.0044, 0.030, 190.0, 96.0, 0.01, 0.01]),
];

/// Tab. 7: the A1 fit of the stacker crane's mast and the collocated
/// models with the same undamped FRF, as printed: (ID, m1 m2 m3 and the
/// two springs in the order of [`crate::Model::undamped_parameters`]). A4
/// and B1 have two solutions each.
pub const TAB7: [(&str, [f64; 5]); 7] = [
    ("A1", [0.0044, 0.0173, 0.0184, 46.8, 14.3]),
    ("A4", [0.0084, 0.0044, 0.0273, 31.4, 15.3]),
    ("A4", [0.0273, 0.0044, 0.0084, 15.3, 31.4]),
    ("B1", [0.038, 0.0049, 0.0351, 53.5, 58.9]),
    ("B1", [0.0056, 0.0194, 0.0206, 76.7, 14.2]),
    ("C1", [0.0049, 0.0091, 0.040, 31.5, 27.4]),
    ("C3", [0.0421, 0.0049, 0.040, 67.7, 58.9]),
];

/// The rows of [`TAB7`] printed for model `id` (two for A4 and B1).
///
/// ```
/// assert_eq!(mms::paper::tab7_rows("B1").len(), 2);
/// assert_eq!(mms::paper::tab7_rows("C1"), [[0.0049, 0.0091, 0.040, 31.5, 27.4]]);
/// ```
pub fn tab7_rows(id: &str) -> Vec<[f64; 5]> {
    TAB7.iter()
        .filter(|(r, _)| *r == id)
        .map(|(_, v)| *v)
        .collect()
}
