#!/usr/bin/env bash
# Integration tests of `cellmap serve` (issue 49) over HTTP with curl: tiles
# against the labels `export` gives, tiles that compute against a single
# solve of the union, point queries against `orbit`, bad requests, 50
# requests at once, a second writer refused and readers served meanwhile,
# read-only, and SIGTERM leaving the file whole.
# usage: serve_test.sh PATH/TO/cellmap SOURCE_DIR
set -u
CM=$1
SRC=$2
. "$SRC/tests/testlib.sh"
enter_workdir
export PYTHONPATH="$SRC/tests"
check() { python3 "$SRC/tests/serve_check.py" "$@"; }

# status PATH [curl options]: the HTTP status of a request
status() { local p=$1; shift; curl -s -o /dev/null -w '%{http_code}' "$@" "$url$p"; }

pd="--model microchaos-pd --param alpha=0.078,beta=0,P=0.007,D=0.02"
# the cells of tile (0, 1, -2): x 128..256, v -19.52..0.96, around attractor A at x 144
"$CM" solve --db s.cmdb $pd --region 128:256,-19.52:0.96 --cells 256x256 > /dev/null ||
  fail "solve"

# --- the page, Leaflet's files, the info -------------------------------------
# (tiles compute at zoom 0 only: what the file holds stays a known box)
printf '# the legend names attractors 1 and 2\n1 the first one\n2 the second one\n' > names.txt
serve_start s.cmdb --tile-cells 65536 --labels names.txt
grep -q "http://127.0.0.1:" serve.out || fail "serve does not listen on 127.0.0.1 by default"
# the server runs with the heap in huge pages where the kernel gives them
# on request, unless the build is sanitized (src/run_env.h); the
# environment it was executed with is in /proc
if grep -q '\[madvise\]' /sys/kernel/mm/transparent_hugepage/enabled 2> /dev/null &&
  ! ldd "$CM" | grep -q libasan; then
  tr '\0' '\n' < /proc/$pid/environ | grep -qx 'GLIBC_TUNABLES=glibc.malloc.hugetlb=1' ||
    fail "serve runs without huge pages for its heap"
fi
curl -sf "$url/" | grep -q "L.CRS.Simple" || fail "the page is not the Leaflet map"
curl -sf "$url/leaflet/leaflet.js" -o leaflet.js || fail "leaflet.js not served"
cmp -s leaflet.js /usr/share/javascript/leaflet/leaflet.js || fail "leaflet.js is not Debian's"
curl -sf "$url/info" -o info.json || fail "/info"
[ "$(check json info.json lattice computes)" = '{"origin": [128, -19.52], "width": [0.5, 0.08]} true' ] ||
  fail "/info: $(cat info.json)"
grep -q '"label":1,"name":"the first one"' info.json || fail "--labels did not name attractor 1: $(cat info.json)"

# --- tiles are the labels export gives --------------------------------------
# window Z X Y: the state rectangle of tile (Z, X, Y), a hundredth of a cell
# inside. The lattice's origin is the solve's corner (128, -19.52): tile
# (0, 0, -1) holds its cells.
window() {
  python3 -c "
z, x, y = $1, $2, $3
n = 256 << -z
lo0, hi0, lo1, hi1 = x * n, (x + 1) * n, -(y + 1) * n, -y * n
print('%.6f:%.6f,%.6f:%.6f' % (128 + lo0 * 0.5 + 0.005, 128 + hi0 * 0.5 - 0.005,
                               -19.52 + lo1 * 0.08 + 0.0008, -19.52 + hi1 * 0.08 - 0.0008))"
}
# tile 0/0/-1 drawn and kept before its neighbour grows the cluster: kept
# tiles must be drawn again (its cells leading there change their labels)
curl -sf "$url/tiles/0/0/-1.png" -o /dev/null || fail "tile 0/0/-1 before"
# a tile over cells not computed: 65 536 new cells, joined and committed
curl -sf "$url/tiles/0/1/-1.png" -o /dev/null || fail "tile 0/1/-1 (computing)"
# the tiles compared with export below: drawn from the cluster as it ends
curl -sf "$url/tiles/0/0/-1.png" -o t0.png || fail "tile 0/0/-1"
curl -sf "$url/tiles/-1/0/-1.png" -o t1.png || fail "tile -1/0/-1"
curl -sf "$url/tiles/0/1/-1.png" -o t2.png || fail "tile 0/1/-1"
curl -sf "$url/info" -o legend.json || fail "/info after computing"
# a reader meanwhile: the file is whole, its attractors found afresh
"$CM" info s.cmdb > info.txt 2>&1 || fail "info while serving: $(cat info.txt)"
grep -q "regions 2," info.txt || fail "the computed tile is not in the file: $(head -5 info.txt)"
# a second writer is refused
echo "view 0:10 -10:0" | "$CM" explore s.cmdb - > explore.out 2>&1 &&
  fail "explore ran on a file being served"
