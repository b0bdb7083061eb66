//! `sahara merge`: the parts of a frame assembled into its image.
//!
//! Every part's header is read and checked first (same frame, no overlap,
//! nothing missing, nothing partial unless allowed), before any pixel is
//! read. Then the parts are added up group by group: parts whose windows
//! overlap (the sample ranges of one tile) form a group, which is summed
//! into one buffer over the group's pixels, turned into the image's
//! pixels, and dropped. At most one group's sums, one part and the image
//! (with its render passes) are in memory at once. The passes' sums are
//! merged like the beauty's, so the merged frame's passes are those of the
//! whole frame rendered at once; a frame whose parts ask for denoising is
//! denoised here, once merged (a part alone never is).

use std::ops::Range;
use std::path::PathBuf;

use anyhow::{anyhow, bail, Result};
use sahara_formats::request::{denoise, GUIDES};
use sahara_formats::{check_output, read_part, read_part_info, write_names_beside, PartInfo};
use sahara_formats::{Denoised, FrameImage};
use sahara_render::{
    cost_maps, Aov, Aux, AuxImages, AuxSums, Film, Integrator, Named, RenderResult, RenderStats,
    SumBuffer,
};
use sahara_render::{tile, PixelWindow};

use crate::cli::MergeArgs;

/// Entries of the list of what is missing shown in full.
const MISSING_SHOWN: usize = 8;

/// `sahara merge PARTS... -o OUT`.
pub fn run(args: &MergeArgs) -> Result<()> {
    check_output(&args.output, false).map_err(|e| anyhow!("{e}"))?;
    let mut parts: Vec<(PathBuf, PartInfo)> = Vec::with_capacity(args.parts.len());
    for path in &args.parts {
        let info = read_part_info(path).map_err(|e| anyhow!("{e}"))?;
        parts.push((path.clone(), info));
    }
    check_one_frame(&parts)?;
    let first = &parts[0].1;
    let denoise_it = args.denoise || first.output.denoise;
    if denoise_it && !GUIDES.iter().all(|a| first.passes.contains(a)) {
        bail!(
            "--denoise: the parts hold no albedo and normal for the denoiser: render them with \
             --denoise (or --aov albedo,normal)"
        );
    }
    // The library is found before any pixel is read.
    let denoiser = if denoise_it {
        Some(sahara_denoise::Denoiser::load().map_err(|e| anyhow!("--denoise: {e}"))?)
    } else {
        None
    };
    let partial: Vec<&(PathBuf, PartInfo)> = parts.iter().filter(|(_, i)| !i.complete).collect();
    if let Some((path, info)) = partial.first().filter(|_| !args.allow_partial) {
        bail!(
            "{}: a partial part (interrupted: samples {} of {} rendered); render it again, \
             or merge with --allow-partial",
            path.display(),
            range(&info.samples_done),
            range(&info.samples)
        );
    }
    let spp = check_coverage(&parts)?;
    for (path, info) in &partial {
        eprintln!(
            "merging partial part {}: samples {} of {}, pixels {}",
            path.display(),
            range(&info.samples_done),
            range(&info.samples),
            info.window
        );
    }
    let merged = add_up(&parts)?;
    let mut result = merged.result(first, spp);
    let denoised = match &denoiser {
        Some(d) => {
            let denoising = crate::status::Step::start("denoising");
            let done = denoise(d, &mut result, first.noisy_guides);
            drop(denoising);
            let done = done.map_err(|e| anyhow!("--denoise: {e}"))?;
            if let Denoised::Done { seconds, .. } = &done {
                eprintln!(
                    "denoised with Open Image Denoise {} in {seconds:.2} s, from {}",
                    d.version(),
                    d.location()
                );
            }
            Some(done)
        }
        None => None,
    };
    let noisy = match &denoised {
        Some(Denoised::Done { noisy, .. }) => Some(noisy.as_slice()),
        _ => None,
    };
    // The merged frame is written as the frame rendered whole: its
    // settings are the parts'.
    let out = FrameImage {
        path: args.output.clone(),
        frame: &first.frame,
        look: &first.output,
        noisy,
    };
    let said = out
        .write(&result, !partial.is_empty())
        .map_err(|e| anyhow!("cannot write the output image: {e}"))?;
    if let Some(said) = said {
        eprintln!("{said}");
    }
    if !first.names.is_empty() {
        write_names_beside(&args.output, &first.names)
            .map_err(|e| anyhow!("cannot write the list of object and material names: {e}"))?;
    }
    eprintln!(
        "wrote {}{}: {} parts, {}x{}, {} spp",
        if partial.is_empty() { "" } else { "PARTIAL " },
        args.output.display(),
        parts.len(),
        first.frame.width,
        first.frame.height,
        spp
    );
    Ok(())
}

