//! The settings a caller gives, one entry each ([`SETTINGS`]): its name,
//! what it takes, its help, and where its value goes in the caller's
//! [`SettingsLayer`]. The command line makes one option of each entry
//! (`--noise-threshold T`) and the Python package one keyword argument
//! (`noise_threshold=`); both parse values here, so a setting, its
//! checks and its messages are written once.

use std::ops::Range;
use std::time::Duration;

use sahara_kd::{AccelKind, Builder};
use sahara_render::{
    AdaptiveChoice, Aov, FilterKind, Guiding, IntegratorKind, LightSampler, Named, PathLoop, Pick,
    SamplerKind, ToneMap,
};

use crate::description::{SettingsLayer, Split};

/// A value as a front end gives it: the command line's text, or a
/// Python value.
#[derive(Clone, Debug, PartialEq)]
pub enum Given {
    /// Text a person typed (every command-line value): read as the
    /// setting's kind, a number from its digits.
    Text(String),
    /// A Python `str` or path: a name, a path or a value spelled as text
    /// (a part `1/4`), but not a number (`spp="16"` is of the wrong kind).
    Str(String),
    /// A whole number.
    Whole(i128),
    /// A number.
    Number(f64),
    /// True or false (a command-line switch given, a Python `bool`).
    Flag(bool),
    /// A list or tuple.
    List(Vec<Given>),
}

/// Why a setting does not take a value: of the wrong kind (Python's
/// `TypeError`), or out of its range (`ValueError`). The message does not
/// name the setting: the front end does, in its own spelling.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Refused {
    /// A value of the wrong kind: what was expected.
    Type(String),
    /// A value the setting does not take: why.
    Value(String),
}

impl std::fmt::Display for Refused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Refused::Type(m) | Refused::Value(m) => f.write_str(m),
        }
    }
}

/// What a setting takes, as a command line's parser needs to know.
#[derive(Clone, Copy, Debug)]
pub enum Takes {
    /// One value.
    Value,
    /// One of these names.
    Name(fn() -> Vec<&'static str>),
    /// Any of these names, as a list (comma-separated on a command line,
    /// the option repeatable).
    Names(fn() -> Vec<&'static str>),
    /// Nothing: the setting is a switch, on when given.
    Switch,
}

/// One setting a caller gives.
pub struct Setting {
    /// Its name: `--<name with hyphens>` on the command line, the keyword
    /// argument `<name>` in Python (unless [`Setting::keyword`] says
    /// otherwise), and how messages name it.
    pub name: &'static str,
    /// Its Python keyword argument.
    pub keyword: &'static str,
    /// Its one-letter option on the command line (`-o`).
    pub short: Option<char>,
    /// What its value is called in `--help` (`N`, `SECS`).
    pub value_name: &'static str,
    /// What it takes.
    pub takes: Takes,
    /// What it does and its default, for `--help` and documents.
    pub help: &'static str,
    /// Another setting it needs beside it (`min_spp` needs
    /// `noise_threshold`).
    pub requires: Option<&'static str>,
    /// Puts a value into a layer.
    set: fn(&mut SettingsLayer, &Given) -> Result<(), Refused>,
}

impl Setting {
    /// Puts `value` into `layer`, or says why not.
    pub fn set(&self, layer: &mut SettingsLayer, value: &Given) -> Result<(), Refused> {
        (self.set)(layer, value)
    }

    /// Its command-line option, `--noise-threshold`.
    pub fn flag(&self) -> String {
        format!("--{}", self.name.replace('_', "-"))
    }

    /// The setting called `name`.
    pub fn named(name: &str) -> Option<&'static Setting> {
        SETTINGS.iter().find(|s| s.name == name)
    }

    /// The setting whose Python keyword is `keyword`.
    pub fn by_keyword(keyword: &str) -> Option<&'static Setting> {
        SETTINGS.iter().find(|s| s.keyword == keyword)
    }
}

impl std::fmt::Debug for Setting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Setting({})", self.name)
    }
}

