//! Render parts: a piece of a frame (a pixel window and a sample range) as
//! an OpenEXR file holding its exact sums, for `sahara merge`.
//!
//! The file is a single-part scanline EXR the size of the window (1 x 1,
//! all zero, for a window without pixels) with 16 `UINT` channels: each of
//! the four 128-bit fixed-point sums of a pixel
//! ([`sahara_render::PixelSum`]: R, G, B and the weight) as four 32-bit
//! words, `sum.R.w0` (least significant) to `sum.R.w3`, then `sum.G.*`,
//! `sum.B.*` and `weight.w*`. The render passes' sums follow in the same
//! form, each under its pass's name (`albedo.sum.R.w0` ... `albedo.weight.w3`;
//! the variance's two buffers as `variance.sum.*` and `variance.square.*`),
//! with adaptive sampling each pixel's sample count as `samples.n`, and the
//! object and material ids as `object.id` and `material.id`.
//! What the merge needs to know of it is in string attributes
//! ([`PartInfo`]): the whole frame's settings ([`FrameSettings`], each
//! filter and integrator parameter as `sahara:filter:<name>` and
//! `sahara:integrator:<name>`) and how it is written ([`OutputSettings`]),
//! so the merged frame is written as the frame rendered whole would be.
//! It is written atomically.

use std::io::{BufWriter, Read, Write};
use std::ops::Range;
use std::path::Path;

use exr::meta::attribute::{AttributeValue, Text};
use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer, LayerAttributes, SmallVec,
    WritableImage,
};
use sahara_readers::FormatError;
use sahara_render::{
    Adaptive, Aov, Aux, AuxSums, Filter, FilterKind, FrameSettings, Guiding, Integrator,
    IntegratorKind, LightSampler, Named, Parameter, PixelSum, PixelWindow, SumBuffer,
};

use crate::output::atomic::write_atomically;
use crate::output::frame::OutputSettings;

/// The value of `sahara:format` in a part file.
const FORMAT: &str = "sahara render part 2";

/// Largest frame side a part may describe (as for `sahara render`).
const MAX_SIDE: u32 = 65536;

/// What a part file says about itself.
#[derive(Clone, Debug, PartialEq)]
pub struct PartInfo {
    /// Digest of the scene and of the settings that change pixels
    /// ([`sahara_render::frame_digest`]).
    pub digest: String,
    /// The whole frame's settings: size, samples per pixel (of the whole
    /// frame), seed, sampler, filter, integrator, adaptive sampling.
    pub frame: FrameSettings,
    /// How the merged frame is written: exposure and tone map for a PNG,
    /// the render passes written as layers (sorted; the denoiser's albedo
    /// and normal are held without being written), whether it is
    /// denoised (parts never are).
    pub output: OutputSettings,
    /// The pixels this part holds.
    pub window: PixelWindow,
    /// The sample indices this part was asked to render.
    pub samples: Range<u32>,
    /// The sample indices its sums hold: `samples` when complete, a
    /// prefix of it when interrupted.
    pub samples_done: Range<u32>,
    /// False if the render was interrupted: the part must not be taken for
    /// a finished one.
    pub complete: bool,
    /// How the part was chosen, e.g. `3/8 tiles` (empty if by hand).
    pub part: String,
    /// The render passes whose sums the part holds (sorted).
    pub passes: Vec<Aov>,
    /// True if the denoiser is to clean the albedo and normal first
    /// (depth of field or motion blur make them noisy).
    pub noisy_guides: bool,
    /// The list of names of the object and material passes (JSON, ASCII;
    /// empty without those passes).
    pub names: String,
    /// Render statistics as (name, value) pairs, kept for people.
    pub stats: Vec<(String, String)>,
}

