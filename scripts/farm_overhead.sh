#!/usr/bin/env bash
# The overhead of splitting a frame (docs/render-farm.md): the frame
# rendered whole and as 2, 4, 8 and 16 tile parts, each process on one
# thread, by CPU time (user + system, which other work on the machine
# disturbs less than wall time); then the merge's wall time and peak memory.
# Checks that every merge equals the whole frame byte for byte. Prints a
# Markdown table, then the fixed cost of one process: a part without
# samples (loading the scene and building its trees).
#
#   scripts/farm_overhead.sh SAHARA SCENE [RENDER OPTIONS...]
set -euo pipefail
sahara=$(realpath "$1")
scene=$2
shift 2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# CPU seconds and peak resident KiB of one command.
measure() {
    /usr/bin/time -f '%U %S %M %e' -o "$work/time" "$@" 2>>"$work/log" >/dev/null
    read -r user sys rss wall < "$work/time"
    printf '%.2f %s %s\n' "$(echo "$user + $sys" | bc)" "$rss" "$wall"
}
read -r whole_cpu _ _ < <(measure "$sahara" render "$scene" "$@" --threads 1 -o "$work/whole.exr")
echo "| parts | CPU time of the parts | vs whole | merge time | merge peak memory |"
echo "|---:|---:|---:|---:|---:|"
echo "| 1 (whole) | ${whole_cpu} s | 1.000 | | |"
for n in 2 4 8 16; do
    total=0
    files=()
    for ((i = 0; i < n; i++)); do
        f=$work/part-$i-of-$n.exr
        read -r cpu _ _ < <(measure "$sahara" render "$scene" "$@" --threads 1 --part "$i/$n" -o "$f")
        total=$(printf '%.2f' "$(echo "$total + $cpu" | bc)")
        files+=("$f")
    done
    read -r _ rss wall < <(measure "$sahara" merge "${files[@]}" -o "$work/merged.exr")
    cmp "$work/merged.exr" "$work/whole.exr"
    ratio=$(printf '%.3f' "$(echo "scale=4; $total / $whole_cpu" | bc)")
    echo "| $n | ${total} s | ${ratio} | ${wall} s | $((rss / 1024)) MiB |"
done
read -r fixed_cpu _ _ < <(measure "$sahara" render "$scene" "$@" --threads 1 --samples 0..0 -o "$work/empty.exr")
echo
echo "fixed cost of one process (a part without samples): ${fixed_cpu} s"
