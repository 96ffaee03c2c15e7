//! The data arrays of a VTK XML file, written either inline as ASCII text or appended after
//! the XML as raw binary, zlib-compressed (`vtkZLibDataCompressor`, `header_type="UInt64"`):
//! a large model's ParaView files are then a fraction of the size and read far faster.
//!
//! A compressed array is a header of UInt64 — the number of blocks, the uncompressed block
//! size, the uncompressed size of a partial last block (0 when it is full) and each block's
//! compressed size — followed by the blocks, each a zlib stream. The `offset` of an array
//! counts bytes from the `_` that opens the appended data.

use crate::Real;
use flate2::write::ZlibEncoder;
use flate2::Compression;
use std::fmt::Write as _;
use std::io::Write as _;

/// Uncompressed bytes per compressed block.
const BLOCK: usize = 1 << 20;

/// How the data arrays of a `.vtu` file are stored.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum VtkEncoding {
    /// Appended raw binary, zlib-compressed (the default).
    #[default]
    Binary,
    /// Inline ASCII text, readable in an editor.
    Ascii,
}

impl VtkEncoding {
    /// The `[output] vtk_format` value: `"binary"` or `"ascii"`.
    pub fn parse(text: &str) -> Option<Self> {
        match text {
            "binary" => Some(VtkEncoding::Binary),
            "ascii" => Some(VtkEncoding::Ascii),
            _ => None,
        }
    }

    /// The attributes of the `VTKFile` element after `byte_order`: the compressor when arrays
    /// are compressed.
    pub(crate) fn file_attributes(self) -> &'static str {
        match self {
            VtkEncoding::Binary => " compressor=\"vtkZLibDataCompressor\"",
            VtkEncoding::Ascii => "",
        }
    }
}

/// The XML of a file being written and, in binary, the appended bytes of its arrays.
pub(crate) struct VtuArrays {
    encoding: VtkEncoding,
    /// The XML so far.
    pub(crate) xml: String,
    appended: Vec<u8>,
}

/// The element type of an array, with how to write one value as text and as bytes.
trait Element: Copy {
    /// VTK's name of the type.
    const TYPE: &'static str;
    fn text(self, s: &mut String);
    fn bytes(self, out: &mut Vec<u8>);
}

impl Element for Real {
    const TYPE: &'static str = "Float64";
    fn text(self, s: &mut String) {
        let _ = write!(s, "{self:e} ");
    }
    fn bytes(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

/// A whole number stored as Int32 (body, member and obstacle numbers, flags).
#[derive(Clone, Copy)]
pub(crate) struct Int32(pub(crate) usize);

impl Element for Int32 {
    const TYPE: &'static str = "Int32";
    fn text(self, s: &mut String) {
        let _ = write!(s, "{} ", self.0);
    }
    fn bytes(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&(self.0 as i32).to_le_bytes());
    }
}

/// A point index or offset stored as Int64.
#[derive(Clone, Copy)]
pub(crate) struct Int64(pub(crate) usize);

impl Element for Int64 {
    const TYPE: &'static str = "Int64";
    fn text(self, s: &mut String) {
        let _ = write!(s, "{} ", self.0);
    }
    fn bytes(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&(self.0 as i64).to_le_bytes());
    }
}

/// A cell type stored as UInt8.
#[derive(Clone, Copy)]
pub(crate) struct UInt8(pub(crate) u8);

impl Element for UInt8 {
    const TYPE: &'static str = "UInt8";
    fn text(self, s: &mut String) {
        let _ = write!(s, "{} ", self.0);
    }
    fn bytes(self, out: &mut Vec<u8>) {
        out.push(self.0);
    }
}

impl VtuArrays {
    /// An empty file of `encoding`, `capacity` bytes of XML reserved.
    pub(crate) fn new(encoding: VtkEncoding, capacity: usize) -> Self {
        VtuArrays {
            encoding,
            xml: String::with_capacity(match encoding {
                VtkEncoding::Ascii => capacity,
                VtkEncoding::Binary => 4096,
            }),
            appended: Vec::new(),
        }
    }

    /// 3-vectors (`NumberOfComponents="3"`).
    pub(crate) fn vectors(&mut self, name: &str, v: &[[Real; 3]]) {
        self.array(name, 3, v.iter().flatten().copied());
    }

    /// Float64 scalars.
    pub(crate) fn scalars(&mut self, name: &str, v: impl Iterator<Item = Real>) {
        self.array(name, 1, v);
    }

    /// Int32 scalars.
    pub(crate) fn ints(&mut self, name: &str, v: impl Iterator<Item = usize>) {
        self.array(name, 1, v.map(Int32));
    }

    /// Int64 scalars (connectivity, offsets).
    pub(crate) fn longs(&mut self, name: &str, v: impl Iterator<Item = usize>) {
        self.array(name, 1, v.map(Int64));
    }

    /// UInt8 scalars (cell types).
    pub(crate) fn bytes(&mut self, name: &str, v: impl Iterator<Item = u8>) {
        self.array(name, 1, v.map(UInt8));
    }

