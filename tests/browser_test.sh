#!/usr/bin/env bash
# The end-to-end test of `cellmap serve` in a real browser (issue 49):
# tests/browser_test.py drives Debian's headless chromium over the DevTools
# protocol (first view's pixels, a pan by dragging, a wheel zoom past one
# pixel per cell, a click's popup and orbit); then the cells the views
# computed, in the refined level's file, equal a single solve of their box
# at half the cell size, cell by cell.
# usage: browser_test.sh PATH/TO/cellmap SOURCE_DIR
set -u
CM=$1
SRC=$2
. "$SRC/tests/testlib.sh"
enter_workdir
export PYTHONPATH="$SRC/tests"

pd="--model microchaos-pd --param alpha=0.078,beta=0,P=0.007,D=0.02"
# a box of whole zoom-0 tiles (256 x 256 cells) holding the attractor at x 144
"$CM" solve --db b.cmdb $pd --region 128:256,-19.52:0.96 --cells 256x256 > /dev/null || fail "solve"
serve_start b.cmdb
python3 "$SRC/tests/browser_test.py" "$url" . || fail "the browser's checks"
serve_stop

# the zoom past one pixel per cell made refined levels, whole files
for level in 1 2 3; do
  "$CM" info b.zoom$level.cmdb > zoom$level.txt 2>&1 || fail "info of zoom $level: $(cat zoom$level.txt)"
  grep -q "^regions [1-9]" zoom$level.txt || fail "zoom $level computed nothing: $(cat zoom$level.txt)"
done

# The first view and the pan (a level-1 view: the page fits 256 x 256
# cells into 1000 x 800 pixels at zoom 1) computed whole rows of level-1
# tiles: a box of cells whose solve at half the cell size the file must
# equal, labels and steps.
read -r cells box boxcells < <(sed -n 's/^regions [0-9]*, cells \([0-9]*\), bounding box \([^ ]*\) (\([0-9]*\) cells)$/\1 \2 \3/p' zoom1.txt)
[ -n "${cells:-}" ] && [ "$cells" = "$boxcells" ] ||
  fail "the computed cells of zoom 1 are not a box: $(grep ^regions zoom1.txt)"
if [ -n "${box:-}" ]; then
  geometry() {
    python3 -c "
x, y = '$box'.split(',')
(x0, x1), (y0, y1) = (map(float, x.split(':')), map(float, y.split(':')))
print(round((x1 - x0) / 0.25), round((y1 - y0) / 0.04),
      '%.6f:%.6f,%.6f:%.6f' % (x0 + 0.0025, x1 - 0.0025, y0 + 0.0004, y1 - 0.0004))"
  }
  read -r nx ny window < <(geometry)
  "$CM" solve --db single.cmdb $pd --region "$box" --cells "${nx}x$ny" > /dev/null ||
    fail "single solve of $box"
  for f in b.zoom1 single; do
    "$CM" export $f.cmdb --labels $f.labels.npy --steps $f.steps.npy --window "$window" ||
      fail "export $f"
  done
  python3 "$SRC/tests/serve_check.py" same b.zoom1.labels.npy single.labels.npy ||
    fail "zoom 1's labels differ from a solve at half the cell size"
  python3 "$SRC/tests/serve_check.py" equal b.zoom1.steps.npy single.steps.npy ||
    fail "zoom 1's steps differ from a solve at half the cell size"
fi
exit $((fails > 0))
