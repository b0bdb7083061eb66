//! The primary set traced in packets of eight: 4x2 pixel tiles, as
//! `embree_bench.c` forms its 8-ray packets (its 16-ray ones are 4x4).

use std::time::Instant;

use sahara_kd::packet::PACKET;
use sahara_kd::{Hit, KdTree, Ray};

use super::throughput::{mrays_per_sec, thread_cpu_seconds};
use crate::protocol::camera::ImageSize;
use crate::record::HitRecord;

/// Tile width and height of a packet.
pub const TILE: (u32, u32) = (4, 2);
const _: () = assert!((TILE.0 * TILE.1) as usize == PACKET);

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
/// [`PACKET`] is one 4x2 tile; rows and columns that do not fill a tile
/// come last, in row-major order.
pub fn tile_order(image: ImageSize) -> Vec<u32> {
    let (w, h) = (image.width, image.height);
    let (tw, th) = TILE;
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
fn trace_tiles(tree: &KdTree, rays: &[Ray], order: &[u32], out: &mut [HitRecord]) {
    let mut packet = [Ray::new(glam::Vec3::ZERO, glam::Vec3::Z); PACKET];
    let mut hits: [Option<Hit>; PACKET] = [None; PACKET];
    for idx in order.chunks(PACKET) {
        for (p, &i) in packet.iter_mut().zip(idx) {
            *p = rays[i as usize];
        }
        let n = idx.len();
        tree.closest_hit_packet(&packet[..n], &mut hits[..n]);
        for (h, &i) in hits.iter().zip(idx) {
            out[i as usize] = HitRecord::from_closest(*h);
        }
    }
}

/// Trace the row-major `rays` of `image` in 4x2 packets on the calling
/// thread: one warm-up, then the best of `runs`; the records are compared
/// with `reference` (the single-ray path's).
pub fn measure_packets(
    tree: &KdTree,
    rays: &[Ray],
    image: ImageSize,
    runs: usize,
    reference: &[HitRecord],
) -> PacketMeasurement {
    assert_eq!(rays.len(), (image.width * image.height) as usize);
    let order = tile_order(image);
    let mut out = vec![HitRecord::MISS; rays.len()];
    trace_tiles(tree, rays, &order, &mut out);
    let (mut best, mut best_cpu) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..runs.max(1) {
        let (t0, c0) = (Instant::now(), thread_cpu_seconds());
        trace_tiles(tree, rays, &order, &mut out);
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
        let order = tile_order(image);
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
}
