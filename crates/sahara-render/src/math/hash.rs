//! Integer hashing: the only source of randomness in the renderer.
//!
//! Every random number is a pure function of (seed, pixel, pass, sample,
//! dimension), so an image never depends on thread scheduling.

/// The SplitMix64 finaliser (Steele, Lea, Flood 2014): a bijective 64-bit
/// mix with full avalanche.
#[inline(always)]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Hash of two words (order matters).
#[inline(always)]
pub fn hash2(a: u64, b: u64) -> u64 {
    mix64(mix64(a ^ 0x9e37_79b9_7f4a_7c15).wrapping_add(b))
}

/// Hash of three words (order matters).
#[inline(always)]
pub fn hash3(a: u64, b: u64, c: u64) -> u64 {
    hash2(hash2(a, b), c)
}

/// A uniform float in `[0, 1)` from the top 24 bits of a hash (every value
/// is exactly representable, so the result is never rounded up to 1).
#[inline(always)]
pub fn unit_f32(h: u64) -> f32 {
    (h >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
}

/// A pseudo-random permutation of `0..n` evaluated at `i` (`i < n`), keyed
/// by `key`: a keyed bijection on the next power of two, cycle-walked until
/// the value falls below `n`. Every step is invertible modulo 2^k (xor with a
/// constant, multiply by an odd number, xor-shift right), so the map is a
/// bijection and the walk terminates.
pub fn permute(mut i: u32, n: u32, key: u64) -> u32 {
    debug_assert!(i < n);
    if n <= 1 {
        return 0;
    }
    let bits = 32 - (n - 1).leading_zeros();
    let mask = if bits == 32 {
        u32::MAX
    } else {
        (1u32 << bits) - 1
    };
    let k0 = key as u32;
    let k1 = (key >> 32) as u32 | 1;
    loop {
        i ^= k0 & mask;
        i = i.wrapping_mul(k1) & mask;
        i ^= i >> (bits / 2 + 1);
        i = i.wrapping_mul(0x2c1b_3c6d | 1) & mask;
        i ^= (k0 >> 7) & mask;
        i = i.wrapping_mul(0x297a_2d39 | 1) & mask;
        i ^= i >> (bits / 3 + 1);
        if i < n {
            return i;
        }
    }
}

/// Numbers in `[0, 1)` for tests: the hashes of `seed` and a count.
#[cfg(test)]
pub(crate) fn test_numbers(seed: u64) -> impl FnMut() -> f32 {
    let mut k = 0u64;
    move || {
        k += 1;
        unit_f32(hash2(seed, k))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permute_is_a_bijection() {
        for n in [1u32, 2, 3, 7, 16, 100, 257] {
            for key in [0u64, 1, 0xdead_beef_1234] {
                let mut seen = vec![false; n as usize];
                for i in 0..n {
                    let j = permute(i, n, key);
                    assert!(!seen[j as usize], "n={n} key={key}");
                    seen[j as usize] = true;
                }
            }
        }
    }

    #[test]
    fn unit_f32_is_below_one() {
        assert!(unit_f32(u64::MAX) < 1.0);
        assert_eq!(unit_f32(0), 0.0);
    }
}
