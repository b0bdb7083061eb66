//! The real denoiser on a synthetic image: a clean rendering of flat and
//! curved shapes, the same with Monte Carlo-like noise, and the error of
//! each against the clean one.
//!
//! These need Open Image Denoise. Where it is not found they print a line
//! and pass, unless `SAHARA_REQUIRE_OIDN` is set (to anything but `0`), as
//! CI does: then a missing library fails them.

use sahara_denoise::{Aux, DenoiseError, Denoiser, Image};

/// The denoiser, or `None` (said so) when the library is missing and not
/// required.
fn denoiser() -> Option<Denoiser> {
    match Denoiser::load() {
        Ok(d) => Some(d),
        Err(e @ DenoiseError::NotFound { .. }) if !required() => {
            skip_note(&format!(
                "the denoiser's tests ({e}; set SAHARA_REQUIRE_OIDN=1 to fail instead)"
            ));
            None
        }
        Err(e) => panic!("{e}"),
    }
}

/// Says once, on the test binary's own stderr (which `cargo test` shows
/// without `--nocapture`), that the tests are skipped and why.
fn skip_note(reason: &str) {
    use std::io::Write;
    static SAID: std::sync::Once = std::sync::Once::new();
    SAID.call_once(|| {
        let _ = std::io::stderr().write_all(format!("SKIPPED: {reason}\n").as_bytes());
    });
}

/// Whether `SAHARA_REQUIRE_OIDN` asks for the library.
fn required() -> bool {
    std::env::var_os("SAHARA_REQUIRE_OIDN").is_some_and(|v| !v.is_empty() && v != "0")
}

const W: usize = 128;
const H: usize = 128;

/// A 32-bit integer hash (Wellons' lowbias32).
fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^ (x >> 16)
}

/// A uniform number in (0, 1) from a seed.
fn uniform(seed: u32) -> f32 {
    ((hash(seed) >> 8) as f32 + 0.5) / (1u32 << 24) as f32
}

/// The clean scene: per pixel an albedo, a unit normal and the beauty
/// (albedo times a smooth diffuse shading, in HDR units up to about 3).
/// A gradient floor, a shaded disc (a sphere's normals) and two flat
/// rectangles of other colours give smooth regions and hard edges.
struct Scene {
    albedo: Vec<f32>,
    normal: Vec<f32>,
    color: Vec<f32>,
}

fn scene() -> Scene {
    let light = normalize([0.4, 0.6, 0.7]);
    let mut s = Scene {
        albedo: Vec::with_capacity(W * H * 3),
        normal: Vec::with_capacity(W * H * 3),
        color: Vec::with_capacity(W * H * 3),
    };
    for y in 0..H {
        for x in 0..W {
            let (u, v) = ((x as f32 + 0.5) / W as f32, (y as f32 + 0.5) / H as f32);
            // The floor: a colour gradient facing the viewer, tilted down.
            let mut albedo = [0.3 + 0.5 * u, 0.4, 0.7 - 0.4 * v];
            let mut normal = normalize([0.0, 0.3, 1.0]);
            let (dx, dy) = (u - 0.35, v - 0.4);
            let r = 0.22;
            if dx * dx + dy * dy < r * r {
                // A sphere seen from the front.
                let (nx, ny) = (dx / r, -dy / r);
                normal = [nx, ny, (1.0 - nx * nx - ny * ny).max(0.0).sqrt()];
                albedo = [0.8, 0.25, 0.2];
            } else if (0.62..0.9).contains(&u) && (0.15..0.5).contains(&v) {
                albedo = [0.15, 0.7, 0.3];
                normal = normalize([-0.5, 0.1, 1.0]);
            } else if (0.55..0.95).contains(&u) && (0.65..0.8).contains(&v) {
                albedo = [0.9, 0.85, 0.2];
                normal = normalize([0.2, -0.4, 1.0]);
            }
            let shade = 0.15 + 2.8 * dot(normal, light).max(0.0);
            s.albedo.extend(albedo);
            s.normal.extend(normal);
            s.color.extend(albedo.map(|a| a * shade));
        }
    }
    s
}

/// `clean` as a path tracer at `spp` samples a pixel might estimate it:
/// each sample the clean value times an exponential weight (mean 1, so the
/// estimate is unbiased), the same weight for a sample's three channels.
/// Deterministic for a `seed`.
fn noisy(clean: &[f32], spp: u32, seed: u32) -> Vec<f32> {
    let mut out = Vec::with_capacity(clean.len());
    for (p, rgb) in clean.chunks_exact(3).enumerate() {
        let mut sum = 0.0;
        for s in 0..spp {
            let key = (p as u32).wrapping_mul(spp).wrapping_add(s) ^ seed.wrapping_mul(0x9e37_79b9);
            sum += -uniform(key).ln();
        }
        let weight = sum / spp as f32;
        out.extend(rgb.iter().map(|c| c * weight));
    }
    out
}

/// Root mean square difference.
fn rmse(a: &[f32], b: &[f32]) -> f32 {
    assert_eq!(a.len(), b.len());
    let sum: f64 = a.iter().zip(b).map(|(x, y)| f64::from(x - y).powi(2)).sum();
    (sum / a.len() as f64).sqrt() as f32
}

