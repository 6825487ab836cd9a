//! Array files for other tools: NumPy `.npz` ([`npz_bytes`]) and MATLAB v5 `.mat`
//! ([`mat_bytes`]), built in memory from a list of named arrays ([`ArrayValue`]) and
//! byte-identical for the same input: entries in the order given, no time stamps (zip entries
//! are dated 1980-01-01 00:00, the zip format's epoch), no hash-map ordering, no random fields.
//!
//! Formats (the specifications these writers follow, and the tests check against):
//! - NPY 1.0 (NumPy's `numpy/lib/format.py`, "NPY format"): magic `\x93NUMPY`, version 1.0, a
//!   little-endian u16 header length, an ASCII Python dict literal
//!   `{'descr': '<f8', 'fortran_order': False, 'shape': (3, 2), }` padded with spaces and ended
//!   by `\n` so that the data start at a multiple of 64 bytes, then the data in C order.
//!   An `.npz` is a zip archive of such files named `<name>.npy` (what `numpy.savez` writes);
//!   entries are stored, not compressed.
//! - MAT-file level 5 (MathWorks, "MAT-File Format", R2024 and earlier, chapter 1): a 128-byte
//!   header (116 bytes of text, 8 bytes of subsystem offset, version 0x0100, endian indicator
//!   `IM`), then one `miMATRIX` element per variable: array flags, dimensions, name, data; every
//!   element padded to 8 bytes, elements of at most 4 bytes in the small-data-element form.
//!
//! The MAT writer is written here: the Rust crates that read MAT files (`matfile`, `mat5`)
//! cannot write them, and `matio-rs` binds the C library libmatio, which the build would then
//! need on every machine. Level 5 without compression is a few tag-length-value records.
//!
//! Conventions, the same in both files:
//! - [`ArrayValue::Real`] takes its data in row-major (C) order, as NumPy does; the MAT writer
//!   transposes to MATLAB's column-major order. A 1-d array of n values is an n×1 column in
//!   MATLAB (a per-mode vector reads as a column, as `eig` returns them) and a 0-d array 1×1.
//! - Text: NumPy `<U` (UTF-32) holds it exactly. MATLAB char data are written as UTF-16
//!   (`miUTF16`), whose code units are MATLAB's characters, with one exception: a character
//!   beyond the Basic Multilingual Plane (an emoji, a mathematical italic letter) becomes
//!   U+FFFD, because SciPy decodes char data to code points and then needs exactly as many as
//!   the dimensions count UTF-16 units (a surrogate pair makes `loadmat` fail). Octave reads
//!   the ASCII part of UTF-16 char data and replaces other characters by `?` with a warning
//!   (Octave's `ls-mat5.cc`); the names flexcraft writes are ASCII.
//! - Names follow MATLAB's rules for variable names in both files (so that one list of names
//!   serves both): a letter, then letters, digits and `_`, at most 63 characters, not a MATLAB
//!   keyword.

use std::collections::HashSet;
use std::io::Write;
use thiserror::Error;

/// One named array for an export file.
#[derive(Debug, Clone, PartialEq)]
pub enum ArrayValue {
    /// A real array: `shape` `[]` (a scalar), `[n]` or `[rows, cols]` (or more axes), and
    /// `shape.iter().product()` values in row-major order (NumPy's C order: the last index
    /// varies fastest).
    Real {
        /// Length along each axis.
        shape: Vec<usize>,
        /// The values, row-major.
        data: Vec<f64>,
    },
    /// A list of strings (names of states, inputs, outputs): NumPy a 1-d `<U{longest}` array,
    /// MATLAB a 1×n cell array of char row vectors.
    Strings(Vec<String>),
    /// One string (units, the scenario name): NumPy a 0-d `<U{length}` array (`str(a)` or
    /// `a.item()` gives the string), MATLAB a 1×length char row vector.
    Text(String),
}

impl ArrayValue {
    /// A rows×cols matrix from its values in row-major order.
    pub fn matrix(rows: usize, cols: usize, data: Vec<f64>) -> Self {
        Self::Real {
            shape: vec![rows, cols],
            data,
        }
    }

    /// A 1-d array (NumPy shape `(n,)`, MATLAB n×1).
    pub fn vector(data: Vec<f64>) -> Self {
        Self::Real {
            shape: vec![data.len()],
            data,
        }
    }

    /// A scalar (NumPy 0-d, MATLAB 1×1).
    pub fn scalar(v: f64) -> Self {
        Self::Real {
            shape: Vec::new(),
            data: vec![v],
        }
    }
}

/// What is wrong with an array name (MATLAB's rules for variable names).
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum NameProblem {
    /// The empty name.
    #[error("empty")]
    Empty,
    /// Longer than MATLAB's `namelengthmax`.
    #[error("{chars} characters, at most {MAX_NAME_CHARS} allowed")]
    TooLong {
        /// Its length in characters.
        chars: usize,
    },
    /// Does not start with an ASCII letter.
    #[error("must start with a letter (A-Z, a-z)")]
    BadFirstCharacter,
    /// A character other than A-Z, a-z, 0-9 and `_`.
    #[error("character {0:?} not allowed (only A-Z, a-z, 0-9 and _)")]
    BadCharacter(char),
    /// A MATLAB keyword (`end`, `for`, …): MATLAB cannot name a variable so.
    #[error("a MATLAB keyword")]
    Keyword,
}

