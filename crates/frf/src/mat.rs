//! MATLAB level-5 MAT-files (as saved by `save -v6` and `-v7`): numeric
//! variables.
//!
//! Layout: a 128-byte header (text, subsystem offset, version `0x0100`, and
//! the endian indicator `IM` little- or `MI` big-endian), then data
//! elements. Each element has an 8-byte tag (type, byte count) or, for at
//! most 4 bytes of data, the 4-byte "small element" tag; elements inside
//! an array are padded to 8 bytes. A variable is an `miMATRIX` element
//! (array flags, dimensions, name, real part, imaginary part), optionally
//! wrapped in an `miCOMPRESSED` element holding it zlib-compressed (v7).
//!
//! [`read_mat`] returns every numeric array (double, single, int8 ..
//! uint64, logical; real or complex) converted to `f64` in MATLAB's
//! column-major order, and lists the variables of other classes (cell,
//! char, sparse, objects, ...) in [`MatFile::skipped`]. The fields of a
//! scalar struct are read as variables of their own, named by their path
//! (`Data.signals.u`), to a nesting depth of [`MAX_STRUCT_DEPTH`]; a
//! struct array is listed as skipped.
//!
//! Every size read from the file is checked against the bytes that remain
//! before anything is allocated, so a truncated or garbled file gives an
//! error, never a panic or a huge allocation. Version 7.3 files (HDF5) are
//! recognised and refused.
//!
//! ```
//! // A minimal file: header, then `x = [1 2 3]` (1 x 3 double), uncompressed.
//! let mut f = vec![b' '; 116];
//! f[..10].copy_from_slice(b"MATLAB 5.0");
//! f.extend_from_slice(&[0; 8]);
//! f.extend_from_slice(&[0x00, 0x01, b'I', b'M']);
//! let le = |v: u32| v.to_le_bytes();
//! f.extend_from_slice(&le(14)); // miMATRIX
//! f.extend_from_slice(&le(16 + 16 + 8 + 8 + 24));
//! f.extend_from_slice(&le(6)); f.extend_from_slice(&le(8)); // array flags
//! f.extend_from_slice(&le(6)); f.extend_from_slice(&le(0)); // class double
//! f.extend_from_slice(&le(5)); f.extend_from_slice(&le(8)); // dims 1 x 3
//! f.extend_from_slice(&le(1)); f.extend_from_slice(&le(3));
//! f.extend_from_slice(&((1u32 << 16) | 1).to_le_bytes()); // small element: name "x"
//! f.extend_from_slice(&[b'x', 0, 0, 0]);
//! f.extend_from_slice(&le(9)); f.extend_from_slice(&le(24)); // miDOUBLE
//! for v in [1.0f64, 2.0, 3.0] { f.extend_from_slice(&v.to_le_bytes()); }
//!
//! let mat = frf::mat::read_mat(&f)?;
//! let x = mat.get("x").unwrap();
//! assert_eq!(x.dims, vec![1, 3]);
//! assert_eq!(x.real, vec![1.0, 2.0, 3.0]);
//! // Cut short, the same bytes are an error, not a panic.
//! assert!(frf::mat::read_mat(&f[..f.len() - 5]).is_err());
//! # Ok::<(), frf::mat::MatError>(())
//! ```

use std::fmt;

/// Largest inflated size accepted for one compressed variable (2 GiB):
/// deflate can expand about 1000-fold, so the compressed size alone does
/// not bound the memory a hostile file could ask for.
pub const MAX_INFLATED_BYTES: usize = 1 << 31;

/// How deeply structs may nest: deeper fields are an error, so a hostile
/// file cannot recurse without bound.
pub const MAX_STRUCT_DEPTH: usize = 16;

/// A problem in a MAT-file, naming the variable where it is known.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}{message}", match variable { Some(v) => format!("variable '{v}': "), None => String::new() })]
pub struct MatError {
    /// Name of the variable being read, if it was already known.
    pub variable: Option<String>,
    /// What is wrong.
    pub message: String,
}

fn err(message: impl Into<String>) -> MatError {
    MatError {
        variable: None,
        message: message.into(),
    }
}

/// Numeric class of a variable as MATLAB stores it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NumericClass {
    /// `double`.
    Double,
    /// `single`.
    Single,
    /// `int8`.
    Int8,
    /// `uint8`.
    UInt8,
    /// `int16`.
    Int16,
    /// `uint16`.
    UInt16,
    /// `int32`.
    Int32,
    /// `uint32`.
    UInt32,
    /// `int64`.
    Int64,
    /// `uint64`.
    UInt64,
    /// `logical` (stored as uint8 with the logical flag).
    Logical,
}