fn normalize(v: [f32; 3]) -> [f32; 3] {
    let l = dot(v, v).sqrt();
    v.map(|c| c / l)
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Fails unless the denoised error `ratio` is under half the noisy
/// image's.
fn assert_halved(ratio: f32, what: &str) {
    assert!(ratio < 0.5, "{what}: error {ratio:.2}x the noisy image's");
}

/// Denoises `noisy` with `aux`, checks the output is finite, and returns
/// its error against `clean` as a fraction of the noisy image's.
fn error_ratio(d: &Denoiser, clean: &[f32], noisy: &[f32], hdr: bool, aux: Aux) -> f32 {
    let image = Image {
        width: W,
        height: H,
        color: noisy,
        hdr,
    };
    let out = d.denoise(&image, aux).unwrap();
    assert_eq!(out.len(), clean.len());
    assert!(out.iter().all(|v| v.is_finite()));
    let (before, after) = (rmse(noisy, clean), rmse(&out, clean));
    println!("rmse {before:.4} -> {after:.4} ({:.2}x)", after / before);
    after / before
}

#[test]
fn denoising_lowers_the_error_of_a_noisy_hdr_image_with_and_without_aux() {
    let Some(d) = denoiser() else { return };
    println!("Open Image Denoise {} from {}", d.version(), d.location());
    assert!(d.version().major >= 2);
    let s = scene();
    let noisy = noisy(&s.color, 4, 1);
    let both = Aux::albedo_normal(&s.albedo, &s.normal);
    let cases = [
        ("beauty alone", Aux::none()),
        (
            "with albedo",
            Aux {
                normal: None,
                ..both
            },
        ),
        ("with albedo and normal", both),
        (
            "with clean albedo and normal",
            Aux {
                clean_aux: true,
                ..both
            },
        ),
    ];
    let ratios: Vec<f32> = cases
        .iter()
        .map(|&(what, aux)| {
            let ratio = error_ratio(&d, &s.color, &noisy, true, aux);
            assert_halved(ratio, what);
            ratio
        })
        .collect();
    assert!(
        ratios[3] < ratios[0],
        "albedo and normal did not help: {ratios:?}"
    );
}

#[test]
fn prefiltered_noisy_aux_buffers_are_denoised_too() {
    let Some(d) = denoiser() else { return };
    let s = scene();
    let noisy_color = noisy(&s.color, 4, 3);
    // Aux buffers with noise of their own (albedo in [0, 1] still).
    let albedo: Vec<f32> = noisy(&s.albedo, 8, 4).iter().map(|a| a.min(1.0)).collect();
    let normal = noisy(&s.normal, 8, 5);
    let aux = Aux::albedo_normal(&albedo, &normal);
    let plain = error_ratio(&d, &s.color, &noisy_color, true, aux);
    let prefiltered = Aux {
        prefilter_aux: true,
        ..aux
    };
    let ratio = error_ratio(&d, &s.color, &noisy_color, true, prefiltered);
    assert_halved(plain, "with noisy aux");
    assert_halved(ratio, "with prefiltered aux");
    // The caller's buffers are left as they were.
    assert_eq!(
        albedo,
        noisy(&s.albedo, 8, 4)
            .iter()
            .map(|a| a.min(1.0))
            .collect::<Vec<_>>()
    );
}

#[test]
fn ldr_images_are_denoised_in_their_range() {
    let Some(d) = denoiser() else { return };
    let s = scene();
    let clean: Vec<f32> = s.color.iter().map(|c| (c / 3.0).min(1.0)).collect();
    let noisy: Vec<f32> = noisy(&clean, 16, 6).iter().map(|c| c.min(1.0)).collect();
    let ratio = error_ratio(&d, &clean, &noisy, false, Aux::none());
    assert!(ratio < 0.5, "LDR: error {ratio:.2}x the noisy image's");
}

#[test]
fn a_wrong_size_is_refused_before_the_library_sees_it() {
    let Some(d) = denoiser() else { return };
    let color = vec![0.5f32; W * H * 3];
    let short = vec![0.5f32; W * H * 3 - 1];
    let image = Image {
        width: W,
        height: H,
        color: &color,
        hdr: true,
    };
    let e = d
        .denoise(&image, Aux::albedo_normal(&short, &color))
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "the albedo buffer has 49151 values; a 128x128 RGB image needs 49152"
    );
}

#[test]
fn one_denoiser_serves_several_threads() {
    fn send_sync<T: Send + Sync>() {}
    send_sync::<Denoiser>();
    let Some(d) = denoiser() else { return };
    let s = scene();
    let noisy = noisy(&s.color, 4, 7);
    let ratios: Vec<f32> = std::thread::scope(|scope| {
        let jobs: Vec<_> = (0..2)
            .map(|_| scope.spawn(|| error_ratio(&d, &s.color, &noisy, true, Aux::none())))
            .collect();
        jobs.into_iter().map(|j| j.join().unwrap()).collect()
    });
    assert_eq!(ratios[0], ratios[1]);
}
