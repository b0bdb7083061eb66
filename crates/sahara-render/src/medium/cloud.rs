//! pbrt-v4's procedural cloud: a density made of Perlin noise, with no
//! grid behind it.
//!
//! At a point `p` of the medium's space the density is a sum of five
//! octaves of Ken Perlin's improved noise (each at 1.99 times the previous
//! frequency and half its weight) at `frequency · p`, the lookup point first
//! pushed about by two octaves of the noise's gradient (the *wispiness*),
//! then scaled by `density`, faded with height (`1 - p.y`) and clamped to
//! [0, 1], with a floor that fills the cloud's bottom below `y = 0.5`. The
//! density never exceeds 1, so the medium's own σt is a majorant everywhere:
//! tracking draws tentative collisions at that one rate inside the
//! medium's box and decides each by the density there.

use glam::{Affine3A, Vec3};

use super::phase::HenyeyGreenstein;
use super::{null_collision, FreeFlight};

/// Tentative collisions a tracking walk takes at most before it gives up
/// (as the grid's walks do).
const MAX_STEPS: u32 = 100_000;

/// A medium whose density is pbrt-v4's noise cloud: at a point of density
/// `ρ` in [0, 1], absorption `ρ σa` and scattering `ρ σs`.
#[derive(Clone, Debug, PartialEq)]
pub struct CloudMedium {
    /// Absorption per unit length at density 1, per channel.
    pub sigma_a: Vec3,
    /// Scattering per unit length at density 1, per channel.
    pub sigma_s: Vec3,
    /// How scattered light leaves.
    pub phase: HenyeyGreenstein,
    /// The factor on the noise sum before the clamp (pbrt's `density`).
    pub density: f32,
    /// How far the noise's gradient pushes the lookup point (0: not at all).
    pub wispiness: f32,
    /// The noise's frequency in the medium's space.
    pub frequency: f32,
    /// The box the medium fills, in the medium's space (lower corner).
    pub bounds_min: Vec3,
    /// The box's upper corner.
    pub bounds_max: Vec3,
    /// World space to the medium's space.
    pub to_medium: Affine3A,
}