impl fmt::Display for NumericClass {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = match self {
            NumericClass::Double => "double",
            NumericClass::Single => "single",
            NumericClass::Int8 => "int8",
            NumericClass::UInt8 => "uint8",
            NumericClass::Int16 => "int16",
            NumericClass::UInt16 => "uint16",
            NumericClass::Int32 => "int32",
            NumericClass::UInt32 => "uint32",
            NumericClass::Int64 => "int64",
            NumericClass::UInt64 => "uint64",
            NumericClass::Logical => "logical",
        };
        f.write_str(s)
    }
}

/// A numeric variable, converted to `f64`.
#[derive(Clone, Debug, PartialEq)]
pub struct MatVariable {
    /// Variable name.
    pub name: String,
    /// Dimensions (at least two), e.g. `[40000, 2]`.
    pub dims: Vec<usize>,
    /// Class as stored in the file.
    pub class: NumericClass,
    /// Real part, column-major (`real[i + rows * j]` is element `(i, j)`).
    pub real: Vec<f64>,
    /// Imaginary part for complex variables.
    pub imag: Option<Vec<f64>>,
}

impl MatVariable {
    /// Number of elements.
    pub fn numel(&self) -> usize {
        self.real.len()
    }

    /// The value of a real 1 x 1 variable.
    pub fn scalar(&self) -> Option<f64> {
        (self.real.len() == 1 && self.imag.is_none()).then(|| self.real[0])
    }

    /// `rows x cols` if the variable has two dimensions.
    pub fn shape2(&self) -> Option<(usize, usize)> {
        match self.dims[..] {
            [r, c] => Some((r, c)),
            _ => None,
        }
    }
}

/// A variable of a class that [`read_mat`] does not convert.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SkippedVariable {
    /// Variable name (empty if the file did not give one).
    pub name: String,
    /// MATLAB class, e.g. `"cell"`, `"struct"`, `"char"`, `"sparse"`.
    pub class: String,
}

/// The contents of a MAT-file.
#[derive(Clone, Debug, PartialEq)]
pub struct MatFile {
    /// Descriptive text of the header (trimmed).
    pub header_text: String,
    /// Numeric variables in file order.
    pub variables: Vec<MatVariable>,
    /// Variables of other classes, listed but not read.
    pub skipped: Vec<SkippedVariable>,
}

impl MatFile {
    /// The first numeric variable called `name`.
    pub fn get(&self, name: &str) -> Option<&MatVariable> {
        self.variables.iter().find(|v| v.name == name)
    }

    /// The fields of the struct at `path` (`Data.signals`), numeric or
    /// not, in file order; empty if there is no such struct.
    pub fn fields(&self, path: &str) -> Vec<String> {
        let prefix = format!("{path}.");
        let mut out: Vec<String> = Vec::new();
        let names = self
            .variables
            .iter()
            .map(|v| &v.name)
            .chain(self.skipped.iter().map(|s| &s.name));
        for name in names {
            if let Some(rest) = name.strip_prefix(&prefix) {
                let field = rest.split('.').next().unwrap_or(rest).to_string();
                if !out.contains(&field) {
                    out.push(field);
                }
            }
        }
        out
    }
}

// Data types of elements.
const MI_INT8: u32 = 1;
const MI_UINT8: u32 = 2;
const MI_INT16: u32 = 3;
const MI_UINT16: u32 = 4;
const MI_INT32: u32 = 5;
const MI_UINT32: u32 = 6;
const MI_SINGLE: u32 = 7;
const MI_DOUBLE: u32 = 9;
const MI_INT64: u32 = 12;
const MI_UINT64: u32 = 13;
const MI_MATRIX: u32 = 14;
const MI_COMPRESSED: u32 = 15;
const MI_UTF8: u32 = 16;

/// One data element: its type and the bytes of its data.
struct Element<'a> {
    kind: u32,
    data: &'a [u8],
    /// Offset of the tag in the buffer it came from.
    offset: usize,
}

/// Reads the elements of a buffer in sequence.
struct Cursor<'a> {
    buf: &'a [u8],
    pos: usize,
    big: bool,
}

impl<'a> Cursor<'a> {
    fn u32_at(&self, at: usize) -> Option<u32> {
        let b: [u8; 4] = self.buf.get(at..at.checked_add(4)?)?.try_into().ok()?;
        Some(if self.big {
            u32::from_be_bytes(b)
        } else {
            u32::from_le_bytes(b)
        })
    }

    fn at_end(&self) -> bool {
        self.pos >= self.buf.len()
    }

