//! Refusing a render that would not fit in memory, before it starts: one
//! estimate (the triangles with their trees, the film with its passes)
//! against the memory the machine can still give. A failed allocation in
//! a render's threads would abort the process, losing the work of
//! whatever runs it (a Python session, say); the request refuses first.

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

/// Bytes per film pixel of each render pass: its exact sums (64) and its
/// image (at most 16).
pub const BYTES_PER_PASS_PIXEL: u64 = 80;

/// Memory the machine can still give, from `/proc/meminfo` (None where that
/// cannot be read, e.g. off Linux).
pub fn available_bytes() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// The estimate for `triangles` triangles and a `width` x `height` film
/// with `passes` render passes.
pub fn estimate(triangles: u64, width: u32, height: u32, passes: usize) -> u64 {
    let pixels = u64::from(width) * u64::from(height);
    let per_pixel = BYTES_PER_PIXEL + passes as u64 * BYTES_PER_PASS_PIXEL;
    triangles
        .saturating_mul(BYTES_PER_TRIANGLE)
        .saturating_add(pixels.saturating_mul(per_pixel))
}

/// Why the estimate exceeds `available` bytes (never when that is
/// unknown).
pub fn check_fits(
    triangles: u64,
    (width, height): (u32, u32),
    passes: usize,
    available: Option<u64>,
) -> Result<(), String> {
    let need = estimate(triangles, width, height, passes);
    match available {
        Some(have) if need > have => Err(format!(
            "this render needs about {} ({triangles} triangles, a {width}x{height} film{}) but \
             only {} of memory are available; use a smaller image or fewer triangles",
            gib(need),
            match passes {
                0 => String::new(),
                1 => " with 1 render pass".to_string(),
                n => format!(" with {n} render passes"),
            },
            gib(have)
        )),
        _ => Ok(()),
    }
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
        let e = check_fits(1000, (65536, 65536), 0, Some(24 << 30)).unwrap_err();
        assert!(e.contains("384.0 GiB") && e.contains("24.0 GiB"), "{e}");
        assert!(e.contains("a 65536x65536 film)"), "{e}");
        // Each pass counts: 176 bytes a pixel with one.
        let e = check_fits(0, (65536, 65536), 1, Some(24 << 30)).unwrap_err();
        assert!(
            e.contains("704.0 GiB") && e.contains("with 1 render pass"),
            "{e}"
        );
        assert!(check_fits(1_000_000, (1024, 1024), 2, Some(24 << 30)).is_ok());
        // Unknown availability never refuses.
        assert!(check_fits(u64::MAX / 512, (65536, 65536), 0, None).is_ok());
    }

    #[test]
    fn available_memory_is_read_on_linux() {
        if cfg!(target_os = "linux") {
            assert!(available_bytes().is_some_and(|b| b > 0));
        }
    }
}