/// Largest samples per pixel a caller may ask for.
pub const MAX_SPP: i128 = 1 << 20;

/// Largest image side in pixels.
pub const MAX_SIDE: i128 = 65536;

/// The settings a caller gives, in the order `--help` lists them.
pub static SETTINGS: &[Setting] = &[
    Setting {
        name: "output",
        keyword: "output",
        short: Some('o'),
        value_name: "FILE",
        takes: Takes::Value,
        help: "Output image; the format follows the extension (.png, .exr) [default: the scene \
               file's output, else <scene name>.png in the working folder; in Python, no file \
               unless named]",
        requires: None,
        set: |l, g| {
            l.path = Some(text(g)?.into());
            Ok(())
        },
    },
    Setting {
        name: "spp",
        keyword: "spp",
        short: None,
        value_name: "N",
        takes: Takes::Value,
        help: "Samples per pixel: exactly this many, the last pass shorter if need be \
               [default: the scene file's, else 64; with a time limit, no cap]",
        requires: None,
        set: |l, g| {
            l.frame.spp = Some(whole(g, 1, MAX_SPP)? as u32);
            Ok(())
        },
    },
    Setting {
        name: "noise_threshold",
        keyword: "noise_threshold",
        short: None,
        value_name: "T",
        takes: Takes::Value,
        help: "Adaptive sampling: a pixel stops taking samples once its estimated noise is \
               below T (relative to the square root of its brightness, as Cycles' noise \
               threshold: 0.01 is a good start, lower is cleaner), and spp becomes the cap; \
               pixels are tested after each pass",
        requires: None,
        set: |l, g| {
            let t = number(g)?;
            if !(t > 0.0 && t.is_finite()) {
                return Err(Refused::Value(
                    "must be a positive number (0.01 is a good start)".into(),
                ));
            }
            adaptive(l).threshold = Some(t as f32);
            Ok(())
        },
    },
    Setting {
        name: "min_spp",
        keyword: "min_spp",
        short: None,
        value_name: "N",
        takes: Takes::Value,
        help: "With a noise threshold: samples every pixel takes before it is first tested \
               [default: the scene file's, else 16]",
        requires: Some("noise_threshold"),
        set: |l, g| {
            adaptive(l).min_spp = Some(whole(g, 2, MAX_SPP)? as u32);
            Ok(())
        },
    },
    Setting {
        name: "pass_spp",
        keyword: "pass_spp",
        short: None,
        value_name: "N",
        takes: Takes::Value,
        help: "Samples per pixel in each progressive pass [default: min(spp, 8)]",
        requires: None,
        set: |l, g| {
            l.frame.pass_spp = Some(whole(g, 1, MAX_SPP)? as u32);
            Ok(())
        },
    },
    Setting {
        name: "width",
        keyword: "width",
        short: None,
        value_name: "WIDTH",
        takes: Takes::Value,
        help: "Image width in pixels [default: the scene file's, else 512]",
        requires: None,
        set: |l, g| {
            l.frame.width = Some(whole(g, 1, MAX_SIDE)? as u32);
            Ok(())
        },
    },
    Setting {
        name: "height",
        keyword: "height",
        short: None,
        value_name: "HEIGHT",
        takes: Takes::Value,
        help: "Image height in pixels [default: the scene file's, else 512]",
        requires: None,
        set: |l, g| {
            l.frame.height = Some(whole(g, 1, MAX_SIDE)? as u32);
            Ok(())
        },
    },
    Setting {
        name: "integrator",
        keyword: "integrator",
        short: None,
        value_name: "NAME",
        takes: Takes::Name(IntegratorKind::names),
        help: "Light transport, with its default parameters (or the scene file's, if it names \
               the same one; path, bdpt, lightpath and sppm keep the file's max_depth of any of \
               them) [default: the scene file's, else path]",
        requires: None,
        set: |l, g| {
            l.frame.integrator = Some(Pick::Kind(named(g)?));
            Ok(())
        },
    },
    Setting {
        name: "sampler",
        keyword: "sampler",
        short: None,
        value_name: "NAME",
        takes: Takes::Name(SamplerKind::names),
        help: "Sample generator [default: the scene file's, else sobol]",
        requires: None,
        set: |l, g| {
            l.frame.sampler = Some(named(g)?);
            Ok(())
        },
    },
    Setting {
        name: "path_loop",
        keyword: "path_loop",
        short: None,
        value_name: "NAME",
        takes: Takes::Name(PathLoop::names),
        help: "How the path tracer traces its samples: lanes (paths in SIMD lanes, 16 under \
               AVX-512, 8 under AVX2, refilled as paths end), lanes-no-refill, or scalar (the \
               reference the lanes are held to); auto takes the lanes where every material of \
               the scene is shaded in the lanes. The lanes' image equals the scalar one to \
               noise, not bit for bit [default: scalar]",
        requires: None,
        set: |l, g| {
            l.path_loop = Some(named(g)?);
            Ok(())
        },
    },
    Setting {
        name: "light_sampler",
        keyword: "light_sampler",
        short: None,
        value_name: "NAME",
        takes: Takes::Name(LightSampler::names),
        help: "How next-event estimation chooses a light: tree (by power, distance and \
               orientation from the shading point), power, or uniform [default: tree]",
        requires: None,
        set: |l, g| {
            l.frame.light_sampler = Some(named(g)?);
            Ok(())
        },
    },
    Setting {
        name: "guiding",
        keyword: "guiding",
        short: None,
        value_name: "WHEN",
        takes: Takes::Name(Guiding::names),
        help: "Path guiding (path integrator): learn where light comes from as the render goes \
               and sample bounces by it; on, off, or auto (on where it applies: path without \
               media, a whole frame, no adaptive sampling) [default: off]",
        requires: None,
        set: |l, g| {
            l.frame.guiding = Some(named(g)?);
            Ok(())
        },
    },
    Setting {
        name: "filter",
        keyword: "filter",
        short: None,
        value_name: "NAME",
        takes: Takes::Name(FilterKind::names),
        help: "Reconstruction filter, with its default parameters (or the scene file's, if it \
               names the same one) [default: the scene file's, else gaussian; box when \
               denoising]",
        requires: None,
        set: |l, g| {
            l.frame.filter = Some(Pick::Kind(named(g)?));
            Ok(())
        },
    },
    Setting {
        name: "seed",
        keyword: "seed",
        short: None,
        value_name: "SEED",
        takes: Takes::Value,
        help: "Seed of every random decision (same seed, same image, bit for bit) [default: \
               the scene file's, else 0]",
        requires: None,
        set: |l, g| {
            l.frame.seed = Some(whole(g, 0, i128::from(u64::MAX))? as u64);
            Ok(())
        },
    },
    Setting {
        name: "time_limit",
        keyword: "time_limit",
        short: None,
        value_name: "SECS",
        takes: Takes::Value,
        help: "Render progressive passes until this many seconds have passed (for equal-time \
               comparisons), or until spp samples if it is given",
        requires: None,
        set: |l, g| {
            let t = number(g)?;
            if !(t > 0.0 && t.is_finite() && t < 1e12) {
                return Err(Refused::Value(
                    "must be a positive number of seconds".into(),
                ));
            }
            l.time_limit = Some(Duration::from_secs_f64(t));
            Ok(())
        },
    },
    Setting {
        name: "accel",
        keyword: "accel",
        short: None,
        value_name: "NAME",
        takes: Takes::Name(|| vec!["bvh", "kd"]),
        help: "The acceleration structure: bvh (the eight-wide hierarchy) or kd (the \
               kd-tree); a speed setting only, the image is the same with either [default: bvh]",
        requires: None,
        set: |l, g| {
            let name = text(g)?;
            l.accel = Some(AccelKind::parse(name).ok_or_else(|| {
                Refused::Value(format!("unknown structure '{name}'; expected bvh or kd"))
            })?);
            Ok(())
        },
    },
    Setting {
        name: "builder",
        keyword: "builder",
        short: None,
        value_name: "NAME",
        takes: Takes::Value,
        help: "Kd-tree builder (as for `sahara bench`), for --accel kd: a speed setting only, \
               the image is the same with any [default: sah]",
        requires: None,
        set: |l, g| {
            let name = text(g)?;
            l.builder = Some(Builder::parse(name).ok_or_else(|| {
                Refused::Value(format!(
                    "unknown builder '{name}'; expected one of: sah, binned, binnedN (N = \
                     2..=1024), rr-middle, rr-median, largest-middle, largest-median, middle, \
                     median"
                ))
            })?);
            Ok(())
        },
    },
    Setting {
        name: "exposure",
        keyword: "exposure",
        short: None,
        value_name: "STOPS",
        takes: Takes::Value,
        help: "Exposure in stops, for PNG output [default: the scene file's, else 0]",
        requires: None,
        set: |l, g| {
            let e = number(g)?;
            if !(e.is_finite() && e.abs() < 1e6) {
                return Err(Refused::Value("must be a finite number of stops".into()));
            }
            l.output.exposure = Some(e as f32);
            Ok(())
        },
    },
    Setting {
        name: "tonemap",
        keyword: "tonemap",
        short: None,
        value_name: "NAME",
        takes: Takes::Name(ToneMap::names),
        help: "Tone map for PNG output [default: the scene file's, else clamp]",
        requires: None,
        set: |l, g| {
            l.output.tonemap = Some(named(g)?);
            Ok(())
        },
    },
    Setting {
        name: "part",
        keyword: "part",
        short: None,
        value_name: "I/N",
        takes: Takes::Value,
        help: "Render part I (0-based) of N of the frame, divided as split says, and write it \
               as a part file (.exr) for `sahara merge`",
        requires: None,
        set: |l, g| {
            l.piece.part = Some(part(g)?);
            Ok(())
        },
    },
    Setting {
        name: "split",
        keyword: "split",
        short: None,
        value_name: "HOW",
        takes: Takes::Name(|| Split::ALL.iter().map(|s| s.name()).collect()),
        help: "How a part divides the frame: tiles (pixel regions) or samples (ranges of every \
               pixel's samples) [default: tiles]",
        requires: Some("part"),
        set: |l, g| {
            let name = text(g)?;
            l.piece.split = Some(
                Split::ALL
                    .into_iter()
                    .find(|s| s.name() == name)
                    .ok_or_else(|| {
                        Refused::Value(format!("unknown split '{name}'; expected tiles or samples"))
                    })?,
            );
            Ok(())
        },
    },
    Setting {
        name: "crop",
        keyword: "crop",
        short: None,
        value_name: "X0,X1,Y0,Y1",
        takes: Takes::Value,
        help: "Render only the crop window X0,X1,Y0,Y1, fractions of the image (y from the \
               top; pixel bounds rounded up, as pbrt-v4's); writes a part file. With a part \
               split by tiles, the tiles divide the crop window",
        requires: None,
        set: |l, g| {
            l.piece.crop = Some(crop(g)?);
            Ok(())
        },
    },
    Setting {
        name: "samples",
        keyword: "samples",
        short: None,
        value_name: "START..END",
        takes: Takes::Value,
        help: "Render only sample indices START..END of every pixel (counted over all passes, \
               0..spp); writes a part file. With a part split by samples, the parts divide this \
               range",
        requires: None,
        set: |l, g| {
            l.piece.samples = Some(sample_range(g)?);
            Ok(())
        },
    },
    Setting {
        name: "aov",
        keyword: "aovs",
        short: None,
        value_name: "LIST",
        takes: Takes::Names(Aov::names),
        help: "Render passes to make beside the beauty (written as layers of an EXR): albedo \
               (albedo.R/G/B), normal (normal.X/Y/Z, world space), depth (depth.Z, camera \
               distance), position (position.X/Y/Z, world space), uv (uv.U/V), variance \
               (variance.R/G/B, of the pixel's estimate), object and material (ids, with a list \
               of names beside the image)",
        requires: None,
        set: |l, g| {
            let list: Vec<Aov> = names(g)?;
            l.output.aovs = (!list.is_empty()).then_some(list);
            Ok(())
        },
    },
    Setting {
        name: "denoise",
        keyword: "denoise",
        short: None,
        value_name: "",
        takes: Takes::Switch,
        help: "Denoise the image with Intel Open Image Denoise, guided by the albedo and normal \
               of what each pixel sees (the library is loaded when found: `pip install \
               pyoidn`, or OIDN_DIR); an EXR keeps the noisy image as the layer `noisy` \
               (noisy.R/G/B)",
        requires: None,
        set: |l, g| {
            // Off is not given: a scene file's `denoise` holds.
            l.output.denoise = switch(g)?.then_some(true);
            Ok(())
        },
    },
];

