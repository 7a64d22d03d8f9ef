//! The memory an OBJ's load takes after its text is read — the rewrites before tobj, tobj's
//! parse and the meshes made of it — bounded from the text's counts, and asked of the
//! allocator before any of it is taken. A failed allocation inside tobj aborts the process
//! (Rust's default, which no `catch_unwind` catches); a failed request here is an error.

use super::lines::Objects;

/// The statements of an OBJ text that its load's memory grows with.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct ObjCounts {
    /// Bytes of text.
    pub text: u64,
    /// `v` lines, and those of them with a colour (tobj keeps three more numbers).
    pub positions: u64,
    pub coloured: u64,
    /// `vt` and `vn` lines.
    pub texcoords: u64,
    pub normals: u64,
    /// Faces of three corners or more (what reaches tobj), their corners, the corners of those
    /// of more than four (a list of their own in tobj), and the corners once triangulated.
    pub faces: u64,
    pub corners: u64,
    pub polygon_corners: u64,
    pub triangle_corners: u64,
    /// Meshes tobj makes (an `o`, `g` or change of `usemtl` followed by faces).
    pub objects: u64,
    /// Distinct corners written in each object, summed, where counted ([`Self::count_distinct`]).
    pub distinct: Option<u64>,
}

/// Bytes of a tobj number (its `use_f64` build).
const FLOAT: u64 = 8;
/// A growing `Vec` holds up to twice its length.
const GROWTH: u64 = 2;
/// A face in tobj's list: room for a quad's four index triples (`usize` each) and its tag.
const FACE: u64 = 4 * 3 * 8 + 8;
/// A corner in a polygon's own list: one index triple.
const POLYGON_CORNER: u64 = 3 * 8;
/// A distinct corner in tobj's per-object map (an index triple and a `u32`: 32 bytes and a
/// control byte), the map up to 16/7 of its entries, and half that again while it grows.
const MAP_ENTRY: u64 = 120;
/// A corner word in [`ObjCounts::count_distinct`]'s set, counted as [`MAP_ENTRY`] is.
const SET_ENTRY: u64 = 64;
/// A mesh's fixed cost: tobj's model, its name (at most 256 bytes) and the mesh made of it.
const OBJECT: u64 = 1024;
/// A distinct vertex once converted: `f64` position while centred, then `f32` position,
/// normal and texture coordinate.
const CONVERTED_VERTEX: u64 = 24 + 12 + 12 + 8;
/// A triangle corner once converted: its `u32` index, and the duplicate check's scratch (16
/// bytes a triangle).
const CONVERTED_CORNER: u64 = 4 + 6;

impl ObjCounts {
    /// Counts `text`, which the line checks have accepted.
    pub fn of(text: &str) -> Self {
        let mut counts = Self {
            text: text.len() as u64,
            ..Self::default()
        };
        let mut objects = Objects::default();
        for line in text.lines() {
            let mut words = line.split_whitespace();
            let key = words.next();
            // Checked already: at most `MAX_SCENE_MESHES` objects.
            let _ = objects.read(key, line);
            match key {
                Some("v") => {
                    counts.positions += 1;
                    counts.coloured += u64::from(words.count() >= 6);
                }
                Some("vt") => counts.texcoords += 1,
                Some("vn") => counts.normals += 1,
                Some("f") => {
                    let n = words.count() as u64;
                    if n >= 3 {
                        counts.faces += 1;
                        counts.corners += n;
                        counts.triangle_corners += 3 * (n - 2);
                        if n > 4 {
                            counts.polygon_corners += n;
                        }
                    }
                }
                _ => {}
            }
        }
        counts.objects = objects.with_faces as u64;
        counts
    }

    /// Counts the distinct corners each object's faces write (`1/2/3` and `1/2/3` once, a
    /// corner with a negative index every time) into [`Self::distinct`]: tobj makes a vertex
    /// of each distinct index triple of an object, and two equal words of positive indices
    /// name one. Takes a set as large as the largest object's distinct corners, asked of the
    /// allocator first (where refused, [`Self::distinct`] stays unknown).
    pub fn count_distinct(&mut self, text: &str) {
        if !can_allocate(self.corners * SET_ENTRY) {
            return;
        }
        let mut seen = std::collections::HashSet::new();
        let (mut objects, mut sum) = (Objects::default(), 0);
        for line in text.lines() {
            let mut words = line.split_whitespace();
            let key = words.next();
            let before = objects.with_faces;
            let _ = objects.read(key, line);
            if objects.with_faces != before {
                sum += seen.len() as u64;
                seen.clear();
            }
            if key == Some("f") && words.clone().count() >= 3 {
                // A negative index counts back from its line: the same word names another
                // triple on another line, so each counts.
                for word in words {
                    if word.contains('-') {
                        sum += 1;
                    } else {
                        seen.insert(word);
                    }
                }
            }
        }
        self.distinct = Some(sum + seen.len() as u64);
    }

