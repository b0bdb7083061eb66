//! `render --denoise`: the finished image through Intel Open Image Denoise
//! (the `sahara-denoise` crate), guided by the render's albedo and normal.

use std::time::Instant;

use anyhow::{anyhow, Result};
use sahara_denoise::{Aux, Denoiser, Image};
use sahara_render::{RenderResult, Scene};

use crate::output::flat;

/// Finds and loads the denoiser, before anything is rendered: a missing
/// library is said in one line with how to get it.
pub(crate) fn load() -> Result<Denoiser> {
    let d = Denoiser::load().map_err(|e| anyhow!("--denoise: {e}"))?;
    Ok(d)
}

/// True where a pixel's samples see different surfaces beyond its edges:
/// through a lens that blurs (depth of field) or while things move
/// (motion blur). The albedo and normal are then noisy images themselves.
pub(crate) fn guides_are_noisy(scene: &Scene) -> bool {
    let c = &scene.camera;
    c.lens_radius > 0.0
        || (c.shutter_close > c.shutter_open
            && scene.instances.iter().any(|i| i.placement.is_moving()))
}

/// Denoises `result`'s image in place and returns the noisy one (linear
/// RGB), or `None` with the reason said when there is nothing to denoise
/// (a first pass stopped before every pixel had its samples: the black
/// pixels would smear into the rest). `noisy_guides`: denoise the albedo
/// and normal first ([`guides_are_noisy`]).
pub(crate) fn apply(
    denoiser: &Denoiser,
    result: &mut RenderResult,
    noisy_guides: bool,
) -> Result<Option<Vec<f32>>> {
    if result.stats.passes == 0 {
        eprintln!("denoise: skipped, the first pass was stopped before every pixel was finished");
        return Ok(None);
    }
    let aux = result
        .aux
        .as_ref()
        .ok_or_else(|| anyhow!("--denoise: the render made no albedo and normal"))?;
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
    let denoising = crate::status::Step::start("denoising");
    let clean = denoiser.denoise(&image, guide);
    drop(denoising);
    let clean = clean.map_err(|e| anyhow!("--denoise: {e}"))?;
    for (p, c) in result.film.pixels.iter_mut().zip(clean.chunks_exact(3)) {
        // The network may leave tiny negative values: radiance is not negative.
        *p = glam::Vec3::new(c[0], c[1], c[2]).max(glam::Vec3::ZERO);
    }
    eprintln!(
        "denoised with Open Image Denoise {} in {:.2} s, from {}",
        denoiser.version(),
        start.elapsed().as_secs_f64(),
        denoiser.location()
    );
    Ok(Some(noisy))
}