/// The layer's adaptive sampling, made if need be.
fn adaptive(l: &mut SettingsLayer) -> &mut AdaptiveChoice {
    l.frame.adaptive.get_or_insert_with(AdaptiveChoice::default)
}

/// What a value of the wrong kind is called.
fn kind_of(g: &Given) -> &'static str {
    match g {
        Given::Text(_) => "text",
        Given::Str(_) => "str",
        Given::Whole(_) => "a whole number",
        Given::Number(_) => "a number",
        Given::Flag(_) => "a truth value",
        Given::List(_) => "a list",
    }
}

/// Text.
fn text(g: &Given) -> Result<&str, Refused> {
    match g {
        Given::Text(t) | Given::Str(t) => Ok(t),
        other => Err(Refused::Type(format!(
            "expected text, got {}",
            kind_of(other)
        ))),
    }
}

/// A whole number in `min..=max`.
fn whole(g: &Given, min: i128, max: i128) -> Result<i128, Refused> {
    let v = match g {
        Given::Whole(v) => *v,
        Given::Text(t) => t
            .trim()
            .parse::<i128>()
            .map_err(|_| Refused::Value(format!("'{t}' is not a whole number")))?,
        other => {
            return Err(Refused::Type(format!(
                "expected a whole number, got {}",
                kind_of(other)
            )))
        }
    };
    if (min..=max).contains(&v) {
        Ok(v)
    } else {
        Err(Refused::Value(format!("{v} is not in {min}..={max}")))
    }
}