grep -q "in use" explore.out || fail "explore's refusal does not say the file is in use: $(cat explore.out)"

# --- a refined level: the tile of zoom 1 over the attractor at x 144 -------
curl -sf "$url/tiles/1/0/-2.png" -o r1.png || fail "tile 1/0/-2"
[ -f s.zoom1.cmdb ] || fail "zoom 1 made no file s.zoom1.cmdb"
curl -sf "$url/cell?x=144.2&y=0&zoom=1&steps=0" -o rcell.json || fail "/cell at zoom 1"
[ "$(check json rcell.json level computed)" = "1 true" ] || fail "/cell at zoom 1: $(cat rcell.json)"

# --- the steps layer: the step numbers export gives, grey by the figures' scale
curl -sf "$url/tiles/0/0/-1.png?layer=steps" -o st0.png || fail "steps tile"
curl -sf "$url/overlays?x0=128&x1=256&y0=-19.52&y1=0.96" -o ov.json || fail "/overlays"
python3 -c "
import json, sys
o = json.load(open('ov.json'))
lines = [v for v in o['overlays'] if v['kind'] == 'switching line']
sys.exit(0 if lines and not o['truncated'] else 'no switching lines: %r' % o)" ||
  fail "/overlays of microchaos-pd has no switching line"

# --- the figure of a view: what `render --layers all` draws, byte for byte --
fig="x0=128&x1=256&y0=-19.52&y1=0.96"
curl -sf "$url/figure.png?$fig&w=800&h=600" -o fig.png || fail "/figure.png"
curl -sf "$url/figure.svg?$fig" -o fig.svg || fail "/figure.svg"

# --- point queries: the cell, its label, its orbit as `orbit` gives it ------
curl -sf "$url/cell?x=150.3&y=0.1&steps=5" -o cell.json || fail "/cell"
[ "$(check json cell.json cell computed)" = "[44, 245] true" ] ||
  fail "/cell of (150.3, 0.1): $(cat cell.json)"
# its attractor (2) as the legend names it: the name --labels gave
grep -q '"label":2,"name":"the second one"' cell.json ||
  fail "/cell does not name attractor 2 as --labels does: $(cat cell.json)"

# --- bad requests: a status and a message, never a crash --------------------
for bad in "/tiles/0/0/x.png" "/tiles/4/0/0.png" "/tiles/-9/0/0.png" "/tiles/0/0/0.jpg" \
           "/tiles/0/9999999999999999/0.png" "/tiles/0/0/-0000000000000000000001.png" \
           "/cell?x=nan&y=0" "/cell?x=1e400&y=0" "/cell?x=1&y=" "/cell" "/cell?x=1e300&y=0" \
           "/cell?x=1&y=2&steps=-1" "/cell?x=1&y=2&steps=1.5" "/cell?x=1&y=2&steps=99999" \
           "/figure.png" "/figure.png?x0=1&x1=0&y0=0&y1=1" "/figure.png?x0=0&x1=1&y0=0&y1=1&w=10" \
           "/figure.svg?x0=0&x1=1e300&y0=0&y1=1" "/cell?x=1&y=2&zoom=99" \
           "/tiles/0/0/-1.png?layer=x" "/overlays" "/overlays?x0=1&x1=0&y0=0&y1=1"; do
  [ "$(status "$bad")" = 400 ] || fail "$bad: status $(status "$bad"), expected 400"
