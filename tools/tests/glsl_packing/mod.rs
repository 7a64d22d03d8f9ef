//! GLSL ES 1.00's counting of uniforms, varyings and attributes (spec Appendix A.7): a
//! shader whose variables pack into the minimum grids by this algorithm must be accepted by
//! every ES 2.0 implementation, whatever it reports. glslangValidator does not enforce it.

use std::cmp::Reverse;

/// A variable's place in the grid: rows a element, columns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shape {
    rows: usize,
    columns: usize,
    /// The packing order of §A.7 (mat4, mat2, vec4, mat3, vec3, vec2, scalars).
    rank: u8,
}

/// One declared variable (an array of `len` elements, 1 for a plain variable).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Variable {
    pub name: String,
    pub shape: Shape,
    pub len: usize,
}

/// What a shader declares at global scope, by storage qualifier.
#[derive(Debug, Default)]
pub struct Declarations {
    pub uniforms: Vec<Variable>,
    pub samplers: usize,
    pub varyings: Vec<Variable>,
    pub attributes: Vec<Variable>,
}

fn shape(ty: &str) -> Option<Shape> {
    let (rows, columns, rank) = match ty {
        "mat4" => (4, 4, 0),
        // A mat2 takes two whole rows (rule 4).
        "mat2" => (2, 4, 1),
        "vec4" | "ivec4" | "bvec4" => (1, 4, 2),
        "mat3" => (3, 3, 3),
        "vec3" | "ivec3" | "bvec3" => (1, 3, 4),
        "vec2" | "ivec2" | "bvec2" => (1, 2, 5),
        "float" | "int" | "bool" => (1, 1, 6),
        _ => return None,
    };
    Some(Shape {
        rows,
        columns,
        rank,
    })
}

/// The global `uniform`, `varying` and `attribute` declarations of preprocessed GLSL ES 1.00
/// source; an error names a type the counting does not know (a struct, say).
pub fn declarations(source: &str) -> Result<Declarations, String> {
    let mut found = Declarations::default();
    for statement in source.split([';', '{', '}']) {
        let mut words = statement.split_whitespace();
        let Some(qualifier @ ("uniform" | "varying" | "attribute")) = words.next() else {
            continue;
        };
        let mut ty = words.next().unwrap_or_default();
        if matches!(ty, "highp" | "mediump" | "lowp") {
            ty = words.next().unwrap_or_default();
        }
        let declarators: String = words.collect();
        if qualifier == "uniform" && ty.starts_with("sampler") {
            found.samplers += declarators.split(',').count();
            continue;
        }
        let shape = shape(ty).ok_or_else(|| format!("unknown type `{ty}` in `{statement}`"))?;
        for declarator in declarators.split(',') {
            let (name, len) = match declarator.split_once('[') {
                Some((name, size)) => {
                    let size = size.trim_end_matches(']');
                    let len = size
                        .parse()
                        .map_err(|_| format!("array size `{size}` in `{statement}`"))?;
                    (name, len)
                }
                None => (declarator, 1),
            };
            let variable = Variable {
                name: name.to_string(),
                shape,
                len,
            };
            match qualifier {
                "uniform" => found.uniforms.push(variable),
                "varying" => found.varyings.push(variable),
                _ => found.attributes.push(variable),
            }
        }
    }
    Ok(found)
}

/// Whether `variables` pack into a grid of `rows` rows of four components by §A.7.
pub fn packs(variables: &[Variable], rows: usize) -> bool {
    let mut used = vec![[false; 4]; rows];
    let mut order: Vec<&Variable> = variables.iter().collect();
    order.sort_by_key(|v| (v.shape.rank, Reverse(v.len)));
    let mut next_row = 0;
    let mut from_the_bottom = false;
    for v in order.iter().filter(|v| v.shape.columns > 1) {
        let height = v.shape.rows * v.len;
        let columns = v.shape.columns;
        // Rule 7: successive rows from the top, aligned to the first column.
        if !from_the_bottom {
            if next_row + height <= rows {
                for row in &mut used[next_row..next_row + height] {
                    row[..columns].fill(true);
                }
                next_row += height;
                continue;
            }
            // Rule 8: only 2-component variables go on, from the bottom.
            from_the_bottom = true;
        }
        if columns != 2 || !place_from_the_bottom(&mut used, height) {
            return false;
        }
    }
    // Rule 9: scalars, largest first, each in the column whose free run it fills best.
    for v in order.iter().filter(|v| v.shape.columns == 1) {
        let mut best: Option<(usize, usize, usize)> = None;
        for column in 0..4 {
            for (start, free) in free_runs(&used, column) {
                if free >= v.len && best.is_none_or(|(f, _, _)| free < f) {
                    best = Some((free, column, start));
                }
            }
        }
        let Some((_, column, start)) = best else {
            return false;
        };
        for row in &mut used[start..start + v.len] {
            row[column] = true;
        }
    }
    true
}

