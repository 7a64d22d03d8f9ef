//! The OBJ and MTL lines tobj would misread, panic on or reject without saying where, checked
//! before it parses: each error names the line and the statement, never the file's text.

use std::collections::HashSet;
use std::path::Path;

use crate::scene::mesh::{MAX_SCENE_MESHES, MAX_TEXCOORD};

/// The file's vertex data and faces as tobj reads them:
/// - `v`, `vt` and `vn` start with 3, 2 and 3 numbers within f32's range (tobj reads each
///   into an `f32`, where `1e39` becomes infinite);
/// - a `v` may then have a `w` (a number the position is divided by: not zero, and the
///   quotient within range) or three colour values, nothing else (tobj rejects anything else
///   as an unplaced "position parse error");
/// - a face or line names at least one vertex (tobj fails an empty one as an unplaced
///   "invalid polygon");
/// - every index of every face and line refers to a vertex, texture coordinate or normal the
///   file defines (negative indices count back from the last one defined before the line):
///   an index beyond them overflowed tobj's arithmetic (a panic in debug builds, a read of the
///   wrong element in release ones);
/// - at most [`MAX_SCENE_MESHES`] objects have faces (tobj makes one at each `o`, `g` or change
///   of `usemtl` after faces): each is a mesh of its own, whose fixed cost (buffers, GL
///   objects, the ray caster's hierarchy) would otherwise grow past memory before a frame;
/// - the faces, triangulated, hold at most [`MAX_OBJ_CORNERS`] corners.
///
/// Lines (`l`) and faces of fewer than three corners are taken out before tobj reads the file
/// ([`Rewrites::not_faces`]): tobj drew an `l` of three or more points as a filled polygon,
/// and kept the others (some 100 bytes each) until their object ended, making an empty model
/// of them.
///
/// Returns what [`rewrite`] must change for tobj to read the file.
pub(super) fn check_obj(text: &str) -> Result<Rewrites, String> {
    check_obj_within(text, MAX_OBJ_CORNERS, false)
}

/// tobj's error `e` on `text`, with the line and corner where it is a face index past what is
/// defined when tobj reads it. tobj also ends an object at a change of material, which
/// [`check_obj`] does not check (a `usemtl` naming no library's material may not end one, and
/// the check must not refuse what tobj reads), so such a failure is located only once tobj
/// has refused the file.
pub(super) fn located(text: &str, e: &tobj::LoadError) -> String {
    use tobj::LoadError::{FaceNormalOutOfBounds, FaceTexCoordOutOfBounds, FaceVertexOutOfBounds};
    let past = matches!(
        e,
        FaceVertexOutOfBounds | FaceTexCoordOutOfBounds | FaceNormalOutOfBounds
    );
    match check_obj_within(text, MAX_OBJ_CORNERS, true) {
        Err(reason) if past => reason,
        _ => e.to_string(),
    }
}

/// What a valid OBJ needs rewritten before tobj reads it.
#[derive(Debug, Default, PartialEq)]
pub(super) struct Rewrites {
    /// Where some `v` lines have a colour and others none (tobj then fails a face that uses
    /// one without: "face vertex color index out of bounds", no line named), the first line
    /// with a colour and the first without: the colours are taken off (manylight does not use
    /// OBJ vertex colours).
    pub mixed_colours: Option<(usize, usize)>,
    /// Some `vt` line gives one number (its `v` is then 0, as OBJ has it; tobj needs two).
    pub one_number_texcoords: bool,
    /// The first `o` or `g` line whose name passes [`MAX_OBJ_NAME_BYTES`]: such names are cut
    /// to it (tobj copies an object's name into every mesh it splits the object into).
    pub long_name: Option<usize>,
    /// How many `l` lines and `f` lines of fewer than three corners there are, and the first's
    /// line: taken out (manylight draws triangles; points and lines are not drawn).
    pub not_faces: Option<(usize, usize)>,
}