/// The pixels of a part: the beauty's sums, the passes' sums and, with
/// adaptive sampling, each pixel's sample count, all over its window.
#[derive(Clone, Debug, PartialEq)]
pub struct PartSums {
    /// The beauty's sums.
    pub beauty: SumBuffer,
    /// The sums of the passes named by [`PartInfo::passes`] (the others
    /// `None`).
    pub passes: AuxSums,
    /// Samples per pixel, rows top to bottom, if
    /// [`PartInfo::sample_counts`].
    pub samples: Option<Vec<u32>>,
    /// The object ids of the pixels, if [`PartInfo::passes`] names
    /// [`Aov::Object`] (rows top to bottom).
    pub object: Option<Vec<u32>>,
    /// The material ids of the pixels, if [`PartInfo::passes`] names
    /// [`Aov::Material`].
    pub material: Option<Vec<u32>>,
}

impl PartSums {
    /// Sums of the beauty alone.
    pub fn beauty(beauty: SumBuffer) -> Self {
        Self {
            beauty,
            passes: AuxSums::default(),
            samples: None,
            object: None,
            material: None,
        }
    }

    /// The passes it holds: those with sums, then the ids.
    fn passes(&self) -> Vec<Aov> {
        let mut p = self.passes.passes();
        p.extend(self.object.as_ref().map(|_| Aov::Object));
        p.extend(self.material.as_ref().map(|_| Aov::Material));
        p.sort();
        p
    }

    /// The channels of whole numbers per pixel: sample counts and ids.
    fn counts(&self) -> Vec<(&'static str, &Vec<u32>)> {
        [
            (SAMPLES_CHANNEL, &self.samples),
            (OBJECT_CHANNEL, &self.object),
            (MATERIAL_CHANNEL, &self.material),
        ]
        .into_iter()
        .filter_map(|(name, v)| Some((name, v.as_ref()?)))
        .collect()
    }

    /// Each sum buffer with the prefix of its channels, beauty first.
    fn buffers(&self) -> Vec<(String, &SumBuffer)> {
        let mut out = vec![(String::new(), &self.beauty)];
        out.extend(
            self.passes
                .buffers()
                .into_iter()
                .map(|(_, name, b)| (format!("{name}."), b)),
        );
        out
    }
}

/// Empty sums over `window` for `passes`.
fn empty_passes(passes: &[Aov], window: &PixelWindow) -> AuxSums {
    let w = window;
    Aux::new(passes, w.x0, w.y0, w.width(), w.height()).sums
}

/// A list of passes as the header writes it: names joined by commas.
fn pass_list(passes: &[Aov]) -> String {
    passes
        .iter()
        .map(|a| a.name())
        .collect::<Vec<_>>()
        .join(",")
}

impl PartInfo {
    /// True if the part holds each pixel's sample count (adaptive
    /// sampling).
    pub fn sample_counts(&self) -> bool {
        self.frame.adaptive.is_some()
    }

