//! Ray queries answered in batches, in the order that suits the kd-tree.
//!
//! The integrators that trace many samples together ([`super::wavefront`],
//! [`super::bdpt`]) gather a round's rays, ask for all their closest hits
//! at once, then for all the shadow rays the round's vertices made. The
//! rays go to the tree grouped by direction octant (the three sign bits):
//! rays that share their signs walk the cells in the same order, which
//! lets coherent ones share a traversal (figures in docs/performance.md).
//! Every answer is the one the query gets alone, whatever the batch.

use glam::Vec3;
use sahara_kd::Ray;

use crate::world::{ShadowQuery, SurfaceHit, World, WorldBuffers};

/// The buffers of batched queries, kept from one batch to the next.
#[derive(Debug, Default)]
pub(crate) struct RayQueries {
    /// The order in which to trace a batch's rays.
    order: Vec<u32>,
    /// A batch's rays, times and hits in that order.
    rays: Vec<Ray>,
    times: Vec<f32>,
    hits: Vec<Option<SurfaceHit>>,
    /// A batch's shadow queries in that order, and their answers.
    queries: Vec<ShadowQuery>,
    answers: Vec<bool>,
    world: WorldBuffers,
}

/// Indices `i < n` for which `dir(i)` gives a direction, grouped by
/// direction octant, in their given order within each group: a counting
/// sort.
fn octant_order(n: usize, dir: impl Fn(usize) -> Option<Vec3>, order: &mut Vec<u32>) {
    let octant = |d: Vec3| {
        (d.x.is_sign_negative() as usize)
            | (d.y.is_sign_negative() as usize) << 1
            | (d.z.is_sign_negative() as usize) << 2
    };
    let mut start = [0u32; 9];
    for i in 0..n {
        if let Some(d) = dir(i) {
            start[octant(d) + 1] += 1;
        }
    }
    for o in 0..8 {
        start[o + 1] += start[o];
    }
    order.clear();
    order.resize(start[8] as usize, 0);
    for i in 0..n {
        if let Some(d) = dir(i) {
            let o = octant(d);
            order[start[o] as usize] = i as u32;
            start[o] += 1;
        }
    }
}

impl RayQueries {
    /// The closest surfaces along `rays`, `rays[i]` at `times[i]` into
    /// `hits[i]`, in one batch grouped by direction octant.
    pub fn closest(
        &mut self,
        world: &World,
        rays: &[Ray],
        times: &[f32],
        hits: &mut [Option<SurfaceHit>],
    ) {
        octant_order(rays.len(), |i| Some(rays[i].dir), &mut self.order);
        self.rays.clear();
        self.times.clear();
        for &j in &self.order {
            self.rays.push(rays[j as usize]);
            self.times.push(times[j as usize]);
        }
        self.hits.clear();
        self.hits.resize(self.order.len(), None);
        world.intersect_batch(&self.rays, &self.times, &mut self.hits, &mut self.world);
        for (&j, h) in self.order.iter().zip(&self.hits) {
            hits[j as usize] = *h;
        }
    }

    /// Whether each of `n` contributions arrives: `visible[i]` is true
    /// when `shadow(i)` has no query or nothing blocks its segment. The
    /// queries are answered in one batch grouped by direction octant.
    pub fn visible<'q>(
        &mut self,
        world: &World,
        n: usize,
        shadow: impl Fn(usize) -> Option<&'q ShadowQuery>,
        visible: &mut Vec<bool>,
    ) {
        octant_order(n, |i| shadow(i).map(|q| q.ray.dir), &mut self.order);
        self.queries.clear();
        self.queries.extend(
            self.order
                .iter()
                .filter_map(|&j| shadow(j as usize).copied()),
        );
        self.answers.clear();
        self.answers.resize(self.queries.len(), true);
        world.visible_batch(&self.queries, &mut self.answers, &mut self.world);
        visible.clear();
        visible.resize(n, true);
        for (&j, &v) in self.order.iter().zip(&self.answers) {
            visible[j as usize] = v;
        }
    }
}
