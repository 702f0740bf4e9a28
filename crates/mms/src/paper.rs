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
