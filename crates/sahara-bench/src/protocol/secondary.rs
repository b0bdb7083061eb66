//! The `shadow` and `diffuse` sets, generated from a tracer's primary hits.

use glam::Vec3;
use sahara_kd::Mesh;
use sahara_kd::Ray;

use super::arith::{add, cross, dot, len, mul, normalize, sub};
use super::frame::{check_mesh, SceneFrame};
use super::splitmix::SplitMix64;
use super::ProtocolError;
use crate::record::HitRecord;

/// The secondary sets: one `shadow` and one `diffuse` ray per primary hit,
/// in increasing pixel order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SecondaryRays {
    /// Occlusion rays towards the point light.
    pub shadow: Vec<Ray>,
    /// Cosine-weighted rays about the normal.
    pub diffuse: Vec<Ray>,
    /// `pixels[k]` is the pixel index `y * W + x` of the primary ray that
    /// `shadow[k]` and `diffuse[k]` continue.
    pub pixels: Vec<u32>,
}

/// The orthonormal frame `(T, B)` about the unit normal `n` (Duff et al.
/// 2017, "Building an Orthonormal Basis, Revisited"), in the reference's
/// f32 order; `copysign` follows the sign bit, so `n.z = -0.0` gives -1.
pub fn duff_basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let t = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let bb = Vec3::new(b, sign + n.y * n.y * a, -n.y);
    (t, bb)
}

/// The cosine-weighted direction about `n` drawn from `rng` (two draws).
pub fn cosine_direction(n: Vec3, rng: &mut SplitMix64) -> Vec3 {
    let u1 = rng.next_f32();
    let u2 = rng.next_f32();
    let phi = 2.0 * std::f32::consts::PI * u1;
    let r = u2.sqrt();
    let lx = r * phi.cos();
    let ly = r * phi.sin();
    let lz = (1.0 - u2).sqrt();
    let (t, b) = duff_basis(n);
    normalize(add(add(mul(t, lx), mul(b, ly)), mul(n, lz)))
}

