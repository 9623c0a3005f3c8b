#!/usr/bin/env bash
# cellmap measure on basins whose measures are known: a map whose basin
# boundary is a Weierstrass curve (tests/weierstrass_plugin.c: uncertainty
# exponent ln 1.5 / ln 3 = 0.369, McDonald et al. 1985) or, with c = 0, the
# straight line y = 0 (alpha = 1; basin entropy growing with the box, Sbb
# under log 2); Newton's method for z^3 - 1 (examples/plugin/newton.c),
# whose three basins are Wada and whose boundary is fractal (Sbb > log 2).
# The shares against a count of `export --labels`; the tipping probabilities
# between two files against sqlite3's count on their flat tables; bad input.
# usage: measure_test.sh PATH/TO/cellmap
set -u
CM=$1
HERE=$(cd "$(dirname "$0")" && pwd)
. "$HERE/testlib.sh"
enter_workdir

cc -shared -fPIC -I"$HERE/.." -o libweierstrass.so "$HERE/weierstrass_plugin.c" -lm \
  || fail "cc weierstrass"
cc -shared -fPIC -I"$HERE/.." -o libnewton.so "$HERE/../examples/plugin/newton.c" -lm \
  || fail "cc newton"
ws=(--model-lib ./libweierstrass.so --model weierstrass --cells 500x4500 --quiet)
"$CM" solve "${ws[@]}" --db curve.cmdb || fail "solve weierstrass"
"$CM" solve "${ws[@]}" --param c=0 --db line.cmdb || fail "solve weierstrass c=0"
"$CM" solve --model-lib ./libnewton.so --model newton --cells 1000x1000 --db newton.cmdb --quiet \
  || fail "solve newton"

# the window -2.5012:2.5 starts 1251 rows below the line y = 0: no box size
# below puts the line on a box's edge (alpha of the curve is 0.393 at these
# 500 x 4500 cells, 0.381 at 1000 x 9000: it converges to 0.369)
"$CM" measure curve.cmdb --window 0:1,-2.5012:2.5 --uncertainty 1:64 --entropy none \
  --json > curve.json || fail "measure curve"
"$CM" measure line.cmdb --window 0:1,-2.5012:2.5 --uncertainty 1:64 --entropy 4,16,64 \
  --json --csv line.csv > line.json || fail "measure line"
"$CM" measure newton.cmdb --json --csv newton.csv --png newton.png --size 600x700 > measured.json \
  || fail "measure newton"
echo '{"view": [0, 1, 0, 1], "size": [600, 700], "texts": {"Model": "newton"}}' > png.json
python3 "$HERE/pngcheck.py" newton.png png.json || fail "measure --png"
"$CM" export newton.cmdb --labels newton.npy > /dev/null || fail "export newton"
python3 - curve.json line.json measured.json newton.csv newton.npy <<'PY' || fail "the measures"
import csv, json, math, struct, sys
curve, line, newton = (json.load(open(p)) for p in sys.argv[1:4])
# the Weierstrass curve: alpha = ln(lambda)/ln(3); two basins, no Wada test
assert abs(curve["alpha"] - math.log(1.5) / math.log(3)) < 0.05, curve["alpha"]
assert "wada" not in curve and len(curve["shares"]) == 2, curve
# the straight line: alpha = 1, Sb grows with the box (it tends to 0 as
# boxes shrink), Sbb under log 2
assert abs(line["alpha"] - 1) < 0.05 and line["alpha_r2"] > 0.999, line["alpha"]
sb = [e["sb"] for e in line["entropy"]]
assert sb[0] < sb[1] < sb[2] and sb[0] < 1e-3, sb
assert all(e["sbb"] < math.log(2) for e in line["entropy"]), line["entropy"]
# Newton: Wada (every boundary cell sees all three basins within 5 cells
# but for under 1 %) and a fractal boundary
w = newton["wada"]
assert w["basins"] == 3 and w["fraction"][-1] >= 0.99 and w["verdict"] == "Wada", w
assert newton["sbb_mean"] > math.log(2) and newton["entropy"][0]["sbb"] > math.log(2), newton
assert newton["computed"] == newton["cells"] == 10**6, newton
# the shares are the labels' counts
data = open(sys.argv[5], "rb").read()
hlen = struct.unpack("<H", data[8:10])[0]
labels = struct.unpack("<%di" % 10**6, data[10 + hlen:])
for s in newton["shares"]:
    assert labels.count(s["label"]) == s["cells"], s
