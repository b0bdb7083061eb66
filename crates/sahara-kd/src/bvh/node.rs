//! The eight-wide node: eight child boxes as structure-of-arrays floats,
//! so that one node step tests all eight with a handful of 256-bit
//! operations, the eight child references, and the order in which to visit
//! the children for each of the eight ray octants.

use crate::math::Aabb;

/// Children per node.
pub(crate) const ARITY: usize = 8;

/// A reference to a node's child, in one `u32`:
/// - an inner node: its index in the node array (bit 31 clear);
/// - a leaf: bit 31 set, its index in the leaf array in bits 0..29 and its
///   triangle count minus one in bits 29 and 30 (a leaf holds one to
///   [`MAX_LEAF`] triangles).
///
/// Nodes and leaves are kept in two arrays, not interleaved: the nodes,
/// which every ray reads from the root down, stay dense in the cache (one
/// array interleaving each node with its leaves made random rays 1.4x
/// slower on the bunny: the nodes spread over four times the memory);
/// - no child: [`EMPTY`] (its box is empty, so no ray ever reaches it).
pub(crate) type ChildRef = u32;

/// The reference of an unused child slot.
pub(crate) const EMPTY: ChildRef = u32::MAX;

/// The most triangles a leaf holds.
pub const MAX_LEAF: usize = super::quad::QUAD;

/// The bit that marks a leaf.
const LEAF_BIT: u32 = 1 << 31;

/// The largest leaf index a reference can hold (`EMPTY`'s excluded).
pub(crate) const MAX_LEAF_INDEX: u32 = (1 << 29) - 2;

/// A leaf's reference from its index and triangle count.
#[inline(always)]
pub(crate) fn leaf_ref(leaf: u32, count: usize) -> ChildRef {
    debug_assert!((1..=MAX_LEAF).contains(&count) && leaf <= MAX_LEAF_INDEX);
    LEAF_BIT | ((count as u32 - 1) << 29) | leaf
}

/// True when `r` names a leaf (or is [`EMPTY`]).
#[inline(always)]
pub(crate) fn is_leaf(r: ChildRef) -> bool {
    r & LEAF_BIT != 0
}

/// A leaf reference's leaf index and triangle count.
#[inline(always)]
pub(crate) fn leaf_parts(r: ChildRef) -> (usize, usize) {
    (
        (r & (LEAF_BIT - 1) & !(3 << 29)) as usize,
        ((r >> 29) & 3) as usize + 1,
    )
}

/// One node of the hierarchy: 256 bytes, four cache lines.
///
/// `bounds[axis][side][slot]` is the lower (`side` 0) or upper (`side` 1)
/// bound of child `slot`'s box along `axis`, so a walk loads the eight
/// near planes of an axis from `side = direction < 0` and the far ones
/// from the other side, without a per-child swap (Fuetterling, Lojewski,
/// Pfreundt & Ebert 2017, "Accelerated single ray tracing for wide vector
/// units"). Unused slots hold the empty box (`+inf` below, `-inf` above),
/// which no ray enters.
///
/// `order[i]` holds, for every octant `o` of a ray's direction (bit 0 set
/// for a negative x, bit 1 for y, bit 2 for z), in bits `3o..3o+3`, the
/// slot visited `i`-th from last: the children sorted far to near by their
/// box centres along the octant's diagonal. A walk shifts the word right by
/// `3o` and uses it as a permutation (the permute instructions read only
/// the low three bits), so that pushing the hit children in slot order
/// leaves the nearest on top of the stack.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub(crate) struct WideNode {
    /// Child boxes, `[axis][min, max][slot]`.
    pub(crate) bounds: [[[f32; ARITY]; 2]; 3],
    /// Child references (see the module's `ChildRef`).
    pub(crate) child: [ChildRef; ARITY],
    /// Visiting order per octant, far to near.
    pub(crate) order: [u32; ARITY],
}

