//! The GLB container of glTF 2.0: a 12-byte header, a JSON chunk and a BIN chunk.

/// `glTF` in little-endian ASCII: the first four bytes of every GLB file.
pub const GLB_MAGIC: u32 = 0x4654_6C67;
/// The JSON chunk's type, `JSON`.
pub const CHUNK_JSON: u32 = 0x4E4F_534A;
/// The binary chunk's type, `BIN\0`.
pub const CHUNK_BIN: u32 = 0x004E_4942;

/// The GLB file of the glTF document `json` (its text) and its one binary buffer `bin`: the
/// header (magic, version 2, total length), the JSON chunk padded with spaces and the BIN
/// chunk padded with zeros, each chunk's length a multiple of 4 (glTF 2.0, §4.4).
pub fn glb_bytes(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let pad = |n: usize| (4 - n % 4) % 4;
    let json_len = json.len() + pad(json.len());
    let bin_len = bin.len() + pad(bin.len());
    let total = 12 + 8 + json_len + if bin.is_empty() { 0 } else { 8 + bin_len };
    let mut out = Vec::with_capacity(total);
    for word in [GLB_MAGIC, 2, total as u32, json_len as u32, CHUNK_JSON] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    out.extend_from_slice(json);
    out.resize(20 + json_len, b' ');
    if !bin.is_empty() {
        out.extend_from_slice(&(bin_len as u32).to_le_bytes());
        out.extend_from_slice(&CHUNK_BIN.to_le_bytes());
        out.extend_from_slice(bin);
        out.resize(total, 0);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn word(b: &[u8], at: usize) -> u32 {
        u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
    }

    #[test]
    fn header_and_chunks_are_aligned_and_counted() {
        // JSON of 5 bytes pads to 8, BIN of 6 to 8: 12 + 8 + 8 + 8 + 8 = 44 bytes.
        let glb = glb_bytes(b"{\"a\":", &[1, 2, 3, 4, 5, 6]);
        assert_eq!(glb.len(), 44);
        assert_eq!(&glb[0..4], b"glTF");
        assert_eq!(word(&glb, 4), 2);
        assert_eq!(word(&glb, 8), 44);
        assert_eq!(word(&glb, 12), 8);
        assert_eq!(&glb[16..20], b"JSON");
        assert_eq!(&glb[20..28], b"{\"a\":   ");
        assert_eq!(word(&glb, 28), 8);
        assert_eq!(&glb[32..36], b"BIN\0");
        assert_eq!(&glb[36..44], &[1, 2, 3, 4, 5, 6, 0, 0]);
        // Without a buffer there is no BIN chunk.
        assert_eq!(glb_bytes(b"{}", &[]).len(), 24);
    }
}
