//! The one front door: a loaded scene and a caller's settings become
//! everything a render needs ([`Plan`]): the scene, the renderer's
//! settings, where and how the result is written, and how it is
//! denoised. The command line and the Python package translate their
//! arguments into a [`Request`] (a [`SettingsLayer`], through the
//! [`SETTINGS`] table) and decide nothing themselves.
//!
//! A plan's settings are one fold of layers, the caller's over the scene
//! file's over the defaults (`defaults.apply(file).apply(caller)`, see
//! [`SettingsLayer::apply`]); then the plan holds the rules every render
//! keeps, whoever asked for it:
//!
//! - a time limit without a sample count leaves the samples uncapped;
//! - denoising adds the albedo and normal passes, and switches to the box
//!   filter unless the caller names one (a wider filter correlates the
//!   noise of neighbouring pixels, which the denoiser then keeps);
//! - a scene file's crop window makes an image of those pixels; a piece of
//!   the frame ([`Piece`]) makes a part file for `sahara merge`;
//! - the camera's aspect is the image's; the scene is validated; what the
//!   integrator cannot do is refused naming what asked for it;
//! - a render that would not fit in memory is refused with its estimate
//!   ([`memory`]);
//! - the denoiser is found before the render, not after it.
//!
//! After the render, [`Plan::denoise`] and [`Plan::write`] finish it the
//! same way for every caller.

mod denoise;
mod error;
pub mod memory;
mod names;
mod piece;
mod table;

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use sahara_denoise::Denoiser;
use sahara_kd::{AccelParams, BuildParams};
use sahara_render::{
    frame_digest, Feature, Filter, FilterKind, FrameSettings, Pick, PixelWindow, RenderResult,
    RenderSettings, Scene, SettingsError, UNLIMITED_SPP,
};

pub use denoise::{denoise, guides_are_noisy, Denoised, GUIDES};
pub use error::{Asked, RequestError, Spelling};
pub use piece::{existing_part_differs, Piece};
pub use table::{Given, Refused, Setting, Takes, MAX_SIDE, MAX_SPP, SETTINGS};

use crate::description::{SettingsLayer, Split};
use crate::load::Loaded;
use crate::output::frame::{check_output, is_exr, partial_path, write_names_beside};
use crate::output::frame::{FrameImage, OutputSettings};
pub use names::names_json;

/// What a caller asks of a loaded scene.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Request {
    /// The caller's settings, over the scene file's, over the defaults.
    pub caller: SettingsLayer,
    /// Whether an image is written where the caller names no output: the
    /// scene file's output, else `<scene name>.png` (a command writes a
    /// file). False: only where the caller names one (a library call
    /// returns the image).
    pub write_by_default: bool,
}

/// A render ready to run, and how to finish it.
pub struct Plan {
    /// The scene, its camera's aspect the image's.
    pub scene: Scene,
    /// What a log calls the scene: its file, or the built-in scene.
    pub description: String,
    /// How to render: the frame's settings, the time limit, the window
    /// and samples of a piece, the passes, a cancel flag (set it to stop).
    pub settings: RenderSettings,
    /// How the frame is written: exposure, tone map, the passes written
    /// beside it, denoising.
    pub output: OutputSettings,
    /// The image (or part) file to write, if one is.
    pub path: Option<PathBuf>,
    /// Whether a file was at `path` before the render: a partial image
    /// then goes beside it, never over it.
    pub path_existed: bool,
    /// The list of names of the object and material passes (JSON), if
    /// asked for.
    pub names: Option<String>,
    /// The piece of the frame a part renders, with the frame's digest.
    pub piece: Option<(Piece, String)>,
    /// The denoiser, when the image is to be denoised (a part never is:
    /// it carries the albedo and normal, and `merge` denoises the frame).
    pub denoiser: Option<Denoiser>,
    /// True if the denoiser is to clean the albedo and normal first
    /// ([`guides_are_noisy`]).
    pub noisy_guides: bool,
    /// Problems of the scene that do not stop the render, one line each,
    /// named after its file.
    pub warnings: Vec<String>,
    /// What the plan decided that a log should say, one line each.
    pub notes: Vec<Note>,
    /// What asked for denoising, for the denoiser's errors.
    denoise_asked: Asked,
}

