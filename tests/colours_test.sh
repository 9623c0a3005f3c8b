#!/usr/bin/env bash
# Colours of touching basins, from the figures' pixels (tests/colours.py):
# every pair of basins that meet side by side differs by the documented
# distance (30: Delta E*ab 30 with normal vision, 15 for deuteranopes and
# protanopes) on the quick start's figure, Newton's three Wada basins
# (examples/plugin/newton.c), Fig. 4.21's twelve attractors and a view of
# 47 attractors on a sheared lattice (tests/lattice_plugin.c, each basin
# touching six), also with palettes whose own colours lie closer; and the
# same attractor keeps its colour in two files of one lattice.
# usage: colours_test.sh PATH/TO/cellmap
set -u
CM=$1
HERE=$(cd "$(dirname "$0")" && pwd)
. "$HERE/testlib.sh"
enter_workdir

cc -shared -fPIC -I"$HERE/.." -o libnewton.so "$HERE/../examples/plugin/newton.c" -lm \
  || fail "cc newton"
cc -shared -fPIC -I"$HERE/.." -o liblattice.so "$HERE/lattice_plugin.c" -lm || fail "cc lattice"
fig=(--layers basin,axes,legend --quiet)
newton=(--model-lib ./libnewton.so --model newton --cells 1000x1000 --size 900x760)
lattice=(--model-lib ./liblattice.so --model lattice --cells 800x500)

"$CM" solve --png quick.png "${fig[@]}" || fail "solve quick start"
"$CM" solve "${newton[@]}" --png newton.png "${fig[@]}" || fail "solve newton"
"$CM" solve "${lattice[@]}" --png lattice.png "${fig[@]}" || fail "solve lattice"
"$CM" solve "${lattice[@]}" --palette tol --png lattice-tol.png "${fig[@]}" || fail "lattice, tol"
"$CM" solve "${newton[@]}" --palette tab20 --png newton-tab20.png "${fig[@]}" || fail "newton, tab20"
# more attractors than the palette has colours: they repeat, never side by side
"$CM" solve "${lattice[@]}" --palette okabe-ito --png lattice-okabe.png "${fig[@]}" \
  || fail "lattice, okabe-ito"
checked=(quick newton lattice lattice-tol newton-tab20 lattice-okabe)
if [ -z "${CELLMAP_SANITIZE:-}" ]; then # 12.8 M cells: release build only
  "$CM" solve --model microchaos-pd --param alpha=6.8511e-3,beta=0,P=5.4997e-5,D=2.5665e-3 \
    --region=-125000:125000,-600:600 --cells 4000x3200 --max-steps 100000 --size 1400x600 \
    --png fig-4.21.png "${fig[@]}" || fail "solve Fig. 4.21"
  checked+=(fig-4.21)
fi
for f in "${checked[@]}"; do
  python3 "$HERE/colours.py" "$f.png" 30 || fail "$f.png: touching basins too close in colour"
done
# the views hold what they are meant to: three and 40+ basins
python3 - "$HERE" newton.png lattice.png <<'PY' || fail "the views' basins"
import sys
sys.path.insert(0, sys.argv[1])
from colours import touching_colours
n = {c for p in touching_colours(sys.argv[2]) for c in p}
l = {c for p in touching_colours(sys.argv[3]) for c in p}
assert len(n) == 3, n
assert len(l) >= 24, len(l)   # the palette's 24 colours (47 attractors) and the outside's grey
PY

# one lattice, two files: the roots' colours agree where no neighbour
# forces a change (Newton's three are the same three in both windows)
"$CM" solve "${newton[@]}" --region=-1:3,-2:2 --png newton-right.png "${fig[@]}" \
  || fail "solve newton -1:3"
python3 - "$HERE" newton.png newton-right.png <<'PY' || fail "an attractor changed colour between files"
import re, sys
sys.path.insert(0, sys.argv[1])
from pngcheck import read_png
def colour(path, x, y):
    w, h, bpp, rows, t = read_png(path)
    ox, oy, pw, ph = map(int, re.search(r"plot (\d+),(\d+) (\d+)x(\d+)", t["View"]).groups())
    x0, x1, y0, y1 = map(float, re.search(r"view ([-\d.e]+):([-\d.e]+),([-\d.e]+):([-\d.e]+)", t["View"]).groups())
    px, py = ox + int((x - x0) / (x1 - x0) * pw), oy + int((y1 - y) / (y1 - y0) * ph)
    return tuple(rows[py][bpp * px:bpp * px + 3])
roots = [(1.0, 0.1), (-0.5, 0.9), (-0.5, -0.9)]
a = [colour(sys.argv[2], *p) for p in roots]
b = [colour(sys.argv[3], *p) for p in roots]
assert a == b and len(set(a)) == 3, (a, b)
PY
exit $((fails > 0))