/// Failure to build an array file. Nothing is written when one occurs.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ArrayFileError {
    /// A name MATLAB would refuse (checked for both formats: see the module documentation).
    #[error("array name \"{}\": {problem}", name.escape_debug())]
    InvalidName {
        /// The name.
        name: String,
        /// What is wrong with it.
        problem: NameProblem,
    },
    /// The same name given twice.
    #[error("array name \"{name}\" given twice")]
    DuplicateName {
        /// The name.
        name: String,
    },
    /// The shape does not match the number of values.
    #[error("array \"{name}\": shape {shape:?} holds {elements} values but {data_len} were given")]
    ShapeMismatch {
        /// The array's name.
        name: String,
        /// The shape given.
        shape: Vec<usize>,
        /// The product of the shape (saturated at `usize::MAX`).
        elements: usize,
        /// The number of values given.
        data_len: usize,
    },
    /// A NUL character in text: NumPy's `<U` strings drop trailing NULs, so the text would
    /// not read back as written.
    #[error("array \"{name}\": string {index} contains a NUL character")]
    NulInText {
        /// The array's name.
        name: String,
        /// The index of the string in the list (0 for [`ArrayValue::Text`]).
        index: usize,
    },
    /// A variable larger than a MAT v5 element can hold (a 32-bit signed byte count per
    /// variable, a 32-bit signed length per dimension).
    #[error("array \"{name}\": {bytes} bytes (or a dimension of {largest_dim}) beyond the MAT v5 limit of {MAT_MAX_BYTES}")]
    TooLarge {
        /// The array's name.
        name: String,
        /// Its size in the file, bytes.
        bytes: u64,
        /// Its largest dimension.
        largest_dim: usize,
    },
    /// The zip container could not be written (in memory: should not occur).
    #[error("npz container: {0}")]
    Zip(#[from] zip::result::ZipError),
}

/// MATLAB's `namelengthmax`.
pub const MAX_NAME_CHARS: usize = 63;

/// MATLAB's keywords (`iskeyword`), refused as names.
const MATLAB_KEYWORDS: [&str; 20] = [
    "break",
    "case",
    "catch",
    "classdef",
    "continue",
    "else",
    "elseif",
    "end",
    "for",
    "function",
    "global",
    "if",
    "otherwise",
    "parfor",
    "persistent",
    "return",
    "spmd",
    "switch",
    "try",
    "while",
];

/// The largest byte count (and dimension) of a MAT v5 variable: the signed 32-bit limit
/// MATLAB applies to level-5 files.
const MAT_MAX_BYTES: u64 = i32::MAX as u64;

/// Checks a name against MATLAB's rules for variable names.
fn check_name(name: &str) -> Result<(), NameProblem> {
    let mut chars = name.chars();
    let first = chars.next().ok_or(NameProblem::Empty)?;
    if !first.is_ascii_alphabetic() {
        return Err(NameProblem::BadFirstCharacter);
    }
    if let Some(c) = chars.find(|c| !(c.is_ascii_alphanumeric() || *c == '_')) {
        return Err(NameProblem::BadCharacter(c));
    }
    // All ASCII from here on: bytes are characters.
    if name.len() > MAX_NAME_CHARS {
        return Err(NameProblem::TooLong { chars: name.len() });
    }
    if MATLAB_KEYWORDS.contains(&name) {
        return Err(NameProblem::Keyword);
    }
    Ok(())
}

