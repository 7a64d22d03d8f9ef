//! OBJ and MTL bytes as the text tobj reads, made within the memory the process can have: a
//! file of any bytes takes at most the room its conversion asks for first.

/// `bytes` as text: bytes that are not UTF-8 (a Latin-1 name) replaced by U+FFFD rather than
/// failing the whole read, and a lone CR (old Mac line ends) taken as a line end, as CRLF is;
/// a UTF-8 byte-order mark (Windows editors write one) is dropped, else tobj would not know
/// the first line's keyword. Also says whether any byte was not UTF-8. `Err` holds the bytes
/// the replaced text would need where the allocator cannot give them.
pub(super) fn text_of(mut bytes: Vec<u8>) -> Result<(String, bool), u64> {
    if bytes.starts_with(b"\xEF\xBB\xBF") {
        bytes.drain(..3);
    }
    // In place: neither line end nor any other byte moves across a multi-byte character.
    unify_line_ends(&mut bytes);
    // Valid UTF-8 (the common file) becomes the text without a copy.
    match String::from_utf8(bytes) {
        Ok(text) => Ok((text, false)),
        Err(e) => {
            let bytes = e.into_bytes();
            let needed = replaced_len(&bytes);
            Ok((replaced(&bytes, needed).ok_or(needed)?, true))
        }
    }
}

/// `bytes` with each invalid run replaced by U+FFFD, in one allocation of exactly `needed`
/// bytes (`String::from_utf8_lossy` grows by doubling: up to twice that, past what was
/// asked for). `None` where the allocator cannot give it.
fn replaced(bytes: &[u8], needed: u64) -> Option<String> {
    let mut text = String::new();
    text.try_reserve_exact(usize::try_from(needed).ok()?).ok()?;
    for chunk in bytes.utf8_chunks() {
        text.push_str(chunk.valid());
        if !chunk.invalid().is_empty() {
            text.push(char::REPLACEMENT_CHARACTER);
        }
    }
    Some(text)
}

/// Bytes of `bytes` as text with each invalid run replaced by U+FFFD (three bytes): up to three
/// times the file.
fn replaced_len(bytes: &[u8]) -> u64 {
    let replaced = |c: std::str::Utf8Chunk| {
        c.valid().len() as u64 + if c.invalid().is_empty() { 0 } else { 3 }
    };
    bytes.utf8_chunks().map(replaced).sum()
}

/// CRLF and lone CR line ends made LF, in place.
fn unify_line_ends(bytes: &mut Vec<u8>) {
    if !bytes.contains(&b'\r') {
        return;
    }
    let mut kept = 0;
    for read in 0..bytes.len() {
        let byte = bytes[read];
        if byte == b'\r' && bytes.get(read + 1) == Some(&b'\n') {
            continue;
        }
        // `kept` <= `read`: the byte after `read` is still the file's.
        bytes[kept] = if byte == b'\r' { b'\n' } else { byte };
        kept += 1;
    }
    bytes.truncate(kept);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_ends_and_bytes_that_are_not_utf8_read_as_text() {
        let text = |b: &[u8]| text_of(b.to_vec()).unwrap();
        assert_eq!(
            text(b"v 1\r\nv 2\rv 3\r\r\n\n"),
            ("v 1\nv 2\nv 3\n\n\n".into(), false)
        );
        assert_eq!(text(b"\xEF\xBB\xBFv 1\r"), ("v 1\n".into(), false));
        assert_eq!(
            text(b"usemtl caf\xE9\r\nf \xFF\xFE1"),
            ("usemtl caf\u{FFFD}\nf \u{FFFD}\u{FFFD}1".into(), true)
        );
        // A CR before a multi-byte character leaves it whole.
        assert_eq!(
            text("\r\u{e9}\r\n".as_bytes()),
            ("\n\u{e9}\n".into(), false)
        );
        assert_eq!(text(b""), (String::new(), false));
    }

    /// What the text with its replacements takes is what is asked for first.
    #[test]
    fn the_size_asked_for_is_the_replaced_texts() {
        for bytes in [
            &b"ok \xFF\xFF ok \xC3"[..],
            b"\xE2\x82",
            b"\xF0\x9F\x98\x80 \xF0\x9F\x98 \xED\xA0\x80 \xC0\xAF",
            b"\x80\x80\x80\x80a",
        ] {
            assert_eq!(
                replaced_len(bytes),
                String::from_utf8_lossy(bytes).len() as u64,
                "{bytes:?}"
            );
            let (text, lossy) = text_of(bytes.to_vec()).unwrap();
            assert!(lossy);
            assert_eq!(text, String::from_utf8_lossy(bytes));
        }
    }

    /// Bytes of address space this process may still map: its limit less what it has.
    fn room_left() -> u64 {
        let field = |file: &str, key: &str, at: usize| -> u64 {
            let text = std::fs::read_to_string(file).unwrap();
            let line = text.lines().find(|l| l.starts_with(key)).unwrap();
            line[key.len()..]
                .split_whitespace()
                .nth(at)
                .unwrap()
                .parse()
                .unwrap()
        };
        let limit = field("/proc/self/limits", "Max address space", 0);
        limit - 1024 * field("/proc/self/status", "VmSize:", 0)
    }

    /// Set in the child process of the test below.
    const CHILD: &str = "MANYLIGHT_TEST_TEXT_UNDER_LIMIT";

    /// Under an address-space limit, a file not UTF-8 whose replaced text would not fit is
    /// refused with the size it needs, where a copy made without asking would abort the
    /// process; one whose text fits is made within what it needs; a file of lone CRs as large
    /// takes no copy at all.
    #[test]
    fn a_file_whose_text_would_not_fit_is_refused_not_aborted() {
        const MIB: usize = 1 << 20;
        if std::env::var_os(CHILD).is_some() {
            // 150 MiB read; as text it takes 450 MiB, past the 400 MB the parent allows.
            let needed = text_of(vec![0xFF; 150 * MIB]).map(|_| ()).unwrap_err();
            assert_eq!(needed, 3 * 150 * MIB as u64);
            let (text, lossy) = text_of(vec![b'\r'; 150 * MIB]).unwrap();
            assert!(!lossy && text.len() == 150 * MIB && !text.contains('\r'));
            drop(text);
            // A file whose text fits the room left with 10 % to spare, where text grown by
            // doubling (to four times the file) would not.
            let file = (room_left() as f64 / 4.5) as usize;
            let (text, lossy) = text_of(vec![0xFF; file]).unwrap();
            assert!(lossy && text.len() == 3 * file && text.capacity() == text.len());
            return;
        }
        if !cfg!(target_os = "linux") {
            return;
        }
        let test =
            "scene::obj::text::tests::a_file_whose_text_would_not_fit_is_refused_not_aborted";
        let out = std::process::Command::new("sh")
            .args(["-c", "ulimit -v 400000 && exec \"$0\" \"$@\""])
            .arg(std::env::current_exe().unwrap())
            .args(["--exact", test, "--test-threads=1"])
            .env(CHILD, "1")
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success() && stdout.contains("1 passed"),
            "{:?}: {stdout}{}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        );
    }
}
