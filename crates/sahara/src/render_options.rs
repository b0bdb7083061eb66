//! The settings of a render: the command line over the scene file over the defaults.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

use anyhow::{bail, Result};
use sahara_formats::FileSettings;
use sahara_kd::BuildParams;
use sahara_render::UNLIMITED_SPP;
use sahara_render::{Adaptive, Filter, FrameSettings, Integrator, RenderSettings, ToneMap};

use crate::cli::RenderArgs;

/// Samples per pixel when neither the command line nor a scene file says
/// (the renderer's default, which scene files use too).
pub const DEFAULT_SPP: u32 = sahara_render::defaults::SPP;
/// Samples per pixel of each pass when the command line does not say.
const PASS_SPP: u32 = sahara_render::defaults::PASS_SPP;
/// Image side in pixels when neither the command line nor a scene file says.
pub const DEFAULT_SIDE: u32 = 512;

/// Everything decided about a render before it starts.
#[derive(Debug)]
pub struct RenderOptions {
    /// What the renderer is given.
    pub settings: RenderSettings,
    /// Exposure in stops, for 8-bit output.
    pub exposure: f32,
    /// Tone map for 8-bit output.
    pub tonemap: ToneMap,
    /// The image file to write.
    pub output: PathBuf,
}

/// The settings of a render of a scene called `name`: explicit command-line
/// options win over the scene file's settings (`file`), which win over the defaults.
pub fn resolve(
    args: &RenderArgs,
    file: Option<&FileSettings>,
    name: &str,
) -> Result<RenderOptions> {
    // A kind named on the command line over the file's (the rules in
    // `Integrator::chosen`, which the Python package shares).
    let integrator = Integrator::chosen(args.integrator, file.map(|f| f.integrator));
    let sampler = args.sampler.or(file.map(|f| f.sampler)).unwrap_or_default();
    let filter = match (args.filter, file) {
        (Some(kind), Some(f)) if f.filter.kind() == kind => f.filter,
        (Some(kind), _) => Filter::from(kind),
        (None, Some(f)) => f.filter,
        (None, None) => Filter::default(),
    };
    let tonemap = args.tonemap.or(file.map(|f| f.tonemap)).unwrap_or_default();
    let pick = |arg: Option<u32>, from_file: Option<u32>, default: u32| {
        arg.or(from_file).unwrap_or(default)
    };
    let width = pick(args.width, file.map(|f| f.width), DEFAULT_SIDE);
    let height = pick(args.height, file.map(|f| f.height), DEFAULT_SIDE);
    // With a time limit the samples are capped only where asked for.
    let spp = match (args.spp, file.map(|f| f.spp), args.time_limit) {
        (Some(n), _, _) => n,
        (None, _, Some(_)) => UNLIMITED_SPP,
        (None, from_file, None) => from_file.unwrap_or(DEFAULT_SPP),
    };
    let seed = args.seed.or(file.map(|f| f.seed)).unwrap_or(0);
    let exposure = args.exposure.or(file.map(|f| f.exposure)).unwrap_or(0.0);
    if !exposure.is_finite() {
        bail!("--exposure must be a finite number of stops");
    }
    let output = args
        .output
        .clone()
        .or_else(|| file.and_then(|f| f.output.clone()))
        .unwrap_or_else(|| PathBuf::from(format!("{name}.png")));
    // The command line's threshold over the file's; its minimum, else the
    // file's, else the default.
    let from_file = file.and_then(|f| f.adaptive);
    let adaptive = match args.noise_threshold {
        Some(threshold) => Some(Adaptive {
            threshold,
            min_spp: args
                .min_spp
                .or(from_file.map(|a| a.min_spp))
                .unwrap_or(Adaptive::DEFAULT_MIN_SPP),
        }),
        None => from_file,
    };
    let time_limit = match args.time_limit {
        Some(t) if !(t > 0.0 && t.is_finite()) => {
            bail!("--time-limit must be a positive number of seconds")
        }
        Some(t) => Some(Duration::from_secs_f64(t)),
        None => None,
    };
    Ok(RenderOptions {
        settings: RenderSettings {
            frame: FrameSettings {
                width,
                height,
                spp,
                pass_spp: args.pass_spp.unwrap_or(PASS_SPP).min(spp),
                seed,
                sampler,
                filter,
                integrator,
                adaptive,
            },
            time_limit,
            cancel: Some(Arc::new(AtomicBool::new(false))),
            build: args
                .builder
                .map_or_else(BuildParams::default, BuildParams::new),
            ..Default::default()
        },
        exposure,
        tonemap,
        output,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use sahara_render::{FilterKind, IntegratorKind, SamplerKind};

    fn file() -> FileSettings {
        FileSettings {
            integrator: Integrator::Distribution {
                max_depth: 3,
                light_samples: 9,
            },
            sampler: SamplerKind::Independent,
            spp: 5,
            seed: 11,
            filter: Filter::Box { radius: 0.7 },
            width: 40,
            height: 30,
            exposure: 1.5,
            tonemap: ToneMap::Filmic,
            output: Some(PathBuf::from("out/x.exr")),
            crop: None,
            adaptive: None,
            denoise: false,
        }
    }

    #[test]
    fn the_file_holds_unless_the_command_line_overrides() {
        let o = resolve(&RenderArgs::default(), Some(&file()), "s").unwrap();
        let s = &o.settings;
        assert_eq!((s.width, s.height, s.spp, s.seed), (40, 30, 5, 11));
        assert_eq!(s.integrator, file().integrator);
        assert_eq!(s.filter, Filter::Box { radius: 0.7 });
        assert_eq!((o.exposure, o.tonemap), (1.5, ToneMap::Filmic));
        assert_eq!(o.output, PathBuf::from("out/x.exr"));

        let args = RenderArgs {
            width: Some(8),
            spp: Some(2),
            integrator: Some(IntegratorKind::Distribution),
            filter: Some(FilterKind::Tent),
            output: Some("y.png".into()),
            ..Default::default()
        };
        let o = resolve(&args, Some(&file()), "s").unwrap();
        let s = &o.settings;
        assert_eq!((s.width, s.height, s.spp), (8, 30, 2));
        // Same integrator name: the file's parameters are kept.
        assert_eq!(s.integrator, file().integrator);
        assert_eq!(s.filter, Filter::from(FilterKind::Tent));
        assert_eq!(o.output, PathBuf::from("y.png"));
    }

    #[test]
    fn another_estimator_keeps_the_files_path_length() {
        let mut f = file();
        f.integrator = Integrator::Bdpt { max_depth: 20 };
        let with = |kind| {
            let args = RenderArgs {
                integrator: Some(kind),
                ..Default::default()
            };
            resolve(&args, Some(&f), "s").unwrap().settings.integrator
        };
        assert_eq!(
            with(IntegratorKind::Path),
            Integrator::Path {
                max_depth: 20,
                rr_depth: sahara_render::defaults::RR_DEPTH
            }
        );
        assert_eq!(with(IntegratorKind::LightPath).path_length(), Some(20));
        assert_eq!(with(IntegratorKind::Sppm).path_length(), Some(20));
        // `distribution` counts its depth otherwise: its default holds.
        assert_eq!(
            with(IntegratorKind::Distribution),
            Integrator::from(IntegratorKind::Distribution)
        );
        // And a file's `distribution` depth does not become a path length.
        let args = RenderArgs {
            integrator: Some(IntegratorKind::Path),
            ..Default::default()
        };
        let o = resolve(&args, Some(&file()), "s").unwrap();
        assert_eq!(
            o.settings.integrator,
            Integrator::from(IntegratorKind::Path)
        );
    }

    #[test]
    fn without_a_file_the_defaults_apply() {
        let o = resolve(&RenderArgs::default(), None, "cornell_box").unwrap();
        let s = &o.settings;
        assert_eq!((s.width, s.height, s.spp), (512, 512, 64));
        assert_eq!(s.integrator, Integrator::default());
        assert_eq!(o.output, PathBuf::from("cornell_box.png"));
    }
}
