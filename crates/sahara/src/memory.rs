//! Refusing work that would not fit in memory, before it starts.

use anyhow::{bail, Result};

/// Bytes per triangle while its kd-tree is built and used: the triangle
/// (36), its share of nodes and references in the finished tree (measured:
/// 64 on the dragon, 110 on the bunny) and the build's event lists (6
/// events of 8 bytes, parent and child lists alive together). Conservative
/// for the meshes measured, not a bound for pathological ones (those are
/// capped by `BuildParams::max_duplication`).
pub const BYTES_PER_TRIANGLE: u64 = 256;

/// Bytes per film pixel: the exact sums (four 128-bit integers), the film,
/// the per-tile splat buffers of a pass and the 8- or 32-bit output copy.
pub const BYTES_PER_PIXEL: u64 = 96;

/// Memory the machine can still give, from `/proc/meminfo` (None where that
/// cannot be read, e.g. off Linux).
pub fn available_bytes() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// The estimate for `triangles` triangles and a `width` x `height` film.
pub fn estimate(triangles: u64, width: u32, height: u32) -> u64 {
    triangles.saturating_mul(BYTES_PER_TRIANGLE)
        + (width as u64 * height as u64).saturating_mul(BYTES_PER_PIXEL)
}

/// An error if the estimate exceeds `available` bytes.
pub fn check_fits(triangles: u64, width: u32, height: u32, available: Option<u64>) -> Result<()> {
    let need = estimate(triangles, width, height);
    if let Some(have) = available {
        if need > have {
            bail!(
                "this render needs about {} ({} triangles, a {}x{} film) but only {} of memory are available; \
                 use a smaller image or fewer triangles",
                gib(need),
                triangles,
                width,
                height,
                gib(have)
            );
        }
    }
    Ok(())
}

fn gib(bytes: u64) -> String {
    format!("{:.1} GiB", bytes as f64 / (1u64 << 30) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_render_that_does_not_fit_is_refused_with_its_estimate() {
        // 65536^2 pixels at 96 bytes = 384 GiB.
        let e = check_fits(1000, 65536, 65536, Some(24 << 30))
            .unwrap_err()
            .to_string();
        assert!(e.contains("384.0 GiB") && e.contains("24.0 GiB"), "{e}");
        assert!(check_fits(1_000_000, 1024, 1024, Some(24 << 30)).is_ok());
        // Unknown availability never refuses.
        assert!(check_fits(u64::MAX / 512, 65536, 65536, None).is_ok());
    }

    #[test]
    fn available_memory_is_read_on_linux() {
        if cfg!(target_os = "linux") {
            assert!(available_bytes().is_some_and(|b| b > 0));
        }
    }
}
