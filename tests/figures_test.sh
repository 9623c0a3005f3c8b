#!/usr/bin/env bash
# The example figures (assets/examples/make-figures.sh) are reproduced byte
# for byte: same commands, same PNGs, on any machine with the same packages;
# and most of them again with OSMesa hidden, so that EGL draws them: the
# same bytes (tests/figures_egl_twice.sh says which).
# usage: figures_test.sh PATH/TO/cellmap SOURCE_DIR
set -u
CM=$(realpath "$1")
SRC=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
mkdir "$out/egl"
FIGURES_CM=$CM FIGURES_EGL_DIR=$out/egl "$SRC/assets/examples/make-figures.sh" \
  "$SRC/tests/figures_egl_twice.sh" "$out" || { echo "FAIL: make-figures.sh"; exit 1; }
fails=0
for f in "$out"/*.png "$out"/egl/*.png; do
  cmp -s "$f" "$SRC/assets/examples/$(basename "$f")" \
    || { echo "FAIL: ${f#"$out"/} differs from assets/examples"; fails=$((fails + 1)); }
done
drawn=$(ls "$out"/egl/*.png | wc -l)
[ "$drawn" -ge 60 ] || { echo "FAIL: only $drawn figures drawn through EGL"; fails=$((fails + 1)); }
[ $fails -eq 0 ] && echo "figures reproduced ($drawn of them through EGL too)"
exit $fails