/// A line the plan has for a log.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Note {
    /// What it decided (`denoise: box filter ...`).
    Said(String),
    /// A setting that will not do what it seems to ask (adaptive sampling
    /// that cannot stop early).
    Warning(String),
}

/// What a plan wrote.
#[derive(Clone, Debug, PartialEq)]
pub enum Written {
    /// Nothing: no output was asked for.
    Nothing,
    /// An image at this path; what a debug view's colours mean, for the
    /// log.
    Image(PathBuf, Option<String>),
    /// A part file at this path, holding these samples of every pixel of
    /// its window.
    Part(PathBuf, std::ops::Range<u32>),
}

impl Request {
    /// Checks what can be checked of the caller's settings alone, before
    /// anything is loaded: a mistake found after a long load (or a
    /// render) would cost the caller that time.
    pub fn check(&self) -> Result<(), RequestError> {
        let c = &self.caller;
        let piece = c.piece.is_piece();
        if piece && c.time_limit.is_some() {
            return Err(RequestError::refused(
                Asked::Caller("time_limit", None),
                "cannot make a part: a part's samples must be fixed in advance",
            ));
        }
        if let (false, Some(how)) = (piece, c.piece.split) {
            return Err(RequestError::refused(
                Asked::Caller("split", Some(how.name())),
                "applies to a part (with part)",
            ));
        }
        if let Some(path) = &c.path {
            output_writable(path, piece)?;
            check_passes_output(c, path)?;
        }
        Ok(())
    }

    /// Plans the render of `loaded`: the settings folded and decided,
    /// and everything the render needs checked before it starts (see the
    /// [module](self)).
    pub fn plan(&self, loaded: Loaded) -> Result<Plan, RequestError> {
        self.check()?;
        let warnings = loaded.problems();
        let Loaded {
            mut scene,
            settings: file,
            name,
            description,
            path: scene_path,
            names,
            ..
        } = loaded;
        let caller = &self.caller;
        let layer = SettingsLayer::default()
            .apply(file.unwrap_or_default())
            .apply(caller.clone());
        let (mut frame, output) = decide(&layer)?;
        let file_window = file_window(&layer, &frame)?;
        let piece = piece::plan(
            &layer.piece,
            (frame.width, frame.height, frame.spp),
            file_window,
        )?;
        let path = self.output_path(&layer, &name, piece.is_some())?;
        let mut notes = Vec::new();
        if output.denoise {
            self.denoising_filter(&mut frame.filter, &mut notes);
        }
        let mut aovs = output.aovs.clone();
        if output.denoise {
            aovs.extend(GUIDES);
        }
        aovs.sort();
        aovs.dedup();
        let settings = RenderSettings {
            frame,
            time_limit: layer.time_limit,
            cancel: Some(Arc::new(AtomicBool::new(false))),
            build: AccelParams {
                kind: layer.accel.unwrap_or_default(),
                kd: layer
                    .builder
                    .map_or_else(BuildParams::default, BuildParams::new),
                ..AccelParams::default()
            },
            window: piece.as_ref().map_or(file_window, |p| Some(p.window)),
            samples: piece.as_ref().map(|p| p.samples.clone()),
            part: piece.is_some(),
            aovs,
            path_loop: layer.path_loop.unwrap_or_default(),
            ..Default::default()
        };
        check_supported(caller, &scene, &settings, output.denoise)?;
        let denoiser = match output.denoise && piece.is_none() {
            true => Some(Denoiser::load().map_err(|e| RequestError::Denoiser {
                asked: denoise_asked(caller),
                reason: e.to_string(),
            })?),
            false => None,
        };
        check_memory(&scene, &settings, piece.as_ref())?;
        // Any aspect ratio: the vertical field of view is kept.
        scene.camera.aspect = settings.width as f32 / settings.height as f32;
        scene.validate().map_err(|e| {
            RequestError::File(match &scene_path {
                Some(p) => format!("{}: invalid scene: {e}", p.display()),
                None => format!("invalid scene: {e}"),
            })
        })?;
        say_what_was_decided(&settings, piece.as_ref(), &mut notes);
        let piece = piece.map(|p| (p, frame_digest(&scene, &settings)));
        Ok(Plan {
            noisy_guides: guides_are_noisy(&scene),
            names: names_json(&names, &output.aovs),
            path_existed: path.as_ref().is_some_and(|p| p.exists()),
            scene,
            description,
            settings,
            output,
            path,
            piece,
            denoiser,
            notes,
            warnings,
            denoise_asked: denoise_asked(caller),
        })
    }

