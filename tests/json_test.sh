#!/usr/bin/env bash
# Every command that prints results prints, with --json, one document that
# docs/cellmap.schema.json accepts; its field names are the CSV's.
# usage: json_test.sh PATH/TO/cellmap SOURCE_DIR
set -u
CM=$(realpath "$1")
SRC=$(realpath "$2")
HERE=$(cd "$(dirname "$0")" && pwd)
SCHEMA=$SRC/docs/cellmap.schema.json
. "$HERE/testlib.sh"
enter_workdir

# the validator itself rejects what the schema forbids
echo '{"command":"solve","model":"m"}' > missing.json
echo '{"command":"orbit","model":"m","params":{},"state":["x"],"from":[1],"steps":1,"points":[[1]],"end":"never"}' > enum.json
for f in missing enum; do
  python3 "$HERE/schema_check.py" "$SCHEMA" $f.json > /dev/null && fail "the validator accepted $f.json"
done

run() { # run NAME args...: cellmap args > NAME.json
  local name=$1; shift
  "$CM" "$@" > "$name.json" || fail "cellmap $* exited $?"
}
run solve solve --cells 120x80 --db basin.cmdb --json
run solve-split solve --cells 120x80 --split 2x1 --json
run solve-extend solve --cells 60x40 --extend 2 --json
run solve-friction solve --model microchaos-pd-friction --region -3000:3000,-10:10 --cells 200x100 --json
run info info basin.cmdb --json
run measure measure basin.cmdb --json
run measure-tipping measure basin.cmdb --to basin.cmdb --entropy none --json
run models models --json
run sweep sweep --model microchaos-pd-friction --vary mu=0.09:0.1:3 --cells 100x50 --refine 1 --json
run fixed-points fixed-points --range -2:2 --json
run fixed-points-friction fixed-points --model microchaos-pd-friction --range -2:2 --json
run orbit orbit --from 10,0 --steps 5 --json
run orbit-sink orbit --model microchaos-1d --from 1e300 --steps 5 --json
run orbit-flow orbit --model chip-4d --from 1.05,0.2,0.27 --steps 2 --json
run equilibria equilibria --model chip-4d --from 1,0.1,0.2,0.25 --json
run periodic periodic --param xi=11 --from 1.05,0.2,0.27 --settle 100 --json
run periodic-cascade periodic --param xi=2.9 --from 1.05,0.2,0.27 --settle 100 --branch xi=2.9:4.1 \
  --direction up --cascade 2 --json
run exponents exponents --param xi=4.8,zeta=21 --from 1,0.1,0.2,0.3 --time 5 --transient 1 --json
run exponents-map exponents --param xi=4.8,zeta=21 --of map --from 1,0.2,0.3 --iterations 20 --skip 5 --json
run exponents-farmer exponents --model chip-bue --samples 5 --time 20 --json
run exponents-sync exponents --model chip-bue --sync --time 40 --json
run exponents-series exponents --model chip-workpiece --param f=0.16 --from 1,0,0,0,0,0 --series tau2 --time 200 --transient 0 --dims 2 --fnn-dim 3 --radius 0.1 --steps 4 --time-unit 1.64e-4 --json
run simulate-flow simulate --model chip-4d --from 1,0.1,0.2,0.3 --time 5 --json
run exponents-henon-like exponents --model microchaos-pd --from 0.1,0.01 --iterations 100 --skip 0 --json
run equilibria-branch equilibria --model chip-4d --from 1,0.1,0.2,0.25 --branch xi=4:12 --json
run equilibria-curve equilibria --model chip-4d --from 1,0.1,0.2,0.25 --branch xi=1:15 \
  --curve zeta=21,21.5 --json
