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
pub const TABLE_FORMAT_VERSION: u32 = 9;

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
    /// One slice of the classes of `masses` masses ([`Shard`]), for a
    /// table computed on several machines and joined by [`merge`].
    Slice {
        /// The number of masses.
        masses: usize,
        /// Which slice.
        shard: Shard,
    },
}

/// Slice `index` of `count` (1-based) of the classes of a table: the
/// classes at positions `index - 1`, `index - 1 + count`, ... of
/// [`crate::equivalence_classes`] (every `count`-th, so the slow classes
/// spread over the slices).
///
/// ```
/// use mms::table::Shard;
/// let s: Shard = "2/3".parse()?;
/// assert!(s.holds(1) && s.holds(4) && !s.holds(2));
/// assert!("0/3".parse::<Shard>().is_err() && "4/3".parse::<Shard>().is_err());
/// # Ok::<(), mms::table::ShardError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// Which slice, from 1.
    pub index: usize,
    /// How many slices.
    pub count: usize,
}

/// A shard spec that is not `K/N` with `1 <= K <= N`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("shard {0:?}: expected K/N with 1 <= K <= N, e.g. 2/8 for the second of eight slices")]
pub struct ShardError(pub String);

impl std::str::FromStr for Shard {
    type Err = ShardError;
    fn from_str(s: &str) -> Result<Shard, ShardError> {
        let bad = || ShardError(s.to_string());
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let index: usize = k.trim().parse().map_err(|_| bad())?;
        let count: usize = n.trim().parse().map_err(|_| bad())?;
        if index == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl Shard {
    /// Whether the class at `position` (0-based, in the order of
    /// [`crate::equivalence_classes`]) is in this slice.
    pub fn holds(&self, position: usize) -> bool {
        position % self.count + 1 == self.index
    }
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
    /// The number of parameters the FRF determines (the paper's Tab. 5):
    /// the rank of the invariants' Jacobian, proven; a proven lower bound
    /// where `determinable_parameters_at_most` is given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub determinable_parameters: Option<usize>,
    /// Where the rank is only sampled (its symbolic proof too large, as at
    /// six masses): the proven upper bound, larger than
    /// `determinable_parameters`. The rank at random points is the lower
    /// bound and, with overwhelming probability, the rank itself.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub determinable_parameters_at_most: Option<usize>,
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
        self.to_json_on(1)
    }

    /// [`to_json`](Self::to_json) with the models written by `threads`
    /// threads at once: the same bytes, sooner for a table of many models.
    ///
    /// ```
    /// # use mms::analysis::{analyze, SearchLimits};
    /// # use mms::table::{AnalysisTable, Covers, TableModel};
    /// let models: Vec<TableModel> = ["A1", "A2"]
    ///     .iter()
    ///     .map(|id| TableModel::new(analyze(&mms::Model::from_id(id).unwrap(), &SearchLimits::default())))
    ///     .collect();
    /// let table = AnalysisTable::new(Covers::Models(vec!["A1".into(), "A2".into()]), models);
    /// assert_eq!(table.to_json_on(2), table.to_json());
    /// ```
    pub fn to_json_on(&self, threads: usize) -> String {
        // Through `Value`s, whose maps keep their keys sorted: the head
        // first, then each model's text into the place of "models", so
        // that a table of many models never holds a second tree of itself.
        let head = TableHead {
            format: &self.format,
            format_version: self.format_version,
            mms_version: &self.mms_version,
            engine_version: self.engine_version,
            search_limits: &self.search_limits,
            covers: &self.covers,
            models: [],
            timing: self.timing.as_ref(),
        };
        let head = serde_json::to_value(head).expect("a table's head serializes");
        let serde_json::Value::Object(fields) = head else {
            unreachable!("a struct serializes to an object")
        };
        let models = model_texts(&self.models, threads);
        let size: usize = models.iter().map(|m| m.len() + 2).sum();
        let mut out = String::with_capacity(size + 4096);
        out.push_str("{\n");
        for (i, (key, value)) in fields.iter().enumerate() {
            out.push_str("  ");
            out.push_str(&serde_json::to_string(key).expect("a key serializes"));
            out.push_str(": ");
            if key == "models" && !models.is_empty() {
                out.push_str("[\n");
                for (j, text) in models.iter().enumerate() {
                    out.push_str(text);
                    out.push_str(if j + 1 < models.len() { ",\n" } else { "\n" });
                }
                out.push_str("  ]");
            } else {
                let text = serde_json::to_string_pretty(value).expect("a JSON value serializes");
                push_indented(&mut out, &text, "  ");
            }
            out.push_str(if i + 1 < fields.len() { ",\n" } else { "\n" });
        }
        out.push_str("}\n");
        out
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

/// The fields of an [`AnalysisTable`] but its models, borrowed: what
/// [`AnalysisTable::to_json`] writes around them. The field names are the
/// table's (serde sorts them anyway).
#[derive(Serialize)]
struct TableHead<'a> {
    format: &'a str,
    format_version: u32,
    mms_version: &'a str,
    engine_version: u32,
    search_limits: &'a SearchLimits,
    covers: &'a Covers,
    models: [TableModel; 0],
    #[serde(skip_serializing_if = "Option::is_none")]
    timing: Option<&'a RunTiming>,
}

/// Each model as pretty JSON nested in the table's "models" (indented by
/// four spaces), in order; `threads` threads take the next model when
/// free.
fn model_texts(models: &[TableModel], threads: usize) -> Vec<String> {
    let one = |model: &TableModel| {
        let v = serde_json::to_value(model).expect("a table's model serializes");
        let text = serde_json::to_string_pretty(&v).expect("a JSON value serializes");
        let mut out = String::with_capacity(text.len() + text.len() / 8);
        out.push_str("    ");
        push_indented(&mut out, &text, "    ");
        out
    };
    let threads = threads.clamp(1, models.len().max(1));
    if threads == 1 {
        return models.iter().map(one).collect();
    }
    let next = std::sync::atomic::AtomicUsize::new(0);
    let mut texts: Vec<(usize, String)> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(model) = models.get(k) else { break };
                        done.push((k, one(model)));
                    }
                    done
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().expect("a model's text is written without panic"))
            .collect()
    });
    texts.sort_by_key(|(k, _)| *k);
    texts.into_iter().map(|(_, t)| t).collect()
}

