#!/usr/bin/env bash
# The chip formation model chip-4d from the command line (docs/models.md
# 12.1): the flow's time in orbit and the mean return time, the cell
# mapping of its section map split and whole, the largest exponent on 1
# and 2 threads, the equilibria's branch and Hopf points, and bad input (a
# section never crossed, unknown words, a start where Newton fails); and
# every Chapter 3 analysis from the command line on short spans, so that
# the sanitizer build runs their paths (chip_dynamics_test checks their
# numbers, in the release build).
# test_chip checks the dynamics themselves.
# usage: chip_test.sh PATH/TO/cellmap
set -u
CM=$1
HERE=$(cd "$(dirname "$0")" && pwd)
. "$HERE/testlib.sh"
enter_workdir

# --- orbit: the section map's points and the flow's time at each --------
"$CM" orbit --model chip-4d --from 1.05,0.2,0.27 --steps 2200 --csv orbit.csv \
  || fail "orbit --model chip-4d"
python3 - orbit.csv <<'PY' || fail "orbit's time column and mean return time"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert list(rows[0]) == ["j", "tau2", "T1", "T2", "t"], list(rows[0])
t = [float(r["t"]) for r in rows]
assert t[0] == 0 and all(b > a for a, b in zip(t, t[1:])), "t does not grow"
mean = (t[-1] - t[200]) / (len(t) - 1 - 200)
assert abs(mean / 0.558 - 1) < 0.01, mean   # thesis: 0.558
PY
"$CM" orbit --model chip-4d --from 1.05,0.2,0.27 --steps 3 --json > orbit.json || fail "orbit --json"
python3 - orbit.json <<'PY' || fail "orbit --json's t"
import json, sys
d = json.load(open(sys.argv[1]))
assert len(d["t"]) == len(d["points"]) == 4 and d["t"][0] == 0, d
PY

# --- the cell mapping of the section map: --split as the single solve ----
cells=(--model chip-4d --param xi=3.5 --cells 20x20x20 --threads 2 --json)
"$CM" solve "${cells[@]}" > whole.json || fail "solve chip-4d"
"$CM" solve "${cells[@]}" --split 2x2x2 > split.json || fail "solve chip-4d --split 2x2x2"
python3 - whole.json split.json <<'PY' || fail "chip-4d: --split differs from the single solve"
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
assert len(a["attractors"]) == 1 and a["attractors"][0]["period"] == 2, a["attractors"]
assert a["attractors"] == b["attractors"], (a["attractors"], b["attractors"])
for key in ("cells", "sink_cells", "diverged_cells", "returned_cells", "outside_cells"):
    assert a[key] == b[key], key
groups = lambda d: sorted((g["period"], g["basin_cells"], g["centre"], g["attractor"]) for g in d["groups"])
assert groups(a) == groups(b)
PY

# --- lyapunov: chaos at xi = 4.8, the same on 1 and 2 threads ------------
ly=(lyapunov --model chip-4d --grid xi=4.8,5.2,zeta=21 --from 1.05,0.2,0.27 --d0 1e-6
    --periods 3000 --quiet)
"$CM" "${ly[@]}" --threads 1 --csv l1.csv || fail "lyapunov chip-4d, 1 thread"
"$CM" "${ly[@]}" --threads 2 --csv l2.csv || fail "lyapunov chip-4d, 2 threads"
cmp -s l1.csv l2.csv || fail "chip-4d lyapunov differs between 1 and 2 threads"
python3 - l1.csv <<'PY' || fail "chip-4d lyapunov at xi = 4.8"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
lam = [float(r["lambda"]) for r in rows if abs(float(r["xi"]) - 4.8) < 1e-12]
assert len(lam) == 1 and abs(lam[0] / 0.647 - 1) < 0.1, lam   # thesis (TISEAN): 0.647
PY

# --- equilibria: the Hopf points of the branch in xi at zeta = 21 --------
"$CM" equilibria --from 1,0.1,0.2,0.25 --branch xi=0.5:15 --csv eq.csv > eq.out \
  || fail "equilibria --branch"
python3 - eq.csv <<'PY' || fail "equilibria's Hopf points"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
hopf = [r for r in rows if r["kind"] == "hopf"]
assert [r["kind"] for r in rows].count("point") > 50, len(rows)
xi = [float(r["xi"]) for r in rows if r["kind"] == "point"]
assert xi == sorted(xi) and xi[0] < 0.6 and xi[-1] > 14.9, (xi[0], xi[-1])
assert len(hopf) == 2, hopf
assert abs(float(hopf[0]["xi"]) - 4.42808) < 1e-4 and abs(float(hopf[1]["xi"]) - 11.8039) < 1e-4, hopf
assert abs(float(hopf[0]["omega"]) - 28.00) < 5e-3 and abs(float(hopf[1]["omega"]) - 34.33) < 5e-3
# unstable (a pair to the right) between the Hopf points, stable outside them
for r in rows:
    if r["kind"] == "point":
        inside = float(hopf[0]["xi"]) < float(r["xi"]) < float(hopf[1]["xi"])
        assert (int(r["unstable"]) == 2) == inside, r