    /// The file the plan writes, checked (the caller's was checked by
    /// [`Request::check`]): the caller's, else (where a request writes by
    /// default) the scene file's, else `<name>.png`.
    fn output_path(
        &self,
        layer: &SettingsLayer,
        name: &str,
        piece: bool,
    ) -> Result<Option<PathBuf>, RequestError> {
        if self.caller.path.is_some() {
            return Ok(self.caller.path.clone());
        }
        if !self.write_by_default {
            return Ok(None);
        }
        let path = layer
            .path
            .clone()
            .unwrap_or_else(|| PathBuf::from(format!("{name}.png")));
        output_writable(&path, piece)?;
        check_passes_output(&self.caller, &path)?;
        Ok(Some(path))
    }

    /// The filter of a denoised render: the box filter unless the caller
    /// names one. A filter wider than a pixel shares each sample between
    /// neighbours: their noise is then correlated, which the denoiser
    /// (trained on independent pixels) takes for detail and keeps.
    /// Figures in docs/clean-image.md.
    fn denoising_filter(&self, filter: &mut Filter, notes: &mut Vec<Note>) {
        let named = self.caller.frame.filter.map(|p| match p {
            Pick::Kind(kind) => kind,
            Pick::Value(f) => f.kind(),
        });
        match named {
            None => {
                *filter = Filter::from(FilterKind::Box);
                notes.push(Note::Said(
                    "denoise: box filter (a wider one correlates the noise of neighbouring \
                     pixels, which the denoiser then keeps; naming a filter chooses another)"
                        .into(),
                ));
            }
            Some(kind) if kind != FilterKind::Box => notes.push(Note::Warning(format!(
                "denoise with the {kind} filter: its noise is correlated between pixels, \
                 which the denoiser keeps (the box filter denoises best)"
            ))),
            Some(_) => {}
        }
    }
}

impl Plan {
    /// Denoises `result` in place if the plan says so (None: it does
    /// not). Returns what was done: the noisy image goes into an EXR's
    /// `noisy` layer ([`Plan::write`]).
    pub fn denoise(&self, result: &mut RenderResult) -> Result<Option<Denoised>, RequestError> {
        let Some(d) = &self.denoiser else {
            return Ok(None);
        };
        denoise(d, result, self.noisy_guides)
            .map(Some)
            .map_err(|reason| RequestError::Denoiser {
                asked: self.denoise_asked.clone(),
                reason,
            })
    }

    /// Where an image goes: the output, or beside it (`<stem>.partial.<ext>`)
    /// for a partial image when a file was there before the render.
    pub fn path_for(&self, partial: bool) -> Option<PathBuf> {
        let path = self.path.as_ref()?;
        Some(if partial {
            partial_path(path, self.path_existed)
        } else {
            path.clone()
        })
    }

    /// The image writer for `result` at `path`, with the image before
    /// denoising (`noisy`) as a layer of an EXR.
    pub fn image<'a>(&'a self, path: PathBuf, noisy: Option<&'a [f32]>) -> FrameImage<'a> {
        FrameImage {
            path,
            frame: &self.settings.frame,
            look: &self.output,
            noisy,
        }
    }

