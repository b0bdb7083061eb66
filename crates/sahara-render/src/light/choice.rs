//! How next-event estimation chooses the light it samples from a shading
//! point ([`LightSampler`]), and the probability of that choice, which
//! multiple importance sampling needs again when a scattered ray finds an
//! emitter.

use glam::Vec3;

use super::tree::{LightBounds, LightTree};
use super::{Light, LightSource};
use crate::math::lanes::{F, M, V};
use crate::math::piecewise::Distribution1D;
use crate::names::name_table;

/// How next-event estimation chooses a light.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum LightSampler {
    /// A light tree over the lights in the scene ([`super::tree`]): by
    /// their power, distance and orientation as seen from the shading
    /// point, each emitting triangle of a mesh on its own; the lights at
    /// infinity by power beside it.
    #[default]
    Tree,
    /// By power alone, the same wherever the shading point is.
    Power,
    /// Every light alike (Mitsuba 3's default).
    Uniform,
}

name_table!(LightSampler, "light sampler", {
    LightSampler::Tree => "tree",
    LightSampler::Power => "power",
    LightSampler::Uniform => "uniform",
});

/// One emitting piece the tree holds: a light, or one triangle of a mesh
/// light.
#[derive(Clone, Copy, Debug)]
struct Piece {
    light: u32,
    /// The triangle among the mesh light's ([`NO_TRIANGLE`]: the whole
    /// light).
    tri: u32,
}

const NO_TRIANGLE: u32 = u32::MAX;

/// A light chosen for a shading point: the light, a mesh light's
/// triangle (None: the whole light) and the probability of the choice.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Chosen {
    pub light: usize,
    pub tri: Option<usize>,
    pub pmf: f32,
}

/// The light choice of a world.
pub(crate) struct LightChoice {
    kind: LightSampler,
    /// Power and uniform: the choice over every light.
    all: Distribution1D,
    /// The tree's: the lights at infinity, chosen by power.
    infinite: Vec<u32>,
    infinite_dist: Distribution1D,
    /// Probability of choosing among the lights at infinity.
    p_infinite: f32,
    /// Per light, its position among `infinite`.
    infinite_slot: Vec<u32>,
    tree: LightTree,
    pieces: Vec<Piece>,
    /// Per light, its first piece.
    first_piece: Vec<u32>,
}

impl LightChoice {
    /// The choice of `kind` over `lights` of emitted power `powers`
    /// (each light at infinity rated by the scene's radius).
    pub(crate) fn new(kind: LightSampler, lights: &[LightSource], powers: &[f32]) -> Self {
        let all = Distribution1D::new(match kind {
            LightSampler::Uniform => vec![1.0; lights.len()],
            LightSampler::Power | LightSampler::Tree => next_event_choice(lights, powers),
        });
        let mut choice = Self {
            kind,
            all,
            infinite: Vec::new(),
            infinite_dist: Distribution1D::new(Vec::new()),
            p_infinite: 0.0,
            infinite_slot: vec![u32::MAX; lights.len()],
            tree: LightTree::new(&[]),
            pieces: Vec::new(),
            first_piece: vec![u32::MAX; lights.len()],
        };
        if kind != LightSampler::Tree {
            return choice;
        }
        let mut bounds = Vec::new();
        let mut far = Vec::new();
        for (i, l) in lights.iter().enumerate() {
            if l.is_infinite() {
                choice.infinite_slot[i] = choice.infinite.len() as u32;
                choice.infinite.push(i as u32);
                far.push(powers[i]);
                continue;
            }
            choice.first_piece[i] = choice.pieces.len() as u32;
            let b = tree_bounds(l);
            let whole = b.len() == 1 && !matches!(l, LightSource::Area(a) if a.is_mesh());
            for (k, b) in b.into_iter().enumerate() {
                choice.pieces.push(Piece {
                    light: i as u32,
                    tri: if whole { NO_TRIANGLE } else { k as u32 },
                });
                bounds.push(b);
            }
        }
        choice.tree = LightTree::new(&bounds);
        let far_power: f64 = far.iter().map(|&p| f64::from(p)).sum();
        choice.p_infinite = match (far_power > 0.0, choice.tree.is_empty()) {
            (false, _) => 0.0,
            (true, true) => 1.0,
            (true, false) => 0.5,
        };
        choice.infinite_dist = Distribution1D::new(far);
        choice
    }

    /// The way this choice was made.
    pub(crate) fn kind(&self) -> LightSampler {
        self.kind
    }

    /// A light chosen by `u` for the point `p` with normal `n` (zero in a
    /// medium).
    pub(crate) fn sample(&self, p: Vec3, n: Vec3, u: f32) -> Option<Chosen> {
        if self.kind != LightSampler::Tree {
            let (light, pmf) = self.all.sample_discrete(u);
            return (pmf > 0.0).then_some(Chosen {
                light,
                tri: None,
                pmf,
            });
        }
        let pi = self.p_infinite;
        if u < pi {
            let (k, pmf) = self
                .infinite_dist
                .sample_discrete((u / pi).min(1.0 - f32::EPSILON / 2.0));
            return (pmf > 0.0).then_some(Chosen {
                light: self.infinite[k] as usize,
                tri: None,
                pmf: pi * pmf,
            });
        }
        let u = ((u - pi) / (1.0 - pi)).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
        let (piece, pmf) = self.tree.sample(p, n, u)?;
        Some(self.chosen_piece(piece, pmf))
    }