/// Checks every name, the uniqueness of names, shapes against data lengths and text for NUL.
fn validate(arrays: &[(&str, ArrayValue)]) -> Result<(), ArrayFileError> {
    let mut seen = HashSet::new();
    for (name, value) in arrays {
        check_name(name).map_err(|problem| ArrayFileError::InvalidName {
            name: name.to_string(),
            problem,
        })?;
        if !seen.insert(*name) {
            return Err(ArrayFileError::DuplicateName {
                name: name.to_string(),
            });
        }
        match value {
            ArrayValue::Real { shape, data } => {
                let elements = shape.iter().fold(1usize, |p, &d| p.saturating_mul(d));
                if elements != data.len() {
                    return Err(ArrayFileError::ShapeMismatch {
                        name: name.to_string(),
                        shape: shape.clone(),
                        elements,
                        data_len: data.len(),
                    });
                }
            }
            ArrayValue::Strings(list) => {
                if let Some(index) = list.iter().position(|s| s.contains('\0')) {
                    return Err(ArrayFileError::NulInText {
                        name: name.to_string(),
                        index,
                    });
                }
            }
            ArrayValue::Text(s) => {
                if s.contains('\0') {
                    return Err(ArrayFileError::NulInText {
                        name: name.to_string(),
                        index: 0,
                    });
                }
            }
        }
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// NumPy

/// The data of NPY files start at a multiple of this (NumPy's `ARRAY_ALIGN`).
const NPY_ALIGN: usize = 64;

/// An `.npz` archive (what `numpy.savez` writes): one stored (uncompressed) zip entry
/// `<name>.npy` per array, in the order given, every entry dated 1980-01-01 00:00 with
/// permissions 0644, so the bytes depend on the arrays only. `numpy.load` returns a mapping
/// from the names to the arrays.
pub fn npz_bytes(arrays: &[(&str, ArrayValue)]) -> Result<Vec<u8>, ArrayFileError> {
    validate(arrays)?;
    let options = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Stored)
        // Explicit: with zip's `time` feature (which another crate could turn on) the default
        // would be the current time.
        .last_modified_time(zip::DateTime::default())
        .unix_permissions(0o644);
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    for (name, value) in arrays {
        let npy = npy_bytes(value);
        // Entries of 4 GiB and more need the zip64 records.
        let options = options.large_file(npy.len() as u64 >= u64::from(u32::MAX));
        zip.start_file(format!("{name}.npy"), options)?;
        zip.write_all(&npy).map_err(zip::result::ZipError::Io)?;
    }
    Ok(zip.finish()?.into_inner())
}

/// One NPY 1.0 file: header, then the data in C order, little-endian.
fn npy_bytes(value: &ArrayValue) -> Vec<u8> {
    match value {
        ArrayValue::Real { shape, data } => {
            let mut out = npy_header("<f8", shape);
            out.reserve(8 * data.len());
            for v in data {
                out.extend_from_slice(&v.to_le_bytes());
            }
            out
        }
        ArrayValue::Strings(list) => {
            let width = list.iter().map(|s| s.chars().count()).max().unwrap_or(0);
            // NumPy's narrowest string type is <U1 (np.array([""]).dtype).
            let width = width.max(1);
            let mut out = npy_header(&format!("<U{width}"), &[list.len()]);
            for s in list {
                push_utf32(&mut out, s, width);
            }
            out
        }
        ArrayValue::Text(s) => {
            let width = s.chars().count().max(1);
            let mut out = npy_header(&format!("<U{width}"), &[]);
            push_utf32(&mut out, s, width);
            out
        }
    }
}

/// `s` as `width` little-endian UTF-32 code points, padded with NULs (NumPy's `<U{width}`).
fn push_utf32(out: &mut Vec<u8>, s: &str, width: usize) {
    let mut n = 0;
    for c in s.chars() {
        out.extend_from_slice(&u32::from(c).to_le_bytes());
        n += 1;
    }
    out.resize(out.len() + 4 * (width - n), 0);
}

/// The NPY 1.0 header for an array of type `descr` and `shape` in C order: the magic, the
/// version, the header length and the dict, padded with spaces and ended by `\n` so that the
/// data start at a multiple of [`NPY_ALIGN`].
fn npy_header(descr: &str, shape: &[usize]) -> Vec<u8> {
    // A Python tuple: (), (3,), (3, 2).
    let shape_txt = match shape {
        [] => "()".to_string(),
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|d| d.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let dict = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape_txt}, }}");
    // magic (6) + version (2) + header length (2) + dict + padding + '\n'.
    let unpadded = 10 + dict.len() + 1;
    let pad = (NPY_ALIGN - unpadded % NPY_ALIGN) % NPY_ALIGN;
    // At most a few hundred bytes even for many axes: always fits the u16 of version 1.0.
    let header_len = (dict.len() + pad + 1) as u16;
    let mut out = Vec::with_capacity(10 + header_len as usize);
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&header_len.to_le_bytes());
    out.extend_from_slice(dict.as_bytes());
    out.resize(out.len() + pad, b' ');
    out.push(b'\n');
    out
}

// ---------------------------------------------------------------------------------------------
// MATLAB

/// MAT v5 data types (MAT-File Format, table 1-1).
const MI_INT8: u32 = 1;
const MI_INT32: u32 = 5;
const MI_UINT32: u32 = 6;
const MI_DOUBLE: u32 = 9;
const MI_MATRIX: u32 = 14;
const MI_UTF16: u32 = 17;
/// MATLAB array classes (MAT-File Format, table 1-3).
const MX_CELL_CLASS: u8 = 1;
const MX_CHAR_CLASS: u8 = 4;
const MX_DOUBLE_CLASS: u8 = 6;

/// Length of the MAT header's descriptive text.
const MAT_TEXT_BYTES: usize = 116;

/// A MATLAB level-5 MAT-file holding `arrays` in the order given, uncompressed (MATLAB
/// `-v6` style, loadable by every MATLAB since 5, by Octave and by `scipy.io.loadmat`).
///
/// `header_text` goes into the header's descriptive text after `MATLAB 5.0 MAT-file, `
/// (what MATLAB writes, followed by platform and creator); characters outside printable ASCII
/// become `?`, and the text is cut at 116 bytes. Pass no date if the file must be
/// byte-identical between runs.
pub fn mat_bytes(
    arrays: &[(&str, ArrayValue)],
    header_text: &str,
) -> Result<Vec<u8>, ArrayFileError> {
    validate(arrays)?;
    let mut out = mat_header(header_text);
    for (name, value) in arrays {
        let element = matrix_element(name, value).map_err(|(bytes, largest_dim)| {
            ArrayFileError::TooLarge {
                name: name.to_string(),
                bytes,
                largest_dim,
            }
        })?;
        out.extend_from_slice(&element);
    }
    Ok(out)
}