    /// The next element; `pad` rounds the end of a full-size element up to
    /// a multiple of 8 bytes (not done after `miCOMPRESSED`, whose byte
    /// count is exact).
    fn next(&mut self, pad: bool) -> Result<Element<'a>, MatError> {
        let offset = self.pos;
        let remaining = self.buf.len() - offset;
        let first = self.u32_at(offset).ok_or_else(|| {
            err(format!(
                "truncated element tag at byte {offset} ({remaining} bytes left)"
            ))
        })?;
        if first >> 16 != 0 {
            // Small element: byte count in the upper half, data in the
            // next four bytes of the tag.
            let (kind, n) = (first & 0xffff, (first >> 16) as usize);
            if n > 4 {
                return Err(err(format!(
                    "small element at byte {offset} claims {n} bytes (at most 4)"
                )));
            }
            let data = self
                .buf
                .get(offset + 4..offset + 4 + n)
                .filter(|_| remaining >= 8)
                .ok_or_else(|| err(format!("truncated small element at byte {offset}")))?;
            self.pos = offset + 8;
            return Ok(Element { kind, data, offset });
        }
        let n = self
            .u32_at(offset + 4)
            .ok_or_else(|| err(format!("truncated element tag at byte {offset}")))?
            as usize;
        let start = offset + 8;
        if n > self.buf.len() - start {
            return Err(err(format!(
                "element at byte {offset} claims {n} bytes but only {} remain",
                self.buf.len() - start
            )));
        }
        let end = start + n;
        self.pos = if pad {
            // The last element of a buffer may omit its padding.
            end.checked_next_multiple_of(8)
                .unwrap_or(usize::MAX)
                .min(self.buf.len())
        } else {
            end
        };
        Ok(Element {
            kind: first,
            data: &self.buf[start..end],
            offset,
        })
    }
}

/// Reads a MAT-file from its bytes; see the [module documentation](self).
pub fn read_mat(bytes: &[u8]) -> Result<MatFile, MatError> {
    if bytes.len() < 128 {
        return Err(err(format!(
            "{} bytes are too few for a MAT-file header (128)",
            bytes.len()
        )));
    }
    let header_text = String::from_utf8_lossy(&bytes[..116])
        .trim_end_matches(['\0', ' '])
        .to_string();
    let big = match &bytes[126..128] {
        b"IM" => false,
        b"MI" => true,
        _ => {
            return Err(err(
                "not a MATLAB level-5 MAT-file (no endian indicator at byte 126)",
            ))
        }
    };
    let version = if big {
        u16::from_be_bytes([bytes[124], bytes[125]])
    } else {
        u16::from_le_bytes([bytes[124], bytes[125]])
    };
    if version == 0x0200 || header_text.starts_with("MATLAB 7.3") {
        return Err(err(
            "MAT-file version 7.3 (HDF5) is not supported: save with -v7",
        ));
    }
    if version != 0x0100 {
        return Err(err(format!(
            "unknown MAT-file version 0x{version:04x} (expected 0x0100)"
        )));
    }
    let mut out = MatFile {
        header_text,
        variables: Vec::new(),
        skipped: Vec::new(),
    };
    let mut top = Cursor {
        buf: bytes,
        pos: 128,
        big,
    };
    while !top.at_end() {
        // Some writers pad the file end with zeros.
        if bytes[top.pos..].iter().all(|&b| b == 0) {
            break;
        }
        let el = top.next(false)?;
        match el.kind {
            MI_COMPRESSED => {
                let inflated = miniz_oxide::inflate::decompress_to_vec_zlib_with_limit(
                    el.data,
                    MAX_INFLATED_BYTES,
                )
                .map_err(|e| {
                    err(format!(
                        "compressed element at byte {}: zlib data are corrupt or truncated ({:?})",
                        el.offset, e.status
                    ))
                })?;
                let mut inner = Cursor {
                    buf: &inflated,
                    pos: 0,
                    big,
                };
                while !inner.at_end() {
                    let el = inner.next(true)?;
                    match el.kind {
                        MI_MATRIX => read_matrix(el.data, big, &mut out, None, 0)?,
                        other => {
                            return Err(err(format!(
                                "compressed element at byte {} holds data type {other}, expected a matrix",
                                el.offset
                            )))
                        }
                    }
                }
            }
            MI_MATRIX => {
                read_matrix(el.data, big, &mut out, None, 0)?;
                // Uncompressed arrays are padded to 8 bytes.
                top.pos = top.pos.next_multiple_of(8).min(bytes.len());
            }
            other => {
                return Err(err(format!(
                    "element at byte {} has data type {other}, expected a matrix",
                    el.offset
                )))
            }
        }
    }
    Ok(out)
}

fn class_name(class: u32) -> String {
    match class {
        1 => "cell".into(),
        2 => "struct".into(),
        3 => "object".into(),
        4 => "char".into(),
        5 => "sparse".into(),
        16 => "function handle".into(),
        17 => "opaque object".into(),
        c => format!("unknown class {c}"),
    }
}

