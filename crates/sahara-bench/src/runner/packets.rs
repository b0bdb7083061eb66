//! The primary set traced in packets: eight rays on 4x2 pixel tiles and
//! sixteen on 4x4 tiles, as `embree_bench.c` forms its 8- and 16-ray
//! packets.

use std::time::Instant;

use sahara_kd::{Hit, Ray, TriangleAccel};
use sahara_kd::{PACKET, PACKET16};

use super::throughput::{mrays_per_sec, thread_cpu_seconds};
use crate::protocol::camera::ImageSize;
use crate::record::HitRecord;

/// The packet paths measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PacketSize {
    /// [`PACKET`] rays on 4x2 tiles (`KdTree::closest_hit_packet`).
    Eight,
    /// [`PACKET16`] rays on 4x4 tiles (`KdTree::closest_hit_packet16`):
    /// rows 0-1 and 2-3 of a tile are its two 4x2 halves.
    Sixteen,
}

impl PacketSize {
    /// Rays per packet.
    pub fn rays(self) -> usize {
        match self {
            PacketSize::Eight => PACKET,
            PacketSize::Sixteen => PACKET16,
        }
    }

    /// Tile width and height.
    pub fn tile(self) -> (u32, u32) {
        match self {
            PacketSize::Eight => (4, 2),
            PacketSize::Sixteen => (4, 4),
        }
    }
}

/// Speed of the packet path on one thread, and whether it agreed.
#[derive(Clone, Copy, Debug)]
pub struct PacketMeasurement {
    /// Best Mrays/s by wall clock.
    pub mrays_1t: f64,
    /// Best Mrays/s by the tracing thread's CPU time.
    pub mrays_1t_cpu: f64,
    /// True if every record equals the single-ray path's.
    pub agrees: bool,
}

/// Indices of the row-major rays of `image`, tile by tile: each run of
/// `size.rays()` is one tile, row by row; rows and columns that do not
/// fill a tile come last, in row-major order.
pub fn tile_order(image: ImageSize, size: PacketSize) -> Vec<u32> {
    let (w, h) = (image.width, image.height);
    let (tw, th) = size.tile();
    let (full_w, full_h) = (w - w % tw, h - h % th);
    let mut order = Vec::with_capacity((w * h) as usize);
    for ty in (0..full_h).step_by(th as usize) {
        for tx in (0..full_w).step_by(tw as usize) {
            for y in ty..ty + th {
                for x in tx..tx + tw {
                    order.push(y * w + x);
                }
            }
        }
    }
    for y in 0..h {
        for x in 0..w {
            if x >= full_w || y >= full_h {
                order.push(y * w + x);
            }
        }
    }
    order
}

/// One pass: gather each tile's rays, trace the packet, scatter the hits
/// (gathering and scattering are timed, as in `embree_bench.c`).
fn trace_tiles(
    tree: &TriangleAccel,
    rays: &[Ray],
    order: &[u32],
    size: PacketSize,
    out: &mut [HitRecord],
) {
    let mut packet = [Ray::new(glam::Vec3::ZERO, glam::Vec3::Z); PACKET16];
    let mut hits: [Option<Hit>; PACKET16] = [None; PACKET16];
    for idx in order.chunks(size.rays()) {
        for (p, &i) in packet.iter_mut().zip(idx) {
            *p = rays[i as usize];
        }
        let n = idx.len();
        match size {
            PacketSize::Eight => tree.closest_hit_packet(&packet[..n], &mut hits[..n]),
            PacketSize::Sixteen => tree.closest_hit_packet16(&packet[..n], &mut hits[..n]),
        }
        for (h, &i) in hits.iter().zip(idx) {
            out[i as usize] = HitRecord::from_closest(*h);
        }
    }
}

/// Trace the row-major `rays` of `image` in packets of `size` on the
/// calling thread: one warm-up, then the best of `runs`; the records are
/// compared with `reference` (the single-ray path's).
pub fn measure_packets(
    tree: &TriangleAccel,
    rays: &[Ray],
    image: ImageSize,
    runs: usize,
    reference: &[HitRecord],
    size: PacketSize,
) -> PacketMeasurement {
    assert_eq!(rays.len(), (image.width * image.height) as usize);
    let order = tile_order(image, size);
    let mut out = vec![HitRecord::MISS; rays.len()];
    trace_tiles(tree, rays, &order, size, &mut out);
    let (mut best, mut best_cpu) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..runs.max(1) {
        let (t0, c0) = (Instant::now(), thread_cpu_seconds());
        trace_tiles(tree, rays, &order, size, &mut out);
        best_cpu = best_cpu.min(thread_cpu_seconds() - c0);
        best = best.min(t0.elapsed().as_secs_f64());
    }
    let agrees = out.len() == reference.len()
        && out
            .iter()
            .zip(reference)
            .all(|(a, b)| a.tri == b.tri && a.t.to_bits() == b.t.to_bits());
    PacketMeasurement {
        mrays_1t: mrays_per_sec(rays.len(), best),
        mrays_1t_cpu: mrays_per_sec(rays.len(), best_cpu),
        agrees,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tile_order_is_a_permutation_in_4x2_tiles() {
        let image = ImageSize {
            width: 10,
            height: 5,
        };
        let order = tile_order(image, PacketSize::Eight);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..50).collect::<Vec<u32>>());
        // The first tile: pixels (0..4, 0..2).
        assert_eq!(&order[..8], &[0, 1, 2, 3, 10, 11, 12, 13]);
        // The second: (4..8, 0..2).
        assert_eq!(&order[8..16], &[4, 5, 6, 7, 14, 15, 16, 17]);
        // 2 x 2 full tiles; then the leftover column pair and last row.
        assert_eq!(order[32], 8);
    }

    #[test]
    fn tile_order_is_a_permutation_in_4x4_tiles() {
        let image = ImageSize {
            width: 10,
            height: 5,
        };
        let order = tile_order(image, PacketSize::Sixteen);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..50).collect::<Vec<u32>>());
        // The first tile: pixels (0..4, 0..4), its halves rows 0-1 and 2-3.
        assert_eq!(
            &order[..16],
            &[0, 1, 2, 3, 10, 11, 12, 13, 20, 21, 22, 23, 30, 31, 32, 33]
        );
        // The second: (4..8, 0..4); then the leftovers, row-major.
        assert_eq!(&order[16..20], &[4, 5, 6, 7]);
        assert_eq!(&order[32..35], &[8, 9, 18]);
    }
}
