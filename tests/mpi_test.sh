#!/usr/bin/env bash
# `cellmap solve` on MPI ranks (lib/ranks.h): on 1, 2 and 3 ranks with 1
# and 2 threads each, a 4x4 split, a 16x16 split and an --extend 6 run give
# the JSON (but its times and the ranks' own traffic), the PNG, the cells
# exported and the database's tables of the solve without MPI; a rank
# killed mid-solve leaves a file that a resumed solve on another number of
# ranks completes to the same cluster; bad input gets one message from
# rank 0, a failure on every rank and no file; a cellmap without
# cellmap-mpi beside it says so under mpirun.
# usage: mpi_test.sh PATH/TO/cellmap
CM=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
. "$(dirname "$0")/testlib.sh"
enter_workdir
# Open MPI refuses root without these (CI runs as root); 3 ranks on 2 cores
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
# In a sanitizer build, no leak check at exit: Open MPI keeps thousands of
# its records to the end, allocated from its components, which it has
# unloaded by then, so no suppression can name them. Every other check of
# AddressSanitizer and UBSan stays on. (Under valgrind's memcheck, 2 ranks
# of a 4x4 split lose memory only from MPI_Init's frames.)
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
command -v mpirun >/dev/null || { echo "FAIL: mpirun not found (openmpi-bin)" >&2; exit 1; }
[ -x "$(dirname "$CM")/cellmap-mpi" ] || { echo "FAIL: no cellmap-mpi beside $CM" >&2; exit 1; }
mpi() { local n=$1; shift; mpirun -n "$n" "$CM" "$@"; }
# rank_pids DB [RANK]: the ranks of the solve writing DB (all, or RANK's)
rank_pids() {
  local p
  for p in $(pgrep -f -- "--db $1"); do
    tr '\0' '\n' < /proc/"$p"/environ 2>/dev/null |
      grep -q "^OMPI_COMM_WORLD_RANK=${2:-[0-9]*}\$" && echo "$p"
  done
}
# wait_commit DB: until the solve writing DB has committed a region
wait_commit() {
  local n
  for _ in $(seq 500); do
    n=$([ -s "$1" ] && sqlite3 -readonly "$1" 'SELECT COUNT(*) FROM regions' 2>/dev/null)
    [ "${n:-0}" -gt 0 ] && return
    sleep 0.01
  done
}

# the JSON without its times and the ranks' traffic, keys sorted
strip_json() {
  python3 -c 'import json, sys
d = json.load(open(sys.argv[1]))
d.pop("time_s"); d.pop("ranks", None); d.pop("command", None)
for s in d.get("extension", {}).get("steps", []):
    s.pop("time_s", None)
print(json.dumps(d, sort_keys=True))' "$1"
}

# every table of a database but its meta command line, as text
dump_db() {
  sqlite3 "$1" ".dump" | grep -v "^INSERT INTO meta VALUES('command'"
}

# outputs NAME: the JSON, PNG, cells and database of a run named NAME
outputs() {
  strip_json "$1.json" > "$1.sjson" && "$CM" export "$1.cmdb" --cells - > "$1.cells" &&
    dump_db "$1.cmdb" > "$1.dump" && [ -s "$1.sjson" ] && [ -s "$1.cells" ] && [ -s "$1.dump" ]
}

same_as() { # same_as REF NAME
  local f
  for f in sjson cells dump png; do
    cmp -s "$1.$f" "$2.$f" || fail "$2: its .$f differs from the solve without MPI ($1)"
  done
}

