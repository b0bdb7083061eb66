//! One triangle accelerator of either structure, chosen at build time:
//! the kd-tree or the eight-wide hierarchy, behind the queries both
//! answer. Callers that trace (the renderer, the benchmark, the Python
//! package) hold this, so the structure is a setting, not a type.

use crate::build::BuildParams;
use crate::bvh::{Bvh, BvhBuilder, BvhParams};
use crate::isect::Hit;
use crate::kd::{Counters, KdTree};
use crate::math::{Aabb, Ray, Triangle};
use crate::simd::Isa;

/// Which structure an accelerator is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum AccelKind {
    /// The SAH kd-tree.
    Kd,
    /// The eight-wide bounding volume hierarchy, the default (which
    /// structure is faster where: `docs/accelerator.md`).
    #[default]
    Bvh,
}

impl AccelKind {
    /// The name `--accel` takes: `kd` or `bvh`.
    pub fn name(&self) -> &'static str {
        match self {
            AccelKind::Kd => "kd",
            AccelKind::Bvh => "bvh",
        }
    }

    /// The kind named `s`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "kd" => Some(AccelKind::Kd),
            "bvh" => Some(AccelKind::Bvh),
            _ => None,
        }
    }
}

/// How to build an accelerator.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AccelParams {
    /// The structure.
    pub kind: AccelKind,
    /// The kd-tree's parameters (for [`AccelKind::Kd`]).
    pub kd: BuildParams,
    /// The hierarchy's parameters (for [`AccelKind::Bvh`]).
    pub bvh: BvhParams,
    /// The widest instructions its queries may use (the default: the
    /// best the CPU has; see [`Isa`]).
    pub isa: Isa,
}

impl AccelParams {
    /// Parameters for a kd-tree built with `kd`.
    pub fn kd(kd: BuildParams) -> Self {
        Self {
            kind: AccelKind::Kd,
            kd,
            ..Self::default()
        }
    }

    /// Parameters from names, as the command line and the Python package
    /// take them: the structure `accel` (`bvh` or `kd`) and, optionally, a
    /// builder of that structure (`spatial`, `binned` or `kd` for the
    /// hierarchy; `sah`, `binned`, `binnedN`, ... for the kd-tree). The
    /// error names the argument at fault.
    pub fn from_names(accel: &str, builder: Option<&str>) -> Result<Self, String> {
        let kind = AccelKind::parse(accel)
            .ok_or_else(|| format!("accel: unknown structure '{accel}' (expected bvh or kd)"))?;
        let Some(b) = builder else {
            return Ok(Self {
                kind,
                ..Self::default()
            });
        };
        match kind {
            AccelKind::Bvh => BvhBuilder::parse(b).map(Self::bvh).ok_or_else(|| {
                format!("builder: unknown builder '{b}' (expected spatial, binned or kd for accel 'bvh')")
            }),
            AccelKind::Kd => crate::Builder::parse(b)
                .map(|b| Self::kd(BuildParams::new(b)))
                .ok_or_else(|| {
                    format!(
                        "builder: unknown builder '{b}' (expected sah, binned, binnedN with N in \
                         2..=1024, rr-middle, rr-median, largest-middle, largest-median for accel 'kd')"
                    )
                }),
        }
    }

    /// The builder's name, as `from_names` takes it.
    pub fn builder_name(&self) -> String {
        match self.kind {
            AccelKind::Bvh => self.bvh.builder.name().to_owned(),
            AccelKind::Kd => self.kd.builder.name(),
        }
    }

    /// Parameters for a hierarchy built by `builder`.
    pub fn bvh(builder: BvhBuilder) -> Self {
        Self {
            kind: AccelKind::Bvh,
            bvh: BvhParams::new(builder),
            ..Self::default()
        }
    }
}

/// What both structures report of themselves (their own statistics,
/// [`crate::TreeStats`] and [`crate::BvhStats`], say more).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AccelSummary {
    /// The structure and its builder, as `kd-tree (sah)` or `bvh8 (spatial)`.
    pub structure: String,
    /// Triangles given to the build.
    pub triangles: usize,
    /// Bytes of nodes, leaf data and indices.
    pub memory_bytes: usize,
    /// The SAH cost in the structure's own units (not comparable between
    /// structures: see their statistics).
    pub sah_cost: f64,
    /// Depth of the deepest leaf.
    pub depth: u32,
    /// Leaves.
    pub leaves: usize,
    /// Triangle references in leaves.
    pub references: usize,
    /// Inner nodes (wide nodes for the hierarchy) the SAH expects a ray
    /// meeting the root to visit.
    pub expected_inner: f64,
    /// Leaves the SAH expects such a ray to visit.
    pub expected_leaves: f64,
    /// Triangle tests the SAH expects.
    pub expected_triangles: f64,
}

/// A triangle accelerator: a kd-tree or an eight-wide hierarchy.
#[derive(Clone, Debug)]
pub enum TriangleAccel {
    /// A kd-tree.
    Kd(KdTree),
    /// An eight-wide hierarchy.
    Bvh(Bvh),
}

/// The same call on whichever structure `self` is.
macro_rules! each {
    ($self:ident, $t:ident => $e:expr) => {
        match $self {
            TriangleAccel::Kd($t) => $e,
            TriangleAccel::Bvh($t) => $e,
        }
    };
}

impl TriangleAccel {
    /// Build the structure `params.kind` over `triangles` (those no ray
    /// can hit are left out; hit indices are positions in `triangles`).
    pub fn build(triangles: Vec<Triangle>, params: &AccelParams) -> Self {
        let mut a = match params.kind {
            AccelKind::Kd => TriangleAccel::Kd(KdTree::build(triangles, &params.kd)),
            AccelKind::Bvh => TriangleAccel::Bvh(Bvh::build(triangles, &params.bvh)),
        };
        a.set_isa(params.isa);
        a
    }

