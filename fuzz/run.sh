#!/usr/bin/env bash
# Runs fuzz targets for a bounded time each: `fuzz/run.sh SECONDS [TARGET...]`
# (default: every target). Seeds are (re)made first by make_seeds.py.
#
# cargo-fuzz wants a nightly compiler; on a stable one, RUSTC_BOOTSTRAP=1
# lets it use the -Z flags it needs (sanitizer, coverage). Exits non-zero on
# the first target that finds a crash, leak, timeout or out-of-memory; the
# input is left in fuzz/artifacts/<target>/ and libFuzzer prints how to
# reproduce it (`cargo fuzz run TARGET fuzz/artifacts/TARGET/crash-...`).
# Extra libFuzzer flags can be given in $FUZZ_FLAGS.
#
# $FUZZ_SEED and $FUZZ_RUNS make a run repeatable: libFuzzer's -seed and
# -runs (inputs tried per target), with SECONDS still the cap. .ci/run sets
# both, so that CI mutates the same corpus the same way on every clone of a
# commit (nearly: coverage through the readers' per-process hash seeds
# varies a little); by hand, leave them unset to explore from a fresh
# random seed until the time is up.
#
# The kd-tree's target (unsafe SIMD walks) is built with the address
# sanitizer, alone (`--no-default-features`: the kd-tree and nothing else)
# in a target folder of its own. The readers' targets (safe Rust) are built
# without a sanitizer unless $FUZZ_SANITIZER names one: libFuzzer still
# catches their panics, timeouts and excess allocations, and their build
# (the readers, the scene formats and the renderer under them) takes
# 5 min 24 s on 2 cores instead of 8 min 07 s with the address sanitizer.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=${1:?usage: fuzz/run.sh SECONDS [TARGET...]}
shift
if [ $# -eq 0 ]; then
    set -- obj ply scene_file gltf image kdtree pbrt mitsuba
fi
export RUSTC_BOOTSTRAP=1
python3 fuzz/make_seeds.py
for target in "$@"; do
    dict=()
    if [ -f "fuzz/dicts/$target.dict" ]; then
        dict=("-dict=fuzz/dicts/$target.dict")
    fi
    if [ "$target" = kdtree ]; then
        build=(--no-default-features --target-dir fuzz/target/kdtree)
    else
        build=(--sanitizer "${FUZZ_SANITIZER:-none}")
    fi
    echo "== fuzz $target for ${seconds}s"
    repeat=()
    if [ -n "${FUZZ_SEED:-}" ]; then
        repeat+=("-seed=$FUZZ_SEED")
    fi
    if [ -n "${FUZZ_RUNS:-}" ]; then
        repeat+=("-runs=$FUZZ_RUNS")
    fi
    # shellcheck disable=SC2086
    cargo fuzz run --fuzz-dir fuzz "${build[@]}" "$target" -- \
        -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 \
        -print_final_stats=1 "${dict[@]}" "${repeat[@]}" ${FUZZ_FLAGS:-}
done