/// Appends `text`, each line after the first indented by `indent`: a pretty
/// JSON value nested at that depth (a JSON string holds no raw newline).
fn push_indented(out: &mut String, text: &str, indent: &str) {
    for (k, line) in text.split('\n').enumerate() {
        if k > 0 {
            out.push('\n');
            out.push_str(indent);
        }
        out.push_str(line);
    }
}

impl AnalysisTable {
    /// Fills every model's `similar`: for each type it can show, the other
    /// models of the table that can show it too, in the table's order.
    pub fn fill_similar(&mut self) {
        let possible: Vec<Vec<&FrfType>> =
            self.models.iter().map(|m| m.analysis.possible()).collect();
        let similar: Vec<Vec<SimilarSystems>> = (0..self.models.len())
            .map(|i| {
                possible[i]
                    .iter()
                    .map(|t| SimilarSystems {
                        frf_type: (*t).clone(),
                        models: (0..self.models.len())
                            .filter(|&j| j != i && possible[j].contains(t))
                            .map(|j| self.models[j].analysis.id.clone())
                            .collect(),
                    })
                    .collect()
            })
            .collect();
        for (m, s) in self.models.iter_mut().zip(similar) {
            m.similar = Some(s);
        }
    }
}

/// Why slices of a table cannot be joined.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum MergeError {
    /// No slice given.
    #[error("no slice to merge")]
    Empty,
    /// A file that is not a slice.
    #[error("{file}: not a slice of a table (it covers {covers}); give the files of mms analyze --masses N --shard K/N")]
    NotASlice {
        /// The file.
        file: String,
        /// What it covers instead.
        covers: String,
    },
    /// A slice made otherwise than the first.
    #[error("{file}: {what} differs from {first}'s ({theirs} against {ours}); slices must come from the same version and settings")]
    Mismatch {
        /// The slice that differs.
        file: String,
        /// The first slice.
        first: String,
        /// What differs.
        what: &'static str,
        /// Its value in the slice that differs.
        theirs: String,
        /// Its value in the first slice.
        ours: String,
    },
    /// A model that is no class of the table's masses, or in the wrong
    /// slice.
    #[error("{file}: {model} {why}")]
    Foreign {
        /// The file.
        file: String,
        /// The model's ID.
        model: String,
        /// Why it does not belong.
        why: String,
    },
    /// Classes in more than one slice.
    #[error("overlap: the classes of {} are in more than one slice", .0.join(", "))]
    Overlap(Vec<String>),
    /// Classes in no slice.
    #[error("gap: the classes of {} are in no slice (of {total} classes)", .missing.join(", "))]
    Missing {
        /// Representatives of the missing classes.
        missing: Vec<String>,
        /// The number of classes.
        total: usize,
    },
}

