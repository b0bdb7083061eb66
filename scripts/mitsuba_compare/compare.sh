#!/usr/bin/env bash
# The Mitsuba comparison kit (../shared/compare/mitsuba, read-only) run on its two scenes plus `cornell_quads`
# (Mitsuba's mi.cornell_box() as quads; see scenes.py beside this file). The kit's files are linked into
# $WORK/kit/compare/mitsuba with this folder's scenes.py in place of the kit's (which it imports as kit_scenes),
# and the kit's meshes as $WORK/kit/scenes; then the kit's compare.sh runs from there with the same arguments
# and environment (SAHARA, WORK, REF_SPP, ...; see the kit's README.md).
#   scripts/mitsuba_compare/compare.sh [--quick] [--check]
set -euo pipefail
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
KIT=${SAHARA_MITSUBA_KIT:-$(cd "$HERE/../../.." && pwd)/shared/compare/mitsuba}
[ -e "$KIT/compare.sh" ] || { echo "no Mitsuba kit at $KIT: set SAHARA_MITSUBA_KIT" >&2; exit 1; }
export WORK=${WORK:-${TMPDIR:-/tmp}/sahara-mitsuba-compare}
shadow=$WORK/kit/compare/mitsuba
rm -rf "$WORK/kit"
mkdir -p "$shadow"
for f in "$KIT"/*; do
  case $(basename "$f") in
    scenes.py) ln -s "$f" "$shadow/kit_scenes.py" ;;
    *) ln -s "$f" "$shadow/$(basename "$f")" ;;
  esac
done
cp "$HERE/scenes.py" "$shadow/scenes.py"
ln -s "$(cd "$KIT/../../scenes" && pwd)" "$WORK/kit/scenes"
exec bash "$shadow/compare.sh" "$@"
