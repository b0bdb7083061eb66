//! A rendered frame through Intel Open Image Denoise (the `sahara-denoise`
//! crate), guided by the render's albedo and normal: the glue both front
//! ends and `sahara merge` denoise a result with.

use std::time::Instant;

use sahara_denoise::{Aux, Denoiser, Image};
use sahara_render::{Aov, RenderResult, Scene};

use crate::output::frame::flat;

/// The render passes that guide the denoiser: a denoised render makes
/// them, and a farm's parts carry them for `sahara merge` to denoise.
pub const GUIDES: [Aov; 2] = [Aov::Albedo, Aov::Normal];

/// True where a pixel's samples see different surfaces beyond its edges:
/// through a lens that blurs (depth of field) or while things move
/// (motion blur). The albedo and normal are then noisy images themselves.
pub fn guides_are_noisy(scene: &Scene) -> bool {
    let c = &scene.camera;
    c.lens_radius > 0.0
        || (c.shutter_close > c.shutter_open
            && scene.instances.iter().any(|i| i.placement.is_moving()))
}

/// What denoising did.
#[derive(Clone, Debug, PartialEq)]
pub enum Denoised {
    /// Nothing: a first pass stopped before every pixel had its samples
    /// (the black pixels would smear into the rest).
    Skipped,
    /// The image was denoised in place.
    Done {
        /// The image before denoising (linear RGB), for an EXR's `noisy`
        /// layer.
        noisy: Vec<f32>,
        /// Seconds the denoiser took.
        seconds: f64,
    },
}

/// Denoises `result`'s image in place with `denoiser`. `noisy_guides`:
/// denoise the albedo and normal first ([`guides_are_noisy`]). The error
/// says what went wrong, without naming what asked for denoising.
pub fn denoise(
    denoiser: &Denoiser,
    result: &mut RenderResult,
    noisy_guides: bool,
) -> Result<Denoised, String> {
    if result.stats.passes == 0 {
        return Ok(Denoised::Skipped);
    }
    let aux = result
        .aux
        .as_ref()
        .ok_or("the render made no albedo and normal")?;
    let (albedo, normal) = (flat(&aux.images.albedo), flat(&aux.images.normal));
    let noisy = result.film.to_rgb_f32();
    let image = Image {
        width: result.film.width as usize,
        height: result.film.height as usize,
        color: &noisy,
        hdr: true,
    };
    // A pixel's albedo and normal are means over its samples. Under depth
    // of field or motion blur they are noisy, and are denoised first, as
    // Open Image Denoise advises; that costs several times the beauty's
    // filter (docs/clean-image.md), so sharp, still frames pass them as
    // they are (their only noise, at edges, the network tolerates).
    let guide = Aux {
        prefilter_aux: noisy_guides,
        ..Aux::albedo_normal(&albedo, &normal)
    };
    let start = Instant::now();
    let clean = denoiser.denoise(&image, guide).map_err(|e| e.to_string())?;
    for (p, c) in result.film.pixels.iter_mut().zip(clean.chunks_exact(3)) {
        // The network may leave tiny negative values: radiance is not negative.
        *p = glam::Vec3::new(c[0], c[1], c[2]).max(glam::Vec3::ZERO);
    }
    Ok(Denoised::Done {
        noisy,
        seconds: start.elapsed().as_secs_f64(),
    })
}
