//! The node hierarchy: local transforms read in `f64` from the JSON (the `gltf` crate keeps
//! them as `f32`, which loses centimetres a few hundred kilometres out), composed parent to
//! child in `f64`, walked without recursion. Each node may be reached once: a cycle, or a node
//! with two parents, is an error naming the node.

use glam::{DMat4, DQuat, DVec3};
use serde::Deserialize;

use crate::scene::not_affine;

#[derive(Deserialize)]
struct RawRoot {
    #[serde(default)]
    nodes: Vec<RawNode>,
}

#[derive(Deserialize)]
struct RawNode {
    matrix: Option<[f64; 16]>,
    translation: Option<[f64; 3]>,
    rotation: Option<[f64; 4]>,
    scale: Option<[f64; 3]>,
}

/// Every node's local transform (`matrix`, or translation × rotation × scale), from the JSON
/// text in `f64`. Errors name the node and the field.
pub(super) fn local_transforms(json: &[u8]) -> Result<Vec<DMat4>, String> {
    let root: RawRoot = serde_json::from_slice(json).map_err(|e| format!("nodes: {e}"))?;
    root.nodes
        .iter()
        .enumerate()
        .map(|(i, n)| {
            let field = format!("nodes[{i}]");
            if let Some(m) = n.matrix {
                return matrix(&m).map_err(|e| format!("{field}.matrix: {e}"));
            }
            let t = DVec3::from(n.translation.unwrap_or([0.0; 3]));
            let s = DVec3::from(n.scale.unwrap_or([1.0; 3]));
            let [x, y, z, w] = n.rotation.unwrap_or([0.0, 0.0, 0.0, 1.0]);
            let q = DQuat::from_xyzw(x, y, z, w);
            if !t.is_finite() {
                return Err(format!("{field}.translation: must be finite, got {t:?}"));
            }
            if !s.is_finite() {
                return Err(format!("{field}.scale: must be finite, got {s:?}"));
            }
            // Exporters round: a quaternion is normalised (divided by its largest component
            // first, so no length overflows); one of no length has no rotation to give.
            let largest = glam::DVec4::from(q).abs().max_element();
            let q = q / largest;
            let length = q.length();
            if !(largest.is_finite() && largest > 0.0 && length.is_finite()) {
                return Err(format!(
                    "{field}.rotation: must be a finite non-zero quaternion, got {:?}",
                    [x, y, z, w]
                ));
            }
            let q = q / length;
            Ok(DMat4::from_scale_rotation_translation(s, q, t))
        })
        .collect()
}

/// A node's `matrix` (column-major): finite and affine (glTF asks for a TRS matrix; a
/// projective one would put every vertex at w ≠ 1, a last row of zeros at infinity). A
/// singular one is kept: it flattens its node, as a zero scale does.
fn matrix(m: &[f64; 16]) -> Result<DMat4, String> {
    let mut m = DMat4::from_cols_array(m);
    if !m.is_finite() {
        return Err("must be finite".into());
    }
    if let Some(row) = not_affine(&m) {
        return Err(format!("not an affine transform ({row})"));
    }
    for col in [&mut m.x_axis, &mut m.y_axis, &mut m.z_axis] {
        col.w = 0.0;
    }
    m.w_axis.w = 1.0;
    Ok(m)
}

/// A node reached from the scene's roots, with its world transform.
#[derive(Clone, Debug)]
pub(super) struct Placed {
    /// Node index.
    pub node: usize,
    /// Node space → world space (the caller's root transform included).
    pub world: DMat4,
}

/// The nodes to place: the default scene's (`scene`), else the first scene's, else — a file
/// without scenes — every node that is no other node's child. Returns the roots and what they
/// came from (for messages).
pub(super) fn roots(document: &gltf::Document) -> (Vec<usize>, String) {
    if let Some(s) = document.default_scene() {
        return (
            s.nodes().map(|n| n.index()).collect(),
            format!("scenes[{}]", s.index()),
        );
    }
    if let Some(s) = document.scenes().next() {
        return (s.nodes().map(|n| n.index()).collect(), "scenes[0]".into());
    }
    let mut is_child = vec![false; document.nodes().len()];
    for n in document.nodes() {
        for c in n.children() {
            is_child[c.index()] = true;
        }
    }
    let roots = (0..is_child.len()).filter(|&i| !is_child[i]).collect();
    (
        roots,
        "the nodes without a parent (the file has no scene)".into(),
    )
}

/// Walks the hierarchy from `roots` depth first (children in order), composing `root` ×
/// parents × node. `locals` are the nodes' local transforms.
pub(super) fn walk(
    document: &gltf::Document,
    roots: &[usize],
    locals: &[DMat4],
    root: DMat4,
) -> Result<Vec<Placed>, String> {
    let count = locals.len();
    // Who reached each node first (`usize::MAX`: a root), to tell a cycle from two parents.
    // Set when a node is put on the stack, so the stack holds each node once: a list naming
    // one node millions of times is refused at its second mention, not stacked whole.
    let mut parent: Vec<Option<usize>> = vec![None; count];
    let reach = |node: usize, from: usize, parent: &mut Vec<Option<usize>>| match parent.get(node) {
        None => Err(format!("nodes[{node}] does not exist ({count} nodes)")),
        Some(Some(first)) => Err(reached_twice(node, *first, from, parent)),
        Some(None) => {
            parent[node] = Some(from);
            Ok(())
        }
    };
    let mut placed = Vec::new();
    let mut stack: Vec<(usize, DMat4)> = Vec::new();
    for &r in roots.iter() {
        reach(r, usize::MAX, &mut parent)?;
    }
    stack.extend(roots.iter().rev().map(|&r| (r, root)));
    while let Some((node, parent_world)) = stack.pop() {
        let world = parent_world * locals[node];
        placed.push(Placed { node, world });
        let Some(n) = document.nodes().nth(node) else {
            continue;
        };
        let children: Vec<usize> = n.children().map(|c| c.index()).collect();
        for &c in &children {
            reach(c, node, &mut parent)?;
        }
        stack.extend(children.iter().rev().map(|&c| (c, world)));
    }
    Ok(placed)
}

