//! Path guiding after Müller, Gross & Novák, "Practical Path Guiding for
//! Efficient Light-Transport Simulation" (EGSR 2017).
//!
//! The render learns, as it goes, where light comes from at each place in
//! the scene, and `path` samples its bounces by that as well as by the
//! BSDF. What is learned is an SD-tree ([`sdtree`]): a binary tree over
//! space whose leaves each hold a quadtree over directions ([`quadtree`]).
//! The render runs in iterations of 1, 2, 4, ... samples per pixel; each
//! iteration samples with the tree the last one learned and trains a
//! fresh one, refined where the last found many paths (space) and much
//! light (directions). A finished path splats, at each of its vertices
//! that scattered off a non-delta lobe, the radiance that reached the
//! vertex along the sampled direction divided by that direction's density
//! (an estimate of the incident radiance's integral over the cell) into
//! the leaf holding the vertex, into the cell of that direction.
//!
//! At a vertex whose leaf has learned something, the bounce is drawn by
//! one-sample MIS: the BSDF or the guide with probability 1/2 each (the
//! paper's fixed choice), the density the balance of the two; that
//! density is the one next-event estimation's MIS weights against. Delta
//! lobes are never guided: a BSDF with only delta lobes samples as
//! always, and a delta lobe drawn from a mixed BSDF counts with half its
//! probability.
//!
//! Determinism: the training sums are integers, added with atomic integer
//! additions (each value rounded to fixed point stochastically, by a hash
//! of the vertex), so a trained tree does not depend on the order threads
//! add to it; the sampling tree is fixed during an iteration.

pub(crate) mod quadtree;
pub(crate) mod sdtree;

use std::cell::RefCell;

use glam::Vec3;
use sahara_kd::Ray;

use super::{Context, PathState, Shading};
use crate::material::BsdfSample;
use crate::math::hash::{hash3, unit_f32};
use crate::math::warp::luminance;
use crate::names::name_table;
use crate::sampler::dims;
use crate::world::SurfaceHit;
use quadtree::Quadtree;
use sdtree::SdTree;

/// Whether `path` guides its bounces by what the render learns
/// (Müller et al. 2017).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Guiding {
    /// Never.
    #[default]
    Off,
    /// Always (an error where it cannot apply: another integrator, media,
    /// adaptive sampling, a farm's part).
    On,
    /// Where it applies: `path` without media, a whole frame without
    /// adaptive sampling.
    Auto,
}

name_table!(Guiding, "guiding", {
    Guiding::Off => "off",
    Guiding::On => "on",
    Guiding::Auto => "auto",
});

/// A directional quadtree's cell is a node of its own where it holds more
/// than this share of its leaf's light (the paper's ρ).
pub(crate) const RHO: f32 = 0.01;
/// A spatial leaf is cut while its vertices exceed `C·√spp` (the paper's c).
pub(crate) const SPATIAL_C: f64 = 12_000.0;
/// The most vertices of a path that train the tree (deeper ones still
/// sample with it).
const MAX_RECORDED: usize = 16;
/// Marks a path that does not record vertices.
pub(crate) const NO_RECORD: u32 = u32::MAX;

/// What the render has learned, and is learning, of the light.
#[derive(Debug)]
pub struct Guide {
    tree: SdTree,
}

impl Guide {
    /// A guide that knows nothing yet, over a cube holding `bounds`.
    pub(crate) fn new(bounds: sahara_kd::Aabb) -> Self {
        Self {
            tree: SdTree::new(bounds),
        }
    }

    /// The guide for the next iteration, the last having drawn `spp`
    /// samples per pixel.
    pub(crate) fn next(self, spp: u32) -> Self {
        let threshold = SPATIAL_C * f64::from(spp.max(1)).sqrt();
        Self {
            tree: self.tree.next(threshold, RHO),
        }
    }