/// Rule 8: the highest row, then the lowest column, where a 2-wide variable of `height` rows
/// fits.
fn place_from_the_bottom(used: &mut [[bool; 4]], height: usize) -> bool {
    let Some(last_top) = used.len().checked_sub(height) else {
        return false;
    };
    for top in (0..=last_top).rev() {
        for column in 0..3 {
            let rows = &mut used[top..top + height];
            if rows.iter().all(|r| !r[column] && !r[column + 1]) {
                for r in rows {
                    r[column] = true;
                    r[column + 1] = true;
                }
                return true;
            }
        }
    }
    false
}

/// A column's free runs of rows: (first row, length).
fn free_runs(used: &[[bool; 4]], column: usize) -> Vec<(usize, usize)> {
    let mut runs = Vec::new();
    let mut start = None;
    for (row, cells) in used.iter().enumerate() {
        match (cells[column], start) {
            (false, None) => start = Some(row),
            (true, Some(s)) => {
                runs.push((s, row - s));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        runs.push((s, used.len() - s));
    }
    runs
}

/// The fewest rows `variables` pack into (for messages).
pub fn rows_needed(variables: &[Variable]) -> usize {
    (0..).find(|&rows| packs(variables, rows)).unwrap()
}

/// Attribute slots: one a column of a matrix, one a vector or scalar (§A.7 counts whole
/// vec4 slots for attributes).
pub fn attribute_slots(attributes: &[Variable]) -> usize {
    attributes.iter().map(|a| a.shape.rows * a.len).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn many(ty: &str, count: usize, len: usize) -> Vec<Variable> {
        (0..count)
            .map(|i| Variable {
                name: format!("{ty}{i}"),
                shape: shape(ty).unwrap(),
                len,
            })
            .collect()
    }

    fn join(parts: &[Vec<Variable>]) -> Vec<Variable> {
        parts.concat()
    }

    /// Each case follows from the rules alone, not from a run of the packer.
    #[test]
    fn the_packing_follows_the_rules_of_a7() {
        // A vec4 a row: 16 fill 16 rows.
        assert!(packs(&many("vec4", 16, 1), 16));
        assert!(!packs(&many("vec4", 17, 1), 16));
        // An array is never split (rule 3): float[16] takes a column, float[17] none.
        assert!(packs(&many("float", 1, 16), 16));
        assert!(!packs(&many("float", 1, 17), 16));
        // vec3s leave the fourth column to scalars (rule 9), not to a vec2 (rules 7 and 8):
        // 16 vec3 take 48 of 64 components, and still no vec2 fits.
        let vec3s = many("vec3", 16, 1);
        assert!(packs(&join(&[vec3s.clone(), many("float", 16, 1)]), 16));
        assert!(!packs(&join(&[vec3s.clone(), many("float", 17, 1)]), 16));
        assert!(!packs(&join(&[vec3s, many("vec2", 1, 1)]), 16));
        // vec2s go down the first two columns, then up the last two (rule 8): 32 fit.
        assert!(packs(&many("vec2", 32, 1), 16));
        assert!(!packs(&many("vec2", 33, 1), 16));
        // A mat2 takes two whole rows (rule 4): eight fill 16 rows.
        assert!(packs(&many("mat2", 8, 1), 16));
        assert!(!packs(
            &join(&[many("mat2", 8, 1), many("float", 1, 1)]),
            16
        ));
        // Two mat4 and four vec3 leave 4 + 4 rows: four vec2 and 12 scalars fill them.
        let mixed = join(&[many("mat4", 2, 1), many("vec3", 4, 1), many("vec2", 4, 1)]);
        assert!(packs(&join(&[mixed.clone(), many("float", 12, 1)]), 16));
        assert!(!packs(&join(&[mixed.clone(), many("float", 13, 1)]), 16));
        assert_eq!(rows_needed(&join(&[mixed, many("float", 13, 1)])), 17);
    }

    #[test]
    fn declarations_are_read_by_qualifier_and_type() {
        let source = "precision mediump float;\nuniform highp vec3 u_a[4];\nuniform float u_b, u_c;\n\
            uniform sampler2D u_t;\nvarying vec2 v_uv;\nattribute mat3 a_m;\nstruct S { vec3 x; };\n\
            void main() { vec4 uniformish = vec4(0.0); }";
        let found = declarations(source).unwrap();
        let names: Vec<_> = found
            .uniforms
            .iter()
            .map(|u| (&u.name[..], u.len))
            .collect();
        assert_eq!(names, [("u_a", 4), ("u_b", 1), ("u_c", 1)]);
        assert_eq!(found.samplers, 1);
        assert_eq!(found.varyings.len(), 1);
        assert_eq!(attribute_slots(&found.attributes), 3);
        assert!(declarations("uniform Light u_l;").is_err());
    }
}