    /// One `DataArray`. Scalars (1 component) leave `NumberOfComponents` out, so readers
    /// give plain arrays.
    fn array<E: Element>(
        &mut self,
        name: &str,
        components: usize,
        values: impl Iterator<Item = E>,
    ) {
        let s = &mut self.xml;
        let _ = write!(
            s,
            "        <DataArray type=\"{}\" Name=\"{name}\" ",
            E::TYPE
        );
        if components > 1 {
            let _ = write!(s, "NumberOfComponents=\"{components}\" ");
        }
        match self.encoding {
            VtkEncoding::Ascii => {
                s.push_str("format=\"ascii\">\n          ");
                for v in values {
                    v.text(s);
                }
                s.push_str("\n        </DataArray>\n");
            }
            VtkEncoding::Binary => {
                let _ = writeln!(
                    s,
                    "format=\"appended\" offset=\"{}\"/>",
                    self.appended.len()
                );
                let mut raw = Vec::new();
                for v in values {
                    v.bytes(&mut raw);
                }
                compressed(&raw, &mut self.appended);
            }
        }
    }

    /// The whole file: the XML, the appended data (binary) and the closing `</VTKFile>`.
    pub(crate) fn finish(mut self) -> Vec<u8> {
        if self.encoding == VtkEncoding::Ascii {
            self.xml.push_str("</VTKFile>\n");
            return self.xml.into_bytes();
        }
        let mut out = self.xml.into_bytes();
        out.reserve(self.appended.len() + 64);
        out.extend_from_slice(b"  <AppendedData encoding=\"raw\">\n   _");
        out.extend_from_slice(&self.appended);
        out.extend_from_slice(b"\n  </AppendedData>\n</VTKFile>\n");
        out
    }
}

/// Append `raw` to `out` as a zlib-compressed VTK array: the UInt64 header, then the blocks.
fn compressed(raw: &[u8], out: &mut Vec<u8>) {
    let blocks: Vec<Vec<u8>> = raw
        .chunks(BLOCK)
        .map(|chunk| {
            let mut z = ZlibEncoder::new(Vec::with_capacity(chunk.len() / 2), Compression::fast());
            // Writing to a Vec cannot fail.
            let _ = z.write_all(chunk);
            z.finish().unwrap_or_default()
        })
        .collect();
    let header = [blocks.len(), BLOCK, raw.len() % BLOCK]
        .into_iter()
        .chain(blocks.iter().map(Vec::len));
    for h in header {
        out.extend_from_slice(&(h as u64).to_le_bytes());
    }
    for b in &blocks {
        out.extend_from_slice(b);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flate2::read::ZlibDecoder;
    use std::io::Read as _;

    /// Read back the array at `offset` of the appended data `data`.
    fn decompress(data: &[u8], offset: usize) -> Vec<u8> {
        let word = |k: usize| {
            let at = offset + 8 * k;
            u64::from_le_bytes(data[at..at + 8].try_into().unwrap()) as usize
        };
        let blocks = word(0);
        let mut at = offset + 8 * (3 + blocks);
        let mut out = Vec::new();
        for b in 0..blocks {
            let size = word(3 + b);
            ZlibDecoder::new(&data[at..at + size])
                .read_to_end(&mut out)
                .unwrap();
            at += size;
        }
        assert_eq!(word(1), BLOCK);
        assert_eq!(word(2), out.len() % BLOCK);
        out
    }

    #[test]
    fn arrays_read_back_exactly_across_block_boundaries() {
        let mut a = VtuArrays::new(VtkEncoding::Binary, 0);
        let values: Vec<Real> = (0..300_000).map(|i| (i as Real).sin() * 1e-3).collect();
        a.scalars("s", values.iter().copied());
        a.ints("i", [1usize, 2, 3].into_iter());
        let xml = a.xml.clone();
        let file = a.finish();
        let opening = b"<AppendedData encoding=\"raw\">\n   _";
        let start = file
            .windows(opening.len())
            .position(|w| w == opening)
            .unwrap();
        let data = &file[start + opening.len()..];
        assert!(xml.contains("offset=\"0\""));
        let second: usize = xml
            .split("offset=\"")
            .nth(2)
            .and_then(|t| t.split('"').next())
            .and_then(|t| t.parse().ok())
            .unwrap();
        let back: Vec<Real> = decompress(data, 0)
            .chunks(8)
            .map(|c| Real::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(back, values, "2.4 MB: three blocks");
        let ints: Vec<i32> = decompress(data, second)
            .chunks(4)
            .map(|c| i32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(ints, [1, 2, 3]);
    }

    #[test]
    fn an_empty_array_has_no_blocks() {
        let mut out = Vec::new();
        compressed(&[], &mut out);
        assert_eq!(out.len(), 24);
        assert!(out
            .iter()
            .enumerate()
            .all(|(k, &b)| b == 0 || (8..16).contains(&k)));
    }

    #[test]
    fn ascii_arrays_are_inline_text() {
        let mut a = VtuArrays::new(VtkEncoding::Ascii, 0);
        a.vectors("v", &[[1.0, 2.0, 3.0]]);
        let text = String::from_utf8(a.finish()).unwrap();
        assert!(
            text.contains("NumberOfComponents=\"3\" format=\"ascii\">\n          1e0 2e0 3e0 \n")
        );
    }
}
