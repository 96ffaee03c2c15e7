//! Base64 (RFC 4648, standard alphabet, padded): how the viewer's page carries its binary
//! arrays (float32 positions, uint32 indices) in text.

const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// `bytes` in base64: each 3 bytes become 4 characters, the last group padded with `=`.
pub fn base64(bytes: &[u8]) -> String {
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for group in bytes.chunks(3) {
        let b = [
            group[0],
            group.get(1).copied().unwrap_or(0),
            group.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= group.len() {
                out.push(ALPHABET[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Little-endian float32 values in base64 (JavaScript's `Float32Array` on every browser's
/// little-endian platform).
pub fn base64_f32(values: impl IntoIterator<Item = f32>) -> String {
    base64(
        &values
            .into_iter()
            .flat_map(f32::to_le_bytes)
            .collect::<Vec<u8>>(),
    )
}

/// Little-endian uint32 values in base64.
pub fn base64_u32(values: impl IntoIterator<Item = u32>) -> String {
    base64(
        &values
            .into_iter()
            .flat_map(u32::to_le_bytes)
            .collect::<Vec<u8>>(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rfc_4648_test_vectors() {
        // RFC 4648 §10.
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(plain.as_bytes()), coded);
        }
        // 1.0f32 is 0x3F800000: bytes 00 00 80 3F.
        assert_eq!(base64_f32([1.0]), "AACAPw==");
        assert_eq!(base64_u32([1]), "AQAAAA==");
    }
}