/// The secondary sets from the primary rays and a tracer's hits on them
/// (`hits[i]` answers `primary[i]`, the pixel index being `i`).
///
/// For a hit at `p = o + t d` on a triangle with geometric normal
/// `n = normalize(cross(v1 - v0, v2 - v0))`, turned to face the ray, both
/// rays start at `p + eps n`; the shadow ray goes towards
/// [`SceneFrame::light`] with `tmax = 0.999 |L - origin|`, the diffuse ray in
/// a cosine-weighted direction seeded by the pixel index.
pub fn secondary_rays(
    mesh: &Mesh,
    frame: &SceneFrame,
    primary: &[Ray],
    hits: &[HitRecord],
) -> Result<SecondaryRays, ProtocolError> {
    check_mesh(mesh)?;
    if primary.len() != hits.len() {
        return Err(ProtocolError::LengthMismatch {
            rays: primary.len(),
            hits: hits.len(),
        });
    }
    let light = frame.light();
    let n_hits = hits.iter().filter(|h| h.is_hit()).count();
    let mut out = SecondaryRays {
        shadow: Vec::with_capacity(n_hits),
        diffuse: Vec::with_capacity(n_hits),
        pixels: Vec::with_capacity(n_hits),
    };
    for (i, (ray, hit)) in primary.iter().zip(hits).enumerate() {
        if !hit.is_hit() {
            continue;
        }
        let Some(tri) = mesh.indices.get(hit.tri as usize) else {
            return Err(ProtocolError::BadHit {
                ray: i,
                triangle: hit.tri,
                triangles: mesh.indices.len(),
            });
        };
        let [v0, v1, v2] = tri.map(|v| mesh.positions[v as usize]);
        let d = ray.dir;
        let p = add(ray.origin, mul(d, hit.t));
        let mut n = normalize(cross(sub(v1, v0), sub(v2, v0)));
        if dot(n, d) > 0.0 {
            n = mul(n, -1.0);
        }
        let origin = add(p, mul(n, frame.eps));

        let to_light = sub(light, origin);
        let dist = len(to_light);
        out.shadow.push(Ray::with_interval(
            origin,
            normalize(to_light),
            0.0,
            0.999 * dist,
        ));

        let mut rng = SplitMix64::new(i as u64);
        out.diffuse.push(Ray::with_interval(
            origin,
            cosine_direction(n, &mut rng),
            0.0,
            f32::INFINITY,
        ));
        out.pixels.push(i as u32);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A floor quad at y = 0 over [-1, 1]^2, wound so its normal is -y
    /// (facing away from a camera above it), and rays straight down.
    fn floor() -> (Mesh, SceneFrame) {
        let mesh = Mesh {
            positions: vec![
                Vec3::new(-1.0, 0.0, -1.0),
                Vec3::new(1.0, 0.0, -1.0),
                Vec3::new(1.0, 0.0, 1.0),
                Vec3::new(-1.0, 0.0, 1.0),
            ],
            indices: vec![[0, 1, 2], [0, 2, 3]],
        };
        let frame = SceneFrame::from_mesh(&mesh).unwrap();
        (mesh, frame)
    }

    #[test]
    fn duff_basis_is_orthonormal_for_both_hemispheres() {
        for n in [
            Vec3::Z,
            Vec3::NEG_Z,
            Vec3::X,
            Vec3::new(0.3, -0.4, 0.5).normalize(),
            Vec3::new(-0.6, 0.0, -0.8),
            Vec3::new(0.0, 1.0, -0.0),
        ] {
            let (t, b) = duff_basis(n);
            for (p, q) in [(t, b), (t, n), (b, n)] {
                assert!(p.dot(q).abs() < 1e-6, "{n}: {p} . {q}");
            }
            assert!((t.length() - 1.0).abs() < 1e-6 && (b.length() - 1.0).abs() < 1e-6);
            // Right-handed: T x B = n.
            assert!((t.cross(b) - n).length() < 1e-6, "{n}");
        }
        // n = +z: T = x, B = y. n = -z: T = x, B = -y.
        assert_eq!(duff_basis(Vec3::Z), (Vec3::X, Vec3::Y));
        let (t, b) = duff_basis(Vec3::NEG_Z);
        assert_eq!(
            (t.x, t.y, t.z, b.x, b.y, b.z),
            (1.0, 0.0, 0.0, 0.0, -1.0, 0.0)
        );
        // -0.0 counts as negative (T.z = -sign n.x tells the branches apart).
        let (t, _) = duff_basis(Vec3::new(0.6, 0.8, -0.0));
        assert_eq!(t.z, 0.6);
        let (t, _) = duff_basis(Vec3::new(0.6, 0.8, 0.0));
        assert_eq!(t.z, -0.6);
    }

    #[test]
    fn cosine_direction_for_plus_z_is_the_local_sample() {
        // With n = +z the frame is the identity, so the direction is
        // (sqrt(u2) cos 2 pi u1, sqrt(u2) sin 2 pi u1, sqrt(1 - u2)), checked in f64.
        for seed in [0u64, 1, 99, 123_456] {
            let mut g = SplitMix64::new(seed);
            let (u1, u2) = (g.next_f32() as f64, g.next_f32() as f64);
            let want = Vec3::new(
                (u2.sqrt() * (2.0 * std::f64::consts::PI * u1).cos()) as f32,
                (u2.sqrt() * (2.0 * std::f64::consts::PI * u1).sin()) as f32,
                (1.0 - u2).sqrt() as f32,
            );
            let got = cosine_direction(Vec3::Z, &mut SplitMix64::new(seed));
            assert!((got - want).length() < 1e-6, "{got} vs {want}");
        }
    }

    #[test]
    fn secondary_rays_follow_the_primary_hits() {
        let (mesh, frame) = floor();
        // Four primary rays from above, straight down; rays 1 and 3 miss.
        let o = [
            Vec3::new(0.25, 2.0, 0.5),
            Vec3::new(5.0, 2.0, 0.0),
            Vec3::new(-0.5, 2.0, -0.5),
            Vec3::new(0.0, 2.0, 9.0),
        ];
        let primary: Vec<Ray> = o.iter().map(|&p| Ray::new(p, Vec3::NEG_Y)).collect();
        let hits = [
            HitRecord { t: 2.0, tri: 1 },
            HitRecord::MISS,
            HitRecord { t: 2.0, tri: 0 },
            HitRecord::MISS,
        ];
        let s = secondary_rays(&mesh, &frame, &primary, &hits).unwrap();
        assert_eq!(s.pixels, vec![0, 2]);
        assert_eq!((s.shadow.len(), s.diffuse.len()), (2, 2));
        // The mesh normal is -y; it is turned to face the downward ray: +y.
        let light = frame.light();
        for (k, &pix) in s.pixels.iter().enumerate() {
            let p = o[pix as usize] - Vec3::new(0.0, 2.0, 0.0);
            let want_origin = p + Vec3::new(0.0, frame.eps, 0.0);
            let sh = s.shadow[k];
            assert_eq!(sh.origin, want_origin);
            assert_eq!(s.diffuse[k].origin, want_origin);
            assert!(((light - want_origin).normalize() - sh.dir).length() < 1e-6);
            assert!(((light - want_origin).length() * 0.999 - sh.tmax).abs() < 1e-5);
            assert_eq!(sh.tmin, 0.0);
            let d = s.diffuse[k];
            assert!(d.dir.y > 0.0 && (d.dir.length() - 1.0).abs() < 1e-6);
            assert_eq!(d.tmax, f32::INFINITY);
            // Seeded by the pixel index, about the turned normal +y.
            let want = cosine_direction(Vec3::Y, &mut SplitMix64::new(pix as u64));
            assert_eq!(d.dir, want);
        }
    }

    #[test]
    fn mismatched_or_foreign_hits_are_errors() {
        let (mesh, frame) = floor();
        let primary = vec![Ray::new(Vec3::Y, Vec3::NEG_Y)];
        assert!(matches!(
            secondary_rays(&mesh, &frame, &primary, &[]),
            Err(ProtocolError::LengthMismatch { rays: 1, hits: 0 })
        ));
        assert!(matches!(
            secondary_rays(&mesh, &frame, &primary, &[HitRecord { t: 1.0, tri: 7 }]),
            Err(ProtocolError::BadHit { triangle: 7, .. })
        ));
        assert!(matches!(
            secondary_rays(&mesh, &frame, &primary, &[HitRecord::OCCLUDED]),
            Err(ProtocolError::BadHit { .. })
        ));
    }
}
