//! # mms: multiple-mass models of electromechanical motion systems
//!
//! The model layer of a reproduction of Tantau, Helmke, Perner, Wielitzka,
//! *Distinguishability study of 3-Mass Models for Electromechanical Motion
//! Systems*:
//!
//! - [`Model`]: `N` masses in a chain ground - m1 - ... - mN with one gap
//!   (the missing spring), one actuator and one sensor, validated against
//!   rule (1) of the paper; parameter names (`m1`, `c12`, `d12`, ...), the
//!   paper's IDs (`A1` .. `C4`) and a generic ID (`N3-g0-a1.0-s2.0`);
//! - enumeration ([`basic_models`], [`degradation_free_models`],
//!   [`rule3_models`]) reproducing Tab. 1, and the true equivalence classes
//!   under renumbering of masses ([`equivalence_classes`],
//!   [`redundancy_report`]);
//! - the chain matrices `M`, `C`, `D`, `b`, `c` and exact symbolic transfer
//!   functions: undamped in `Omega = omega^2 = -s^2` ([`UndampedTf`],
//!   [`OmegaTf`]) and damped in `s` ([`DampedTf`]), for position, velocity
//!   or acceleration output ([`Output`]);
//! - paper-style rendering as text, LaTeX or Markdown ([`render`]);
//! - moment invariants, determinable parameters (Tab. 5) and structural
//!   equivalence of models ([`mod@identifiability`], [`structural_equivalences`]);
//! - the numeric damped frequency response and its parameter derivatives
//!   ([`response`]), for fitting, and model files in TOML ([`model_file`]);
//! - a nonlinear time simulation with Coulomb friction and backlash
//!   ([`simulate`]);
//! - several sensors on one chain ([`sensors`]): which structures a sensor
//!   set tells apart, with checkable witnesses;
//! - analytic back-solving: every positive parameter set of a structure
//!   reproducing a given undamped inertance, or its families, or why there
//!   is none ([`backsolve`]);
//! - FRF-type analysis with witnesses and certificates ([`analysis`]), and
//!   an independent exact checker of its output ([`check`]).
//!
//! The library does no terminal I/O; errors are typed ([`ModelError`]).
//!
//! ```
//! use mms::{render::RenderOptions, Model, Output};
//!
//! let a2 = Model::from_id("A2")?; // force on m1, position of m2, free chain
//! let tf = a2.undamped_tf(); // inertance num/den in Omega
//! assert_eq!(tf.num.to_string(), "-Omega*c12*m3 + c12*c23"); // eq. (21)
//! assert_eq!(
//!     tf.den.to_string(),
//!     "Omega^2*m1*m2*m3 - Omega*c12*m1*m3 - Omega*c12*m2*m3 - Omega*c23*m1*m2 \
//!      - Omega*c23*m1*m3 + c12*c23*m1 + c12*c23*m2 + c12*c23*m3"
//! ); // eq. (10)
//! let latex = tf.render(&RenderOptions::latex());
//! assert!(latex.starts_with(r"\frac{-c_{12} m_{3} \Omega + c_{12} c_{23}}{m_{1.2.3} \Omega^{2}"));
//!
//! let damped = a2.damped_tf(Output::Position);
//! assert_eq!(damped.den.degree("s"), 6);
//! # Ok::<(), mms::ModelError>(())
//! ```

#![warn(missing_docs)]

pub mod analysis;
pub mod backsolve;
pub mod check;
mod enumerate;
pub mod identifiability;
mod model;
pub mod model_file;
pub mod paper;
pub mod ranges;
pub mod render;
pub mod response;
pub mod sensors;
pub mod simulate;
pub mod table;
mod tf;
pub mod xorshift;

pub use crate::backsolve::{
    back_solve, back_solve_with, invariant_relations, BackSolution, BackSolveError, Target,
};
pub use crate::enumerate::{
    basic_models, class_representatives, counts, degradation_free_models, equivalence_classes,
    redundancy_report, rule3_models, Counts, RedundancyReport, Symmetry,
};
pub use crate::identifiability::{
    identical_transfer_functions, identifiability, identifiability_with, mirror_renaming,
    moment_invariants, structural_equivalences, Equivalence, EquivalenceGroup, EquivalenceReason,
    Identifiability, MomentInvariant, ParameterRenaming, RankCertificate, RankOptions,
    ScalingSymmetry, TfPart,
};
pub use crate::model::{
    damper_name, mass_name, spring_name, Model, ModelError, Port, MAX_MASSES, PAPER_IDS,
};
pub use crate::sensors::{
    check_distinguishability_witness, sensor_set_distinguishability, two_sensor_pairs, SensorSet,
    SensorSetVerdict,
};
pub use crate::tf::{
    DampedTf, OmegaTf, Output, ParseOutputError, UndampedCoefficients, UndampedTf, OMEGA, S,
};
