//! Leaf blocks as a tree stores them: each block of up to eight triangles
//! keeps its distinct vertices once and, per lane, the numbers of its three
//! vertices.
//!
//! Why: the triangles of a leaf block share most of their vertices (a
//! connected piece of mesh: 9-12 distinct vertices for 8 triangles on the
//! bunny, sponza, the dragon and the teapot in its stadium), so storing the
//! 24 vertex slots of [`TriangleBlock`] whole spent about twice the memory
//! the block needs (figures in `docs/accelerator.md`). The AVX2 block test shears each distinct vertex once and
//! gathers the lanes from the vertex table with in-register permutes
//! (`vpermps` and a blend, or one `vpermt2ps` with AVX-512 VL).
//!
//! The coordinates are the triangles' own, bit for bit, so every test that
//! reads a block computes what it computed on the whole copies.
//!
//! Layout of one block in the pool of `u32` words:
//! - word 0: the index-array offset of lane 0 (the leaf run's entry);
//! - word 1: the number of distinct vertices `n` and the table stride `s`
//!   (`n | s << 8`);
//! - words 2..8: 24 vertex numbers, one byte each, by vertex then lane;
//! - then the table: `s` x coordinates, `s` y, `s` z (f32 bits).
//!
//! `s` is `n` rounded up to a multiple of four (at most 16); a block whose
//! triangles have more than 16 distinct vertices (rare: 36 of the bunny's
//! 21,402 blocks) stores its 24 vertex slots as they are (`s` = 24, vertex
//! `k` of lane `l` is number `8 k + l`), and the AVX2 test loads those
//! lanes directly. The pool ends with [`POOL_TAIL`] zero words, so that a
//! test may load eight table entries past the last block's end (lanes it
//! never selects).

use std::marker::PhantomData;

use glam::Vec3;

use super::{run_triangles, TriangleBlock, BLOCK_WIDTH};
use crate::math::Triangle;
#[cfg(target_arch = "x86_64")]
use crate::simd::level;

/// Words before a block's vertex table.
const HEADER: usize = 8;

/// Distinct vertices a table holds at most (two registers of eight).
const MAX_TABLE: usize = 16;

/// The stride of a block stored vertex slot by vertex slot.
const VERBATIM: usize = 3 * BLOCK_WIDTH;

/// Zero words after the last block (see the module documentation).
pub const POOL_TAIL: usize = 16;

/// All leaf blocks of a triangle tree, in leaf order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IndexedBlocks {
    words: Vec<u32>,
}

impl IndexedBlocks {
    /// Packs the blocks of a padded index array (runs of eight, `u32::MAX`
    /// marking padding) and returns, for each run of eight, the word offset
    /// of its block.
    pub fn pack(prims: &[Triangle], padded_indices: &[u32]) -> (Self, Vec<u32>) {
        // Room for blocks with a typical table of 12 entries.
        let blocks = padded_indices.len() / BLOCK_WIDTH;
        let mut words = Vec::with_capacity(blocks * (HEADER + 3 * 12) + POOL_TAIL);
        let mut starts = Vec::with_capacity(blocks);
        for (run, chunk) in padded_indices.chunks(BLOCK_WIDTH).enumerate() {
            starts.push(u32::try_from(words.len()).expect("leaf data beyond 2^32 words"));
            let tris = run_triangles(prims, chunk);
            push_block(&mut words, (run * BLOCK_WIDTH) as u32, &tris);
        }
        words.resize(words.len() + POOL_TAIL, 0);
        (Self { words }, starts)
    }

    /// The first word, for addresses of blocks (prefetches).
    #[inline(always)]
    pub(crate) fn words_ptr(&self) -> *const u32 {
        self.words.as_ptr()
    }

