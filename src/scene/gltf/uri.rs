//! The URIs a glTF file names its buffers and images with: `data:` URIs (base64 or
//! percent-encoded) decoded in memory, relative file references percent-decoded into paths.
//! Nothing is fetched over a network: any other scheme is refused.

/// What a URI refers to.
#[derive(Debug, PartialEq, Eq)]
pub(super) enum Uri {
    /// The bytes of a `data:` URI and its media type (empty when not given).
    Data {
        /// Media type, e.g. `image/png` (parameters such as `;charset` dropped).
        media_type: String,
        /// The decoded payload.
        bytes: Vec<u8>,
    },
    /// A file, relative to the glTF file's folder (percent-decoded).
    File(String),
}

/// Whether `uri` is a `data:` URI (its scheme alone, nothing decoded).
pub(super) fn is_data(uri: &str) -> bool {
    strip_prefix_ignore_case(uri, "data:").is_some()
}

/// Classifies and decodes `uri`; errors say what is wrong with it.
pub(super) fn parse(uri: &str) -> Result<Uri, String> {
    if let Some(rest) = strip_prefix_ignore_case(uri, "data:") {
        let (header, payload) = rest
            .split_once(',')
            .ok_or("a data URI without a `,` before its payload")?;
        let mut params = header.split(';');
        let media_type = params.next().unwrap_or_default().trim().to_lowercase();
        let base64 = params.any(|p| p.trim().eq_ignore_ascii_case("base64"));
        let bytes = if base64 {
            decode_base64(payload)?
        } else {
            percent_decode(payload)?
        };
        return Ok(Uri::Data { media_type, bytes });
    }
    if let Some(scheme) = scheme(uri) {
        return Err(format!(
            "URI scheme `{scheme}:` is not read (only data URIs and files next to the glTF file)"
        ));
    }
    if uri.is_empty() {
        return Err("an empty URI".into());
    }
    let decoded = percent_decode(uri)?;
    String::from_utf8(decoded)
        .map(Uri::File)
        .map_err(|_| "a file URI that is not UTF-8 once percent-decoded".into())
}

fn strip_prefix_ignore_case<'a>(s: &'a str, prefix: &str) -> Option<&'a str> {
    let head = s.get(..prefix.len())?;
    head.eq_ignore_ascii_case(prefix)
        .then(|| &s[prefix.len()..])
}

/// The scheme of an absolute URI (`http` of `http://…`), or `None` for a relative reference.
/// A single letter before `:` is a Windows drive, not a scheme.
fn scheme(uri: &str) -> Option<&str> {
    let (scheme, _) = uri.split_once(':')?;
    let valid = scheme.len() > 1
        && scheme.starts_with(|c: char| c.is_ascii_alphabetic())
        && scheme
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'));
    valid.then_some(scheme)
}

/// `%XX` sequences to bytes; everything else as it is.
pub(super) fn percent_decode(s: &str) -> Result<Vec<u8>, String> {
    let bytes = s.as_bytes();
    let mut out = Vec::new();
    reserve(&mut out, bytes.len())?;
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| format!("a bad percent escape at byte {i}"))?;
            out.push(hex);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    Ok(out)
}

/// Standard base64 (RFC 4648, `+` and `/`; the URL-safe `-` and `_` accepted too), padding
/// optional, stray bits in the last character ignored. Errors name the first bad character's
/// position.
pub(super) fn decode_base64(s: &str) -> Result<Vec<u8>, String> {
    use base64::engine::{DecodePaddingMode, GeneralPurpose, GeneralPurposeConfig};
    use base64::{alphabet, DecodeError, Engine};
    const LENIENT: GeneralPurpose = GeneralPurpose::new(
        &alphabet::STANDARD,
        GeneralPurposeConfig::new()
            .with_decode_padding_mode(DecodePaddingMode::Indifferent)
            .with_decode_allow_trailing_bits(true),
    );
    // The URL-safe alphabet's two characters, mapped to the standard ones (exporters mix
    // them) in a copy made only where there are any: a payload may be a gigabyte.
    let payload = s.trim_end_matches('=');
    let mapped;
    let input = if payload.contains(['-', '_']) {
        let mut copy = Vec::new();
        reserve(&mut copy, payload.len())?;
        copy.extend(payload.bytes().map(|c| match c {
            b'-' => b'+',
            b'_' => b'/',
            c => c,
        }));
        mapped = copy;
        &mapped[..]
    } else {
        payload.as_bytes()
    };
    let mut out = Vec::new();
    reserve(&mut out, base64::decoded_len_estimate(input.len()))?;
    LENIENT.decode_vec(input, &mut out).map_err(|e| match e {
        // The position only: the payload is the file's data.
        DecodeError::InvalidByte(i, _) => {
            format!("base64 payload has an invalid character at position {i}")
        }
        DecodeError::InvalidLength(_) | DecodeError::InvalidLastSymbol(..) => {
            "base64 payload is truncated (its length is not valid)".into()
        }
        DecodeError::InvalidPadding => "base64 payload has invalid padding".into(),
    })?;
    Ok(out)
}

/// Room for `bytes` more in `v`, asked of the allocator (a failed allocation would abort).
fn reserve(v: &mut Vec<u8>, bytes: usize) -> Result<(), String> {
    v.try_reserve_exact(bytes).map_err(|_| {
        format!("a data URI of {bytes} bytes: more than this process can allocate now")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_decodes_with_and_without_padding() {
        assert_eq!(decode_base64("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(decode_base64("aGVsbG8").unwrap(), b"hello");
        assert_eq!(decode_base64("aGVsbG8h").unwrap(), b"hello!");
        assert_eq!(decode_base64("").unwrap(), b"");
        assert_eq!(decode_base64("AAECAw==").unwrap(), [0, 1, 2, 3]);
        let err = decode_base64("aGV*bG8=").unwrap_err();
        assert!(err.contains("position 3") && !err.contains('*'), "{err}");
        // URL-safe characters, mapped; and a character that is not ASCII is not shown.
        assert_eq!(decode_base64("-_-_").unwrap(), [0xfb, 0xff, 0xbf]);
        let err = decode_base64("aGV\u{c3}bG8=").unwrap_err();
        assert!(
            err.contains("position 3") && !err.contains('\u{c3}'),
            "{err}"
        );
        assert!(
            decode_base64("aGVsb").is_err(),
            "one character past a whole byte"
        );
    }

    #[test]
    fn data_uris_files_and_schemes() {
        assert_eq!(
            parse("data:application/octet-stream;base64,AAEC").unwrap(),
            Uri::Data {
                media_type: "application/octet-stream".into(),
                bytes: vec![0, 1, 2]
            }
        );
        assert_eq!(
            parse("DATA:image/png,%41b").unwrap(),
            Uri::Data {
                media_type: "image/png".into(),
                bytes: b"Ab".to_vec()
            }
        );
        assert_eq!(
            parse("tex/my%20file.png").unwrap(),
            Uri::File("tex/my file.png".into())
        );
        assert_eq!(
            parse("C:/models/a.bin").unwrap(),
            Uri::File("C:/models/a.bin".into())
        );
        assert!(parse("https://example.com/a.bin")
            .unwrap_err()
            .contains("https"));
        assert!(parse("data:;base64").is_err());
        assert!(parse("a%zz.bin").is_err());
        assert!(parse("").is_err());
    }
}
