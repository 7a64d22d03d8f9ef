//! Text read from a file (a name, a path, a key) as a message shows it: a message never
//! carries a file's bytes as they are, since a terminal acts on control characters (an escape
//! sequence can retitle it, clear it or fake output) and a 10 MB name makes a 10 MB line.

use std::borrow::Cow;

/// Most characters of a name a message quotes; longer ones are cut, with the count left out.
pub const MAX_SHOWN_NAME: usize = 64;

/// Most characters of a message's reason built from a file (a parser's message quoting a key
/// or a URI); longer ones are cut, with the count left out.
pub const MAX_SHOWN_REASON: usize = 1000;

/// Whether `c` is escaped: a control character, a line or paragraph separator (U+2028,
/// U+2029: a new line to many terminals and log viewers, a forged line of output), one that
/// reorders the text around it (bidirectional marks, embeddings, overrides and isolates: a
/// name could make a message read other than it is), or one that shows as nothing or as
/// nothing in particular (zero-width and other invisible format characters, the byte order
/// mark, variation selectors, tags, private use: two names that look alike, or hidden text).
fn escaped(c: char) -> bool {
    c.is_control()
        || matches!(
            c,
            '\u{ad}'
                | '\u{34f}'
                | '\u{61c}'
                | '\u{115f}'..='\u{1160}'
                | '\u{17b4}'..='\u{17b5}'
                | '\u{180b}'..='\u{180f}'
                | '\u{200b}'..='\u{200f}'
                | '\u{2028}'..='\u{202e}'
                | '\u{2060}'..='\u{206f}'
                | '\u{3164}'
                | '\u{e000}'..='\u{f8ff}'
                | '\u{fe00}'..='\u{fe0f}'
                | '\u{feff}'
                | '\u{ffa0}'
                | '\u{fff0}'..='\u{fffb}'
                | '\u{1bca0}'..='\u{1bca3}'
                | '\u{1d173}'..='\u{1d17a}'
                | '\u{e0000}'..='\u{e0fff}'
                | '\u{f0000}'..='\u{10ffff}'
        )
}

/// `text` with every control, reordering and invisible character written `\u{1b}`, but for a
/// joiner or a variation selector between two characters shown as they are; the rest as it is.
pub fn text(text: &str) -> Cow<'_, str> {
    escape(text, |_| false)
}

/// [`text`], keeping line ends and tabs: for messages written over several lines on purpose
/// (a shader's compile log), where the rest must still reach a terminal inert.
pub fn lines(text: &str) -> Cow<'_, str> {
    escape(text, |c| c == '\n' || c == '\t')
}

/// Joiners and variation selectors: part of emoji (`❤️`, `👨‍👩‍👧`), of Persian and Indic
/// spelling (ZWNJ, ZWJ) and of ideographic variants, so kept where they join two characters.
fn joins(c: char) -> bool {
    matches!(
        c,
        '\u{200c}' | '\u{200d}' | '\u{fe0e}' | '\u{fe0f}' | '\u{e0100}'..='\u{e01ef}'
    )
}

fn escape(text: &str, keep: impl Fn(char) -> bool) -> Cow<'_, str> {
    if !text.chars().any(|c| escaped(c) && !keep(c)) {
        return Cow::Borrowed(text);
    }
    let shown = |c: char| (!escaped(c) || joins(c)) && !c.is_whitespace();
    let mut out = String::with_capacity(text.len() + 8);
    let mut chars = text.chars().peekable();
    let mut after_shown = false;
    while let Some(c) = chars.next() {
        let joining = joins(c) && after_shown && chars.peek().is_some_and(|&n| shown(n));
        if escaped(c) && !keep(c) && !joining {
            out.extend(c.escape_unicode());
            after_shown = false;
        } else {
            out.push(c);
            after_shown = !c.is_whitespace();
        }
    }
    Cow::Owned(out)
}

/// A reason built from a file as an error or warning gives it: [`text`], at most
/// [`MAX_SHOWN_REASON`] characters.
pub fn reason(reason: &str) -> String {
    cut(reason, MAX_SHOWN_REASON)
}

/// A path as a message shows it: [`reason`] of its text (a path may hold line ends, escape
/// sequences or be very long).
pub fn path(path: &std::path::Path) -> String {
    reason(&path.to_string_lossy())
}

/// A name from a file as a message quotes it: [`text`], at most [`MAX_SHOWN_NAME`] characters.
pub fn name(name: &str) -> String {
    cut(name, MAX_SHOWN_NAME)
}