    /// The leaf at `p`, and its distribution if it has learned one.
    #[inline]
    fn at(&self, p: Vec3) -> (u32, Option<&Quadtree>) {
        let l = self.tree.leaf_index(p);
        let d = &self.tree.leaf(l).sampling;
        (l, (d.total() > 0.0).then_some(d))
    }
}

/// A path vertex that trains the guide once its path is finished.
#[derive(Clone, Copy, Debug, Default)]
struct Vertex {
    leaf: u32,
    /// The direction sampled (world space).
    dir: Vec3,
    /// The path's throughput after the bounce (before Russian roulette).
    beta: Vec3,
    /// The density of the direction.
    pdf: f32,
    /// The path's radiance before anything arriving along `dir` (set at
    /// the next step).
    l0: Vec3,
}

/// One batch's recorded vertices: `MAX_RECORDED` slots per path.
#[derive(Default)]
struct Records {
    vertices: Vec<Vertex>,
    counts: Vec<u8>,
}

thread_local! {
    /// This thread's records of the batch it traces.
    static RECORDS: RefCell<Records> = RefCell::new(Records::default());
}

/// Readies this thread to record the vertices of `paths`, numbering each
/// path's records (call before tracing a batch with a guide).
pub(crate) fn begin(paths: &mut [PathState]) {
    RECORDS.with_borrow_mut(|r| {
        r.counts.clear();
        r.counts.resize(paths.len(), 0);
        r.vertices
            .resize(paths.len() * MAX_RECORDED, Vertex::default());
    });
    for (i, p) in paths.iter_mut().enumerate() {
        p.guide = i as u32;
    }
}

/// Splats the vertices of the finished `paths` (traced since [`begin`])
/// into the guide's training tree.
pub(crate) fn finish(guide: &Guide, paths: &[PathState]) {
    RECORDS.with_borrow(|r| {
        for (i, p) in paths.iter().enumerate() {
            let n = r.counts.get(i).copied().unwrap_or(0) as usize;
            for v in &r.vertices[i * MAX_RECORDED..i * MAX_RECORDED + n] {
                let arrived = p.l - v.l0;
                let mut li = Vec3::ZERO;
                for c in 0..3 {
                    if v.beta[c] > 0.0 {
                        li[c] = arrived[c] / v.beta[c];
                    }
                }
                let value = luminance(li).max(0.0) / v.pdf;
                let leaf = guide.tree.leaf(v.leaf);
                guide.tree.count(v.leaf);
                if value.is_finite() && value > 0.0 {
                    let jitter = unit_f32(hash3(
                        u64::from(value.to_bits()),
                        u64::from(v.dir.x.to_bits()) << 32 | u64::from(v.dir.y.to_bits()),
                        u64::from(v.leaf),
                    ));
                    leaf.training.splat(v.dir, value, jitter);
                }
            }
        }
    });
}

/// Notes, at the start of a step, the radiance the path had gathered
/// before anything arriving along its last recorded direction.
#[inline]
pub(crate) fn close(st: &PathState) {
    if st.guide == NO_RECORD {
        return;
    }
    RECORDS.with_borrow_mut(|r| {
        let i = st.guide as usize;
        let n = r.counts[i] as usize;
        if n > 0 {
            let v = &mut r.vertices[i * MAX_RECORDED + n - 1];
            if v.l0.x.is_nan() {
                v.l0 = st.l;
            }
        }
    });
}

/// Records a bounce of `st` from a point in `leaf` along `dir` with
/// density `pdf`, its throughput now `beta`.
#[inline]
fn record(st: &PathState, leaf: u32, dir: Vec3, beta: Vec3, pdf: f32) {
    if st.guide == NO_RECORD || pdf.is_nan() || pdf <= 0.0 {
        return;
    }
    RECORDS.with_borrow_mut(|r| {
        let i = st.guide as usize;
        let n = r.counts[i] as usize;
        if n < MAX_RECORDED {
            r.vertices[i * MAX_RECORDED + n] = Vertex {
                leaf,
                dir,
                beta,
                pdf,
                l0: Vec3::NAN,
            };
            r.counts[i] += 1;
        }
    });
}

