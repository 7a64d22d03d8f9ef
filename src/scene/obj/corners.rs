//! Faces whose corners name texture coordinates or normals in some places and not in others.
//!
//! OBJ allows it (`f 1/1 2/2 3/3` then `f 2 4 3`), but tobj then pushes a texture coordinate
//! only for the corners that have one, so a mesh's coordinates no longer line up with its
//! vertices. Such a file is
//! rewritten before tobj reads it: one texture coordinate `(0, 0)` and one zero normal are
//! put first, each corner without one names them, and every positive index is moved past
//! them (negative ones count back from the corner and still find the same line). A zero
//! normal is then replaced by the faces' own, as for any unusable normal in a file.

/// The text with every face corner naming a texture coordinate where the file has any, and a
/// normal where it has any (`mixed`, from [`mixed`]); `None` when every corner already does
/// (the common file).
pub(super) fn fill_missing(text: &str, mixed: [bool; 2]) -> Option<String> {
    let [fill_uvs, fill_normals] = mixed;
    if !fill_uvs && !fill_normals {
        return None;
    }
    let mut out = String::with_capacity(text.len() + text.len() / 4);
    if fill_uvs {
        out.push_str("vt 0 0\n");
    }
    if fill_normals {
        out.push_str("vn 0 0 0\n");
    }
    for line in text.lines() {
        let mut words = line.split_whitespace();
        if words.next() != Some("f") {
            out.push_str(line);
            out.push('\n');
            continue;
        }
        out.push('f');
        for corner in words {
            let mut parts = corner.split('/');
            out.push(' ');
            out.push_str(parts.next().unwrap_or_default());
            let (uv, normal) = (parts.next(), parts.next());
            let uv = filled(uv, fill_uvs);
            let normal = filled(normal, fill_normals);
            if uv.is_some() || normal.is_some() {
                out.push('/');
                if let Some(uv) = uv {
                    out.push_str(&uv);
                }
            }
            if let Some(normal) = normal {
                out.push('/');
                out.push_str(&normal);
            }
        }
        out.push('\n');
    }
    Some(out)
}

/// Whether the file has texture coordinates (`[0]`) and normals (`[1]`) and some object's
/// faces name them in some corners and not in others, in one pass. An object runs to the
/// next `o` or `g` line; tobj also starts a new mesh at a `usemtl` that changes the material,
/// so this may see a mix tobj would not (then the rewrite only costs a warning), never the
/// other way round.
pub(super) fn mixed(text: &str) -> [bool; 2] {
    let (mut has, mut mixed) = ([false; 2], [false; 2]);
    let (mut with, mut without) = ([false; 2], [false; 2]);
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("vt") => has[0] = true,
            Some("vn") => has[1] = true,
            Some("o" | "g") => (with, without) = ([false; 2], [false; 2]),
            Some("f") => {
                for corner in words {
                    let mut indices = corner.split('/').skip(1);
                    for k in 0..2 {
                        match indices.next() {
                            Some(index) if !index.is_empty() => with[k] = true,
                            _ => without[k] = true,
                        }
                    }
                }
                for k in 0..2 {
                    mixed[k] |= with[k] && without[k];
                }
            }
            _ => {}
        }
    }
    [has[0] && mixed[0], has[1] && mixed[1]]
}

/// A corner's texture coordinate or normal index once the file is rewritten: as written
/// where nothing was put first (`fill` false), else `1` (what was put first) where it named
/// none, a positive index one more, a negative or unreadable one as written (the checks
/// before refuse an unreadable one).
fn filled(index: Option<&str>, fill: bool) -> Option<String> {
    let index = index.filter(|i| !i.is_empty());
    if !fill {
        return index.map(str::to_string);
    }
    Some(match index {
        None => "1".to_string(),
        Some(i) => match i.parse::<i64>() {
            Ok(n) if n > 0 => (n + 1).to_string(),
            _ => i.to_string(),
        },
    })
}

#[cfg(test)]
mod tests {
    use super::{fill_missing, mixed};

    fn filled(text: &str) -> Option<String> {
        fill_missing(text, mixed(text))
    }

    #[test]
    fn corners_without_a_texture_coordinate_or_normal_name_the_ones_put_first() {
        let uniform = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\nf 1 2 3\n";
        assert_eq!(
            filled(uniform).as_deref(),
            Some("vt 0 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/2 2/2 3/2\nf 1/1 2/1 3/1\n")
        );
        // Normals too, negative indices kept, a corner with only a normal keeps its `//`.
        let mixed = "v 0 0 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 1/-1 1//-1\n";
        assert_eq!(
            filled(mixed).as_deref(),
            Some("vt 0 0\nvn 0 0 0\nv 0 0 0\nvt 0 0\nvn 0 0 1\nf 1/2/2 1/-1/1 1/1/-1\n")
        );
        // Files whose corners all name them, or that have none, or whose objects each do or
        // do not (tobj makes each object its own mesh), are left alone.
        for text in [
            "v 0 0 0\nvt 0 0\no a\nf 1/1 1/1 1/1\no b\nf 1 1 1\n",
            "v 0 0 0\nvt 0 0\nf 1/1 1/1 1/1\n",
            "v 0 0 0\nf 1 1 1\n",
            "v 0 0 0\nvn 0 0 1\nf 1//1 1//1 1//1\n",
        ] {
            assert_eq!(filled(text), None, "{text:?}");
        }
    }
}