/// Refuses parts of other frames than the first part's (another scene,
/// other settings) and parts with other render passes.
fn check_one_frame(parts: &[(PathBuf, PartInfo)]) -> Result<()> {
    let (first_path, first) = &parts[0];
    for (path, info) in &parts[1..] {
        let same = info.digest == first.digest && info.frame == first.frame;
        if !same {
            bail!(
                "{}: a part of another frame than {} (digest {} vs {}): another scene or other settings",
                path.display(),
                first_path.display(),
                short(&info.digest),
                short(&first.digest)
            );
        }
        let same_passes = (&info.passes, &info.output.aovs, info.output.denoise)
            == (&first.passes, &first.output.aovs, first.output.denoise);
        if !same_passes {
            bail!(
                "{}: rendered with other render passes than {} ({} vs {}): render every part \
                 with the same --aov and --denoise",
                path.display(),
                first_path.display(),
                passes_said(info),
                passes_said(first)
            );
        }
    }
    Ok(())
}

/// The frame's pixels as the parts add up to them.
struct Merged {
    film: Film,
    passes: FramePasses,
    /// The samples each pixel took, when the parts count them.
    samples: Option<Vec<u32>>,
}

impl Merged {
    /// The frame as a render's result of `spp` samples.
    fn result(self, first: &PartInfo, spp: u32) -> RenderResult {
        let mut film = self.film;
        let integrator = first.frame.integrator;
        let cost = matches!(integrator, Integrator::Cost).then(|| cost_maps(&mut film, None));
        RenderResult {
            film,
            sums: SumBuffer::new(0, 0, 0, 0),
            stats: RenderStats {
                passes: 1,
                spp,
                ..Default::default()
            },
            cost,
            aux: (!first.passes.is_empty()).then(|| Aux {
                images: self.passes.images,
                sums: AuxSums::default(),
            }),
            samples: self.samples,
        }
    }
}

/// Adds the parts up group by group (parts whose windows overlap), one
/// group's sums in memory at a time.
fn add_up(parts: &[(PathBuf, PartInfo)]) -> Result<Merged> {
    let first = &parts[0].1;
    let (w, h) = (first.frame.width, first.frame.height);
    let mut merged = Merged {
        film: Film::new(w, h),
        passes: FramePasses::new(&first.passes, w, h),
        samples: first.sample_counts().then(|| vec![0u32; (w * h) as usize]),
    };
    for group in groups(parts) {
        let bounds = group
            .iter()
            .map(|&k| parts[k].1.window)
            .reduce(|a, b| PixelWindow {
                x0: a.x0.min(b.x0),
                x1: a.x1.max(b.x1),
                y0: a.y0.min(b.y0),
                y1: a.y1.max(b.y1),
            })
            .expect("a group has a part");
        let mut sums = SumBuffer::new(bounds.x0, bounds.y0, bounds.width(), bounds.height());
        let mut aux = Aux::new(
            &first.passes,
            bounds.x0,
            bounds.y0,
            bounds.width(),
            bounds.height(),
        );
        for &k in &group {
            add_part(&parts[k], w, &mut sums, &mut aux, &mut merged)?;
        }
        let aux = Aux::from_sums(aux.sums);
        for &k in &group {
            let win = parts[k].1.window;
            for (x, y) in rows(&win) {
                let value = sums.get(x, y).expect("inside the group").value();
                merged.film.pixels[(y * w + x) as usize] = value;
                let at = (y - bounds.y0) * bounds.width() + (x - bounds.x0);
                merged
                    .passes
                    .set((y * w + x) as usize, &aux.images, at as usize);
            }
        }
    }
    Ok(merged)
}

/// Reads one part and adds it to its group's `sums` and `aux`, its sample
/// counts and ids to the frame's (`w` pixels wide).
fn add_part(
    (path, info): &(PathBuf, PartInfo),
    w: u32,
    sums: &mut SumBuffer,
    aux: &mut Aux,
    merged: &mut Merged,
) -> Result<()> {
    if info.samples_done.is_empty() {
        return Ok(());
    }
    let (again, part) = read_part(path).map_err(|e| anyhow!("{e}"))?;
    if again != *info {
        bail!("{}: the file changed while being merged", path.display());
    }
    sums.add(&part.beauty);
    aux.add(&Aux {
        images: AuxImages::default(),
        sums: part.passes,
    });
    let win = info.window;
    if let (Some(frame), Some(n)) = (&mut merged.samples, &part.samples) {
        for (k, (x, y)) in rows(&win).enumerate() {
            frame[(y * w + x) as usize] += n[k];
        }
    }
    // Ids depend on the pixel alone: every part of a pixel has them.
    let f = &mut merged.passes.images;
    for (frame, ids) in [
        (&mut f.object, &part.object),
        (&mut f.material, &part.material),
    ] {
        if let Some(ids) = ids {
            for (k, (x, y)) in rows(&win).enumerate() {
                frame[(y * w + x) as usize] = ids[k];
            }
        }
    }
    Ok(())
}