/// Parses the contents of one `miMATRIX` element; `path` names a struct
/// field (whose own name in the file is empty), `depth` counts the structs
/// around it.
fn read_matrix(
    content: &[u8],
    big: bool,
    out: &mut MatFile,
    path: Option<&str>,
    depth: usize,
) -> Result<(), MatError> {
    if content.is_empty() {
        // An empty array element (as MATLAB writes for empty cells).
        return Ok(());
    }
    let mut c = Cursor {
        buf: content,
        pos: 0,
        big,
    };
    let flags = c.next(true)?;
    if flags.kind != MI_UINT32 || flags.data.len() != 8 {
        return Err(err(
            "malformed array: the first sub-element is not the 8-byte array flags",
        ));
    }
    let word = if big {
        u32::from_be_bytes(flags.data[..4].try_into().unwrap_or_default())
    } else {
        u32::from_le_bytes(flags.data[..4].try_into().unwrap_or_default())
    };
    let class = word & 0xff;
    let complex = word & 0x0800 != 0;
    let logical = word & 0x0200 != 0;
    if class == 17 {
        // Opaque objects (e.g. string, table) have a name but no dims.
        let name = c.next(true).map(|e| text(e.data)).unwrap_or_default();
        if path.is_none() && name.is_empty() {
            return Ok(());
        }
        out.skipped.push(SkippedVariable {
            name: path.map_or(name, str::to_string),
            class: class_name(class),
        });
        return Ok(());
    }
    let dims_el = c.next(true)?;
    if dims_el.kind != MI_INT32 || dims_el.data.len() % 4 != 0 || dims_el.data.len() < 8 {
        return Err(err(
            "malformed array: expected at least two int32 dimensions",
        ));
    }
    let name_el = c.next(true)?;
    if name_el.kind != MI_INT8 && name_el.kind != MI_UTF8 {
        return Err(err(format!(
            "malformed array: expected the name, found data type {}",
            name_el.kind
        )));
    }
    let name = path.map_or_else(|| text(name_el.data), str::to_string);
    // A nameless top-level entry is MATLAB's subsystem data (behind string
    // and other objects), not a variable anyone saved.
    if path.is_none() && name.is_empty() {
        return Ok(());
    }
    let with_name = |message: String| MatError {
        variable: Some(name.clone()),
        message,
    };
    let dims = dimensions(&dims_el, big).map_err(&with_name)?;
    if class == 2 {
        return read_struct(&mut c, &dims, big, out, &name, depth)
            .map_err(|e| with_name(e.message));
    }
    let numeric = match class {
        6 => NumericClass::Double,
        7 => NumericClass::Single,
        8 => NumericClass::Int8,
        9 if logical => NumericClass::Logical,
        9 => NumericClass::UInt8,
        10 => NumericClass::Int16,
        11 => NumericClass::UInt16,
        12 => NumericClass::Int32,
        13 => NumericClass::UInt32,
        14 => NumericClass::Int64,
        15 => NumericClass::UInt64,
        other => {
            out.skipped.push(SkippedVariable {
                name,
                class: class_name(other),
            });
            return Ok(());
        }
    };
    let numel = dims
        .iter()
        .try_fold(1usize, |acc, &d| acc.checked_mul(d))
        .ok_or_else(|| with_name(format!("absurd dimensions {dims:?}")))?;
    let real_el = c.next(true).map_err(|e| with_name(e.message))?;
    let real = convert(&real_el, numel, big).map_err(|m| with_name(format!("real part: {m}")))?;
    let imag = if complex {
        let el = c.next(true).map_err(|e| with_name(e.message))?;
        Some(convert(&el, numel, big).map_err(|m| with_name(format!("imaginary part: {m}")))?)
    } else {
        None
    };
    out.variables.push(MatVariable {
        name,
        dims,
        class: numeric,
        real,
        imag,
    });
    Ok(())
}

