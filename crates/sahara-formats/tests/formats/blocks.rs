//! How far an image is from a reference, block by block: the measure the
//! reference tests (BSDFs, the Mitsuba comparison kit) hold Sahara to.

use glam::Vec3;

/// Edge of a block in pixels.
pub const BLOCK: usize = 8;

/// For every whole `BLOCK x BLOCK` block of the `w x h` images and each
/// channel, `|mean of image - mean of reference| / (mean of reference +
/// 0.02)`, sorted.
pub fn block_errors(image: &[Vec3], reference: &[Vec3], w: usize, h: usize) -> Vec<f32> {
    let mut blocks = Vec::new();
    for by in 0..h / BLOCK {
        for bx in 0..w / BLOCK {
            let (mut a, mut b) = (Vec3::ZERO, Vec3::ZERO);
            for y in by * BLOCK..(by + 1) * BLOCK {
                for x in bx * BLOCK..(bx + 1) * BLOCK {
                    a += image[y * w + x];
                    b += reference[y * w + x];
                }
            }
            let k = (BLOCK * BLOCK) as f32;
            let e = (a / k - b / k).abs() / (b / k + Vec3::splat(0.02));
            blocks.extend(e.to_array());
        }
    }
    blocks.sort_by(f32::total_cmp);
    blocks
}
