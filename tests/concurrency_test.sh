#!/usr/bin/env bash
# Readers beside a writer (issue 45, item 3): `info`, `export --cells` and
# `render` in a loop while `solve --split` writes a file, while an explore
# session pans over one, and while a killed solve is resumed. No reader may
# call the file damaged (a reader of a file in WAL mode keeps one snapshot
# for its whole read), every writer exits 0 (readers that hold the switch
# back to rollback mode off are waited for), and the final file reads as
# the same solve without readers, cell by cell.
# usage: concurrency_test.sh PATH/TO/cellmap
set -u
CM=$1
HERE=$(cd "$(dirname "$0")" && pwd)
. "$HERE/testlib.sh"
enter_workdir

# readers FILE PID: reads FILE in turns until PID ends; prints the runs
# and counts the false "damaged" (and any crash) as failures
readers() {
  local file=$1 pid=$2 runs=0 rc out
  while kill -0 "$pid" 2> /dev/null; do
    case $((runs % 4)) in # the cells of a window: regions, their pages and node tables
      0) out=$("$CM" export "$file" --cells cells.csv --window 0:60,-10:10 --quiet 2>&1 > /dev/null) ;;
      1) out=$("$CM" render "$file" --png view.png --view 0:60,-10:10 --quiet 2>&1 > /dev/null) ;;
      *) out=$("$CM" info "$file" 2>&1 > /dev/null) ;;
    esac
    rc=$?
    runs=$((runs + 1))
    # before the first commit the file may not be there or hold no region
    if [ $rc -gt 1 ] || grep -q "damaged" <<<"$out"; then
      fail "a reader of $file beside its writer (rc $rc): $out"
    fi
  done
  echo "$runs"
}

# same_cells A.cmdb B.cmdb: the same cells, groups, steps and attractors
same_cells() {
  "$CM" export "$1" --cells a.csv --quiet > /dev/null && "$CM" export "$2" --cells b.csv --quiet > /dev/null \
    && cmp -s a.csv b.csv
}

box=(--cells 1200x1200 --split 8x8 --threads 1)
"$CM" solve "${box[@]}" --db alone.cmdb > /dev/null || fail "solve without readers"

# a split solve
"$CM" solve "${box[@]}" --db split.cmdb > /dev/null 2> split.err &
pid=$!
n=$(readers split.cmdb $pid)
wait $pid || fail "the split solve beside readers exited $?: $(cat split.err)"
[ "$n" -ge 30 ] || fail "only $n reader runs beside the split solve"
same_cells split.cmdb alone.cmdb || fail "the split solve beside readers differs from one without"
[ ! -e split.cmdb-wal ] || fail "the split solve left its WAL behind"

# a killed solve, resumed beside readers
"$CM" solve "${box[@]}" --db resumed.cmdb > /dev/null 2>&1 &
pid=$!
for _ in $(seq 3000); do
  [ "$(sqlite3 -readonly resumed.cmdb 'SELECT COUNT(*) FROM regions' 2> /dev/null)" -ge 8 ] 2> /dev/null && break
  sleep 0.01
done
kill -9 $pid 2> /dev/null
wait $pid 2> /dev/null
"$CM" solve "${box[@]}" --db resumed.cmdb --resume > /dev/null 2> resume.err &
pid=$!
n=$(readers resumed.cmdb $pid)
wait $pid || fail "the resume beside readers exited $?: $(cat resume.err)"
[ "$n" -ge 30 ] || fail "only $n reader runs beside the resume"
same_cells resumed.cmdb alone.cmdb || fail "the resume beside readers differs from a solve without"

# an explore session panning
{
  echo "view 0:60 -40:40"
  for _ in $(seq 60); do echo "pan right 50%"; done
} > pans.explore
"$CM" explore pans.cmdb pans.explore --model microchaos-pd --cell-size 0.25,0.08 --origin 0,-40 \
  > /dev/null 2> pans.err &
pid=$!
n=$(readers pans.cmdb $pid)
wait $pid || fail "the explore session beside readers exited $?: $(cat pans.err)"
[ "$n" -ge 30 ] || fail "only $n reader runs beside the explore session"
"$CM" explore alone-pans.cmdb pans.explore --model microchaos-pd --cell-size 0.25,0.08 --origin 0,-40 \
  > /dev/null || fail "the explore session without readers"
same_cells pans.cmdb alone-pans.cmdb || fail "the explore session beside readers differs from one without"

[ "$fails" -eq 0 ] && echo "concurrency_test: ok"
exit $((fails > 0))