/// The fields of a struct after its name: the field-name length, the
/// names, then one `miMATRIX` per field (per element; only scalar structs
/// are read).
fn read_struct(
    c: &mut Cursor<'_>,
    dims: &[usize],
    big: bool,
    out: &mut MatFile,
    name: &str,
    depth: usize,
) -> Result<(), MatError> {
    let numel = dims.iter().try_fold(1usize, |acc, &d| acc.checked_mul(d));
    if numel != Some(1) {
        out.skipped.push(SkippedVariable {
            name: name.to_string(),
            class: "struct array".into(),
        });
        return Ok(());
    }
    if depth >= MAX_STRUCT_DEPTH {
        return Err(err(format!(
            "structs nested deeper than {MAX_STRUCT_DEPTH} levels"
        )));
    }
    let len_el = c.next(true)?;
    let field_len = match (len_el.kind, len_el.data.len()) {
        (MI_INT32, 4) => {
            let b: [u8; 4] = len_el.data.try_into().unwrap_or_default();
            (if big {
                i32::from_be_bytes(b)
            } else {
                i32::from_le_bytes(b)
            }) as i64
        }
        _ => return Err(err("malformed struct: no field-name length")),
    };
    let names_el = c.next(true)?;
    if field_len <= 0 || names_el.kind != MI_INT8 || names_el.data.len() % field_len as usize != 0 {
        return Err(err("malformed struct: field names do not fit their length"));
    }
    let fields: Vec<String> = names_el
        .data
        .chunks_exact(field_len as usize)
        .map(text)
        .collect();
    for field in fields {
        let el = c.next(true)?;
        if el.kind != MI_MATRIX {
            return Err(err(format!(
                "malformed struct: field '{field}' is data type {}, not an array",
                el.kind
            )));
        }
        let path = format!("{name}.{field}");
        read_matrix(el.data, big, out, Some(&path), depth + 1)?;
    }
    Ok(())
}

/// The dimensions of an array from its int32 dimensions element.
fn dimensions(el: &Element<'_>, big: bool) -> Result<Vec<usize>, String> {
    el.data
        .chunks_exact(4)
        .map(|chunk| {
            let b: [u8; 4] = chunk.try_into().unwrap_or_default();
            let d = if big {
                i32::from_be_bytes(b)
            } else {
                i32::from_le_bytes(b)
            };
            usize::try_from(d).map_err(|_| format!("negative dimension {d}"))
        })
        .collect()
}

fn text(data: &[u8]) -> String {
    String::from_utf8_lossy(data)
        .trim_end_matches('\0')
        .to_string()
}

/// Converts the data of a numeric element to `f64`; the element must
/// hold exactly `numel` values.
fn convert(el: &Element<'_>, numel: usize, big: bool) -> Result<Vec<f64>, String> {
    let size = match el.kind {
        MI_INT8 | MI_UINT8 => 1,
        MI_INT16 | MI_UINT16 => 2,
        MI_INT32 | MI_UINT32 | MI_SINGLE => 4,
        MI_DOUBLE | MI_INT64 | MI_UINT64 => 8,
        other => return Err(format!("unsupported data type {other}")),
    };
    if numel.checked_mul(size) != Some(el.data.len()) {
        return Err(format!(
            "{} bytes of data type {} do not hold the {numel} values of the dimensions",
            el.data.len(),
            el.kind
        ));
    }
    // `numel` now equals a count of bytes present in the buffer: safe to
    // allocate.
    macro_rules! conv {
        ($t:ty) => {
            el.data
                .chunks_exact(size)
                .map(|b| {
                    let a = b.try_into().unwrap_or_default();
                    (if big {
                        <$t>::from_be_bytes(a)
                    } else {
                        <$t>::from_le_bytes(a)
                    }) as f64
                })
                .collect()
        };
    }
    Ok(match el.kind {
        MI_INT8 => conv!(i8),
        MI_UINT8 => conv!(u8),
        MI_INT16 => conv!(i16),
        MI_UINT16 => conv!(u16),
        MI_INT32 => conv!(i32),
        MI_UINT32 => conv!(u32),
        MI_SINGLE => conv!(f32),
        MI_INT64 => conv!(i64),
        MI_UINT64 => conv!(u64),
        _ => conv!(f64),
    })
}

/// A small level-5 writer for tests: enough of the format to produce the
/// cases the reader must handle (classes, complex, small elements, both
/// byte orders, compression) independently of the reader's code.
#[cfg(test)]
pub(crate) mod writer {
    /// What to store for one variable.
    pub enum Data {
        /// Real values with an element data type (miDOUBLE = 9, ...).
        Real(Vec<f64>, u32),
        /// Real and imaginary doubles.
        Complex(Vec<f64>, Vec<f64>),
        /// A char array (class 4, stored as miUINT16).
        Char(String),
        /// An empty cell array (class 1).
        Cell,
        /// A struct (class 2): its fields, each a variable whose own name
        /// the writer leaves empty, as MATLAB does.
        Struct(Vec<(String, Var)>),
    }

    pub struct Var {
        pub name: String,
        pub dims: Vec<i32>,
        pub class: u32,
        pub logical: bool,
        pub data: Data,
    }

    impl Var {
        /// A copy of the parts the struct writer needs.
        pub fn shallow(&self) -> Var {
            Var {
                name: self.name.clone(),
                dims: self.dims.clone(),
                class: self.class,
                logical: self.logical,
                data: match &self.data {
                    Data::Real(x, k) => Data::Real(x.clone(), *k),
                    Data::Struct(f) => {
                        Data::Struct(f.iter().map(|(n, v)| (n.clone(), v.shallow())).collect())
                    }
                    _ => Data::Cell,
                },
            }
        }