/// The 128-byte header: text, subsystem data offset (none: zeros), version 0x0100 and the
/// endian indicator: the characters `IM` as a little-endian u16 ("MI" read back on a
/// big-endian machine tells the reader to swap).
fn mat_header(header_text: &str) -> Vec<u8> {
    let mut out: Vec<u8> = format!("MATLAB 5.0 MAT-file, {header_text}")
        .chars()
        .map(|c| {
            if c.is_ascii_graphic() || c == ' ' {
                c as u8
            } else {
                b'?'
            }
        })
        .take(MAT_TEXT_BYTES)
        .collect();
    out.resize(MAT_TEXT_BYTES, b' ');
    out.extend_from_slice(&[0; 8]);
    out.extend_from_slice(&0x0100u16.to_le_bytes());
    out.extend_from_slice(b"IM");
    out
}

/// One `miMATRIX` element (tag and body), or (bytes, largest dimension) when it exceeds
/// [`MAT_MAX_BYTES`].
fn matrix_element(name: &str, value: &ArrayValue) -> Result<Vec<u8>, (u64, usize)> {
    let mut body = Vec::new();
    let dims: Vec<usize> = match value {
        ArrayValue::Real { shape, data } => {
            let dims = match shape.as_slice() {
                [] => vec![1, 1],
                [n] => vec![*n, 1],
                _ => shape.clone(),
            };
            push_matrix_head(&mut body, MX_DOUBLE_CLASS, &dims, name)?;
            let mut bytes = Vec::with_capacity(8 * data.len());
            for v in column_major(shape, data) {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
            push_element(&mut body, MI_DOUBLE, &bytes);
            dims
        }
        ArrayValue::Text(s) => {
            // One UTF-16 unit per character: beyond the BMP, U+FFFD (see the module docs).
            let units: Vec<u16> = s
                .chars()
                .map(|c| u16::try_from(u32::from(c)).unwrap_or(0xFFFD))
                .collect();
            let dims = vec![1, units.len()];
            push_matrix_head(&mut body, MX_CHAR_CLASS, &dims, name)?;
            let bytes: Vec<u8> = units.iter().flat_map(|u| u.to_le_bytes()).collect();
            push_element(&mut body, MI_UTF16, &bytes);
            dims
        }
        ArrayValue::Strings(list) => {
            let dims = vec![1, list.len()];
            push_matrix_head(&mut body, MX_CELL_CLASS, &dims, name)?;
            // A cell's contents: one unnamed miMATRIX element per cell, column-major (1×n:
            // in order).
            for s in list {
                body.extend_from_slice(&matrix_element("", &ArrayValue::Text(s.clone()))?);
            }
            dims
        }
    };
    let largest_dim = dims.iter().copied().max().unwrap_or(0);
    let bytes = 8 + body.len() as u64;
    if bytes > MAT_MAX_BYTES || largest_dim as u64 > MAT_MAX_BYTES {
        return Err((bytes, largest_dim));
    }
    let mut out = Vec::with_capacity(8 + body.len());
    out.extend_from_slice(&MI_MATRIX.to_le_bytes());
    out.extend_from_slice(&(body.len() as u32).to_le_bytes());
    out.extend_from_slice(&body);
    Ok(out)
}

/// The array flags (class, not complex, not global, not logical; nzmax 0), the dimensions and
/// the name of an miMATRIX element.
fn push_matrix_head(
    body: &mut Vec<u8>,
    class: u8,
    dims: &[usize],
    name: &str,
) -> Result<(), (u64, usize)> {
    let mut flags = [0u8; 8];
    flags[0] = class;
    push_element(body, MI_UINT32, &flags);
    let mut dim_bytes = Vec::with_capacity(4 * dims.len());
    for &d in dims {
        let d32 = i32::try_from(d).map_err(|_| (0, d))?;
        dim_bytes.extend_from_slice(&d32.to_le_bytes());
    }
    push_element(body, MI_INT32, &dim_bytes);
    push_element(body, MI_INT8, name.as_bytes());
    Ok(())
}

/// One data element: the small-data-element form (the byte count in the tag's upper 16 bits,
/// the type in the lower 16, the data in the next 4 bytes) for 1 to 4 bytes, otherwise an
/// 8-byte tag and the data padded with zeros to a multiple of 8 bytes. (The empty element,
/// e.g. the name of a cell's content, is an 8-byte tag with count 0, as MATLAB writes it.)
fn push_element(body: &mut Vec<u8>, data_type: u32, data: &[u8]) {
    if (1..=4).contains(&data.len()) {
        let tag = ((data.len() as u32) << 16) | data_type;
        body.extend_from_slice(&tag.to_le_bytes());
        body.extend_from_slice(data);
        body.resize(body.len() + 4 - data.len(), 0);
    } else {
        body.extend_from_slice(&data_type.to_le_bytes());
        body.extend_from_slice(&(data.len() as u32).to_le_bytes());
        body.extend_from_slice(data);
        body.resize(body.len() + (8 - data.len() % 8) % 8, 0);
    }
}

/// Values of an array of `shape` given in row-major (C) order, in column-major (Fortran)
/// order: the first index varies fastest.
fn column_major(shape: &[usize], data: &[f64]) -> Vec<f64> {
    if shape.len() < 2 {
        return data.to_vec();
    }
    // Row-major strides.
    let mut strides = vec![1; shape.len()];
    for k in (0..shape.len() - 1).rev() {
        strides[k] = strides[k + 1] * shape[k + 1];
    }
    let mut out = Vec::with_capacity(data.len());
    let mut index = vec![0; shape.len()];
    for _ in 0..data.len() {
        let offset: usize = index.iter().zip(&strides).map(|(i, s)| i * s).sum();
        out.push(data[offset]);
        // Next multi-index, first axis fastest.
        for k in 0..shape.len() {
            index[k] += 1;
            if index[k] < shape[k] {
                break;
            }
            index[k] = 0;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Vec<(&'static str, ArrayValue)> {
        vec![
            (
                "A",
                ArrayValue::matrix(3, 2, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]),
            ),
            ("freq_hz", ArrayValue::vector(vec![0.5, 1.25, -3.0e-300])),
            ("mass_kg", ArrayValue::scalar(12.5)),
            (
                "state_names",
                ArrayValue::Strings(vec!["eta_1".into(), "eta_dot_1".into(), "".into()]),
            ),
            ("units", ArrayValue::Text("rad/s".into())),
        ]
    }

    // -- an independent, minimal reader of the two formats, written from the specifications --

    fn u16_at(b: &[u8], i: usize) -> u16 {
        u16::from_le_bytes([b[i], b[i + 1]])
    }
    fn u32_at(b: &[u8], i: usize) -> u32 {
        u32::from_le_bytes(b[i..i + 4].try_into().unwrap())
    }

    /// CRC-32 (IEEE 802.3, reflected, polynomial 0xEDB88320), bit by bit.
    fn crc32(data: &[u8]) -> u32 {
        let mut crc = !0u32;
        for &b in data {
            crc ^= u32::from(b);
            for _ in 0..8 {
                crc = if crc & 1 == 1 {
                    (crc >> 1) ^ 0xEDB8_8320
                } else {
                    crc >> 1
                };
            }
        }
        !crc
    }

    /// The entries (name, data) of a zip archive of stored entries, read through the local
    /// file headers (APPNOTE.TXT 4.3.7), checking method, date, CRC and the end record.
    fn zip_entries(b: &[u8]) -> Vec<(String, Vec<u8>)> {
        let mut entries = Vec::new();
        let mut i = 0;
        while u32_at(b, i) == 0x0403_4b50 {
            let flags = u16_at(b, i + 6);
            assert_eq!(flags & 0x0008, 0, "no data descriptor");
            assert_eq!(u16_at(b, i + 8), 0, "stored");
            assert_eq!(u16_at(b, i + 10), 0, "time 00:00:00");
            assert_eq!(u16_at(b, i + 12), (1 << 5) | 1, "date 1980-01-01");
            let crc = u32_at(b, i + 14);
            let csize = u32_at(b, i + 18) as usize;
            assert_eq!(csize, u32_at(b, i + 22) as usize, "stored: sizes equal");
            let name_len = u16_at(b, i + 26) as usize;
            let extra_len = u16_at(b, i + 28) as usize;
            let name = String::from_utf8(b[i + 30..i + 30 + name_len].to_vec()).unwrap();
            let start = i + 30 + name_len + extra_len;
            let data = b[start..start + csize].to_vec();
            assert_eq!(crc32(&data), crc, "CRC of {name}");
            entries.push((name, data));
            i = start + csize;
        }
        // Central directory, then the end-of-central-directory record (22 bytes, no comment).
        assert_eq!(
            u32_at(b, i),
            0x0201_4b50,
            "central directory follows the entries"
        );
        let end = b.len() - 22;
        assert_eq!(u32_at(b, end), 0x0605_4b50);
        assert_eq!(u16_at(b, end + 10) as usize, entries.len());
        assert_eq!(u32_at(b, end + 16) as usize, i, "central directory offset");
        entries
    }

    /// (header dict, data) of an NPY file, checking magic, version and alignment.
    fn npy_parts(b: &[u8]) -> (String, &[u8]) {
        assert_eq!(&b[..8], b"\x93NUMPY\x01\x00");
        let header_len = u16_at(b, 8) as usize;
        assert_eq!((10 + header_len) % 64, 0, "data 64-byte aligned");
        let header = std::str::from_utf8(&b[10..10 + header_len]).unwrap();
        assert!(header.ends_with('\n'));
        (header.trim_end().to_string(), &b[10 + header_len..])
    }

    #[derive(Debug, PartialEq)]
    enum MatVar {
        Double { dims: Vec<i32>, data: Vec<f64> },
        Char { dims: Vec<i32>, text: String },
        Cell { dims: Vec<i32>, items: Vec<MatVar> },
    }

    /// One data element at `b[i..]`: (type, data, offset of the next element), checking the
    /// 8-byte alignment and zero padding.
    fn mat_element(b: &[u8], i: usize) -> (u32, &[u8], usize) {
        assert_eq!(i % 8, 0, "element aligned at 8 bytes");
        let tag = u32_at(b, i);
        if tag >> 16 != 0 {
            let n = (tag >> 16) as usize;
            assert!(n <= 4);
            assert!(b[i + 4 + n..i + 8].iter().all(|&x| x == 0), "zero padding");
            return (tag & 0xffff, &b[i + 4..i + 4 + n], i + 8);
        }
        let n = u32_at(b, i + 4) as usize;
        let padded = n.div_ceil(8) * 8;
        assert!(
            b[i + 8 + n..i + 8 + padded].iter().all(|&x| x == 0),
            "zero padding"
        );
        (tag, &b[i + 8..i + 8 + n], i + 8 + padded)
    }

    /// A miMATRIX element's (name, variable).
    fn mat_matrix(b: &[u8]) -> (String, MatVar) {
        let (t, flags, i) = mat_element(b, 0);
        assert_eq!(t, MI_UINT32);
        assert_eq!(flags.len(), 8);
        assert_eq!(
            &flags[1..],
            &[0; 7],
            "no complex/global/logical flag, nzmax 0"
        );
        let (t, dims, i) = mat_element(b, i);
        assert_eq!(t, MI_INT32);
        let dims: Vec<i32> = dims
            .chunks(4)
            .map(|c| i32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert!(dims.len() >= 2);
        let (t, name, mut i) = mat_element(b, i);
        assert_eq!(t, MI_INT8);
        let name = String::from_utf8(name.to_vec()).unwrap();
        let count: i32 = dims.iter().product();
        let var = match flags[0] {
            MX_DOUBLE_CLASS => {
                let (t, data, end) = mat_element(b, i);
                assert_eq!(t, MI_DOUBLE);
                assert_eq!(end, b.len());
                let data: Vec<f64> = data
                    .chunks(8)
                    .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
                    .collect();
                assert_eq!(data.len() as i32, count);
                MatVar::Double { dims, data }
            }
            MX_CHAR_CLASS => {
                let (t, data, end) = mat_element(b, i);
                assert_eq!(t, MI_UTF16);
                assert_eq!(end, b.len());
                let units: Vec<u16> = data
                    .chunks(2)
                    .map(|c| u16::from_le_bytes([c[0], c[1]]))
                    .collect();
                assert_eq!(units.len() as i32, count);
                MatVar::Char {
                    dims,
                    text: String::from_utf16(&units).unwrap(),
                }
            }
            MX_CELL_CLASS => {
                let mut items = Vec::new();
                for _ in 0..count {
                    let (t, item, next) = mat_element(b, i);
                    assert_eq!(t, MI_MATRIX);
                    let (item_name, var) = mat_matrix(item);
                    assert_eq!(item_name, "", "cell contents are unnamed");
                    items.push(var);
                    i = next;
                }
                assert_eq!(i, b.len());
                MatVar::Cell { dims, items }
            }
            c => panic!("unexpected class {c}"),
        };
        (name, var)
    }

    /// The header text and the variables of a MAT v5 file.
    fn mat_read(b: &[u8]) -> (String, Vec<(String, MatVar)>) {
        assert!(b.len() >= 128);
        let text = String::from_utf8(b[..116].to_vec()).unwrap();
        assert_eq!(&b[116..124], &[0; 8], "no subsystem data");
        assert_eq!(&b[124..126], &[0x00, 0x01], "version 0x0100, little-endian");
        assert_eq!(&b[126..128], b"IM");
        let mut vars = Vec::new();
        let mut i = 128;
        while i < b.len() {
            let (t, body, next) = mat_element(b, i);
            assert_eq!(t, MI_MATRIX);
            vars.push(mat_matrix(body));
            i = next;
        }
        (text, vars)
    }

    // -- the tests --

    #[test]
    fn npz_entries_are_npy_files_in_order() {
        let bytes = npz_bytes(&sample()).unwrap();
        let entries = zip_entries(&bytes);
        let names: Vec<&str> = entries.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(
            names,
            [
                "A.npy",
                "freq_hz.npy",
                "mass_kg.npy",
                "state_names.npy",
                "units.npy"
            ]
        );

        let (header, data) = npy_parts(&entries[0].1);
        assert_eq!(
            header,
            "{'descr': '<f8', 'fortran_order': False, 'shape': (3, 2), }"
        );
        let values: Vec<f64> = data
            .chunks(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(values, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0], "C order kept");

        let (header, data) = npy_parts(&entries[1].1);
        assert_eq!(
            header,
            "{'descr': '<f8', 'fortran_order': False, 'shape': (3,), }"
        );
        assert_eq!(&data[16..24], &(-3.0e-300f64).to_le_bytes());

        let (header, data) = npy_parts(&entries[2].1);
        assert_eq!(
            header,
            "{'descr': '<f8', 'fortran_order': False, 'shape': (), }"
        );
        assert_eq!(data, &12.5f64.to_le_bytes());

        // Longest name: "eta_dot_1", 9 characters, each 4 bytes; "" all NULs.
        let (header, data) = npy_parts(&entries[3].1);
        assert_eq!(
            header,
            "{'descr': '<U9', 'fortran_order': False, 'shape': (3,), }"
        );
        assert_eq!(data.len(), 3 * 9 * 4);
        assert_eq!(&data[..8], &[b'e', 0, 0, 0, b't', 0, 0, 0]);
        assert_eq!(&data[5 * 4..9 * 4], &[0; 16], "eta_1 padded with NULs");
        assert!(data[18 * 4..].iter().all(|&b| b == 0));

        let (header, data) = npy_parts(&entries[4].1);
        assert_eq!(
            header,
            "{'descr': '<U5', 'fortran_order': False, 'shape': (), }"
        );
        let text: String = data
            .chunks(4)
            .map(|c| char::from_u32(u32_at(c, 0)).unwrap())
            .collect();
        assert_eq!(text, "rad/s");
    }

    #[test]
    fn npy_text_is_unicode_code_points() {
        let bytes = npz_bytes(&[
            ("angle", ArrayValue::Text("θ° 𝜔".into())),
            ("empty", ArrayValue::Text(String::new())),
            ("none", ArrayValue::Strings(Vec::new())),
        ])
        .unwrap();
        let entries = zip_entries(&bytes);
        let (header, data) = npy_parts(&entries[0].1);
        assert_eq!(
            header,
            "{'descr': '<U4', 'fortran_order': False, 'shape': (), }"
        );
        assert_eq!(u32_at(data, 12), 0x1D714, "one code point beyond the BMP");
        let (header, data) = npy_parts(&entries[1].1);
        assert_eq!(
            header,
            "{'descr': '<U1', 'fortran_order': False, 'shape': (), }"
        );
        assert_eq!(data, &[0; 4]);
        let (header, data) = npy_parts(&entries[2].1);
        assert_eq!(
            header,
            "{'descr': '<U1', 'fortran_order': False, 'shape': (0,), }"
        );
        assert!(data.is_empty());
    }

    #[test]
    fn npy_header_alignment_over_header_lengths() {
        // Shapes whose dict lengths cross the 64-byte boundaries.
        for rank in 0..12 {
            for d in [0usize, 7, 123_456_789] {
                let shape = vec![d; rank];
                let header = npy_header("<f8", &shape);
                assert_eq!(header.len() % 64, 0, "rank {rank}, dim {d}");
                assert_eq!(*header.last().unwrap(), b'\n');
                assert_eq!(u16_at(&header, 8) as usize, header.len() - 10);
            }
        }
    }

    #[test]
    fn mat_layout_follows_the_level5_spec() {
        let bytes = mat_bytes(&sample(), "Platform: any, Created by: flexcraft").unwrap();
        let (text, vars) = mat_read(&bytes);
        assert!(text.starts_with("MATLAB 5.0 MAT-file, Platform: any, Created by: flexcraft  "));
        assert_eq!(vars.len(), 5);
        assert_eq!(
            vars[0],
            (
                "A".into(),
                MatVar::Double {
                    dims: vec![3, 2],
                    data: vec![1.0, 3.0, 5.0, 2.0, 4.0, 6.0]
                }
            ),
            "3×2, column-major"
        );
        assert_eq!(
            vars[1],
            (
                "freq_hz".into(),
                MatVar::Double {
                    dims: vec![3, 1],
                    data: vec![0.5, 1.25, -3.0e-300]
                }
            ),
            "1-d: a column"
        );
        assert_eq!(
            vars[2],
            (
                "mass_kg".into(),
                MatVar::Double {
                    dims: vec![1, 1],
                    data: vec![12.5]
                }
            )
        );
        let char_row = |s: &str| MatVar::Char {
            dims: vec![1, s.chars().count() as i32],
            text: s.into(),
        };
        assert_eq!(
            vars[3],
            (
                "state_names".into(),
                MatVar::Cell {
                    dims: vec![1, 3],
                    items: vec![char_row("eta_1"), char_row("eta_dot_1"), char_row("")]
                }
            )
        );
        assert_eq!(vars[4], ("units".into(), char_row("rad/s")));
    }

    #[test]
    fn mat_small_data_elements() {
        // A 4-character name and a 2-character text fit the small form: the whole variable is
        // flags (16) + dims (16) + name (8) + data (8) + the miMATRIX tag (8).
        let bytes = mat_bytes(&[("abcd", ArrayValue::Text("ok".into()))], "").unwrap();
        assert_eq!(bytes.len(), 128 + 8 + 48);
        assert_eq!(u32_at(&bytes, 128 + 8 + 32), (4 << 16) | MI_INT8);
        assert_eq!(&bytes[128 + 8 + 36..128 + 8 + 40], b"abcd");
        assert_eq!(u32_at(&bytes, 128 + 8 + 40), (4 << 16) | MI_UTF16);
        // A 5-character name does not: tag (8) + 5 bytes + 3 of padding.
        let bytes = mat_bytes(&[("abcde", ArrayValue::scalar(1.0))], "").unwrap();
        assert_eq!(u32_at(&bytes, 128 + 8 + 32), MI_INT8);
        assert_eq!(u32_at(&bytes, 128 + 8 + 36), 5);
        let (_, vars) = mat_read(&bytes);
        assert_eq!(vars[0].0, "abcde");
    }

    #[test]
    fn mat_transposes_every_rank() {
        // 2×3×4 in C order: value = 100 i + 10 j + k.
        let (a, b, c) = (2, 3, 4);
        let data: Vec<f64> = (0..a * b * c)
            .map(|n| (100 * (n / (b * c)) + 10 * (n / c % b) + n % c) as f64)
            .collect();
        let value = ArrayValue::Real {
            shape: vec![a, b, c],
            data,
        };
        let (_, vars) = mat_read(&mat_bytes(&[("T", value)], "").unwrap());
        let MatVar::Double { dims, data } = &vars[0].1 else {
            panic!("{vars:?}")
        };
        assert_eq!(dims, &[2, 3, 4]);
        // Fortran order: first index fastest.
        let mut n = 0;
        for k in 0..c {
            for j in 0..b {
                for i in 0..a {
                    assert_eq!(data[n], (100 * i + 10 * j + k) as f64);
                    n += 1;
                }
            }
        }
    }

    #[test]
    fn mat_text_keeps_unicode_and_cleans_the_header() {
        let bytes = mat_bytes(
            &[("angle", ArrayValue::Text("θ° 𝜔".into()))],
            &format!("é\n{}", "x".repeat(200)),
        )
        .unwrap();
        let (text, vars) = mat_read(&bytes);
        assert_eq!(text.len(), 116);
        assert!(text.starts_with("MATLAB 5.0 MAT-file, ??xxx"));
        // 𝜔 (beyond the BMP) would be a surrogate pair, which SciPy cannot read: U+FFFD.
        assert_eq!(
            vars[0].1,
            MatVar::Char {
                dims: vec![1, 4],
                text: "θ° \u{FFFD}".into()
            }
        );
    }

    #[test]
    fn writes_are_byte_identical() {
        assert_eq!(npz_bytes(&sample()).unwrap(), npz_bytes(&sample()).unwrap());
        assert_eq!(
            mat_bytes(&sample(), "x").unwrap(),
            mat_bytes(&sample(), "x").unwrap()
        );
        // Order is the caller's: swapping two arrays changes the bytes.
        let mut swapped = sample();
        swapped.swap(0, 1);
        assert_ne!(npz_bytes(&sample()).unwrap(), npz_bytes(&swapped).unwrap());
    }

    #[test]
    fn bad_names_are_refused_in_both_formats() {
        let cases: [(&str, NameProblem); 6] = [
            ("", NameProblem::Empty),
            ("1abc", NameProblem::BadFirstCharacter),
            ("_abc", NameProblem::BadFirstCharacter),
            ("a-b", NameProblem::BadCharacter('-')),
            ("end", NameProblem::Keyword),
            (&"a".repeat(64), NameProblem::TooLong { chars: 64 }),
        ];
        for (name, problem) in cases {
            let arrays = [(name, ArrayValue::scalar(1.0))];
            for result in [npz_bytes(&arrays), mat_bytes(&arrays, "")] {
                match result {
                    Err(ArrayFileError::InvalidName {
                        name: n,
                        problem: p,
                    }) => {
                        assert_eq!((n.as_str(), &p), (name, &problem))
                    }
                    other => panic!("{name:?}: {other:?}"),
                }
            }
        }
        let longest = "a".repeat(63);
        assert!(mat_bytes(&[(&longest, ArrayValue::scalar(1.0))], "").is_ok());
        assert!(mat_bytes(&[("ü", ArrayValue::scalar(1.0))], "").is_err());
    }

    #[test]
    fn duplicate_names_mismatched_shapes_and_nul_are_refused() {
        let dup = [
            ("a", ArrayValue::scalar(1.0)),
            ("a", ArrayValue::scalar(2.0)),
        ];
        assert!(matches!(
            npz_bytes(&dup),
            Err(ArrayFileError::DuplicateName { name }) if name == "a"
        ));
        assert!(matches!(
            mat_bytes(&dup, ""),
            Err(ArrayFileError::DuplicateName { .. })
        ));

        let bad = [("m", ArrayValue::matrix(2, 3, vec![0.0; 5]))];
        let err = mat_bytes(&bad, "").unwrap_err();
        assert!(matches!(
            err,
            ArrayFileError::ShapeMismatch {
                elements: 6,
                data_len: 5,
                ..
            }
        ));
        assert_eq!(
            err.to_string(),
            "array \"m\": shape [2, 3] holds 6 values but 5 were given"
        );
        let huge = [(
            "h",
            ArrayValue::Real {
                shape: vec![usize::MAX, 2],
                data: vec![],
            },
        )];
        assert!(matches!(
            npz_bytes(&huge),
            Err(ArrayFileError::ShapeMismatch {
                elements: usize::MAX,
                ..
            })
        ));

        let nul = [("s", ArrayValue::Strings(vec!["ok".into(), "a\0".into()]))];
        assert!(matches!(
            npz_bytes(&nul),
            Err(ArrayFileError::NulInText { index: 1, .. })
        ));
    }

    #[test]
    fn mat_dimension_beyond_i32_is_refused() {
        let zero_rows = [(
            "z",
            ArrayValue::Real {
                shape: vec![0, 1 << 31],
                data: vec![],
            },
        )];
        assert!(matches!(
            mat_bytes(&zero_rows, ""),
            Err(ArrayFileError::TooLarge { largest_dim, .. }) if largest_dim == 1 << 31
        ));
        // NumPy has no such limit.
        assert!(npz_bytes(&zero_rows).is_ok());
    }

    #[test]
    fn empty_arrays() {
        let arrays = [
            ("e", ArrayValue::matrix(0, 3, vec![])),
            ("c", ArrayValue::Strings(vec![])),
        ];
        let (_, vars) = mat_read(&mat_bytes(&arrays, "").unwrap());
        assert_eq!(
            vars[0].1,
            MatVar::Double {
                dims: vec![0, 3],
                data: vec![]
            }
        );
        assert_eq!(
            vars[1].1,
            MatVar::Cell {
                dims: vec![1, 0],
                items: vec![]
            }
        );
        let entries = zip_entries(&npz_bytes(&arrays).unwrap());
        assert_eq!(
            npy_parts(&entries[0].1).0,
            "{'descr': '<f8', 'fortran_order': False, 'shape': (0, 3), }"
        );
    }
}
