#!/usr/bin/env bash
# Readers beside a writer (issue 45, item 3): `info`, `export --cells`,
# `render` and the Python module's read() in a loop while `solve --split` writes a file, while an explore
# session pans over one, and while a killed solve is resumed. No reader may
# call the file damaged (a reader of a file in WAL mode keeps one snapshot
# for its whole read), every writer exits 0 (readers that hold the switch
# back to rollback mode off are waited for), and the final file reads as
# the same solve without readers, cell by cell.
# usage: concurrency_test.sh PATH/TO/cellmap SOURCE_DIR BUILD_DIR
set -u
CM=$1
SRC=$(realpath "$2")
BUILD=$(realpath "$3")
HERE=$(cd "$(dirname "$0")" && pwd)
. "$HERE/testlib.sh"
enter_workdir

# reader_loop FILE PID K: reads FILE in turns until PID ends (the cells of
# a window: regions, their pages and node tables; a render; info); prints
# its runs and the failures: a false "damaged", or a crash (before the
# first commit the file may not be there, status 2 "does not exist", or
# hold no region, status 1)
reader_loop() {
  local file=$1 pid=$2 k=$3 runs=0 rc out python_runs=0
  while kill -0 "$pid" 2> /dev/null; do
    # the Python module's start (numpy) is slow: the second loop reads
    # with it first and then one read in twelve
    if [ "$k" -eq 2 ] && [ $((runs % 12)) -eq 0 ]; then
      out=$(python_read "$file" 2>&1 > /dev/null)
      python_runs=$((python_runs + 1))
    else
      case $(((runs + k) % 3)) in
        0) out=$("$CM" export "$file" --cells cells$k.csv --window 0:60,-40:-31 --quiet 2>&1 > /dev/null) ;;
        1) out=$("$CM" render "$file" --png view$k.png --view 0:60,-40:-31 --quiet 2>&1 > /dev/null) ;;
        2) out=$("$CM" info "$file" 2>&1 > /dev/null) ;;
      esac
    fi
    rc=$?
    runs=$((runs + 1))
    if { [ $rc -gt 1 ] && ! { [ $rc -eq 2 ] && grep -q "does not exist" <<<"$out"; }; } ||
      grep -q "damaged" <<<"$out"; then
      echo "failure (rc $rc): $out"
    fi
  done
  echo "runs $runs"
  [ "$k" -ne 2 ] || echo "python $python_runs"
}

# python_read FILE: the Python module (from the source tree, over the
# build's libcellmap) reads a window as arrays; its exceptions name the
# problem ("damaged" for damage), status 1
python_read() {
  env PYTHONPATH="$SRC/python" CELLMAP_LIB="$lib" LD_PRELOAD="$preload" ASAN_OPTIONS=detect_leaks=0 \
    /usr/bin/python3 -c 'import sys, cellmap
r = cellmap.open(sys.argv[1]).read(view=[(0, 60), (-40, -31)])
assert r.labels.size > 0' "$1"
}
lib=$(ls "$BUILD"/libcellmap.so.0 2> /dev/null | head -1)
[ -n "$lib" ] || { echo "concurrency_test: no libcellmap.so.0 in $BUILD" >&2; exit 1; }
preload=
[ -n "${CELLMAP_SANITIZE:-}" ] && preload="$(gcc -print-file-name=libasan.so) $(gcc -print-file-name=libubsan.so)"

# readers FILE PID: two reader loops beside the writer PID; their runs in
# $n, each failure counted (not in a subshell: fail counts here)
readers() {
  reader_loop "$1" "$2" 1 > readers1.txt &
  local other=$!
  reader_loop "$1" "$2" 2 > readers2.txt
  wait $other
  while read -r line; do
    fail "a reader of $1 beside its writer: $line"
  done < <(grep -h '^failure' readers1.txt readers2.txt)
  n=$(($(sed -n 's/^runs //p' readers1.txt) + $(sed -n 's/^runs //p' readers2.txt)))
  local py
  py=$(sed -n 's/^python //p' readers2.txt)
  [ "${py:-0}" -ge 1 ] || fail "no Python read of $1 beside its writer"
}

