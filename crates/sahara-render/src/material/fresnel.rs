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

/// Schlick's form with reflectance `f0` at normal incidence and `f90` at
/// grazing incidence (`KHR_materials_specular` scales the latter).
#[inline]
pub fn schlick_f90(f0: Vec3, f90: Vec3, cos: f32) -> Vec3 {
    let m = (1.0 - cos.clamp(0.0, 1.0)).powi(5);
    f0 + (f90 - f0) * m
}

/// Exact unpolarised Fresnel reflectance of a conductor of complex index
/// `eta + i k` (per channel, relative to the outside medium) for light
/// arriving at `cos_i` (clamped to `[0, 1]`).
///
/// With `a^2 + b^2 = sqrt((eta^2 - k^2 - sin^2)^2 + 4 eta^2 k^2)` and
/// `a^2 = (that + eta^2 - k^2 - sin^2) / 2`, the s and p reflectances are
/// `Rs = (a^2 + b^2 - 2a cos + cos^2) / (a^2 + b^2 + 2a cos + cos^2)` and
/// `Rp = Rs (cos^2 (a^2 + b^2) - 2a cos sin^2 + sin^4) /
/// (cos^2 (a^2 + b^2) + 2a cos sin^2 + sin^4)`.
#[inline]
pub fn conductor(cos_i: f32, eta: Vec3, k: Vec3) -> Vec3 {
    let c = cos_i.clamp(0.0, 1.0);
    let c2 = c * c;
    let s2 = 1.0 - c2;
    let t0 = eta * eta - k * k - Vec3::splat(s2);
    let a2b2 = (t0 * t0 + 4.0 * eta * eta * k * k)
        .max(Vec3::ZERO)
        .powf(0.5);
    let a = (0.5 * (a2b2 + t0)).max(Vec3::ZERO).powf(0.5);
    let t1 = a2b2 + Vec3::splat(c2);
    let t2 = 2.0 * c * a;
    let rs = (t1 - t2) / (t1 + t2).max(Vec3::splat(1e-30));
    let t3 = c2 * a2b2 + Vec3::splat(s2 * s2);
    let t4 = t2 * s2;
    let rp = rs * (t3 - t4) / (t3 + t4).max(Vec3::splat(1e-30));
    (0.5 * (rs + rp)).clamp(Vec3::ZERO, Vec3::ONE)
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

    #[test]
    fn conductor_fresnel_limits() {
        let (eta, k) = (Vec3::new(0.2, 1.0, 1.4), Vec3::new(3.6, 2.6, 1.9));
        // Normal incidence: ((n - 1)^2 + k^2) / ((n + 1)^2 + k^2).
        let f0 = conductor(1.0, eta, k);
        let want = ((eta - 1.0) * (eta - 1.0) + k * k) / ((eta + 1.0) * (eta + 1.0) + k * k);
        assert!((f0 - want).abs().max_element() < 1e-5, "{f0} vs {want}");
        // Grazing incidence reflects everything.
        assert!((conductor(0.0, eta, k) - Vec3::ONE).abs().max_element() < 1e-5);
        // Without absorption it is the dielectric formula.
        for c in [0.1f32, 0.5, 0.9] {
            let d = dielectric(c, 1.5);
            let m = conductor(c, Vec3::splat(1.5), Vec3::ZERO);
            assert!((m.x - d).abs() < 1e-5, "cos {c}: {} vs {d}", m.x);
        }
    }
}