impl Rewrites {
    /// What the rewrites change of the file at `path`, one warning each.
    pub fn warnings(&self, path: &Path) -> Vec<String> {
        let mut warnings = Vec::new();
        if let Some((count, line)) = self.not_faces {
            let what = if count == 1 {
                format!("a line (`l`) or face of fewer than three corners (at line {line}) is")
            } else {
                format!(
                    "{count} lines (`l`) and faces of fewer than three corners (the first at \
                     line {line}) are"
                )
            };
            warnings.push(format!(
                "{}: {what} not drawn; manylight draws triangles",
                path.display()
            ));
        }
        if let Some(line) = self.long_name {
            warnings.push(format!(
                "{}: object or group names longer than {MAX_OBJ_NAME_BYTES} bytes (the first at \
                 line {line}) are cut to that length",
                path.display()
            ));
        }
        if let Some((with, without)) = self.mixed_colours {
            warnings.push(format!(
                "{}: vertex colours on some `v` lines only (line {with} has one, line {without} \
                 none); ignored, as manylight does not use OBJ vertex colours",
                path.display()
            ));
        }
        warnings
    }

    /// Whether anything needs rewriting.
    pub fn needed(&self) -> bool {
        self.mixed_colours.is_some()
            || self.one_number_texcoords
            || self.long_name.is_some()
            || self.not_faces.is_some()
    }
}

/// `text` with what `rewrites` names changed: every `v` line's colour taken off, every `vt`
/// line of one number given its `v` of 0, every object or group name cut to
/// [`MAX_OBJ_NAME_BYTES`], every line and face of fewer than three corners left empty.
pub(super) fn rewrite(text: &str, rewrites: &Rewrites) -> String {
    let mut out = String::with_capacity(text.len() + text.len() / 8);
    for line in text.lines() {
        let mut words = line.split_whitespace();
        let key = words.next();
        let count = words.clone().count();
        if rewrites.not_faces.is_some() && is_not_a_face(key, count) {
            // Left empty: nothing of it reaches tobj.
        } else if rewrites.mixed_colours.is_some() && key == Some("v") && count == 6 {
            out.push('v');
            for word in words.take(3) {
                out.push(' ');
                out.push_str(word);
            }
        } else if rewrites.one_number_texcoords && key == Some("vt") && count == 1 {
            out.push_str(line.trim_end());
            out.push_str(" 0");
        } else if let (Some(_), Some(name)) = (rewrites.long_name, long_object_name(key, line)) {
            out.push_str(key.unwrap_or_default());
            out.push(' ');
            let end = (0..=MAX_OBJ_NAME_BYTES)
                .rev()
                .find(|&i| name.is_char_boundary(i))
                .unwrap_or(0);
            out.push_str(&name[..end]);
        } else {
            out.push_str(line);
        }
        out.push('\n');
    }
    out
}

/// True for a line statement (`l`) or a face of fewer than three corners (`count` words after
/// the key).
fn is_not_a_face(key: Option<&str>, count: usize) -> bool {
    key == Some("l") || (key == Some("f") && count < 3)
}

/// Longest object or group name kept, in bytes: longer ones are cut (a name is copied into
/// each of up to [`MAX_SCENE_MESHES`] meshes).
pub const MAX_OBJ_NAME_BYTES: usize = 256;

/// The name of an `o` or `g` line (`key` its first word), as tobj reads it (all after the
/// key, trimmed), when it is longer than [`MAX_OBJ_NAME_BYTES`].
fn long_object_name<'a>(key: Option<&str>, line: &'a str) -> Option<&'a str> {
    let key = key.filter(|k| matches!(*k, "o" | "g"))?;
    let name = line.trim_start()[key.len()..].trim();
    (name.len() > MAX_OBJ_NAME_BYTES).then_some(name)
}

/// Most triangle corners the faces of one OBJ may hold once triangulated (as many indices as
/// a glTF file may decode): parsed, each takes some 40 to 70 bytes, so a file's parse takes
/// 16 to 35 times its size (a 67 MB face of 2²⁵ corners took 2.2 GB), and this bounds it.
pub const MAX_OBJ_CORNERS: usize = 3 << 25;

