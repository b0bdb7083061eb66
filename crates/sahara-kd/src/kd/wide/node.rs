//! The wide node: three levels of the binary tree (up to seven split planes
//! and eight children) in one 64-byte cache line, derived from the 8-byte
//! nodes after the build.
//!
//! The seven planes sit in heap order: plane 0 is the subtree's root,
//! planes `2p + 1` and `2p + 2` the children below and above plane `p`.
//! Child slot `c` (bits `b0 b1 b2`, 1 meaning above) lies below or above
//! plane 0 by `b0`, plane `1 + b0` by `b1` and plane `3 + 2 b0 + b1` by
//! `b2`. Where the binary subtree ends early (a leaf at depth one or two),
//! the planes under it are NaN: a NaN plane distance leaves an interval
//! whole (the in-plane rule of `kd::interval`), so the leaf's slot gets the
//! interval of the cell it is, and the slots beside it are marked unused.
//! Empty leaves are marked unused too, so the walk never visits them.

use crate::kd::Node;

/// Children of a wide node.
pub(crate) const WIDTH: usize = 8;

/// Planes of a wide node (three binary levels).
pub(crate) const PLANES: usize = 7;

/// A child word with this bit is a leaf.
pub(crate) const LEAF_BIT: u32 = 1 << 31;
/// A leaf word's triangle count sits above this bit (6 bits, 0: the word
/// names a binary leaf node instead).
const COUNT_SHIFT: u32 = 25;
const COUNT_MASK: u32 = 63;
/// A leaf word's payload: its offset divided by the leaf width, or for a
/// leaf that does not fit, the index of its binary node.
const PAYLOAD_MASK: u32 = (1 << COUNT_SHIFT) - 1;

/// Eight children and the planes that separate them, in 64 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub(crate) struct WideNode {
    /// The seven split positions (NaN where there is no binary node); the
    /// eighth lane holds `meta`'s bits, so that the planes load as one
    /// vector.
    pub(crate) planes: [f32; WIDTH],
    /// Per slot: a wide node's index, or a leaf word (`LEAF_BIT`).
    pub(crate) children: [u32; WIDTH],
}

impl WideNode {
    /// The split axes, two bits per plane (plane `p` at bit `2p`), and the
    /// mask of used slots at bit 16.
    #[inline(always)]
    pub(crate) fn meta(&self) -> u32 {
        self.planes[PLANES].to_bits()
    }

    /// Split axis of plane `p` (0 for a NaN plane).
    #[inline(always)]
    pub(crate) fn axis(&self, p: usize) -> usize {
        ((self.meta() >> (2 * p)) & 3) as usize
    }

    /// Bit `c` set: slot `c` holds a child to visit.
    #[inline(always)]
    pub(crate) fn used(&self) -> u32 {
        (self.meta() >> 16) & 0xff
    }
}

/// A leaf as the walk finds it in a child word: `(offset, count)` of its
/// index run, as the binary leaf node gives them.
#[inline(always)]
pub(crate) fn leaf_of(word: u32, shift: u32, binary: &[Node]) -> (u32, u32) {
    let count = (word >> COUNT_SHIFT) & COUNT_MASK;
    let payload = word & PAYLOAD_MASK;
    if count != 0 {
        (payload << shift, count)
    } else {
        debug_assert!((payload as usize) < binary.len());
        // SAFETY: `derive` writes only indices of binary leaves here.
        let n = unsafe { binary.get_unchecked(payload as usize) };
        (n.leaf_offset(), n.leaf_count())
    }
}

/// [`leaf_of`] for a leaf stored inline (a meaningless pair for one that
/// is not): no load, for prefetches.
#[inline(always)]
pub(crate) fn leaf_of_inline(word: u32, shift: u32) -> (u32, u32) {
    (
        (word & PAYLOAD_MASK) << shift,
        (word >> COUNT_SHIFT) & COUNT_MASK,
    )
}

/// The leaf word of binary leaf `index` (non-empty): its offset and count
/// inline when they fit, else the node's index; `None` if neither fits.
fn leaf_word(index: u32, n: &Node, shift: u32) -> Option<u32> {
    let (offset, count) = (n.leaf_offset(), n.leaf_count());
    let inline =
        offset & ((1 << shift) - 1) == 0 && offset >> shift <= PAYLOAD_MASK && count <= COUNT_MASK;
    if inline {
        Some(LEAF_BIT | (count << COUNT_SHIFT) | (offset >> shift))
    } else if index <= PAYLOAD_MASK {
        Some(LEAF_BIT | index)
    } else {
        None
    }
}

/// The wide nodes of a binary tree (`binary[0]` its root), root first,
/// each node before its subtrees; leaf offsets whose low `shift` bits are
/// zero are stored shifted down by `shift`. `None` if a leaf fits no leaf
/// word (a tree of over 2^25 nodes with a leaf offset that does not fit).
pub(crate) fn derive(binary: &[Node], shift: u32) -> Option<Vec<WideNode>> {
    if binary.is_empty() {
        return Some(Vec::new());
    }
    let mut out = Vec::with_capacity(binary.len() / 6 + 1);
    derive_from(binary, 0, shift, &mut out)?;
    Some(out)
}

