//! The surface area heuristic for one candidate plane.

use crate::build::BuildParams;
use crate::math::Aabb;

/// Which side triangles lying in the split plane go to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlanarSide {
    /// Below the plane.
    Left,
    /// Above the plane.
    Right,
}

/// A candidate split and its SAH cost.
#[derive(Clone, Copy, Debug)]
pub struct Split {
    /// Axis 0, 1, 2.
    pub axis: usize,
    /// Plane position.
    pub pos: f32,
    /// Side of the triangles lying in the plane.
    pub planar: PlanarSide,
    /// Expected cost, in the same units as `K_I * n` for a leaf.
    pub cost: f64,
    /// References in both children together (straddlers count twice).
    pub refs: usize,
}

/// The SAH cost model of one node (Wald & Havran 2006, section 4).
pub struct SahModel {
    cell: Aabb,
    inv_area: f64,
    k_t: f64,
    k_i: f64,
    lambda: f64,
    width: u32,
    /// `log2(width)` when the width is a power of two (the default 8): the
    /// leaf-test count is then a shift, not a division (the sweep prices
    /// every candidate plane twice; divisions were most of `cost` in the
    /// build's profile).
    width_shift: Option<u32>,
    lane_cost: f32,
    /// The cell's extents in f64 (what `Aabb::surface_area` computes from).
    extent: [f64; 3],
}

impl SahModel {
    /// The model for splitting `cell`; `None` if the cell has no area.
    pub fn new(cell: Aabb, p: &BuildParams) -> Option<Self> {
        let area = cell.surface_area();
        (area > 0.0).then(|| Self {
            cell,
            inv_area: 1.0 / area,
            k_t: p.traversal_cost as f64,
            k_i: p.intersection_cost as f64,
            lambda: 1.0 - p.empty_bonus as f64,
            width: p.leaf_width,
            width_shift: p
                .leaf_width
                .is_power_of_two()
                .then(|| p.leaf_width.trailing_zeros()),
            lane_cost: p.lane_cost,
            extent: cell.extent().as_dvec3().to_array(),
        })
    }

    /// Tests a leaf of `n` triangles takes: `ceil(n / leaf_width)`.
    #[inline(always)]
    fn tests(&self, n: usize) -> f64 {
        match self.width_shift {
            Some(s) if self.lane_cost == 0.0 => ((n + (1 << s) - 1) >> s) as f64,
            _ => super::params::leaf_tests(n, self.width, self.lane_cost),
        }
    }

    /// Surface area of the cell with its `axis` extent set to `e` (f32, as
    /// `Aabb::split` and `Aabb::extent` would compute it), by the formula
    /// and operation order of `Aabb::surface_area`.
    #[inline(always)]
    fn area_with(&self, axis: usize, e: f32) -> f64 {
        let mut x = self.extent;
        x[axis] = e as f64;
        2.0 * (x[0] * x[1] + x[1] * x[2] + x[2] * x[0])
    }

    /// Cost of a leaf with `n` triangles.
    pub fn leaf_cost(&self, n: usize) -> f64 {
        self.k_i * self.tests(n)
    }

    /// Cost of splitting at `axis = pos` with `nl`, `nr` triangles on each
    /// side; `None` for a plane that makes no progress (it cuts off an empty
    /// zero-volume slab at the cell's face).
    #[inline]
    pub fn cost(&self, axis: usize, pos: f32, nl: usize, nr: usize) -> Option<f64> {
        let at_min = pos <= self.cell.min[axis];
        let at_max = pos >= self.cell.max[axis];
        if (at_min && nl == 0) || (at_max && nr == 0) {
            return None;
        }
        // The children's areas as `cell.split(axis, pos)` would give them
        // (the plane lies in the cell, so neither child is empty).
        debug_assert!(pos >= self.cell.min[axis] && pos <= self.cell.max[axis]);
        let pl = self.area_with(axis, pos - self.cell.min[axis]) * self.inv_area;
        let pr = self.area_with(axis, self.cell.max[axis] - pos) * self.inv_area;
        let c = self.k_t + self.k_i * (pl * self.tests(nl) + pr * self.tests(nr));
        // Bonus for cutting off empty space, but not for a flat empty side.
        let bonus = (nl == 0 || nr == 0) && !at_min && !at_max;
        Some(if bonus { self.lambda * c } else { c })
    }

    /// The better of the two placements of `np` planar triangles.
    #[inline]
    pub fn best_planar(
        &self,
        axis: usize,
        pos: f32,
        nl: usize,
        np: usize,
        nr: usize,
    ) -> Option<Split> {
        let left = self.cost(axis, pos, nl + np, nr);
        // Without planar triangles both placements are the same split (the
        // common case: only axis-aligned triangles are planar).
        let right = if np == 0 {
            left
        } else {
            self.cost(axis, pos, nl, nr + np)
        };
        let pick = match (left, right) {
            (Some(a), Some(b)) if a <= b => Some((a, PlanarSide::Left)),
            (_, Some(b)) => Some((b, PlanarSide::Right)),
            (Some(a), None) => Some((a, PlanarSide::Left)),
            (None, None) => None,
        };
        pick.map(|(cost, planar)| Split {
            axis,
            pos,
            planar,
            cost,
            refs: nl + np + nr,
        })
    }
}
