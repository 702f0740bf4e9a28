//! # ident: identification of multiple-mass models from measured FRFs
//!
//! Reads nothing from disk and writes nothing to the terminal: it takes a
//! measured [`frf::Frf`] and the model layer of [`mms`], and returns
//! classifications, fitted parameters and rankings as data.

#![warn(missing_docs)]

pub mod advice;
pub mod amplitude;
pub mod classify;
pub mod concealed;
pub mod diagnose;
pub mod diagnosis;
pub mod evidence;
pub mod fit;
pub mod identify;
pub mod idim;
pub mod joint;
pub mod nonlinear;
pub mod notes;
pub mod operating;
mod selection;
pub mod stability;
pub mod start;
pub mod synth;

pub use crate::classify::{
    classify, Classification, ClassifiedFeature, ClassifyError, ClassifyOptions, NmDip, NmEvidence,
};