        /// A 1 x 1 struct of `fields`.
        pub fn structure(name: &str, fields: Vec<(&str, Var)>) -> Var {
            Var {
                name: name.into(),
                dims: vec![1, 1],
                class: 2,
                logical: false,
                data: Data::Struct(fields.into_iter().map(|(n, v)| (n.into(), v)).collect()),
            }
        }

        pub fn double(name: &str, rows: i32, cols: i32, values: Vec<f64>) -> Var {
            Var {
                name: name.into(),
                dims: vec![rows, cols],
                class: 6,
                logical: false,
                data: Data::Real(values, 9),
            }
        }
    }

    struct W {
        big: bool,
        out: Vec<u8>,
    }

    impl W {
        fn u32(&mut self, v: u32) {
            let b = if self.big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            };
            self.out.extend_from_slice(&b);
        }
        /// Tag + data, small format when it fits, padded to 8.
        fn element(&mut self, kind: u32, data: &[u8]) {
            if data.len() <= 4 && !data.is_empty() {
                self.u32(((data.len() as u32) << 16) | kind);
                let mut d = data.to_vec();
                d.resize(4, 0);
                self.out.extend_from_slice(&d);
            } else {
                self.u32(kind);
                self.u32(data.len() as u32);
                self.out.extend_from_slice(data);
                while self.out.len() & 7 != 0 {
                    self.out.push(0);
                }
            }
        }
    }

    fn encode(values: &[f64], kind: u32, big: bool) -> Vec<u8> {
        let mut out = Vec::new();
        for &v in values {
            macro_rules! put {
                ($t:ty) => {{
                    let x = v as $t;
                    out.extend_from_slice(&if big {
                        x.to_be_bytes()
                    } else {
                        x.to_le_bytes()
                    });
                }};
            }
            match kind {
                1 => put!(i8),
                2 => put!(u8),
                3 => put!(i16),
                4 => put!(u16),
                5 => put!(i32),
                6 => put!(u32),
                7 => put!(f32),
                12 => put!(i64),
                13 => put!(u64),
                _ => put!(f64),
            }
        }
        out
    }

    /// The bytes of one miMATRIX element (tag included).
    fn matrix(var: &Var, big: bool) -> Vec<u8> {
        let mut w = W {
            big,
            out: Vec::new(),
        };
        let flags = var.class
            | if var.logical { 0x0200 } else { 0 }
            | if matches!(var.data, Data::Complex(..)) {
                0x0800
            } else {
                0
            };
        let mut f = Vec::new();
        f.extend_from_slice(&if big {
            flags.to_be_bytes()
        } else {
            flags.to_le_bytes()
        });
        f.extend_from_slice(&[0; 4]);
        w.element(6, &f);
        let dims: Vec<u8> = var
            .dims
            .iter()
            .flat_map(|d| {
                if big {
                    d.to_be_bytes()
                } else {
                    d.to_le_bytes()
                }
            })
            .collect();
        w.element(5, &dims);
        w.element(1, var.name.as_bytes());
        match &var.data {
            Data::Real(v, kind) => w.element(*kind, &encode(v, *kind, big)),
            Data::Complex(re, im) => {
                w.element(9, &encode(re, 9, big));
                w.element(9, &encode(im, 9, big));
            }
            Data::Char(s) => {
                let v: Vec<f64> = s.chars().map(|c| c as u32 as f64).collect();
                w.element(4, &encode(&v, 4, big));
            }
            Data::Cell => {}
            Data::Struct(fields) => {
                let len = 32usize;
                w.element(5, &encode(&[len as f64], 5, big));
                let mut names = Vec::new();
                for (n, _) in fields {
                    let mut b = n.as_bytes().to_vec();
                    b.resize(len, 0);
                    names.extend_from_slice(&b);
                }
                w.element(1, &names);
                for (_, v) in fields {
                    let inner = Var {
                        name: String::new(),
                        dims: v.dims.clone(),
                        class: v.class,
                        logical: v.logical,
                        data: match &v.data {
                            Data::Real(x, k) => Data::Real(x.clone(), *k),
                            Data::Struct(f) => Data::Struct(
                                f.iter().map(|(n, v)| (n.clone(), v.shallow())).collect(),
                            ),
                            _ => Data::Cell,
                        },
                    };
                    w.out.extend_from_slice(&matrix(&inner, big));
                }
            }
        }
        let body = w.out;
        let mut e = W {
            big,
            out: Vec::new(),
        };
        e.u32(14);
        e.u32(body.len() as u32);
        e.out.extend_from_slice(&body);
        e.out
    }

    /// A complete file; `compress` wraps each variable in miCOMPRESSED.
    pub fn file(vars: &[Var], compress: bool, big: bool) -> Vec<u8> {
        let mut out = vec![b' '; 116];
        let text = b"MATLAB 5.0 MAT-file, written by the frf tests";
        out[..text.len()].copy_from_slice(text);
        out.extend_from_slice(&[0; 8]);
        if big {
            out.extend_from_slice(&[0x01, 0x00, b'M', b'I']);
        } else {
            out.extend_from_slice(&[0x00, 0x01, b'I', b'M']);
        }
        let mut w = W { big, out };
        for v in vars {
            let m = matrix(v, big);
            if compress {
                let z = miniz_oxide::deflate::compress_to_vec_zlib(&m, 6);
                w.u32(15);
                w.u32(z.len() as u32);
                w.out.extend_from_slice(&z);
            } else {
                w.out.extend_from_slice(&m);
            }
        }
        w.out
    }
}