run lyapunov lyapunov --param S0=0.4 --grid Omega=0.49:0.51:2,S=0.3:0.5:2 --periods 50 --json
run lyapunov_sync lyapunov --method sync --param S=0.05,S0=0.4,Omega=0.5 --q 0:0.01:2 --periods 200 --json
run lyapunov_stickmap lyapunov --method stickmap --param S=0.0465,S0=0.4,Omega=0.5 --runs 4 --periods 300 --json
run bifurcation bifurcation --param S0=0.4,Omega=0.5 --sweep S=0.28:0.44:2 --transient 20 --record 5 --json
run bifurcation-map bifurcation --model chip-4d --sweep xi=3.5,4.8 --runs 1 --transient 10 --record 5 --json
run bifurcation-list bifurcation --param S0=0.4,Omega=0.5 --sweep S=0.32,0.4 --transient 20 --record 5 --json
run simulate simulate --param S=0.4,S0=0.4,Omega=0.5 --periods 3 --json
run amplitude amplitude --param S=0.5,S0=0.5 --omega 0.2:2:10 --json
run amplitude-h amplitude --h 0.6,0.4 --json
run amplitude-extremal amplitude --param S=0.1,S0=0.1,Omega=0.5 --extremal 0.01 --json
run amplitude-converge amplitude --param S=0.1,S0=0.1,Omega=0.98 --converge 500 --json
run continue continue --param S=0.3,S0=0.4,Omega=0.5 --vary S=0.02:0.4 --down --json
run partition partition --param a=1.3,b=0.66 --json
run horseshoe horseshoe --param alpha=0.8,beta=0.3,P=0.7,D=0.6 --m 4:7 --json
run stability stability --param alpha=0.8,beta=0.3,P=0.9,D=0.4 --json
run stability-delay stability --model microchaos-delay --param a=1.3,b=0.66 --json
run escape escape --param a=1.5,b=1.3 --I0 0.25 --cells 100000 --ensemble 100000 --json
run escape-sweep escape --param b=1.3 --I0 0.25 --sweep a=1.15:1.55:4 --cells 1000 --ensemble 10000 --json
"$CM" export basin.cmdb --labels labels.npy --steps steps.npy --window 100:300,-5:5 --by groups \
  || fail "export --labels --steps"
"$CM" export basin.cmdb --cells window.csv --window 100:300,-5:5 > /dev/null || fail "export --cells"
# a window whose v bounds are cell centres (v = -4.5 and 4.5: both in)
"$CM" export basin.cmdb --labels edge.npy --steps edge-steps.npy --cells edge.csv --by groups \
  --window 100:300,-4.5:4.5 > /dev/null || fail "export of a window on cell centres"
"$CM" solve --model microchaos-general --param n=1,d=2,A=1.5,B=-1,K=0.6:0.2:0.1 \
  --region=-6:6,-6:6,-6:6 --cells 6x5x4 --db cube.cmdb > /dev/null || fail "3-D solve"
"$CM" export cube.cmdb --labels cube.npy --cells cube.csv --by groups > /dev/null \
  || fail "3-D export --labels"
# by attractors (the default): each cell's label is its group's attractor
"$CM" export basin.cmdb --labels att.npy --cells att.csv > /dev/null || fail "export --labels by attractors"
printf 'view 0:500 -40:40\nstats --json\n' | "$CM" explore ex.cmdb --model microchaos-pd --cell-size 4,1 \
  2> /dev/null | grep '^{' > stats.json || fail "explore stats --json"