configs=(
  "s4|--cells 160x80 --split 4x4"
  "s16|--cells 192x96 --split 16x16"
  "e6|--param alpha=0.078,beta=0,P=0.007,D=0.02 --region 0:60,-12:12 --cells 60x24 --extend 6"
)
for c in "${configs[@]}"; do
  name=${c%%|*}
  args=(${c#*|})
  "$CM" solve "${args[@]}" --threads 2 --json --png "$name-ref.png" --db "$name-ref.cmdb" \
    > "$name-ref.json" || fail "$name: the solve without MPI failed"
  outputs "$name-ref" || fail "$name: the reference's outputs"
  for r in 1 2 3; do
    for t in 1 2; do
      run=$name-r$r-t$t
      mpi "$r" solve "${args[@]}" --threads "$t" --json --png "$run.png" --db "$run.cmdb" \
        > "$run.json" || { fail "$run: mpirun exited $?"; continue; }
      outputs "$run" || { fail "$run: its outputs"; continue; }
      same_as "$name-ref" "$run"
      if [ "$r" -gt 1 ]; then # the workers solved their share
        got=$(python3 -c 'import json, sys; r = json.load(open(sys.argv[1]))["ranks"]
by = r["regions_by_rank"]  # a count per rank, and every region from a worker came
print(r["count"], r["regions_from_workers"] > 0, r["bytes_received"] > 0,
      len(by) == r["count"] and sum(by[1:]) == r["regions_from_workers"])' "$run.json")
        [ "$got" = "$r True True True" ] || fail "$run: its ranks: '$got'"
      fi
    done
  done
done

# with a memory budget, rank 0 pages regions to the file while it joins
paged=(--cells 800x400 --split 16x16 --mem 2M)
"$CM" solve "${paged[@]}" --json --db mem-ref.cmdb > mem-ref.json &&
  mpi 3 solve "${paged[@]}" --threads 2 --json --db mem-r3.cmdb > mem-r3.json &&
  strip_json mem-ref.json > mem-ref.sjson && strip_json mem-r3.json > mem-r3.sjson &&
  dump_db mem-ref.cmdb > mem-ref.dump && dump_db mem-r3.cmdb > mem-r3.dump ||
  fail "--mem: a solve failed"
cmp -s mem-ref.sjson mem-r3.sjson && cmp -s mem-ref.dump mem-r3.dump ||
  fail "--mem 2M on 3 ranks: not the solve without MPI"

# the ranks' JSON keeps to the schema
python3 "$(dirname "$0")/schema_check.py" "$(dirname "$0")/../docs/cellmap.schema.json" \
  s16-r3-t2.json > /dev/null || fail "s16-r3-t2.json: not what the schema says"

# a rank killed at a random moment, then --resume on another number of
# ranks (and without MPI): the cluster of the uninterrupted solve
big=(--cells 800x400 --split 16x16)
"$CM" solve "${big[@]}" --json --db big-ref.cmdb > big-ref.json || fail "big: the reference"
dump_db big-ref.cmdb > big-ref.dump
interrupted=0
for k in 1 2 3; do
  rm -f big-$k.cmdb*
  mpi 3 solve "${big[@]}" --db big-$k.cmdb > /dev/null 2>&1 &
  launcher=$!
  wait_commit big-$k.cmdb # then at a random moment
  sleep "0.0$((RANDOM % 10))"
  victims=($(rank_pids big-$k.cmdb))
  [ ${#victims[@]} -gt 0 ] && kill -9 "${victims[RANDOM % ${#victims[@]}]}"
  wait "$launcher" || interrupted=$((interrupted + 1))
  case $k in 1) again=(mpirun -n 2 "$CM") ;; 2) again=("$CM") ;; 3) again=(mpirun -n 3 "$CM") ;; esac
  "${again[@]}" solve "${big[@]}" --db big-$k.cmdb --resume > /dev/null 2>&1 ||
    fail "big $k: the resumed solve after a rank was killed failed"
  dump_db big-$k.cmdb > big-$k.dump
  cmp -s big-ref.dump big-$k.dump || fail "big $k: the resumed cluster differs from the whole one"
done
[ "$interrupted" -gt 0 ] || fail "no kill of a rank interrupted the solve (it was too quick)"

# Ctrl-C to rank 0: it stops after its last commit, says how to finish,
# the workers stop with it (what they still send is drained), all fail
mpi 3 solve "${big[@]}" --db int.cmdb > /dev/null 2> int.err &
launcher=$!
wait_commit int.cmdb
kill -INT $(rank_pids int.cmdb 0)
wait "$launcher" && fail "Ctrl-C to rank 0: mpirun exited 0"
grep -q "cellmap solve: interrupted; int.cmdb keeps the .* To finish it: .*cellmap solve .*--resume" \
  int.err || fail "Ctrl-C to rank 0: $(head -3 int.err)"
"$CM" solve "${big[@]}" --db int.cmdb --resume > /dev/null 2>&1 && dump_db int.cmdb > int.dump &&
  cmp -s big-ref.dump int.dump || fail "Ctrl-C to rank 0: the resumed cluster differs"

# bad input: one message (rank 0's), failure everywhere, no file
out=$(mpi 3 solve --cells 40x20 --split 1x2 --db few.cmdb 2>&1); rc=$?
[ "$rc" -ne 0 ] || fail "3 ranks for 2 regions: exit 0"
[ "$(grep -c 'ranks for 2 regions' <<<"$out")" = 1 ] || fail "3 ranks for 2 regions: '$out'"
[ ! -e few.cmdb ] || fail "3 ranks for 2 regions: few.cmdb was made"
out=$(mpi 2 solve --cells 40x20 2>&1); rc=$?
[ "$rc" -ne 0 ] && grep -q 'split the box' <<<"$out" || fail "one region on 2 ranks: $rc '$out'"
out=$(mpi 2 info nothing.cmdb 2>&1); rc=$?
[ "$rc" -eq 2 ] && [ "$(grep -c 'only solve runs on MPI ranks' <<<"$out")" = 1 ] ||
  fail "info on 2 ranks: $rc '$out'"
# another binary on rank 1: a copy of the programs with cellmap-mpi changed
mkdir other && cp "$CM" "$(dirname "$CM")/cellmap-mpi" other/ && echo >> other/cellmap-mpi
out=$(mpirun -n 1 "$CM" solve --cells 40x20 --split 2x2 --db bin.cmdb : \
      -n 1 other/cellmap solve --cells 40x20 --split 2x2 --db bin.cmdb 2>&1); rc=$?
[ "$rc" -ne 0 ] && grep -q 'rank 1 runs another cellmap program' <<<"$out" ||
  fail "another binary: $rc '$out'"
[ ! -e bin.cmdb ] || fail "another binary: bin.cmdb was made"
out=$(mpirun -n 1 "$CM" solve --cells 40x20 --split 2x2 : -n 1 "$CM" solve --cells 40x22 \
      --split 2x2 2>&1); rc=$?
[ "$rc" -ne 0 ] && grep -q 'rank 1 was given other arguments' <<<"$out" ||
  fail "other arguments: $rc '$out'"
# a cellmap without cellmap-mpi beside it, under mpirun
mkdir alone && cp "$CM" alone/
out=$(mpirun -n 2 alone/cellmap solve --cells 40x20 --split 2x2 2>&1); rc=$?
[ "$rc" -ne 0 ] && grep -q 'cellmap-mpi is built beside cellmap where MPI was found' <<<"$out" ||
  fail "without cellmap-mpi: $rc '$out'"

[ "$fails" -eq 0 ] && echo "mpi_test: ok ($interrupted of 3 killed ranks interrupted the solve)" || { echo "mpi_test: $fails failure(s)" >&2; exit 1; }