impl CloudMedium {
    /// A cloud filling the box `bounds_min` to `bounds_max` of the
    /// medium's space, which `to_world` places in the world.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        sigma_a: Vec3,
        sigma_s: Vec3,
        phase: HenyeyGreenstein,
        density: f32,
        wispiness: f32,
        frequency: f32,
        bounds: (Vec3, Vec3),
        to_world: Affine3A,
    ) -> Self {
        Self {
            sigma_a,
            sigma_s,
            phase,
            density,
            wispiness,
            frequency,
            bounds_min: bounds.0,
            bounds_max: bounds.1,
            to_medium: to_world.inverse(),
        }
    }

    /// The density at `p` in the medium's space, in [0, 1] (also outside
    /// the box: the box only limits where the medium is).
    pub fn density_in_medium(&self, p: Vec3) -> f32 {
        let mut pp = self.frequency * p;
        if self.wispiness > 0.0 {
            let (mut weight, mut scale) = (0.05 * self.wispiness, 10.0f32);
            for _ in 0..2 {
                pp += weight * noise_gradient(scale * pp);
                weight *= 0.5;
                scale *= 1.99;
            }
        }
        let (mut sum, mut weight, mut scale) = (0.0f32, 0.5f32, 1.0f32);
        for _ in 0..5 {
            sum += weight * noise(scale * pp);
            weight *= 0.5;
            scale *= 1.99;
        }
        let d = unit((1.0 - p.y) * 4.5 * self.density * sum);
        unit(d + 2.0 * (0.5 - p.y).max(0.0))
    }

    /// The density at world point `p`, zero outside the box.
    #[inline]
    pub fn density_at(&self, p: Vec3) -> f32 {
        let q = self.to_medium.transform_point3(p);
        if q.cmplt(self.bounds_min).any() || q.cmpgt(self.bounds_max).any() {
            return 0.0;
        }
        self.density_in_medium(q)
    }

    /// The stretch `[t0, t1]` of `origin + t dir`, `t` in `[0, t_max]`,
    /// inside the box, if any.
    fn inside(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<(f32, f32)> {
        let o = self.to_medium.transform_point3(origin);
        let d = self.to_medium.transform_vector3(dir);
        let (mut t0, mut t1) = (0.0f32, t_max);
        for a in 0..3 {
            let inv = 1.0 / d[a];
            let (mut near, mut far) = (
                (self.bounds_min[a] - o[a]) * inv,
                (self.bounds_max[a] - o[a]) * inv,
            );
            if near > far {
                std::mem::swap(&mut near, &mut far);
            }
            // Parallel to a face: NaN when the ray lies in its plane.
            if near.is_nan() || far.is_nan() {
                if o[a] < self.bounds_min[a] || o[a] > self.bounds_max[a] {
                    return None;
                }
                continue;
            }
            t0 = t0.max(near);
            t1 = t1.min(far);
        }
        (t0 < t1).then_some((t0, t1))
    }

    /// Tentative collisions at the rate `m` (the largest σt) along the
    /// ray's stretch in the box, `collide(t, draw)` at each until it
    /// returns false. `Some(t)`: stopped at `t` (or gave up there); `None`:
    /// reached the stretch's end.
    fn track(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        m: f32,
        draw: &mut dyn FnMut() -> f32,
        mut collide: impl FnMut(f32, &mut dyn FnMut() -> f32) -> bool,
    ) -> Option<(f32, bool)> {
        let (t0, t1) = self.inside(origin, dir, t_max)?;
        if m <= 0.0 {
            return None;
        }
        let mut t = t0;
        for _ in 0..MAX_STEPS {
            t -= (1.0 - draw()).ln() / m;
            if t >= t1 {
                return None;
            }
            if !collide(t, &mut *draw) {
                return Some((t, false));
            }
        }
        Some((t, true))
    }

    /// Delta (spectral) tracking along `origin + t dir` over `[0, t_max]`,
    /// with the same real-or-null choice as the grid medium's.
    pub(crate) fn free_flight(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        draw: &mut dyn FnMut() -> f32,
    ) -> FreeFlight {
        let sigma_t = self.sigma_a + self.sigma_s;
        let m = sigma_t.max_element();
        let mut weight = Vec3::ONE;
        let ended = self.track(origin, dir, t_max, m, draw, |t, draw| {
            let rho = self.density_at(origin + dir * t);
            let sigma_s = self.sigma_s * rho;
            let sigma_n = (Vec3::splat(m) - sigma_t * rho).max(Vec3::ZERO);
            null_collision(&mut weight, sigma_s, sigma_n, m, draw)
        });
        match ended {
            None => FreeFlight {
                t: t_max,
                scattered: false,
                weight,
                emitted: Vec3::ZERO,
            },
            Some((t, gave_up)) => FreeFlight {
                t,
                scattered: !gave_up && weight != Vec3::ZERO,
                weight: if gave_up { Vec3::ZERO } else { weight },
                emitted: Vec3::ZERO,
            },
        }
    }

    /// Ratio tracking of the transmittance along `origin + t dir` over
    /// `[0, d]`.
    pub(crate) fn transmittance(
        &self,
        origin: Vec3,
        dir: Vec3,
        d: f32,
        draw: &mut dyn FnMut() -> f32,
    ) -> Vec3 {
        let sigma_t = self.sigma_a + self.sigma_s;
        let m = sigma_t.max_element();
        let mut tr = Vec3::ONE;
        let ended = self.track(origin, dir, d, m, draw, |t, _| {
            tr *= Vec3::ONE - sigma_t * (self.density_at(origin + dir * t) / m);
            tr.max_element() > 0.0
        });
        match ended {
            None => tr,
            Some(_) => Vec3::ZERO,
        }
    }
}

/// `x` clamped to [0, 1], a NaN (from a non-finite point) to 0.
#[inline]
fn unit(x: f32) -> f32 {
    if x > 0.0 {
        x.min(1.0)
    } else {
        0.0
    }
}