    /// The block starting at word `at`.
    ///
    /// # Safety
    /// `at` must be the start of a block of this pool.
    #[inline(always)]
    pub unsafe fn block(&self, at: usize) -> IndexedBlock<'_> {
        debug_assert!(self.checked_block(at).is_some());
        IndexedBlock {
            // SAFETY: the caller's contract; the block and the tail that
            // tests may over-read lie inside `words`.
            w: unsafe { self.words.as_ptr().add(at) },
            pool: PhantomData,
        }
    }

    /// The block starting at word `at`, if one can start there (checked;
    /// for validation and tests).
    pub fn checked_block(&self, at: usize) -> Option<IndexedBlock<'_>> {
        let w = self.words.get(at..)?;
        if w.len() < HEADER {
            return None;
        }
        let (count, stride) = ((w[1] & 0xff) as usize, (w[1] >> 8) as usize);
        let table = stride == VERBATIM
            || (4..=MAX_TABLE).contains(&stride) && stride.is_multiple_of(4) && count <= stride;
        let fits = table && HEADER + 3 * stride + POOL_TAIL <= w.len();
        fits.then_some(IndexedBlock {
            w: w.as_ptr(),
            pool: PhantomData,
        })
    }

    /// Heap bytes of the pool.
    pub fn bytes(&self) -> usize {
        std::mem::size_of_val(self.words.as_slice())
    }

    /// The pool's words, mutable (tests that corrupt a block).
    #[cfg(test)]
    pub(crate) fn words_mut(&mut self) -> &mut [u32] {
        &mut self.words
    }
}

/// Appends the block of `tris` (at most eight), whose lane 0 is index-array
/// entry `run`.
fn push_block(words: &mut Vec<u32>, run: u32, tris: &[Triangle]) {
    assert!(tris.len() <= BLOCK_WIDTH, "{} triangles", tris.len());
    let mut table: Vec<Vec3> = Vec::with_capacity(3 * BLOCK_WIDTH);
    let mut numbers = [0u8; 3 * BLOCK_WIDTH];
    let key = |p: Vec3| p.to_array().map(f32::to_bits);
    for (l, t) in tris.iter().enumerate() {
        for (k, &p) in t.v.iter().enumerate() {
            let n = match table.iter().position(|&q| key(q) == key(p)) {
                Some(n) => n,
                None => {
                    table.push(p);
                    table.len() - 1
                }
            };
            numbers[k * BLOCK_WIDTH + l] = n as u8;
        }
    }
    let stride = if table.len() > MAX_TABLE {
        // Too many for two registers: the slots as they are.
        table = (0..3 * BLOCK_WIDTH)
            .map(|s| {
                let (k, l) = (s / BLOCK_WIDTH, s % BLOCK_WIDTH);
                tris.get(l).map_or(Vec3::ZERO, |t| t.v[k])
            })
            .collect();
        for (s, n) in numbers.iter_mut().enumerate() {
            *n = s as u8;
        }
        VERBATIM
    } else {
        table.len().next_multiple_of(4).max(4)
    };
    words.push(run);
    words.push(table.len() as u32 | (stride as u32) << 8);
    for q in numbers.chunks(4) {
        words.push(u32::from_ne_bytes([q[0], q[1], q[2], q[3]]));
    }
    for axis in 0..3 {
        for n in 0..stride {
            words.push(table.get(n).map_or(0.0, |p| p[axis]).to_bits());
        }
    }
}

/// One block of an [`IndexedBlocks`] pool (a view; see the module
/// documentation for the layout).
#[derive(Clone, Copy, Debug)]
pub struct IndexedBlock<'a> {
    /// The block's first word: the block and at least [`POOL_TAIL`] words
    /// after it lie in the pool (`IndexedBlocks::block` and
    /// `checked_block` make sure). A pointer rather than a slice: the
    /// slice's bounds checks and length arithmetic were a tenth of the
    /// block test's instructions (cachegrind, sponza's camera rays).
    w: *const u32,
    pool: PhantomData<&'a [u32]>,
}

// SAFETY: a shared view of `u32` words, like `&[u32]`.
unsafe impl Send for IndexedBlock<'_> {}
// SAFETY: as above.
unsafe impl Sync for IndexedBlock<'_> {}

impl<'a> IndexedBlock<'a> {
    /// Word `i` of the block (its header and table, or the pool's tail).
    #[inline(always)]
    fn word(&self, i: usize) -> u32 {
        debug_assert!(i < HEADER + 3 * VERBATIM + POOL_TAIL);
        // SAFETY: callers read only the block's words (header, numbers,
        // table entries named by its numbers).
        unsafe { *self.w.add(i) }
    }

    /// The index-array offset of lane 0.
    #[inline(always)]
    pub fn run(&self) -> usize {
        self.word(0) as usize
    }