/// The frame's render passes, filled group by group.
struct FramePasses {
    images: AuxImages,
}

impl FramePasses {
    /// Black images of the frame for `passes`.
    fn new(passes: &[Aov], w: u32, h: u32) -> Self {
        let n = (w * h) as usize;
        let sized = |a: Aov| if passes.contains(&a) { n } else { 0 };
        Self {
            images: AuxImages {
                albedo: vec![Default::default(); sized(Aov::Albedo)],
                normal: vec![Default::default(); sized(Aov::Normal)],
                depth: vec![0.0; sized(Aov::Depth)],
                position: vec![Default::default(); sized(Aov::Position)],
                uv: vec![Default::default(); sized(Aov::Uv)],
                variance: vec![Default::default(); sized(Aov::Variance)],
                object: vec![0; sized(Aov::Object)],
                material: vec![0; sized(Aov::Material)],
            },
        }
    }

    /// Pixel `to` of the frame's passes from pixel `from` of `group`'s.
    fn set(&mut self, to: usize, group: &AuxImages, from: usize) {
        fn copy<T: Copy>(to: usize, frame: &mut [T], group: &[T], from: usize) {
            if let Some(v) = group.get(from) {
                frame[to] = *v;
            }
        }
        let f = &mut self.images;
        copy(to, &mut f.albedo, &group.albedo, from);
        copy(to, &mut f.normal, &group.normal, from);
        copy(to, &mut f.depth, &group.depth, from);
        copy(to, &mut f.position, &group.position, from);
        copy(to, &mut f.uv, &group.uv, from);
        copy(to, &mut f.variance, &group.variance, from);
    }
}

/// The pixels of `win`, rows top to bottom.
fn rows(win: &PixelWindow) -> impl Iterator<Item = (u32, u32)> + '_ {
    (win.y0..win.y1).flat_map(move |y| (win.x0..win.x1).map(move |x| (x, y)))
}

/// A part's render passes, for a message.
fn passes_said(info: &PartInfo) -> String {
    let list = |p: &[Aov]| {
        if p.is_empty() {
            "none".to_string()
        } else {
            p.iter().map(|a| a.name()).collect::<Vec<_>>().join(",")
        }
    };
    format!(
        "passes {}{}",
        list(&info.output.aovs),
        if info.output.denoise {
            ", denoised"
        } else {
            ""
        }
    )
}

fn short(digest: &str) -> &str {
    &digest[..digest.len().min(12)]
}

fn range(r: &Range<u32>) -> String {
    format!("{}..{}", r.start, r.end)
}

/// Checks that every pixel's samples `0..spp` are held by exactly one part
/// each; returns the fewest samples any pixel gets from the parts' sums
/// (`spp` unless partial parts are merged).
fn check_coverage(parts: &[(PathBuf, PartInfo)]) -> Result<u32> {
    let first = &parts[0].1;
    let (w, h, spp) = (first.frame.width, first.frame.height, first.frame.spp);
    let (xs, ys, cells) = cut_frame(parts, w, h);
    let (nx, ny) = (xs.len() - 1, ys.len() - 1);
    let grids = tile_grids(parts);
    let full = PixelWindow::full(w, h);
    let name_cell = |cell: &PixelWindow| {
        for &n in &grids {
            if let Some(i) = (0..n).find(|&i| tile(&full, i, n) == *cell) {
                return format!("tile {i} of {n} (pixels {cell})");
            }
        }
        format!("pixels {cell}")
    };
    let mut missing: Vec<String> = Vec::new();
    let mut fewest = spp;
    for iy in 0..ny {
        for ix in 0..nx {
            let cell = PixelWindow {
                x0: xs[ix],
                x1: xs[ix + 1],
                y0: ys[iy],
                y1: ys[iy + 1],
            };
            let mut here = cells[iy * nx + ix].clone();
            here.sort_by_key(|&k| (parts[k].1.samples.start, parts[k].1.samples.end));
            let mut at = 0;
            let mut last: Option<usize> = None;
            let mut done = 0;
            for &k in &here {
                let s = &parts[k].1.samples;
                if s.start < at {
                    let other = last.expect("a part ended there");
                    bail!(
                        "{} and {} overlap: both hold samples {}..{} of pixels {}",
                        parts[other].0.display(),
                        parts[k].0.display(),
                        s.start,
                        at.min(s.end),
                        cell
                    );
                }
                if s.start > at {
                    missing.push(format!("samples {at}..{} of {}", s.start, name_cell(&cell)));
                }
                at = s.end;
                last = Some(k);
                done += parts[k].1.samples_done.len() as u32;
            }
            if at < spp {
                missing.push(format!("samples {at}..{spp} of {}", name_cell(&cell)));
            }
            fewest = fewest.min(done);
        }
    }
    if !missing.is_empty() {
        let n = missing.len();
        let mut list = missing[..n.min(MISSING_SHOWN)].join("; ");
        if n > MISSING_SHOWN {
            list += &format!("; and {} more", n - MISSING_SHOWN);
        }
        bail!(
            "the parts do not make the whole frame ({w}x{h}, {spp} spp): missing {list} \
             ({} part files given)",
            parts.len()
        );
    }
    Ok(fewest)
}

