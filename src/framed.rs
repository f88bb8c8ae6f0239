//! The framing of mecano-rs's binary files (`checkpoint.bin`, the superelement reduction
//! cache): an 8-byte magic, the format version (u32, little-endian), the payload's length
//! (u64, LE), the SHA-256 of the payload (32 bytes), then the payload. A torn, damaged or
//! foreign file is recognised by its magic, version, length and checksum.

use sha2::{Digest, Sha256};

/// Bytes before the payload.
pub const HEADER_LEN: usize = 8 + 4 + 8 + 32;

/// `payload` framed under `magic` and `version`.
pub fn frame(magic: &[u8; 8], version: u32, payload: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER_LEN + payload.len());
    out.extend_from_slice(magic);
    out.extend_from_slice(&version.to_le_bytes());
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&Sha256::digest(payload));
    out.extend_from_slice(payload);
    out
}

/// The payload of `bytes` framed under `magic` and `version`, or why it is not one (in
/// words for a user: "it does not begin with …", "format version …", "… (a torn write?)",
/// "… (a damaged file?)").
pub fn unframe<'a>(bytes: &'a [u8], magic: &[u8; 8], version: u32) -> Result<&'a [u8], String> {
    if bytes.len() < HEADER_LEN || &bytes[..8] != magic {
        return Err(format!(
            "it does not begin with `{}`",
            String::from_utf8_lossy(magic)
        ));
    }
    let found = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
    if found != version {
        return Err(format!(
            "format version {found}, this mecano-rs reads version {version}"
        ));
    }
    let len = u64::from_le_bytes(bytes[12..20].try_into().expect("8 bytes"));
    let payload = &bytes[HEADER_LEN..];
    if payload.len() as u64 != len {
        return Err(format!(
            "{} bytes of payload, the header says {len} (a torn write?)",
            payload.len()
        ));
    }
    if Sha256::digest(payload)[..] != bytes[20..52] {
        return Err("its checksum does not match (a damaged file?)".into());
    }
    Ok(payload)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame reads back; each kind of damage is refused with its own reason.
    #[test]
    fn frames_read_back_and_damage_is_named() {
        let f = frame(b"MECANOXX", 3, b"payload");
        assert_eq!(unframe(&f, b"MECANOXX", 3), Ok(&b"payload"[..]));
        assert!(
            unframe(&f, b"MECANOYY", 3)
                .unwrap_err()
                .contains("`MECANOYY`")
        );
        assert!(
            unframe(&f, b"MECANOXX", 4)
                .unwrap_err()
                .contains("format version 3")
        );
        assert!(
            unframe(&f[..f.len() - 1], b"MECANOXX", 3)
                .unwrap_err()
                .contains("torn")
        );
        let mut bad = f.clone();
        *bad.last_mut().unwrap() ^= 1;
        assert!(
            unframe(&bad, b"MECANOXX", 3)
                .unwrap_err()
                .contains("damaged")
        );
    }
}