/// [`check_obj`] with at most `max_corners` triangle corners; where `materials_end_objects`, a
/// `usemtl` naming another material ends an object too ([`located`]).
fn check_obj_within(
    text: &str,
    max_corners: usize,
    materials_end_objects: bool,
) -> Result<Rewrites, String> {
    let kind_of = |key: Option<&str>| match key {
        Some("v") => Some(0),
        Some("vt") => Some(1),
        Some("vn") => Some(2),
        _ => None,
    };
    // tobj resolves positive indices once the whole object is read (a face may come before
    // its vertices) and negative ones against what is defined so far; it ignores texture and
    // normal indices when the file has none of them, and `p` lines altogether.
    let mut totals = [0i64; 3];
    for line in text.lines() {
        if let Some(kind) = kind_of(line.split_whitespace().next()) {
            totals[kind] += 1;
        }
    }
    let mut defined = [0i64; 3];
    let mut objects = Objects::default();
    let mut corners = 0usize;
    // The first `v` line without a colour and the first with one.
    let mut coloured: [Option<usize>; 2] = [None, None];
    let mut one_number_texcoords = false;
    let mut long_name = None;
    let mut not_faces: Option<(usize, usize)> = None;
    // Per kind, the largest positive index the current object's faces use, and where.
    let mut pending: [Option<PendingIndex>; 3] = [None; 3];
    for (number, line) in text.lines().enumerate() {
        let at_line = |what: String| format!("line {}: {what}", number + 1);
        let mut words = line.split_whitespace();
        let key = words.next();
        // tobj resolves an object's positive indices when it ends, at the next `o` or `g`
        // (or a change of material, checked only in `located`: a later check is never
        // stricter).
        let material_change =
            || key == Some("usemtl") && objects.material != Some(usemtl_name(line));
        if matches!(key, Some("o" | "g")) || (materials_end_objects && material_change()) {
            check_pending(&mut pending, &defined, number + 1)?;
        }
        objects.read(key, line).map_err(at_line)?;
        if long_name.is_none() && long_object_name(key, line).is_some() {
            long_name = Some(number + 1);
        }
        if let Some(kind) = kind_of(key) {
            let read = check_vertex_data(key.unwrap_or_default(), words).map_err(at_line)?;
            defined[kind] += 1;
            if kind == 0 {
                let colour = read == VertexLine::Coloured;
                coloured[usize::from(colour)].get_or_insert(number + 1);
            }
            one_number_texcoords |= read == VertexLine::OneTexcoord;
            continue;
        }
        // tobj's "material parse error", without a line (and not about an MTL file).
        if key == Some("usemtl") && usemtl_name(line).is_empty() {
            return Err(at_line("`usemtl` names no material".to_string()));
        }
        let Some(key @ ("f" | "l")) = key else {
            continue;
        };
        // tobj's "invalid polygon", without a line.
        if words.clone().next().is_none() {
            return Err(at_line(format!("`{key}` names no vertices")));
        }
        let count = words.clone().count();
        let reaches_tobj = !is_not_a_face(Some(key), count);
        if !reaches_tobj {
            let (n, _) = not_faces.get_or_insert((0, number + 1));
            *n += 1;
        } else {
            // Triangulated as a fan: three corners for each corner past the second.
            corners += 3 * (count - 2);
            if corners > max_corners {
                return Err(at_line(format!(
                    "the faces so far hold more than the {max_corners} triangle corners one \
                     OBJ may (each takes some 40 bytes or more parsed)"
                )));
            }
        }
        for (at, word) in words.enumerate() {
            // tobj's "face parse error", without a line (it reads `1/2/3/` as `1/2/3`).
            // Up to the last one written: `1/1/1/1/` has four.
            let parts = word.trim_end_matches('/').split('/').count();
            if parts > 3 {
                return Err(at_line(format!(
                    "`{key}` corner {} has {parts} indices; a corner is v, v/vt, v//vn or \
                     v/vt/vn",
                    at + 1
                )));
            }
            for (kind, part) in word.split('/').enumerate() {
                if kind > 0 && part.is_empty() {
                    continue;
                }
                let index = part.parse::<i64>().ok();
                // tobj ignores them where the file has none, but parses them all the same.
                if kind > 0 && totals[kind] == 0 && index.is_some() {
                    continue;
                }
                let resolves = index.is_some_and(|i| match i {
                    0 => false,
                    i if i > 0 => i <= totals[kind],
                    i => i.unsigned_abs() <= defined[kind].unsigned_abs(),
                });
                if let (true, Some(index @ 1..)) = (reaches_tobj, index) {
                    if pending[kind].is_none_or(|p| index > p.index) {
                        pending[kind] = Some(PendingIndex {
                            index,
                            line: number + 1,
                            corner: at + 1,
                        });
                    }
                }
                // Digits past i64's range are an index out of range (below), not a word.
                let digits = part.strip_prefix('-').unwrap_or(part);
                let word = digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit());
                if index.is_none() && word {
                    let what = INDEX_KINDS[kind];
                    return Err(at_line(format!(
                        "`{key}` corner {}: its {what} index is not a whole number",
                        at + 1
                    )));
                }
                if !resolves {
                    let what = INDEX_KINDS[kind];
                    return Err(at_line(format!(
                        "`{key}` corner {}: its {what} index is not one of the {} the file \
                         defines ({} before this line)",
                        at + 1,
                        totals[kind],
                        defined[kind]
                    )));
                }
            }
        }
    }
    Ok(Rewrites {
        mixed_colours: match coloured {
            [Some(without), Some(with)] => Some((with, without)),
            _ => None,
        },
        one_number_texcoords,
        long_name,
        not_faces,
    })
}

