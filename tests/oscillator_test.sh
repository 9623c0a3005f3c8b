#!/usr/bin/env bash
# Integration tests of the dry friction oscillator's commands: lyapunov,
# simulate and bifurcation (values at thesis points, CSV, pictures,
# determinism across thread counts, errors). Its basins are checked by
# figures_test.
# usage: oscillator_test.sh PATH/TO/cellmap
set -u
CM=$1
HERE=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
. "$HERE/testlib.sh"
cd "$work"

# --- lyapunov: the chaotic point of Sec. 2.6.1 and the 1a orbit ------------
# one-point grids centred on (Omega, S) = (0.5, 0.05) and (0.5, 0.32), S0 = 0.4
"$CM" lyapunov --param S0=0.4 --grid Omega=0.49:0.51:1,S=0.04:0.06:1 --periods 1000 \
  --csv chaos.csv > /dev/null || fail "lyapunov at the chaotic point"
"$CM" lyapunov --param S0=0.4 --grid Omega=0.49:0.51:1,S=0.31:0.33:1 --periods 1000 \
  --csv orbit1a.csv > /dev/null || fail "lyapunov at 1a"
python3 - chaos.csv orbit1a.csv <<'PY' || fail "lyapunov values"
import csv, sys
chaos = list(csv.DictReader(open(sys.argv[1])))
a1 = list(csv.DictReader(open(sys.argv[2])))
assert len(chaos) == 1 and abs(float(chaos[0]["Omega"]) - 0.5) < 1e-15, chaos
assert abs(float(chaos[0]["S"]) - 0.05) < 1e-15, chaos
assert 0 < float(chaos[0]["lambda"]) < 0.0073, chaos      # thesis: <= 0.0073 (synchronisation)
assert abs(float(a1[0]["lambda"]) + 0.02661) < 0.0005, a1  # ln|multiplier|/T of 1a
PY

# --- a small Fig. 2.20-like grid: CSV and PNG identical on 1 and 2 threads --
grid=(--param S0=0.4 --grid Omega=0.3:0.7:8,S=0.02:0.5:6 --periods 150 --size 600x450)
"$CM" lyapunov "${grid[@]}" --threads 1 --csv g1.csv --png g1.png > g1.out || fail "grid, 1 thread"
"$CM" lyapunov "${grid[@]}" --threads 2 --csv g2.csv --png g2.png > /dev/null || fail "grid, 2 threads"
cmp -s g1.csv g2.csv || fail "lyapunov CSV differs between 1 and 2 threads"
cmp -s g1.png g2.png || fail "lyapunov PNG differs between 1 and 2 threads"
grep -q "48 grid points" g1.out || fail "summary line: $(cat g1.out)"
python3 - g1.csv g1.png "$HERE" <<'PY' || fail "grid CSV and PNG"
import csv, struct, sys, zlib
rows = list(csv.DictReader(open(sys.argv[1])))
assert len(rows) == 48, len(rows)
nan = [r for r in rows if r["lambda"] == "nan"]
assert nan and all(float(r["S"]) > 0.4 for r in nan), nan   # S > S0: not computed
assert all(float(r["S"]) < 0.4 for r in rows if r["lambda"] != "nan")
data = open(sys.argv[2], "rb").read()
w, h = struct.unpack(">II", data[16:24])
assert (w, h) == (600, 450), (w, h)
assert b"Grid" in data and b"Omega=0.3:0.7:8,S=0.02:0.5:6" in data  # numbers as typed
sys.path.insert(0, sys.argv[3])
from pngcheck import read_png
params = read_png(sys.argv[2])[4]["Parameters"]
assert "S0=0.4," in params, params          # the fixed ones are named,
assert "Omega=" not in params and "S=" not in params, params  # the grid's are in Grid only
PY
# --- continue: branches and their events (thesis Fig. 2.17) ----------------
expect_usage "--vary NAME=LO:HI is required" continue --csv x.csv
expect_usage "--vary: 'Q=0:1'" continue --vary Q=0:1
expect_usage "--vary: 'S=0.4:0.1'" continue --vary S=0.4:0.1
expect_usage "outside the range S=0.02:0.2" continue --param S=0.3 --vary S=0.02:0.2
expect_usage "continue follows friction-oscillator only" continue --model microchaos-pd --vary S=0:1
"$CM" continue --param S=0.3,S0=0.4,Omega=0.5 --vary S=0.02:0.4 --down --csv branch.csv \
  --events events.csv > cont.txt || fail "continue the 1a branch"