/// A number.
fn number(g: &Given) -> Result<f64, Refused> {
    match g {
        Given::Whole(v) => Ok(*v as f64),
        Given::Number(v) => Ok(*v),
        Given::Text(t) => t
            .trim()
            .parse::<f64>()
            .map_err(|_| Refused::Value(format!("'{t}' is not a number"))),
        other => Err(Refused::Type(format!(
            "expected a number, got {}",
            kind_of(other)
        ))),
    }
}

/// A name of `T`'s table.
fn named<T: Named>(g: &Given) -> Result<T, Refused> {
    T::from_name(text(g)?).map_err(|e| Refused::Value(e.to_string()))
}

/// Names of `T`'s table: a comma-separated text, or a list of names.
fn names<T: Named>(g: &Given) -> Result<Vec<T>, Refused> {
    match g {
        Given::Text(t) | Given::Str(t) => t
            .split(',')
            .map(str::trim)
            .filter(|n| !n.is_empty())
            .map(|n| T::from_name(n).map_err(|e| Refused::Value(e.to_string())))
            .collect(),
        Given::List(items) => items.iter().map(named).collect(),
        other => Err(Refused::Type(format!(
            "expected a name or a list of names, got {}",
            kind_of(other)
        ))),
    }
}

/// A switch: on or off.
fn switch(g: &Given) -> Result<bool, Refused> {
    match g {
        Given::Flag(b) => Ok(*b),
        other => Err(Refused::Type(format!(
            "expected True or False, got {}",
            kind_of(other)
        ))),
    }
}