    /// Number of distinct vertices in the table.
    #[inline(always)]
    pub fn vertex_count(&self) -> usize {
        (self.word(1) & 0xff) as usize
    }

    /// Entries per table row (x, y, z).
    #[inline(always)]
    fn stride(&self) -> usize {
        (self.word(1) >> 8) as usize
    }

    /// Words the block takes in the pool (never zero).
    #[allow(clippy::len_without_is_empty)]
    #[inline(always)]
    pub fn len(&self) -> usize {
        HEADER + 3 * self.stride()
    }

    /// True for a block stored slot by slot (more than 16 distinct vertices).
    #[inline(always)]
    pub fn is_verbatim(&self) -> bool {
        self.stride() == VERBATIM
    }

    /// The next block of the same leaf.
    ///
    /// # Safety
    /// The leaf must have another block after this one.
    #[inline(always)]
    pub unsafe fn next(&self) -> IndexedBlock<'a> {
        // SAFETY: the caller's contract.
        IndexedBlock {
            w: unsafe { self.w.add(self.len()) },
            pool: PhantomData,
        }
    }

    /// Table entries in use: the distinct vertices, or the 24 slots of a
    /// verbatim block.
    #[inline(always)]
    pub fn table_len(&self) -> usize {
        if self.is_verbatim() {
            VERBATIM
        } else {
            self.vertex_count()
        }
    }

    /// The table number of vertex `k` of `lane`.
    #[inline(always)]
    pub fn number(&self, k: usize, lane: usize) -> usize {
        debug_assert!(k < 3 && lane < BLOCK_WIDTH);
        // SAFETY: the 24 number bytes follow the first two header words.
        unsafe { *(self.w.add(2) as *const u8).add(k * BLOCK_WIDTH + lane) as usize }
    }

    /// Table entry `n`.
    #[inline(always)]
    pub fn table_vertex(&self, n: usize) -> Vec3 {
        let s = self.stride();
        let c = |axis: usize| f32::from_bits(self.word(HEADER + axis * s + n));
        Vec3::new(c(0), c(1), c(2))
    }

    /// Vertex `k` of the triangle in `lane`.
    #[inline(always)]
    pub fn vertex(&self, k: usize, lane: usize) -> Vec3 {
        self.table_vertex(self.number(k, lane))
    }

    /// The triangle in `lane`, as it was packed.
    #[inline(always)]
    pub fn triangle(&self, lane: usize) -> Triangle {
        Triangle::new(
            self.vertex(0, lane),
            self.vertex(1, lane),
            self.vertex(2, lane),
        )
    }

    /// The block with every lane's vertices written out (the layout the
    /// portable tests read); lanes past the block's triangles hold its
    /// first vertex or zeros.
    #[inline(always)]
    pub fn expand(&self) -> TriangleBlock {
        let mut v = [[[0.0; BLOCK_WIDTH]; 3]; 3];
        for (k, vk) in v.iter_mut().enumerate() {
            for l in 0..BLOCK_WIDTH {
                let p = self.vertex(k, l).to_array();
                for (row, x) in vk.iter_mut().zip(p) {
                    row[l] = x;
                }
            }
        }
        TriangleBlock { v }
    }
}

#[cfg(target_arch = "x86_64")]
use crate::simd::lanes::Lanes8;

