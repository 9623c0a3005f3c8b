#!/usr/bin/env bash
# A model of your own: cellmap installed to a temporary prefix, the Henon
# plugin of examples/plugin/ built against it out of tree with pkg-config
# only (plain cc and CMake), solved, and its result checked against orbits
# this test computes itself; files remember their plugin; a plugin of
# another ABI is refused.
# usage: plugin_test.sh PATH/TO/cellmap SOURCE_DIR BUILD_DIR
set -u
SRC=$(realpath "$2")
BUILD=$(realpath "$3")
HERE=$(cd "$(dirname "$0")" && pwd)
. "$HERE/testlib.sh"
enter_workdir

cmake --install "$BUILD" --prefix "$work/prefix" > install.log 2>&1 || fail "install: $(cat install.log)"
CM="$work/prefix/bin/cellmap"
export PKG_CONFIG_PATH="$work/prefix/share/pkgconfig"
cc -Wall -Wextra -Werror -shared -fPIC $(pkg-config --cflags cellmap) -o libhenon.so \
  "$SRC/examples/plugin/henon.c" -lm || fail "cc with pkg-config"
cmake -S "$SRC/examples/plugin" -B henon-build > cmake.log 2>&1 && cmake --build henon-build > build.log 2>&1 \
  && [ -s henon-build/libhenon.so ] || fail "the plugin's CMake build: $(tail -5 cmake.log build.log)"

"$CM" models --model-lib ./libhenon.so | grep -q "^henon$" || fail "models --model-lib lists no henon"
# Newton's method for z^3 - 1: the three roots, each of period 1
cc -Wall -Wextra -Werror -shared -fPIC $(pkg-config --cflags cellmap) -o libnewton.so \
  "$SRC/examples/plugin/newton.c" -lm || fail "cc newton.c"
[ -s henon-build/libnewton.so ] || fail "the CMake build has no libnewton.so"
"$CM" solve --model-lib ./libnewton.so --model newton --cells 300x300 --json > newton.json \
  || fail "solve newton"
python3 - newton.json <<'PY' || fail "Newton's attractors"
import json, sys
a = json.load(open(sys.argv[1]))["attractors"]
roots = [(1, 0), (-0.5, 0.8660254037844386), (-0.5, -0.8660254037844386)]
assert len(a) == 3 and all(x["kind"] == "periodic" and x["period"] == 1 for x in a), a
assert sorted(min(abs(x["centre"][0] - r[0]) + abs(x["centre"][1] - r[1]) for r in roots) for x in a)[-1] < 1e-12, a
PY
henon=(--model-lib ./libhenon.so --model henon --param a=1.4,b=0.3 --region=-2.5:2.5,-2.5:2.5)
"$CM" solve "${henon[@]}" --cells 1000x1000 --max-steps 4 --db henon.cmdb > henon.txt || fail "solve henon"
"$CM" export henon.cmdb --cells cells.csv --quiet || fail "export henon.cmdb"
"$CM" solve --model-lib ./libhenon.so --model henon --cells 60x30 --json | grep -q '"box":\[\[-1.5,1.5\],\[-0.45,0.45\]\]' \
  || fail "the plugin's default region"

# the attractor against orbits: every point of a long orbit lies in (or next
# to) a cell of the attractor's group, and cells' labels (attractor or
# escape) agree with the orbit from their centre
python3 - cells.csv <<'PY' || fail "Henon against its orbits"
import csv, random
w, x0, y0 = 0.005, -2.5, -2.5
grp, basin = {}, {}
for r in csv.DictReader(open("cells.csv")):
    c = (int(r["ix"]), int(r["iy"]))
    grp[c] = int(r["grp"])
    basin[grp[c]] = basin.get(grp[c], 0) + 1
