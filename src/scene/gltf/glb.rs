//! The binary container (`.glb`): a 12-byte header, a JSON chunk, an optional BIN chunk.
//! Parsed here rather than by the `gltf` crate so that a truncated or lying header is an error
//! that says which length is wrong (the crate's own parser subtracts before it checks).

/// The magic number every GLB starts with.
pub(super) const MAGIC: &[u8; 4] = b"glTF";
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;

/// The chunks of a GLB file.
#[derive(Debug)]
pub(super) struct Glb<'a> {
    /// The JSON chunk.
    pub json: &'a [u8],
    /// The first BIN chunk, if there is one.
    pub bin: Option<&'a [u8]>,
}

fn u32_at(bytes: &[u8], at: usize) -> Option<u32> {
    let b = bytes.get(at..at.checked_add(4)?)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// A chunk type for messages: its number, and its four bytes when they are printable ASCII
/// (`0x004E4942 \`BIN\``).
fn chunk_type(kind: u32) -> String {
    let bytes = kind.to_le_bytes();
    let printable = bytes
        .iter()
        .all(|b| b.is_ascii_graphic() || *b == 0 || *b == b' ');
    let text: String = bytes
        .iter()
        .map(|&b| {
            if b == 0 {
                "\\0".to_string()
            } else {
                (b as char).to_string()
            }
        })
        .collect();
    if printable {
        format!("0x{kind:08X} `{text}`")
    } else {
        format!("0x{kind:08X}")
    }
}

/// Splits a GLB file into its chunks; errors say what is truncated or wrong.
pub(super) fn split(bytes: &[u8]) -> Result<Glb<'_>, String> {
    if bytes.len() < 12 {
        return Err(format!(
            "truncated GLB: {} bytes, less than its 12-byte header",
            bytes.len()
        ));
    }
    let version = u32_at(bytes, 4).unwrap_or_default();
    if version != 2 {
        return Err(format!("GLB version {version}; only version 2 is read"));
    }
    let length = u32_at(bytes, 8).unwrap_or_default() as usize;
    if length > bytes.len() {
        return Err(format!(
            "truncated GLB: its header says {length} bytes, the file has {}",
            bytes.len()
        ));
    }
    if length < 20 {
        return Err(format!(
            "GLB header says {length} bytes: too short for the JSON chunk every GLB has"
        ));
    }
    // Bytes past the declared length are ignored, as the format says.
    let body = &bytes[..length];
    let mut at = 12;
    let mut json = None;
    let mut bin = None;
    while at < body.len() {
        let (Some(chunk_len), Some(kind)) = (u32_at(body, at), u32_at(body, at + 4)) else {
            return Err(format!(
                "truncated GLB: a chunk header at byte {at} runs past the end ({length} bytes)"
            ));
        };
        let start = at + 8;
        let end = start
            .checked_add(chunk_len as usize)
            .filter(|&e| e <= body.len())
            .ok_or_else(|| {
                format!(
                    "truncated GLB: the chunk at byte {at} says {chunk_len} bytes, only {} \
                     remain",
                    body.len() - start.min(body.len())
                )
            })?;
        let data = &body[start..end];
        match kind {
            CHUNK_JSON if json.is_none() => json = Some(data),
            _ if json.is_none() => {
                return Err(format!(
                    "GLB's first chunk has type {}; it must be JSON (0x{CHUNK_JSON:08X} `JSON`)",
                    chunk_type(kind)
                ))
            }
            CHUNK_JSON => return Err(format!("GLB has a second JSON chunk at byte {at}")),
            CHUNK_BIN if bin.is_none() => bin = Some(data),
            // Further BIN chunks and chunks of unknown types are ignored (the format says so).
            _ => {}
        }
        // Chunks are padded to 4 bytes; a length that is not is tolerated.
        at = end.div_ceil(4) * 4;
    }
    let json = json.ok_or("GLB has no JSON chunk")?;
    Ok(Glb { json, bin })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
        let pad = |v: &[u8], with: u8| {
            let mut v = v.to_vec();
            while !v.len().is_multiple_of(4) {
                v.push(with);
            }
            v
        };
        let mut body = Vec::new();
        let json = pad(json, b' ');
        body.extend((json.len() as u32).to_le_bytes());
        body.extend(CHUNK_JSON.to_le_bytes());
        body.extend(&json);
        if let Some(bin) = bin {
            let bin = pad(bin, 0);
            body.extend((bin.len() as u32).to_le_bytes());
            body.extend(CHUNK_BIN.to_le_bytes());
            body.extend(&bin);
        }
        let mut out = MAGIC.to_vec();
        out.extend(2u32.to_le_bytes());
        out.extend(((body.len() + 12) as u32).to_le_bytes());
        out.extend(body);
        out
    }

    #[test]
    fn splits_json_and_bin() {
        let file = glb(br#"{"asset":{"version":"2.0"}}"#, Some(&[1, 2, 3]));
        let g = split(&file).unwrap();
        assert!(g.json.starts_with(br#"{"asset""#));
        assert_eq!(g.bin.unwrap(), [1, 2, 3, 0]);
        let file = glb(b"{}", None);
        assert!(split(&file).unwrap().bin.is_none());
    }

    #[test]
    fn truncations_and_bad_headers_say_what_is_wrong() {
        let file = glb(br#"{"asset":{"version":"2.0"}}"#, Some(&[1, 2, 3, 4, 5]));
        for cut in [0, 5, 11, 12, 19, 30, file.len() - 1] {
            let err = split(&file[..cut]).unwrap_err();
            assert!(
                err.contains("truncated") || err.contains("short"),
                "{cut}: {err}"
            );
        }
        let mut v1 = file.clone();
        v1[4] = 1;
        assert!(split(&v1).unwrap_err().contains("version 1"));
        // A chunk length that runs past the declared length.
        let mut long = file.clone();
        long[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(split(&long).unwrap_err().contains("chunk at byte 12"));
    }

    #[test]
    fn a_first_chunk_that_is_not_json_is_named_by_its_type() {
        let file = glb(br#"{"asset":{"version":"2.0"}}"#, Some(&[1, 2, 3, 4]));
        for (kind, want) in [
            (*b"BIN\0", "0x004E4942 `BIN\\0`"),
            (*b"XYZW", "0x575A5958 `XYZW`"),
            ([1, 2, 3, 200], "type 0xC8030201;"),
        ] {
            let mut bad = file.clone();
            bad[16..20].copy_from_slice(&kind);
            let err = split(&bad).unwrap_err();
            assert!(
                err.contains("first chunk has type") && err.contains(want),
                "{err}"
            );
        }
    }
}
