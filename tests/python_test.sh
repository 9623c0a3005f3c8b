#!/usr/bin/env bash
# The Python module (python/cellmap) over the installed libcellmap:
# installed with pip from the source tree into a directory, it solves a
# region and reads a database and a view; every label and step equals what
# `cellmap solve` + `export` give; plugins, cancelling and errors.
# usage: python_test.sh PATH/TO/cellmap SOURCE_DIR BUILD_DIR
set -u
SRC=$(realpath "$2")
BUILD=$(realpath "$3")
HERE=$(cd "$(dirname "$0")" && pwd)
. "$HERE/testlib.sh"
enter_workdir
PY=/usr/bin/python3 # Debian's, with python3-numpy
if [ -n "${CELLMAP_SANITIZE:-}" ]; then # an instrumented libcellmap: its runtimes first
  export LD_PRELOAD="$(gcc -print-file-name=libasan.so) $(gcc -print-file-name=libubsan.so)"
  export ASAN_OPTIONS=detect_leaks=0 # Python's own allocations are no finding of ours
fi

cmake --install "$BUILD" --prefix "$work/prefix" > install.log 2>&1 || fail "install: $(cat install.log)"
CM="$work/prefix/bin/cellmap"
lib=$(ls "$work"/prefix/lib*/libcellmap.so.0 "$work"/prefix/lib/*/libcellmap.so.0 2>/dev/null | head -1)
[ -n "$lib" ] || fail "no libcellmap.so.0 installed: $(find prefix -name 'libcellmap*')"
export CELLMAP_LIB=$lib
LD_PRELOAD= $PY -m pip install --quiet --no-deps --no-build-isolation --target "$work/site" "$SRC/python" \
  > pip.log 2>&1 || fail "pip install: $(tail -5 pip.log)"
export PYTHONPATH="$work/site"

pd=(--param alpha=0.078,beta=0,P=0.007,D=0.02 --region 0:500,-40:40 --cells 400x200)
"$CM" solve "${pd[@]}" --db pd.cmdb --quiet > /dev/null || fail "solve --db"
"$CM" export pd.cmdb --labels labels.npy --steps steps.npy --by groups --quiet || fail "export"
"$CM" export pd.cmdb --labels attractors.npy --quiet || fail "export by attractors"
export PKG_CONFIG_PATH="$work/prefix/share/pkgconfig"
cc -shared -fPIC $(pkg-config --cflags cellmap) -o libhenon.so "$SRC/examples/plugin/henon.c" -lm \
  || fail "cc henon"

$PY - <<'PY' || fail "the Python module"
import numpy as np
import cellmap

assert cellmap.version().count(".") == 2
pd = cellmap.System("microchaos-pd", alpha=0.078, beta=0, P=0.007, D=0.02)
assert pd.dim == 2 and pd.coords == ["x", "v"] and pd.region() == [(0, 500), (-40, 40)]
labels, steps = np.load("labels.npy"), np.load("steps.npy")
attractors = np.load("attractors.npy")
for split in (None, (2, 2)):
    res = cellmap.solve(pd, region=[(0, 500), (-40, 40)], cells=(400, 200), threads=2, split=split)
    assert res.labels.shape == labels.shape == (400, 200), (res.labels.shape, labels.shape)
    assert res.labels.dtype == np.int32 and res.labels.flags["C_CONTIGUOUS"]
    if split is None:  # one region: the same group ids as the file
        assert (res.labels == labels).all(), "labels differ from cellmap solve + export"
    else:              # the same partition, numbered by the joins
        pairs = set(zip(res.labels.ravel().tolist(), labels.ravel().tolist()))
        assert len(pairs) == len({a for a, _ in pairs}) == len({b for _, b in pairs})
    assert (res.steps == steps).all(), "steps differ"
    # the system's attractors: the same labels as export --labels, in any split
    assert (res.attractor_labels == attractors).all(), "attractor labels differ from export"
    assert len(res.attractors) == len(set(attractors[attractors > 0].ravel().tolist()))
    assert all(a["kind"] in ("periodic", "aperiodic") and a["footprint_cells"] > 0
               for a in res.attractors), res.attractors
    assert sum(g["basin_cells"] for g in res.groups) + (res.labels == 0).sum() == 400 * 200
db = cellmap.open("pd.cmdb")
assert db.model == "microchaos-pd" and db.cells == [400, 200]
assert (db.read().labels == labels).all()
assert (db.read().attractor_labels == attractors).all()
view = db.read(view=[(125, 250), (-20, 20)])
assert view.labels.shape == (100, 100) and (view.labels == labels[100:200, 50:150]).all()
res.png("pd.png", 600, 400)
assert open("pd.png", "rb").read(8) == b"\x89PNG\r\n\x1a\n"

# a plugin's model, and a cancelled solve
henon = cellmap.System("henon", plugins=["./libhenon.so"], a=1.4, b=0.3)
h = cellmap.solve(henon, cells=(300, 100))
assert h.groups and h.groups[0]["period"] >= 1
seen = []
try:
    cellmap.solve(pd, cells=(400, 200), split=(4, 4), progress=lambda f: seen.append(f) or f > 0.3)
    raise AssertionError("not cancelled")
except cellmap.CellmapError as e:
    assert "cancelled" in str(e) and seen, e
for bad in (lambda: cellmap.System("nope"), lambda: cellmap.open("missing.cmdb"),
            lambda: cellmap.System("microchaos-pd", alpha="x")):
    try:
        bad()
        raise AssertionError("no error")
    except cellmap.CellmapError as e:
        assert str(e), e
# short or long states and views are refused, not padded or read past
for bad in (lambda: pd.step([1.0]), lambda: pd.step([1.0, 2.0, 3.0]), lambda: db.read([(0, 100)]),
            lambda: db.read([]), lambda: db.read([(0, 100)] * 7), lambda: db.read([(0,), (1,)])):
    try:
        bad()
        raise AssertionError("accepted")
    except ValueError as e:
        assert "dimension" in str(e) or "(lo, hi)" in str(e), e
assert len(pd.step([1.0, 0.5])) == 2
print("python module: labels and steps equal cellmap solve + export")
PY

# libcellmap on MPI ranks (cm_ranks, libcellmap-mpi.so.0 beside it): create()
# on 2 and 3 ranks writes the file create() writes in one process, every
# rank solving regions (the witness plugin notes the processes that step
# its map); ranks asked for different solves, or more ranks than regions,
# fail on every rank with rank 0's message and no file. Not in the
# sanitizer build: Python there runs on preloaded runtimes, and the MPI
# code is checked under the sanitizers by mpi_test.
if [ -z "${CELLMAP_SANITIZE:-}" ] && [ -e "$(dirname "$lib")/libcellmap-mpi.so.0" ]; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
  cc -shared -fPIC $(pkg-config --cflags cellmap) -o libwitness.so "$SRC/tests/rank_witness.c" \
    || fail "cc rank_witness"
  cat > ranks.py <<'PY'
import os, sys, cellmap
path, split = sys.argv[1], (int(sys.argv[2]), int(sys.argv[3]))
differ, abort = "differ" in sys.argv[4:], "abort" in sys.argv[4:]
with cellmap.Ranks() as r:
    # the last rank asks for other cells when told to differ
    cells = (160, 120) if differ and r.rank == r.size - 1 else (160, 100)
    try:
        db = cellmap.create(path, "witness", plugins=["./libwitness.so"], region=[(-4, 4), (-4, 4)],
                            cells=cells, split=split, threads=1, ranks=r,
                            abort_above=3.5 if abort else 1e300)
    except cellmap.CellmapError as e:  # a file per rank: mpirun interleaves their output
        with open("%s.failed-%d" % (path, r.rank), "w") as f:
            f.write(str(e))
        sys.exit(3)
    assert (db is not None) == (r.rank == 0), (r.rank, db)
    if r.size > 1:  # growing a file is one process's: refused on ranks
        import ctypes
        o = cellmap._DbOptions()
        o.ranks = r._h
        lo, hi = (ctypes.c_double * 2)(-5, -4), (ctypes.c_double * 2)(-4, 4)
        try:
            cellmap._call(cellmap._lib.cm_db_add_box, path.encode(), lo, hi, ctypes.byref(o),
                          None)
            raise AssertionError("cm_db_add_box on ranks accepted")
        except cellmap.CellmapError as e:
            assert "grows in one process" in str(e), e
    print(r.rank, r.size)
PY
  mkdir w1 && CELLMAP_WITNESS=w1 $PY ranks.py one.cmdb 4 4 > one.out 2>&1 || fail "ranks.py: $(cat one.out)"
  [ "$(cat one.out)" = "0 1" ] || fail "one process: '$(cat one.out)'"
  sqlite3 one.cmdb .dump > one.sql && [ -s one.sql ] || fail "one process: no database"
  for n in 2 3; do
    mkdir "w$n"
    CELLMAP_WITNESS=w$n mpirun -n "$n" -x CELLMAP_WITNESS -x PYTHONPATH -x CELLMAP_LIB $PY ranks.py \
      "r$n.cmdb" 4 4 > "r$n.out" 2>&1 || fail "$n ranks: $(cat "r$n.out")"
    sqlite3 "r$n.cmdb" .dump > "r$n.sql" && cmp -s one.sql "r$n.sql" \
      || fail "$n ranks: another file than one process's"
    [ "$(ls "w$n" | wc -l)" = "$n" ] || fail "$n ranks: the map stepped by $(ls "w$n" | wc -l) processes"
  done
  bad() { # bad NAME RANKS ARGS...: every rank fails, rank 0 names the problem, no file
    local name=$1 n=$2
    shift 2
    mpirun -n "$n" -x PYTHONPATH -x CELLMAP_LIB $PY ranks.py "$name.cmdb" "$@" > "$name.out" 2>&1 \
      && fail "$name: mpirun exited 0"
    [ "$(ls "$name".cmdb.failed-* 2>/dev/null | wc -l)" = "$n" ] \
      || fail "$name: not every rank failed: $(cat "$name.out")"
    grep -q "$EXPECT" "$name.cmdb.failed-0" || fail "$name: rank 0 said: $(cat "$name.cmdb.failed-0")"
  }
  EXPECT="rank 1 was asked for another solve" bad differ 2 2 2 differ
  EXPECT="3 ranks for 2 regions" bad many 3 2 1
  for name in differ many; do [ ! -e "$name.cmdb" ] || fail "$name: a file was made"; done
  # a region whose map aborts (the last column of boxes), on whichever rank
  # solves it: every rank fails with rank 0's message, which names it
  EXPECT="region 3: .*model witness aborted" bad abort 3 4 4 abort
  # a program that starts MPI itself (mpi4py, at MPI_THREAD_MULTIPLE): the
  # same file, and MPI still up after the ranks are closed (the program's)
  cat > own_mpi.py <<'PY'
import sys
from mpi4py import MPI
import cellmap
r = cellmap.Ranks()
cellmap.create(sys.argv[1], "witness", plugins=["./libwitness.so"], region=[(-4, 4), (-4, 4)],
               cells=(160, 100), split=(4, 4), threads=1, ranks=r)
r.close()
MPI.COMM_WORLD.Barrier()
PY
  mpirun -n 2 -x PYTHONPATH -x CELLMAP_LIB $PY own_mpi.py own.cmdb > own.out 2>&1 \
    || fail "mpi4py: $(cat own.out)"
  sqlite3 own.cmdb .dump > own.sql && cmp -s one.sql own.sql || fail "mpi4py: another file"
  # a libcellmap without the module beside it says so, under mpirun only
  mkdir nomodule && cp "$lib" nomodule/ || fail "copy libcellmap"
  out=$(CELLMAP_LIB=$PWD/nomodule/libcellmap.so.0 mpirun -n 2 -x PYTHONPATH -x CELLMAP_LIB $PY -c \
    'import cellmap; cellmap.Ranks()' 2>&1) && fail "no module: mpirun exited 0"
  grep -q "libcellmap needs $PWD/nomodule/libcellmap-mpi.so.0" <<<"$out" || fail "no module: $out"
  CELLMAP_LIB=$PWD/nomodule/libcellmap.so.0 $PY -c 'import cellmap; assert cellmap.Ranks().size == 1' \
    || fail "no module, no mpirun: not one rank"
  echo "python module on 2 and 3 MPI ranks: the file of one process"
fi

[ $fails -eq 0 ] && echo "python tests passed"
exit $fails
