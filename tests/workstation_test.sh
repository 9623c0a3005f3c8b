#!/usr/bin/env bash
# The workstation from C and from Python (issue 44): libcellmap installed
# to a prefix, a C program built with pkg-config alone (tests/workstation.c)
# and the Python module (python/cellmap, pip-installed without network) do
# what the command does - solve --db --split 2x2, --resume of a cancelled
# solve, --extend 3, an explore session of 20 pans with a render of the
# view, export --labels, and the analysis commands - and what they write
# equals the command's: every database row (but the recorded command
# line), the PNGs' and tables' bytes and the arrays' bytes.
# usage: workstation_test.sh PATH/TO/cellmap SOURCE_DIR BUILD_DIR
set -u
SRC=$(realpath "$2")
BUILD=$(realpath "$3")
HERE=$(cd "$(dirname "$0")" && pwd)
. "$HERE/testlib.sh"
enter_workdir
PY=/usr/bin/python3
if [ -n "${CELLMAP_SANITIZE:-}" ]; then # an instrumented libcellmap: its runtimes first
  export LD_PRELOAD="$(gcc -print-file-name=libasan.so) $(gcc -print-file-name=libubsan.so)"
  export ASAN_OPTIONS=detect_leaks=0
fi

cmake --install "$BUILD" --prefix "$work/prefix" > install.log 2>&1 || fail "install: $(cat install.log)"
CM="$work/prefix/bin/cellmap"
export PKG_CONFIG_PATH="$work/prefix/share/pkgconfig"
# pkg-config alone says how to build and where the library is
san=${CELLMAP_SANITIZE:+-fsanitize=address,undefined}
LD_PRELOAD= cc -std=c11 -Wall -Wextra -Werror $san $(pkg-config --cflags cellmap) -o workstation \
  "$SRC/tests/workstation.c" $(pkg-config --libs cellmap) \
  -Wl,-rpath,"$(pkg-config --variable=libdir cellmap)" 2> cc.log || fail "cc: $(cat cc.log)"

# every table's rows, blobs as hex, the provenance left out (the command
# line, and the journal a script's run keeps)
rows() {
  local t
  for t in $(sqlite3 "$1" "SELECT name FROM sqlite_master WHERE type = 'table' ORDER BY name"); do
    echo "== $t"
    if [ "$t" = meta ]; then
      sqlite3 -cmd '.mode quote' "$1" "SELECT * FROM meta WHERE key NOT IN ('command', 'note.explore.journal') AND NOT ($VIEWLESS AND key LIKE 'note.explore.%') ORDER BY key"
    else
      sqlite3 -cmd '.mode quote' "$1" "SELECT * FROM \"$t\" ORDER BY rowid"
    fi
  done
}
VIEWLESS=0 # 1: leave out the view and depth an explore session notes
same_db() { # A B WHAT
  rows "$1" > a.rows && rows "$2" > b.rows || { fail "$3: cannot read the rows"; return; }
  [ "$(grep -c . a.rows)" -gt 20 ] || fail "$3: only $(grep -c . a.rows) rows in $1"
  cmp -s a.rows b.rows || fail "$3: $1 and $2 differ: $(diff a.rows b.rows | head -5)"
}
same_bytes() { # A B WHAT
  [ -s "$1" ] && cmp -s "$1" "$2" || fail "$3: $1 and $2 differ (or are missing)"
}

# the command's work: solves, a session, an export
PD=(--param alpha=0.078,beta=0,P=0.007,D=0.02)
"$CM" solve "${PD[@]}" --region 0:500,-40:40 --cells 200x100 --split 2x2 --threads 2 \
  --db cli_split.cmdb --quiet || fail "solve --split"
"$CM" solve "${PD[@]}" --region 0:100,-40:40 --cells 100x100 --extend 3 --threads 2 \
  --db cli_ext.cmdb --quiet || fail "solve --extend"
{
  echo "view 0:50 -4:4"
  for k in $(seq 20); do echo "pan right 10%"; done
  echo "render cli_view.png"
} > pans.explore
"$CM" explore cli_explore.cmdb pans.explore --model microchaos-pd "${PD[@]}" \
  --cell-size 0.5,0.08 --threads 2 > explore.log || fail "explore: $(cat explore.log)"
"$CM" export cli_split.cmdb --labels cli_labels.npy --quiet || fail "export --labels"

# a file grown in place: a box added beside a solved tile, and the tile
# extended 3 times, as explore's `view` and `extend auto 3` grow a file
"$CM" solve "${PD[@]}" --region 0:100,-40:40 --cells 100x100 --threads 2 --db cli_added.cmdb \
  --quiet || fail "solve a tile"