    /// The tree's piece `piece`, chosen by the tree with probability
    /// `pmf`, as a light choice.
    #[inline]
    fn chosen_piece(&self, piece: u32, pmf: f32) -> Chosen {
        let piece = self.pieces[piece as usize];
        Chosen {
            light: piece.light as usize,
            tri: (piece.tri != NO_TRIANGLE).then_some(piece.tri as usize),
            pmf: (1.0 - self.p_infinite) * pmf,
        }
    }

    /// [`LightChoice::sample`] for the lanes `on` (points `p`, normals `n`,
    /// numbers `u`), each lane's choice the scalar one's: the tree's walk
    /// in the lanes, the choices by power or among the lights at infinity
    /// (a search in a table) lane by lane.
    #[inline(always)]
    pub(crate) fn sample_lanes<const N: usize>(
        &self,
        on: M<N>,
        p: V<N>,
        n: V<N>,
        u: F<N>,
    ) -> [Option<Chosen>; N] {
        // Lane by lane where the tree does not choose.
        let scalar = |take: M<N>| -> [Option<Chosen>; N] {
            std::array::from_fn(|i| {
                take.0[i]
                    .then(|| self.sample(p.get(i), n.get(i), u.0[i]))
                    .flatten()
            })
        };
        if self.kind != LightSampler::Tree {
            return scalar(on);
        }
        let pi = self.p_infinite;
        let far = u.lt(F::splat(pi));
        let mut out = scalar(on & far);
        let near = on & !far;
        if !near.any() {
            return out;
        }
        let u = ((u - F::splat(pi)) / F::splat(1.0 - pi))
            .map(|x| x.clamp(0.0, 1.0 - f32::EPSILON / 2.0));
        let (piece, pmf, found) = self.tree.sample_lanes(near, p, n, u);
        for (i, out) in out.iter_mut().enumerate() {
            if found.0[i] {
                *out = Some(self.chosen_piece(piece.0[i], pmf.0[i]));
            }
        }
        out
    }

    /// The probability that [`LightChoice::sample`] at `p` with normal `n`
    /// chooses `light` (and, for a mesh light in the tree, its triangle
    /// `tri`).
    pub(crate) fn pmf(&self, p: Vec3, n: Vec3, light: usize, tri: Option<usize>) -> f32 {
        if self.kind != LightSampler::Tree {
            return self.all.pmf(light);
        }
        let slot = self.infinite_slot[light];
        if slot != u32::MAX {
            return self.p_infinite * self.infinite_dist.pmf(slot as usize);
        }
        let first = self.first_piece[light];
        if first == u32::MAX {
            return 0.0;
        }
        let piece = first + tri.unwrap_or(0) as u32;
        (1.0 - self.p_infinite) * self.tree.pmf(p, n, piece)
    }

    /// Whether a mesh light is chosen triangle by triangle.
    pub(crate) fn by_triangle(&self) -> bool {
        self.kind == LightSampler::Tree
    }
}

/// The tree's pieces of light `l` with their bounds.
fn tree_bounds(l: &LightSource) -> Vec<LightBounds> {
    match l {
        LightSource::Area(a) => a.tree_bounds(),
        LightSource::Explicit(Light::Point {
            position,
            intensity,
        }) => vec![LightBounds::point(
            *position,
            crate::math::warp::luminance(*intensity),
        )],
        LightSource::Explicit(Light::Spot {
            position,
            direction,
            intensity,
            cos_inner,
            cos_outer,
        }) => {
            // Full within the inner cone, none beyond the outer.
            let spread = (cos_outer.clamp(-1.0, 1.0).acos() - cos_inner.clamp(-1.0, 1.0).acos())
                .max(0.0)
                .cos();
            vec![LightBounds::cone(
                *position,
                crate::math::warp::luminance(*intensity),
                *direction,
                *cos_inner,
                spread,
            )]
        }
        LightSource::Explicit(Light::Directional { .. }) | LightSource::Environment(_) => {
            unreachable!("lights at infinity are chosen beside the tree")
        }
    }
}

/// The weights by which power sampling picks a light: by power within
/// each of two families, the lights infinitely far away (the environment,
/// directional lights) and the lights in the scene, with half the choices
/// to each family when the scene has both. Power alone would rate an
/// environment by the disc of the whole scene it lights, and a dim sky
/// around a room would take nearly every choice from the lamp that lights
/// the room (pbrt-v4's light samplers split the same way; the tree keeps
/// the same split).
fn next_event_choice(lights: &[LightSource], powers: &[f32]) -> Vec<f32> {
    let infinite = LightSource::is_infinite;
    let (mut far, mut near) = (0.0f64, 0.0f64);
    for (l, &p) in lights.iter().zip(powers) {
        if infinite(l) {
            far += p as f64;
        } else {
            near += p as f64;
        }
    }
    if far <= 0.0 || near <= 0.0 {
        return powers.to_vec();
    }
    lights
        .iter()
        .zip(powers)
        .map(|(l, &p)| (p as f64 / if infinite(l) { far } else { near }) as f32)
        .collect()
}