    /// At most how many bytes a rewrite of the text takes (either of them, whose copy then
    /// replaces it): a one-number `vt` line grows by two bytes, a corner given a texture
    /// coordinate and a normal by up to six.
    pub fn rewrite_bytes(&self) -> u64 {
        GROWTH * (self.text + self.text / 2 + 6 * self.corners)
    }

    /// At most how many bytes tobj's parse and the meshes converted from it take besides the
    /// text. Distinct corners (each a vertex of tobj's meshes) are bounded by those counted,
    /// or else by the corners written, and by every index triple the file could name in each
    /// object.
    pub fn parse_bytes(&self) -> u64 {
        let (t, n) = (self.texcoords + 1, self.normals + 1);
        let triples = u128::from(self.objects) * u128::from(self.positions) * u128::from(t);
        let written = self.distinct.unwrap_or(self.corners);
        let distinct = (triples * u128::from(n)).min(u128::from(written)) as u64;
        // tobj's lists, growing one at a time: each holds up to twice its length, and the
        // one growing its old block too while it moves.
        let lists = [
            FLOAT * 3 * self.positions,
            FLOAT * 3 * self.coloured,
            FLOAT * 2 * t,
            FLOAT * 3 * n,
            FACE * self.faces,
            POLYGON_CORNER * self.polygon_corners,
            FLOAT * 3 * distinct,
            FLOAT * 2 * distinct,
            FLOAT * 3 * distinct,
            FLOAT * 3 * distinct,
            4 * self.triangle_corners,
        ];
        let held = GROWTH * lists.iter().sum::<u64>() + lists.iter().max().unwrap_or(&0);
        let meshes = distinct * (MAP_ENTRY + CONVERTED_VERTEX)
            + self.triangle_corners * CONVERTED_CORNER
            + self.objects * OBJECT;
        held + meshes
    }
}

use crate::scene::alloc_probe::can_allocate;

#[cfg(test)]
mod tests {
    use super::{ObjCounts, CONVERTED_CORNER, FACE};

    #[test]
    fn counts_follow_what_tobj_reads() {
        let text = "v 0 0 0\nv 1 0 0 1 1 1\nvt 0 0\nvn 0 0 1\n\
                    o a\nf 1 2 1\nf 1 2 1 2 1\nl 1 2\nf 1 2\nusemtl m\nf 1 2 1 2\n";
        let counts = ObjCounts::of(text);
        let want = ObjCounts {
            text: text.len() as u64,
            positions: 2,
            coloured: 1,
            texcoords: 1,
            normals: 1,
            faces: 3,
            corners: 3 + 5 + 4,
            polygon_corners: 5,
            triangle_corners: 3 + 9 + 6,
            objects: 2,
            distinct: None,
        };
        assert_eq!(counts, want);
        // `1 2 1` and `1 2 1 2 1` are two distinct corners in object `a`; `1 2 1 2` in the
        // object `usemtl` starts, two more.
        let mut counted = counts;
        counted.count_distinct(text);
        assert_eq!(counted.distinct, Some(4));
        assert!(counted.parse_bytes() < counts.parse_bytes());
    }

    #[test]
    fn distinct_corners_are_bounded_by_what_the_file_can_name() {
        // A million faces naming the same three vertices make three distinct corners, so their
        // bound is tobj's face list and indices, not a vertex per corner.
        let repeated = ObjCounts {
            positions: 3,
            faces: 1_000_000,
            corners: 3_000_000,
            triangle_corners: 3_000_000,
            objects: 1,
            ..ObjCounts::default()
        };
        let distinct = ObjCounts {
            positions: 3_000_000,
            ..repeated
        };
        let (few, many) = (repeated.parse_bytes(), distinct.parse_bytes());
        // Twice the face list and the indices, the face list once more while it grows, and
        // the converted indices; the three vertices and the one object take a few kilobytes.
        let lists = 3 * FACE * 1_000_000 + (2 * 4 + CONVERTED_CORNER) * 3_000_000;
        assert!(few <= lists + 4_096, "{few} against {lists}");
        assert!(many > few + 3_000_000 * 100, "{many} against {few}");
    }
}
