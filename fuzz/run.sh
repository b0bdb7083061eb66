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
    echo "== fuzz $target for ${seconds}s"
    # shellcheck disable=SC2086
    cargo fuzz run --fuzz-dir fuzz "$target" -- \
        -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 \
        -print_final_stats=1 "${dict[@]}" ${FUZZ_FLAGS:-}
done
