#!/usr/bin/env bash
# End-to-end check of sahara-render.yaml with the Open Job Description
# reference runtime: a small scene rendered as 4 parts and merged by
# `openjd run`, then compared byte for byte with one `sahara render`, for
# tiles and for sample ranges.
#
#   farm/openjd/test.sh SAHARA [OPENJD]
#
# SAHARA is the sahara executable; OPENJD the `openjd` command (default:
# openjd on PATH).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
sahara=$(realpath "$1")
openjd=${2:-openjd}
scene=$(realpath "$here/../../scenes/cornell_glossy_glass.toml")
options="--width 64 --height 48 --spp 16 --pass-spp 8"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$openjd" check "$here/sahara-render.yaml"
# shellcheck disable=SC2086
"$sahara" render "$scene" $options -o "$work/whole.exr" 2>/dev/null
# shellcheck disable=SC2086
"$sahara" render "$scene" $options -o "$work/whole.png" 2>/dev/null
for split in tiles samples; do
    for ext in exr png; do
        out="$work/$split.$ext"
        "$openjd" run "$here/sahara-render.yaml" --step Merge --run-dependencies \
            -p "Scene=$scene" -p "Output=$out" -p "PartsDir=$work/parts-$split" \
            -p Parts=4 -p "Split=$split" -p "RenderOptions=$options" \
            -p "Sahara=$sahara" > "$work/log" 2>&1 || { cat "$work/log"; exit 1; }
        if ! cmp "$out" "$work/whole.$ext"; then
            echo "openjd: the merged $split $ext differs from the single-process image"
            exit 1
        fi
        echo "openjd: 4 $split parts + merge == single-process $ext, byte for byte"
    done
done
