#!/usr/bin/env bash
# The system's attractors of a cluster are those of the single-box solve of
# its cells, cell by cell (export --labels by attractors) and attractor by
# attractor (solve --json): a 4x4 split, 1 and 2 threads, a budget that
# pages regions out, a 50-pan explore session over the same box, and a
# solve killed (kill -9) and resumed. Then the bad input the attractor
# options refuse.
# usage: attractors_test.sh PATH/TO/cellmap
set -u
CM=$1
HERE=$(cd "$(dirname "$0")" && pwd)
. "$HERE/testlib.sh"
enter_workdir

pd=(--model microchaos-pd --param alpha=0.078,beta=0,P=0.007,D=0.02)
box=(--region 0:500,-40:40 --cells 1000x400)
"$CM" solve "${pd[@]}" "${box[@]}" --db whole.cmdb --json > whole-solve.json || fail "single-box solve"
"$CM" export whole.cmdb --labels whole.npy > /dev/null || fail "export whole"

# attractors JSON without times and group ids (a split numbers groups its own way)
attractors() {
  /usr/bin/python3 -c '
import json, sys
d = json.load(open(sys.argv[1]))
for a in d["attractors"]:
    print(a["kind"], a["period"], a["basin_cells"], a["anchor"], a["centre"], a["lo"], a["hi"],
          a["footprint_cells"], len(a["groups"]))
print(d["diverged_cells"], d["undecided_cells"], d["outside_cells"], d["returned_cells"])' "$1"
}
want=$(attractors whole-solve.json) && [ -n "$want" ] || fail "no attractors in whole-solve.json"

# same_labels NAME: NAME.cmdb's attractor labels equal whole.npy's, cell by cell
same_labels() {
  "$CM" export "$1.cmdb" --labels "$1.npy" > /dev/null || { fail "export $1"; return; }
  cmp -s "$1.npy" whole.npy || fail "$1: attractor labels differ from the single-box solve's"
}