    /// The attributes of the file.
    fn attributes(&self) -> Vec<(String, String)> {
        let (w, f, o) = (&self.window, &self.frame, &self.output);
        let mut a = vec![
            ("sahara:format".to_string(), FORMAT.to_string()),
            ("sahara:digest".into(), self.digest.clone()),
            ("sahara:frame".into(), format!("{}x{}", f.width, f.height)),
            ("sahara:spp".into(), f.spp.to_string()),
            ("sahara:pass_spp".into(), f.pass_spp.to_string()),
            (
                "sahara:window".into(),
                format!("{},{},{},{}", w.x0, w.x1, w.y0, w.y1),
            ),
            ("sahara:samples".into(), range(&self.samples)),
            ("sahara:samples_done".into(), range(&self.samples_done)),
            ("sahara:complete".into(), self.complete.to_string()),
            ("sahara:partial".into(), (!self.complete).to_string()),
            ("sahara:part".into(), self.part.clone()),
            ("sahara:seed".into(), f.seed.to_string()),
            ("sahara:sampler".into(), f.sampler.to_string()),
            ("sahara:light_sampler".into(), f.light_sampler.to_string()),
            ("sahara:guiding".into(), f.guiding.to_string()),
            ("sahara:exposure".into(), o.exposure.to_string()),
            ("sahara:tonemap".into(), o.tonemap.to_string()),
            ("sahara:passes".into(), pass_list(&self.passes)),
            ("sahara:aovs".into(), pass_list(&o.aovs)),
            ("sahara:denoise".into(), o.denoise.to_string()),
            ("sahara:noisy_guides".into(), self.noisy_guides.to_string()),
            ("sahara:names".into(), self.names.clone()),
        ];
        let kinds = [
            (
                "filter",
                f.filter.name(),
                f.filter.kind().parameters(),
                f.filter.parameters(),
            ),
            (
                "integrator",
                f.integrator.name(),
                f.integrator.kind().parameters(),
                f.integrator.parameters(),
            ),
        ];
        for (what, name, keys, values) in kinds {
            a.push((format!("sahara:{what}"), name.to_string()));
            for (p, v) in keys.iter().zip(values) {
                a.push((format!("sahara:{what}:{}", p.name), v.to_string()));
            }
        }
        if let Some(adaptive) = f.adaptive {
            a.push((
                "sahara:noise_threshold".into(),
                adaptive.threshold.to_string(),
            ));
            a.push(("sahara:min_spp".into(), adaptive.min_spp.to_string()));
        }
        a.extend(
            self.stats
                .iter()
                .map(|(k, v)| (format!("sahara:stats:{k}"), v.clone())),
        );
        a
    }

    /// Parses the attributes of the file `name`.
    fn parse(name: &str, get: &dyn Fn(&str) -> Option<String>) -> Result<PartInfo, FormatError> {
        let h = Header { name, get };
        let format = h.need("sahara:format")?;
        if format != FORMAT {
            return Err(FormatError::in_file(
                name,
                format!(
                    "a render part of another format ({format:?}; this sahara reads {FORMAT:?})"
                ),
            ));
        }
        let (width, height) = h.frame()?;
        let spp: u32 = h.parsed("sahara:spp")?;
        let window = h.window(width, height)?;
        let samples = h.range("sahara:samples", spp)?;
        let samples_done = h.range("sahara:samples_done", spp)?;
        if samples_done.start != samples.start || samples_done.end > samples.end {
            return Err(h.bad("sahara:samples_done", &range(&samples_done)));
        }
        let complete = match h.need("sahara:complete")?.as_str() {
            "true" => true,
            "false" => false,
            v => return Err(h.bad("sahara:complete", v)),
        };
        let held = h.passes("sahara:passes")?;
        let aovs = h.passes("sahara:aovs")?;
        let denoise = h.flag("sahara:denoise")?;
        if let Some(a) = aovs.iter().find(|a| !held.contains(a)) {
            return Err(h.bad("sahara:aovs", a.name()));
        }
        if denoise && !(held.contains(&Aov::Albedo) && held.contains(&Aov::Normal)) {
            return Err(h.bad("sahara:passes", &pass_list(&held)));
        }
        if complete && samples_done != samples {
            return Err(h.bad("sahara:samples_done", &range(&samples_done)));
        }
        let adaptive = match get("sahara:noise_threshold") {
            None => None,
            Some(_) => Some(Adaptive {
                threshold: h.finite("sahara:noise_threshold")?,
                min_spp: h.parsed("sahara:min_spp")?,
            }),
        };
        let frame = FrameSettings {
            width,
            height,
            spp,
            pass_spp: h.parsed("sahara:pass_spp")?,
            seed: h.parsed("sahara:seed")?,
            sampler: h.parsed("sahara:sampler")?,
            filter: Filter::with_parameters(
                h.parsed("sahara:filter")?,
                &h.parameters("filter", FilterKind::parameters(h.parsed("sahara:filter")?))?,
            ),
            integrator: Integrator::with_parameters(
                h.parsed("sahara:integrator")?,
                &h.parameters(
                    "integrator",
                    IntegratorKind::parameters(h.parsed("sahara:integrator")?),
                )?,
            ),
            adaptive,
            // Parts written before the setting existed chose by power.
            light_sampler: match get("sahara:light_sampler") {
                None => LightSampler::Power,
                Some(_) => h.parsed("sahara:light_sampler")?,
            },
            // Parts written before the setting existed were not guided.
            guiding: match get("sahara:guiding") {
                None => Guiding::Off,
                Some(_) => h.parsed("sahara:guiding")?,
            },
        };
        Ok(PartInfo {
            digest: h.need("sahara:digest")?,
            frame,
            output: OutputSettings {
                exposure: h.finite("sahara:exposure")?,
                tonemap: h.parsed("sahara:tonemap")?,
                aovs,
                denoise,
            },
            window,
            samples,
            samples_done,
            complete,
            part: get("sahara:part").unwrap_or_default(),
            passes: held,
            noisy_guides: h.flag("sahara:noisy_guides")?,
            names: get("sahara:names").unwrap_or_default(),
            stats: Vec::new(),
        })
    }
}