#[cfg(test)]
mod tests {
    use super::writer::{file, Data, Var};
    use super::*;

    /// Struct fields come out as variables named by their path, in both
    /// byte orders, compressed or not; a struct array is listed, not read;
    /// nesting beyond the limit is an error.
    #[test]
    fn struct_fields_are_variables_by_path() {
        let data = Var::structure(
            "Data",
            vec![
                (
                    "signals",
                    Var::structure(
                        "",
                        vec![
                            ("u", Var::double("", 3, 1, vec![1.0, -2.0, 3.5])),
                            ("y", Var::double("", 1, 2, vec![0.25, 7.0])),
                        ],
                    ),
                ),
                ("fs", Var::double("", 1, 1, vec![4000.0])),
            ],
        );
        for (compress, big) in [(false, false), (true, false), (false, true)] {
            let m = read_mat(&file(&[data.shallow()], compress, big)).unwrap();
            assert_eq!(m.get("Data.signals.u").unwrap().real, vec![1.0, -2.0, 3.5]);
            assert_eq!(m.get("Data.signals.y").unwrap().dims, vec![1, 2]);
            assert_eq!(m.get("Data.fs").unwrap().scalar(), Some(4000.0));
        }
        let mut array = Var::structure("many", vec![("a", Var::double("", 1, 1, vec![1.0]))]);
        array.dims = vec![1, 2];
        let m = read_mat(&file(&[array], false, false)).unwrap();
        assert!(m.variables.is_empty());
        assert_eq!(m.skipped[0].class, "struct array");
        let mut deep = Var::double("", 1, 1, vec![1.0]);
        for _ in 0..MAX_STRUCT_DEPTH + 1 {
            deep = Var::structure("", vec![("x", deep)]);
        }
        deep.name = "deep".into();
        let e = read_mat(&file(&[deep], true, false)).unwrap_err();
        assert!(e.message.contains("nested deeper"), "{e}");
    }

    fn sample_vars() -> Vec<Var> {
        vec![
            Var::double(
                "result",
                4,
                2,
                vec![1.0, 2.0, 3.0, 4.0, -1.5, -2.5, 0.25, 1e300],
            ),
            Var::double("Fs", 1, 1, vec![400.0]),
            Var {
                name: "counts".into(),
                dims: vec![1, 3],
                class: 10,
                logical: false,
                data: Data::Real(vec![-7.0, 0.0, 32767.0], 3),
            },
            Var {
                // A uint8 class stored with a narrower element type, as
                // MATLAB does to save space for small integers.
                name: "big_int".into(),
                dims: vec![2, 1],
                class: 15,
                logical: false,
                data: Data::Real(vec![5.0, 200.0], 2),
            },
            Var {
                name: "flag".into(),
                dims: vec![1, 2],
                class: 9,
                logical: true,
                data: Data::Real(vec![1.0, 0.0], 2),
            },
            Var {
                name: "single_val".into(),
                dims: vec![1, 2],
                class: 7,
                logical: false,
                data: Data::Real(vec![0.5, -3.25], 7),
            },
            Var {
                name: "z".into(),
                dims: vec![2, 1],
                class: 6,
                logical: false,
                data: Data::Complex(vec![1.0, 2.0], vec![-1.0, 0.5]),
            },
            Var {
                name: "label".into(),
                dims: vec![1, 2],
                class: 4,
                logical: false,
                data: Data::Char("hi".into()),
            },
            Var {
                name: "notes".into(),
                dims: vec![0, 0],
                class: 1,
                logical: false,
                data: Data::Cell,
            },
        ]
    }