python3 "$HERE/schema_check.py" "$SCHEMA" $(ls ./*.json | grep -v -e missing.json -e enum.json) \
  || fail "documents the schema rejects (above)"

# one document per command; what the JSON says, the other outputs say too
python3 - <<'PY' || fail "JSON contents"
import json, math
def load(name):
    return json.load(open(name + ".json"))
s, i = load("solve"), load("info")
assert s["command"] == "solve" and i["command"] == "info"
assert s["box"] == [[0, 500], [-40, 40]], s["box"]          # state units, as typed
assert s["params"] == {"alpha": 0.078, "beta": 0, "P": 0.007, "D": 0.02}, s["params"]
assert s["state"] == ["x", "v"] and i["state"] == ["x", "v"]
assert i["box"] == s["box"] and i["cells"] == s["cells"] == 9600
assert i["sink_cells"] == s["sink_cells"]
key = lambda g: (g["id"], g["kind"], g["period"], g["basin_cells"], g["centre"])
assert sorted(map(key, s["groups"])) == sorted(map(key, i["groups"]))
assert sum(g["basin_cells"] for g in s["groups"]) + s["sink_cells"] == s["cells"]
split = load("solve-split")
assert sorted((g["period"], g["basin_cells"]) for g in split["groups"]) == \
       sorted((g["period"], g["basin_cells"]) for g in s["groups"])
e = load("solve-extend")
assert len(e["extension"]["steps"]) == 2 and e["box"] == [[-500, 1000], [-40, 40]], e["box"]
assert any(g["kind"] == "sticking" for g in load("solve-friction")["groups"])
m = {x["name"]: x for x in load("models")["models"]}
assert m["microchaos-delay"]["state"] == ["x_lag1", "x"] and m["friction-oscillator"]["state"] == ["x", "v"]
assert m["microchaos-pd-twofold"]["state"] == ["x", "v"], m["microchaos-pd-twofold"]
sw = load("sweep")
assert [p["value"] for p in sw["points"]] == sorted(p["value"] for p in sw["points"])
o = load("orbit")
assert len(o["points"]) == 6 and o["points"][0] == [10, 0] and o["end"] == "steps"
assert load("orbit-sink")["end"] == "sink"
fp = load("fixed-points")
assert [p["level"] for p in fp["fixed_points"]] == [-2, -1, 0, 1, 2]
st = load("stats")
assert st["box"] == [[0, 500], [-40, 40]] and st["cells"] == 125 * 80
assert all("in_view" in g for g in st["groups"])
sb = load("stability")
assert sb["stable"] and sb["n_fixed"] == 5 and sb["m_max"] == 3 and abs(sb["P_min"] - 0.64) < 1e-15, sb
ah = load("amplitude-h")["h"]
assert ah[0]["t_max"] == 0 and ah[1]["t_max"] > 0 and ah[1]["H_max"] > ah[1]["limit"], ah
assert abs(load("amplitude-extremal")["coefficient"] + 2) < 0.01
ac = load("amplitude-converge")
assert abs(ac["decay_fit"] / math.log(ac["mult_max"]) - 1) < 0.01, ac
sd = load("stability-delay")
assert sd["domain_01"] and sd["partition_mu_sl"] and sd["bands"] == [0, 1], sd
pt = load("partition")
assert [r["row"] for r in pt["regions"]][3] == "000011000" and pt["primitive_index"] == 65, pt
hs = load("horseshoe")["lines"]
assert [l["kind"] for l in hs] == ["repeller", "attractor", "attractor", "repeller"], hs
es = load("escape")["points"][0]
assert es["valid"] and abs(es["exact_mean"] - 9.29996054) < 1e-8, es
assert abs(es["scm_mean"] - es["exact_mean"]) < 0.1 and abs(es["ensemble_mean"] - es["exact_mean"]) < 0.1
sweep = load("escape-sweep")["points"]
assert len(sweep) == 4 and sweep[0]["border"] and not sweep[-1]["border"], sweep
PY

# the arrays, read by numpy (Debian's python3-numpy): shape, dtype and every
# value against export --cells
for a in labels:window steps:window cube:cube; do
  /usr/bin/python3 - ${a%%:*}.npy ${a#*:}.csv <<'PY' || fail "the array ${a%%:*}.npy"
import csv, json, sys
import numpy as np
arr, side = np.load(sys.argv[1]), json.load(open(sys.argv[1][:-4] + ".json"))
assert arr.dtype == np.dtype("<i4") and arr.flags["C_CONTIGUOUS"], arr.dtype
rows = list(csv.DictReader(open(sys.argv[2])))
names = side["axes"]
lo = side["first_cell"]
assert list(arr.shape) == side["shape"], (arr.shape, side["shape"])
assert arr.shape == tuple(len({int(r["i" + n]) for r in rows}) for n in names), arr.shape
field = "grp" if side["array"] == "labels" else "step"
seen = 0
for r in rows:
    at = tuple(int(r["i" + n]) - lo[k] for k, n in enumerate(names))
    assert arr[at] == int(r[field]), (at, arr[at], r[field])
    seen += 1
assert seen == arr.size and (arr >= 0).all(), (seen, arr.size)   # every cell computed
ids = {g["id"] for g in side["groups"]}
if side["array"] == "labels":
    assert ids == set(np.unique(arr[arr > 0]).tolist()), "the sidecar lists the groups in the array"
    assert all(g["colour"].startswith("#") and len(g["colour"]) == 7 for g in side["groups"])
PY
done

# the windows' cells against the window computed here, by brute force over
# basin.cmdb's lattice (0:500 x -40:40 in 120 x 80 cells): the cells whose
# centres lie in the window, bounds included
/usr/bin/python3 - <<'PY' || fail "export --window: shape, first and last cell"
import csv, json
import numpy as np
width = (500 / 120, 80 / 80)
origin = (0, -40)
def inside(k, lo, hi):
    return [i for i in range((120, 80)[k]) if lo <= origin[k] + (i + 0.5) * width[k] <= hi]
for stem, csv_name, window in (("labels", "window", ((100, 300), (-5, 5))),
                               ("steps", "window", ((100, 300), (-5, 5))),
                               ("edge", "edge", ((100, 300), (-4.5, 4.5))),
                               ("edge-steps", "edge", ((100, 300), (-4.5, 4.5)))):
    cells = [inside(k, *window[k]) for k in range(2)]
    first, last = [c[0] for c in cells], [c[-1] for c in cells]
    shape = [len(c) for c in cells]
    side = json.load(open(stem + ".json"))
    assert side["first_cell"] == first, (stem, side["first_cell"], first)
    assert side["shape"] == shape and list(np.load(stem + ".npy").shape) == shape, (stem, side["shape"], shape)
    assert [a + n - 1 for a, n in zip(side["first_cell"], side["shape"])] == last, (stem, last)
    rows = list(csv.DictReader(open(csv_name + ".csv")))
    got = sorted((int(r["ix"]), int(r["iv"])) for r in rows)
    assert got == sorted((i, j) for i in cells[0] for j in cells[1]), (csv_name, got[:3], got[-3:])
    assert got[0] == tuple(first) and got[-1] == tuple(last), (got[0], got[-1])
assert inside(1, -4.5, 4.5) == list(range(35, 45)), inside(1, -4.5, 4.5)   # both centres in
PY

# the attractor labels against the groups' attractors of solve --json, cell
# by cell: the sink -2 (outside), a group whose orbit diverges 0 or whose
# orbit is undecided -2 (its attractor null), else its attractor's id
/usr/bin/python3 - <<'PY' || fail "export --labels by attractors"
import csv, json
import numpy as np
arr, side, solve = np.load("att.npy"), json.load(open("att.json")), json.load(open("solve.json"))
assert side["by"] == "attractors" and "attractors" in side and "groups" not in side, side.keys()
of = {g["id"]: g["attractor"] for g in solve["groups"]}
ids = {a["id"] for a in solve["attractors"]}
bad = 0
for r in csv.DictReader(open("att.csv")):
    g, got = int(r["grp"]), int(arr[int(r["ix"]), int(r["iv"])])
    want = {-2} if g == 0 else ({0, -2} if of[g] is None else {of[g]})
    bad += got not in want
assert bad == 0, bad
assert {a["id"] for a in side["attractors"]} == set(np.unique(arr[arr > 0]).tolist()) <= ids
for a in side["attractors"]:
    assert a["in_view"] == int((arr == a["id"]).sum()), a
PY

# the CSV columns carry the JSON's names
"$CM" sweep --model microchaos-pd-friction --vary mu=0.09:0.1:3 --cells 100x50 --csv sweep.csv > /dev/null \
  || fail "sweep --csv"
head -1 sweep.csv | grep -qx "mu,attractors,sticking,attractor_cells,sticking_cells,groups,sink_cells,seconds" \
  || fail "sweep CSV header: $(head -1 sweep.csv)"
"$CM" export basin.cmdb --groups groups.csv 2> /dev/null || fail "export --groups"
head -1 groups.csv | grep -q "^id,period,basin_cells,.*centre_x,centre_v.*,kind,attractor$" \
  || fail "groups CSV header: $(head -1 groups.csv)"
"$CM" orbit --from 10,0 --steps 1 | head -1 | grep -qx "j,x,v" || fail "orbit CSV header"
"$CM" fixed-points --range 0:0 | head -1 | grep -qx "level,band,kind,x,v" || fail "fixed-points CSV header"

# a flat export says where it came from and where its cells lie, and is indexed
"$CM" export basin.cmdb --flat flat.sqlite --window 100:300,-5:5 > /dev/null || fail "export --flat"
[ "$(sqlite3 flat.sqlite "SELECT group_concat(key || '=' || value, ' ') FROM meta WHERE key IN
    ('source', 'lattice_origin', 'lattice_width', 'state') ORDER BY key")" = \
  'lattice_origin=[0,-40] lattice_width=[4.166666666666667,1] source=basin.cmdb state=["x","v"]' ] \
  || fail "flat meta: $(sqlite3 flat.sqlite 'SELECT * FROM meta')"
sqlite3 flat.sqlite "EXPLAIN QUERY PLAN SELECT COUNT(*) FROM cells WHERE grp = 2" | grep -q "USING.*INDEX cells_grp" \
  || fail "no index on cells(grp)"
sqlite3 flat.sqlite "EXPLAIN QUERY PLAN SELECT grp FROM cells WHERE ix = 30 AND iv = 18" | grep -q "INDEX cells_cell" \
  || fail "no index on the cells' indices"

[ $fails -eq 0 ] && echo "json tests passed"
exit $fails