done
for missing in "/etc/passwd" "/leaflet/../../../../etc/passwd" "/leaflet/leaflet.js.map" \
                "/leaflet/%2e%2e/%2e%2e/etc/passwd" "/tiles" "/s.cmdb"; do
  [ "$(status "$missing" --path-as-is)" = 404 ] || fail "$missing: status $(status "$missing" --path-as-is)"
done
for page in /info /tiles/Z/X/Y.png /cell /overlays /figure.png /figure.svg /leaflet/; do
  curl -s "$url/nope" | grep -qF "$page" || fail "the 404 of an unknown page does not list $page"
done
[ "$(status / -X POST -d x=1)" = 405 ] || fail "POST: status $(status / -X POST -d x=1)"
[ "$(status / -X DELETE)" = 405 ] || fail "DELETE answered"

# --- 50 tile requests at once ------------------------------------------------
(
  for i in $(seq 0 49); do
    curl -s -o /dev/null -w '%{http_code}\n' "$url/tiles/$((i % 2 - 1))/0/-1.png" &
  done
  wait
) > many.txt
[ "$(grep -c '^200$' many.txt)" = 50 ] || fail "50 requests at once: $(sort many.txt | uniq -c)"
serve_stop
"$CM" info s.cmdb > info.txt 2>&1 || fail "info after serving: $(cat info.txt)"
grep -q "^attractors" info.txt || fail "the file lost its attractors: $(cat info.txt)"
"$CM" render s.cmdb --png render.png --view 128:256,-19.52:0.96 --size 800x600 --labels names.txt \
  --layers all || fail "render"
cmp -s fig.png render.png || fail "/figure.png differs from render's PNG of the view"
"$CM" render s.cmdb --svg render.svg --view 128:256,-19.52:0.96 --size 1000x800 --layers all --labels names.txt ||
  fail "render --svg"
cmp -s fig.svg render.svg || fail "/figure.svg differs from render's SVG of the view"

"$CM" export s.cmdb --labels l0.npy --window "$(window 0 0 -1)" || fail "export tile 0"
"$CM" export s.cmdb --labels l1.npy --window "$(window -1 0 -1)" || fail "export tile -1"
"$CM" export s.cmdb --labels l2.npy --window "$(window 0 1 -1)" || fail "export tile 2"
check tile t0.png legend.json l0.npy 0 0 -1 || fail "tile 0/0/-1 is not the cells' labels"
check tile t1.png legend.json l1.npy -1 0 -1 || fail "tile -1/0/-1 is not its blocks' labels"
check tile t2.png legend.json l2.npy 0 1 -1 || fail "the computing tile is not the cells' labels"
"$CM" export s.cmdb --steps st0.npy --window "$(window 0 0 -1)" || fail "export steps of tile 0"
check steps st0.png st0.npy 0 0 -1 || fail "the steps tile is not the cells' step numbers"

# the cells the tile computed equal a single solve of the union, cell by cell
"$CM" solve --db union.cmdb $pd --region 128:384,-19.52:0.96 --cells 512x256 > /dev/null ||
  fail "solve of the union"
for f in s union; do
  "$CM" export $f.cmdb --labels $f.labels.npy --steps $f.steps.npy --window "128.005:383.995,-19.5192:0.9592" ||
    fail "export $f"
done
check same s.labels.npy union.labels.npy || fail "the served file's labels differ from a single solve's"
check equal s.steps.npy union.steps.npy || fail "the served file's steps differ from a single solve's"

# the refined level is a solve at half the cell size, its tile its labels
# (its attractors' ids its own: colours checked as /cell gives them)
"$CM" solve --db half.cmdb $pd --region 128:192,-9.28:0.96 --cells 256x256 > /dev/null ||
  fail "solve at half the cell size"