#[cfg(target_arch = "x86_64")]
impl IndexedBlock<'_> {
    /// Row `axis` of the vertex table: entries 0..8 and 8..16 (the second
    /// register holds other words when the table is shorter; no lane that
    /// [`IndexedBlock::gather_avx2`] returns reads them).
    ///
    /// # Safety
    /// The CPU must have AVX2, and the caller must be compiled for it
    /// (always inlined, as [`IndexedBlock::numbers_avx2`]); the block must
    /// not be verbatim.
    #[inline(always)]
    pub(crate) unsafe fn row_avx2(&self, axis: usize) -> (Lanes8, Lanes8) {
        use std::arch::x86_64::*;
        debug_assert!(!self.is_verbatim());
        let at = HEADER + axis * self.stride();
        // SAFETY: the row and the pool's tail hold 16 words from `at`.
        unsafe {
            let p = self.w.add(at) as *const f32;
            (_mm256_loadu_ps(p), _mm256_loadu_ps(p.add(BLOCK_WIDTH)))
        }
    }

    /// The table numbers of vertex `k` of the eight lanes.
    ///
    /// # Safety
    /// The CPU must have AVX2, and the caller must be compiled for it
    /// (always inlined: see `RayShear::indexed_edges_intrinsics`).
    #[inline(always)]
    pub(crate) unsafe fn numbers_avx2(&self, k: usize) -> std::arch::x86_64::__m256i {
        use std::arch::x86_64::*;
        // SAFETY: eight bytes of the header.
        unsafe {
            let p = self.w.add(2 + 2 * k) as *const __m128i;
            _mm256_cvtepu8_epi32(_mm_loadl_epi64(p))
        }
    }

    /// Lane `l` of the result is entry `numbers[l]` of the 16-entry table
    /// `(lo, hi)`: two in-register permutes and a blend on bit 3.
    ///
    /// # Safety
    /// The CPU must have AVX2, and the caller must be compiled for it
    /// (always inlined, as [`IndexedBlock::numbers_avx2`]).
    #[inline(always)]
    pub(crate) unsafe fn gather_avx2(
        (lo, hi): (Lanes8, Lanes8),
        numbers: std::arch::x86_64::__m256i,
    ) -> Lanes8 {
        use std::arch::x86_64::*;
        // `vpermps` reads the low three bits of each number; bit 3 (moved
        // to the sign bit) picks the register.
        // SAFETY: AVX2 (the caller's contract).
        unsafe {
            let upper = _mm256_castsi256_ps(_mm256_slli_epi32::<28>(numbers));
            _mm256_blendv_ps(
                _mm256_permutevar8x32_ps(lo, numbers),
                _mm256_permutevar8x32_ps(hi, numbers),
                upper,
            )
        }
    }

    /// [`IndexedBlock::gather_avx2`], or with `SIMD` at
    /// [`level::AVX512`] one AVX-512 (VL) two-register permute.
    ///
    /// # Safety
    /// The CPU must have the level's instructions, and the caller must be
    /// compiled for them (always inlined).
    #[inline(always)]
    pub(crate) unsafe fn gather<const SIMD: u8>(
        table: (Lanes8, Lanes8),
        numbers: std::arch::x86_64::__m256i,
    ) -> Lanes8 {
        // SAFETY: the caller's contract.
        unsafe {
            if SIMD >= level::AVX512 {
                // Low four bits of each number: entry of `lo` then `hi`.
                std::arch::x86_64::_mm256_permutex2var_ps(table.0, numbers, table.1)
            } else {
                Self::gather_avx2(table, numbers)
            }
        }
    }

    /// The lanes of vertex `k`, coordinate `axis`, of a verbatim block.
    ///
    /// # Safety
    /// The CPU must have AVX2; the block must be verbatim.
    #[target_feature(enable = "avx2")]
    #[inline]
    pub(crate) unsafe fn slot_avx2(&self, k: usize, axis: usize) -> Lanes8 {
        use std::arch::x86_64::*;
        debug_assert!(self.is_verbatim());
        // SAFETY: a verbatim table has 24 entries per row.
        unsafe {
            let p = self.w.add(HEADER + axis * VERBATIM + k * BLOCK_WIDTH);
            _mm256_loadu_ps(p as *const f32)
        }
    }

    /// Every lane's vertices, `[vertex][axis]`, as [`IndexedBlock::expand`]
    /// gives them.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    #[inline]
    pub(crate) unsafe fn lanes_avx2(&self) -> [[Lanes8; 3]; 3] {
        if self.is_verbatim() {
            // SAFETY: verbatim, AVX2 (the caller's contract).
            return std::array::from_fn(|k| {
                std::array::from_fn(|axis| unsafe { self.slot_avx2(k, axis) })
            });
        }
        // SAFETY: not verbatim, AVX2.
        let rows: [(Lanes8, Lanes8); 3] = std::array::from_fn(|a| unsafe { self.row_avx2(a) });
        std::array::from_fn(|k| {
            // SAFETY: AVX2.
            let n = unsafe { self.numbers_avx2(k) };
            // SAFETY: AVX2, and this function is compiled for it.
            rows.map(|r| unsafe { Self::gather_avx2(r, n) })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::floats;

    fn bits(t: &Triangle) -> [[u32; 3]; 3] {
        t.v.map(|p| p.to_array().map(f32::to_bits))
    }

    /// Blocks of shared and of unshared vertices (up to 24 distinct, the
    /// verbatim layout) give back their triangles bit for bit, lane by lane
    /// and expanded, and the AVX2 lanes equal the expanded ones.
    #[test]
    fn blocks_round_trip() {
        let mut f = floats(5);
        let mut verbatim = 0;
        for round in 0..400 {
            // A pool of `distinct` points; triangles pick from it, so the
            // number of distinct vertices in a block runs from 3 to 24.
            let distinct = 3 + round % 22;
            let pts: Vec<Vec3> = (0..distinct)
                .map(|i| match i % 5 {
                    0 => Vec3::new(-0.0, f(), 0.0),
                    _ => Vec3::new(f(), f(), f()) * 10f32.powi(i as i32 % 7 - 3),
                })
                .collect();
            let mut pick = floats(round as u64);
            // Lanes per block; six or more for the verbatim rounds.
            let n = if round % 4 == 0 {
                6 + round % 3
            } else {
                1 + round % 8
            };
            let tris: Vec<Triangle> = (0..16)
                .map(|_| {
                    let mut q = || {
                        if round % 4 == 0 {
                            // Every vertex its own: 24 distinct, verbatim.
                            Vec3::new(pick(), pick(), pick())
                        } else {
                            pts[((pick() + 1.0) * 0.5 * distinct as f32) as usize % distinct]
                        }
                    };
                    Triangle::new(q(), q(), q())
                })
                .collect();
            let idx: Vec<u32> = (0..16)
                .map(|i| if i % 8 < n { i as u32 } else { u32::MAX })
                .collect();
            let (pool, starts) = IndexedBlocks::pack(&tris, &idx);
            assert_eq!(starts.len(), 2);
            for (b, &at) in starts.iter().enumerate() {
                let block = pool.checked_block(at as usize).unwrap();
                assert_eq!(block.run(), b * 8);
                verbatim += block.is_verbatim() as usize;
                if b == 0 {
                    // SAFETY: two blocks, `at` is the first.
                    let next = unsafe { block.next() };
                    assert_eq!(next.run(), 8);
                }
                let expanded = block.expand();
                for l in 0..n {
                    let want = &tris[b * 8 + l];
                    assert_eq!(bits(&block.triangle(l)), bits(want));
                    assert_eq!(bits(&expanded.triangle(l)), bits(want));
                }
                #[cfg(target_arch = "x86_64")]
                if crate::simd::has_avx2() {
                    // SAFETY: AVX2 checked.
                    let lanes = unsafe { block.lanes_avx2() };
                    for (k, vk) in lanes.iter().enumerate() {
                        for (axis, &x) in vk.iter().enumerate() {
                            let got: [f32; 8] = unsafe { std::mem::transmute(x) };
                            assert_eq!(
                                got.map(f32::to_bits),
                                expanded.v[k][axis].map(f32::to_bits)
                            );
                        }
                    }
                }
            }
        }
        assert!(verbatim > 10, "{verbatim} verbatim blocks");
    }

    /// A run of padding packs as an empty block, and a damaged header
    /// (a table past the pool, more vertices than the table holds) is
    /// caught by the checked accessor.
    #[test]
    fn checked_block_rejects_overruns() {
        let t = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
        let (empty, starts) = IndexedBlocks::pack(&[t], &[u32::MAX; 8]);
        assert_eq!(
            empty
                .checked_block(starts[0] as usize)
                .unwrap()
                .vertex_count(),
            0
        );
        let mut run = [u32::MAX; 8];
        run[0] = 0;
        let (mut pool, starts) = IndexedBlocks::pack(&[t], &run);
        let at = starts[0] as usize;
        assert_eq!(pool.checked_block(at).unwrap().vertex_count(), 3);
        pool.words_mut()[at + 1] = 3 | 200 << 8;
        assert!(pool.checked_block(at).is_none());
        pool.words_mut()[at + 1] = 9 | 4 << 8;
        assert!(pool.checked_block(at).is_none());
    }
}