/// What a face corner's indices refer to, in their order.
const INDEX_KINDS: [&str; 3] = ["vertex", "texture coordinate", "normal"];

/// A positive index of a face, kept until its object ends.
#[derive(Clone, Copy)]
struct PendingIndex {
    index: i64,
    line: usize,
    corner: usize,
}

/// At the end of an object (line `end`), every positive index its faces used must be defined
/// by then (tobj's "face vertex index out of bounds", without a line, otherwise); clears them.
fn check_pending(
    pending: &mut [Option<PendingIndex>; 3],
    defined: &[i64; 3],
    end: usize,
) -> Result<(), String> {
    for (kind, p) in pending.iter_mut().enumerate() {
        if let Some(p) = p.take().filter(|p| p.index > defined[kind]) {
            return Err(format!(
                "line {}: `f` corner {}: its {} index is past the {} defined before its object \
                 ends (line {end}), where its indices are read",
                p.line, p.corner, INDEX_KINDS[kind], defined[kind]
            ));
        }
    }
    Ok(())
}

/// What [`check_vertex_data`] found a line to be, besides valid.
#[derive(Clone, Copy, Debug, PartialEq)]
enum VertexLine {
    Plain,
    /// A `v` with a colour.
    Coloured,
    /// A `vt` of one number.
    OneTexcoord,
}

/// The objects tobj makes of a file, counted as [`check_obj`] reads it: one where faces
/// follow an `o`, a `g` or a `usemtl` naming another material.
#[derive(Default)]
pub(super) struct Objects<'a> {
    pub with_faces: usize,
    current_has_faces: bool,
    material: Option<&'a str>,
}

impl<'a> Objects<'a> {
    pub fn read(&mut self, key: Option<&str>, line: &'a str) -> Result<(), String> {
        match key {
            Some("o" | "g") => self.current_has_faces = false,
            Some("usemtl") => {
                // Two names no library defines are one object to tobj (both no material) and
                // two here: a count a little high, never too low.
                let name = Some(usemtl_name(line));
                if name != self.material {
                    self.current_has_faces = false;
                    self.material = name;
                }
            }
            // A face of three corners or more (the others do not reach tobj).
            Some("f")
                if !self.current_has_faces
                    && !is_not_a_face(key, line.split_whitespace().count() - 1) =>
            {
                self.current_has_faces = true;
                self.with_faces += 1;
                if self.with_faces > MAX_SCENE_MESHES {
                    return Err(format!(
                        "a face of object {}: more than {MAX_SCENE_MESHES} objects with faces \
                         (`o`, `g` and material changes), the limit per file; merge objects \
                         that share a material in the exporter",
                        self.with_faces
                    ));
                }
            }
            _ => {}
        }
        Ok(())
    }
}