/// The numbers of a list (or of a text split at `sep`).
fn numbers(g: &Given, sep: &str) -> Option<Vec<f64>> {
    match g {
        Given::Text(t) | Given::Str(t) => t.split(sep).map(|p| p.trim().parse().ok()).collect(),
        Given::List(items) => items.iter().map(|i| number(i).ok()).collect(),
        _ => None,
    }
}

/// Part `I/N` with `I < N`: the text `I/N` or a pair.
fn part(g: &Given) -> Result<(u32, u32), Refused> {
    let bad = || {
        Refused::Value(format!(
            "'{}' is not a part I/N with 0 <= I < N (I counts from 0)",
            shown(g)
        ))
    };
    let v = numbers(g, "/").ok_or_else(bad)?;
    match v[..] {
        [i, n] if i.fract() == 0.0 && n.fract() == 0.0 && 0.0 <= i && i < n && n <= 1e9 => {
            Ok((i as u32, n as u32))
        }
        _ => Err(bad()),
    }
}

/// A crop window `x0,x1,y0,y1` of fractions, `x0 <= x1`, `y0 <= y1`.
fn crop(g: &Given) -> Result<[f64; 4], Refused> {
    let bad = || {
        Refused::Value(format!(
            "'{}' is not a crop window x0,x1,y0,y1 of fractions in [0, 1] with x0 <= x1, \
             y0 <= y1",
            shown(g)
        ))
    };
    let v = numbers(g, ",").ok_or_else(bad)?;
    match v[..] {
        [x0, x1, y0, y1] if v.iter().all(|f| (0.0..=1.0).contains(f)) && x0 <= x1 && y0 <= y1 => {
            Ok([x0, x1, y0, y1])
        }
        _ => Err(bad()),
    }
}