PY
grep -q "^hopf at xi = 4.4280" eq.out || fail "equilibria's summary: $(cat eq.out)"
"$CM" equilibria --from 1,0.1,0.2,0.25 --param zeta=40 --json > eq40.json || fail "equilibria --json"
python3 - eq40.json <<'PY' || fail "the equilibrium at xi = 4.8, zeta = 40 (Fig. 3.8 a)"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["unstable"] == 0 and abs(d["re"][0] + 6.23) < 5e-3 and abs(d["im"][0] - 30.14) < 5e-3, d
assert abs(d["re"][2] + 35.9) < 5e-2 and abs(d["re"][3] + 123.3) < 5e-2, d
PY

# --- periodic: the first doublings of the cascade PD1 (Table 3.1) ---------
"$CM" periodic --param xi=2.9 --from 1.05,0.2,0.27 --settle 400 --branch xi=2.9:4.36 \
  --direction up --cascade 3 --csv casc.csv > casc.out || fail "periodic --cascade 3"
python3 - casc.csv <<'PY' || fail "periodic's doublings"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
pd = [(int(r["period"]), float(r["xi"]), float(r["re_1"])) for r in rows if r["kind"] == "pd"]
assert [p for p, _, _ in pd] == [1, 2, 4], pd
for (_, xi, mu), thesis in zip(pd, (3.11285, 4.03007, 4.26861)):
    assert abs(xi - thesis) < 2e-4 and abs(mu + 1) < 1e-3, (xi, thesis, mu)
assert all(int(r["outside"]) == 0 for r in rows if r["kind"] == "point" and r["period"] == "1"
           and float(r["xi"]) < 3.11), "period 1 unstable before its doubling"
PY
grep -q "^Feigenbaum ratio 1: 3.84" casc.out || fail "periodic's Feigenbaum ratio: $(cat casc.out)"

# --- Chapter 3's analyses on short spans (their numbers: chip_dynamics_test) --
"$CM" periodic --hopf --from 1,0.1,0.2,0.25 --param xi=4 --branch xi=2.5:15 --max-points 10 \
  --csv hopf.csv > hopf.out || fail "periodic --hopf"
grep -q "^Hopf point at xi = 4.4280" hopf.out || fail "periodic --hopf's Hopf point: $(cat hopf.out)"
"$CM" equilibria --from 1,0.1,0.2,0.25 --branch xi=3:12 --csv eqb.csv --quiet || fail "equilibria"
"$CM" bifurcation --model chip-4d --sweep xi=3.5,11 --runs 2 --transient 5 --record 5 \
  --of tau2 --branches eqb.csv --csv bif.csv --png bif.png --threads 2 --quiet \
  || fail "bifurcation --model chip-4d"
"$CM" simulate --model chip-workpiece --from 1,0,0,0,0,0 --time 30 --skip 10 --dt 0.05 \
  --of z --time-unit 1.64e-4 --spectrum wp_z.csv --csv wp.csv --png wp.png --json > wp.json \
  || fail "simulate chip-workpiece"
"$CM" simulate --model chip-4d --param xi=4.8 --from 1,0.1,0.2,0.3 --time 5 --dt 0.01 \
  --returns --png returns.png --quiet || fail "simulate --returns"
"$CM" simulate --model chip-bue --param H=0.1 --time 10 --dt 0.05 --of tau --csv bue.csv \
  --quiet || fail "simulate chip-bue"
"$CM" exponents --param xi=4.8 --from 1,0.1,0.2,0.3 --time 2 --transient 1 --json \
  --png flowexp.png > flowexp.json || fail "exponents chip-4d"
"$CM" exponents --param xi=4.8 --of map --from 1,0.2,0.3 --iterations 10 --skip 2 \
  --csv mapexp.csv --quiet || fail "exponents --of map"
"$CM" exponents --model chip-bue --samples 4 --time 5 --transient 1 --csv farmer.csv --quiet \
  || fail "exponents --model chip-bue"
"$CM" exponents --model chip-bue --euler-tangent --samples 4 --time 5 --transient 1 --quiet \
  || fail "exponents --model chip-bue --euler-tangent"
