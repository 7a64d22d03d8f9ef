//! Text read from a file (a name, a path, a key) as a message shows it: a message never
//! carries a file's bytes as they are, since a terminal acts on control characters (an escape
//! sequence can retitle it, clear it or fake output) and a 10 MB name makes a 10 MB line.

use std::borrow::Cow;

/// Most characters of a name a message quotes; longer ones are cut, with the count left out.
pub const MAX_SHOWN_NAME: usize = 64;

/// `text` with every control character escaped (`\u{1b}`), the rest as it is.
pub fn text(text: &str) -> Cow<'_, str> {
    if !text.chars().any(char::is_control) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if c.is_control() {
            out.extend(c.escape_unicode());
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

/// A name from a file as a message quotes it: [`text`], at most [`MAX_SHOWN_NAME`] characters.
pub fn name(name: &str) -> String {
    let count = name.chars().count();
    if count <= MAX_SHOWN_NAME {
        return text(name).into_owned();
    }
    let kept: String = name.chars().take(MAX_SHOWN_NAME).collect();
    format!(
        "{}… ({} characters more)",
        text(&kept),
        count - MAX_SHOWN_NAME
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_are_escaped_and_long_names_cut() {
        assert_eq!(text("plain name ü"), "plain name ü");
        assert_eq!(text("\u{1b}]0;PWN\u{7}x\0"), "\\u{1b}]0;PWN\\u{7}x\\u{0}");
        assert_eq!(text("a\nb\u{9b}c"), "a\\u{a}b\\u{9b}c");
        assert_eq!(name("short"), "short");
        let long = "n".repeat(10_000_000);
        let shown = name(&long);
        assert!(shown.len() < 100, "{}", shown.len());
        assert!(shown.ends_with("… (9999936 characters more)"), "{shown}");
        assert!(!name(&format!("{long}\u{1b}")).contains('\u{1b}'));
    }
}
