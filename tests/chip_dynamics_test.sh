#!/usr/bin/env bash
# Chapter 3's dynamics from the command line (docs/models.md 12): the
# orbit born at chip-4d's Hopf point, its Monte Carlo diagram (Fig. 3.5),
# the workpiece's spectra (600 Hz, 12 000 Hz) and amplitude, chip-4d's
# return times and Lyapunov spectra, chip-bue's series and exponents.
# Release build only: these are long runs, and the sanitizer build runs
# the same commands on short spans in chip_test.
# usage: chip_dynamics_test.sh PATH/TO/cellmap
set -u
CM=$1
HERE=$(cd "$(dirname "$0")" && pwd)
. "$HERE/testlib.sh"
enter_workdir

# --- the orbit born at the Hopf point (subcritical: it exists below 4.42808) --
"$CM" periodic --hopf --from 1,0.1,0.2,0.25 --param xi=4 --branch xi=2.5:15 --max-points 200 \
  --csv hopf.csv > hopf.out || fail "periodic --hopf"
grep -q "^Hopf point at xi = 4.4280" hopf.out || fail "periodic --hopf's Hopf point: $(cat hopf.out)"
python3 - hopf.csv <<'PY' || fail "the Hopf orbit's branch"
import csv, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["kind"] == "point"]
xi = [float(r["xi"]) for r in rows]
# from next to the Hopf point down to where the orbit grazes the plane (2.688)
assert max(xi) < 4.42808 and max(xi) > 4.42 and min(xi) < 2.75, (min(xi), max(xi))
assert all(r["outside"] == "1" for r in rows), "the small orbit is unstable (subcritical)"
PY

# --- the Monte Carlo bifurcation diagram (Fig. 3.5) -----------------------
"$CM" equilibria --from 1,0.1,0.2,0.25 --branch xi=3:12 --csv eqb.csv --quiet || fail "equilibria"
"$CM" bifurcation --model chip-4d --sweep xi=3.5,4.8,11 --runs 2 --transient 100 --record 40 \
  --of tau2 --branches eqb.csv --csv bif.csv --png bif.png --threads 2 > bif.out \
  || fail "bifurcation --model chip-4d"
"$CM" bifurcation --model chip-4d --sweep xi=3.5,4.8,11 --runs 2 --transient 100 --record 40 \
  --of tau2 --csv bif1.csv --threads 1 --quiet || fail "bifurcation on one thread"
cmp -s bif.csv bif1.csv || fail "bifurcation: 1 and 2 threads differ"
python3 - bif.csv <<'PY' || fail "chip-4d's diagram: period 2 at 3.5, chaos at 4.8, period 1 at 11"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert list(rows[0]) == ["xi", "run", "tau2"], list(rows[0])
def distinct(xi):
    return len({round(float(r["tau2"]), 6) for r in rows if float(r["xi"]) == xi})
assert distinct(3.5) == 2 and distinct(11) == 1 and distinct(4.8) > 50, \
    (distinct(3.5), distinct(4.8), distinct(11))
PY
[ -s bif.png ] || fail "bifurcation --png wrote no figure"

# --- time series and spectra (thesis 3.3, Figs. 3.9-3.10) -----------------
"$CM" simulate --model chip-workpiece --from 1,0,0,0,0,0 --time 6000 --skip 2000 --dt 0.05 \
  --of z --time-unit 1.64e-4 --spectrum wp_z.csv --csv wp.csv --png wp.png --fmax 20000 \
  > wp.out || fail "simulate chip-workpiece"
"$CM" simulate --model chip-workpiece --from 1,0,0,0,0,0 --time 6000 --skip 2000 --dt 0.05 \
  --time-unit 1.64e-4 --spectrum wp_tau2.csv --json > wp.json || fail "simulate --json"