/// A sample range `START..END`, `START <= END`: the text or a pair.
fn sample_range(g: &Given) -> Result<Range<u32>, Refused> {
    let bad = || {
        Refused::Value(format!(
            "'{}' is not a sample range START..END with START <= END",
            shown(g)
        ))
    };
    let v = numbers(g, "..").ok_or_else(bad)?;
    let whole = |x: f64| x.fract() == 0.0 && (0.0..=u32::MAX as f64).contains(&x);
    match v[..] {
        [a, b] if whole(a) && whole(b) && a <= b => Ok(a as u32..b as u32),
        _ => Err(bad()),
    }
}

/// A value as a message shows it.
fn shown(g: &Given) -> String {
    match g {
        Given::Text(t) | Given::Str(t) => t.clone(),
        Given::Whole(v) => v.to_string(),
        Given::Number(v) => v.to_string(),
        Given::Flag(b) => b.to_string(),
        Given::List(items) => items.iter().map(shown).collect::<Vec<_>>().join(", "),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sahara_render::{defaults, Adaptive};

    fn set(name: &str, g: Given) -> Result<SettingsLayer, Refused> {
        let mut l = SettingsLayer::default();
        Setting::named(name).expect(name).set(&mut l, &g)?;
        Ok(l)
    }

    fn text(s: &str) -> Given {
        Given::Text(s.into())
    }

    #[test]
    fn the_command_lines_text_and_pythons_values_set_the_same_layer() {
        let same = [
            ("spp", text("16"), Given::Whole(16)),
            ("noise_threshold", text("0.05"), Given::Number(0.05)),
            ("time_limit", text("2"), Given::Whole(2)),
            (
                "part",
                text("1/4"),
                Given::List(vec![Given::Whole(1), Given::Whole(4)]),
            ),
            (
                "crop",
                text("0,0.5,0.25,1"),
                Given::List(vec![
                    Given::Whole(0),
                    Given::Number(0.5),
                    Given::Number(0.25),
                    Given::Whole(1),
                ]),
            ),
            (
                "samples",
                text("2..6"),
                Given::List(vec![Given::Whole(2), Given::Whole(6)]),
            ),
            ("path_loop", text("scalar"), Given::Str("scalar".into())),
            (
                "aov",
                text("depth,albedo"),
                Given::List(vec![text("depth"), text("albedo")]),
            ),
        ];
        for (name, a, b) in same {
            assert_eq!(set(name, a).unwrap(), set(name, b).unwrap(), "{name}");
        }
        let l = set("noise_threshold", text("0.05")).unwrap();
        assert_eq!(
            l.frame.apply(Default::default()).decided().adaptive,
            Some(Adaptive {
                threshold: 0.05,
                min_spp: Adaptive::DEFAULT_MIN_SPP
            })
        );
        assert_eq!(
            set("seed", Given::Whole(u64::MAX.into()))
                .unwrap()
                .frame
                .seed,
            Some(u64::MAX)
        );
        assert_eq!(
            set("denoise", Given::Flag(false)).unwrap().output.denoise,
            None
        );
        assert_eq!(
            set("integrator", text("sppm")).unwrap().frame.integrator,
            Some(Pick::Kind(IntegratorKind::Sppm))
        );
    }

    #[test]
    fn bad_values_are_refused_saying_why_and_wrong_kinds_saying_what_was_expected() {
        let refused = |name, g| set(name, g).unwrap_err();
        assert_eq!(
            refused("spp", text("0")),
            Refused::Value("0 is not in 1..=1048576".into())
        );
        assert_eq!(
            refused("spp", Given::Whole(-1)),
            Refused::Value("-1 is not in 1..=1048576".into())
        );
        assert!(matches!(
            refused("spp", Given::Number(2.5)),
            Refused::Type(_)
        ));
        assert_eq!(
            refused("width", Given::Whole(100_000)),
            Refused::Value("100000 is not in 1..=65536".into())
        );
        assert!(refused("sampler", text("halton"))
            .to_string()
            .contains("unknown sampler 'halton'"));
        assert!(refused("time_limit", text("-1"))
            .to_string()
            .contains("positive number of seconds"));
        assert!(refused("part", text("2/2"))
            .to_string()
            .contains("not a part I/N"));
        assert!(refused("crop", text("0.5,0.2,0,1"))
            .to_string()
            .contains("not a crop window"));
        assert!(refused("builder", text("bvh"))
            .to_string()
            .contains("unknown builder 'bvh'"));
        assert!(refused("accel", text("octree"))
            .to_string()
            .contains("unknown structure 'octree'"));
        assert!(refused("path_loop", text("wide"))
            .to_string()
            .contains("unknown path loop 'wide'"));
        assert!(matches!(
            refused("denoise", Given::Whole(1)),
            Refused::Type(_)
        ));
    }

    #[test]
    fn every_setting_has_one_name_keyword_and_option() {
        for (i, s) in SETTINGS.iter().enumerate() {
            for t in &SETTINGS[i + 1..] {
                assert_ne!(s.name, t.name);
                assert_ne!(s.keyword, t.keyword);
            }
            if let Some(r) = s.requires {
                assert!(Setting::named(r).is_some(), "{}", s.name);
            }
            assert!(!s.help.is_empty(), "{}", s.name);
        }
        assert_eq!(Setting::by_keyword("aovs").unwrap().flag(), "--aov");
        // The defaults the help gives are the defaults.
        let spp = Setting::named("spp").unwrap().help;
        assert!(spp.contains(&format!("else {}", defaults::SPP)), "{spp}");
        let min = Setting::named("min_spp").unwrap().help;
        assert!(
            min.contains(&format!("else {}", Adaptive::DEFAULT_MIN_SPP)),
            "{min}"
        );
        let side = sahara_render::FrameSettings::default().width;
        for name in ["width", "height"] {
            let help = Setting::named(name).unwrap().help;
            assert!(help.contains(&format!("else {side}")), "{help}");
        }
        let pass = Setting::named("pass_spp").unwrap().help;
        assert!(
            pass.contains(&format!("min(spp, {})", defaults::PASS_SPP)),
            "{pass}"
        );
    }
}
