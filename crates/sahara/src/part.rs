//! `sahara render --part / --crop / --samples`: which piece of the frame a
//! render is, and the part file it writes.

use std::ops::Range;
use std::path::Path;

use anyhow::{anyhow, bail, Result};
use sahara_formats::{read_part_info, write_part, PartInfo, PartSums};
use sahara_render::{crop, sample_range, tile, PixelWindow};
use sahara_render::{Aov, Aux, AuxImages, RenderResult, RenderSettings, SumBuffer, ToneMap};

use crate::cli::{RenderArgs, Split};

/// A piece of a frame: its pixels and its samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    /// The pixels.
    pub window: PixelWindow,
    /// The sample indices of every pixel.
    pub samples: Range<u32>,
    /// How it was chosen (`I/N tiles`, `I/N samples`, or empty).
    pub label: String,
}

/// True if the options ask for a part of the frame (`--part`, `--crop` or
/// `--samples`).
pub fn is_part(args: &RenderArgs) -> bool {
    args.part.is_some() || args.crop.is_some() || args.samples.is_some()
}

/// Refuses options that do not go with the part asked for (or with no part).
pub fn check_args(args: &RenderArgs) -> Result<()> {
    if !is_part(args) {
        if args.skip_existing {
            bail!("--skip-existing applies to parts (--part, --crop or --samples)");
        }
        return Ok(());
    }
    if args.time_limit.is_some() {
        bail!("--time-limit cannot make a part: a part's samples must be fixed in advance");
    }
    if args.preview_every.is_some() {
        bail!("--preview-every does not apply to a part");
    }
    Ok(())
}

/// The piece the options ask for (None: a plain image). `file_window` is
/// the crop the scene file asks for: the pixels `--part` divides unless
/// `--crop` names others. The options were checked by [`check_args`].
pub fn plan(
    args: &RenderArgs,
    settings: &RenderSettings,
    file_window: Option<PixelWindow>,
) -> Result<Option<Piece>> {
    if !is_part(args) {
        return Ok(None);
    }
    let (w, h) = (settings.width, settings.height);
    let total = settings.spp;
    let mut window = match args.crop {
        Some(f) => crop(w, h, f),
        None => file_window.unwrap_or_else(|| PixelWindow::full(w, h)),
    };
    let mut samples = match &args.samples {
        Some(r) if r.end > total => bail!(
            "--samples {}..{} reaches past the frame's {total} samples per pixel",
            r.start,
            r.end
        ),
        Some(r) => r.clone(),
        None => 0..total,
    };
    let mut label = String::new();
    if let Some((i, n)) = args.part {
        match args.split.unwrap_or_default() {
            Split::Tiles => {
                window = tile(&window, i, n);
                label = format!("{i}/{n} tiles");
            }
            Split::Samples => {
                samples = sample_range(&samples, i, n);
                label = format!("{i}/{n} samples");
            }
        }
    }
    Ok(Some(Piece {
        window,
        samples,
        label,
    }))
}

/// Why an existing part file at `path` is not this piece, complete (None:
/// it is, and need not be rendered again).
pub fn existing_differs(path: &Path, digest: &str, piece: &Piece) -> Option<String> {
    if !path.exists() {
        return Some("it does not exist".into());
    }
    match read_part_info(path) {
        Err(e) => Some(format!("it cannot be used ({e})")),
        Ok(i) if i.digest != digest => Some("it is of another frame (digest differs)".into()),
        Ok(i) if i.window != piece.window || i.samples != piece.samples => {
            Some("it is another piece of the frame".into())
        }
        Ok(i) if !i.complete => Some("it is partial".into()),
        Ok(_) => None,
    }
}

