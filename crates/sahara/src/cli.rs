//! The command line: subcommands and options (clap derive).

use std::path::PathBuf;

use clap::{ArgAction, Args, Parser, Subcommand};
use sahara_bench::SetKind;
use sahara_kd::{AccelKind, AccelParams, BuildParams, Builder, BvhBuilder, BvhParams, Isa};
use sahara_render::Mesh;

pub use crate::setting_args::SettingArgs;

/// Default timed runs per set.
pub const DEFAULT_RUNS: usize = 3;

/// Sahara: a ray tracer built around an SAH kd-tree.
///
/// With no subcommand, renders the built-in Cornell box to
/// `cornell_box.png` in the working folder (as `sahara render` would);
/// options with no subcommand are `render`'s (`sahara -o out.png --spp 4`).
#[derive(Debug, Parser)]
#[command(name = "sahara", version, propagate_version = true)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run the ray-casting benchmark protocol (docs/bench-protocol.md) on a mesh.
    #[command(long_about = BENCH_ABOUT)]
    Bench(BenchArgs),
    /// Build a kd-tree over a mesh and print its statistics and build time;
    /// of a scene file, how many trees and instances its render builds.
    Stats(StatsArgs),
    /// Render a scene (built-in Cornell box, a mesh file, or a scene file) to PNG or EXR.
    Render(RenderArgs),
    /// Merge render parts into the frame: the same bytes as the frame rendered whole.
    Merge(MergeArgs),
}

/// Options of `sahara merge`.
#[derive(Debug, Args, Clone, PartialEq)]
pub struct MergeArgs {
    /// The part files (.exr) that `sahara render --part / --crop / --samples` wrote.
    #[arg(required = true, value_name = "PARTS")]
    pub parts: Vec<PathBuf>,
    /// The frame to write: .exr or .png.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// Also merge parts that were interrupted (partial), saying what was merged.
    #[arg(long)]
    pub allow_partial: bool,
    /// Denoise the merged frame with Intel Open Image Denoise (the parts must
    /// hold the albedo and normal: render them with --denoise, which also
    /// makes merge denoise, or with --aov albedo,normal).
    #[arg(long)]
    pub denoise: bool,
}

/// Options of `sahara render`.
///
/// The render settings (`--spp`, `--width`, `--integrator`, `--denoise`,
/// `--part`, ...) are the request's table's ([`SettingArgs`]): each holds
/// only if given, over the scene file's value, over the default. The
/// options here are the command line's own: what to load, on how many
/// threads, and what the command does around the render.
#[derive(Debug, Args, Clone, PartialEq, Default)]
pub struct RenderArgs {
    /// What to render: a scene file (.toml, .pbrt, .pbrt.gz, Mitsuba .xml), or a mesh (.obj, .ply, .gltf,
    /// .glb) with its own materials and lights, seen by its camera sidecar,
    /// its own camera or an automatic one, and lit by a default sky and
    /// sun when its own lights are weak (see --sky); none for the built-in
    /// Cornell box.
    pub scene: Option<PathBuf>,
    /// The render settings.
    #[command(flatten)]
    pub settings: SettingArgs,
    /// Rendering threads [default: all hardware threads].
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u16).range(1..=1024))]
    pub threads: Option<u16>,
    /// The camera of a mesh (or the built-in scene): a sidecar JSON file,
    /// or the name of one of a glTF file's cameras [default: the sidecar
    /// <dir>/<stem>.camera.json, else a glTF file's first camera, else the
    /// automatic camera].
    #[arg(long, value_name = "FILE|NAME")]
    pub camera: Option<String>,
    /// What lights the scene besides its own lights: default (Sahara's sky
    /// and sun), none, auto (the default sky and sun if the scene's own
    /// lights are weak), or an equirectangular image FILE (.exr, .hdr)
    /// [default: auto for a mesh, the scene file's `sky` key (else none)
    /// for a scene file].
    #[arg(long, value_name = "default|none|auto|FILE")]
    pub sky: Option<String>,
    /// A parameter of a Mitsuba scene (.xml), as Mitsuba's own `-D`: its
    /// `$NAME` references take VALUE, whatever the file's `<default>` says
    /// (repeatable).
    #[arg(short = 'D', value_name = "NAME=VALUE", value_parser = parse_define)]
    pub define: Vec<(String, String)>,
    /// During a progressive render, rewrite the output (atomically, marked
    /// partial) with the passes done so far at most every SECS seconds, to
    /// watch it in an image viewer; the final image replaces it.
    #[arg(long, value_name = "SECS")]
    pub preview_every: Option<f64>,
    /// With a part: if the output already holds this part of this frame,
    /// complete, do not render it again (for retried farm tasks).
    #[arg(long)]
    pub skip_existing: bool,
}