cp cli_added.cmdb cli_extended.cmdb
echo "view 100:200 -40:40" > add.explore
printf 'view 0:100 -40:40\nextend auto 3\n' > extend.explore
"$CM" explore cli_added.cmdb add.explore --threads 2 > add.log 2>&1 || fail "explore's view: $(cat add.log)"
"$CM" explore cli_extended.cmdb extend.explore --threads 2 > ext.log 2>&1 ||
  fail "explore's extend: $(cat ext.log)"

# the analysis commands (cheap settings; tests/workstation_analysis.py and
# tests/workstation.c make the same calls)
{ "$CM" stability --P 0.007:0.02:50 --alpha 0.1:1:20 --csv cli_stability.csv --png cli_stability.png &&
  "$CM" partition --param a=1.3,b=0.66 --csv cli_partition.csv --png cli_partition.png &&
  "$CM" amplitude --omega 0.2:2:20 --periods 50 --csv cli_amplitude.csv --png cli_amplitude.png &&
  "$CM" horseshoe --m 1:3 --periods 6 --csv cli_horseshoe.csv --png cli_horseshoe.png &&
  "$CM" escape --cells 1000 --ensemble 1000 --csv cli_escape.csv --png cli_escape.png &&
  "$CM" simulate --from 1,0 --periods 5 --csv cli_simulate.csv --png cli_simulate.png &&
  "$CM" bifurcation --sweep S=0.1:0.3:4 --runs 2 --transient 20 --record 5 \
    --csv cli_bifurcation.csv --runs-csv cli_bifurcation_runs.csv --png cli_bifurcation.png &&
  "$CM" lyapunov --grid Omega=0.4:0.6:3,S=0.1:0.2:3 --periods 50 --csv cli_lyapunov.csv \
    --png cli_lyapunov.png &&
  "$CM" sweep --vary P=0.006,0.007 --region 0:100,-10:10 --cells 50x50 --csv cli_sweep.csv \
    --fractions cli_sweep_fractions.csv --png cli_sweep.png --keep cli_kept &&
  "$CM" continue --vary S=0.02:0.4 --max-points 50 --csv cli_continue.csv \
    --events cli_continue_events.csv --png cli_continue.png &&
  "$CM" equilibria --from 1,0.1,0.2,0.25 --branch xi=3:15 --curve zeta=20:21:2 \
    --csv cli_equilibria.csv &&
  "$CM" periodic --param xi=2.9 --from 1.05,0.2,0.27 --settle 100 --branch xi=2.9:4.1 \
    --direction up --cascade 2 --csv cli_periodic.csv &&
  "$CM" exponents --param xi=4.8 --from 1,0.1,0.2,0.3 --time 20 --transient 5 \
    --csv cli_exponents.csv --png cli_exponents.png &&
  "$CM" simulate --model chip-bue --time 50 --dt 0.05 --of tau --time-unit 1e-3 \
    --csv cli_series.csv --png cli_series.png --spectrum cli_series_spectrum.csv &&
  "$CM" exponents --param xi=4.8 --from 1,0.1,0.2,0.3 --series tau2 --time 200 --transient 10 \
    --dt 0.005 --steps 10 --csv cli_embedding.csv --png cli_embedding.png &&
  "$CM" measure cli_split.cmdb --to cli_split.cmdb --window 0:100,-40:40 --samples 2000 \
    --csv cli_measure.csv --png cli_measure.png --quiet; } > analyses.log 2>&1 ||
  fail "the analysis commands: $(tail -3 analyses.log)"
ANALYSES="stability partition amplitude horseshoe escape simulate bifurcation lyapunov continue exponents series
  embedding"

# without_seconds CSV: the table without its last column (a sweep's timings)
without_seconds() { sed 's/,[^,]*$//' "$1"; }