for f in s.zoom1 half; do
  "$CM" export $f.cmdb --labels $f.labels.npy --steps $f.steps.npy --window "128.0025:191.9975,-9.2796:0.9596" ||
    fail "export $f"
done
check same s.zoom1.labels.npy half.labels.npy || fail "zoom 1's labels differ from a solve at half the cell size"
check equal s.zoom1.steps.npy half.steps.npy || fail "zoom 1's steps differ from a solve at half the cell size"
check tile-ids r1.png s.zoom1.labels.npy 0 0 -2 || fail "the zoom-1 tile is not its cells' labels"

# --- read-only: nothing computed, nothing written ----------------------------
cp s.cmdb before.cmdb
serve_start s.cmdb --read-only
curl -sf "$url/tiles/0/2/-1.png" -o t3.png || fail "read-only tile"
curl -sf "$url/info" -o ro.json || fail "read-only info"
[ "$(check json ro.json computes regions)" = "false 2" ] || fail "read-only info: $(cat ro.json)"
serve_stop
same_rows s.cmdb before.cmdb "SELECT COUNT(*) FROM regions" || fail "read-only serve changed the regions"

# --- a hostile campaign: 10^4 requests, malformed ones, raw garbage ----------
cp s.cmdb h.cmdb
serve_start h.cmdb --tile-cells 65536
python3 "$SRC/tests/serve_campaign.py" 127.0.0.1 "${url##*:}" 10000 || fail "the hostile campaign"
serve_stop
"$CM" info h.cmdb > /dev/null 2>&1 || fail "info after the campaign"

# --- killed while computing: the file stays whole, serving goes on ----------
serve_start h.cmdb
curl -s -o /dev/null "$url/tiles/-2/3/-1.png" &
sleep 0.3
kill -KILL "$pid"
wait "$pid" 2>/dev/null
wait
"$CM" info h.cmdb > info.txt 2>&1 || fail "info after a kill mid-compute: $(cat info.txt)"
serve_start h.cmdb
[ "$(status /tiles/-2/3/-1.png)" = 200 ] || fail "the tile after a kill mid-compute"
serve_stop

# --- a refined level's file of another lattice is refused by name ----------
cp s.cmdb w.cmdb
"$CM" solve --db w.zoom1.cmdb $pd --region 0:10,0:1 --cells 10x10 > /dev/null || fail "solve w.zoom1"
serve_start w.cmdb --read-only
[ "$(status /tiles/1/0/-1.png)" = 400 ] || fail "zoom 1 of another lattice: status $(status /tiles/1/0/-1.png)"
curl -s "$url/tiles/1/0/-1.png" | grep -q "w.zoom1.cmdb is not zoom 1 of w.cmdb" ||
  fail "zoom 1 of another lattice: $(curl -s "$url/tiles/1/0/-1.png")"
serve_stop

# --- usage ---------------------------------------------------------------------
expect_usage "--port" serve s.cmdb --port 70000
expect_usage "not an IPv4 or IPv6 address" serve new.cmdb $pd --cell-size 0.5,0.08 --bind 1.2.3
[ ! -e new.cmdb ] || fail "serve with a bad --bind made the new file"
expect_usage "which file" serve
echo "one two" > bad-names.txt
expect_usage "bad-names.txt:1" serve s.cmdb --labels bad-names.txt
# a new file whose server cannot listen (the port in use) is not left behind
serve_start s.cmdb --read-only
port=${url##*:}
out=$("$CM" serve made.cmdb $pd --cell-size 0.5,0.08 --port "$port" 2>&1); rc=$?
[ "$rc" = 1 ] && grep -q "cannot listen" <<<"$out" && [ ! -e made.cmdb ] ||
  fail "serve of a new file on a port in use: $rc $out; $(ls made.cmdb* 2>&1)"
serve_stop
out=$("$CM" serve nothing.cmdb 2>&1); rc=$?
[ "$rc" = 2 ] && [ ! -e nothing.cmdb ] || fail "serve of a missing file without a model: $rc $out"

exit $((fails > 0))