"$CM" exponents --model chip-bue --sync --own-delay --q-max 50 --time 5 --transient 1 --quiet \
  || fail "exponents --model chip-bue --sync"
python3 - wp.json farmer.csv flowexp.json <<'PY' || fail "the short runs' outputs"
import csv, json, sys
d = json.load(open(sys.argv[1]))
assert d["samples"] == 401 and d["of"] == "z", d
rows = list(csv.DictReader(open(sys.argv[2])))
assert list(rows[0]) == ["t", "lambda_1", "lambda_2", "lambda_3", "lambda_4", "kaplan_yorke"], rows[0]
assert len(json.load(open(sys.argv[3]))["lambda"]) == 4
PY
for f in bif.png wp.png returns.png flowexp.png; do [ -s $f ] || fail "no $f"; done

# --- Fig. 3.8: the exponent over (xi, zeta) with the Hopf curve over it ---
"$CM" equilibria --from 1,0.1,0.2,0.25 --branch xi=3:13 --curve zeta=20:22:4 --csv hc.csv \
  --quiet || fail "equilibria --curve"
"$CM" lyapunov --model chip-4d --grid xi=4:6:2,zeta=20:22:2 --periods 30 --curves hc.csv \
  --png hc.png --quiet || fail "lyapunov --curves with a Hopf table"
[ -s hc.png ] || fail "lyapunov --curves wrote no figure"
printf 'kind,xi,T9\nhopf,1,2\n' > wrong.csv
expect_usage "is a table in (xi, T9), the grid in (xi, zeta)" \
  lyapunov --model chip-4d --grid xi=4:6:2,zeta=20:22:2 --periods 3 --curves wrong.csv --png w.png

# --- bad input -----------------------------------------------------------
expect_usage "--hopf needs --branch" periodic --hopf --from 1,0.1,0.2,0.25
expect_usage "--of x: model chip-4d's map has the coordinates tau2, T1, T2" \
  bifurcation --model chip-4d --sweep xi=3.5,4 --of x --csv x.csv
expect_usage "cannot be read" bifurcation --model chip-4d --sweep xi=3.5,4 --branches nope.csv --png x.png
expect_usage "--runs-csv is friction-oscillator's" bifurcation --model chip-4d --sweep xi=3.5,4 --runs-csv r.csv
expect_usage "--of and --branches are for map models" bifurcation --sweep S=0.1:0.2:2 --of x --csv x.csv
expect_usage "dt" simulate --model chip-bue --param dt=0 --time 10
expect_usage "leave out --from" simulate --model chip-bue --from 1,2,3,4 --time 10
expect_usage "a return map needs 3 crossings" simulate --model chip-bue --time 10 --returns --png r.png
expect_usage "coordinates are" simulate --model chip-4d --of x --time 10
expect_usage "--periods is for friction-oscillator" simulate --model chip-4d --periods 3
expect_usage "--dt is for flows" simulate --dt 0.1
expect_usage "is a map: simulate follows flows" simulate --model microchaos-1d --time 10
expect_usage "--renorm 5 is longer than --time 1" exponents --renorm 5 --time 1
expect_usage "the flow of model chip-4d has 4 coordinates" exponents --from 1,2
expect_usage "leave out --from" exponents --model chip-bue --from 1,2,3,4
expect_usage "--sync and --euler-tangent are for the delay model" exponents --sync
expect_usage "--own-delay goes with --sync" exponents --model chip-bue --own-delay
expect_usage "dt = -1" exponents --model chip-bue --param dt=-1
# the exponent of one series (models/embedding.h): a measurement's file, the
# logistic map at r = 4 (log 2 per value), and a model's coordinate
awk 'BEGIN { x = 0.3; print "t,x"; for (i = 0; i < 6000; i++) { x = 4 * x * (1 - x); print i "," x } }' \
  > logistic.csv
"$CM" exponents --series x --input logistic.csv --values all --dims 1 --radius 0.0002 \
  --fit 0:5 --steps 8 --json --csv kantz.csv --png kantz.png > kantz.json \
  || fail "exponents --series --input"
