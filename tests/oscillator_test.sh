#!/usr/bin/env bash
# Integration tests of the dry friction oscillator's commands: lyapunov
# (values at thesis points, CSV, heat map, determinism across thread
# counts, errors). Its basins are checked by figures_test.
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
python3 - g1.csv g1.png <<'PY' || fail "grid CSV and PNG"
import csv, struct, sys, zlib
rows = list(csv.DictReader(open(sys.argv[1])))
assert len(rows) == 48, len(rows)
nan = [r for r in rows if r["lambda"] == "nan"]
assert nan and all(float(r["S"]) > 0.4 for r in nan), nan   # S > S0: not computed
assert all(float(r["S"]) < 0.4 for r in rows if r["lambda"] != "nan")
data = open(sys.argv[2], "rb").read()
w, h = struct.unpack(">II", data[16:24])
assert (w, h) == (600, 450), (w, h)
assert b"Grid" in data and b"Omega=0.29999999999999999:0.69999999999999996:8" in data
PY
ls | grep -q tmp- && fail "temporary files left behind"

# --- errors: usage (exit 2) and failures (exit 1) leave no file ------------
expect_usage "--grid: 'Omega=0.3:0.7," lyapunov --grid Omega=0.3:0.7,S=0.1:0.2:3 --csv x.csv
expect_usage "'Q' is not a parameter" lyapunov --grid Q=0.3:0.7:3,S=0.1:0.2:3 --csv x.csv
expect_usage "nothing to write" lyapunov --grid Omega=0.3:0.7:3,S=0.1:0.2:3
expect_usage "--d0" lyapunov --grid Omega=0.3:0.7:3,S=0.1:0.2:3 --d0 1e-12 --csv x.csv
expect_usage "friction-oscillator only" lyapunov --model microchaos-pd --grid P=0.1:0.2:2,D=0.1:0.2:2 --csv x.csv
out=$("$CM" lyapunov --param S0=0.1 --grid Omega=0.3:0.7:2,S=0.2:0.3:2 --csv none.csv 2>&1); rc=$?
[ $rc -eq 1 ] && grep -q "S <= S0" <<<"$out" && [ ! -e none.csv ] || fail "all points invalid: $rc $out"
out=$("$CM" lyapunov --grid Omega=0.3:0.7:2,S=0.1:0.2:2 --periods 10 --csv nodir/x.csv 2>&1); rc=$?
[ $rc -eq 1 ] && grep -q "nodir/x.csv" <<<"$out" || fail "lyapunov into a missing directory: $rc $out"

[ $fails -eq 0 ] && echo "oscillator tests passed" || echo "$fails oscillator test(s) failed"
exit $fails
