#!/usr/bin/env bash
# The example figures (assets/examples/make-figures.sh) are reproduced byte
# for byte: same commands, same PNGs, on any machine with the same packages.
# usage: figures_test.sh PATH/TO/cellmap SOURCE_DIR
set -u
CM=$1
SRC=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$SRC/assets/examples/make-figures.sh" "$CM" "$out" || { echo "FAIL: make-figures.sh"; exit 1; }
fails=0
for f in "$out"/*.png; do
  cmp -s "$f" "$SRC/assets/examples/$(basename "$f")" \
    || { echo "FAIL: $(basename "$f") differs from assets/examples"; fails=$((fails + 1)); }
done
[ $fails -eq 0 ] && echo "figures reproduced"
exit $fails