const BENCH_ABOUT: &str = "\
Run the ray-casting benchmark protocol (docs/bench-protocol.md) on a mesh.

Builds the tree (best of 3 builds), generates the protocol's ray sets on a
1024x1024 image (primary; shadow and diffuse from Sahara's own primary hits;
1,048,576 random rays) and traces each set once as a warm-up, then --runs
times on 1 thread and --runs times on --threads threads (chunks of 4096
rays). Reports rays, hits, the f64 t-sum and the best Mrays/s of each.

The camera is --camera FILE, else the sidecar <dir>/<stem>.camera.json next
to the mesh if it exists, else the protocol's auto camera.

Comparing ray by ray with another tracer (e.g. embree_bench):
  --dump-rays SET FILE  writes the generated rays of SET (32 bytes per ray:
                        f32 ox oy oz tmin dx dy dz tmax, little endian);
  --dump SET FILE       writes Sahara's hits on SET (8 bytes per ray: f32 t,
                        u32 triangle; miss = +inf/0xFFFFFFFF, occluded shadow
                        ray = 0/0xFFFFFFFE); SET must be one of --sets;
  --rays FILE           traces the rays of a ray file instead of generating
                        sets; they form the set named `file` (closest hit, or
                        any hit with --any-hit), so its hits are dumped with
                        `--dump file HITS`.
  --primary-hits FILE   generates shadow and diffuse from another tracer's
                        primary hit file instead of Sahara's primary hits:
                        secondary rays start at the hit points, so a 1-ulp
                        difference in a primary t moves them, and a few
                        grazing rays change their result; with the other
                        tracer's hits both trace bit-identical rays.
--dump and --dump-rays may be given several times.

Human-readable results go to stdout, progress to stderr; with --json stdout
holds exactly one JSON object: mesh, triangles, builder, build_ms,
memory_bytes, sah_cost, threads, runs, tree_depth, leaves, camera, and
sets.<name>.{rays, hits, t_sum, mrays_1t, mrays_1t_cpu, mrays_all,
mrays_batch_1t, mrays_batch_1t_cpu[, counters]} (batch: one closest_hits or
any_hits call over the set, checked hit for hit against single rays);
the primary set adds its packet paths (8 rays on 4x2 tiles, 16 on 4x4):
mrays_packet_1t[_cpu] and mrays_packet16_1t[_cpu].";

/// Options of `sahara bench`.
#[derive(Debug, Args)]
pub struct BenchArgs {
    /// The mesh (.obj, .ply, .gltf or .glb; a glTF scene's meshes are merged
    /// in scene order); none for a built-in procedural scene.
    pub mesh: Option<PathBuf>,
    /// How to run.
    #[command(flatten)]
    pub opts: BenchOptions,
}

/// Options of `sahara bench` other than the mesh.
#[derive(Debug, Args)]
pub struct BenchOptions {
    /// The tree to build.
    #[command(flatten)]
    pub tree: TreeOptions,
    /// Threads of the multi-threaded runs (and of the build) [default: all
    /// hardware threads].
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u16).range(1..=1024))]
    pub threads: Option<u16>,
    /// Timed runs per set and thread count; the best is reported.
    #[arg(long, default_value_t = DEFAULT_RUNS, value_parser = parse_runs)]
    pub runs: usize,
    /// Sets to trace, comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        value_parser = parse_set,
        default_value = "primary,shadow,diffuse,random",
        conflicts_with = "rays"
    )]
    pub sets: Vec<SetKind>,
    /// Print one JSON object on stdout instead of tables.
    #[arg(long)]
    pub json: bool,
    /// Also count traversal work (inner nodes, leaves, triangle tests per
    /// ray) and show the SAH's expectation next to it.
    #[arg(long)]
    pub counters: bool,
    /// Write the hits of SET (or `file` with --rays) to FILE.
    #[arg(long, num_args = 2, value_names = ["SET", "FILE"], action = ArgAction::Append)]
    pub dump: Vec<String>,
    /// Write the generated rays of SET to FILE.
    #[arg(
        long = "dump-rays",
        num_args = 2,
        value_names = ["SET", "FILE"],
        action = ArgAction::Append,
        conflicts_with = "rays"
    )]
    pub dump_rays: Vec<String>,
    /// Trace the rays of this ray file (the set `file`) instead of the
    /// generated sets.
    #[arg(long, value_name = "FILE")]
    pub rays: Option<PathBuf>,
    /// With --rays: trace any-hit (occlusion) queries instead of closest hit.
    #[arg(long, requires = "rays")]
    pub any_hit: bool,
    /// Generate shadow and diffuse from the primary hits in this hit file
    /// (e.g. another tracer's `--dump primary`) instead of Sahara's own, so
    /// that both tracers trace bit-identical secondary rays.
    #[arg(long, value_name = "FILE", conflicts_with = "rays")]
    pub primary_hits: Option<PathBuf>,
    /// Camera sidecar JSON to use instead of <dir>/<stem>.camera.json.
    #[arg(long, value_name = "FILE", conflicts_with = "rays")]
    pub camera: Option<PathBuf>,
}