impl WideNode {
    /// A node whose slots hold `children` (at most eight boxes and
    /// references), the rest empty, with its visiting orders.
    pub(crate) fn new(children: &[(Aabb, ChildRef)]) -> Self {
        assert!(!children.is_empty() && children.len() <= ARITY);
        let mut bounds = [[[f32::INFINITY; ARITY], [f32::NEG_INFINITY; ARITY]]; 3];
        let mut child = [EMPTY; ARITY];
        for (slot, (b, r)) in children.iter().enumerate() {
            for (axis, [lo, hi]) in bounds.iter_mut().enumerate() {
                lo[slot] = b.min[axis];
                hi[slot] = b.max[axis];
            }
            child[slot] = *r;
        }
        let mut order = [0u32; ARITY];
        for octant in 0..8u32 {
            // The octant's diagonal, pointing the way the ray goes.
            let diag = [0, 1, 2].map(|a| if octant >> a & 1 == 1 { -1.0f64 } else { 1.0 });
            let key = |slot: usize| -> f64 {
                if slot >= children.len() {
                    // Empty slots last (nearest): never pushed anyway.
                    return f64::NEG_INFINITY;
                }
                let c = children[slot].0.center();
                (0..3).map(|a| c[a] as f64 * diag[a]).sum()
            };
            let mut slots: [usize; ARITY] = std::array::from_fn(|s| s);
            // Far first: descending distance along the diagonal; ties by
            // slot, so the order is deterministic.
            slots.sort_by(|&a, &b| key(b).total_cmp(&key(a)).then(a.cmp(&b)));
            for (i, &s) in slots.iter().enumerate() {
                order[i] |= (s as u32) << (3 * octant);
            }
        }
        Self {
            bounds,
            child,
            order,
        }
    }

    /// The box of child `slot` (empty for an unused slot).
    pub(crate) fn child_bounds(&self, slot: usize) -> Aabb {
        let b = &self.bounds;
        Aabb {
            min: glam::Vec3::new(b[0][0][slot], b[1][0][slot], b[2][0][slot]),
            max: glam::Vec3::new(b[0][1][slot], b[1][1][slot], b[2][1][slot]),
        }
    }

    /// The slot visited `i`-th from last by a ray in `octant`.
    #[inline(always)]
    pub(crate) fn slot_in_order(&self, i: usize, octant: u32) -> usize {
        (self.order[i] >> (3 * octant) & 7) as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn leaf_references_round_trip() {
        for (first, count) in [(0, 1), (5, 4), (MAX_LEAF_INDEX, 3)] {
            let r = leaf_ref(first, count);
            assert!(is_leaf(r) && r != EMPTY);
            assert_eq!(leaf_parts(r), (first as usize, count));
        }
        assert!(!is_leaf(12345));
        assert_eq!(std::mem::size_of::<WideNode>(), 256);
    }

    /// A ray going +x meets the child at small x first: it is visited last
    /// from the end (on top of the stack).
    #[test]
    fn order_puts_the_nearest_child_last() {
        let kids: Vec<(Aabb, ChildRef)> = (0..5)
            .map(|i| {
                let x = [3.0, 1.0, 4.0, 0.0, 2.0][i];
                (
                    Aabb::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x + 0.5, 1.0, 1.0)),
                    i as u32,
                )
            })
            .collect();
        let n = WideNode::new(&kids);
        // Octant 0 (+x +y +z): far to near by x, then the empty slots.
        let seq: Vec<usize> = (0..ARITY).map(|i| n.slot_in_order(i, 0)).collect();
        assert_eq!(&seq[..5], &[2, 0, 4, 1, 3]);
        // Octant 1 (-x): the reverse.
        let seq: Vec<usize> = (0..ARITY).map(|i| n.slot_in_order(i, 1)).collect();
        assert_eq!(&seq[..5], &[3, 1, 4, 0, 2]);
        assert!(n.child_bounds(6).is_empty());
    }
}