/// What the part file of a render records.
pub struct PartRecord<'a> {
    /// The piece.
    pub piece: &'a Piece,
    /// The frame's digest.
    pub digest: &'a str,
    /// Exposure for a PNG of the merged frame.
    pub exposure: f32,
    /// Tone map for a PNG of the merged frame.
    pub tonemap: ToneMap,
    /// The render passes the merged frame writes as layers.
    pub aovs: &'a [Aov],
    /// True if the merged frame is to be denoised.
    pub denoise: bool,
    /// True if the denoiser is to clean the albedo and normal first.
    pub noisy_guides: bool,
    /// The list of names of the object and material passes (JSON).
    pub names: Option<&'a str>,
    /// True if the render was interrupted.
    pub interrupted: bool,
}

/// Writes the part file of `result`; returns the samples its sums hold.
pub fn write(
    path: &Path,
    record: &PartRecord<'_>,
    settings: &RenderSettings,
    result: &RenderResult,
) -> Result<Range<u32>> {
    let piece = record.piece;
    let s = &result.stats;
    // An interrupted first pass leaves some pixels with fewer samples than
    // others: a part holds whole passes only.
    let w = piece.window;
    // The ids depend on the pixel alone: kept even if no pass finished.
    let ids = |pick: fn(&AuxImages) -> &Vec<u32>, aov: Aov| {
        settings.aovs.contains(&aov).then(|| {
            result
                .aux
                .as_ref()
                .map_or_else(|| vec![0; w.pixels() as usize], |a| pick(&a.images).clone())
        })
    };
    let (object, material) = (
        ids(|i| &i.object, Aov::Object),
        ids(|i| &i.material, Aov::Material),
    );
    let (done, sums) = if s.passes == 0 && !piece.samples.is_empty() {
        let nothing = Aux::new(&settings.aovs, w.x0, w.y0, w.width(), w.height());
        (
            piece.samples.start..piece.samples.start,
            PartSums {
                beauty: SumBuffer::new(w.x0, w.y0, w.width(), w.height()),
                passes: nothing.sums,
                samples: result
                    .samples
                    .as_ref()
                    .map(|_| vec![0; w.pixels() as usize]),
                object,
                material,
            },
        )
    } else {
        let passes = match &result.aux {
            Some(aux) => aux.sums.clone(),
            None => Default::default(),
        };
        (
            piece.samples.start..piece.samples.start + s.spp,
            PartSums {
                beauty: result.sums.clone(),
                passes,
                samples: result.samples.clone(),
                object,
                material,
            },
        )
    };
    let mut aovs = record.aovs.to_vec();
    aovs.sort();
    aovs.dedup();
    let info = PartInfo {
        digest: record.digest.to_string(),
        width: settings.width,
        height: settings.height,
        spp: settings.spp,
        window: piece.window,
        samples: piece.samples.clone(),
        samples_done: done.clone(),
        complete: !record.interrupted && done == piece.samples,
        part: piece.label.clone(),
        integrator: settings.integrator.kind(),
        seed: settings.seed,
        exposure: record.exposure,
        tonemap: record.tonemap,
        passes: settings.aovs.clone(),
        aovs,
        denoise: record.denoise,
        noisy_guides: record.noisy_guides,
        sample_counts: sums.samples.is_some(),
        names: record.names.unwrap_or_default().to_string(),
        stats: vec![
            ("passes".into(), s.passes.to_string()),
            ("rays".into(), s.rays().to_string()),
            (
                "render_seconds".into(),
                format!("{:.3}", s.render_time.as_secs_f64()),
            ),
            (
                "render_cpu_seconds".into(),
                format!("{:.3}", s.render_cpu_time.as_secs_f64()),
            ),
            (
                "build_seconds".into(),
                format!("{:.3}", s.build_time.as_secs_f64()),
            ),
            ("nan_samples".into(), s.nan_samples.to_string()),
        ],
    };
    write_part(path, &info, &sums)
        .map_err(|e| anyhow!("{e}"))
        .map_err(|e| e.context("cannot write the part file"))?;
    Ok(done)
}