    fn check(mat: &MatFile) {
        let r = mat.get("result").unwrap();
        assert_eq!(r.dims, vec![4, 2]);
        assert_eq!(r.shape2(), Some((4, 2)));
        assert_eq!(r.class, NumericClass::Double);
        assert_eq!(r.real, vec![1.0, 2.0, 3.0, 4.0, -1.5, -2.5, 0.25, 1e300]);
        assert_eq!(mat.get("Fs").unwrap().scalar(), Some(400.0));
        let c = mat.get("counts").unwrap();
        assert_eq!(
            (c.class, c.real.clone()),
            (NumericClass::Int16, vec![-7.0, 0.0, 32767.0])
        );
        let b = mat.get("big_int").unwrap();
        assert_eq!(
            (b.class, b.real.clone()),
            (NumericClass::UInt64, vec![5.0, 200.0])
        );
        let f = mat.get("flag").unwrap();
        assert_eq!(
            (f.class, f.real.clone()),
            (NumericClass::Logical, vec![1.0, 0.0])
        );
        let s = mat.get("single_val").unwrap();
        assert_eq!(
            (s.class, s.real.clone()),
            (NumericClass::Single, vec![0.5, -3.25])
        );
        let z = mat.get("z").unwrap();
        assert_eq!(z.real, vec![1.0, 2.0]);
        assert_eq!(z.imag, Some(vec![-1.0, 0.5]));
        assert_eq!(z.scalar(), None);
        assert_eq!(mat.variables.len(), 7);
        assert_eq!(
            mat.skipped,
            vec![
                SkippedVariable {
                    name: "label".into(),
                    class: "char".into()
                },
                SkippedVariable {
                    name: "notes".into(),
                    class: "cell".into()
                },
            ]
        );
    }

    #[test]
    fn reads_all_layouts() {
        for compress in [false, true] {
            for big in [false, true] {
                let bytes = file(&sample_vars(), compress, big);
                let mat = read_mat(&bytes).unwrap_or_else(|e| panic!("{compress} {big}: {e}"));
                check(&mat);
                assert!(mat.header_text.starts_with("MATLAB 5.0"));
            }
        }
    }

    #[test]
    fn header_errors() {
        assert!(read_mat(&[]).unwrap_err().message.contains("too few"));
        let mut bytes = file(&sample_vars(), false, false);
        bytes[126] = b'X';
        assert!(read_mat(&bytes).unwrap_err().message.contains("endian"));
        let mut bytes = file(&sample_vars(), false, false);
        bytes[124] = 0x00;
        bytes[125] = 0x02;
        assert!(read_mat(&bytes).unwrap_err().message.contains("7.3"));
    }

    #[test]
    fn absurd_sizes_are_errors() {
        // Dimensions whose product overflows.
        let mut v = Var::double("huge", 1, 1, vec![1.0]);
        v.dims = vec![i32::MAX, i32::MAX, i32::MAX, i32::MAX];
        let e = read_mat(&file(&[v], false, false)).unwrap_err();
        assert_eq!(e.variable.as_deref(), Some("huge"));
        assert!(e.message.contains("absurd"), "{e}");
        // Dimensions that do not match the data.
        let mut v = Var::double("short", 1, 1, vec![1.0]);
        v.dims = vec![1_000_000, 1_000];
        let e = read_mat(&file(&[v], true, false)).unwrap_err();
        assert_eq!(e.variable.as_deref(), Some("short"));
        assert!(e.message.contains("do not hold"), "{e}");
        // A tag claiming 4 GiB - 1 in a small file.
        let mut bytes = file(&[Var::double("x", 1, 1, vec![1.0])], false, false);
        bytes[132..136].copy_from_slice(&u32::MAX.to_le_bytes());
        let e = read_mat(&bytes).unwrap_err();
        assert!(e.message.contains("claims"), "{e}");
        // Negative dimension.
        let mut v = Var::double("neg", 1, 1, vec![1.0]);
        v.dims = vec![-1, 1];
        assert!(read_mat(&file(&[v], false, false))
            .unwrap_err()
            .message
            .contains("negative"));
    }

    #[test]
    fn truncated_and_garbled_files_never_panic() {
        for compress in [false, true] {
            let bytes = file(&sample_vars(), compress, false);
            // Every truncation point: an error (or, at an element
            // boundary, a shorter but valid file), never a panic.
            for cut in 0..bytes.len() {
                if let Ok(m) = read_mat(&bytes[..cut]) {
                    assert!(m.variables.len() + m.skipped.len() < 9);
                }
            }
            // Flip each byte after the header in turn; only no-panic and
            // no runaway allocation are required.
            let mut rng = 0x2545_f491_4f6c_dd1du64;
            for i in 128..bytes.len() {
                let mut b = bytes.clone();
                rng ^= rng << 13;
                rng ^= rng >> 7;
                rng ^= rng << 17;
                b[i] ^= (rng as u8) | 1;
                let _ = read_mat(&b);
            }
        }
    }
}