impl Default for BenchOptions {
    fn default() -> Self {
        Self {
            tree: TreeOptions::default(),
            threads: None,
            runs: DEFAULT_RUNS,
            sets: SetKind::ALL.to_vec(),
            json: false,
            counters: false,
            dump: Vec::new(),
            dump_rays: Vec::new(),
            rays: None,
            any_hit: false,
            primary_hits: None,
            camera: None,
        }
    }
}

/// Options of `sahara stats`.
#[derive(Debug, Args)]
pub struct StatsArgs {
    /// The mesh (.obj, .ply, .gltf or .glb; a glTF scene's meshes are merged
    /// in scene order), or a scene file (.toml, .pbrt, .pbrt.gz, .xml): then the
    /// trees and instances a render of it builds.
    pub mesh: PathBuf,
    /// The tree to build.
    #[command(flatten)]
    pub tree: TreeOptions,
    /// Builds to time; the best is reported.
    #[arg(long, default_value_t = 1, value_parser = parse_runs)]
    pub runs: usize,
    /// Threads of the build [default: all hardware threads].
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u16).range(1..=1024))]
    pub threads: Option<u16>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
    /// Also build the kd-tree and the hierarchy by each of its builders
    /// (spatial, binned, kd) over the same triangles, and put their build
    /// times, memory, references and expected work per ray side by side.
    #[arg(long)]
    pub all: bool,
}

/// Which tree to build over which triangles (shared by `bench` and `stats`).
#[derive(Debug, Args, Clone, PartialEq)]
pub struct TreeOptions {
    /// The structure: `bvh` (the eight-wide hierarchy, the default) or
    /// `kd` (the kd-tree).
    #[arg(long, default_value = "bvh", value_parser = parse_accel)]
    pub accel: AccelKind,
    /// The hierarchy's build: spatial (SAH with spatial splits, the
    /// default), binned (object splits only), kd (collapsed from the SAH
    /// kd-tree).
    #[arg(long, default_value = "spatial", value_name = "NAME", value_parser = parse_bvh_builder)]
    pub bvh_builder: BvhBuilder,
    /// The widest instructions the queries may use, of those the CPU has:
    /// avx512 (the default), avx2 or portable. Renders hold their queries
    /// to avx2 (docs/performance.md says why); answers are the same.
    #[arg(long, default_value = "avx512", value_parser = parse_isa)]
    pub isa: Isa,
    /// Tree builder: sah, binned, binnedN (N bins, 2..=1024), rr-middle,
    /// rr-median, largest-middle, largest-median, middle, median.
    #[arg(long, default_value = "sah", value_parser = parse_builder)]
    pub builder: Builder,
    /// SAH cost of a traversal step, K_T [default: the builder's].
    #[arg(long, value_parser = parse_positive)]
    pub traversal_cost: Option<f32>,
    /// SAH cost of one leaf test (a block of --leaf-width triangles), K_I [default: 40].
    #[arg(long, value_parser = parse_positive)]
    pub intersection_cost: Option<f32>,
    /// Fraction of the SAH cost forgiven for cutting off empty space, in
    /// [0, 1) [default: the builder's].
    #[arg(long, value_parser = parse_bonus)]
    pub empty_bonus: Option<f32>,
    /// Depth cap [default: 8 + 1.3 log2 N].
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=63))]
    pub max_depth: Option<u32>,
    /// Leaf size at which the naive builders stop [default: 4].
    #[arg(long)]
    pub max_leaf_size: Option<u32>,
    /// Triangles the SAH assumes a leaf tests at once: a leaf of n costs
    /// K_I ceil(n / W) [default: 8, the leaf block width; 1 is the classic
    /// SAH].
    #[arg(long, value_name = "W", allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub leaf_width: Option<u32>,
    /// Extra SAH cost of each triangle in a leaf, in leaf tests: a leaf of n
    /// costs K_I (ceil(n / W) + C n) [default: the builder's].
    #[arg(long, value_name = "C", value_parser = parse_non_negative)]
    pub lane_cost: Option<f32>,
    /// Binned builder: cells of at most N references are built by the
    /// exact sweep (0: bins all the way down) [default: the builder's].
    #[arg(long, value_name = "N")]
    pub exact_below: Option<u32>,
    /// Store each leaf block's distinct vertices once: about two thirds of
    /// the tree's memory, tracing some 3-13% slower.
    #[arg(long)]
    pub compact_leaves: bool,
    /// Build no wide nodes: batches walk the binary 8-byte nodes ray by
    /// ray, and the tree's memory holds no wide nodes (for comparisons).
    #[arg(long)]
    pub binary_nodes: bool,
    /// Use only the first FRACTION of the triangles, in file order (0 < F
    /// <= 1; for build-scaling measurements).
    #[arg(long, value_name = "FRACTION", value_parser = parse_subset)]
    pub subset: Option<f64>,
}

