//! The on-disk format of an analysis table: what `mms analyze --format
//! json` writes, what `mms check` reads, and what a program loads to look
//! up a model's verdicts.
//!
//! One type family, serde both ways: [`AnalysisTable`] holds what the file
//! covers, the versions and search limits it was made with, and one
//! [`TableModel`] per model (its [`ModelAnalysis`] with the witnesses and
//! certificates, and the fields derived from the whole table). The file
//! names its format and [`TABLE_FORMAT_VERSION`]; a file of another
//! version is refused, never half read.
//!
//! ```
//! use mms::analysis::{analyze, FrfType, SearchLimits, Status};
//! use mms::table::{AnalysisTable, Covers, TableModel};
//!
//! let a2 = mms::Model::from_id("A2")?;
//! let model = TableModel::new(analyze(&a2, &SearchLimits::default()));
//! let table = AnalysisTable::new(Covers::Models(vec![a2.id()]), vec![model]);
//! let text = table.to_json();
//!
//! // Read back, and queried by the paper's ID or the generic one.
//! let read = AnalysisTable::from_json(&text)?;
//! assert_eq!(read, table);
//! let ty: FrfType = "RAR".parse()?;
//! assert_eq!(read.model("A2").unwrap().status(&ty), Some(Status::Possible));
//! assert_eq!(read.model("N3-g0-a1.0-s2.0").unwrap().status(&ty), Some(Status::Possible));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::analysis::{FrfType, ModelAnalysis, SearchLimits, Status, TypeVerdict, ENGINE_VERSION};
use crate::identifiability::UnidentifiableDirection;
use serde::{Deserialize, Serialize};

/// The format's name, the first thing a reader checks.
pub const TABLE_FORMAT: &str = "mms-analysis-table";

/// The version of the format: raised whenever a field is added, removed or
/// changes meaning, so that no reader takes a file for what it is not.
pub const TABLE_FORMAT_VERSION: u32 = 1;

/// A table of analyses (see the [module docs](self)).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AnalysisTable {
    /// [`TABLE_FORMAT`].
    pub format: String,
    /// [`TABLE_FORMAT_VERSION`].
    pub format_version: u32,
    /// The version of mms that wrote it.
    pub mms_version: String,
    /// The decision procedure's version ([`ENGINE_VERSION`]).
    pub engine_version: u32,
    /// How far the search went.
    pub search_limits: SearchLimits,
    /// What the table claims to cover; `mms check` holds it to that.
    pub covers: Covers,
    /// One entry per model, in the table's order.
    pub models: Vec<TableModel>,
    /// The run's times (`mms analyze --timings`); no claim.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub timing: Option<RunTiming>,
}

/// What a table claims to cover.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Covers {
    /// Every renumbering class of this many masses, once.
    Masses(usize),
    /// Exactly these models (generic IDs).
    Models(Vec<String>),
}

/// One model of a table: its analysis and what the table derives for it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TableModel {
    /// The model's analysis: transfer function, verdicts with witnesses and
    /// certificates, cancellations, critical factors.
    #[serde(flatten)]
    pub analysis: ModelAnalysis,
    /// For each possible type, the other models of the table that can
    /// show it (the paper's "potentially similar systems").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub similar: Option<Vec<SimilarSystems>>,
    /// The number of parameters the FRF determines (the paper's Tab. 5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub determinable_parameters: Option<usize>,
    /// The number of moment invariants that are not constant (Tab. 5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub moment_invariants: Option<usize>,
    /// The directions along which the FRF does not change: the proof of
    /// the upper bound of `determinable_parameters`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unidentifiable_directions: Option<Vec<UnidentifiableDirection>>,
    /// The analysis time (`mms analyze --timings`); no claim.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub timing: Option<ModelTiming>,
}

/// The models of a table that can show a type too.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct SimilarSystems {
    /// The type.
    #[serde(rename = "type")]
    pub frf_type: FrfType,
    /// The other models (IDs as in the table) with that type possible.
    pub models: Vec<String>,
}

/// The times of a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunTiming {
    /// Wall time of the run.
    pub wall_seconds: f64,
    /// Worker threads.
    pub threads: usize,
    /// Models analysed or read from the cache.
    pub models_analysed: usize,
    /// Of those, read from the cache.
    pub models_from_cache: usize,
}

