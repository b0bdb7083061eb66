//! The settings of a render: the command line over the scene file over the defaults.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

use anyhow::{anyhow, bail, Result};
use sahara_formats::scene_load::FileSettings;
use sahara_kd::BuildParams;
use sahara_render::{Filter, Integrator, RenderSettings, SamplerKind, ToneMap};

use crate::cli::RenderArgs;

/// Samples per pixel when neither the command line nor a scene file says
/// (the renderer's default, which scene files use too).
pub const DEFAULT_SPP: u32 = sahara_render::integrator::defaults::SPP;
/// Image side in pixels when neither the command line nor a scene file says.
pub const DEFAULT_SIDE: u32 = 512;

/// Everything decided about a render before it starts.
#[derive(Debug)]
pub struct RenderOptions {
    /// What the renderer is given.
    pub settings: RenderSettings,
    /// Name of the sampler, for the summary line.
    pub sampler_name: &'static str,
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
    let integrator = match (&args.integrator, file) {
        (Some(n), f) => {
            let i = integrator_named(n)?;
            // Same name as the file's: keep the file's parameters.
            match f {
                Some(f) if f.integrator.name() == i.name() => f.integrator,
                _ => i,
            }
        }
        (None, Some(f)) => f.integrator,
        (None, None) => Integrator::default(),
    };
    let sampler = match (&args.sampler, file) {
        (Some(n), _) => sampler_named(n)?,
        (None, Some(f)) => f.sampler,
        (None, None) => SamplerKind::Sobol,
    };
    let filter = match (&args.filter, file) {
        (Some(n), f) => {
            let named = filter_named(n)?;
            match f {
                Some(f) if std::mem::discriminant(&f.filter) == std::mem::discriminant(&named) => {
                    f.filter
                }
                _ => named,
            }
        }
        (None, Some(f)) => f.filter,
        (None, None) => Filter::default(),
    };
    let tonemap = match (&args.tonemap, file) {
        (Some(n), _) => match n.as_str() {
            "clamp" => ToneMap::Clamp,
            "filmic" => ToneMap::Filmic,
            t => bail!("unknown tone map '{t}'; expected clamp or filmic"),
        },
        (None, Some(f)) => f.tonemap,
        (None, None) => ToneMap::Clamp,
    };
    let pick = |arg: Option<u32>, from_file: Option<u32>, default: u32| {
        arg.or(from_file).unwrap_or(default)
    };
    let width = pick(args.width, file.map(|f| f.width), DEFAULT_SIDE);
    let height = pick(args.height, file.map(|f| f.height), DEFAULT_SIDE);
    let spp_total = pick(args.spp, file.map(|f| f.spp), DEFAULT_SPP);
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
    let (spp, passes, time_limit) = match args.time_limit {
        Some(t) if !(t > 0.0 && t.is_finite()) => {
            bail!("--time-limit must be a positive number of seconds")
        }
        Some(t) => (spp_total, u32::MAX, Some(Duration::from_secs_f64(t))),
        None => {
            let per_pass = args.pass_spp.unwrap_or(spp_total.min(8)).min(spp_total);
            (per_pass, spp_total.div_ceil(per_pass), None)
        }
    };
    Ok(RenderOptions {
        settings: RenderSettings {
            width,
            height,
            spp,
            passes,
            time_limit,
            cancel: Some(Arc::new(AtomicBool::new(false))),
            seed,
            sampler,
            filter,
            integrator,
            build: args
                .builder
                .map_or_else(BuildParams::default, BuildParams::new),
            ..Default::default()
        },
        sampler_name: match sampler {
            SamplerKind::Independent => "independent",
            SamplerKind::Stratified => "stratified",
            SamplerKind::Sobol => "sobol",
        },
        exposure,
        tonemap,
        output,
    })
}

/// The integrator called `name`, with its default parameters.
fn integrator_named(name: &str) -> Result<Integrator> {
    Integrator::from_name(name).ok_or_else(|| {
        anyhow!(
            "unknown integrator '{name}'; expected path, distribution, normals, depth, ao or cost"
        )
    })
}

/// The sampler called `name`.
fn sampler_named(name: &str) -> Result<SamplerKind> {
    Ok(match name {
        "independent" => SamplerKind::Independent,
        "stratified" => SamplerKind::Stratified,
        "sobol" => SamplerKind::Sobol,
        s => bail!("unknown sampler '{s}'; expected independent, stratified or sobol"),
    })
}

/// The filter called `name`, with its default parameters.
fn filter_named(name: &str) -> Result<Filter> {
    Ok(match name {
        "box" => Filter::box_filter(),
        "tent" => Filter::tent(),
        "gaussian" => Filter::default(),
        "mitchell" => Filter::mitchell(),
        f => bail!("unknown filter '{f}'; expected box, tent, gaussian or mitchell"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

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
        }
    }

    #[test]
    fn the_file_holds_unless_the_command_line_overrides() {
        let o = resolve(&RenderArgs::default(), Some(&file()), "s").unwrap();
        let s = &o.settings;
        assert_eq!(
            (s.width, s.height, s.spp * s.passes, s.seed),
            (40, 30, 5, 11)
        );
        assert_eq!(s.integrator, file().integrator);
        assert_eq!(s.filter, Filter::Box { radius: 0.7 });
        assert_eq!((o.exposure, o.tonemap), (1.5, ToneMap::Filmic));
        assert_eq!(o.output, PathBuf::from("out/x.exr"));

        let args = RenderArgs {
            width: Some(8),
            spp: Some(2),
            integrator: Some("distribution".into()),
            filter: Some("tent".into()),
            output: Some("y.png".into()),
            ..Default::default()
        };
        let o = resolve(&args, Some(&file()), "s").unwrap();
        let s = &o.settings;
        assert_eq!((s.width, s.height, s.spp * s.passes), (8, 30, 2));
        // Same integrator name: the file's parameters are kept.
        assert_eq!(s.integrator, file().integrator);
        assert_eq!(s.filter, Filter::tent());
        assert_eq!(o.output, PathBuf::from("y.png"));
    }

    #[test]
    fn without_a_file_the_defaults_apply() {
        let o = resolve(&RenderArgs::default(), None, "cornell_box").unwrap();
        let s = &o.settings;
        assert_eq!((s.width, s.height, s.spp * s.passes), (512, 512, 64));
        assert_eq!(s.integrator, Integrator::default());
        assert_eq!(o.output, PathBuf::from("cornell_box.png"));
    }

    #[test]
    fn unknown_names_are_clear_errors() {
        for (args, what) in [
            (
                RenderArgs {
                    integrator: Some("whitted".into()),
                    ..Default::default()
                },
                "unknown integrator 'whitted'",
            ),
            (
                RenderArgs {
                    sampler: Some("halton".into()),
                    ..Default::default()
                },
                "unknown sampler 'halton'",
            ),
            (
                RenderArgs {
                    filter: Some("lanczos".into()),
                    ..Default::default()
                },
                "unknown filter 'lanczos'",
            ),
            (
                RenderArgs {
                    tonemap: Some("reinhard".into()),
                    ..Default::default()
                },
                "unknown tone map 'reinhard'",
            ),
        ] {
            let e = resolve(&args, None, "s").unwrap_err().to_string();
            assert!(e.contains(what), "{e}");
        }
    }
}