check_analyses() { # PREFIX: the analyses' files, against the command's
  local name
  for name in $ANALYSES; do
    same_bytes "cli_$name.csv" "$1_$name.csv" "$1: $name's table"
    same_bytes "cli_$name.png" "$1_$name.png" "$1: $name's figure"
  done
  same_bytes cli_bifurcation_runs.csv "$1_bifurcation_runs.csv" "$1: bifurcation's runs"
  same_bytes cli_continue_events.csv "$1_continue_events.csv" "$1: continue's events"
  same_bytes cli_equilibria.csv "$1_equilibria.csv" "$1: equilibria's table"
  same_bytes cli_periodic.csv "$1_periodic.csv" "$1: periodic's table"
  same_bytes cli_series_spectrum.csv "$1_series_spectrum.csv" "$1: the series' spectrum"
  same_bytes cli_measure.csv "$1_measure.csv" "$1: measure's table"
  same_bytes cli_measure.png "$1_measure.png" "$1: measure's figure"
  same_bytes cli_sweep_fractions.csv "$1_sweep_fractions.csv" "$1: sweep's basin shares"
  same_bytes cli_sweep.png "$1_sweep.png" "$1: sweep's figure"
  same_db cli_kept/P=0.006.cmdb "$1_kept/P=0.006.cmdb" "$1: sweep's file of P = 0.006"
  same_db cli_kept/P=0.007.cmdb "$1_kept/P=0.007.cmdb" "$1: sweep's file of P = 0.007"
  head -1 cli_sweep.csv | grep -q ',seconds$' || fail "the sweep's table no longer ends in seconds"
  without_seconds cli_sweep.csv > a_sweep.csv && without_seconds "$1_sweep.csv" > b_sweep.csv &&
    [ "$(grep -c . b_sweep.csv)" -eq 3 ] && cmp -s a_sweep.csv b_sweep.csv ||
    fail "$1: sweep's table differs"
}

check() { # PREFIX: what the C program or Python wrote, against the command's
  same_db cli_split.cmdb "$1_split.cmdb" "$1: solve --split 2x2"
  same_db cli_split.cmdb "$1_resumed.cmdb" "$1: cancelled and resumed"
  same_db cli_ext.cmdb "$1_ext.cmdb" "$1: solve --extend 3"
  same_db cli_explore.cmdb "$1_explore.cmdb" "$1: explore's 20 pans"
  VIEWLESS=1
  same_db cli_added.cmdb "$1_added.cmdb" "$1: a box added"
  same_db cli_extended.cmdb "$1_extended.cmdb" "$1: extended 3 times"
  VIEWLESS=0
  same_bytes cli_view.png "$1_view.png" "$1: render of the view"
  same_bytes cli_labels.npy "$1_labels.npy" "$1: export --labels"
  sed "s/$1_/cli_/g" "$1_labels.json" > sidecar.json
  same_bytes cli_labels.json sidecar.json "$1: export --labels' sidecar"
  # the command resumes what the library left cancelled, to the same file
  [ -s "$1_partial.cmdb" ] && [ "$(sqlite3 "$1_partial.cmdb" 'SELECT COUNT(*) FROM regions')" -lt 4 ] \
    || fail "$1: the cancelled file is not partial"
  "$CM" solve "${PD[@]}" --region 0:500,-40:40 --cells 200x100 --split 2x2 --threads 2 \
    --db "$1_partial.cmdb" --resume --quiet || fail "$1: the command's --resume"
  same_db cli_split.cmdb "$1_partial.cmdb" "$1: resumed by the command"
}

LD_PRELOAD=${LD_PRELOAD:-} ./workstation > c.log 2>&1 || fail "the C program: $(cat c.log)"
check c
check_analyses c

# the same from Python, installed as the README says: pip without network
# or build isolation under the prefix cellmap went to, and no CELLMAP_LIB or
# PKG_CONFIG_PATH: the module finds PREFIX/lib/libcellmap.so.0 itself
unset CELLMAP_LIB PKG_CONFIG_PATH
LD_PRELOAD= $PY -m pip install --quiet --no-deps --no-build-isolation --no-index \
  --prefix "$work/prefix" "$SRC/python" > pip.log 2>&1 || fail "pip install: $(tail -5 pip.log)"
site=$(dirname "$(find "$work/prefix" -path '*-packages/cellmap/__init__.py' | head -1)")
export PYTHONPATH=$(dirname "$site")
$PY "$SRC/tests/workstation.py" > py.log 2>&1 || fail "the Python program: $(tail -20 py.log)"
$PY "$SRC/tests/workstation_analysis.py" py > py_analysis.log 2>&1 ||
  fail "the Python analyses: $(tail -20 py_analysis.log)"
check py
check_analyses py

# a map given as a Python function agrees with the same map as a plugin
LD_PRELOAD= cc -shared -fPIC -I"$work/prefix/include" -o libhenon.so "$SRC/examples/plugin/henon.c" \
  -lm || fail "cc henon"
$PY "$SRC/tests/bench_function_model.py" ./libhenon.so 100 > bench.log 2>&1 \
  || fail "the Python function model: $(tail -20 bench.log)"
cat bench.log

[ "$fails" -eq 0 ] && echo "workstation_test: ok" || exit 1