grep -q "PD_1a  S = 0.0683" cont.txt || fail "continue: no PD_1a near S = 0.068: $(cat cont.txt)"
python3 - branch.csv events.csv <<'PY' || fail "continue's CSV"
import csv, sys
pts = list(csv.DictReader(open(sys.argv[1])))
ev = list(csv.DictReader(open(sys.argv[2])))
assert pts[0]["S"] == "0.29999999999999999" or abs(float(pts[0]["S"]) - 0.3) < 1e-12, pts[0]
s = [float(p["S"]) for p in pts]
assert s == sorted(s, reverse=True), "the branch goes down in S"
assert {p["signature"] for p in pts} == {"dsu"} and all(p["sticks"] == "1" for p in pts)
stable = [p["stable"] == "1" for p in pts]
assert stable[0] and not stable[-1], "stable at the start, unstable past PD"
assert len(ev) == 1 and ev[0]["label"] == "PD_1a" and abs(float(ev[0]["mult1_re"]) + 1) < 1e-6, ev
assert abs(float(ev[0]["S"]) - 0.068) < 1e-3
PY
"$CM" continue --param S=0.38 --vary S=0.3:0.4 --down --from 1.33,0.02 --period 1 --quiet \
  --events - | grep -q "^1,SN_2s,branch point,0,0.3333" || fail "continue --from --period: no SN_2s"
out=$("$CM" continue --vary S=0.02:0.4 --from 1.46,0.04 --period 3 --csv p3.csv 2>&1); rc=$?
[ $rc -eq 1 ] && grep -q "repeats after 1 period(s), not 3: give the period 1" <<<"$out" && [ ! -e p3.csv ] \
  || fail "continue --period 3 on a period-1 solution: $rc $out"

# the diagram: branches drawn as lines (a column of pixels crosses the
# green 1a branch between PD_1a and CS_a with no gap), and --mark's name
# added to the label of the nearest event in every panel: with and
# without it, the images differ only right of SN_1a (S = 0.0356), once
# in each of the three panels
fig=(--param S=0.3,S0=0.4,Omega=0.5 --vary S=0.02:0.4 --both --start 0.3 --start 0.04 --quiet)
"$CM" continue "${fig[@]}" --png plain.png && "$CM" continue "${fig[@]}" --mark 0.0356=N \
  --png marked.png || fail "continue --png, --mark"