    /// Writes `result`: the part file of a piece, else the image (with its
    /// list of names), marked `partial` (an interrupted render) or not.
    /// A partial file goes beside an earlier complete one; a complete
    /// image removes a partial one left beside it by a preview.
    pub fn write(
        &self,
        result: &RenderResult,
        denoised: Option<&Denoised>,
        partial: bool,
    ) -> Result<Written, RequestError> {
        let Some(path) = self.path_for(partial) else {
            return Ok(Written::Nothing);
        };
        if let Some((piece, digest)) = &self.piece {
            let record = piece::PartRecord {
                piece,
                digest,
                output: &self.output,
                noisy_guides: self.noisy_guides,
                names: self.names.as_deref(),
                interrupted: partial,
            };
            let done = piece::write(&path, &record, &self.settings, result)?;
            return Ok(Written::Part(path, done));
        }
        let noisy = match denoised {
            Some(Denoised::Done { noisy, .. }) => Some(noisy.as_slice()),
            _ => None,
        };
        let said = self
            .image(path.clone(), noisy)
            .write(result, partial)
            .map_err(|e| RequestError::File(format!("cannot write the output image: {e}")))?;
        if let Some(names) = &self.names {
            write_names_beside(&path, names).map_err(|e| {
                RequestError::File(format!(
                    "cannot write the list of object and material names: {e}"
                ))
            })?;
        }
        if !partial {
            // A preview written beside the earlier image is stale now.
            if let Some(beside) = self.path_for(true).filter(|b| *b != path && b.exists()) {
                let _ = std::fs::remove_file(beside);
            }
        }
        Ok(Written::Image(path, said))
    }
}

/// The frame's and the output's settings the folded `layer` decides: the
/// defaults where no layer gave one, passes of at most `spp` samples, the
/// passes written sorted, each once. A minimum of samples without a noise
/// threshold asks for nothing: refused.
fn decide(layer: &SettingsLayer) -> Result<(FrameSettings, OutputSettings), RequestError> {
    if let Some(a) = layer.frame.adaptive.filter(|a| a.threshold.is_none()) {
        if a.min_spp.is_some() {
            return Err(RequestError::refused(
                Asked::Caller("min_spp", None),
                "needs a noise threshold (noise_threshold) to ask for adaptive sampling",
            ));
        }
    }
    let mut frame = layer.frame.clone().decided();
    frame.pass_spp = frame.pass_spp.min(frame.spp);
    let mut output = layer.output.clone().decided();
    output.aovs.sort();
    output.aovs.dedup();
    Ok((frame, output))
}

/// The pixels of the scene file's crop window in `frame`, if it has one:
/// a plain render is an image of those pixels, as pbrt writes it.
fn file_window(
    layer: &SettingsLayer,
    frame: &FrameSettings,
) -> Result<Option<PixelWindow>, RequestError> {
    let Some(crop) = layer.crop_window else {
        return Ok(None);
    };
    let w = crop.window(frame.width, frame.height);
    if w.is_empty() {
        return Err(RequestError::refused(
            Asked::File("crop window"),
            format!(
                "holds no pixel of the {}x{} image",
                frame.width, frame.height
            ),
        ));
    }
    Ok(Some(w))
}

/// Refuses an output that cannot be written ([`check_output`]).
fn output_writable(path: &std::path::Path, piece: bool) -> Result<(), RequestError> {
    check_output(path, piece)
        .map_err(|e| RequestError::File(format!("cannot write the output image: {e}")))
}

/// Render passes are layers of an EXR: refused for any other output.
fn check_passes_output(caller: &SettingsLayer, path: &std::path::Path) -> Result<(), RequestError> {
    if caller.output.aovs.as_ref().is_some_and(|a| !a.is_empty()) && !is_exr(path) {
        return Err(RequestError::refused(
            Asked::Caller("aov", None),
            format!(
                "render passes are written as layers of an EXR file: the output {} is not one \
                 (name a .exr file)",
                path.display()
            ),
        ));
    }
    Ok(())
}

/// What asked for denoising: the caller, else the scene file.
fn denoise_asked(caller: &SettingsLayer) -> Asked {
    if caller.output.denoise.is_some() {
        Asked::Caller("denoise", None)
    } else {
        Asked::File("denoise")
    }
}