/// A part file's header attributes, read with errors that name the file.
struct Header<'a> {
    name: &'a str,
    get: &'a dyn Fn(&str) -> Option<String>,
}

impl Header<'_> {
    /// Attribute `key`, which must be there.
    fn need(&self, key: &str) -> Result<String, FormatError> {
        (self.get)(key).ok_or_else(|| {
            FormatError::in_file(
                self.name,
                format!("not a Sahara render part: the header has no {key} attribute"),
            )
        })
    }

    /// The error of attribute `key`'s value `v`.
    fn bad(&self, key: &str, v: &str) -> FormatError {
        FormatError::in_file(
            self.name,
            format!("the header's {key} = {v:?} is not valid"),
        )
    }

    /// Attribute `key` parsed as a `T`.
    fn parsed<T: std::str::FromStr>(&self, key: &str) -> Result<T, FormatError> {
        let v = self.need(key)?;
        v.parse().map_err(|_| self.bad(key, &v))
    }

    /// Attribute `key`, a finite number.
    fn finite(&self, key: &str) -> Result<f32, FormatError> {
        let v = self.need(key)?;
        v.parse()
            .ok()
            .filter(|x: &f32| x.is_finite())
            .ok_or_else(|| self.bad(key, &v))
    }

    /// The values of a `what`'s parameters `keys` (`sahara:<what>:<name>`),
    /// each accepted by its parameter.
    fn parameters(&self, what: &str, keys: &[Parameter]) -> Result<Vec<f32>, FormatError> {
        keys.iter()
            .map(|p| {
                let key = format!("sahara:{what}:{}", p.name);
                let v = self.finite(&key)?;
                p.check(v).map_err(|_| self.bad(&key, &v.to_string()))
            })
            .collect()
    }

    /// The frame's size, `WxH`, each side in `1..=MAX_SIDE`.
    fn frame(&self) -> Result<(u32, u32), FormatError> {
        let frame = self.need("sahara:frame")?;
        frame
            .split_once('x')
            .and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)))
            .filter(|&(w, h)| (1..=MAX_SIDE).contains(&w) && (1..=MAX_SIDE).contains(&h))
            .ok_or_else(|| self.bad("sahara:frame", &frame))
    }

    /// The part's pixels, `x0,x1,y0,y1` inside a `width` x `height` frame.
    fn window(&self, width: u32, height: u32) -> Result<PixelWindow, FormatError> {
        let win = self.need("sahara:window")?;
        let v: Vec<u32> = win.split(',').filter_map(|p| p.parse().ok()).collect();
        match v[..] {
            [x0, x1, y0, y1] if x0 <= x1 && x1 <= width && y0 <= y1 && y1 <= height => {
                Ok(PixelWindow { x0, x1, y0, y1 })
            }
            _ => Err(self.bad("sahara:window", &win)),
        }
    }

    /// A range of samples `a..b` within `0..spp`.
    fn range(&self, key: &str, spp: u32) -> Result<Range<u32>, FormatError> {
        let v = self.need(key)?;
        v.split_once("..")
            .and_then(|(a, b)| Some(a.parse::<u32>().ok()?..b.parse::<u32>().ok()?))
            .filter(|r| r.start <= r.end && r.end <= spp)
            .ok_or_else(|| self.bad(key, &v))
    }

    /// A flag; parts of a render without passes may leave it out (false).
    fn flag(&self, key: &str) -> Result<bool, FormatError> {
        match (self.get)(key).as_deref() {
            None => Ok(false),
            Some("true") => Ok(true),
            Some("false") => Ok(false),
            Some(v) => Err(self.bad(key, v)),
        }
    }

    /// A list of render passes, sorted, each once (empty if left out).
    fn passes(&self, key: &str) -> Result<Vec<Aov>, FormatError> {
        let v = (self.get)(key).unwrap_or_default();
        let mut list = v
            .split(',')
            .filter(|p| !p.is_empty())
            .map(Aov::from_name)
            .collect::<Result<Vec<_>, _>>()
            .map_err(|_| self.bad(key, &v))?;
        list.sort();
        list.dedup();
        Ok(list)
    }
}