python3 - "$HERE" plain.png marked.png <<'PY' || fail "continue's diagram: lines, --mark"
import sys
sys.path.insert(0, sys.argv[1])
from pngcheck import read_png
w, h, bpp, a, _ = read_png(sys.argv[2])
b = read_png(sys.argv[3])[3]
changed = [(x, y) for y in range(h) for x in range(w) if a[y][bpp * x:bpp * x + 3] != b[y][bpp * x:bpp * x + 3]]
assert changed, "--mark changed nothing"
rows = sorted({y for _, y in changed})
bands = 1 + sum(1 for r, s in zip(rows, rows[1:]) if s - r > 40)
assert bands == 3, (bands, rows[:5], rows[-5:])      # one label in each panel
assert min(x for x, _ in changed) > 0.05 * w and max(x for x, _ in changed) < 0.4 * w, changed[:3]
green = (26, 152, 80)
def green_rows(x):
    return [y for y in range(h // 3) if tuple(a[y][bpp * x:bpp * x + 3]) == green]
assert all(green_rows(x) for x in range(w // 3, 2 * w // 3, 7)), "a gap in the 1a branch"
PY
expect_usage "--mark: 'N' is not P=TEXT" continue --vary S=0.02:0.4 --mark N

# --method sync (Fig. 2.23): the coupling that pulls a copy onto the
# oscillator bounds the direct exponent from above, and lies close to it
# (docs/models.md 9.8); the same CSV on one thread and two; bad input
"$CM" lyapunov --param S0=0.4 --grid Omega=0.5,S=0.05 --csv direct.csv --quiet &&
"$CM" lyapunov --method sync --param S=0.05,S0=0.4,Omega=0.5 --q 0:0.01:20 --csv sync.csv \
  --json > sync.json && "$CM" lyapunov --method sync --param S=0.05,S0=0.4,Omega=0.5 \
  --q 0:0.01:20 --csv sync1.csv --threads 1 --quiet || fail "lyapunov --method sync"
cmp -s sync.csv sync1.csv || fail "lyapunov --method sync: the CSV depends on the thread count"
python3 - direct.csv sync.csv sync.json <<'PY' || fail "lyapunov --method sync: the estimate"
import csv, json, sys
direct = float(list(csv.DictReader(open(sys.argv[1])))[0]["lambda"])
rows = list(csv.DictReader(open(sys.argv[2])))
q = json.load(open(sys.argv[3]))["q_sync"]
assert 0.004 < direct < 0.005, direct
assert direct <= q <= 1.25 * direct, (direct, q)          # an upper bound, and a close one
assert [r["synchronised"] for r in rows] == ["0"] * 10 + ["1"] * 10, [r["synchronised"] for r in rows]
assert all(float(r["largest_difference"]) > 1e-3 for r in rows[:10]), rows[:10]
PY
expect_usage "--method sync takes --q LO:HI:N" lyapunov --method sync --grid Omega=0.5,S=0.05 --csv x.csv
expect_usage "--q goes with --method sync" lyapunov --q 0:0.01:10 --csv x.csv
expect_usage "--method: 'fast' must be direct, sync or stickmap" lyapunov --method fast --q 0:1:2
expect_usage "--q: '0.01:0:5' is not LO:HI:N" lyapunov --method sync --q 0.01:0:5

# --method stickmap (Figs. 2.25-2.26): the map of every third stick at S =
# 0.0465 and its transient's exponent, within 10 % of the thesis' lambda_map
# = 0.2167 and lambda_flow = 0.005748, a map step three periods (37.7);
# the same points on one thread and two
stick=(--method stickmap --param S=0.0465,S0=0.4,Omega=0.5)
"$CM" lyapunov "${stick[@]}" --csv stick.csv --json > stick.json &&
"$CM" lyapunov "${stick[@]}" --csv stick1.csv --threads 1 --quiet || fail "lyapunov --method stickmap"
cmp -s stick.csv stick1.csv || fail "lyapunov --method stickmap: the CSV depends on the thread count"
python3 - stick.json stick.csv <<'PY' || fail "lyapunov --method stickmap: the estimate"
import csv, json, math, sys
j = json.load(open(sys.argv[1]))
assert abs(j["lambda_map"] - 0.2167) < 0.1 * 0.2167, j
assert abs(j["lambda_flow"] - 0.005748) < 0.1 * 0.005748, j
assert abs(j["step_time"] - 3 * 4 * math.pi) < 0.5, j
rows = list(csv.DictReader(open(sys.argv[2])))
counted = [r for r in rows if r["counted"] == "1"]
assert len(counted) == j["counted"] > 10000, (len(counted), j["counted"])
# the period-3 orbit's three sticks are fixed points of the map (Fig. 2.26's red dots)
fixed = {round(float(r["x"]), 4) for r in rows if abs(float(r["x"]) - float(r["x_next"])) < 1e-9}
assert {0.845, 0.8581, 1.0606} <= fixed, sorted(fixed)[:12]
PY
expect_usage "--method stickmap takes no --grid" lyapunov --method stickmap --grid Omega=0.5,S=0.05 --csv x.csv

# --switch: the period-doubled branch from PD_1a, a period-2 solution (P^2's
# fixed point, not P's) stable just below the doubling
"$CM" continue --param S=0.3,S0=0.4,Omega=0.5 --vary S=0.02:0.4 --down --switch --csv pd.csv \
  --quiet || fail "continue --switch"
python3 - pd.csv <<'PY' || fail "continue --switch: the doubled branch"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
two = [r for r in rows if r["branch"] in ("2", "3")]
assert two and all(r["period"] == "2" for r in two), set(r["period"] for r in two)
near = [r for r in two if 0.06 < float(r["S"]) < 0.0683]
assert near and all(r["stable"] == "1" for r in near), near[:2]
PY
# --curve: the PD_1a curve in (S, Omega), drawn over a Lyapunov heat map
"$CM" continue --param S=0.3,S0=0.4,Omega=0.5 --vary S=0.02:0.4 --down --curve Omega=0.2:0.8 \
  --curves curves.csv --quiet || fail "continue --curve"
python3 - curves.csv <<'PY' || fail "continue --curves CSV"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert rows and {r["label"] for r in rows} == {"PD_1a"}, rows[:2]
assert abs(float(rows[0]["S"]) - 0.06838) < 1e-4 and float(rows[0]["Omega"]) == 0.5
assert len({r["curve"] for r in rows}) == 2 and max(abs(float(r["Omega"]) - 0.5) for r in rows) > 0.02
PY
"$CM" lyapunov --param S0=0.4 --grid Omega=0.3:0.7:8,S=0.02:0.4:8 --periods 20 --png lle.png \
  --curves curves.csv --quiet || fail "lyapunov --curves"
python3 "$HERE/pngcheck.py" lle.png > /dev/null 2>&1 || [ -s lle.png ] || fail "lyapunov --curves: no PNG"
expect_usage "--curves draws over the heat map" lyapunov --grid Omega=0.3:0.7:8,S=0.02:0.4:8 \
  --curves curves.csv --csv x.csv
out=$("$CM" lyapunov --grid Omega=0.3:0.7:2,S0=0.4:0.5:2 --periods 5 --png l2.png --curves curves.csv 2>&1)
[ $? -eq 2 ] && grep -q "is in (S, Omega), the grid in (Omega, S0)" <<<"$out" && [ ! -e l2.png ] \
  || fail "lyapunov --curves of other parameters: $out"
expect_usage "--curve NAME2=LO:HI and --curves FILE go together" continue --vary S=0.02:0.4 \
  --curve Omega=0.2:0.8
# bad starts and panels: a usage error each, and no file written
expect_usage "--start: 'abc' is not a number" continue --vary S=0.02:0.4 --start abc --csv bad.csv
expect_usage "--from: '1,2,3,4' is not X,V or X,V,P" continue --vary S=0.02:0.4 --from 1,2,3,4 \
  --csv bad.csv
expect_usage "--panels: 'bogus' is not a list of x_max, stops and psi" continue \
  --vary S=0.02:0.4 --panels bogus --png bad.png
expect_usage "--panels: 'psi,psi' is not a list" continue --vary S=0.02:0.4 --panels psi,psi \
  --png bad.png
expect_usage "--curve: 'Q=1:2' is not NAME2=LO:HI" continue --vary S=0.02:0.4 \
  --curve Q=1:2 --curves bad.csv
out=$("$CM" continue --vary S=0.02:0.4 --start 0.5 --csv bad.csv 2>&1); rc=$?
[ "$rc" -eq 2 ] && grep -qF "the start's S = 0.5 is outside the range S=0.02:0.4" <<<"$out" \
  || fail "continue --start outside the range: exit $rc, $out"
[ ! -e bad.csv ] && [ ! -e bad.png ] || fail "a rejected continue left a file behind"

# --- amplitude: the symmetric non-sticking solution (thesis 2.2) -----------
"$CM" amplitude --param S=0.5,S0=0.5 --omega 0.1:3:116 --csv amp5.csv --quiet \
  || fail "amplitude at S = S0 = 0.5"
"$CM" amplitude --param S=0.05,S0=0.05 --omega 0.1:3:116 --periods 600 --threads 1 --csv amp05.csv \
  --quiet || fail "amplitude at S = S0 = 0.05"
"$CM" amplitude --param S=0.05,S0=0.05 --omega 0.1:3:116 --periods 600 --threads 2 --csv amp05b.csv \
  --quiet || fail "amplitude, 2 threads"
cmp -s amp05.csv amp05b.csv || fail "amplitude differs between 1 and 2 threads"
python3 - amp5.csv amp05.csv <<'PY' || fail "amplitude against the thesis"
import csv, math, sys
for path, S in ((sys.argv[1], 0.5), (sys.argv[2], 0.05)):
    rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(open(path))]
    for r in rows:
        w = r["Omega"]
        if w >= 0.5:  # (2.34): H_max = 1/Omega^2 there
            assert abs(r["turn_limit"] - S / w**2) < 1e-12 * max(1, S / w**2), r
        # where (2.25) holds and the solution attracts fast, the simulation finds it
        if r["valid"] and r["stable"] and r["mult_max"] < 0.9:
            assert abs(r["sim_amplitude"] - r["x0"]) < 1e-6 * max(1, r["x0"]), r
            assert r["sim_sticks"] == 0, r
        # where the slipping condition (2.27) fails, the motion sticks
        if not math.isnan(r["x0"]) and r["x0"] < r["slip_limit"] * 0.99:
            assert r["sim_sticks"] > 0, r
    if S == 0.5:  # S0 > 1/3: no non-sticking symmetric solution below Omega = 0.5
        assert not any(r["valid"] for r in rows if r["Omega"] < 0.5)
        assert all(r["valid"] and r["stable"] for r in rows if r["Omega"] > 0.6)
PY
# x0 = (1 - 1/(4 n^2))^-1 at Omega = 1/(2n), whatever S: 4/3 at Omega = 0.5
for S in 0.05 0.3; do
  "$CM" amplitude --param S=$S,S0=$S --omega 0.499:0.501:1 --csv - --quiet | tail -1 \
    | awk -F, '{ if ($2 < 1.3333 || $2 > 1.33337) exit 1 }' || fail "x0(0.5, $S) is not 4/3"
done
ls | grep -q tmp- && fail "temporary files left behind"

# --- ODE flows: Duffing's stroboscopic map (docs/models.md 11) -------------
# A stable focus of the map: the exponent is -delta/2 at every grid point
# (delta varies), by finite differences; one thread or two, the same CSV.
"$CM" lyapunov --model duffing --grid delta=0.1:0.3:2,gamma=0.09:0.11:2 --from -0.9,0 \
  --periods 200 --threads 1 --csv d1.csv > /dev/null || fail "lyapunov --model duffing"
"$CM" lyapunov --model duffing --grid delta=0.1:0.3:2,gamma=0.09:0.11:2 --from -0.9,0 \
  --periods 200 --threads 2 --csv d2.csv > /dev/null || fail "lyapunov --model duffing, 2 threads"
cmp -s d1.csv d2.csv || fail "duffing lyapunov differs between 1 and 2 threads"
python3 - d1.csv <<'PY' || fail "duffing lyapunov values"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert len(rows) == 4, rows
for r in rows:
    want = -float(r["delta"]) / 2
    assert abs(float(r["lambda"]) - want) < 2e-3, (r, want)
PY
expect_usage "the start has 1 value(s) but model duffing has dimension 2" \
  lyapunov --model duffing --grid delta=0.1:0.3:2,gamma=0.1:0.2:2 --from 1 --csv x.csv
"$CM" solve --model duffing --cells 60x60 --threads 2 > duf.txt \
  || fail "solve --model duffing"
grep -q "periodic groups" duf.txt || fail "solve --model duffing printed: $(head -3 duf.txt)"
ls | grep -q tmp- && fail "temporary files left behind"

# --- errors: usage (exit 2) and failures (exit 1) leave no file ------------
expect_usage "--grid: 'Omega=0.3:0.7," lyapunov --grid Omega=0.3:0.7,S=0.1:0.2:3 --csv x.csv
expect_usage "'Q' is not a parameter" lyapunov --grid Q=0.3:0.7:3,S=0.1:0.2:3 --csv x.csv
expect_usage "nothing to write" lyapunov --grid Omega=0.3:0.7:3,S=0.1:0.2:3
expect_usage "--d0" lyapunov --grid Omega=0.3:0.7:3,S=0.1:0.2:3 --d0 1e-12 --csv x.csv
# any other map by finite differences: the 1-D micro-chaos map stretches by a
"$CM" lyapunov --model microchaos-1d --grid a=1.5:1.7:2,b=0.9:1.1:1 --from 2.345 --periods 20000 \
  --csv m1.csv > /dev/null || fail "lyapunov --model microchaos-1d"
python3 - m1.csv <<'PY' || fail "microchaos-1d lyapunov is not ln a"
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert len(rows) == 2 and all(abs(float(r["lambda"]) - math.log(float(r["a"]))) < 1e-3 for r in rows), rows
PY
out=$("$CM" lyapunov --param S0=0.1 --grid Omega=0.3:0.7:2,S=0.2:0.3:2 --csv none.csv 2>&1); rc=$?
[ $rc -eq 1 ] && grep -q "S <= S0" <<<"$out" && [ ! -e none.csv ] || fail "all points invalid: $rc $out"
out=$("$CM" lyapunov --grid Omega=0.3:0.7:2,S=0.1:0.2:2 --periods 10 --csv nodir/x.csv 2>&1); rc=$?
[ $rc -eq 2 ] && grep -q "nodir/x.csv" <<<"$out" || fail "lyapunov into a missing directory: $rc $out"

# --- simulate: the 1a orbit (S = 0.32) from its fixed point stuck at the section
"$CM" simulate --param S=0.32 --from 1.242560606171,0 --periods 5 --csv a1.csv --png a1.png \
  > a1.out || fail "simulate 1a"
grep -q "last period: 1 sticks, 1 turns, 1 breakaways" a1.out || fail "1a summary: $(cat a1.out)"
grep -q "a fixed point of the map" a1.out || fail "1a is a fixed point: $(cat a1.out)"
python3 - a1.csv <<'PY' || fail "simulate 1a events"
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
kinds = [r["kind"] for r in rows]
assert kinds == ["start"] + ["break", "turn", "stick", "section"] * 5, kinds
T = 4 * math.pi                                    # Omega = 0.5
for k, r in enumerate(r for r in rows if r["kind"] == "section"):
    assert abs(float(r["t"]) - (k + 1) * T) < 1e-12, r
    assert abs(float(r["x"]) - 1.242560606171) < 1e-9 and float(r["v"]) == 0, r
for r in rows:
    if r["kind"] in ("break", "turn", "stick"):
        assert float(r["v"]) == 0, r
    if r["kind"] == "stick":                       # stuck before the section, at the same place
        assert abs(float(r["x"]) - 1.242560606171) < 1e-9, r
PY

# --- simulate from a random start mid-period (t0 < 0): 2s at S = 0.4 --------
"$CM" simulate --param S=0.4 --from 0.2,-0.4 --t0 -3.3 --periods 1000 --skip 995 --csv s2.csv \
  > s2.out || fail "simulate 2s"
grep -q "last period: 2 sticks, 0 turns, 2 breakaways" s2.out || fail "2s summary: $(cat s2.out)"
python3 - s2.csv s2.out <<'PY' || fail "simulate 2s events"
import csv, math, re, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert rows[0]["kind"] == "start" and len([r for r in rows if r["kind"] == "section"]) == 5
T = 4 * math.pi
assert abs(float(rows[0]["t"]) - 994 * T) < 1e-9, rows[0]   # the 995th section after -3.3
last = rows[-1]
assert abs(float(last["x"]) - 1.327985521085) < 1e-9, last  # the 2s fixed point
assert abs(float(last["v"]) - 0.033944334843) < 1e-9, last
psi = float(re.search(r"Psi over the 5 periods shown = (\S+)", open(sys.argv[2]).read()).group(1))
assert psi < 1e-9, psi                                      # symmetric: Psi = 0
PY

# --- simulate pictures: sticks are drawn green, and only where the block sticks
"$CM" simulate --param S=0.05,S0=0.05,Omega=0.8 --periods 5 --skip 2 --png slide.png \
  > /dev/null || fail "simulate without sticking"
python3 - "$HERE" a1.png slide.png <<'PY' || fail "simulate PNGs"
import sys
sys.path.insert(0, sys.argv[1])
from pngcheck import read_png
def greens(path):
    w, h, bpp, rows, texts = read_png(path)
    assert (w, h) == (900, 1000), (w, h)
    assert texts["Model"] == "friction-oscillator" and texts["Start"].startswith("t0="), texts
    return sum(1 for row in rows for i in range(0, len(row), bpp)
               if tuple(row[i:i + 3]) == (0, 150, 40))
g1a, gslide = greens(sys.argv[2]), greens(sys.argv[3])
assert g1a > 100 and gslide == 0, (g1a, gslide)
PY

# --- bifurcation: 1a (S = 0.32) and 2s (S = 0.40) at S0 = 0.4, Omega = 0.5 ---
bif=(--param S0=0.4,Omega=0.5 --sweep S=0.28:0.44:2 --transient 600 --record 20 --size 600x600)
"$CM" bifurcation "${bif[@]}" --threads 1 --csv b1.csv --runs-csv r1.csv --png b1.png \
  > b1.out || fail "bifurcation, 1 thread"
"$CM" bifurcation "${bif[@]}" --threads 2 --csv b2.csv --runs-csv r2.csv --png b2.png \
  > /dev/null || fail "bifurcation, 2 threads"
for f in b r; do cmp -s ${f}1.csv ${f}2.csv || fail "bifurcation $f CSV differs between 1 and 2 threads"; done
cmp -s b1.png b2.png || fail "bifurcation PNG differs between 1 and 2 threads"
"$CM" bifurcation "${bif[@]}" --seed 2 --runs-csv r3.csv > /dev/null || fail "bifurcation, seed 2"
cmp -s r1.csv r3.csv && fail "another seed gave the same runs"
grep -q "2 values of S x 10 runs" b1.out || fail "bifurcation summary: $(cat b1.out)"
python3 - r1.csv b1.csv b1.png "$HERE" <<'PY' || fail "bifurcation results"
import csv, math, sys
runs = list(csv.DictReader(open(sys.argv[1])))
assert len(runs) == 20 and all(r["status"] == "ok" for r in runs), runs
for r in runs:
    S, x0, v0, t0 = (float(r[k]) for k in ("S", "x0", "v0", "t0"))
    assert -1 <= x0 <= 1 and -1 <= v0 <= 1 and abs(t0) <= 4 * math.pi, r   # thesis' ranges
    if abs(S - 0.32) < 1e-12:   # 1a: one stick a period, Psi = |x_stick + x_turn| per period
        assert float(r["sticks_per_period"]) == 1 and abs(float(r["psi_per_period"]) - 0.181657) < 1e-5, r
    else:                       # 2s: symmetric, two sticks
        assert abs(S - 0.40) < 1e-12 and float(r["sticks_per_period"]) == 2, r
        assert float(r["psi_per_period"]) < 1e-9, r
points = list(csv.DictReader(open(sys.argv[2])))
assert len(points) == 20 * (10 + 20), len(points)           # ten stops, twenty sections a run
sticks32 = {round(float(p["x"]), 9) for p in points if p["kind"] == "stick" and float(p["S"]) < 0.35}
assert sticks32 == {1.242560606, -1.242560606}, sticks32     # both mirror copies of 1a found
for p in points:
    if p["kind"] == "section" and float(p["S"]) > 0.35:        # the 2s fixed point
        assert abs(float(p["x"]) - 1.327985521085) < 1e-9 and abs(float(p["v"]) - 0.033944334843) < 1e-9, p
sys.path.insert(0, sys.argv[4])
from pngcheck import read_png
w, h, bpp, rows, texts = read_png(sys.argv[3])
assert (w, h) == (600, 600), (w, h)
assert texts["Sweep"] == "S=0.28:0.44:2" and "S=" not in texts["Parameters"], texts
# the three stacked panels share the parameter axis: their frames' left
# sides (the first column inked down most of the panel) are one column
def frame_left(top, bottom):
    for x in range(w):
        inked = sum(rows[y][bpp * x:bpp * x + 3] == b"\0\0\0" for y in range(top, bottom))
        if inked > 0.6 * (bottom - top):
            return x
lefts = [frame_left(k * 200, k * 200 + 200) for k in range(3)]
assert lefts[0] is not None and lefts == [lefts[0]] * 3, lefts
PY
ls | grep -q tmp- && fail "temporary files left behind"

# --- simulate and bifurcation errors ----------------------------------------
expect_usage "--skip 5 leaves nothing" simulate --periods 5 --skip 5 --csv x.csv
expect_usage "--from: friction-oscillator starts from X,V" simulate --from 1 --csv x.csv
expect_usage "is a map: simulate follows flows" simulate --model microchaos-pd --csv x.csv
expect_usage "S0" simulate --param S=0.5,S0=0.4 --csv x.csv
expect_usage "--sweep NAME=LO:HI:N is required" bifurcation --csv x.csv
expect_usage "--sweep: 'S=0.4:0.1:3'" bifurcation --sweep S=0.4:0.1:3 --csv x.csv
expect_usage "'Q' is not a parameter" bifurcation --sweep Q=0.1:0.4:3 --csv x.csv
expect_usage "nothing to write" bifurcation --sweep S=0.1:0.4:3
expect_usage "more than 1e7" bifurcation --sweep S=0.1:0.4:2000 --runs 1000 --record 10 --csv x.csv
# any other map's diagram is lib/map_bifurcation's (chip_test): its coordinate must be the map's
expect_usage "--of q: model microchaos-pd's map has the coordinates x, v" \
  bifurcation --model microchaos-pd --sweep P=0.1:0.2:2 --of q --csv x.csv
# the two commands' outputs: at most one on standard output, and not with --json
expect_usage "--json and an output to standard output" simulate --json --csv -
expect_usage "--csv - and --png -: only one" simulate --csv - --png -
expect_usage "--json and an output to standard output" bifurcation --sweep S=0.1:0.4:3 --json --png -
expect_usage "--runs-csv - and another output" bifurcation --sweep S=0.1:0.4:3 --runs-csv - --csv -
expect_usage "--runs-csv - and another output" bifurcation --sweep S=0.1:0.4:3 --runs-csv - --json
out=$("$CM" bifurcation --param S0=0.1 --sweep S=0.2:0.3:2 --csv none.csv 2>&1); rc=$?
[ $rc -eq 1 ] && grep -q "S <= S0" <<<"$out" && [ ! -e none.csv ] || fail "bifurcation, all values invalid: $rc $out"
out=$("$CM" simulate --periods 2 --png nodir/x.png 2>&1); rc=$?
[ $rc -eq 2 ] && grep -q "nodir/x.png" <<<"$out" || fail "simulate into a missing directory: $rc $out"
ls | grep -q tmp- && fail "temporary files left behind"

[ $fails -eq 0 ] && echo "oscillator tests passed" || echo "$fails oscillator test(s) failed"
exit $fails
