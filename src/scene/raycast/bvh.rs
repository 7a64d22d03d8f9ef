//! The bounding volume hierarchy both levels of the ray caster use: built by median split of
//! the item centroids along the widest axis (quick to build; trace quality matters little for
//! the few thousand rays a reference casts) and traversed iteratively, nearer child first.

use std::collections::TryReserveError;
use std::ops::Range;

use glam::{DMat4, DVec3};

/// Most items in a leaf.
const LEAF_SIZE: usize = 4;

/// A node: a leaf holds `count > 0` items from `first` of the build order; an inner node
/// (`count == 0`) has its two children at `first` and `first + 1`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Node {
    pub min: DVec3,
    pub max: DVec3,
    pub first: u32,
    pub count: u32,
}

impl Node {
    /// Entry parameter of the ray into the box within `[0, t_max]`, if it enters at all.
    pub fn slab(&self, origin: DVec3, inv_dir: DVec3, t_max: f64) -> Option<f64> {
        slab(self.min, self.max, origin, inv_dir, t_max)
    }

    /// [`Node::slab`] for the box carried by an affine `m`, grown a little so that rounding
    /// never puts a transformed triangle outside it.
    pub fn slab_transformed(
        &self,
        m: &DMat4,
        origin: DVec3,
        inv_dir: DVec3,
        t_max: f64,
    ) -> Option<f64> {
        let (min, max) = transformed_box(self.min, self.max, m);
        slab(min, max, origin, inv_dir, t_max)
    }
}

/// The world box of an object-space box under an affine `m` (centre and half extents through
/// the matrix and its absolute value), padded by a relative 10⁻⁹ for rounding.
pub(super) fn transformed_box(min: DVec3, max: DVec3, m: &DMat4) -> (DVec3, DVec3) {
    let centre = m.transform_point3((min + max) * 0.5);
    let half = (max - min) * 0.5;
    let abs = |v: glam::DVec4| v.truncate().abs();
    let extent = abs(m.x_axis) * half.x + abs(m.y_axis) * half.y + abs(m.z_axis) * half.z;
    let pad = extent * 1e-9 + DVec3::splat(centre.abs().max_element() * 1e-15);
    (centre - extent - pad, centre + extent + pad)
}

fn slab(min: DVec3, max: DVec3, origin: DVec3, inv_dir: DVec3, t_max: f64) -> Option<f64> {
    let t0 = (min - origin) * inv_dir;
    let t1 = (max - origin) * inv_dir;
    // A zero direction component gives ±∞ (or NaN on the slab's plane, which min/max ignore).
    let enter = t0.min(t1).max_element().max(0.0);
    let exit = t0.max(t1).min_element().min(t_max);
    (enter <= exit).then_some(enter)
}

/// Builds the hierarchy over items given by their boxes; returns the nodes and the item order
/// the leaves refer to, or the error where the allocator refuses them. Allocates the order
/// exactly, room for the most nodes the split can make (shrunk once built) and the centroids'
/// scratch, each asked of the allocator first.
pub(super) fn build(boxes: &[(DVec3, DVec3)]) -> Result<(Vec<Node>, Vec<u32>), TryReserveError> {
    let n = boxes.len();
    if n == 0 {
        return Ok((Vec::new(), Vec::new()));
    }
    let mut centroids = Vec::new();
    centroids.try_reserve_exact(n)?;
    centroids.extend(boxes.iter().map(|(lo, hi)| (*lo + *hi) * 0.5));
    let mut order = Vec::new();
    order.try_reserve_exact(n)?;
    order.extend(0..n as u32);
    let empty = Node {
        min: DVec3::ZERO,
        max: DVec3::ZERO,
        first: 0,
        count: 0,
    };
    // A set of more than LEAF_SIZE items splits in halves of two or more, so leaves hold two
    // items or more (one only where n is 1): fewer than n nodes in all.
    let mut nodes = Vec::new();
    nodes.try_reserve_exact(n)?;
    nodes.push(empty);
    let mut work = vec![(0usize, 0usize, n)];
    while let Some((ni, start, end)) = work.pop() {
        let items = &mut order[start..end];
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        let (mut clo, mut chi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for &i in items.iter() {
            let (bl, bh) = boxes[i as usize];
            (lo, hi) = (lo.min(bl), hi.max(bh));
            let c = centroids[i as usize];
            (clo, chi) = (clo.min(c), chi.max(c));
        }
        nodes[ni].min = lo;
        nodes[ni].max = hi;
        if items.len() <= LEAF_SIZE {
            nodes[ni].first = start as u32;
            nodes[ni].count = items.len() as u32;
            continue;
        }
        let extent = chi - clo;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        // Median split: always halves the set, so the depth stays log₂(n) even when many
        // centroids coincide.
        let mid = items.len() / 2;
        items.select_nth_unstable_by(mid, |&a, &b| {
            centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
        });
        let left = nodes.len();
        nodes.extend([empty, empty]);
        nodes[ni].first = left as u32;
        work.push((left, start, start + mid));
        work.push((left + 1, start + mid, end));
    }
    debug_assert!(nodes.len() <= n, "{} nodes for {n} items", nodes.len());
    nodes.shrink_to_fit();
    Ok((nodes, order))
}

/// Walks the hierarchy nearer child first, calling `leaf` with the order range of every leaf
/// whose box `enter` accepts (`enter` is asked again when a node is popped: a nearer hit found
/// since may rule it out). `stack` is scratch, left empty.
pub(super) fn traverse<S>(
    nodes: &[Node],
    stack: &mut Vec<u32>,
    state: &mut S,
    enter: impl Fn(&Node, &S) -> Option<f64>,
    mut leaf: impl FnMut(&mut S, Range<usize>),
) {
    stack.clear();
    if nodes
        .first()
        .is_some_and(|root| enter(root, state).is_some())
    {
        stack.push(0);
    }
    while let Some(ni) = stack.pop() {
        let node = &nodes[ni as usize];
        if enter(node, state).is_none() {
            continue;
        }
        if node.count > 0 {
            leaf(
                state,
                node.first as usize..(node.first + node.count) as usize,
            );
            continue;
        }
        let (a, b) = (node.first, node.first + 1);
        let ta = enter(&nodes[a as usize], state);
        let tb = enter(&nodes[b as usize], state);
        // Push the farther child first so the nearer one is traversed first.
        match (ta, tb) {
            (Some(ta), Some(tb)) if ta <= tb => stack.extend([b, a]),
            (Some(_), Some(_)) => stack.extend([a, b]),
            (Some(_), None) => stack.push(a),
            (None, Some(_)) => stack.push(b),
            (None, None) => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_transformed_box_holds_its_transformed_corners() {
        let m = DMat4::from_translation(DVec3::new(1e6, -3.0, 2.0))
            * DMat4::from_rotation_y(0.7)
            * DMat4::from_scale(DVec3::new(2.0, -0.5, 3.0));
        let (lo, hi) = (DVec3::new(-1.0, 0.0, 2.0), DVec3::new(0.5, 4.0, 2.5));
        let (wlo, whi) = transformed_box(lo, hi, &m);
        for i in 0..8 {
            let pick = |bit: u32, a: f64, b: f64| if i & (1 << bit) != 0 { b } else { a };
            let corner = m.transform_point3(DVec3::new(
                pick(0, lo.x, hi.x),
                pick(1, lo.y, hi.y),
                pick(2, lo.z, hi.z),
            ));
            assert!(
                corner.cmpge(wlo).all() && corner.cmple(whi).all(),
                "{corner}"
            );
        }
    }
}