/// Ken Perlin's permutation of 0..=255 (the published table of his
/// improved noise), repeated so that sums of two entries index it.
const PERM: [u8; 512] = {
    const P: [u8; 256] = [
        151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30,
        69, 142, 8, 99, 37, 240, 21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94,
        252, 219, 203, 117, 35, 11, 32, 57, 177, 33, 88, 237, 149, 56, 87, 174, 20, 125, 136, 171,
        168, 68, 175, 74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231, 83, 111, 229, 122, 60,
        211, 133, 230, 220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25, 63, 161, 1,
        216, 80, 73, 209, 76, 132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159, 86,
        164, 100, 109, 198, 173, 186, 3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118,
        126, 255, 82, 85, 212, 207, 206, 59, 227, 47, 16, 58, 17, 182, 189, 28, 42, 223, 183, 170,
        213, 119, 248, 152, 2, 44, 154, 163, 70, 221, 153, 101, 155, 167, 43, 172, 9, 129, 22, 39,
        253, 19, 98, 108, 110, 79, 113, 224, 232, 178, 185, 112, 104, 218, 246, 97, 228, 251, 34,
        242, 193, 238, 210, 144, 12, 191, 179, 162, 241, 81, 51, 145, 235, 249, 14, 239, 107, 49,
        192, 214, 31, 181, 199, 106, 157, 184, 84, 204, 176, 115, 121, 50, 45, 127, 4, 150, 254,
        138, 236, 205, 93, 222, 114, 67, 29, 24, 72, 243, 141, 128, 195, 78, 66, 215, 61, 156, 180,
    ];
    let mut t = [0u8; 512];
    let mut i = 0;
    while i < 512 {
        t[i] = P[i % 256];
        i += 1;
    }
    t
};

