//! One ray's result in the protocol's hit-file form: `f32 t, u32 triangle`.

use sahara_kd::Hit;

/// The result of tracing one ray, as a hit file stores it.
///
/// A closest hit is `(t, triangle)`; a miss is `(+inf, 0xFFFFFFFF)`; an
/// occluded `shadow` ray is `(0, 0xFFFFFFFE)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HitRecord {
    /// Distance of the hit (`+inf` for a miss, 0 for an occlusion).
    pub t: f32,
    /// Triangle index, or [`HitRecord::MISS_TRI`] / [`HitRecord::OCCLUDED_TRI`].
    pub tri: u32,
}

impl HitRecord {
    /// Triangle field of a miss.
    pub const MISS_TRI: u32 = 0xFFFF_FFFF;
    /// Triangle field of an occluded any-hit ray.
    pub const OCCLUDED_TRI: u32 = 0xFFFF_FFFE;
    /// The record of a ray that hit nothing.
    pub const MISS: HitRecord = HitRecord {
        t: f32::INFINITY,
        tri: Self::MISS_TRI,
    };
    /// The record of an occluded any-hit ray.
    pub const OCCLUDED: HitRecord = HitRecord {
        t: 0.0,
        tri: Self::OCCLUDED_TRI,
    };

    /// The record of a closest-hit query.
    #[inline]
    pub fn from_closest(hit: Option<Hit>) -> Self {
        match hit {
            Some(h) => HitRecord { t: h.t, tri: h.tri },
            None => Self::MISS,
        }
    }

    /// The record of an any-hit query.
    #[inline]
    pub fn from_occluded(occluded: bool) -> Self {
        if occluded {
            Self::OCCLUDED
        } else {
            Self::MISS
        }
    }

    /// True unless this is a miss (occlusions count as hits).
    #[inline]
    pub fn is_hit(&self) -> bool {
        self.tri != Self::MISS_TRI
    }

    /// True for a closest hit on a triangle (not a miss, not an occlusion).
    #[inline]
    pub fn is_triangle_hit(&self) -> bool {
        self.tri != Self::MISS_TRI && self.tri != Self::OCCLUDED_TRI
    }
}

/// Hit count and t-sum of a set: hits are records that are not misses; the
/// t-sum adds the `t` of triangle hits as f64, in ray order (deterministic).
pub fn checksum(records: &[HitRecord]) -> (u64, f64) {
    let mut hits = 0u64;
    let mut t_sum = 0.0f64;
    for r in records {
        if r.is_hit() {
            hits += 1;
            if r.is_triangle_hit() {
                t_sum += r.t as f64;
            }
        }
    }
    (hits, t_sum)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_and_checksum() {
        let recs = [
            HitRecord::from_closest(Some(Hit {
                t: 1.5,
                tri: 3,
                u: 0.0,
                v: 0.0,
            })),
            HitRecord::from_closest(None),
            HitRecord::from_occluded(true),
            HitRecord::from_occluded(false),
            HitRecord { t: 2.25, tri: 0 },
        ];
        assert_eq!(recs[0], HitRecord { t: 1.5, tri: 3 });
        assert_eq!(recs[1].tri, 0xFFFF_FFFF);
        assert_eq!(recs[1].t, f32::INFINITY);
        assert_eq!(
            recs[2],
            HitRecord {
                t: 0.0,
                tri: 0xFFFF_FFFE
            }
        );
        assert_eq!(recs[3], HitRecord::MISS);
        assert_eq!(checksum(&recs), (3, 3.75));
        assert_eq!(checksum(&[]), (0, 0.0));
    }
}