impl Default for TreeOptions {
    fn default() -> Self {
        Self {
            accel: AccelKind::Bvh,
            bvh_builder: BvhBuilder::Spatial,
            isa: Isa::Avx512,
            builder: Builder::Sah,
            traversal_cost: None,
            intersection_cost: None,
            empty_bonus: None,
            max_depth: None,
            max_leaf_size: None,
            leaf_width: None,
            lane_cost: None,
            exact_below: None,
            compact_leaves: false,
            binary_nodes: false,
            subset: None,
        }
    }
}

impl TreeOptions {
    /// The structure and build parameters these options ask for.
    pub fn accel_params(&self) -> AccelParams {
        let kd = self.params();
        AccelParams {
            kind: self.accel,
            kd,
            bvh: BvhParams {
                kd,
                ..BvhParams::new(self.bvh_builder)
            },
            isa: self.isa,
        }
    }

    /// A name for what is built, as `bvh8 (spatial)` or `kd-tree (sah)`.
    pub fn structure_name(&self) -> String {
        match self.accel {
            AccelKind::Bvh => format!("bvh8 ({})", self.bvh_builder.name()),
            AccelKind::Kd => format!("kd-tree ({})", self.builder.name()),
        }
    }

    /// The kd-tree's build parameters these options ask for.
    pub fn params(&self) -> BuildParams {
        let mut p = BuildParams::new(self.builder);
        p.traversal_cost = self.traversal_cost.unwrap_or(p.traversal_cost);
        p.intersection_cost = self.intersection_cost.unwrap_or(p.intersection_cost);
        p.empty_bonus = self.empty_bonus.unwrap_or(p.empty_bonus);
        p.max_depth = self.max_depth.or(p.max_depth);
        p.max_leaf_size = self.max_leaf_size.unwrap_or(p.max_leaf_size);
        p.leaf_width = self.leaf_width.unwrap_or(p.leaf_width);
        p.lane_cost = self.lane_cost.unwrap_or(p.lane_cost);
        p.exact_below = self.exact_below.unwrap_or(p.exact_below);
        p.compact_leaves = self.compact_leaves;
        p.wide_nodes = !self.binary_nodes;
        p
    }

    /// The mesh cut down to `--subset`, if given.
    pub fn select(&self, mut mesh: Mesh) -> Mesh {
        if let Some(f) = self.subset {
            let n = ((mesh.indices.len() as f64 * f).round() as usize).max(1);
            mesh.indices.truncate(n);
        }
        mesh
    }
}

fn parse_positive(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v > 0.0 && v.is_finite() => Ok(v),
        _ => Err(format!("'{s}' is not a positive number")),
    }
}

fn parse_non_negative(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v >= 0.0 && v.is_finite() => Ok(v),
        _ => Err(format!("'{s}' is not a number >= 0")),
    }
}

fn parse_bonus(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if (0.0..1.0).contains(&v) => Ok(v),
        _ => Err(format!("'{s}' is not a number in [0, 1)")),
    }
}