fn range(r: &Range<u32>) -> String {
    format!("{}..{}", r.start, r.end)
}

/// The channel of each pixel's sample count.
const SAMPLES_CHANNEL: &str = "samples.n";
/// The channel of each pixel's object id.
const OBJECT_CHANNEL: &str = "object.id";
/// The channel of each pixel's material id.
const MATERIAL_CHANNEL: &str = "material.id";

/// Channel names of a sum buffer whose channels begin with `prefix`, in
/// the order of the words of [`PixelSum`]'s sums.
fn sum_channels(prefix: &str) -> Vec<String> {
    let mut names = Vec::with_capacity(16);
    for sum in ["sum.R", "sum.G", "sum.B", "weight"] {
        for word in 0..4 {
            names.push(format!("{prefix}{sum}.w{word}"));
        }
    }
    names
}

/// Every channel a part described by `info` holds, sorted.
fn channel_names(info: &PartInfo) -> Vec<String> {
    let window = PixelWindow {
        x0: 0,
        x1: 0,
        y0: 0,
        y1: 0,
    };
    let mut names = sum_channels("");
    for (_, name, _) in empty_passes(&info.passes, &window).buffers() {
        names.extend(sum_channels(&format!("{name}.")));
    }
    for (held, channel) in [
        (info.sample_counts(), SAMPLES_CHANNEL),
        (info.passes.contains(&Aov::Object), OBJECT_CHANNEL),
        (info.passes.contains(&Aov::Material), MATERIAL_CHANNEL),
    ] {
        if held {
            names.push(channel.to_string());
        }
    }
    names.sort();
    names
}