    /// Hold its queries to the instructions of `isa` at most (see
    /// [`Isa`]); answers do not change.
    pub fn set_isa(&mut self, isa: Isa) {
        each!(self, t => t.set_isa(isa))
    }

    /// The widest instructions its queries may use.
    pub fn isa(&self) -> Isa {
        each!(self, t => t.isa())
    }

    /// Which structure this is.
    pub fn kind(&self) -> AccelKind {
        match self {
            TriangleAccel::Kd(_) => AccelKind::Kd,
            TriangleAccel::Bvh(_) => AccelKind::Bvh,
        }
    }

    /// The bounds of the hittable triangles.
    pub fn bounds(&self) -> Aabb {
        each!(self, t => t.bounds())
    }

    /// Number of triangles given to the build.
    pub fn primitive_count(&self) -> usize {
        each!(self, t => t.primitive_count())
    }

    /// Bytes of the structure (nodes, leaf data and indices).
    pub fn memory_bytes(&self) -> usize {
        self.summary().memory_bytes
    }

    /// The figures both structures have (one pass over the nodes).
    pub fn summary(&self) -> AccelSummary {
        match self {
            TriangleAccel::Kd(t) => {
                let s = t.stats();
                AccelSummary {
                    structure: format!("kd-tree ({})", t.params().builder.name()),
                    triangles: s.triangles,
                    memory_bytes: s.memory_bytes,
                    sah_cost: s.sah_cost,
                    depth: s.max_depth,
                    leaves: s.leaves,
                    references: s.references,
                    expected_inner: s.expected_inner,
                    expected_leaves: s.expected_leaves,
                    expected_triangles: s.expected_triangles,
                }
            }
            TriangleAccel::Bvh(b) => {
                let s = b.stats();
                AccelSummary {
                    structure: format!("bvh8 ({})", b.params().builder.name()),
                    triangles: s.triangles,
                    memory_bytes: s.memory_bytes,
                    sah_cost: s.sah_cost,
                    depth: s.max_depth,
                    leaves: s.leaves,
                    references: s.references,
                    expected_inner: s.expected_nodes,
                    expected_leaves: s.expected_leaves,
                    expected_triangles: s.expected_triangles,
                }
            }
        }
    }

    /// The closest hit with `t` in `(ray.tmin, ray.tmax]` (ties: the
    /// smallest triangle index).
    #[inline]
    pub fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        each!(self, t => t.closest_hit(ray))
    }

    /// [`TriangleAccel::closest_hit`], counting the work done.
    pub fn closest_hit_counted<C: Counters>(&self, ray: &Ray, counters: &mut C) -> Option<Hit> {
        each!(self, t => t.closest_hit_counted(ray, counters))
    }

    /// True if any triangle is hit with `t` in `(ray.tmin, ray.tmax]`.
    #[inline]
    pub fn any_hit(&self, ray: &Ray) -> bool {
        each!(self, t => t.any_hit(ray))
    }

    /// [`TriangleAccel::any_hit`], counting the work done.
    pub fn any_hit_counted<C: Counters>(&self, ray: &Ray, counters: &mut C) -> bool {
        each!(self, t => t.any_hit_counted(ray, counters))
    }

    /// Every hit along the ray, ordered by `t` then triangle index.
    pub fn all_hits(&self, ray: &Ray, hits: &mut Vec<Hit>) {
        each!(self, t => t.all_hits(ray, hits))
    }

    /// Closest hits of many rays, in parallel.
    pub fn closest_hits(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        each!(self, t => t.closest_hits(rays, out))
    }

    /// Occlusion of many rays, in parallel.
    pub fn any_hits(&self, rays: &[Ray], out: &mut [bool]) {
        each!(self, t => t.any_hits(rays, out))
    }

    /// Closest hits of many rays on the calling thread.
    pub fn closest_hits_serial(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        each!(self, t => t.closest_hits_serial(rays, out))
    }

    /// Occlusion of many rays on the calling thread.
    pub fn any_hits_serial(&self, rays: &[Ray], out: &mut [bool]) {
        each!(self, t => t.any_hits_serial(rays, out))
    }

    /// Closest hits of up to 8 coherent rays (a camera tile) traced as one
    /// packet by either structure's packet walk ([`KdTree::closest_hit_packet`],
    /// [`Bvh::closest_hit_packet`]); the same answers as
    /// [`TriangleAccel::closest_hit`], bit for bit. On the hierarchy, camera
    /// tiles trace about twice as fast as packets as ray by ray
    /// (`docs/performance.md`).
    pub fn closest_hit_packet(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        each!(self, t => t.closest_hit_packet(rays, out))
    }

    /// Closest hits of up to 16 coherent rays (a 4x4 camera tile) traced as
    /// one packet, as [`TriangleAccel::closest_hit_packet`].
    pub fn closest_hit_packet16(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        each!(self, t => t.closest_hit_packet16(rays, out))
    }

    /// Whether each of up to 16 rays hits anything: on the hierarchy one
    /// packet ([`Bvh::any_hit_packet16`]), on the kd-tree ray by ray; the
    /// same answers as [`TriangleAccel::any_hit`].
    pub fn any_hit_packet16(&self, rays: &[Ray], out: &mut [bool]) {
        assert_eq!(rays.len(), out.len(), "one output slot per ray");
        match self {
            TriangleAccel::Kd(t) => {
                for (r, o) in rays.iter().zip(out.iter_mut()) {
                    *o = t.any_hit(r);
                }
            }
            TriangleAccel::Bvh(t) => t.any_hit_packet16(rays, out),
        }
    }
}