/// The frame cut along every part's window edges, so that each cell is
/// held by the same parts throughout: the cuts along x and y, and each
/// cell's parts (rows of cells, top to bottom). Parts without pixels or
/// samples hold none.
fn cut_frame(
    parts: &[(PathBuf, PartInfo)],
    w: u32,
    h: u32,
) -> (Vec<u32>, Vec<u32>, Vec<Vec<usize>>) {
    let cuts = |edges: &mut Vec<u32>| {
        edges.sort_unstable();
        edges.dedup();
    };
    let held: Vec<usize> = (0..parts.len())
        .filter(|&k| !parts[k].1.window.is_empty() && !parts[k].1.samples.is_empty())
        .collect();
    let mut xs = vec![0, w];
    let mut ys = vec![0, h];
    for &k in &held {
        let win = parts[k].1.window;
        xs.extend([win.x0, win.x1]);
        ys.extend([win.y0, win.y1]);
    }
    cuts(&mut xs);
    cuts(&mut ys);
    let nx = xs.len() - 1;
    let mut cells: Vec<Vec<usize>> = vec![Vec::new(); nx * (ys.len() - 1)];
    for &k in &held {
        let win = parts[k].1.window;
        let ix0 = xs.binary_search(&win.x0).expect("an edge");
        let ix1 = xs.binary_search(&win.x1).expect("an edge");
        let iy0 = ys.binary_search(&win.y0).expect("an edge");
        let iy1 = ys.binary_search(&win.y1).expect("an edge");
        for iy in iy0..iy1 {
            for ix in ix0..ix1 {
                cells[iy * nx + ix].push(k);
            }
        }
    }
    (xs, ys, cells)
}

/// The tile grids the parts came from (`I/N tiles`), to name a missing
/// cell by its tile.
fn tile_grids(parts: &[(PathBuf, PartInfo)]) -> Vec<u32> {
    let mut grids: Vec<u32> = parts
        .iter()
        .filter_map(|(_, i)| {
            let (_, rest) = i.part.split_once('/')?;
            let (n, how) = rest.split_once(' ')?;
            (how == "tiles").then(|| n.parse().ok()).flatten()
        })
        .collect();
    grids.sort_unstable();
    grids.dedup();
    grids
}

/// The parts in groups whose windows overlap (transitively); parts without
/// pixels are left out.
fn groups(parts: &[(PathBuf, PartInfo)]) -> Vec<Vec<usize>> {
    let n = parts.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut k: usize) -> usize {
        while parent[k] != k {
            parent[k] = parent[parent[k]];
            k = parent[k];
        }
        k
    }
    // Sorted by window, parts of one window are neighbours; overlapping
    // windows of different shapes are joined by the pairwise test.
    let mut order: Vec<usize> = (0..n).filter(|&k| !parts[k].1.window.is_empty()).collect();
    order.sort_by_key(|&k| parts[k].1.window);
    for (a, &i) in order.iter().enumerate() {
        for &j in &order[a + 1..] {
            let (wi, wj) = (parts[i].1.window, parts[j].1.window);
            if wi == wj || !wi.intersect(&wj).is_empty() {
                let (ri, rj) = (root(&mut parent, i), root(&mut parent, j));
                parent[ri] = rj;
            }
        }
    }
    let mut out: Vec<Vec<usize>> = Vec::new();
    let mut index_of = vec![usize::MAX; n];
    for &k in &order {
        let r = root(&mut parent, k);
        if index_of[r] == usize::MAX {
            index_of[r] = out.len();
            out.push(Vec::new());
        }
        out[index_of[r]].push(k);
    }
    out
}
