//! Fresnel reflectance and Snell refraction.

use glam::Vec3;

/// Unpolarised Fresnel reflectance of a dielectric boundary for light
/// arriving at `cos_i >= 0` from the side of index `n_i`, with
/// `eta = n_t / n_i`; 1 under total internal reflection.
#[inline]
pub fn dielectric(cos_i: f32, eta: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// Schlick's approximation with normal-incidence reflectance `f0`.
#[inline]
pub fn schlick(f0: Vec3, cos: f32) -> Vec3 {
    let m = (1.0 - cos.clamp(0.0, 1.0)).powi(5);
    f0 + (Vec3::ONE - f0) * m
}

/// The refraction of `w` (pointing away from the surface, on the side `n`
/// points to) into the other side, `eta = n_t / n_i`; `None` under total
/// internal reflection.
#[inline]
pub fn refract(w: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = n.dot(w);
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some(-w / eta + (cos_i / eta - cos_t) * n)
}

/// Mirror reflection of `w` about `n`.
#[inline]
pub fn reflect(w: Vec3, n: Vec3) -> Vec3 {
    2.0 * w.dot(n) * n - w
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_and_snell() {
        // ((n - 1) / (n + 1))^2 = 0.04 for n = 1.5.
        assert!((dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
        assert_eq!(dielectric(0.1, 1.0 / 1.5), 1.0);
        let w = Vec3::new(0.6, 0.0, 0.8);
        let t = refract(w, Vec3::Z, 1.5).unwrap();
        assert!((t.length() - 1.0).abs() < 1e-5);
        // n_i sin_i = n_t sin_t.
        assert!((0.6 - 1.5 * t.x.abs()).abs() < 1e-5 && t.z < 0.0);
    }
}