/// The dot product of the lattice point `(x, y, z)`'s gradient (one of
/// twelve cube-edge directions, chosen by hashing the point) with the
/// offset `(dx, dy, dz)` from it.
#[inline]
fn gradient_dot(x: usize, y: usize, z: usize, dx: f32, dy: f32, dz: f32) -> f32 {
    let h = PERM[PERM[PERM[x] as usize + y] as usize + z] & 15;
    let u = if h < 8 || h == 12 || h == 13 { dx } else { dy };
    let v = if h < 4 || h == 12 || h == 13 { dy } else { dz };
    (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
}

/// Perlin's quintic fade, `6t⁵ - 15t⁴ + 10t³`.
#[inline]
fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// Perlin's improved noise at `p` as pbrt-v4 computes it (its choice of
/// gradient for two of the sixteen hashes differs from Perlin's), in about
/// [-1, 1], zero at the lattice points; periodic with period 256.
pub fn noise(p: Vec3) -> f32 {
    // Wrapped first so that the lattice coordinates fit an i32.
    let wrap = (1u32 << 30) as f32;
    let q = Vec3::new(p.x % wrap, p.y % wrap, p.z % wrap);
    let f = q.floor();
    let d = q - f;
    let cell = |v: f32| (v as i32 & 255) as usize;
    let (x, y, z) = (cell(f.x), cell(f.y), cell(f.z));
    let (wx, wy, wz) = (fade(d.x), fade(d.y), fade(d.z));
    let lerp = |t: f32, a: f32, b: f32| (1.0 - t) * a + t * b;
    let g = |i: usize, j: usize, k: usize| {
        gradient_dot(
            x + i,
            y + j,
            z + k,
            d.x - i as f32,
            d.y - j as f32,
            d.z - k as f32,
        )
    };
    let yz = |j: usize, k: usize| lerp(wx, g(0, j, k), g(1, j, k));
    lerp(
        wz,
        lerp(wy, yz(0, 0), yz(1, 0)),
        lerp(wy, yz(0, 1), yz(1, 1)),
    )
}

/// The noise's gradient at `p` by forward differences of 0.01 (as pbrt
/// estimates it, so the cloud's wisps fall where pbrt's do).
pub fn noise_gradient(p: Vec3) -> Vec3 {
    let h = 0.01f32;
    let n = noise(p);
    (Vec3::new(
        noise(p + Vec3::new(h, 0.0, 0.0)),
        noise(p + Vec3::new(0.0, h, 0.0)),
        noise(p + Vec3::new(0.0, 0.0, h)),
    ) - Vec3::splat(n))
        / h
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Perlin's improved noise written out independently, in f64, after
    /// his reference implementation's structure (hashes of the corners,
    /// then nested interpolation).
    fn noise_ref(x: f64, y: f64, z: f64) -> f64 {
        let p = |i: usize| PERM[i] as usize;
        let (xf, yf, zf) = (x.floor(), y.floor(), z.floor());
        let (xi, yi, zi) = (
            (xf as i64 & 255) as usize,
            (yf as i64 & 255) as usize,
            (zf as i64 & 255) as usize,
        );
        let (x, y, z) = (x - xf, y - yf, z - zf);
        let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
        let (u, v, w) = (fade(x), fade(y), fade(z));
        let grad = |hash: usize, x: f64, y: f64, z: f64| {
            // The twelve edge directions and four repeated, in the order
            // pbrt-v4 picks them (which differs from Perlin's own for
            // hashes 13 and 14).
            let dirs: [[f64; 3]; 16] = [
                [1., 1., 0.],
                [-1., 1., 0.],
                [1., -1., 0.],
                [-1., -1., 0.],
                [1., 0., 1.],
                [-1., 0., 1.],
                [1., 0., -1.],
                [-1., 0., -1.],
                [0., 1., 1.],
                [0., -1., 1.],
                [0., 1., -1.],
                [0., -1., -1.],
                [1., 1., 0.],
                [-1., 1., 0.],
                [0., 1., -1.],
                [0., -1., -1.],
            ];
            let g = dirs[hash & 15];
            g[0] * x + g[1] * y + g[2] * z
        };
        let a = p(xi) + yi;
        let (aa, ab) = (p(a) + zi, p(a + 1) + zi);
        let b = p(xi + 1) + yi;
        let (ba, bb) = (p(b) + zi, p(b + 1) + zi);
        let lerp = |t: f64, a: f64, b: f64| a + t * (b - a);
        lerp(
            w,
            lerp(
                v,
                lerp(u, grad(p(aa), x, y, z), grad(p(ba), x - 1., y, z)),
                lerp(u, grad(p(ab), x, y - 1., z), grad(p(bb), x - 1., y - 1., z)),
            ),
            lerp(
                v,
                lerp(
                    u,
                    grad(p(aa + 1), x, y, z - 1.),
                    grad(p(ba + 1), x - 1., y, z - 1.),
                ),
                lerp(
                    u,
                    grad(p(ab + 1), x, y - 1., z - 1.),
                    grad(p(bb + 1), x - 1., y - 1., z - 1.),
                ),
            ),
        )
    }

    /// pbrt-v4's cloud density written out again in f64 from its
    /// definition.
    fn density_ref(c: &CloudMedium, p: [f64; 3]) -> f64 {
        let n = |q: [f64; 3]| noise_ref(q[0], q[1], q[2]);
        let f = c.frequency as f64;
        let mut q = [p[0] * f, p[1] * f, p[2] * f];
        if c.wispiness > 0.0 {
            let mut amp = 0.05 * c.wispiness as f64;
            let mut freq = 10.0f64;
            for _ in 0..2 {
                let s = [q[0] * freq, q[1] * freq, q[2] * freq];
                let n0 = n(s);
                let dn = [
                    (n([s[0] + 0.01, s[1], s[2]]) - n0) / 0.01,
                    (n([s[0], s[1] + 0.01, s[2]]) - n0) / 0.01,
                    (n([s[0], s[1], s[2] + 0.01]) - n0) / 0.01,
                ];
                for a in 0..3 {
                    q[a] += amp * dn[a];
                }
                amp /= 2.0;
                freq *= 1.99;
            }
        }
        let mut sum = 0.0;
        for i in 0..5 {
            let l = 1.99f64.powi(i);
            sum += 0.5f64.powi(i + 1) * n([q[0] * l, q[1] * l, q[2] * l]);
        }
        let d = ((1.0 - p[1]) * 4.5 * c.density as f64 * sum).clamp(0.0, 1.0);
        (d + 2.0 * (0.5 - p[1]).max(0.0)).clamp(0.0, 1.0)
    }

    fn cloud(wispiness: f32) -> CloudMedium {
        CloudMedium::new(
            Vec3::new(0.2, 0.5, 1.0),
            Vec3::new(4.0, 3.0, 2.0),
            HenyeyGreenstein::new(0.3),
            1.0,
            wispiness,
            5.0,
            (Vec3::ZERO, Vec3::ONE),
            Affine3A::from_scale_rotation_translation(
                Vec3::new(2.0, 1.5, 2.0),
                glam::Quat::from_rotation_y(0.3),
                Vec3::new(-1.0, 0.0, -1.0),
            ),
        )
    }

    fn xorshift(seed: u32) -> impl FnMut() -> f32 {
        let mut state = seed;
        move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            (state >> 8) as f32 / (1u32 << 24) as f32
        }
    }

    #[test]
    fn noise_matches_perlins_reference() {
        let mut r = xorshift(7);
        for _ in 0..2000 {
            let p = Vec3::new(r(), r(), r()) * 40.0 - 20.0;
            let want = noise_ref(p.x as f64, p.y as f64, p.z as f64);
            let got = noise(p);
            assert!((got as f64 - want).abs() < 1e-5, "{p} {got} {want}");
        }
        // Zero on the lattice, a hand-checkable value.
        assert_eq!(noise(Vec3::new(3.0, -7.0, 12.0)), 0.0);
    }

    /// The density stays in [0, 1] and equals the formula evaluated again
    /// in f64; it is 1 at the bottom (y <= 0) and 0 at the top (y = 1) by
    /// the height terms alone.
    #[test]
    fn density_follows_the_formula_within_0_1() {
        for wisp in [0.0, 1.0, 3.0] {
            let c = cloud(wisp);
            let mut r = xorshift(11);
            let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
            let mut worst = 0.0f64;
            for _ in 0..5000 {
                let p = Vec3::new(r(), r() * 1.4 - 0.2, r());
                let got = c.density_in_medium(p);
                assert!((0.0..=1.0).contains(&got), "{p} {got}");
                lo = lo.min(got);
                hi = hi.max(got);
                let want = density_ref(&c, [p.x as f64, p.y as f64, p.z as f64]);
                worst = worst.max((got as f64 - want).abs());
            }
            // The wisps' forward differences over 0.01 lose digits in f32
            // (pbrt's precision), which the octaves above amplify.
            let tolerance = 1e-5 + 1e-3 * wisp as f64;
            assert!(worst < tolerance, "wispiness {wisp}: {worst}");
            eprintln!("wispiness {wisp}: largest difference from f64 {worst:.2e}");
            // The noise reaches both clamps.
            assert!(lo == 0.0 && hi == 1.0, "{lo} {hi}");
            assert_eq!(c.density_in_medium(Vec3::new(0.3, 0.0, 0.7)), 1.0);
            assert_eq!(c.density_in_medium(Vec3::new(0.3, -0.5, 0.7)), 1.0);
            assert_eq!(c.density_in_medium(Vec3::new(0.3, 1.0, 0.7)), 0.0);
        }
        assert_eq!(cloud(1.0).density_in_medium(Vec3::splat(f32::NAN)), 0.0);
    }

    /// The transmittance along the ray by numerical integration of the
    /// density, in f64 steps of a thousandth of the segment or less.
    fn transmittance_exact(c: &CloudMedium, o: Vec3, d: Vec3, len: f32) -> Vec3 {
        let n = 100_000;
        let h = len as f64 / n as f64;
        let tau: f64 = (0..n)
            .map(|i| c.density_at(o + d * ((i as f64 + 0.5) * h) as f32) as f64 * h)
            .sum();
        let sigma_t = c.sigma_a + c.sigma_s;
        Vec3::from_array(sigma_t.to_array().map(|s| (-(s as f64) * tau).exp() as f32))
    }

    /// Ratio tracking's mean and delta tracking's passing weight equal the
    /// transmittance integrated numerically, along rays through, into and
    /// along the cloud.
    #[test]
    fn tracking_is_unbiased() {
        let c = cloud(1.0);
        let mut draw = xorshift(0x1234_5678);
        for (o, d, len) in [
            (Vec3::new(-3.0, 0.6, 0.0), Vec3::X, 6.0),
            (
                Vec3::new(0.0, 1.4, 0.0),
                Vec3::new(0.3, -1.0, 0.2).normalize(),
                1.0,
            ),
            (
                Vec3::new(0.0, 1.0, -3.0),
                Vec3::new(0.1, 0.0, 1.0).normalize(),
                5.0,
            ),
        ] {
            let want = transmittance_exact(&c, o, d, len);
            assert!(
                want.min_element() > 0.02 && want.max_element() < 0.98,
                "{want}"
            );
            let n = 40_000;
            let mut sum = Vec3::ZERO;
            for _ in 0..n {
                sum += c.transmittance(o, d, len, &mut draw);
            }
            let got = sum / n as f32;
            assert!((got - want).abs().max_element() < 0.01, "{got} {want}");
            let mut pass = Vec3::ZERO;
            for _ in 0..n {
                let f = c.free_flight(o, d, len, &mut draw);
                assert!(f.weight.is_finite());
                if !f.scattered {
                    assert_eq!(f.t, len);
                    pass += f.weight;
                } else {
                    assert!(f.t < len && c.density_at(o + d * f.t) > 0.0);
                }
            }
            let got = pass / n as f32;
            assert!((got - want).abs().max_element() < 0.015, "{got} {want}");
        }
    }
}