/// A `v`, `vt` or `vn` statement's words after its key, as [`check_obj`] says.
fn check_vertex_data<'a>(
    key: &str,
    mut words: impl Iterator<Item = &'a str>,
) -> Result<VertexLine, String> {
    let needs = if key == "vt" { 2 } else { 3 };
    let mut values = [0f32; 3];
    for (i, value) in values.iter_mut().enumerate().take(needs) {
        // The numbers first, so a bad one is named rather than the face that uses it.
        match words.next().map(str::parse::<f32>) {
            Some(Ok(v)) if key == "vt" && v.is_finite() && v.abs() > MAX_TEXCOORD => {
                return Err(format!(
                    "`vt` number {}: a texture coordinate must be within ±{MAX_TEXCOORD:e}",
                    i + 1
                ))
            }
            Some(Ok(v)) if v.is_finite() => *value = v,
            Some(Ok(_)) => {
                return Err(format!(
                    "`{key}` number {}: not a finite number within f32's range (±{:.1e})",
                    i + 1,
                    f32::MAX
                ))
            }
            // OBJ's `vt u`: its `v` is 0.
            None if key == "vt" && i == 1 => return Ok(VertexLine::OneTexcoord),
            _ => return Err(format!("`{key}` needs {needs} numbers, found {i}")),
        }
    }
    if key != "v" {
        return Ok(VertexLine::Plain); // tobj ignores what follows a texture coordinate or a normal
    }
    let rest: Vec<&str> = words.take(4).collect();
    match rest[..] {
        [] => Ok(VertexLine::Plain),
        [w] => match w.parse::<f32>() {
            Ok(w) if w != 0.0 && values.iter().all(|x| (x / w).is_finite()) => {
                Ok(VertexLine::Plain)
            }
            Ok(_) => Err(format!(
                "`v` w: the position divided by it must be finite (w not zero, within \
                 f32's range ±{:.1e})",
                f32::MAX
            )),
            Err(_) => Err("`v` w (the 4th value) is not a number".into()),
        },
        // A colour, which tobj reads (and manylight does not use) value by value until one is
        // not a number: none read (`v 1 2 3 # id 5`) is no colour; one or two leave the
        // colours out of step with the positions.
        [first, _, _] if first.parse::<f32>().is_err() => Ok(VertexLine::Plain),
        [_, _, _] if rest.iter().all(|c| c.parse::<f32>().is_ok()) => Ok(VertexLine::Coloured),
        [_, _, _] => Err("`v` colour: its 4th value is a number, a later one is not".into()),
        _ => Err(format!(
            "`v` takes 3 numbers, then a w or an RGB colour (1 or 3 values); found {} more",
            if rest.len() > 3 { "4 or" } else { "2" }
        )),
    }
}

/// The material name of a `usemtl` line as tobj reads it: everything after the line's first
/// space, trimmed (so a tab after the key, or spaces before it, change what it names).
fn usemtl_name(line: &str) -> &str {
    line.split_once(' ').map_or("", |(_, name)| name.trim())
}

/// What `usemtl` lines name that no material library defined (tobj gives those faces no
/// material, and they are drawn in the default grey), said without the names (the file's
/// text): how many, and the line of the first.
pub(super) fn undefined_materials(text: &str, defined: &HashSet<&str>) -> Option<String> {
    let mut missing = HashSet::new();
    let mut first = None;
    for (number, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() != Some("usemtl") {
            continue;
        }
        let name = usemtl_name(line);
        if defined.contains(name) {
            continue;
        }
        if missing.insert(name) && first.is_none() {
            first = Some(number + 1);
        }
    }
    first.map(|line| {
        format!(
            "{} material names given to `usemtl` are defined by no material library (the \
             first at line {line}); their faces are drawn in the default grey",
            missing.len()
        )
    })
}

/// Most materials the material libraries of one OBJ may define together: tobj keeps about a
/// kilobyte for each, so 1.1 million `newmtl` lines (16 MB) took 1.1 GB, and every material
/// kept costs each frame. Far more than a model uses.
pub const MAX_OBJ_MATERIALS: usize = 65_536;