/// The renderer's refusal of settings the integrator cannot honour in
/// `scene` ([`RenderSettings::check_for`]; `IntegratorKind::supports`
/// declares what each integrator supports), naming the setting or scene
/// file key that asked for it. `denoise`: the render is to be denoised.
fn check_supported(
    caller: &SettingsLayer,
    scene: &Scene,
    settings: &RenderSettings,
    denoise: bool,
) -> Result<(), RequestError> {
    let asked = |e: &SettingsError| -> Asked {
        let feature = match e {
            SettingsError::Unsupported { feature, .. } => *feature,
            SettingsError::AdaptiveSampleRange { .. } => Feature::Adaptive,
            SettingsError::Guiding(_) if caller.frame.guiding.is_some() => {
                return Asked::Caller("guiding", None)
            }
            SettingsError::Guiding(_) => return Asked::File("guiding"),
        };
        let p = &caller.piece;
        match feature {
            Feature::Denoise => denoise_asked(caller),
            Feature::Aovs => Asked::Caller("aov", None),
            Feature::Adaptive => match caller.frame.adaptive.and_then(|a| a.threshold) {
                Some(_) => Asked::Caller("noise_threshold", None),
                None => Asked::File("noise_threshold"),
            },
            Feature::PixelParts if p.crop.is_some() => Asked::Caller("crop", None),
            Feature::PixelParts if p.part.is_some() && p.split != Some(Split::Samples) => {
                Asked::Caller("split", Some("tiles"))
            }
            Feature::PixelParts => Asked::File("crop window"),
            Feature::SampleRanges if p.samples.is_some() => Asked::Caller("samples", None),
            Feature::SampleRanges => Asked::Caller("split", Some("samples")),
            Feature::Media if caller.frame.integrator.is_some() => {
                Asked::Caller("integrator", None)
            }
            Feature::Media => Asked::Scene("integrator"),
        }
    };
    let named = |e: SettingsError| RequestError::refused(asked(&e), e.to_string());
    if denoise {
        settings
            .integrator
            .kind()
            .require(Feature::Denoise)
            .map_err(named)?;
    }
    settings.check_for(scene).map_err(named)
}

/// Refuses a render that would not fit in memory: the scene's triangles
/// and the film of the pixels rendered (a piece's, a crop's or the
/// frame's), with its passes.
fn check_memory(
    scene: &Scene,
    settings: &RenderSettings,
    piece: Option<&Piece>,
) -> Result<(), RequestError> {
    let triangles: u64 = scene
        .meshes
        .iter()
        .map(|m| m.mesh.indices.len() as u64)
        .sum();
    let film = match (piece, settings.window) {
        (Some(p), _) => (p.window.width().max(1), p.window.height().max(1)),
        (None, Some(w)) => (w.width(), w.height()),
        (None, None) => (settings.width, settings.height),
    };
    memory::check_fits(
        triangles,
        film,
        settings.aovs.len(),
        memory::available_bytes(),
    )
    .map_err(RequestError::Memory)
}

/// Notes on what the plan decided that a reader of the log would not
/// guess: a scene file's crop; adaptive sampling that cannot stop early.
fn say_what_was_decided(settings: &RenderSettings, piece: Option<&Piece>, notes: &mut Vec<Note>) {
    if let (None, Some(w)) = (piece, settings.window) {
        notes.push(Note::Said(format!(
            "crop window of the scene file: pixels {w}, written as a {}x{} image",
            w.width(),
            w.height()
        )));
    }
    if let Some(a) = settings.adaptive {
        if settings.spp != UNLIMITED_SPP && a.min_spp >= settings.spp {
            notes.push(Note::Warning(format!(
                "adaptive: every pixel takes all {spp} samples, as at least {min} are taken \
                 before the noise is tested; raise spp (the cap) above {min}, or lower min_spp, \
                 for pixels to stop early",
                spp = settings.spp,
                min = a.min_spp
            )));
        }
    }
}
