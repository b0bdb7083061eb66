//! The two layouts of a triangle tree's leaf blocks, and what a leaf test
//! asks of a block in either.
//!
//! - [`TriangleLeaves::Whole`] (the default): every lane's three vertices
//!   written out, 288 bytes per block of eight; the block test loads its
//!   lanes directly.
//! - [`TriangleLeaves::Indexed`] (`BuildParams::compact_leaves`): each
//!   block's distinct vertices once (see `compact`): about two thirds of
//!   the memory, tracing some 3-13% slower (the gathers cost more than
//!   the smaller leaf data saves; figures in `docs/performance.md`). It is
//!   an option, for scenes where memory counts more than the last tenth of
//!   speed (Embree's compact scenes make the same trade).
//!
//! The leaf tests are written once over `LeafBlock` and compiled for each
//! layout; each traversal is compiled per layout too (see `Layout`).

use super::Frustum;
use super::PacketShear;
use super::{IndexedBlock, IndexedBlocks};
use super::{TriangleBlock, BLOCK_WIDTH};
use crate::isect::RayShear;
use crate::math::Triangle;
#[cfg(target_arch = "x86_64")]
use crate::simd::level;

/// The leaf blocks of a triangle tree, in leaf order.
#[derive(Clone, Debug, PartialEq)]
pub enum TriangleLeaves {
    /// Every lane's vertices written out (the default, fastest to test);
    /// leaf offsets are index-array offsets, block `offset / 8` first.
    Whole(Vec<TriangleBlock>),
    /// Each block's distinct vertices once (about two thirds of the memory); leaf
    /// offsets are word offsets of a leaf's first block.
    Indexed(IndexedBlocks),
}

impl Default for TriangleLeaves {
    fn default() -> Self {
        TriangleLeaves::Whole(Vec::new())
    }
}

impl TriangleLeaves {
    /// Heap bytes of the blocks.
    pub fn bytes(&self) -> usize {
        match self {
            TriangleLeaves::Whole(v) => std::mem::size_of_val(v.as_slice()),
            TriangleLeaves::Indexed(p) => p.bytes(),
        }
    }

    /// The index-array offset of the non-empty leaf whose offset field is
    /// `offset`, if the leaf data has a block there.
    pub fn leaf_run(&self, offset: u32) -> Option<usize> {
        match self {
            TriangleLeaves::Whole(_) => Some(offset as usize),
            TriangleLeaves::Indexed(p) => p.checked_block(offset as usize).map(|b| b.run()),
        }
    }
}

/// One block as the leaf tests read it, in either layout.
pub(crate) trait LeafBlock: Copy {
    /// The index-array offset of lane 0.
    fn run(&self) -> usize;

    /// The triangle in `lane`.
    fn triangle(&self, lane: usize) -> Triangle;

    /// The block test of one ray against the first `lanes` lanes:
    /// candidate mask and edge functions, as [`RayShear::block_edges`].
    ///
    /// # Safety
    /// The CPU must have the instructions of level `SIMD`, and the caller
    /// must be compiled for them.
    unsafe fn edges<const SIMD: u8>(
        &self,
        shear: &RayShear,
        lanes: usize,
    ) -> (u32, [[f32; BLOCK_WIDTH]; 3]);

    /// The packet test of the triangle in `lane`: as
    /// [`PacketShear::triangle_edges`].
    ///
    /// # Safety
    /// As [`LeafBlock::edges`].
    #[inline(always)]
    unsafe fn packet_edges<const SIMD: u8>(
        &self,
        ps: &PacketShear,
        lane: usize,
    ) -> (u32, [[f32; BLOCK_WIDTH]; 3]) {
        #[cfg(target_arch = "x86_64")]
        if SIMD >= level::AVX2 {
            // SAFETY: the caller's contract.
            return unsafe { ps.triangle_edges_intrinsics(|k, axis| self.coord(k, axis, lane)) };
        }
        ps.triangle_edges(&self.triangle(lane))
    }

    /// Coordinate `axis` of vertex `k` of the triangle in `lane`.
    fn coord(&self, k: usize, axis: usize, lane: usize) -> f32;

    /// The lanes among the first `lanes` that some ray of `frustum` may
    /// hit, as [`Frustum::survivors`].
    ///
    /// # Safety
    /// As [`LeafBlock::edges`].
    unsafe fn survivors<const SIMD: u8>(&self, frustum: &Frustum, lanes: usize) -> u32;
}

/// A block of the whole layout and the index-array offset of its lane 0.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WholeBlock<'a> {
    block: &'a TriangleBlock,
    run: usize,
}

impl LeafBlock for WholeBlock<'_> {
    #[inline(always)]
    fn run(&self) -> usize {
        self.run
    }

    #[inline(always)]
    fn triangle(&self, lane: usize) -> Triangle {
        self.block.triangle(lane)
    }

    #[inline(always)]
    fn coord(&self, k: usize, axis: usize, lane: usize) -> f32 {
        self.block.v[k][axis][lane]
    }

    #[inline(always)]
    unsafe fn edges<const SIMD: u8>(
        &self,
        shear: &RayShear,
        lanes: usize,
    ) -> (u32, [[f32; BLOCK_WIDTH]; 3]) {
        #[cfg(target_arch = "x86_64")]
        if SIMD >= level::AVX2 {
            // SAFETY: the caller's contract.
            return unsafe { shear.block_edges_avx2(self.block, lanes) };
        }
        shear.block_edges(self.block, lanes)
    }

    #[inline(always)]
    unsafe fn survivors<const SIMD: u8>(&self, frustum: &Frustum, lanes: usize) -> u32 {
        #[cfg(target_arch = "x86_64")]
        if SIMD >= level::AVX2 {
            // SAFETY: the caller's contract.
            return unsafe { frustum.survivors_avx2(self.block, lanes) };
        }
        frustum.survivors(self.block, lanes)
    }
}

