//! The interleaved batch walk: several rays' wide walks advanced in turn,
//! one step each, so that one ray's node and leaf loads (prefetched when
//! its previous step ends) arrive while the others compute. A wide step
//! has no branch per plane, so switching rays costs no mispredictions the
//! single-ray walk would not have had (after Kocberber et al., "Asynchronous
//! memory access chaining", VLDB 2015; the interleaving of binary walks,
//! whose every step branches, lost: see `docs/performance.md`).

use super::walk::Walker;
use crate::kd::walk::LeafVisit;
use crate::kd::{KdTree, LeafStorage, NoCounters};
use crate::math::Ray;

/// Rays in flight per thread.
pub(crate) const IN_FLIGHT: usize = 8;

impl<P: LeafStorage> KdTree<P> {
    /// Walks every ray of `rays` over the wide nodes, `IN_FLIGHT` at a
    /// time: `visit(i)` makes ray `i`'s leaf visit, `done(i, v)` receives
    /// it when the walk of ray `i` is over (in no particular order of `i`).
    /// `SIMD` is the level the caller is compiled for. The tree must have
    /// wide nodes.
    #[inline(always)]
    pub(crate) fn walk_interleaved<V, const SIMD: u8>(
        &self,
        rays: &[Ray],
        mut visit: impl FnMut(usize) -> V,
        mut done: impl FnMut(usize, V),
    ) where
        V: LeafVisit<NoCounters>,
    {
        debug_assert!(!self.wide.is_empty());
        let mut walkers: [Walker; IN_FLIGHT] = std::array::from_fn(|_| Walker::idle());
        let mut visits: [Option<(usize, V)>; IN_FLIGHT] = std::array::from_fn(|_| None);
        let mut next = 0;
        let mut live = 0;
        for (w, slot) in walkers.iter_mut().zip(visits.iter_mut()) {
            live += self.refill(rays, &mut next, w, slot, &mut visit, &mut done) as usize;
        }
        while live != 0 {
            for (w, slot) in walkers.iter_mut().zip(visits.iter_mut()) {
                let Some((_, v)) = slot else { continue };
                if w.advance::<P, NoCounters, SIMD, true>(self, &mut NoCounters, v) {
                    continue;
                }
                let (i, v) = slot.take().expect("a live slot");
                done(i, v);
                if !self.refill(rays, &mut next, w, slot, &mut visit, &mut done) {
                    live -= 1;
                }
            }
        }
    }

    /// Starts in `w` the walk of the next ray from `next` on that has
    /// anything to walk, finishing the others at once; false when the
    /// rays are used up.
    #[inline(always)]
    fn refill<V: LeafVisit<NoCounters>>(
        &self,
        rays: &[Ray],
        next: &mut usize,
        w: &mut Walker,
        slot: &mut Option<(usize, V)>,
        visit: &mut impl FnMut(usize) -> V,
        done: &mut impl FnMut(usize, V),
    ) -> bool {
        while *next < rays.len() {
            let i = *next;
            *next += 1;
            let v = visit(i);
            if w.start(self, &rays[i]) {
                w.prefetch_first(self, &v);
                *slot = Some((i, v));
                return true;
            }
            done(i, v);
        }
        false
    }
}