python3 - wp.csv wp_z.csv wp_tau2.csv wp.json <<'PY' || fail "chip-workpiece's series and spectra"
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert list(rows[0]) == ["t", "tau2", "T0", "T1", "T2", "z", "v"], list(rows[0])
assert len(rows) == 80001 and float(rows[0]["t"]) == 2000 and float(rows[-1]["t"]) == 6000
# the settled band's top is the thesis' amplitude 18.25
zmax = max(float(r["z"]) for r in rows)
assert 18.0 < zmax < 18.5, zmax
def peaks(path, lo, hi):
    s = [(float(r["frequency_hz"]), float(r["power"])) for r in csv.DictReader(open(path))]
    return max((p, f) for f, p in s if lo < f < hi)[1]
# z: the workpiece's 600 Hz (sqrt(A)/(2 pi K0) = 600.2 Hz, one bin = 1.5 Hz)
assert abs(peaks(sys.argv[2], 100, 5000) - 600.2) < 2, peaks(sys.argv[2], 100, 5000)
# tau2: the chip's segmentation near 12 000 Hz (thesis: "about 12000 Hz")
f = peaks(sys.argv[3], 5000, 30000)
assert 11000 < f < 13500, f
d = json.load(open(sys.argv[4]))
assert d["of"] == "tau2" and d["samples"] == 80001 and d["peaks"][0]["frequency_hz"] > 0, d
PY
[ -s wp.png ] || fail "simulate --png wrote no figure"
"$CM" simulate --model chip-4d --param xi=4.8 --from 1,0.1,0.2,0.3 --time 300 --skip 50 --dt 0.01 --of tau2 \
  --json > returns.json || fail "simulate chip-4d --json"
python3 - returns.json <<'PY' || fail "chip-4d's crossings in simulate"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["crossings"] > 400 and abs(d["mean_return"] / 0.558 - 1) < 0.01, d
PY
"$CM" simulate --model chip-bue --param H=0.1 --time 200 --dt 0.05 --of tau --csv bue.csv \
  > bue.out || fail "simulate chip-bue"
python3 - bue.csv <<'PY' || fail "chip-bue's series"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert list(rows[0]) == ["t", "T0", "T", "gamma", "tau"], list(rows[0])
# the start-up: only tau moves before the delay
early = [r for r in rows if float(r["t"]) < 0.4]
assert all(float(r["T"]) == 0 and float(r["gamma"]) == 0 for r in early)
assert max(float(r["T"]) for r in rows) > 1, "no bursts"
PY

# --- the workpiece's exponents from tau2's extrema alone, as the thesis ----
# measured them with TISEAN (Figs. 3.12, 3.15): 462 1/s at f = 0.16 from the
# maxima (m = 10..12; 930 steps of 0.0005 between maxima in its time, ours
# times f), 340 1/s at f = 0.083 from the minima (m = 8..9; 507.4 steps)
kantz="--model chip-workpiece --from 1,0,0,0,0,0 --series tau2 --time 3000 --transient 0
  --dt 0.005 --time-unit 1.64e-4 --radius 0.02,0.05,0.1 --fit 1:6 --json"
"$CM" exponents $kantz --param f=0.16 --dims 10:12 > kantz16.json || fail "exponents --series f=0.16"
"$CM" exponents $kantz --param f=0.083 --values min --dims 8:9 > kantz083.json \
  || fail "exponents --series f=0.083"
python3 - kantz16.json kantz083.json <<'PY' || fail "the workpiece's exponents from its series"
import json, sys
for path, thesis, interval in ((sys.argv[1], 462, 930 * 0.0005 / 0.16),
                               (sys.argv[2], 340, 507.4 * 0.0005 / 0.083)):
    d = json.load(open(path))
    assert d["n"] > 900, d["n"]
    assert abs(d["interval"] / interval - 1) < 0.03, (path, d["interval"], interval)
    assert abs(d["lambda_per_second"] / thesis - 1) < 0.2, (path, d["lambda_per_second"], thesis)
    assert all(c["references"] > 100 for c in d["curves"]), d["curves"]