attractor = max((g for g in basin if g), key=basin.get)  # the group with the largest basin
cell = lambda x, y: (int((x - x0) // w), int((y - y0) // w))
def step(x, y):
    return 1 - 1.4 * x * x + y, 0.3 * x
x, y = 0.1, 0.1
for _ in range(1000):
    x, y = step(x, y)
near = 0
for _ in range(100000):
    x, y = step(x, y)
    i, j = cell(x, y)
    near += any(grp.get((i + di, j + dj)) == attractor for di in (-1, 0, 1) for dj in (-1, 0, 1))
assert near == 100000, near
random.seed(1)
agree = 0
for _ in range(1000):
    c = (random.randrange(1000), random.randrange(1000))
    x, y = x0 + (c[0] + 0.5) * w, y0 + (c[1] + 0.5) * w
    escaped = False
    for _ in range(2000):
        x, y = step(x, y)
        if abs(x) > 1e6:
            escaped = True
            break
    agree += (grp[c] == 0) == escaped
assert agree >= 980, agree
print("orbit points in the attractor's cells:", near, "labels that agree:", agree)
PY

# the file remembers its plugin: found from any directory, refused when gone or changed
mkdir elsewhere
(cd elsewhere && "$CM" info ../henon.cmdb > info.txt) || fail "info from another directory"
grep -q "^model henon" elsewhere/info.txt || fail "info: $(cat elsewhere/info.txt)"
"$CM" render henon.cmdb --png henon.png || fail "render of a plugin's file"
grep -q "^plugin .*/libhenon.so (hash [0-9a-f]*)$" elsewhere/info.txt || fail "info names no plugin"
mv libhenon.so moved.so
"$CM" render henon.cmdb --png gone.png 2> gone.txt && fail "a missing plugin was not noticed"
grep -q "comes from the plugin .*libhenon.so, which cannot be loaded" gone.txt || fail "missing: $(cat gone.txt)"
"$CM" info henon.cmdb | grep -q "^plugin .*which cannot be loaded" || fail "info of a missing plugin"
"$CM" explore henon.cmdb - --model-lib ./moved.so < /dev/null > /dev/null 2> moved.txt \
  || fail "explore with the plugin where it is now: $(cat moved.txt)"
sed 's/return fabs(y\[0\]) < 1e100/return fabs(y[0]) < 1e99/' "$SRC/examples/plugin/henon.c" > changed.c
cc -shared -fPIC $(pkg-config --cflags cellmap) -o libhenon.so changed.c -lm
"$CM" render henon.cmdb --png changed.png 2> changed.txt && fail "a changed plugin was not noticed"
grep -q "the plugin changed since" changed.txt || fail "changed: $(cat changed.txt)"

# libcellmap from the prefix, with pkg-config only: shared (the SONAME
# carries the major version) and static
cat > api.c <<'C'
#include <cellmap/cellmap.h>
#include <stdio.h>
int main(void)
{
    cm_system *s;
    cm_result *r;
    char msg[256];
    const cm_grid g = {2, {-1.5, -0.45}, {1.5, 0.45}, {120, 40}};
    if (cm_system_new(NULL, "microchaos-pd", NULL, &s, msg, sizeof msg) != CM_OK ||
        cm_solve(s, &g, NULL, &r, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "%s\n", msg);
        return 1;
    }
    printf("%s %llu %u\n", cm_version(), (unsigned long long)cm_result_cells(r), cm_result_groups(r));
    cm_result_free(r);
    cm_system_free(s);
    return 0;
}
C
san=${CELLMAP_SANITIZE:+-fsanitize=address,undefined} # an instrumented libcellmap
cc -Wall -Wextra -Werror $san $(pkg-config --cflags cellmap) -o api-shared api.c $(pkg-config --libs cellmap) \
  || fail "cc against libcellmap.so"
cc $san $(pkg-config --cflags cellmap) -o api-static api.c -Wl,-Bstatic $(pkg-config --libs-only-L cellmap) \
  -lcellmap -Wl,-Bdynamic $(pkg-config --static --libs-only-l cellmap | sed 's/-lcellmap//') -fopenmp \
  || fail "cc against libcellmap.a"
libdir=$(pkg-config --variable=libdir cellmap)
objdump -p "$libdir/libcellmap.so" | grep -q "SONAME *libcellmap.so.0" || fail "no SONAME libcellmap.so.0"
[ "$(LD_LIBRARY_PATH=$libdir ./api-shared | cut -d' ' -f2)" = 4800 ] || fail "api-shared: $(LD_LIBRARY_PATH=$libdir ./api-shared 2>&1)"
a=$(./api-static) && b=$(LD_LIBRARY_PATH=$libdir ./api-shared) && [ -n "$a" ] && [ "$a" = "$b" ] \
  || fail "api-static: $(./api-static 2>&1)"
objdump -p api-static | grep -q "NEEDED *libcellmap" && fail "api-static needs libcellmap.so"

# an ODE in a plugin: its vector field, integrated by cellmap; unforced and
# damped (A = 0, b = 0.5) the stroboscopic map is the linearised pendulum's
# decay near the origin, and the solve finds the rest state
cc -Wall -Wextra -Werror -shared -fPIC $(pkg-config --cflags cellmap) -o libpendulum.so \
  "$SRC/examples/plugin/pendulum.c" -lm || fail "cc pendulum.c"
"$CM" orbit --model-lib ./libpendulum.so --model pendulum --param A=0,b=0.5 --from 0.01,0 \
  --steps 1 > pend.csv || fail "orbit of the pendulum plugin"
python3 - pend.csv <<'PY' || fail "the pendulum plugin's map is not the linear decay"
import csv, math, sys
rows = [r for r in csv.reader(l for l in open(sys.argv[1]) if not l.startswith("#"))]
x1 = float(rows[2][1])
b, T = 0.5, 2 * math.pi / 0.9     # x'' + b x' + x = 0 from (0.01, 0) over one period
wd = math.sqrt(1 - b * b / 4)
want = 0.01 * math.exp(-b * T / 2) * (math.cos(wd * T) + b / (2 * wd) * math.sin(wd * T))
assert abs(x1 - want) < 1e-6 * 0.01 + 2e-7, (x1, want)   # sin(x) ~ x to 1e-6 here
PY
"$CM" solve --model-lib ./libpendulum.so --model pendulum --param A=0,b=0.5 --cells 41x41 \
  --max-steps 20 --json > pend.json || fail "solve the pendulum plugin"
grep -q '"period":1,"basin_cells":[0-9]*,"centre":\[0,0\]' pend.json || fail "pendulum: no rest state found: $(head -c 300 pend.json)"

# a plugin built for another ABI is refused, with both versions
sed 's/static const cm_plugin plugin = {CM_PLUGIN_ABI,/static const cm_plugin plugin = {CM_PLUGIN_ABI + 98,/' \
  "$SRC/examples/plugin/henon.c" > abi.c
cc -shared -fPIC $(pkg-config --cflags cellmap) -o libabi.so abi.c -lm
abi=$(sed -n 's/^#define CM_PLUGIN_ABI \([0-9]*\).*/\1/p' "$SRC/cellmap/plugin.h")
oldest=$(sed -n 's/^#define CM_PLUGIN_ABI_OLDEST \([0-9]*\).*/\1/p' "$SRC/cellmap/plugin.h")
[ "$oldest" -lt "$abi" ] || fail "CM_PLUGIN_ABI_OLDEST '$oldest' is not below CM_PLUGIN_ABI '$abi'"
expect_usage "was built for plugin ABI $((abi + 98)), this cellmap loads ABI $oldest..$abi" \
  solve --model-lib ./libabi.so --model henon
# a plugin of the oldest ABI still loads (cm_model only grew at its end since)
sed "s/static const cm_plugin plugin = {CM_PLUGIN_ABI,/static const cm_plugin plugin = {$oldest,/" \
  "$SRC/examples/plugin/henon.c" > oldest.c
cc -shared -fPIC $(pkg-config --cflags cellmap) -o liboldest.so oldest.c -lm
"$CM" solve --model-lib ./liboldest.so --model henon --cells 40x40 --quiet \
  || fail "a plugin of ABI $oldest is refused"
# one before it is refused
sed "s/static const cm_plugin plugin = {CM_PLUGIN_ABI,/static const cm_plugin plugin = {$((oldest - 1)),/" \
  "$SRC/examples/plugin/henon.c" > old.c
cc -shared -fPIC $(pkg-config --cflags cellmap) -o libold.so old.c -lm
expect_usage "was built for plugin ABI $((oldest - 1)), this cellmap loads ABI $oldest..$abi: build it again" \
  solve --model-lib ./libold.so --model henon

# the pendulum's angle is periodic (-pi:pi): a rotation goes round instead
# of leaving the box, so nothing is left outside or diverges
"$CM" solve --model-lib ./libpendulum.so --model pendulum --cells 100x100 --json > rot.json \
  || fail "solve the forced pendulum"
python3 - rot.json <<'PY' || fail "the pendulum's rotations leave the box: $(head -c 300 rot.json)"
import json, sys
d = json.load(open(sys.argv[1]))
assert abs(d["box"][0][0] + 3.141592653589793) < 1e-9 and abs(d["box"][0][1] - 3.141592653589793) < 1e-9, d["box"]
assert d["diverged_cells"] == d["outside_cells"] == 0 and len(d["attractors"]) >= 1, d
PY
# a box wider than the period, or beyond it: a clear message, exit 2, nothing written
expect_usage "more than its period" solve --model-lib ./libpendulum.so --model pendulum \
  --region=-4:4,-4:4 --cells 10x10 --db wide.cmdb
expect_usage "beyond its period" solve --model-lib ./libpendulum.so --model pendulum \
  --region=0:4,-4:4 --cells 10x10 --db beyond.cmdb
expect_usage "its cells must tile the period" explore tile.cmdb - --model-lib ./libpendulum.so \
  --model pendulum --cell-size 0.05,0.1
[ ! -e wide.cmdb ] && [ ! -e beyond.cmdb ] && [ ! -e tile.cmdb ] || fail "a refused command wrote a file"
# a pan across the seam stops there: every region stays within -pi:pi
w=$(python3 -c 'import math; print(repr(2 * math.pi / 100))')
printf 'view 2.5:3.1 -1:1\npan right 50%%\npan right 50%%\nview -3.14:-2.5 -1:1\npan left 50%%\n' |
  "$CM" explore seam.cmdb - --model-lib ./libpendulum.so --model pendulum --cell-size "$w",0.1 \
  --origin=-3.141592653589793,0 > seam.out || fail "explore across the angle's seam"
sqlite3 seam.cmdb "SELECT lo, hi FROM regions" | python3 -c '
import json, math, sys
w = 2 * math.pi / 100
for line in sys.stdin:
    lo, hi = (json.loads(v) for v in line.strip().split("|"))
    assert -math.pi - 1e-9 <= -math.pi + lo[0] * w and -math.pi + hi[0] * w <= math.pi + 1e-9, line
' || fail "a region of the explore session crosses the angle's seam"

# a plugin whose create() fails without a message: the failure is said
sed 's/    memset(m, 0, sizeof \*m);/    memset(m, 0, sizeof *m);\n    return CM_EINVAL;/' \
  "$SRC/examples/plugin/henon.c" > mute.c
cc -shared -fPIC $(pkg-config --cflags cellmap) -o libmute.so mute.c -lm 2> /dev/null
expect_usage "create() failed (status" solve --model-lib ./libmute.so --model henon --region=-1:1,-1:1

# a step that returns a status that is no CM_STEP_* code stops the run
# (exit 1, the model named) instead of passing for the sink
sed 's/    return fabs(y\[0\]) < 1e100/    return x[0] > 1.5 ? 7 : fabs(y[0]) < 1e100/' \
  "$SRC/examples/plugin/henon.c" > code.c
grep -q "? 7 :" code.c || fail "the undefined-status plugin was not made"
cc -shared -fPIC $(pkg-config --cflags cellmap) -o libcode.so code.c -lm
out=$("$CM" solve --model-lib ./libcode.so --model henon --region=-2:2,-2:2 --cells 50x50 2>&1 > /dev/null); rc=$?
[ $rc -eq 1 ] && grep -q "model henon aborted" <<<"$out" || fail "an undefined step status: rc $rc, '$out'"

# a model that cannot be one, or takes a built-in model's name, is refused
sed 's/    m->dim = 2;/    m->dim = 9;/' "$SRC/examples/plugin/henon.c" > dim.c
cc -shared -fPIC $(pkg-config --cflags cellmap) -o libdim.so dim.c -lm
expect_usage "create() gave dimension 9; it must give 1..6" solve --model-lib ./libdim.so --model henon \
  --region=-1:1,-1:1
sed 's/{"henon", "x, y"/{"microchaos-pd", "x, y"/' "$SRC/examples/plugin/henon.c" > twin.c
cc -shared -fPIC $(pkg-config --cflags cellmap) -o libtwin.so twin.c -lm
expect_usage "(microchaos-pd) has the name of a model cellmap knows already" solve --model-lib ./libtwin.so
expect_usage "is no cellmap plugin" solve --model-lib /usr/lib/x86_64-linux-gnu/libm.so.6 --model henon

[ $fails -eq 0 ] && echo "plugin tests passed"
exit $fails