for run in "split:--split 4x4" "one-thread:--threads 1" "paged:--split 4x4 --mem 1M"; do
  name=${run%%:*}
  "$CM" solve "${pd[@]}" "${box[@]}" ${run#*:} --db $name.cmdb --json > $name-solve.json \
    || fail "solve $name"
  [ "$(attractors $name-solve.json)" = "$want" ] || fail "$name: attractors differ"
  same_labels $name
done

# explore: 50 pans right over a lattice of the same cells, from a view of
# 10 cells' width at the box's left edge to its right edge
{
  echo "view 0:5 -40:40"
  for _ in $(seq 49); do echo "pan right 100%"; done
  echo "view 0:500 -40:40"
  echo "render pans.png 200x80"
} > pans.explore
"$CM" explore pans.cmdb pans.explore "${pd[@]}" --cell-size 0.5,0.2 --origin 0,-40 > /dev/null \
  || fail "explore of 50 pans"
same_labels pans
"$CM" info pans.cmdb --json > pans-info.json || fail "info pans"
[ "$(attractors pans-info.json)" = "$want" ] || fail "pans: attractors differ"

# kill -9 in the middle of a split solve (after some of its 64 joins were
# committed), then --resume: the single-box solve's labels
big=(--region 0:500,-40:40 --cells 2000x1600)
"$CM" solve "${pd[@]}" "${big[@]}" --db whole-big.cmdb > /dev/null || fail "single-box solve (big)"
"$CM" export whole-big.cmdb --labels whole-big.npy > /dev/null || fail "export whole-big"
"$CM" solve "${pd[@]}" "${big[@]}" --split 8x8 --threads 1 --db killed.cmdb > /dev/null 2>&1 &
pid=$!
joined() { # regions committed so far; read-only, so that no empty file is made before the solve's
  [ -s killed.cmdb ] && sqlite3 -readonly killed.cmdb 'SELECT COUNT(*) FROM regions' 2> /dev/null
}
for _ in $(seq 3000); do
  [ "$(joined)" -ge 8 ] 2> /dev/null && break
  sleep 0.01
done
kill -9 "$pid" 2> /dev/null || fail "the split solve ended before kill -9"
wait "$pid" 2> /dev/null
n=$(joined)
[ -n "$n" ] && [ "$n" -ge 8 ] && [ "$n" -lt 64 ] || fail "kill -9 left '$n' regions, expected some of 64"
"$CM" solve "${pd[@]}" "${big[@]}" --split 8x8 --threads 1 --db killed.cmdb --resume > /dev/null \
  || fail "resume after kill -9"
"$CM" export killed.cmdb --labels killed.npy > /dev/null || fail "export killed"
cmp -s killed.npy whole-big.npy || fail "killed and resumed: attractor labels differ from the single-box solve's"

# Newton's method for z^3 - 1 (examples/plugin/newton.c): 13.7 % of -2:2^2
# leaves the box and comes back, so the exits' followed orbits decide
# those cells. The same labels and counts from a split, 1 thread, a paged
# budget, 50 pans, kill -9 and resume, and an extended cluster rebuilt in
# another order.
cc -shared -fPIC -I"$HERE/.." -o libnewton.so "$HERE/../examples/plugin/newton.c" -lm \
  || fail "build the Newton plugin"
nw=(--model-lib ./libnewton.so --model newton)
nbox=(--region=-2:2,-2:2 --cells 400x400)
"$CM" solve "${nw[@]}" "${nbox[@]}" --db newton.cmdb --json > newton-solve.json || fail "solve newton"
"$CM" export newton.cmdb --labels newton.npy > /dev/null || fail "export newton"
# the single region (no file: one region, its exits followed from its own
# images) draws each cell's attractor as the file's cluster does
"$CM" solve "${nw[@]}" "${nbox[@]}" --json --png region.png --png-mode indexed > region-solve.json \
  || fail "solve newton without a file"
"$CM" render newton.cmdb --png cluster.png --png-mode indexed || fail "render newton.cmdb"
/usr/bin/python3 - "$HERE" region.png cluster.png <<'PY' || fail "Newton: the region's attractor classes differ from the cluster's"
import sys
sys.path.insert(0, sys.argv[1])
from pngcheck import read_png
a, b = read_png(sys.argv[2]), read_png(sys.argv[3])
assert a[3] == b[3] and a[4]["Group classes"] == b[4]["Group classes"]
PY
/usr/bin/python3 - newton-solve.json <<'PY' || fail "Newton: the sink's cells do not come back"
import json, sys
d = json.load(open(sys.argv[1]))
assert len(d["attractors"]) == 3 and d["outside_steps"] == 100, d["attractors"]
assert d["returned_cells"] > 0.1 * d["cells"], d["returned_cells"]
assert d["returned_cells"] + d["diverged_cells"] + d["outside_cells"] == d["sink_cells"], d
assert d["diverged_cells"] + d["outside_cells"] <= d["cells"] // 1000, d
PY
nwant=$(attractors newton-solve.json)
[ "$(attractors region-solve.json)" = "$nwant" ] || fail "Newton: the single region's attractors differ"
for run in "nsplit:--split 4x4" "none-thread:--threads 1" "npaged:--split 4x4 --mem 1M"; do
  name=${run%%:*}
  "$CM" solve "${nw[@]}" "${nbox[@]}" ${run#*:} --db $name.cmdb --json > $name-solve.json \
    || fail "solve $name"
  [ "$(attractors $name-solve.json)" = "$nwant" ] || fail "$name: attractors differ"
  "$CM" export $name.cmdb --labels $name.npy > /dev/null && cmp -s $name.npy newton.npy \
    || fail "$name: attractor labels differ from the single-box solve's"
done
{
  echo "view -2:-1.96 -2:2"
  for _ in $(seq 99); do echo "pan right 100%"; done
  echo "view -2:2 -2:2"
} > npans.explore
"$CM" explore npans.cmdb npans.explore "${nw[@]}" --cell-size 0.01,0.01 --origin=-2,-2 > /dev/null \
  || fail "explore of 100 pans (Newton)"
"$CM" export npans.cmdb --labels npans.npy > /dev/null && cmp -s npans.npy newton.npy \
  || fail "Newton pans: attractor labels differ from the single-box solve's"
"$CM" solve "${nw[@]}" "${nbox[@]}" --split 8x8 --threads 1 --db nkilled.cmdb > /dev/null 2>&1 &
pid=$!
for _ in $(seq 3000); do
  [ -s nkilled.cmdb ] && [ "$(sqlite3 -readonly nkilled.cmdb 'SELECT COUNT(*) FROM regions' 2> /dev/null)" -ge 8 ] \
    2> /dev/null && break
  sleep 0.005
done
kill -9 "$pid" 2> /dev/null
wait "$pid" 2> /dev/null
"$CM" solve "${nw[@]}" "${nbox[@]}" --split 8x8 --threads 1 --db nkilled.cmdb --resume > /dev/null \
  || fail "resume after kill -9 (Newton)"
"$CM" export nkilled.cmdb --labels nkilled.npy > /dev/null && cmp -s nkilled.npy newton.npy \
  || fail "Newton killed and resumed: attractor labels differ from the single-box solve's"
# --extend 3 from the left half; the same regions solved again in reverse
# order as explore views: the same labels
"$CM" solve "${nw[@]}" --region=-2:0,-2:2 --cells 200x400 --extend 3 --db next.cmdb > /dev/null \
  || fail "solve --extend 3 (Newton)"
sqlite3 next.cmdb "SELECT lo, hi FROM regions ORDER BY id DESC" | /usr/bin/python3 -c '
import json, sys
for line in sys.stdin:
    lo, hi = (json.loads(v) for v in line.strip().split("|"))
    x = lambda c: -2 + 0.01 * c
    print("view %.6f:%.6f %.6f:%.6f" % (x(lo[0]), x(hi[0]), x(lo[1]), x(hi[1])))' > nrev.explore
[ "$(wc -l < nrev.explore)" -ge 3 ] || fail "--extend 3 made $(wc -l < nrev.explore) regions"
"$CM" explore nrev.cmdb nrev.explore "${nw[@]}" --cell-size 0.01,0.01 --origin=-2,-2 > /dev/null \
  || fail "explore of the extended regions in reverse order"
"$CM" export next.cmdb --labels next.npy > /dev/null && "$CM" export nrev.cmdb --labels nrev.npy > /dev/null \
  && cmp -s next.npy nrev.npy || fail "Newton --extend 3: labels differ from the same regions in another order"

# Duffing at omega = 0.001 (a period of 6283 time units): rk8pd's first step
# was 98 time units, the state overflowed and GSL accepted it, so every
# orbit had "no image"; it finds the two attractors rkf45 finds
for m in rk8pd rkf45; do
  "$CM" solve --model duffing --param omega=0.001,method=$m --cells 8x8 --json > slow-$m.json \
    || fail "solve duffing omega=0.001 $m"
  /usr/bin/python3 - slow-$m.json <<'PY' || fail "duffing omega=0.001 $m: not two attractors"
import json, sys
d = json.load(open(sys.argv[1]))
assert len(d["attractors"]) == 2 and d["diverged_cells"] == 0, (d["attractors"], d["diverged_cells"])
PY
done

# bad input: a clear message, exit 2, nothing written
expect_usage "--outside-steps" solve --cells 10x10 --outside-steps -1 --db bad3.cmdb
expect_usage "--outside-steps" solve --cells 10x10 --outside-steps 2000000
expect_usage "--outside-steps" solve --cells 10x10 --outside-steps 1.5
expect_usage "--attractor-tol: '0' must be TOL or TOL,MATCH, each above 0" solve --cells 10x10 \
  --attractor-tol 0 --db bad1.cmdb
expect_usage "matching tolerance" solve --cells 10x10 --attractor-tol 1e-3,1e-5
expect_usage "--attractor-tol" solve --cells 10x10 --attractor-tol -1
expect_usage "--attractor-steps" solve --cells 10x10 --attractor-steps 10
expect_usage "--attractor-steps" solve --cells 10x10 --attractor-steps -1,500
expect_usage "--outside-steps" solve --cells 10x10 --outside-steps nan
expect_usage "budget" solve --cells 10x10 --attractor-steps 100,50,60 --db bad2.cmdb
expect_usage "--by" render whole.cmdb --png x.png --by cells
[ ! -e bad1.cmdb ] && [ ! -e bad2.cmdb ] && [ ! -e bad3.cmdb ] && [ ! -e x.png ] || fail "a refused command wrote a file"

[ "$fails" -eq 0 ] && echo "attractors_test: ok"
exit $((fails > 0))
