//! How long Open Image Denoise takes here: the beauty alone, with albedo
//! and normal, and with the two prefiltered, at 512x512 and 1920x1080 (the
//! cost does not depend on the pixels' values, so they are plain noise).
//!
//! `cargo run --release -p sahara-denoise --example denoise_time`

use std::time::Instant;

use sahara_denoise::{Aux, Denoiser, Image};

fn main() -> Result<(), sahara_denoise::DenoiseError> {
    let start = Instant::now();
    let d = Denoiser::load()?;
    println!(
        "Open Image Denoise {} from {}: loaded in {:.0} ms",
        d.version(),
        d.location(),
        start.elapsed().as_secs_f64() * 1e3
    );
    for (width, height) in [(512, 512), (1920, 1080)] {
        let n = width * height * 3;
        let color: Vec<f32> = (0..n).map(|i| (i * 7919 % 1000) as f32 / 500.0).collect();
        let albedo = vec![0.7f32; n];
        let normal = [0.0f32, 0.0, 1.0].repeat(width * height);
        let image = Image {
            width,
            height,
            color: &color,
            hdr: true,
        };
        let both = Aux::albedo_normal(&albedo, &normal);
        let prefiltered = Aux {
            prefilter_aux: true,
            ..both
        };
        for (what, aux) in [
            ("beauty alone", Aux::none()),
            ("albedo and normal", both),
            ("prefiltered albedo and normal", prefiltered),
        ] {
            // The first run of a filter also sets it up; then the best of 3.
            let mut times = Vec::new();
            for _ in 0..4 {
                let start = Instant::now();
                d.denoise(&image, aux)?;
                times.push(start.elapsed().as_secs_f64());
            }
            let best = times[1..].iter().copied().fold(f64::INFINITY, f64::min);
            println!(
                "{width}x{height} {what}: {:.2} s (first run {:.2} s)",
                best, times[0]
            );
        }
    }
    Ok(())
}