python3 - kantz.json kantz.csv <<'PY' || fail "the logistic map's exponent from its series"
import csv, json, math, sys
d = json.load(open(sys.argv[1]))
assert d["of"] == "series" and d["n"] == 6000 and d["interval"] == 1, d
assert abs(d["lambda"] - math.log(2)) < 0.05, d["lambda"]
assert d["embedding_dim"] == 1 and d["false_neighbours"][0] < 0.01, d["false_neighbours"]
rows = list(csv.DictReader(open(sys.argv[2])))
assert len(rows) == 9 and list(rows[0]) == ["dim", "radius", "k", "S"], rows[0]
assert [int(r["k"]) for r in rows] == list(range(9)) and float(rows[0]["radius"]) < 0.001, rows
PY
echo '{"view": [0, 1, 0, 1], "size": [900, 900], "texts": {"Source": "logistic.csv, column x"}}' > kantz.check.json
python3 "$HERE/pngcheck.py" kantz.png kantz.check.json || fail "exponents --series --png"
"$CM" exponents --model chip-workpiece --param f=0.16 --from 1,0,0,0,0,0 --series tau2 \
  --time 150 --transient 0 --dims 2 --fnn-dim 3 --radius 0.1 --steps 4 --quiet \
  --csv wpkantz.csv || fail "exponents --series of a model"
[ -s wpkantz.csv ] || fail "exponents --series wrote no curves"
expect_usage "no column y in its header" exponents --series y --input logistic.csv
expect_usage "cannot be read" exponents --series x --input nope.csv
expect_usage "--input, --dims and --fit go with --series NAME" exponents --input logistic.csv
expect_usage "--values: 'most' is not max, min or all" exponents --series x --values most
expect_usage "--dims: '3:1' is not M or M:M2" exponents --series x --input logistic.csv --dims 3:1
expect_usage "radii are fractions of the series' range" \
  exponents --series x --input logistic.csv --radius 2
expect_usage "coordinates are" exponents --model chip-4d --series x --time 10
printf 't,x\n0,1\n1,1\n2,1\n' > flat.csv
expect_usage "is constant or empty" exponents --series x --input flat.csv --values all
printf 't,x\n0,1\n1,oops\n' > words.csv
expect_usage "words.csv:3: 'oops' is not a number" exponents --series x --input words.csv
out=$("$CM" simulate --model chip-4d --from 1,0.1,1e7,0 --time 10 --csv lost.csv 2>&1); rc=$?
[ "$rc" -eq 1 ] || fail "simulate of a lost orbit exited $rc: $out"
[ ! -e lost.csv ] || fail "simulate wrote lost.csv although the orbit was lost"

expect_usage "--cascade needs --direction" periodic --from 1,0.2,0.25 --branch xi=2.9:4.36 --cascade 2
expect_usage "the start has 2 value(s)" periodic --from 1,0.2
out=$("$CM" periodic --param xi=4.8 --period 3 --from 3,3,3 --csv nope.csv 2>&1); rc=$?
[ "$rc" -eq 1 ] || fail "periodic where Newton fails exited $rc: $out"
grep -q "Newton's method finds no period-3 point" <<<"$out" || fail "periodic where Newton fails: '$out'"
[ ! -e nope.csv ] || fail "periodic wrote nope.csv although Newton failed"
expect_usage "the flow of model chip-4d has 4 coordinates (tau2, T0, T1, T2)" \
  equilibria --from 1,0.2,0.25
expect_usage "must hold the model's xi = 4.8" equilibria --from 1,0.1,0.2,0.25 --branch xi=5:6
expect_usage "is a map, not a flow" equilibria --model microchaos-1d --from 1
expect_usage "need --branch" equilibria --from 1,0.1,0.2,0.25 --curve zeta=20,21
out=$("$CM" equilibria --from 1,0.1,1e6,-0.999 --csv noeq.csv 2>&1); rc=$?
[ "$rc" -eq 1 ] || fail "equilibria from a start where Newton fails exited $rc: $out"
grep -qi "newton" <<<"$out" || fail "equilibria where Newton fails: '$out'"
[ ! -e noeq.csv ] || fail "equilibria wrote noeq.csv although Newton failed"
out=$("$CM" orbit --model chip-4d --param level=5 --from 1,0.2,0.25 --steps 3 --csv never.csv 2>&1)
rc=$?
[ "$rc" -eq 1 ] || fail "orbit from a start that never crosses the section exited $rc"
grep -q "does not reach the model's section" <<<"$out" || fail "never crossed: '$out'"
[ ! -e never.csv ] || fail "orbit wrote never.csv although the section was not reached"
expect_usage "crossing" orbit --model chip-4d --param crossing=sideways --from 1,0.2,0.25 --steps 1
expect_usage "section" orbit --model chip-4d --param section=T9 --from 1,0.2,0.25 --steps 1
expect_usage "t_max" orbit --model chip-4d --param t_max=0 --from 1,0.2,0.25 --steps 1
expect_usage "dimension 3" orbit --model chip-4d --from 1,0,0.2,0.25 --steps 1

[ "$fails" -eq 0 ] && echo "chip_test: all passed"
exit $((fails > 0))