impl LeafBlock for IndexedBlock<'_> {
    #[inline(always)]
    fn run(&self) -> usize {
        IndexedBlock::run(self)
    }

    #[inline(always)]
    fn triangle(&self, lane: usize) -> Triangle {
        IndexedBlock::triangle(self, lane)
    }

    #[inline(always)]
    fn coord(&self, k: usize, axis: usize, lane: usize) -> f32 {
        self.vertex(k, lane)[axis]
    }

    #[inline(always)]
    unsafe fn edges<const SIMD: u8>(
        &self,
        shear: &RayShear,
        lanes: usize,
    ) -> (u32, [[f32; BLOCK_WIDTH]; 3]) {
        // SAFETY: the caller's contract.
        unsafe { shear.indexed_block_edges::<SIMD>(*self, lanes) }
    }

    #[inline(always)]
    unsafe fn survivors<const SIMD: u8>(&self, frustum: &Frustum, lanes: usize) -> u32 {
        #[cfg(target_arch = "x86_64")]
        if SIMD >= level::AVX2 {
            // SAFETY: the caller's contract.
            return unsafe { frustum.survivors_indexed_avx2(*self, lanes) };
        }
        frustum.survivors(&self.expand(), lanes)
    }
}

/// A tree's leaf blocks in one layout, as the traversals read them: each
/// traversal is compiled once per layout and picks it once per query, so
/// that its loop holds one leaf test (both inlined into one loop made the
/// packets slower).
pub(crate) trait Layout: Copy {
    /// One block.
    type Block<'a>: LeafBlock
    where
        Self: 'a;

    /// The blocks of the non-empty leaf with offset field `offset` and
    /// `count` triangles.
    ///
    /// # Safety
    /// `offset` and `count` must be those of a non-empty leaf of the tree
    /// these blocks belong to.
    unsafe fn blocks(&self, offset: usize, count: usize) -> impl Iterator<Item = Self::Block<'_>>;

    /// The address of the first block of the leaf with offset field
    /// `offset`, for a prefetch (any offset is safe: nothing is read).
    fn address(&self, offset: usize) -> *const u8;
}

/// Asks the cache for the `lines` 64-byte lines from `p` (a hint: any
/// address is safe, nothing is read).
#[inline(always)]
pub(crate) fn prefetch_lines(p: *const u8, lines: usize) {
    #[cfg(target_arch = "x86_64")]
    for l in 0..lines {
        // SAFETY: a prefetch neither faults nor reads.
        unsafe {
            std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(
                p.wrapping_add(64 * l).cast(),
            )
        };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (p, lines);
}

/// The whole layout's blocks.
#[derive(Clone, Copy)]
pub(crate) struct Whole<'a>(pub &'a [TriangleBlock]);

impl Layout for Whole<'_> {
    type Block<'b>
        = WholeBlock<'b>
    where
        Self: 'b;

    #[inline(always)]
    unsafe fn blocks(&self, offset: usize, count: usize) -> impl Iterator<Item = WholeBlock<'_>> {
        let first = offset / BLOCK_WIDTH;
        let n = count.div_ceil(BLOCK_WIDTH);
        debug_assert!(offset.is_multiple_of(BLOCK_WIDTH) && first + n <= self.0.len());
        // SAFETY: the build pads every leaf run to whole blocks and makes
        // one block per eight run entries (the caller's contract).
        let run = unsafe { self.0.get_unchecked(first..first + n) };
        run.iter().enumerate().map(move |(b, block)| WholeBlock {
            block,
            run: offset + b * BLOCK_WIDTH,
        })
    }

    #[inline(always)]
    fn address(&self, offset: usize) -> *const u8 {
        self.0.as_ptr().wrapping_add(offset / BLOCK_WIDTH).cast()
    }
}

/// The indexed layout's blocks.
#[derive(Clone, Copy)]
pub(crate) struct Indexed<'a>(pub &'a IndexedBlocks);

impl Layout for Indexed<'_> {
    type Block<'b>
        = IndexedBlock<'b>
    where
        Self: 'b;

    #[inline(always)]
    unsafe fn blocks(&self, offset: usize, count: usize) -> impl Iterator<Item = IndexedBlock<'_>> {
        IndexedRun {
            // SAFETY: the build points a non-empty leaf at its first block
            // (the caller's contract).
            next: unsafe { self.0.block(offset) },
            left: count.div_ceil(BLOCK_WIDTH),
        }
    }

    #[inline(always)]
    fn address(&self, offset: usize) -> *const u8 {
        self.0.words_ptr().wrapping_add(offset).cast()
    }
}

/// The blocks of one indexed-layout leaf, in order.
pub(crate) struct IndexedRun<'a> {
    next: IndexedBlock<'a>,
    left: usize,
}

impl<'a> Iterator for IndexedRun<'a> {
    type Item = IndexedBlock<'a>;
    #[inline(always)]
    fn next(&mut self) -> Option<IndexedBlock<'a>> {
        if self.left == 0 {
            return None;
        }
        self.left -= 1;
        let b = self.next;
        if self.left != 0 {
            // SAFETY: a leaf's blocks follow one another; `left` more.
            self.next = unsafe { b.next() };
        }
        Some(b)
    }
}