/// Where a path's bounce at a vertex is guided: the leaf of the vertex
/// and its distribution (None: not learned yet, the BSDF alone).
#[derive(Clone, Copy)]
pub(crate) struct AtVertex<'g> {
    leaf: u32,
    dist: Option<&'g Quadtree>,
}

impl<'g> AtVertex<'g> {
    /// The guide at `hit` for shading `sh`: None where nothing is guided
    /// or recorded (no guide, a BSDF of delta lobes alone).
    #[inline]
    pub(crate) fn of(guide: Option<&'g Guide>, sh: &Shading, hit: &SurfaceHit) -> Option<Self> {
        let g = guide?;
        if sh.bsdf.is_delta() || sh.blind {
            return None;
        }
        let (leaf, dist) = g.at(hit.p);
        Some(Self { leaf, dist })
    }

    /// The density of scattering towards world direction `wi` given the
    /// BSDF's density `bsdf_pdf` there: the balance of the two when the
    /// vertex is guided.
    #[inline]
    pub(crate) fn pdf(&self, wi: Vec3, bsdf_pdf: f32) -> f32 {
        match self.dist {
            Some(d) => 0.5 * bsdf_pdf + 0.5 * d.pdf(wi),
            None => bsdf_pdf,
        }
    }

    /// The path's next bounce ([`Shading::sample_bounce`]): by the BSDF
    /// alone where the leaf has learned nothing, else one-sample MIS of
    /// the BSDF and the guide, each with probability 1/2 (the lobe's
    /// random number decides, and is stretched back to `[0, 1)`).
    pub(crate) fn sample_bounce(
        &self,
        ctx: &mut Context,
        sh: &Shading,
        hit: &SurfaceHit,
        depth: u32,
    ) -> Option<(BsdfSample, Ray)> {
        let Some(dist) = self.dist else {
            return sh.sample_bounce(ctx, hit, depth);
        };
        let u_lobe = ctx.sampler.get_1d(dims::bounce(depth, dims::BSDF_LOBE));
        let u = ctx.sampler.get_2d(dims::bounce(depth, dims::BSDF_DIR));
        let (s, wi) = if u_lobe < 0.5 {
            let mut s = sh.bsdf.sample(sh.wo, (u_lobe * 2.0).min(ONE_BELOW), u)?;
            let wi = sh.scattered(hit, s.wi, s.delta)?;
            if s.delta {
                // Drawn only by the BSDF's half.
                s.weight *= 2.0;
                s.pdf *= 0.5;
            } else {
                let pdf = 0.5 * s.pdf + 0.5 * dist.pdf(wi);
                s.weight *= s.pdf / pdf;
                s.pdf = pdf;
            }
            (s, wi)
        } else {
            // The density as evaluated (not as the descent found it), so
            // that the same direction has the same density whichever half
            // drew it.
            let (d, _) = dist.sample(u)?;
            let guide_pdf = dist.pdf(d);
            let local = sh.frame.to_local(d);
            let wi = sh.scattered(hit, local, false)?;
            let e = sh.bsdf.eval(sh.wo, local);
            let pdf = 0.5 * e.pdf + 0.5 * guide_pdf;
            let weight = e.f * local.z.abs() / pdf;
            if pdf.is_nan() || pdf <= 0.0 || weight.max_element() <= 0.0 {
                return None;
            }
            (
                BsdfSample {
                    wi: local,
                    weight,
                    pdf,
                    delta: false,
                },
                wi,
            )
        };
        ctx.stats.bounce_rays += 1;
        Some((s, Ray::new(hit.spawn_origin(wi), wi)))
    }

    /// Records the bounce just taken (a non-delta one) for training.
    #[inline]
    pub(crate) fn record(&self, st: &PathState, dir: Vec3, beta: Vec3, pdf: f32) {
        record(st, self.leaf, dir, beta, pdf);
    }
}

const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;
