//! A piece of a frame rendered on its own (a render farm's part: a pixel
//! window and a range of every pixel's samples) and the part file it
//! writes for `sahara merge`.

use std::ops::Range;
use std::path::Path;

use sahara_render::{crop, sample_range, tile, PixelWindow};
use sahara_render::{Aov, Aux, AuxImages, RenderResult, RenderSettings, SumBuffer};

use super::error::{Asked, RequestError};
use crate::description::{PieceLayer, Split};
use crate::output::frame::OutputSettings;
use crate::output::part::{read_part_info, write_part, PartInfo, PartSums};

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

/// The piece `asked` for (None: the whole frame) of a `width x height`
/// frame of `spp` samples per pixel. `file_window`: the crop the scene
/// file asks for, the pixels a part divides unless a crop window names
/// others.
pub(crate) fn plan(
    asked: &PieceLayer,
    (width, height, spp): (u32, u32, u32),
    file_window: Option<PixelWindow>,
) -> Result<Option<Piece>, RequestError> {
    if !asked.is_piece() {
        return Ok(None);
    }
    let mut window = match asked.crop {
        Some(f) => crop(width, height, f),
        None => file_window.unwrap_or_else(|| PixelWindow::full(width, height)),
    };
    let mut samples = match &asked.samples {
        Some(r) if r.end > spp => {
            return Err(RequestError::refused(
                Asked::Caller("samples", None),
                format!(
                    "{}..{} reaches past the frame's {spp} samples per pixel",
                    r.start, r.end
                ),
            ))
        }
        Some(r) => r.clone(),
        None => 0..spp,
    };
    let mut label = String::new();
    if let Some((i, n)) = asked.part {
        match asked.split.unwrap_or_default() {
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

/// Why an existing part file at `path` is not `piece` of the frame of
/// `digest`, complete (None: it is, and need not be rendered again).
pub fn existing_part_differs(path: &Path, digest: &str, piece: &Piece) -> Option<String> {
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

/// What the part file of a render records besides its sums.
pub(crate) struct PartRecord<'a> {
    /// The piece.
    pub piece: &'a Piece,
    /// The frame's digest.
    pub digest: &'a str,
    /// How the merged frame is written.
    pub output: &'a OutputSettings,
    /// True if the denoiser is to clean the albedo and normal first.
    pub noisy_guides: bool,
    /// The list of names of the object and material passes (JSON).
    pub names: Option<&'a str>,
    /// True if the render was interrupted.
    pub interrupted: bool,
}

/// Writes the part file of `result`, rendered with `settings`; returns
/// the samples its sums hold.
pub(crate) fn write(
    path: &Path,
    record: &PartRecord<'_>,
    settings: &RenderSettings,
    result: &RenderResult,
) -> Result<Range<u32>, RequestError> {
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
    let info = PartInfo {
        digest: record.digest.to_string(),
        frame: settings.frame.clone(),
        output: record.output.clone(),
        window: piece.window,
        samples: piece.samples.clone(),
        samples_done: done.clone(),
        complete: !record.interrupted && done == piece.samples,
        part: piece.label.clone(),
        passes: settings.aovs.clone(),
        noisy_guides: record.noisy_guides,
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
        .map_err(|e| RequestError::File(format!("cannot write the part file: {e}")))?;
    Ok(done)
}