/// [`text`] of at most `most` characters of `s`, then how many more there were.
fn cut(s: &str, most: usize) -> String {
    let count = s.chars().count();
    if count <= most {
        return text(s).into_owned();
    }
    let kept: String = s.chars().take(most).collect();
    format!("{}… ({} characters more)", text(&kept), count - most)
}

/// A number as an error message writes it: as written for ordinary magnitudes, in exponent form
/// for tiny and huge ones (`{}` writes 1e-300 in 300 digits, and `f32::MAX` in 39).
pub(crate) struct Short<T>(pub T);

impl<T> std::fmt::Display for Short<T>
where
    T: Copy + Into<f64> + std::fmt::Display + std::fmt::LowerExp,
{
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = self.0.into().abs();
        if v != 0.0 && !(1e-4..1e16).contains(&v) {
            write!(f, "{:e}", self.0)
        } else {
            write!(f, "{}", self.0)
        }
    }
}

/// A vector (`Vec3`, `DVec3`) as a message writes it: `[x, y, z]`, each component [`Short`].
pub(crate) fn short3<T>(v: impl Into<[T; 3]>) -> String
where
    T: Copy + Into<f64> + std::fmt::Display + std::fmt::LowerExp,
{
    let [x, y, z] = v.into();
    format!("[{}, {}, {}]", Short(x), Short(y), Short(z))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_in_messages_are_written_short_in_f32_and_f64() {
        let shown = |s: &dyn std::fmt::Display| s.to_string();
        assert_eq!(shown(&Short(16.0f32)), "16");
        assert_eq!(shown(&Short(0.1f32)), "0.1");
        assert_eq!(shown(&Short(f32::MAX)), "3.4028235e38");
        assert_eq!(shown(&Short(-1e300f64)), "-1e300");
        assert_eq!(shown(&Short(1e-300f64)), "1e-300");
        assert_eq!(shown(&Short(0.0f64)), "0");
        assert_eq!(shown(&Short(f64::NAN)), "NaN");
        assert_eq!(shown(&Short(f32::NEG_INFINITY)), "-inf");
    }

    #[test]
    fn control_characters_are_escaped_and_long_names_cut() {
        assert_eq!(text("plain name ü"), "plain name ü");
        assert_eq!(text("\u{1b}]0;PWN\u{7}x\0"), "\\u{1b}]0;PWN\\u{7}x\\u{0}");
        assert_eq!(text("a\nb\u{9b}c"), "a\\u{a}b\\u{9b}c");
        assert_eq!(text("a\u{2028}b\u{2029}"), "a\\u{2028}b\\u{2029}");
        assert_eq!(name("short"), "short");
        let long = "n".repeat(10_000_000);
        let shown = name(&long);
        assert!(shown.len() < 100, "{}", shown.len());
        assert!(shown.ends_with("… (9999936 characters more)"), "{shown}");
        assert!(!name(&format!("{long}\u{1b}")).contains('\u{1b}'));
        assert_eq!(text("a\u{202e}b\u{2066}"), "a\\u{202e}b\\u{2066}");
        // Invisible: a zero-width space, a byte order mark, a soft hyphen, a tag, private use.
        assert_eq!(
            text("a\u{200b}\u{feff}\u{ad}\u{e0041}\u{e000}b"),
            "a\\u{200b}\\u{feff}\\u{ad}\\u{e0041}\\u{e000}b"
        );
        assert_eq!(text("Ünïcödé 名前 ✓"), "Ünïcödé 名前 ✓");
        // Joiners and variation selectors between two characters are text; alone, leading,
        // trailing or beside a space they hide nothing else and are escaped.
        for kept in [
            "❤\u{fe0f}.png",
            "👨\u{200d}👩\u{200d}👧",
            "می\u{200c}خواهم",
            "葛\u{e0100}城",
        ] {
            assert_eq!(text(kept), kept);
        }
        assert_eq!(text("\u{200d}a"), "\\u{200d}a");
        assert_eq!(text("a\u{200d}"), "a\\u{200d}");
        assert_eq!(text("a \u{200c}b"), "a \\u{200c}b");
        assert_eq!(text("a\u{1b}\u{200d}b"), "a\\u{1b}\\u{200d}b");
        assert_eq!(lines("log:\n\tline\u{1b}"), "log:\n\tline\\u{1b}");
        assert_eq!(
            reason(&long).chars().count(),
            1000 + "… (9999000 characters more)".chars().count()
        );
    }
}
