//! Renders the built-in Cornell box to a PPM: `cargo run --release -p
//! sahara-render --example cornell -- OUT.ppm [SIZE] [SPP] [INTEGRATOR]`.

use sahara_render::{builtin, render, FrameSettings, Integrator, RenderSettings, ToneMap};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let out = args.get(1).map_or("cornell.ppm", String::as_str);
    let size: u32 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(256);
    let spp: u32 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(64);
    let integrator = args
        .get(4)
        .and_then(|s| Integrator::named(s).ok())
        .unwrap_or_default();
    let scene = builtin::cornell_box();
    let settings = RenderSettings::from(FrameSettings {
        width: size,
        height: size,
        spp,
        integrator,
        ..Default::default()
    });
    let r = render(&scene, &settings, &|_| {}).unwrap();
    let s = &r.stats;
    eprintln!(
        "{}x{} {} spp {}: {:.2?} render, {} rays ({:.1} Mrays/s), NaN {}, negative {}",
        size,
        size,
        s.spp,
        integrator.name(),
        s.render_time,
        s.rays(),
        s.rays() as f64 / s.render_time.as_secs_f64() / 1e6,
        s.nan_samples,
        s.negative_samples
    );
    std::fs::write(out, r.film.to_ppm(0.0, ToneMap::Clamp)).expect("write image");
}