assert abs(sum(s["share"] for s in newton["shares"]) - 1) < 1e-12
rows = list(csv.DictReader(open(sys.argv[4])))
assert {r["measure"] for r in rows} == {"share", "sb", "sbb", "uncertain", "wada"}, rows[:3]
assert [float(r["value"]) for r in rows if r["measure"] == "wada"] == w["fraction"], rows
PY

# a window larger than the budget is measured in slabs (five of Newton's
# 1000 x 1000 cells under 2 MiB) with the same counts as at once
"$CM" measure newton.cmdb --mem 2M --json > slabs.json || fail "measure newton --mem 2M"
python3 - measured.json slabs.json <<'PY' || fail "measured in slabs"
import json, sys
whole, slabs = (json.load(open(p)) for p in sys.argv[1:3])
for key in ("cells", "computed", "shares", "eps", "uncertain", "alpha", "wada"):
    assert whole[key] == slabs[key], key
for a, b in zip(whole["entropy"], slabs["entropy"]):
    assert all(a[k] == b[k] for k in ("box", "boxes", "boundary_boxes")), (a, b)
    assert abs(a["sb"] - b["sb"]) < 1e-12 and abs(a["sbb"] - b["sbb"]) < 1e-12, (a, b)
PY

# tipping from c = 1 to c = 0.5 on one lattice: each basin's probabilities
# sum to 1 and are the cells a join of the two files' flat tables counts
"$CM" solve "${ws[@]/500x4500/200x1800}" --db tip-a.cmdb || fail "solve tip-a"
"$CM" solve "${ws[@]/500x4500/200x1800}" --param c=0.5 --db tip-b.cmdb || fail "solve tip-b"
"$CM" measure tip-a.cmdb --to tip-b.cmdb --entropy none --uncertainty none --json > tip.json \
  || fail "measure --to"
"$CM" export tip-a.cmdb --flat tip-a.sqlite --quiet && "$CM" export tip-b.cmdb --flat tip-b.sqlite \
  --quiet || fail "export --flat of the tipping files"
sqlite3 -csv tip-a.sqlite "ATTACH 'tip-b.sqlite' AS b; SELECT a.attractor, c.attractor, COUNT(*)
  FROM cells a JOIN b.cells c ON a.ix = c.ix AND a.iy = c.iy GROUP BY 1, 2" > tip-sql.csv \
  || fail "sqlite3's count"
python3 - tip.json tip-sql.csv <<'PY' || fail "the tipping probabilities"
import csv, json, sys
tips = json.load(open(sys.argv[1]))["tipping"]
sql = {(int(a), int(b)): int(n) for a, b, n in csv.reader(open(sys.argv[2]))}
assert {(t["from"], t["to"]): t["cells"] for t in tips} == sql, (tips, sql)
for src in {t["from"] for t in tips}:
    assert abs(sum(t["probability"] for t in tips if t["from"] == src) - 1) < 1e-12, src
assert len(tips) == 4 and all(t["probability"] > 0.9 for t in tips if t["from"] == t["to"]), tips
PY
"$CM" solve "${ws[@]/500x4500/100x900}" --db coarse.cmdb || fail "solve coarse"
expect_usage "another lattice" measure tip-a.cmdb --to coarse.cmdb

# sampled fractions: 10^5 random states of Newton's window followed by the
# true map agree with the cells' shares within their 95 % intervals, the
# same fates for 1 and 2 threads, and most states end where their cell's
# label says (the rest lie on the fractal boundary)
for t in 1 2; do
  "$CM" measure newton.cmdb --samples 100000:3 --threads $t --entropy none --uncertainty none \
    --wada none --json --csv sampled-$t.csv > sampled-$t.json || fail "measure --samples, $t threads"
done
cmp -s sampled-1.csv sampled-2.csv || fail "the sampled shares differ between 1 and 2 threads"
python3 - sampled-1.json sampled-1.csv <<'PY' || fail "the sampled shares"
import csv, json, sys
r = json.load(open(sys.argv[1]))
assert r["samples"] == r["samples_in_computed_cells"] == 100000, r
assert r["samples_agree"] and all(s["agrees"] for s in r["shares"]), r["shares"]
assert 0.98 < r["samples_as_labelled"] / 1e5 < 1, r["samples_as_labelled"]
assert sum(s["sampled"] for s in r["shares"]) == 100000, r["shares"]
for s in r["shares"]:
    assert s["sampled_lo"] <= s["share"] <= s["sampled_hi"] < s["sampled_lo"] + 0.008, s