/// The time of one model's analysis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelTiming {
    /// Seconds of analysis (as recorded when it came from the cache).
    pub seconds: f64,
    /// Whether it came from the cache.
    pub cached: bool,
}

/// Why a text is not a table this version reads.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum TableError {
    /// Not JSON, or not the format's structure (with line and column).
    #[error("not an analysis table: {0}")]
    Json(String),
    /// Another format, or none named.
    #[error(
        "format {found:?}: not an analysis table written by mms analyze (expected format \
         {TABLE_FORMAT:?}; files written before the format was versioned have none: rerun \
         mms analyze)"
    )]
    Format {
        /// The format the file names (empty: none).
        found: String,
    },
    /// A version of the format this mms does not read.
    #[error(
        "format version {found}: this mms reads version {TABLE_FORMAT_VERSION} (rerun mms \
         analyze with this version)"
    )]
    Version {
        /// The file's version.
        found: u64,
    },
}

impl AnalysisTable {
    /// A table of `models` made by this version of mms with the default
    /// search limits.
    pub fn new(covers: Covers, models: Vec<TableModel>) -> AnalysisTable {
        AnalysisTable {
            format: TABLE_FORMAT.to_string(),
            format_version: TABLE_FORMAT_VERSION,
            mms_version: env!("CARGO_PKG_VERSION").to_string(),
            engine_version: ENGINE_VERSION,
            search_limits: SearchLimits::default(),
            covers,
            models,
            timing: None,
        }
    }

    /// Reads a table: its format and version first (a file of another
    /// version is refused as such), then the whole structure.
    pub fn from_json(text: &str) -> Result<AnalysisTable, TableError> {
        #[derive(Deserialize)]
        struct Header {
            format: Option<serde_json::Value>,
            format_version: Option<serde_json::Value>,
        }
        let header: Header =
            serde_json::from_str(text).map_err(|e| TableError::Json(e.to_string()))?;
        match header.format {
            Some(serde_json::Value::String(f)) if f == TABLE_FORMAT => {}
            Some(serde_json::Value::String(f)) => return Err(TableError::Format { found: f }),
            _ => {
                return Err(TableError::Format {
                    found: String::new(),
                })
            }
        }
        match header
            .format_version
            .as_ref()
            .and_then(serde_json::Value::as_u64)
        {
            Some(v) if v == u64::from(TABLE_FORMAT_VERSION) => {}
            Some(v) => return Err(TableError::Version { found: v }),
            None => {
                return Err(TableError::Json(
                    "missing field `format_version` (a whole number)".into(),
                ))
            }
        }
        serde_json::from_str(text).map_err(|e| TableError::Json(e.to_string()))
    }

    /// The table as pretty JSON, every object's keys in sorted order, so
    /// the same table gives the same bytes.
    pub fn to_json(&self) -> String {
        // Through a `Value`, whose maps keep their keys sorted.
        let v = self.to_value();
        let mut s = serde_json::to_string_pretty(&v).expect("a JSON value serializes");
        s.push('\n');
        s
    }

    /// The table as a JSON value (keys sorted).
    pub fn to_value(&self) -> serde_json::Value {
        serde_json::to_value(self).expect("an analysis table serializes")
    }

    /// The model with this ID (the paper's, e.g. `A2` or `A1*`, or the
    /// generic one), if the table has it.
    pub fn model(&self, id: &str) -> Option<&TableModel> {
        let id = id.trim_end_matches('*');
        self.models
            .iter()
            .find(|m| m.analysis.id.trim_end_matches('*') == id || m.analysis.generic_id == id)
    }
}

impl TableModel {
    /// An entry with the analysis only (no derived fields).
    pub fn new(analysis: ModelAnalysis) -> TableModel {
        TableModel {
            analysis,
            similar: None,
            determinable_parameters: None,
            moment_invariants: None,
            unidentifiable_directions: None,
            timing: None,
        }
    }

    /// The verdict on `frf_type`, with its witness or certificate, if the
    /// type is a candidate of the model.
    pub fn verdict(&self, frf_type: &FrfType) -> Option<&TypeVerdict> {
        self.analysis.types.iter().find(|v| &v.frf_type == frf_type)
    }

    /// The status of `frf_type` (possible, impossible or unknown), if the
    /// type is a candidate of the model.
    pub fn status(&self, frf_type: &FrfType) -> Option<Status> {
        self.verdict(frf_type).map(|v| v.status)
    }
}
