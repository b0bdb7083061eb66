//! What a render gives back: the image developed from its exact sums
//! ([`RenderResult`]), and the `cost` view's heat map ([`CostMaps`]).

use glam::Vec3;

use super::aux::Aux;
use super::settings::RenderSettings;
use super::stats::RenderStats;
use crate::film::sums::SumBuffer;
use crate::film::{heat_color, Film};
use crate::integrator::Integrator;

/// The image and what it cost.
#[derive(Clone, Debug)]
pub struct RenderResult {
    /// The image of the window (black if no pass completed).
    pub film: Film,
    /// The window's exact sums over the completed passes (and, in an
    /// interrupted first pass, over the tiles it finished).
    pub sums: SumBuffer,
    /// Counts and times.
    pub stats: RenderStats,
    /// Raw per-pixel work of the `cost` view.
    pub cost: Option<CostMaps>,
    /// The albedo, normal and depth images and their sums, when
    /// [`RenderSettings::aovs`] asks for them.
    pub aux: Option<Aux>,
    /// With adaptive sampling, the samples each pixel of the window took
    /// (rows top to bottom).
    pub samples: Option<Vec<u32>>,
}

/// The image of the sums so far (black where `finished` says a pixel was
/// not), and the render passes' images.
pub(super) fn develop(
    sums: SumBuffer,
    mut aux: Option<Aux>,
    finished: Option<&[bool]>,
    stats: RenderStats,
    settings: &RenderSettings,
    samples: Option<Vec<u32>>,
) -> RenderResult {
    if let Some(a) = &mut aux {
        a.develop(finished);
    }
    let mut film = Film::new(sums.width, sums.height);
    for (k, (p, s)) in film.pixels.iter_mut().zip(&sums.sums).enumerate() {
        let keep = finished.is_none_or(|f| f[k]);
        *p = if keep { s.value() } else { Vec3::ZERO };
    }
    let cost = matches!(settings.integrator, Integrator::Cost)
        .then(|| cost_maps(&mut film, settings.cost_scale));
    RenderResult {
        film,
        sums,
        stats,
        cost,
        aux,
        samples,
    }
}

/// Per-pixel averages of the `cost` view.
#[derive(Clone, Debug, PartialEq)]
pub struct CostMaps {
    /// Traversal steps (inner nodes, leaves, top-level box tests) per ray.
    pub steps: Vec<f32>,
    /// Ray/triangle tests per ray.
    pub tests: Vec<f32>,
    /// The value shown as full heat.
    pub scale: f32,
}

/// Turns the raw film of the `cost` view into its heat map (full heat at
/// `scale` work units per camera ray, or at the image's maximum if None),
/// returning the raw values.
pub fn cost_maps(film: &mut Film, scale: Option<f32>) -> CostMaps {
    let steps: Vec<f32> = film.pixels.iter().map(|p| p.x).collect();
    let tests: Vec<f32> = film.pixels.iter().map(|p| p.y).collect();
    let max = film.pixels.iter().map(|p| p.x + p.y).fold(0.0f32, f32::max);
    let scale = scale.unwrap_or(max).max(1e-6);
    for p in &mut film.pixels {
        *p = heat_color((p.x + p.y) / scale);
    }
    CostMaps {
        steps,
        tests,
        scale,
    }
}
