#!/usr/bin/env bash
# cellmap sweep's attractors tracked across a parameter, against checks
# that do not use cell mapping:
#   - Fig. 4.30 (docs/models.md 8.4): the outermost micro-chaotic attractor
#     near SW_4 is absorbed where its one-cell attractor comes to rest,
#     mu = 72625 alpha^2 - 3 = 0.0967954: its basin collapses there;
#   - Duffing (docs/models.md 11.2; release build only, 25 s): its two
#     large period-1 orbits are born, and its two small ones in the wells
#     die, at saddle-node folds that pseudo-arclength continuation of the
#     map's fixed points (`cellmap periodic --branch`) locates; the sweep's
#     events must bracket them, and the ids of the attractors that live on
#     must not change.
# Each value's shares add up to 1; bad input.
# usage: sweep_test.sh PATH/TO/cellmap
set -u
CM=$1
HERE=$(cd "$(dirname "$0")" && pwd)
. "$HERE/testlib.sh"
enter_workdir

# --- Fig. 4.30: the absorption, bracketed by bisection ----------------------
"$CM" sweep --model microchaos-pd-friction --vary mu=0.095,0.1 \
  --region=-100000:100000,-601.5:601.5 --cells 800x401 --max-steps 100000 --near 71818:73636 \
  --refine 8 --fractions mu.csv --png mu.png --json > mu.json || fail "sweep mu"
python3 - mu.json mu.csv <<'PY' || fail "the absorption of Fig. 4.30"
import csv, json, sys
d = json.load(open(sys.argv[1]))
ev = [e for e in d["events"] if e["event"] == "collapses"]
assert len(ev) == 1 and ev[0]["id"] == 1, d["events"]
mu = 72625 * 6.53e-3 ** 2 - 3
assert ev[0]["from"] < mu < ev[0]["to"] and ev[0]["to"] - ev[0]["from"] < 2e-5, (ev, mu)
for p in d["points"]:   # one attractor in the window throughout; its basin goes to sticking
    assert [t["id"] for t in p["tracked"]] == [1], p
    rest = sum(p[k] for k in ("sticking_cells", "elsewhere_cells", "diverged_cells",
                              "outside_cells", "undecided_cells"))
    assert rest + p["tracked"][0]["cells"] == p["cells"], p
    absorbed = p["value"] >= ev[0]["to"]
    assert (p["sticking_cells"] > 2000) == absorbed and (p["tracked"][0]["cells"] < 300) == absorbed, p
rows = list(csv.DictReader(open(sys.argv[2])))
for v in {r["mu"] for r in rows}:
    assert abs(sum(float(r["share"]) for r in rows if r["mu"] == v) - 1) < 1e-12, v
PY
echo '{"view": [0, 1, 0, 1], "size": [900, 560], "texts": {"Parameter": "mu"}}' > png.json
python3 "$HERE/pngcheck.py" mu.png png.json || fail "sweep --png"

# --- Duffing: folds from continuation, bracketed by the sweep's events ------
if [ -z "${CELLMAP_SANITIZE:-}" ]; then
  "$CM" periodic --model duffing --from -0.704,0.543 --branch gamma=0.01:0.3 --max-points 2000 \
    --json > folds.json || fail "periodic --branch gamma"
  "$CM" sweep --model duffing --vary gamma=0.09,0.1 --cells 200x200 --refine 8 --json \
    > born.json || fail "sweep gamma 0.09..0.1"
  "$CM" sweep --model duffing --vary gamma=0.09,0.1 --cells 200x200 --refine 8 --no-seeds \
    --json > born-lattice.json || fail "sweep gamma 0.09..0.1 --no-seeds"
  "$CM" sweep --model duffing --vary gamma=0.253,0.254 --cells 200x200 --refine 7 --json \
    > dies.json || fail "sweep gamma 0.253..0.254"
  python3 - folds.json born.json dies.json born-lattice.json <<'PY' || fail "Duffing's births and deaths"
import json, sys
folds = sorted(e["p"] for e in json.load(open(sys.argv[1]))["events"] if e["kind"] == "fold")
assert len(folds) == 2 and abs(folds[0] - 0.09645) < 1e-4 and abs(folds[1] - 0.25369) < 1e-4, folds
born, dies = (json.load(open(p)) for p in sys.argv[2:4])
# births: the two large orbits appear at the fold itself, bracketed to the
# bisection's 0.01 / 2^8: their true orbits, seeded from the values that
# show them, persist where this 200 x 200 lattice holds no cell of their
# basins yet (without seeds, 1-4e-4 above it)
app = {}
for e in born["events"]:
    if e["event"] == "appears":
        app.setdefault(e["id"], e)
