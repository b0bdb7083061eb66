//! Human-readable tables of the reports.

use std::fmt::Write;

use sahara_bench::report::{BenchReport, SetReport, StatsReport, StructureStats};

/// `1234567` as `1,234,567`.
pub fn thousands(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// `n` with `word`, pluralised: `1 run`, `3 runs`.
pub fn count(n: usize, word: &str) -> String {
    if n == 1 {
        format!("1 {word}")
    } else {
        format!("{n} {word}s")
    }
}

/// Bytes with a MiB figure.
pub fn bytes(n: usize) -> String {
    format!(
        "{} bytes ({:.2} MiB)",
        thousands(n as u64),
        n as f64 / 1048576.0
    )
}

/// A vector as `(x y z)`.
fn vec3(v: [f32; 3]) -> String {
    format!("({} {} {})", v[0], v[1], v[2])
}

/// What the bench table's sets and columns are, printed under it.
const BENCH_LEGEND: &str = "\
sets: primary (camera rays, one per pixel), shadow (from the primary hits
  to a point light), diffuse (cosine-weighted bounces from the primary
  hits), random (rays between random points of the scene's box); closest
  hit except shadow (any hit); docs/bench-protocol.md has the details
t-sum: the sum of the hit distances in f64, to compare tracers ray for ray
Mrays/s 1T: rays a second traced one by one on 1 thread, by wall time;
  1T CPU: the same by the thread's CPU time; NT: on N threads
batch: the whole set in one batch call on 1 thread; packets: 8- or 16-ray
  packets of neighbouring camera rays; both checked hit for hit";

/// The header and one table row per set.
pub fn bench_report(r: &BenchReport) -> String {
    let mut s = String::new();
    bench_header(&mut s, r);
    let _ = writeln!(s);
    let entries = r.sets.entries();
    bench_table(&mut s, r, &entries);
    let _ = writeln!(s);
    let _ = writeln!(s, "{}", BENCH_LEGEND.trim_end());
    bench_counters(&mut s, &entries);
    // Columns left empty (one thread) leave no trailing blanks.
    s.lines().map(|l| l.trim_end().to_owned() + "\n").collect()
}

/// The report's header: the mesh, the camera, the tree and how it was timed.
fn bench_header(s: &mut String, r: &BenchReport) {
    let _ = writeln!(s, "mesh       {}", r.mesh);
    let _ = writeln!(s, "triangles  {}", thousands(r.triangles as u64));
    if let Some(c) = &r.camera {
        let _ = writeln!(
            s,
            "camera     {}: eye {} target {} up {} vfov {}",
            c.source,
            vec3(c.eye),
            vec3(c.target),
            vec3(c.up),
            c.vfov_deg
        );
    }
    let _ = writeln!(s, "builder    {}", r.builder);
    let _ = writeln!(
        s,
        "build      {:.1} ms (best of {} on {})",
        r.build_ms,
        sahara_bench::runner::BUILD_RUNS,
        count(r.threads, "thread")
    );
    let _ = writeln!(s, "memory     {}", bytes(r.memory_bytes));
    let _ = writeln!(s, "SAH cost   {:.3}", r.sah_cost);
    let _ = writeln!(
        s,
        "tree       depth {}, {} leaves",
        r.tree_depth,
        thousands(r.leaves as u64)
    );
    let _ = writeln!(
        s,
        "timing     best of {} after one warm-up; 1 thread and {}",
        count(r.runs, "run"),
        count(r.threads, "thread")
    );
}

/// One row per set (and its batch and packet rows).
fn bench_table(s: &mut String, r: &BenchReport, entries: &[(&str, &SetReport)]) {
    // With one thread the all-threads column would repeat the first.
    let many = r.threads > 1;
    let all = if many {
        format!("{:>11}", format!("Mrays/s {}T", r.threads))
    } else {
        String::new()
    };
    let _ = writeln!(
        s,
        "{:<8} {:>11} {:>11} {:>22} {:>11} {:>11} {all}",
        "set", "rays", "hits", "t-sum", "Mrays/s 1T", "1T CPU"
    );
    let column = |v: f64| {
        if many {
            format!("{v:>11.3}")
        } else {
            String::new()
        }
    };
    let dash = if many { "-" } else { "" };
    for (name, e) in entries {
        let _ = writeln!(
            s,
            "{:<8} {:>11} {:>11} {:>22.6} {:>11.3} {:>11.3} {}",
            name,
            thousands(e.rays as u64),
            thousands(e.hits),
            e.t_sum,
            e.mrays_1t,
            e.mrays_1t_cpu,
            column(e.mrays_all)
        );
        let _ = writeln!(
            s,
            "{:<8} {:>11} {:>11} {:>22} {:>11.3} {:>11.3} {dash:>11}",
            "  batch",
            "(one call",
            "of the set)",
            "same hits",
            e.mrays_batch_1t,
            e.mrays_batch_1t_cpu
        );
        let packets = [
            (
                "(8 rays,",
                "4x2 tiles)",
                e.mrays_packet_1t,
                e.mrays_packet_1t_cpu,
            ),
            (
                "(16 rays,",
                "4x4 tiles)",
                e.mrays_packet16_1t,
                e.mrays_packet16_1t_cpu,
            ),
        ];
        for (rays, tiles, p, c) in packets {
            if let (Some(p), Some(c)) = (p, c) {
                let _ = writeln!(
                    s,
                    "{:<8} {:>11} {:>11} {:>22} {:>11.3} {:>11.3} {dash:>11}",
                    "  packets", rays, tiles, "same hits", p, c
                );
            }
        }
    }
}

/// The traversal work per ray of the sets that counted it, beside the
/// SAH's expectation.
fn bench_counters(s: &mut String, entries: &[(&str, &SetReport)]) {
    if entries.iter().any(|(_, e)| e.counters.is_some()) {
        let _ = writeln!(s);
        let _ = writeln!(
            s,
            "traversal work per ray meeting the root (and the SAH's expectation, no early exit)"
        );
        let _ = writeln!(
            s,
            "{:<8} {:>7} {:>17} {:>17} {:>19}",
            "set", "root %", "inner (SAH)", "leaves (SAH)", "triangles (SAH)"
        );
        for (name, e) in entries {
            if let Some(c) = &e.counters {
                let (i, l, t) = c.per_root_ray();
                let _ = writeln!(
                    s,
                    "{:<8} {:>7.2} {:>8.2} ({:>6.2}) {:>8.2} ({:>6.2}) {:>9.2} ({:>7.2})",
                    name,
                    100.0 * c.root_fraction,
                    i,
                    c.expected_inner,
                    l,
                    c.expected_leaves,
                    t,
                    c.expected_triangles
                );
            }
        }
    }
}

/// The triangles the trees hold: `given` less `skipped`, then `what` they
/// are, and if any were skipped, how many of how many (`1 (1 of 2
/// skipped: no ray can hit them)`).
pub fn kept_triangles(given: u64, skipped: u64, what: &str) -> String {
    let kept = thousands(given.saturating_sub(skipped));
    if skipped == 0 {
        format!("{kept}{what}")
    } else {
        format!(
            "{kept}{what} ({} of {} skipped: no ray can hit them)",
            thousands(skipped),
            thousands(given)
        )
    }
}

/// The statistics, one per line.
pub fn stats_report(r: &StatsReport) -> String {
    let mut s = String::new();
    let mut lines: Vec<(&str, String)> = vec![
        ("mesh", r.mesh.clone()),
        ("builder", format!("{} ({})", r.builder, r.accel)),
        (
            "build",
            format!(
                "{:.1} ms (best of {})",
                r.build_ms,
                count(r.build_runs, "build")
            ),
        ),
    ];
    match &r.tree {
        StructureStats::Kd(t) => lines.extend(kd_lines(t, r.skipped_triangles)),
        StructureStats::Bvh(b) => lines.extend(bvh_lines(b, r.skipped_triangles)),
    }
    for (k, v) in lines {
        let _ = writeln!(s, "{k:<11} {v}");
    }
    if !r.structures.is_empty() {
        let _ = writeln!(
            s,
            "\n{:<18} {:>10} {:>10} {:>11} {:>9} {:>8} {:>10}",
            "structure", "build ms", "MiB", "references", "inner", "leaves", "triangles"
        );
        for row in &r.structures {
            let m = &row.summary;
            let _ = writeln!(
                s,
                "{:<18} {:>10.1} {:>10.2} {:>11} {:>9.2} {:>8.2} {:>10.2}",
                row.structure,
                row.build_ms,
                m.memory_bytes as f64 / (1 << 20) as f64,
                thousands(m.references as u64),
                m.expected_inner,
                m.expected_leaves,
                m.expected_triangles
            );
        }
        let _ = writeln!(
            s,
            "inner, leaves, triangles: what the SAH expects a ray meeting the root to visit and test \
             (inner: binary kd nodes, or eight-wide nodes)"
        );
    }
    s
}

/// A kd-tree's statistics, as `stats_report` lines.
fn kd_lines(t: &sahara_kd::TreeStats, skipped: usize) -> Vec<(&'static str, String)> {
    vec![
        (
            "triangles",
            kept_triangles(t.triangles as u64, skipped as u64, ""),
        ),
        ("nodes", thousands(t.nodes as u64)),
        ("inner", thousands(t.inner as u64)),
        (
            "leaves",
            format!(
                "{} ({} empty)",
                thousands(t.leaves as u64),
                thousands(t.empty_leaves as u64)
            ),
        ),
        (
            "depth",
            format!("max {}, mean leaf {:.2}", t.max_depth, t.mean_leaf_depth),
        ),
        (
            "leaf size",
            format!(
                "mean {:.2} (non-empty), max {}",
                t.mean_leaf_triangles, t.max_leaf_triangles
            ),
        ),
        (
            "references",
            format!(
                "{} ({:.3} per triangle)",
                thousands(t.references as u64),
                t.duplication
            ),
        ),
        (
            "memory",
            format!(
                "{} (wide nodes {}: {:.3}x the tree without them)",
                bytes(t.memory_bytes),
                bytes(t.wide_node_bytes),
                t.memory_bytes as f64 / (t.memory_bytes - t.wide_node_bytes).max(1) as f64
            ),
        ),
        ("SAH cost", format!("{:.3}", t.sah_cost)),
        (
            "expected",
            format!(
                "{:.2} inner nodes, {:.2} leaves, {:.2} triangles in {:.2} leaf tests per ray meeting the root",
                t.expected_inner, t.expected_leaves, t.expected_triangles, t.expected_leaf_tests
            ),
        ),
    ]
}

/// A hierarchy's statistics, as `stats_report` lines.
fn bvh_lines(b: &sahara_kd::BvhStats, skipped: usize) -> Vec<(&'static str, String)> {
    vec![
        (
            "triangles",
            kept_triangles(b.triangles as u64, skipped as u64, ""),
        ),
        (
            "nodes",
            format!(
                "{} eight-wide, {:.2} children each",
                thousands(b.nodes as u64),
                b.mean_children
            ),
        ),
        (
            "leaves",
            format!(
                "{}, {:.2} triangles each (at most {})",
                thousands(b.leaves as u64),
                b.mean_leaf_triangles,
                sahara_kd::BVH_MAX_LEAF
            ),
        ),
        ("depth", format!("max {}", b.max_depth)),
        (
            "references",
            format!(
                "{} ({:.3} per triangle)",
                thousands(b.references as u64),
                b.duplication
            ),
        ),
        ("memory", bytes(b.memory_bytes)),
        ("SAH cost", format!("{:.3}", b.sah_cost)),
        (
            "expected",
            format!(
                "{:.2} nodes, {:.2} leaves, {:.2} triangles per ray meeting the root",
                b.expected_nodes, b.expected_leaves, b.expected_triangles
            ),
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thousands_separators() {
        assert_eq!(thousands(0), "0");
        assert_eq!(thousands(999), "999");
        assert_eq!(thousands(1000), "1,000");
        assert_eq!(thousands(1048576), "1,048,576");
        assert_eq!(
            (count(1, "run"), count(3, "run")),
            ("1 run".into(), "3 runs".into())
        );
    }
}