/// Joins the slices of a table (`(file name, slice)`, any order) into the
/// whole table: every class once, in the table's order, the similar
/// systems computed over all of them, as `mms analyze --masses N` writes
/// it in one run. Slices of other versions or settings, overlaps and gaps
/// are refused, naming the file or the classes.
pub fn merge(slices: Vec<(String, AnalysisTable)>) -> Result<AnalysisTable, MergeError> {
    let (first_name, first) = slices.first().ok_or(MergeError::Empty)?;
    let slice_of = |name: &str, t: &AnalysisTable| match t.covers {
        Covers::Slice { masses, shard } => Ok((masses, shard.count)),
        ref other => Err(MergeError::NotASlice {
            file: name.to_string(),
            covers: format!("{other:?}"),
        }),
    };
    let (n, count) = slice_of(first_name, first)?;
    for (name, t) in &slices {
        let (masses, slices_count) = slice_of(name, t)?;
        let mismatch = |what: &'static str, theirs: String, ours: String| {
            Err(MergeError::Mismatch {
                file: name.clone(),
                first: first_name.clone(),
                what,
                theirs,
                ours,
            })
        };
        if masses != n {
            return mismatch("the number of masses", masses.to_string(), n.to_string());
        }
        if slices_count != count {
            return mismatch(
                "the number of slices",
                slices_count.to_string(),
                count.to_string(),
            );
        }
        if t.mms_version != first.mms_version {
            return mismatch(
                "the mms version",
                t.mms_version.clone(),
                first.mms_version.clone(),
            );
        }
        if t.engine_version != first.engine_version {
            return mismatch(
                "the engine version",
                t.engine_version.to_string(),
                first.engine_version.to_string(),
            );
        }
        if t.search_limits != first.search_limits {
            return mismatch(
                "the search limits",
                format!("{:?}", t.search_limits),
                format!("{:?}", first.search_limits),
            );
        }
    }
    let classes = crate::equivalence_classes(n, crate::Symmetry::Renumbering).map_err(|e| {
        MergeError::Foreign {
            file: first_name.clone(),
            model: format!("{n} masses"),
            why: e.to_string(),
        }
    })?;
    // What every slice shares, kept before the slices are taken apart.
    let made = AnalysisTable {
        covers: Covers::Masses(n),
        models: Vec::new(),
        timing: None,
        format: first.format.clone(),
        format_version: first.format_version,
        mms_version: first.mms_version.clone(),
        engine_version: first.engine_version,
        search_limits: first.search_limits.clone(),
    };
    // Each class's entries.
    let mut found: Vec<Vec<TableModel>> = vec![Vec::new(); classes.len()];
    for (name, t) in slices {
        let Covers::Slice { shard, .. } = t.covers else {
            unreachable!("checked above")
        };
        for m in t.models {
            let a = &m.analysis;
            let foreign = |why: String| MergeError::Foreign {
                file: name.clone(),
                model: a.id.clone(),
                why,
            };
            let model = crate::Model::from_id(&a.generic_id).map_err(|e| foreign(e.to_string()))?;
            let c = classes
                .iter()
                .position(|c| c.contains(&model))
                .ok_or_else(|| foreign(format!("is not a model of {n} masses")))?;
            if !shard.holds(c) {
                return Err(foreign(format!(
                    "is not in slice {}/{} (its class belongs to slice {}/{})",
                    shard.index,
                    shard.count,
                    c % shard.count + 1,
                    shard.count
                )));
            }
            found[c].push(m);
        }
    }
    let name_of = |c: usize| classes[c][0].id();
    let doubled: Vec<String> = (0..classes.len())
        .filter(|&c| found[c].len() > 1)
        .map(name_of)
        .collect();
    if !doubled.is_empty() {
        return Err(MergeError::Overlap(doubled));
    }
    let missing: Vec<String> = (0..classes.len())
        .filter(|&c| found[c].is_empty())
        .map(name_of)
        .collect();
    if !missing.is_empty() {
        return Err(MergeError::Missing {
            missing,
            total: classes.len(),
        });
    }
    // The table's order: that of the class representatives.
    let order = crate::class_representatives(n).map_err(|e| MergeError::Foreign {
        file: "the slices".into(),
        model: format!("{n} masses"),
        why: e.to_string(),
    })?;
    let mut table = made;
    for rep in &order {
        let c = classes
            .iter()
            .position(|c| c.contains(rep))
            .expect("every representative is of a class");
        let mut m = found[c].pop().expect("every class once, checked above");
        // Times are no claim, and differ from run to run.
        m.timing = None;
        table.models.push(m);
    }
    table.fill_similar();
    Ok(table)
}

impl TableModel {
    /// An entry with the analysis only (no derived fields).
    pub fn new(analysis: ModelAnalysis) -> TableModel {
        TableModel {
            analysis,
            similar: None,
            determinable_parameters: None,
            determinable_parameters_at_most: None,
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