/// Writes a part: `sums` must cover exactly `info.window` and hold the
/// passes and sample counts it names.
pub fn write_part(path: &Path, info: &PartInfo, sums: &PartSums) -> Result<(), FormatError> {
    let name = path.display().to_string();
    let w = &info.window;
    let fits = |b: &SumBuffer| {
        (b.x0, b.y0, b.width, b.height) == (w.x0, w.y0, w.width(), w.height())
            || (w.is_empty() && b.sums.is_empty())
    };
    let buffers = sums.buffers();
    if !buffers.iter().all(|(_, b)| fits(b)) {
        return Err(FormatError::in_file(
            &name,
            "the sums do not cover the part's window",
        ));
    }
    if sums.passes() != info.passes
        || sums.samples.is_some() != info.sample_counts()
        || sums
            .counts()
            .iter()
            .any(|(_, n)| n.len() != w.pixels() as usize)
    {
        return Err(FormatError::in_file(
            &name,
            "the sums are not those the part's header names",
        ));
    }
    let (fw, fh) = if w.is_empty() {
        (1, 1)
    } else {
        (w.width() as usize, w.height() as usize)
    };
    let zero = [PixelSum::default()];
    let value = |p: &PixelSum, k: usize| if k < 3 { p.rgb[k] } else { p.weight };
    let mut channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (prefix, buffer) in buffers {
        let pixels: &[PixelSum] = if w.is_empty() { &zero } else { &buffer.sums };
        for (c, channel) in sum_channels(&prefix).into_iter().enumerate() {
            let (sum, word) = (c / 4, c % 4);
            let data: Vec<u32> = pixels
                .iter()
                .map(|p| (value(p, sum) as u128 >> (32 * word)) as u32)
                .collect();
            channels.push(AnyChannel::new(channel.as_str(), FlatSamples::U32(data)));
        }
    }
    for (channel, n) in sums.counts() {
        let data = if w.is_empty() { vec![0] } else { n.clone() };
        channels.push(AnyChannel::new(channel, FlatSamples::U32(data)));
    }
    let mut attributes = LayerAttributes::default();
    for (key, value) in info.attributes() {
        let text = |s: &str| {
            Text::new_or_none(s).ok_or_else(|| {
                FormatError::in_file(&name, format!("{key} = {value:?} is not Latin-1 text"))
            })
        };
        attributes
            .other
            .insert(text(&key)?, AttributeValue::Text(text(&value)?));
    }
    let layer = Layer::new(
        (fw, fh),
        attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels),
    );
    let mut bytes = std::io::Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .to_buffered(&mut bytes)
        .map_err(|e| FormatError::in_file(&name, format!("cannot encode EXR: {e}")))?;
    let mut bytes = bytes.into_inner();
    crate::output::image::sort_exr_header(&mut bytes)
        .map_err(|e| FormatError::in_file(&name, format!("cannot encode EXR: {e}")))?;
    write_atomically(path, |out: &mut BufWriter<std::fs::File>| {
        out.write_all(&bytes)
            .and_then(|()| out.flush())
            .map_err(|e| FormatError::write(path, e))
    })
}

/// Reads a part file's header only (cheap: no pixels are read).
pub fn read_part_info(path: &Path) -> Result<PartInfo, FormatError> {
    let name = path.display().to_string();
    let mut magic = [0u8; 4];
    let mut file = std::fs::File::open(path).map_err(|e| FormatError::io(path, e))?;
    if file.read_exact(&mut magic).is_err() || magic != [0x76, 0x2f, 0x31, 0x01] {
        return Err(FormatError::in_file(
            &name,
            "not an OpenEXR file (it does not begin with the EXR magic number)",
        ));
    }
    let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| {
        FormatError::in_file(&name, format!("truncated or damaged OpenEXR header: {e}"))
    })?;
    let [header] = &meta.headers[..] else {
        return Err(FormatError::in_file(
            &name,
            "not a Sahara render part: a multi-part EXR file",
        ));
    };
    let attrs = &header.own_attributes.other;
    let get = |key: &str| match attrs.get(&Text::from(key)) {
        Some(AttributeValue::Text(t)) => Some(t.to_string()),
        _ => None,
    };
    let mut info = PartInfo::parse(&name, &get)?;
    let mut stats: Vec<(String, String)> = attrs
        .iter()
        .filter_map(|(k, v)| {
            let k = k.to_string();
            let stat = k.strip_prefix("sahara:stats:")?.to_string();
            match v {
                AttributeValue::Text(t) => Some((stat, t.to_string())),
                _ => None,
            }
        })
        .collect();
    stats.sort();
    info.stats = stats;
    let w = &info.window;
    let expected = if w.is_empty() {
        (1, 1)
    } else {
        (w.width() as usize, w.height() as usize)
    };
    let size = (header.layer_size.x(), header.layer_size.y());
    if size != expected {
        return Err(FormatError::in_file(
            &name,
            format!(
                "the image is {}x{} but its window {} is {}x{}",
                size.0, size.1, w, expected.0, expected.1
            ),
        ));
    }
    let names: Vec<String> = header
        .channels
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    if names != channel_names(&info) {
        return Err(FormatError::in_file(
            &name,
            format!("not a Sahara render part: its channels are {names:?}"),
        ));
    }
    Ok(info)
}