# same_cells A.cmdb B.cmdb: the same groups, steps and attractors, cell by cell
same_cells() {
  "$CM" export "$1" --labels a.npy --steps as.npy --quiet > /dev/null &&
    "$CM" export "$2" --labels b.npy --steps bs.npy --quiet > /dev/null &&
    cmp -s a.npy b.npy && cmp -s as.npy bs.npy
}

box=(--cells 1500x1500 --split 10x10 --threads 1)
# reader runs each kind of writer must see beside it: 30, and 15 in the
# sanitizer build, whose readers (short processes) lose more to the
# instrumentation
runs=${CELLMAP_SANITIZE:+15}
runs=${runs:-30}
"$CM" solve "${box[@]}" --db alone.cmdb > /dev/null || fail "solve without readers"

# Each kind of writer runs beside the readers, each time on a new file,
# until the readers have run $runs times beside that kind (at most three
# writers: the machine is shared, and a busy one leaves fewer reads).
# beside KIND FUNCTION: FUNCTION runs one writer with readers and sets $n
beside() {
  local kind=$1 fn=$2 total=0 attempt
  for attempt in 1 2 3; do
    "$fn"
    total=$((total + n))
    [ "$total" -ge "$runs" ] && break
  done
  echo "$kind: $total reader runs in $attempt writer run(s)"
  [ "$total" -ge "$runs" ] || fail "only $total reader runs beside $attempt writers ($kind)"
}

# a split solve
split_solve() {
  rm -f split.cmdb split.cmdb-wal split.cmdb-shm
  "$CM" solve "${box[@]}" --db split.cmdb > /dev/null 2> split.err &
  local pid=$!
  readers split.cmdb $pid
  wait $pid || fail "the split solve beside readers exited $?: $(cat split.err)"
  same_cells split.cmdb alone.cmdb || fail "the split solve beside readers differs from one without"
  # readers that never let go may keep the file in WAL mode, but the file
  # alone (copied without its -wal) holds every commit
  cp split.cmdb split-alone.cmdb
  same_cells split-alone.cmdb alone.cmdb || fail "the split solve's file without its -wal lacks commits"
}
beside "split solve" split_solve

# a killed solve, resumed beside readers
resume_solve() {
  rm -f resumed.cmdb resumed.cmdb-wal resumed.cmdb-shm
  "$CM" solve "${box[@]}" --db resumed.cmdb > /dev/null 2>&1 &
  local pid=$!
  for _ in $(seq 3000); do
    [ "$(sqlite3 -readonly resumed.cmdb 'SELECT COUNT(*) FROM regions' 2> /dev/null)" -ge 5 ] 2> /dev/null && break
    sleep 0.01
  done
  kill -9 $pid 2> /dev/null
  wait $pid 2> /dev/null
  "$CM" solve "${box[@]}" --db resumed.cmdb --resume > /dev/null 2> resume.err &
  pid=$!
  readers resumed.cmdb $pid
  wait $pid || fail "the resume beside readers exited $?: $(cat resume.err)"
  same_cells resumed.cmdb alone.cmdb || fail "the resume beside readers differs from a solve without"
}
beside "resume" resume_solve

# an explore session panning (30 pans in the sanitizer build, whose session
# is long enough for twice the reader runs it needs with them)
pans=${CELLMAP_SANITIZE:+30}
{
  echo "view 0:60 -40:40"
  for _ in $(seq "${pans:-60}"); do echo "pan right 50%"; done
} > pans.explore
"$CM" explore alone-pans.cmdb pans.explore --model microchaos-pd --cell-size 0.25,0.08 --origin 0,-40 \
  > /dev/null || fail "the explore session without readers"
explore_pans() {
  rm -f pans.cmdb pans.cmdb-wal pans.cmdb-shm
  "$CM" explore pans.cmdb pans.explore --model microchaos-pd --cell-size 0.25,0.08 --origin 0,-40 \
    > /dev/null 2> pans.err &
  local pid=$!
  readers pans.cmdb $pid
  wait $pid || fail "the explore session beside readers exited $?: $(cat pans.err)"
  same_cells pans.cmdb alone-pans.cmdb || fail "the explore session beside readers differs from one without"
}
beside "explore" explore_pans

[ "$fails" -eq 0 ] && echo "concurrency_test: ok"
exit $((fails > 0))