/// The first MTL line tobj would panic on, misread or reject without saying where (a colour
/// with fewer than three numbers, as a truncated file has; `d`, `Ns`, `Ni` or `illum` without
/// its number; a texture statement or `newmtl` naming nothing), or whose `newmtl` takes the
/// materials past [`MAX_OBJ_MATERIALS`] with the `defined` before it, as a message naming the
/// line (not showing it). Returns how many materials the library defines, and the lines to give
/// tobj: those it reads into a material's fields and those `also` names (statements the loader
/// looks up in tobj's map). tobj keeps any other statement as a string in a map per material
/// (some 100 bytes a line, `#comment` included) with no bound, so they are left out.
pub(super) fn check_mtl(
    text: &str,
    defined: usize,
    also: &[&str],
) -> Result<(usize, String), String> {
    let mut materials = 0;
    let mut kept = String::with_capacity(text.len());
    for (number, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let Some(key) = words.next() else {
            continue;
        };
        // `None` for a statement tobj does not read into a field.
        let checked = match key {
            "Ka" | "Kd" | "Ks" | "Ke" => {
                let numbers = words.take(3).filter(|w| w.parse::<f32>().is_ok()).count();
                Some((numbers < 3).then(|| format!("`{key}` needs three numbers, found {numbers}")))
            }
            "Ns" | "Ni" | "d" => Some(
                words
                    .next()
                    .is_none_or(|w| w.parse::<f32>().is_err())
                    .then(|| format!("`{key}` needs a number")),
            ),
            "illum" => Some(
                words
                    .next()
                    .is_none_or(|w| w.parse::<u8>().is_err())
                    .then(|| "`illum` needs an illumination model number (0 to 255)".to_string()),
            ),
            "newmtl" | "map_Ka" | "map_Kd" | "map_Ks" | "map_Bump" | "map_bump" | "map_Ns"
            | "map_ns" | "map_NS" | "bump" | "map_d" => Some(
                words
                    .next()
                    .is_none()
                    .then(|| format!("`{key}` names nothing")),
            ),
            _ => None,
        };
        if checked.is_none() && !also.contains(&key) {
            continue;
        }
        let fault = checked.flatten().or_else(|| {
            materials += usize::from(key == "newmtl");
            (defined + materials > MAX_OBJ_MATERIALS).then(|| {
                format!(
                    "`newmtl` defines more than the {MAX_OBJ_MATERIALS} materials an OBJ's \
                     libraries may hold together"
                )
            })
        });
        if let Some(fault) = fault {
            return Err(format!("line {}: {fault}", number + 1));
        }
        kept.push_str(line);
        kept.push('\n');
    }
    Ok((materials, kept))
}

#[cfg(test)]
mod tests {
    use super::{
        check_mtl, check_obj, check_obj_within, rewrite, undefined_materials, HashSet, Objects,
        MAX_OBJ_NAME_BYTES,
    };

    #[test]
    fn only_statements_tobj_reads_or_the_loader_looks_up_reach_tobj() {
        let text = "# comment\n#note\nnewmtl m\nKd 1 0 0\nPr 0.5\nzz unknown\n  map_Kd a b.png\n\
                    Tf 1 1 1\nillum 2\n";
        assert_eq!(
            check_mtl(text, 0, &["Pr"]),
            Ok((
                1,
                "newmtl m\nKd 1 0 0\nPr 0.5\n  map_Kd a b.png\nillum 2\n".to_string()
            ))
        );
    }

    /// Colours on some `v` lines and not others are found (the first line with, the first
    /// without) and taken off every line that has one; `w` stays.
    #[test]
    fn vertex_colours_on_some_positions_only_are_found_and_stripped() {
        let text = "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0 2\nf 1 2 3\n";
        let found = check_obj(text).unwrap();
        assert_eq!(found.mixed_colours, Some((1, 2)));
        assert_eq!(
            rewrite(text, &found),
            "v 0 0 0\nv 1 0 0\nv 0 1 0 2\nf 1 2 3\n"
        );
        assert!(!check_obj("v 0 0 0 1 0 0\nv 1 0 0 0 1 0\n")
            .unwrap()
            .needed());
        assert!(!check_obj("v 0 0 0\nv 1 0 0\n").unwrap().needed());
    }

    /// OBJ's `vt u` (its `v` 0) is read, where tobj needs two numbers; one that is not a
    /// number is still named.
    #[test]
    fn a_texture_coordinate_of_one_number_gets_v_zero() {
        let text = "v 0 0 0\nvt 0.5\nvt 0.25 1\nf 1/1 1/2 1/1\n";
        let found = check_obj(text).unwrap();
        assert!(found.one_number_texcoords && found.mixed_colours.is_none());
        assert_eq!(
            rewrite(text, &found),
            "v 0 0 0\nvt 0.5 0\nvt 0.25 1\nf 1/1 1/2 1/1\n"
        );
        let err = check_obj("vt 0.5 x\n").unwrap_err();
        assert!(err.contains("`vt` needs 2 numbers"), "{err}");
    }

