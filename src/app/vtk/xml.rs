//! A small writer of VTK XML files (the "VTK file formats" document of Kitware): unstructured
//! grids of vertex cells (`.vtu`) and image data (`.vti`), little-endian, every array inline
//! as base64 of a UInt64 byte count followed by the raw values (`format="binary"`,
//! uncompressed). Only what rheosph writes; read back by an independent reader in
//! `tests/lifecycle.rs`.

use std::fmt::Write as _;

/// One data array: a name, components per tuple, and the values.
pub enum DataArray<'a> {
    F64 {
        name: &'a str,
        components: usize,
        values: &'a [f64],
    },
    U8 {
        name: &'a str,
        values: &'a [u8],
    },
    I64 {
        name: &'a str,
        values: &'a [i64],
    },
}

impl DataArray<'_> {
    pub fn scalars<'a>(name: &'a str, values: &'a [f64]) -> DataArray<'a> {
        DataArray::F64 {
            name,
            components: 1,
            values,
        }
    }

    fn write(&self, xml: &mut String) {
        let (name, kind, components, bytes): (&str, &str, usize, Vec<u8>) = match self {
            DataArray::F64 {
                name,
                components,
                values,
            } => (
                name,
                "Float64",
                *components,
                values.iter().flat_map(|v| v.to_le_bytes()).collect(),
            ),
            DataArray::U8 { name, values } => (name, "UInt8", 1, values.to_vec()),
            DataArray::I64 { name, values } => (
                name,
                "Int64",
                1,
                values.iter().flat_map(|v| v.to_le_bytes()).collect(),
            ),
        };
        let _ = write!(
            xml,
            "        <DataArray type=\"{kind}\" Name=\"{name}\" NumberOfComponents=\"{components}\" format=\"binary\">"
        );
        let mut block = (bytes.len() as u64).to_le_bytes().to_vec();
        block.extend_from_slice(&bytes);
        base64(&block, xml);
        xml.push_str("</DataArray>\n");
    }
}

fn header(kind: &str) -> String {
    format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"{kind}\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
    )
}

fn point_data(xml: &mut String, arrays: &[DataArray]) {
    xml.push_str("      <PointData>\n");
    for a in arrays {
        a.write(xml);
    }
    xml.push_str("      </PointData>\n");
}

/// A `.vtu` of `points` (x, y, z triples), each its own vertex cell, with point data.
pub fn unstructured_vertices(points: &[f64], arrays: &[DataArray]) -> Vec<u8> {
    let n = points.len() / 3;
    let mut xml = header("UnstructuredGrid");
    let _ = writeln!(
        xml,
        "  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{n}\">"
    );
    point_data(&mut xml, arrays);
    xml.push_str("      <Points>\n");
    DataArray::F64 {
        name: "Points",
        components: 3,
        values: points,
    }
    .write(&mut xml);
    xml.push_str("      </Points>\n      <Cells>\n");
    let connectivity: Vec<i64> = (0..n as i64).collect();
    let offsets: Vec<i64> = (1..=n as i64).collect();
    for (name, values) in [("connectivity", &connectivity), ("offsets", &offsets)] {
        DataArray::I64 { name, values }.write(&mut xml);
    }
    const VTK_VERTEX: u8 = 1;
    DataArray::U8 {
        name: "types",
        values: &vec![VTK_VERTEX; n],
    }
    .write(&mut xml);
    xml.push_str("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
    xml.into_bytes()
}

/// A `.vti` of `dims[0] × dims[1]` points (x fastest) at `origin + (i, j)·spacing` in the
/// plane z = 0, with point data.
pub fn image_data(
    origin: [f64; 2],
    spacing: [f64; 2],
    dims: [usize; 2],
    arrays: &[DataArray],
) -> Vec<u8> {
    let extent = format!("0 {} 0 {} 0 0", dims[0] - 1, dims[1] - 1);
    let mut xml = header("ImageData");
    let _ = writeln!(
        xml,
        "  <ImageData WholeExtent=\"{extent}\" Origin=\"{:e} {:e} 0\" Spacing=\"{:e} {:e} 1\">\n    <Piece Extent=\"{extent}\">",
        origin[0], origin[1], spacing[0], spacing[1]
    );
    point_data(&mut xml, arrays);
    xml.push_str("      <CellData>\n      </CellData>\n    </Piece>\n  </ImageData>\n</VTKFile>\n");
    xml.into_bytes()
}

/// Standard base64 (RFC 4648, with padding), appended to `out`.
fn base64(bytes: &[u8], out: &mut String) {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    out.reserve(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let word = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(word >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::base64;

    /// The test vectors of RFC 4648 §10.
    #[test]
    fn base64_matches_rfc_4648() {
        for (input, expected) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            let mut out = String::new();
            base64(input.as_bytes(), &mut out);
            assert_eq!(out, expected);
        }
    }
}