rows = [x for x in csv.DictReader(open(sys.argv[2])) if x["measure"] == "sampled"]
assert [float(x["value"]) for x in rows] == [s["sampled_share"] for s in r["shares"]], rows
PY
# the uncertainty exponent by true orbits below the cell, where the lattice
# is too coarse: the Weierstrass curve's 0.369 (the lattice gives 0.393 at
# these cells), and the straight line's 1
"$CM" measure curve.cmdb --window 0:1,-2.5012:2.5 --uncertainty none --entropy none \
  --samples 100000 --orbit-uncertainty 0.015625:1 --json > orbit-curve.json \
  || fail "measure curve --orbit-uncertainty"
"$CM" measure line.cmdb --window 0:1,-2.5012:2.5 --uncertainty none --entropy none \
  --samples 100000 --orbit-uncertainty 1:16 --json --csv orbit-line.csv > orbit-line.json \
  || fail "measure line --orbit-uncertainty"
python3 - orbit-curve.json orbit-line.json orbit-line.csv <<'PY' || fail "alpha by true orbits"
import csv, json, math, sys
curve, line = (json.load(open(p)) for p in sys.argv[1:3])
assert abs(curve["orbit_alpha"] - math.log(1.5) / math.log(3)) < 0.01, curve["orbit_alpha"]
assert curve["orbit_eps"] == [2.0 ** -k for k in range(6, -1, -1)], curve["orbit_eps"]
assert abs(line["orbit_alpha"] - 1) < 0.05, line["orbit_alpha"]
rows = [r for r in csv.DictReader(open(sys.argv[3])) if r["measure"] == "orbit_uncertain"]
assert [float(r["value"]) for r in rows] == line["orbit_uncertain"], rows
PY
expect_usage "give samples" measure curve.cmdb --orbit-uncertainty 0.5:1
expect_usage "--orbit-uncertainty: '0:1'" measure curve.cmdb --samples 10 --orbit-uncertainty 0:1
expect_usage "--samples: give N[:SEED]" measure newton.cmdb --samples 0
expect_usage "at most 100000000" measure newton.cmdb --samples 100000001

# Duffing (docs/models.md 11.2, four attractors with fractal basins; release
# build only, 20 s): at 1000 x 1000 cells every cell share lies within the
# sampled interval; at 300 x 300 the check finds the lattice too coarse
if [ -z "${CELLMAP_SANITIZE:-}" ]; then
  "$CM" solve --model duffing --cells 1000x1000 --db duffing.cmdb --quiet || fail "solve duffing"
  "$CM" solve --model duffing --cells 300x300 --db duffing-300.cmdb --quiet || fail "solve duffing 300"
  "$CM" measure duffing.cmdb --samples 100000 --entropy none --uncertainty none --wada none \
    --json > duffing.json || fail "measure duffing --samples"
  "$CM" measure duffing-300.cmdb --samples 20000 --entropy none --uncertainty none --wada none \
    > duffing-300.txt || fail "measure duffing-300 --samples"
  python3 - duffing.json <<'PY' || fail "duffing's sampled shares"
import json, sys
r = json.load(open(sys.argv[1]))
assert [s["label"] for s in r["shares"]] == [1, 2, 3, 4], r["shares"]
assert r["samples_agree"] and all(s["agrees"] for s in r["shares"]), r["shares"]
PY
  grep -q "differs" duffing-300.txt && grep -q "the lattice is too coarse" duffing-300.txt \
    || fail "duffing at 300 x 300: no share outside its sampled interval: $(cat duffing-300.txt)"
fi

# bad input: exit 2, nothing written
expect_usage "do not fit the window" measure line.cmdb --entropy 20000 --csv no.csv
expect_usage "needs 3 or more basins" measure line.cmdb --wada 3 --csv no.csv
expect_usage "--uncertainty: '4:2' is not E0:E1" measure line.cmdb --uncertainty 4:2
expect_usage "which file?" measure --wada 2
expect_usage "the database" measure line.cmdb --csv line.cmdb
expect_usage "over half the budget" measure curve.cmdb --uncertainty 1:64 --mem 1M
"$CM" solve --model microchaos-1d --cells 300 --db one.cmdb --quiet || fail "solve microchaos-1d"
expect_usage "it needs a 2-D model" measure one.cmdb --png no.png
[ ! -e no.csv ] && [ ! -e no.png ] || fail "measure wrote no.csv or no.png although it failed"

[ "$fails" -eq 0 ] && echo "measure_test: all passed" || exit 1