/// Appends the wide node rooted at binary node `root`, then its subtrees;
/// returns its index.
fn derive_from(binary: &[Node], root: u32, shift: u32, out: &mut Vec<WideNode>) -> Option<u32> {
    let me = out.len();
    out.push(WideNode {
        planes: [0.0; WIDTH],
        children: [0; WIDTH],
    });
    let mut planes = [f32::NAN; WIDTH];
    let mut meta = 0u32;
    let mut children = [u32::MAX; WIDTH];
    let mut below = Vec::new();
    // (binary node, its depth in this wide node, its plane, its first slot)
    let mut todo = vec![(root, 0u32, 0usize, 0usize)];
    while let Some((i, depth, p, slot)) = todo.pop() {
        let n = &binary[i as usize];
        if n.is_leaf() {
            if n.leaf_count() != 0 {
                children[slot] = leaf_word(i, n, shift)?;
                meta |= 1 << (16 + slot);
            }
        } else if depth == 3 {
            below.push((slot, i));
            meta |= 1 << (16 + slot);
        } else {
            planes[p] = n.split();
            meta |= (n.axis() as u32) << (2 * p);
            let span = WIDTH >> (depth + 1);
            todo.push((n.above_child(), depth + 1, 2 * p + 2, slot + span));
            todo.push((i + 1, depth + 1, 2 * p + 1, slot));
        }
    }
    below.sort_unstable();
    for (slot, i) in below {
        children[slot] = derive_from(binary, i, shift, out)?;
    }
    planes[PLANES] = f32::from_bits(meta);
    out[me] = WideNode { planes, children };
    Some(me as u32)
}

/// The slots in the order a ray meets them, per combination of the seven
/// planes' direction signs (bit `p` of the index: the ray moves towards
/// -axis of plane `p`), farthest first: the walk pushes them in this
/// order, so the nearest is on top of its stack.
pub(crate) static FAR_FIRST: [[u8; WIDTH]; 1 << PLANES] = far_first();

/// Slot `c`'s position in front-to-back order (0 nearest) for planes whose
/// direction signs are `neg`: one bit per binary level, set where the slot
/// lies on the plane's far side (Wald 2004: a ray moving towards -axis
/// meets the cell above the plane first).
pub(crate) const fn rank(neg: usize, c: usize) -> usize {
    let (b0, b1, b2) = (c >> 2, (c >> 1) & 1, c & 1);
    let far0 = b0 ^ (neg & 1);
    let far1 = b1 ^ ((neg >> (1 + b0)) & 1);
    let far2 = b2 ^ ((neg >> (3 + 2 * b0 + b1)) & 1);
    (far0 << 2) | (far1 << 1) | far2
}

const fn far_first() -> [[u8; WIDTH]; 1 << PLANES] {
    let mut t = [[0u8; WIDTH]; 1 << PLANES];
    let mut neg = 0;
    while neg < 1 << PLANES {
        let mut c = 0;
        while c < WIDTH {
            t[neg][WIDTH - 1 - rank(neg, c)] = c as u8;
            c += 1;
        }
        neg += 1;
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wide_node_is_one_cache_line() {
        assert_eq!(std::mem::size_of::<WideNode>(), 64);
        assert_eq!(std::mem::align_of::<WideNode>(), 64);
    }

    /// Front to back is the binary walk's depth-first order: near child
    /// first at every level.
    #[test]
    fn far_first_reverses_the_binary_walks_order() {
        for (neg, far_first) in FAR_FIRST.iter().enumerate() {
            let mut order = Vec::new();
            // The binary walk's order of the eight slots.
            fn visit(neg: usize, p: usize, depth: usize, slot: usize, order: &mut Vec<usize>) {
                if depth == 3 {
                    order.push(slot);
                    return;
                }
                let span = WIDTH >> (depth + 1);
                let (below, above) = ((2 * p + 1, slot), (2 * p + 2, slot + span));
                let (near, far) = if neg >> p & 1 == 1 {
                    (above, below)
                } else {
                    (below, above)
                };
                visit(neg, near.0, depth + 1, near.1, order);
                visit(neg, far.0, depth + 1, far.1, order);
            }
            visit(neg, 0, 0, 0, &mut order);
            let table: Vec<usize> = far_first.iter().rev().map(|&c| c as usize).collect();
            assert_eq!(table, order, "signs {neg:07b}");
        }
    }

    #[test]
    fn leaf_words_round_trip() {
        let binary = [
            Node::leaf(8 * 1000, 17),
            Node::leaf(8 * (1 << 26), 5),
            Node::leaf(16, 200),
        ];
        for (i, n) in binary.iter().enumerate() {
            let w = leaf_word(i as u32, n, 3).unwrap();
            assert_ne!(w & LEAF_BIT, 0);
            assert_eq!(leaf_of(w, 3, &binary), (n.leaf_offset(), n.leaf_count()));
        }
        // Inline for the first; through the node for the others.
        assert_ne!(
            (leaf_word(0, &binary[0], 3).unwrap() >> COUNT_SHIFT) & COUNT_MASK,
            0
        );
        assert_eq!(
            (leaf_word(1, &binary[1], 3).unwrap() >> COUNT_SHIFT) & COUNT_MASK,
            0
        );
        // An offset that is not a multiple of the leaf width goes through the node.
        let odd = Node::leaf(12, 3);
        assert_eq!(leaf_word(0, &odd, 3).unwrap() & !LEAF_BIT, 0);
    }

    /// A binary tree of one inner node over two leaves: the leaves go to
    /// slots 0 and 4, the planes under them are NaN, the others unused.
    #[test]
    fn shallow_subtrees_leave_nan_planes() {
        let binary = [Node::inner(1, 0.5, 2), Node::leaf(0, 3), Node::leaf(8, 4)];
        let w = derive(&binary, 3).unwrap();
        assert_eq!(w.len(), 1);
        let n = &w[0];
        assert_eq!(n.planes[0], 0.5);
        assert!(n.planes[1..PLANES].iter().all(|p| p.is_nan()));
        assert_eq!(n.axis(0), 1);
        assert_eq!(n.used(), 0b0001_0001);
        assert_eq!(leaf_of(n.children[0], 3, &binary), (0, 3));
        assert_eq!(leaf_of(n.children[4], 3, &binary), (8, 4));
    }
}