    /// Corners are counted triangulated, a fan of three for each past the second, and the
    /// face that passes the limit is named.
    #[test]
    fn faces_past_the_corner_limit_are_refused_by_line() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 4\nf 1 2 3\nf 1 2 3\n";
        assert!(check_obj_within(text, 12, false).is_ok());
        let err = check_obj_within(text, 11, false).unwrap_err();
        assert!(
            err.starts_with("line 7:") && err.contains("11 triangle corners"),
            "{err}"
        );
        // Lines (`l`) and faces of one or two corners make no triangles, and are taken out
        // (tobj filled an `l` of four points as a quad), counted with the first's line.
        let text = "v 0 0 0\nl 1 1 1 1\nf 1\nf 1 1 1\nl 1 1\nf 1 1\n";
        let found = check_obj_within(text, 3, false).unwrap();
        assert_eq!(found.not_faces, Some((4, 2)));
        assert_eq!(rewrite(text, &found), "v 0 0 0\n\n\nf 1 1 1\n\n\n");
    }

    /// Object and group names past the limit are cut to it at a character's boundary, the
    /// first such line named.
    #[test]
    fn long_object_names_are_cut() {
        // Byte 256 falls inside a two-byte character.
        let long = format!("a{}", "é".repeat(MAX_OBJ_NAME_BYTES));
        let text = format!("v 0 0 0\no short\n  g {long} \nf 1 1 1\no {long}x\n");
        let found = check_obj(&text).unwrap();
        assert_eq!(found.long_name, Some(3));
        let cut = &long[..MAX_OBJ_NAME_BYTES - 1];
        assert_eq!(
            rewrite(&text, &found),
            format!("v 0 0 0\no short\ng {cut}\nf 1 1 1\no {cut}\n")
        );
        assert_eq!(check_obj("o short\n").unwrap().long_name, None);
    }

    /// Objects are counted as tobj splits them: a `usemtl` naming the whole rest of its line.
    #[test]
    fn objects_split_at_o_g_and_a_change_of_the_whole_material_name() {
        let text = "f 1 1 1\nusemtl red paint\nf 1 1 1\nusemtl red brick\nf 1 1 1\n\
                    usemtl red brick\nf 1 1 1\ng a\ng b\nf 1 1 1\ng c\nl 1 1 1\nf 1 1\n";
        let mut objects = Objects::default();
        for line in text.lines() {
            objects.read(line.split_whitespace().next(), line).unwrap();
        }
        assert_eq!(objects.with_faces, 4);
    }

    #[test]
    fn undefined_material_names_are_counted_as_tobj_reads_them() {
        let text = "usemtl red\nusemtl blue\n  usemtl red\nusemtl blue\n";
        // The indented line names `usemtl red` to tobj, which no library defines either.
        let defined = HashSet::from(["red"]);
        let warning = undefined_materials(text, &defined).unwrap();
        assert!(
            warning.starts_with("2 material names") && warning.contains("line 2"),
            "{warning}"
        );
        assert_eq!(undefined_materials("usemtl red\n", &defined), None);
    }

    #[test]
    fn mtl_statements_without_their_values_are_named_by_line() {
        let cases = [
            (
                "newmtl m\nKd 1 1\n",
                "line 2: `Kd` needs three numbers, found 2",
            ),
            ("newmtl m\nd\n", "line 2: `d` needs a number"),
            ("newmtl m\nNs x\n", "line 2: `Ns` needs a number"),
            ("newmtl m\nillum 300\n", "line 2: `illum` needs"),
            ("newmtl m\nmap_Kd   \n", "line 2: `map_Kd` names nothing"),
            ("newmtl\n", "line 1: `newmtl` names nothing"),
        ];
        for (text, expected) in cases {
            let err = check_mtl(text, 0, &[]).expect_err(text);
            assert!(err.starts_with(expected), "{text:?}: {err}");
        }
        let fine = "newmtl m\nKd 1 1 1\nd 0.5\nNs 10\nillum 2\nmap_Kd a b.png\n";
        assert!(check_mtl(fine, 0, &[]).is_ok());
    }

    #[test]
    fn vertex_lines_tobj_rejects_or_overflows_are_named_by_line() {
        let triangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        assert_eq!(check_obj(triangle), Ok(Default::default()));
        let cases = [
            ("v 0 0 0\nv 1 0 0 \\\n", "line 2: `v` w (the 4th value) is not a number"),
            ("v 0 1e39 0\n", "line 1: `v` number 2: not a finite number"),
            ("v 0 0 0\nvn 0 -1e39 0\n", "line 2: `vn` number 2: not a finite number"),
            ("vt inf 0\n", "line 1: `vt` number 1: not a finite number"),
            ("v 1 2 3 0\n", "line 1: `v` w: the position divided by it must be finite"),
            ("v 1 2 3 1e-39\n", "line 1: `v` w: the position divided by it must be finite"),
            ("v 1 2 3 0.5 0.5\n", "line 1: `v` takes 3 numbers, then a w or an RGB colour (1 or 3 values); found 2 more"),
            ("v 1 2 3 1 1 1 1\n", "found 4 or more"),
            ("v 1 2\n", "line 1: `v` needs 3 numbers, found 2"),
            ("vt\n", "line 1: `vt` needs 2 numbers, found 0"),
            ("v 0 0 0\nf\n", "line 2: `f` names no vertices"),
            ("v 0 0 0\nl \n", "line 2: `l` names no vertices"),
            ("v 0 0 0\nusemtl\nf 1 1 1\n", "line 2: `usemtl` names no material"),
            ("v 0 0 0\nusemtl\tred\nf 1 1 1\n", "line 2: `usemtl` names no material"),
            (
                "v 0 0 0\nvt 0 0\nvn 0 0 1\nf 1/1/1/1 1 1\n",
                "line 4: `f` corner 1 has 4 indices",
            ),
            (
                "v 0 0 0 1 1 1\nv 1 0 0 1 1 1\nv 0 1 0 1 b c\nf 1 2 3\n",
                "line 3: `v` colour: its 4th value is a number, a later one is not",
            ),
            // tobj reads an object's faces when it ends: vertex 3 comes after `o b`.
            (
                "v 0 0 0\nv 1 0 0\nf 1 2 3\no b\nv 0 1 0\n",
                "line 3: `f` corner 3: its vertex index is past the 2 defined before its \
                 object ends (line 4)",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\ng x\nvt 1 1\nf 1/2 2/2 3/2\n",
                "line 5: `f` corner 2: its texture coordinate index is past the 1 defined",
            ),
        ];
        for (text, expected) in cases {
            let err = check_obj(text).expect_err(text);
            assert!(
                err.starts_with(expected) || err.contains(expected),
                "{text:?}: {err}"
            );
        }
        // What tobj accepts stays accepted: a w, a colour, words after a normal.
        for text in [
            "v 2 4 6 2\n",
            "v 0 0 0 1 0.5 0\n",
            "vn 0 0 1 extra\n",
            "vt 0 1 0\n",
            "v 0 0 0\nvt 0 0\nvn 0 0 1\nf 1/1/1/ 1 1\n",
            // Faces before their vertices, within their object.
            "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\no b\n",
        ] {
            assert_eq!(check_obj(text), Ok(Default::default()), "{text:?}");
        }
        // A tail whose first word is not a number is no colour to tobj: alone, nothing to
        // rewrite; beside colours, a mix whose colours are taken off.
        assert_eq!(
            check_obj("v 1 2 3 # id 5\nv 0 0 0\n"),
            Ok(Default::default())
        );
        let mixed = check_obj("v 0 0 0 1 1 1\nv 1 0 0 1 1 1\nv 0 1 0 a b c\nf 1 2 3\n");
        assert_eq!(mixed.unwrap().mixed_colours, Some((1, 3)));
        // A polyline, which never reaches tobj, across an object's end.
        assert!(check_obj("v 0 0 0\nv 1 0 0\nl 1 2 3\no b\nv 0 1 0\n").is_ok());
    }
}
