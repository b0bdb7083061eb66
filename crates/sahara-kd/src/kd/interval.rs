//! The walks' interval rules, written once for every lane form (see
//! [`FloatLanes`]): the single-ray walk and the packet walk decide with
//! these, so they visit the same cells.
//!
//! - A ray's interval `[t0, t1]` in a cell is widened by the relative
//!   slack [`MARGIN`] before it is compared with a split plane's distance
//!   `tp` (see `math::slack`): only a plane beyond the widened interval
//!   sends the ray to the near child alone, only one before it to the far
//!   child alone.
//! - A NaN `tp` (a ray lying in the plane: `o = split`, `d = 0`) satisfies
//!   neither comparison, so both children get the whole interval, as they
//!   must; the cut below keeps the interval whole for it too.
//! - A stacked cell is entered again only if its entry distance is within
//!   the slack of the closest hit found so far.

use crate::math::slack::MARGIN;
use crate::simd::lanes::FloatLanes;

/// The lower end of the widened interval: `t0 - |t0| MARGIN`.
#[inline(always)]
pub(crate) fn widened_t0<L: FloatLanes>(t0: L) -> L {
    t0.sub(t0.abs().mul(L::splat(MARGIN)))
}

/// The upper end of the widened interval: `t1 + |t1| MARGIN`.
#[inline(always)]
pub(crate) fn widened_t1<L: FloatLanes>(t1: L) -> L {
    t1.add(t1.abs().mul(L::splat(MARGIN)))
}

/// The interval cut at the plane `tp`: the near child's `t1` and the far
/// child's `t0`, each clamped into `[t0, t1]` (a NaN `tp` leaves both
/// children the whole interval).
#[inline(always)]
pub(crate) fn cut<L: FloatLanes>(tp: L, t0: L, t1: L) -> (L, L) {
    (tp.min(t1).max(t0), tp.max(t0).min(t1))
}

/// True where a cell entered at `t0` may still hold a hit closer than
/// `closest` (infinity while there is no hit).
#[inline(always)]
pub(crate) fn may_hold_closer<L: FloatLanes>(t0: L, closest: L) -> L::Mask {
    t0.le(closest.mul(L::splat(1.0 + MARGIN)))
}
