//! Named arrays written as NumPy `.npz` and MATLAB `.mat` files (`boomsim linearize --out`),
//! from the formats' own specifications, no Python needed:
//! - `.npz`: a zip of `.npy` files, format version 1.0 (numpy's `numpy/lib/format.py` docs): the
//!   magic `\x93NUMPY`, version 1.0, a little-endian u16 header length, a Python dict literal
//!   `{'descr': ..., 'fortran_order': ..., 'shape': ...}` padded with spaces and a newline to a
//!   multiple of 64 bytes, then the data;
//! - `.mat`: Level 5 MAT-file (MathWorks, "MAT-File Format", R2024a, ch. 1): a 128-byte header,
//!   then one `miMATRIX` element per variable (array flags, dimensions, name, real and imaginary
//!   parts), each sub-element padded to 8 bytes; strings are cell arrays of char rows.
//!
//! Checked by reading the files back with numpy and scipy.io (tests/python/test_linearize.py).

use nalgebra::{Complex, DMatrix};
use std::io::Write;

/// One named array.
pub enum Array {
    /// A real matrix.
    Real(DMatrix<f64>),
    /// A real vector (1-D in .npz, a column in .mat).
    Column(Vec<f64>),
    /// A complex column.
    Complex(Vec<Complex<f64>>),
    /// A list of strings.
    Strings(Vec<String>),
}

/// Writes `arrays` to `path` as `.npz` or `.mat`, by its extension.
pub fn write(path: &std::path::Path, arrays: &[(&str, Array)]) -> Result<(), String> {
    let bytes = match path.extension().and_then(|e| e.to_str()) {
        Some("npz") => npz(arrays)?,
        Some("mat") => mat(arrays),
        _ => return Err(format!("{}: the extension must be .npz or .mat", path.display())),
    };
    std::fs::write(path, bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// The `.npy` file of one array: matrices 2-D in C order, columns and lists 1-D.
fn npy(a: &Array) -> Vec<u8> {
    let (descr, shape, data): (String, String, Vec<u8>) = match a {
        Array::Column(v) => ("<f8".into(), format!("({},)", v.len()), v.iter().flat_map(|x| x.to_le_bytes()).collect()),
        Array::Real(m) => {
            let rows = m.row_iter().flat_map(|r| r.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<_>>());
            ("<f8".into(), format!("({}, {})", m.nrows(), m.ncols()), rows.collect())
        }
        Array::Complex(z) => (
            "<c16".into(),
            format!("({},)", z.len()),
            z.iter().flat_map(|z| z.re.to_le_bytes().into_iter().chain(z.im.to_le_bytes())).collect(),
        ),
        Array::Strings(s) => {
            // '<U{n}': n UTF-32LE code points per string, zero padded.
            let n = s.iter().map(|s| s.chars().count()).max().unwrap_or(0).max(1);
            let data = s
                .iter()
                .flat_map(|s| {
                    s.chars().map(|c| c as u32).chain(std::iter::repeat(0)).take(n).flat_map(u32::to_le_bytes)
                })
                .collect();
            (format!("<U{n}"), format!("({},)", s.len()), data)
        }
    };
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    let total = 10 + header.len() + 1;
    header.push_str(&" ".repeat((64 - total % 64) % 64));
    header.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out.extend(data);
    out
}

fn npz(arrays: &[(&str, Array)]) -> Result<Vec<u8>, String> {
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let options = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    for (name, a) in arrays {
        zip.start_file(format!("{name}.npy"), options).map_err(|e| e.to_string())?;
        zip.write_all(&npy(a)).map_err(|e| e.to_string())?;
    }
    Ok(zip.finish().map_err(|e| e.to_string())?.into_inner())
}

// Level 5 MAT-file data types and array classes (MAT-File Format, Tables 1-1 and 1-3).
const MI_INT8: u32 = 1;
const MI_UINT16: u32 = 4;
const MI_INT32: u32 = 5;
const MI_UINT32: u32 = 6;
const MI_DOUBLE: u32 = 9;
const MI_MATRIX: u32 = 14;
const MX_CELL: u32 = 1;
const MX_CHAR: u32 = 4;
const MX_DOUBLE: u32 = 6;
/// Array flags bit of a complex array.
const COMPLEX: u32 = 0x0800;

/// A data element: tag (type, byte count) and data padded to 8 bytes.
fn element(ty: u32, data: &[u8]) -> Vec<u8> {
    let mut out = ty.to_le_bytes().to_vec();
    out.extend_from_slice(&(data.len() as u32).to_le_bytes());
    out.extend_from_slice(data);
    out.resize(out.len().next_multiple_of(8), 0);
    out
}

/// A `miMATRIX` element of class `class` (flags `flags`), `rows` x `cols`, named `name`, with
/// the parts (real, imaginary, or a cell's elements) that follow the name.
fn matrix(class: u32, flags: u32, rows: usize, cols: usize, name: &str, parts: &[u8]) -> Vec<u8> {
    let mut body = element(MI_UINT32, &[(class | flags).to_le_bytes(), 0u32.to_le_bytes()].concat());
    body.extend(element(MI_INT32, &[(rows as i32).to_le_bytes(), (cols as i32).to_le_bytes()].concat()));
    body.extend(element(MI_INT8, name.as_bytes()));
    body.extend_from_slice(parts);
    element(MI_MATRIX, &body)
}

fn doubles(x: impl Iterator<Item = f64>) -> Vec<u8> {
    element(MI_DOUBLE, &x.flat_map(f64::to_le_bytes).collect::<Vec<_>>())
}

/// One variable: matrices column-major as MATLAB stores them, strings a column cell of rows.
fn mat_variable(name: &str, a: &Array) -> Vec<u8> {
    match a {
        Array::Real(m) => matrix(MX_DOUBLE, 0, m.nrows(), m.ncols(), name, &doubles(m.iter().copied())),
        Array::Column(v) => matrix(MX_DOUBLE, 0, v.len(), 1, name, &doubles(v.iter().copied())),
        Array::Complex(z) => {
            let mut parts = doubles(z.iter().map(|z| z.re));
            parts.extend(doubles(z.iter().map(|z| z.im)));
            matrix(MX_DOUBLE, COMPLEX, z.len(), 1, name, &parts)
        }
        Array::Strings(s) => {
            let cells: Vec<u8> = s
                .iter()
                .flat_map(|s| {
                    let utf16: Vec<u16> = s.encode_utf16().collect();
                    let chars = element(MI_UINT16, &utf16.iter().flat_map(|c| c.to_le_bytes()).collect::<Vec<_>>());
                    matrix(MX_CHAR, 0, 1, utf16.len(), "", &chars)
                })
                .collect();
            matrix(MX_CELL, 0, s.len(), 1, name, &cells)
        }
    }
}

fn mat(arrays: &[(&str, Array)]) -> Vec<u8> {
    let text = "MATLAB 5.0 MAT-file, written by boomsim linearize";
    let mut out = format!("{text:<116}").into_bytes();
    out.extend_from_slice(&[0; 8]); // no subsystem data
    out.extend_from_slice(&0x0100u16.to_le_bytes());
    out.extend_from_slice(b"IM"); // read as a little-endian u16: 'M' 'I'
    for (name, a) in arrays {
        out.extend(mat_variable(name, a));
    }
    out
}