/// Reads a part: its header and its sums (over its window).
pub fn read_part(path: &Path) -> Result<(PartInfo, PartSums), FormatError> {
    let name = path.display().to_string();
    let info = read_part_info(path)?;
    let image = exr::prelude::read_first_flat_layer_from_file(path).map_err(|e| {
        FormatError::in_file(&name, format!("truncated or damaged OpenEXR file: {e}"))
    })?;
    let w = info.window;
    let mut sums = PartSums {
        beauty: SumBuffer::new(w.x0, w.y0, w.width(), w.height()),
        passes: empty_passes(&info.passes, &w),
        samples: info.sample_counts().then(|| vec![0; w.pixels() as usize]),
        object: info
            .passes
            .contains(&Aov::Object)
            .then(|| vec![0; w.pixels() as usize]),
        material: info
            .passes
            .contains(&Aov::Material)
            .then(|| vec![0; w.pixels() as usize]),
    };
    if w.is_empty() {
        return Ok((info, sums));
    }
    let channels = &image.layer_data.channel_data.list;
    let data = |channel: &str, len: usize| {
        channels
            .iter()
            .find(|ch| ch.name.to_string() == channel)
            .and_then(|ch| match &ch.sample_data {
                FlatSamples::U32(d) if d.len() == len => Some(d),
                _ => None,
            })
            .ok_or_else(|| {
                FormatError::in_file(
                    &name,
                    format!("channel {channel} is missing, not UINT or of the wrong size"),
                )
            })
    };
    let mut buffers: Vec<(String, &mut SumBuffer)> = vec![(String::new(), &mut sums.beauty)];
    for (_, name, b) in sums.passes.buffers_mut() {
        buffers.push((format!("{name}."), b));
    }
    for (prefix, buffer) in buffers {
        let len = buffer.sums.len();
        for (c, channel) in sum_channels(&prefix).iter().enumerate() {
            let data = data(channel, len)?;
            let (sum, word) = (c / 4, c % 4);
            for (p, &v) in buffer.sums.iter_mut().zip(data) {
                let slot = if sum < 3 {
                    &mut p.rgb[sum]
                } else {
                    &mut p.weight
                };
                *slot = (*slot as u128 | (v as u128) << (32 * word)) as i128;
            }
        }
    }
    for (channel, n) in [
        (SAMPLES_CHANNEL, &mut sums.samples),
        (OBJECT_CHANNEL, &mut sums.object),
        (MATERIAL_CHANNEL, &mut sums.material),
    ] {
        if let Some(n) = n {
            let len = n.len();
            n.copy_from_slice(data(channel, len)?);
        }
    }
    Ok((info, sums))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec2, Vec3};

    fn info(window: PixelWindow) -> PartInfo {
        PartInfo {
            digest: "ab".repeat(32),
            frame: FrameSettings {
                width: 9,
                height: 7,
                spp: 16,
                pass_spp: 4,
                seed: 3,
                sampler: sahara_render::SamplerKind::Independent,
                light_sampler: LightSampler::Uniform,
                guiding: Guiding::Off,
                filter: Filter::Mitchell {
                    radius: 1.75,
                    b: 0.3,
                    c: 0.35,
                },
                integrator: Integrator::Sppm {
                    max_depth: 6,
                    radius: 0.125,
                    photons: 250_000,
                },
                adaptive: None,
            },
            output: OutputSettings {
                exposure: -0.5,
                tonemap: sahara_render::ToneMap::Filmic,
                aovs: Vec::new(),
                denoise: false,
            },
            window,
            samples: 4..12,
            samples_done: 4..12,
            complete: true,
            part: "1/2 tiles".into(),
            passes: Vec::new(),
            noisy_guides: false,
            names: String::new(),
            stats: vec![("rays".into(), "123".into())],
        }
    }

    #[test]
    fn a_part_reads_back_bit_for_bit() {
        let dir = std::env::temp_dir().join(format!("sahara-part-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let window = PixelWindow {
            x0: 2,
            x1: 6,
            y0: 1,
            y1: 4,
        };
        let mut sums = SumBuffer::new(2, 1, 4, 3);
        let f = Filter::from(sahara_render::FilterKind::Mitchell);
        for k in 0..40 {
            let (x, y) = (2 + k % 4, 1 + k % 3);
            let pos = Vec2::new(x as f32 + 0.1 * (k % 7) as f32, y as f32 + 0.3);
            sums.splat(&f, 2, x, y, pos, Vec3::new(1e6 * k as f32, 0.25, 1e-9));
        }
        let path = dir.join("p.exr");
        write_part(&path, &info(window), &PartSums::beauty(sums.clone())).unwrap();
        let (back, back_sums) = read_part(&path).unwrap();
        assert_eq!(back, info(window));
        assert_eq!(back_sums, PartSums::beauty(sums.clone()));
        // With render passes and sample counts: each buffer its own sums.
        let with = PartInfo {
            passes: vec![
                Aov::Albedo,
                Aov::Normal,
                Aov::Uv,
                Aov::Variance,
                Aov::Object,
            ],
            output: OutputSettings {
                aovs: vec![Aov::Uv, Aov::Variance],
                denoise: true,
                ..info(window).output
            },
            frame: FrameSettings {
                adaptive: Some(Adaptive {
                    threshold: 0.03,
                    min_spp: 8,
                }),
                ..info(window).frame
            },
            noisy_guides: true,
            names: "{\"object\": {\"1\": \"t\\u00eate\"}}".into(),
            ..info(window)
        };
        let mut passes = empty_passes(&with.passes, &window);
        let scaled = |k: f32| {
            let mut b = SumBuffer::new(2, 1, 4, 3);
            for (i, p) in b.sums.iter_mut().enumerate() {
                p.add_sample(Vec3::new(k, -k * i as f32, 1e5 * k), 1.0 + i as f32);
            }
            b
        };
        passes.albedo = Some(scaled(1.0));
        passes.normal = Some(scaled(-2.0));
        passes.uv = Some(scaled(3.0));
        passes.moments = Some([scaled(4.0), scaled(5.0)]);
        let full = PartSums {
            beauty: sums.clone(),
            passes,
            samples: Some((0..12).map(|k| 7 * k).collect()),
            object: Some((0..12).map(|k| 100 + k).collect()),
            material: None,
        };
        write_part(&path, &with, &full).unwrap();
        let (back, back_sums) = read_part(&path).unwrap();
        assert_eq!(back, with);
        assert_eq!(back_sums, full);
        // A header that names other passes than the sums hold is refused.
        assert!(write_part(&path, &info(window), &full).is_err());
        // A part without pixels.
        let empty = PixelWindow {
            x0: 3,
            x1: 3,
            y0: 0,
            y1: 7,
        };
        let nothing = PartSums::beauty(SumBuffer::new(3, 0, 0, 7));
        write_part(&path, &info(empty), &nothing).unwrap();
        let (back, back_sums) = read_part(&path).unwrap();
        assert_eq!(back.window, empty);
        assert!(back_sums.beauty.sums.is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