assert sorted(app) == [3, 4] and born["tracked"] == 4, born["events"]
for e in app.values():
    assert e["from"] <= folds[0] <= e["to"] and e["to"] - e["from"] < 4e-5, (e, folds)
assert not [e for e in born["events"] if e["event"] != "appears"], born["events"]
seeded = [t for p in born["points"] for t in p["tracked"] if t.get("seeded")]
assert seeded and all(t["cells"] == 0 for t in seeded), seeded
# without seeds the lattice alone decides, later
lattice = json.load(open(sys.argv[4]))
late = [e for e in lattice["events"] if e["event"] == "appears"]
assert late and all(e["from"] > folds[0] + 5e-5 for e in late), (late, folds)
# the wells' small orbits keep ids 1 and 2 over the whole sweep
for p in born["points"]:
    t = {a["id"]: a["centre"] for a in p["tracked"]}
    assert abs(t[1][0] + 0.90) < 0.03 and abs(t[2][0] - 1.10) < 0.03, p
# deaths: each small orbit (ids 2 and 3 here, |v| < 0.2) vanishes for good
# within 1e-4 of the fold (near it the lattice may lose and find it again)
ids0 = {a["id"]: a["centre"] for a in dies["points"][0]["tracked"]}
small = sorted(i for i, c in ids0.items() if abs(c[1]) < 0.2)
gone = {}
for e in dies["events"]:
    if e["event"] == "vanishes":
        gone[e["id"]] = e
assert small == [2, 3] and all(i in gone for i in small), (ids0, dies["events"])
assert not set(small) & {a["id"] for a in dies["points"][-1]["tracked"]}, dies["points"][-1]
for e in (gone[i] for i in small):
    assert folds[1] - 1e-4 < e["from"] < e["to"] < folds[1] + 1e-4, (e, folds)
PY
fi

# --- each value kept in a file of its own -----------------------------------
"$CM" sweep --model duffing --vary gamma=0.1,0.2 --cells 80x80 --keep kept --fractions kept.csv \
  --json > kept.json || fail "sweep --keep"
"$CM" sweep --model duffing --vary gamma=0.1,0.2 --cells 80x80 --json > memory.json \
  || fail "sweep in memory"
for v in 0.1 0.2; do
  [ "$(sqlite3 "kept/gamma=$v.cmdb" "SELECT json_extract(value, '$.gamma') FROM meta
    WHERE key = 'params'")" = "$v" ] || fail "kept/gamma=$v.cmdb's parameters"
  sqlite3 -csv "kept/gamma=$v.cmdb" "SELECT basin_cells FROM system_attractors" \
    | sort -n > "stored-$v.txt"
done
"$CM" measure kept/gamma=0.1.cmdb --to kept/gamma=0.2.cmdb --entropy none --uncertainty none \
  --json > kept-tip.json || fail "measure --to between kept values"
python3 - kept.json memory.json kept.csv kept-tip.json <<'PY' || fail "sweep --keep"
import csv, json, sys
kept, memory = (json.load(open(p)) for p in sys.argv[1:3])
for d in (kept, memory):
    for p in d["points"]:
        p.pop("seconds")
assert kept == memory   # the files change nothing of the sweep
rows = list(csv.DictReader(open(sys.argv[3])))
for v in ("0.1", "0.2"):   # the basins the files store are the fractions' cells
    mine = sorted(int(r["cells"]) for r in rows if r["basin"].isdigit() and float(r["gamma"]) == float(v))
    stored = [int(x) for x in open(f"stored-{v}.txt").read().split()]
    assert mine == stored and len(stored) >= 2, (v, mine, stored)
tips = json.load(open(sys.argv[4]))["tipping"]
for f in {t["from"] for t in tips}:   # each basin at 0.1 goes somewhere at 0.2
    assert abs(sum(t["probability"] for t in tips if t["from"] == f) - 1) < 1e-12, tips
PY

# --- bad input ----------------------------------------------------------------
expect_usage "--match-within" sweep --vary P=0.006,0.007 --match-within 2
expect_usage "two outputs to standard output" sweep --vary P=0.006,0.007 --fractions - --json
expect_usage "--vary: 'P=0.006'" sweep --vary P=0.006 --fractions f.csv
expect_usage "not with --by groups" sweep --vary P=0.006,0.007 --by groups --fractions f.csv
[ ! -e f.csv ] || fail "sweep wrote f.csv although it failed"
touch plain
expect_usage "--keep plain: not a directory" sweep --vary P=0.006,0.007 --keep plain
[ ! -s plain ] || fail "sweep wrote into plain"

[ "$fails" -eq 0 ] && echo "sweep_test: all passed" || exit 1
