#!/usr/bin/env bash
# Every command that prints results prints, with --json, one document that
# docs/cellmap.schema.json accepts; its field names are the CSV's.
# usage: json_test.sh PATH/TO/cellmap SOURCE_DIR
set -u
CM=$(realpath "$1")
SRC=$(realpath "$2")
HERE=$(cd "$(dirname "$0")" && pwd)
SCHEMA=$SRC/docs/cellmap.schema.json
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
. "$HERE/testlib.sh"
cd "$work"

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
run models models --json
run sweep sweep --model microchaos-pd-friction --vary mu=0.09:0.1:3 --cells 100x50 --refine 1 --json
run fixed-points fixed-points --range -2:2 --json
run fixed-points-friction fixed-points --model microchaos-pd-friction --range -2:2 --json
run orbit orbit --from 10,0 --steps 5 --json
run orbit-sink orbit --model microchaos-1d --from 1e300 --steps 5 --json
run lyapunov lyapunov --param S0=0.4 --grid Omega=0.49:0.51:2,S=0.3:0.5:2 --periods 50 --json
run bifurcation bifurcation --param S0=0.4,Omega=0.5 --sweep S=0.28:0.44:2 --transient 20 --record 5 --json
run bifurcation-list bifurcation --param S0=0.4,Omega=0.5 --sweep S=0.32,0.4 --transient 20 --record 5 --json
run simulate simulate --param S=0.4,S0=0.4,Omega=0.5 --periods 3 --json
printf 'view 0:500 -40:40\nstats --json\n' | "$CM" explore ex.cmdb --model microchaos-pd --cell-size 4,1 \
  2> /dev/null | grep '^{' > stats.json || fail "explore stats --json"
python3 "$HERE/schema_check.py" "$SCHEMA" $(ls ./*.json | grep -v -e missing.json -e enum.json) \
  || fail "documents the schema rejects (above)"

# one document per command; what the JSON says, the other outputs say too
python3 - <<'PY' || fail "JSON contents"
import json
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
PY

# the CSV columns carry the JSON's names
"$CM" sweep --model microchaos-pd-friction --vary mu=0.09:0.1:3 --cells 100x50 --csv sweep.csv > /dev/null \
  || fail "sweep --csv"
head -1 sweep.csv | grep -qx "mu,attractors,sticking,attractor_cells,sticking_cells,groups,sink_cells,seconds" \
  || fail "sweep CSV header: $(head -1 sweep.csv)"
"$CM" export basin.cmdb --groups groups.csv 2> /dev/null || fail "export --groups"
head -1 groups.csv | grep -q "^id,period,basin_cells,.*centre_x,centre_v.*,kind$" \
  || fail "groups CSV header: $(head -1 groups.csv)"
"$CM" orbit --from 10,0 --steps 1 | head -1 | grep -qx "j,x,v" || fail "orbit CSV header"
"$CM" fixed-points --range 0:0 | head -1 | grep -qx "level,band,kind,x,v" || fail "fixed-points CSV header"

[ $fails -eq 0 ] && echo "json tests passed"
exit $fails