fn reached_twice(node: usize, first: usize, now: usize, parent: &[Option<usize>]) -> String {
    if first == usize::MAX && now == usize::MAX {
        return format!("the scene's roots list nodes[{node}] twice: a node is placed once");
    }
    let via = |p: usize| {
        if p == usize::MAX {
            "the scene's roots".to_string()
        } else {
            format!("nodes[{p}]")
        }
    };
    // A cycle when the node is an ancestor of the one that reached it again.
    let mut at = now;
    let mut steps = 0;
    while at != usize::MAX && steps <= parent.len() {
        if at == node {
            return format!(
                "nodes[{node}] is its own ancestor (through {}): the node hierarchy has a \
                 cycle",
                via(now)
            );
        }
        at = parent[at].unwrap_or(usize::MAX);
        steps += 1;
    }
    format!(
        "nodes[{node}] is reached from both {} and {}: a node may have only one parent",
        via(first),
        via(now)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transforms_are_read_in_f64_and_checked() {
        let json = br#"{"nodes": [
            {"translation": [6378137.123456789, 0, 0]},
            {"matrix": [2,0,0,0, 0,2,0,0, 0,0,2,0, 1,2,3,1]},
            {"rotation": [0, 0, 0, 2], "scale": [1, 2, 3]},
            {"rotation": [0, 0, 0, 0]}
        ]}"#;
        let err = local_transforms(json).unwrap_err();
        assert!(err.starts_with("nodes[3].rotation"), "{err}");
        let json = br#"{"nodes": [
            {"translation": [6378137.123456789, 0, 0]},
            {"matrix": [2,0,0,0, 0,2,0,0, 0,0,2,0, 1,2,3,1]},
            {"rotation": [0, 0, 0, 2], "scale": [1, 2, 3]}
        ]}"#;
        let m = local_transforms(json).unwrap();
        assert_eq!(m[0].w_axis.x, 6378137.123456789);
        assert_eq!(m[1].transform_point3(DVec3::ONE), DVec3::new(3.0, 4.0, 5.0));
        assert_eq!(
            m[2].transform_vector3(DVec3::ONE),
            DVec3::new(1.0, 2.0, 3.0)
        );
        assert!(local_transforms(b"{}").unwrap().is_empty());
        // A quaternion of any finite non-zero length is the rotation it says.
        let json = br#"{"nodes": [{"rotation": [0, 1e200, 0, 1e200]}, {"rotation": [0, 1e-300, 0, 1e-300]}]}"#;
        let quarter = DMat4::from_rotation_y(std::f64::consts::FRAC_PI_2);
        for m in local_transforms(json).unwrap() {
            assert!(
                (m.transform_vector3(DVec3::X) - quarter.transform_vector3(DVec3::X)).length()
                    < 1e-12
            );
        }
    }

    #[test]
    fn a_matrix_must_be_affine_and_finite_and_may_be_singular() {
        let node = |m: &str| format!(r#"{{"nodes": [{{}}, {{"matrix": [{m}]}}]}}"#);
        for (m, want) in [
            ("1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,0", "last row 0 0 0 0"),
            ("1,0,0,0.5, 0,1,0,0, 0,0,1,0, 0,0,0,1", "last row 0.5 0 0 1"),
            ("1,0,0,0, 0,1,0,0, 0,0,1,-1, 0,0,0,1", "last row 0 0 -1 1"),
            // Written short: `{}` wrote 1e-300 in 300 digits.
            (
                "1,0,0,1e-300, 0,1,0,0, 0,0,1,0, 0,0,0,0",
                "last row 1e-300 0 0 0,",
            ),
            ("1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,2", "last row 0 0 0 2"),
        ] {
            let err = local_transforms(node(m).as_bytes()).unwrap_err();
            assert!(err.starts_with("nodes[1].matrix: not an affine"), "{err}");
            assert!(err.contains(want), "{err}");
        }
        // JSON cannot hold infinity; a number past f64 is refused as it is read.
        assert!(
            local_transforms(node("1e999,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1").as_bytes()).is_err()
        );
        // Flat (singular) and nearly affine (rounded by an exporter) matrices are kept; the
        // rounding is snapped away.
        let flat = local_transforms(node("1,0,0,0, 0,0,0,0, 0,0,1,0, 0,0,0,1").as_bytes());
        assert_eq!(flat.unwrap()[1].y_axis, glam::DVec4::ZERO);
        let rounded =
            local_transforms(node("1,0,0,1e-9, 0,1,0,0, 0,0,1,0, 0,0,0,0.9999999").as_bytes());
        assert_eq!(rounded.unwrap()[1], DMat4::IDENTITY);
    }

    #[test]
    fn cycles_and_second_parents_are_told_apart() {
        let parent = vec![Some(usize::MAX), Some(0), Some(1)];
        assert!(reached_twice(0, usize::MAX, 2, &parent).contains("cycle"));
        let parent = vec![Some(usize::MAX), Some(usize::MAX), Some(0)];
        let msg = reached_twice(2, 0, 1, &parent);
        assert!(msg.contains("only one parent"), "{msg}");
        // A root listed twice: it read "reached from both the scene's roots and the scene's
        // roots".
        let msg = reached_twice(1, usize::MAX, usize::MAX, &parent);
        assert!(msg.contains("roots list nodes[1] twice"), "{msg}");
    }
}
