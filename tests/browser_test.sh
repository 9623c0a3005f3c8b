#!/usr/bin/env bash
# The end-to-end test of `cellmap serve` in a real browser (issue 49):
# tests/browser_test.py drives Debian's headless chromium over the DevTools
# protocol (first view's pixels, a pan by dragging, a wheel zoom past one
# pixel per cell, a click's popup and orbit); then the cells the pan
# computed, in the file, equal a single solve of their box cell by cell.
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
"$CM" serve b.cmdb --port 0 > serve.out 2> serve.err &
pid=$!
for _ in $(seq 100); do
  url=$(sed -n 's|.* at \(http://[^ ]*\)/ .*|\1|p' serve.out)
  [ -n "$url" ] && break
  sleep 0.1
done
[ -n "$url" ] || fail "serve did not start: $(cat serve.err)"
python3 "$SRC/tests/browser_test.py" "$url" . || fail "the browser's checks"
kill -TERM "$pid"
wait "$pid" || fail "serve ended with status $?: $(cat serve.err)"

# the file now holds whole tiles around the first box: a box of cells whose
# single solve it must equal, labels and steps
"$CM" info b.cmdb > info.txt || fail "info: $(cat info.txt)"
read -r cells box boxcells < <(sed -n 's/^regions [0-9]*, cells \([0-9]*\), bounding box \([^ ]*\) (\([0-9]*\) cells)$/\1 \2 \3/p' info.txt)
[ -n "${cells:-}" ] && [ "$cells" = "$boxcells" ] ||
  fail "the computed cells are not a box: $(grep ^regions info.txt)"
if [ -n "${box:-}" ]; then
  read -r nx ny < <(python3 -c "
x, y = '$box'.split(',')
(x0, x1), (y0, y1) = (map(float, x.split(':')), map(float, y.split(':')))
print(round((x1 - x0) / 0.5), round((y1 - y0) / 0.08))")
  "$CM" solve --db single.cmdb $pd --region "$box" --cells "${nx}x$ny" > /dev/null || fail "single solve of $box"
  window=$(python3 -c "
x, y = '$box'.split(',')
(x0, x1), (y0, y1) = (map(float, x.split(':')), map(float, y.split(':')))
print('%.6f:%.6f,%.6f:%.6f' % (x0 + 0.005, x1 - 0.005, y0 + 0.0008, y1 - 0.0008))")
  for f in b single; do
    "$CM" export $f.cmdb --labels $f.labels.npy --steps $f.steps.npy --window "$window" || fail "export $f"
  done
  python3 "$SRC/tests/serve_check.py" same b.labels.npy single.labels.npy || fail "labels differ from a single solve's"
  python3 "$SRC/tests/serve_check.py" equal b.steps.npy single.steps.npy || fail "steps differ from a single solve's"
fi
exit $((fails > 0))
