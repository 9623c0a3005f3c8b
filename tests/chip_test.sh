#!/usr/bin/env bash
# The chip formation model chip-4d from the command line (docs/models.md
# 12.1): the flow's time in orbit and the mean return time, the cell
# mapping of its section map split and whole, the largest exponent on 1
# and 2 threads, the equilibria's branch and Hopf points, and bad input (a
# section never crossed, unknown words, a start where Newton fails).
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

# --- bad input -----------------------------------------------------------
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