PY
# chip-4d at xi = 4.8: TISEAN's 0.361 per maximum and 0.647 per unit time
# (Fig. 3.7); the variational equations give 0.631
"$CM" exponents --param xi=4.8 --from 1,0.1,0.2,0.3 --series tau2 --time 3000 --transient 100 \
  --dt 0.002 --json > kantz4d.json || fail "exponents --series chip-4d"
python3 - kantz4d.json <<'PY' || fail "chip-4d's exponent from its maxima"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["embedding_dim"] == 3 and [c["dim"] for c in d["curves"]][::3] == [3, 4, 5], d
assert abs(d["interval"] / 0.558 - 1) < 0.01, d["interval"]
assert abs(d["lambda"] / 0.361 - 1) < 0.05, d["lambda"]
assert abs(d["lambda_per_time"] / 0.647 - 1) < 0.05, d["lambda_per_time"]
assert abs(d["lambda_per_time"] / 0.631 - 1) < 0.03, d["lambda_per_time"]
PY

# --- Lyapunov spectra ------------------------------------------------------
"$CM" exponents --param xi=4.8 --from 1,0.1,0.2,0.3 --time 300 --transient 20 --json \
  > flowexp.json || fail "exponents chip-4d"
"$CM" exponents --param xi=4.8 --of map --from 1,0.2,0.3 --iterations 600 --skip 50 --json \
  --csv mapexp.csv > mapexp.json || fail "exponents --of map"
python3 - flowexp.json mapexp.json mapexp.csv <<'PY' || fail "chip-4d's spectra"
import csv, json, sys
fl, mp = (json.load(open(p)) for p in sys.argv[1:3])
l = fl["lambda"]
# the flow: one positive (thesis 0.647), one zero along the orbit, two strongly negative
assert 0.5 < l[0] < 0.75 and abs(l[1]) < 0.02 and l[2] < -30 and l[3] < -60, l
assert 2.0 < fl["kaplan_yorke"] < 2.05, fl
# the section map: 0.361 per return in the thesis, about 0.56 time units apart
assert abs(mp["mean_flight"] / 0.558 - 1) < 0.01 and 0.28 < mp["lambda"][0] < 0.42, mp
assert abs(mp["lambda_per_time"][0] / l[0] - 1) < 0.15, (mp, l)
rows = list(csv.DictReader(open(sys.argv[3])))
assert list(rows[0])[:2] == ["t", "lambda_1"] and "flow_time" in rows[0], list(rows[0])
assert float(rows[-1]["lambda_1"]) == mp["lambda"][0], (rows[-1], mp)
PY

"$CM" exponents --model chip-bue --samples 10 --time 150 --transient 20 --json --png bue.png \
  > bue_farmer.json || fail "exponents --model chip-bue"
"$CM" exponents --model chip-bue --sync --time 150 --transient 20 --json > bue_sync.json \
  || fail "exponents --model chip-bue --sync"
python3 - bue_farmer.json bue_sync.json <<'PY' || fail "chip-bue's exponents"
import json, sys
fa, sy = (json.load(open(p)) for p in sys.argv[1:3])
# docs/models.md 12.3: a small positive largest exponent, one near zero, by both
# methods (the thesis' Table 3.2 and 2.78 are not reproduced)
l = fa["lambda"]
assert fa["of"] == "farmer" and fa["farmer_dim"] == 44 and 0.05 < l[0] < 0.5 and abs(l[1]) < 0.15, fa
assert l[2] < -3 and 2.0 < fa["kaplan_yorke"] < 2.1, fa
assert sy["of"] == "sync" and 0.05 < sy["lambda"][0] < 0.5, sy
PY
[ -s bue.png ] || fail "exponents --png wrote no figure"

[ "$fails" -eq 0 ] && echo "chip_dynamics_test: all passed"
exit $((fails > 0))