fn parse_subset(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v > 0.0 && v <= 1.0 => Ok(v),
        _ => Err(format!("'{s}' is not a fraction in (0, 1]")),
    }
}

/// A structure by name.
fn parse_accel(s: &str) -> Result<AccelKind, String> {
    AccelKind::parse(s).ok_or_else(|| format!("unknown structure '{s}'; expected bvh or kd"))
}

/// An instruction limit by name.
fn parse_isa(s: &str) -> Result<Isa, String> {
    Isa::parse(s)
        .ok_or_else(|| format!("unknown instructions '{s}'; expected avx512, avx2 or portable"))
}

/// A hierarchy builder by name.
fn parse_bvh_builder(s: &str) -> Result<BvhBuilder, String> {
    BvhBuilder::parse(s)
        .ok_or_else(|| format!("unknown hierarchy builder '{s}'; expected spatial, binned or kd"))
}

/// A builder by name, with the list of names in the error.
fn parse_builder(s: &str) -> Result<Builder, String> {
    Builder::parse(s).ok_or_else(|| {
        format!(
            "unknown builder '{s}'; expected one of: sah, binned, binnedN (N = 2..=1024), \
             rr-middle, rr-median, largest-middle, largest-median, middle, median"
        )
    })
}

/// A set by name.
fn parse_set(s: &str) -> Result<SetKind, String> {
    SetKind::parse(s)
        .ok_or_else(|| format!("unknown set '{s}'; expected primary, shadow, diffuse or random"))
}

/// A run count, 1 to 1000.
/// `NAME=VALUE` of `-D`: a parameter name of letters, digits and `_`.
fn parse_define(s: &str) -> Result<(String, String), String> {
    let Some((name, value)) = s.split_once('=') else {
        return Err(format!("'{s}' is not NAME=VALUE"));
    };
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err(format!(
            "'{name}' is not a parameter name (letters, digits and '_')"
        ));
    }
    Ok((name.to_owned(), value.to_owned()))
}

fn parse_runs(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(n) if (1..=1000).contains(&n) => Ok(n),
        _ => Err(format!("'{s}' is not a run count from 1 to 1000")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn cli_is_well_formed() {
        Cli::command().debug_assert();
    }

    #[test]
    fn bench_options_parse() {
        let cli = Cli::try_parse_from([
            "sahara",
            "bench",
            "m.obj",
            "--builder",
            "binned32",
            "--sets",
            "primary,random",
            "--dump",
            "primary",
            "a.bin",
            "--dump",
            "random",
            "b.bin",
            "--runs",
            "2",
        ])
        .unwrap();
        let Some(Command::Bench(b)) = cli.command else {
            panic!("bench expected")
        };
        assert_eq!(b.opts.tree.builder, Builder::Binned { bins: 32 });
        assert_eq!(b.opts.sets, vec![SetKind::Primary, SetKind::Random]);
        assert_eq!(b.opts.dump, vec!["primary", "a.bin", "random", "b.bin"]);
        assert_eq!(b.opts.runs, 2);
        let d = BenchOptions::default();
        let cli = Cli::try_parse_from(["sahara", "bench", "m.obj"]).unwrap();
        let Some(Command::Bench(b)) = cli.command else {
            panic!("bench expected")
        };
        assert_eq!(
            (b.opts.tree.builder, b.opts.runs, b.opts.sets),
            (d.tree.builder, d.runs, d.sets)
        );
    }

    #[test]
    fn bad_options_are_rejected() {
        for args in [
            &["sahara", "bench", "m.obj", "--builder", "kd"][..],
            &["sahara", "bench", "m.obj", "--sets", "primary,bogus"],
            &["sahara", "bench", "m.obj", "--runs", "0"],
            &["sahara", "bench", "m.obj", "--threads", "0"],
            &["sahara", "bench", "m.obj", "--any-hit"],
            &[
                "sahara", "bench", "m.obj", "--rays", "r.bin", "--sets", "primary",
            ],
            &["sahara", "bench", "m.obj", "--dump", "primary"],
        ] {
            assert!(Cli::try_parse_from(args).is_err(), "{args:?}");
        }
        let e = Cli::try_parse_from(["sahara", "stats", "m.obj", "--builder", "kd"]).unwrap_err();
        assert!(e.to_string().contains("unknown builder 'kd'"), "{e}");
    }
}
