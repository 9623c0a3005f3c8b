#!/usr/bin/env bash
# Regression tests of the Reliability II issue, each defect's reproducer
# first. Outputs onto an input: no command may replace the database it
# reads or writes (or its -wal/-shm, or through a symlink), a palette or
# label file it reads, or another of its outputs; each such command exits
# 2 naming both files and leaves every file byte-identical.
# usage: reliability_test.sh PATH/TO/cellmap
set -u
CM=$1
HERE=$(cd "$(dirname "$0")" && pwd)
. "$HERE/testlib.sh"
enter_workdir

"$CM" solve --cells 60x60 --db plain.cmdb > /dev/null || fail "solve --db plain.cmdb"
sum=$(sha256sum < plain.cmdb)

# refused_apart "needle" FILE args...: exit 2 naming needle, FILE (a copy
# of plain.cmdb) unchanged, no other new file left in the directory
refused_apart() {
  local needle=$1 file=$2; shift 2
  local before after
  before=$(ls -A | sort)
  expect_usage "$needle" "$@"
  after=$(ls -A | sort)
  [ "$before" = "$after" ] || fail "cellmap $*: left files: $(comm -13 <(echo "$before") <(echo "$after"))"
  [ "$(sha256sum < "$file")" = "$sum" ] || fail "cellmap $* changed $file"
}

for f in a d e g h p; do cp plain.cmdb $f.cmdb; done
refused_apart "the PNG a.cmdb is the database a.cmdb" a.cmdb render a.cmdb --png a.cmdb
refused_apart "the SVG a.cmdb is the database a.cmdb" a.cmdb render a.cmdb --svg a.cmdb
refused_apart "--groups d.cmdb is the database d.cmdb" d.cmdb export d.cmdb --groups d.cmdb
refused_apart "--groups d.cmdb is the database" d.cmdb export d.cmdb --cells - --groups d.cmdb
refused_apart "--flat e.cmdb is the database e.cmdb" e.cmdb export e.cmdb --flat e.cmdb
refused_apart "-wal file of the database a.cmdb" a.cmdb render a.cmdb --png a.cmdb-wal
refused_apart "-shm file of the database e.cmdb" e.cmdb export e.cmdb --cells e.cmdb-shm.csv \
  --flat e.cmdb-shm
# through a symlink, a hard link and another spelling of the path
ln -s g.cmdb g.png
refused_apart "the PNG g.png is the database g.cmdb" g.cmdb render g.cmdb --png g.png
ln h.cmdb h-link.png
refused_apart "the PNG h-link.png is the database h.cmdb" h.cmdb render h.cmdb --png h-link.png
mkdir sub
refused_apart "is the database" p.cmdb render p.cmdb --png sub/../p.cmdb
refused_apart "is the database" p.cmdb render p.cmdb --png "$PWD/p.cmdb"
# solve: the image onto the database it writes (new or resumed)
refused_apart "the database b.cmdb are the same file" plain.cmdb \
  solve --cells 20x20 --db b.cmdb --png b.cmdb
[ ! -e b.cmdb ] || fail "solve --db b.cmdb --png b.cmdb created b.cmdb"
cp plain.cmdb r.cmdb
expect_usage "the database r.cmdb" solve --cells 60x60 --db r.cmdb --resume --svg r.cmdb
[ "$(sha256sum < r.cmdb)" = "$sum" ] || fail "solve --resume --svg r.cmdb changed r.cmdb"
# a file the command reads: a palette or label file
printf '#112233\n#445566\n' > pal.txt
printf '1 first\n' > lab.txt
cp pal.txt pal.orig; cp lab.txt lab.orig
expect_usage "the PNG pal.txt is the palette pal.txt" render a.cmdb --palette pal.txt --png pal.txt
expect_usage "the SVG lab.txt is the labels file lab.txt" render a.cmdb --labels lab.txt --svg lab.txt
cmp -s pal.txt pal.orig && cmp -s lab.txt lab.orig || fail "a palette or label file was changed"
# two outputs of one command, an array's JSON sidecar included
refused_apart "--steps x.npy and --labels x.npy are the same file" plain.cmdb \
  export plain.cmdb --labels x.npy --steps x.npy
refused_apart "--labels' JSON y.json and --groups y.json" plain.cmdb \
  export plain.cmdb --labels y.npy --groups y.json
refused_apart "the SVG z.png and the PNG z.png" plain.cmdb render plain.cmdb --png z.png --svg z.png
# explore: render and export onto the session's own file
cp plain.cmdb f.cmdb
printf 'render f.cmdb\n' > s1.explore
printf 'export --flat f.cmdb\n' > s2.explore
printf 'render f.cmdb-wal\n' > s3.explore
for s in s1 s2 s3; do
  out=$("$CM" explore f.cmdb $s.explore 2>&1 >/dev/null); rc=$?
  [ $rc -eq 1 ] && grep -q "f.cmdb" <<<"$out" && grep -Eq "same file|is the database|-wal file" <<<"$out" \
    || fail "explore $s: rc $rc, '$out'"
  [ ! -e f.cmdb-wal ] || fail "explore $s left f.cmdb-wal"
done
"$CM" export f.cmdb --groups f.csv > /dev/null && "$CM" export plain.cmdb --groups plain.csv > /dev/null \
  && cmp -s f.csv plain.csv || fail "explore onto its own file changed its groups"
# what stays allowed: devices, stdout, distinct files beside the database
"$CM" render plain.cmdb --png /dev/null --svg - > /dev/null || fail "render --png /dev/null --svg -"
"$CM" export plain.cmdb --labels l.npy --steps s.npy > /dev/null || fail "export --labels --steps"
[ -s l.npy ] && [ -s l.json ] && [ -s s.npy ] && [ -s s.json ] || fail "export --labels --steps: files"
[ "$(sha256sum < plain.cmdb)" = "$sum" ] || fail "plain.cmdb changed"

# --- item 7: a damaged anchor far out: no overflow in the colour hash ----
cp plain.cmdb anchor.cmdb
sqlite3 anchor.cmdb "UPDATE attractors SET anchor = '[9223372036854775807,-9223372036854775808]' WHERE id = 1"
out=$("$CM" render anchor.cmdb --by groups --png anchor.png 2>&1 > /dev/null); rc=$?
[ $rc -le 1 ] && ! grep -q "runtime error" <<<"$out" || fail "render of a damaged anchor: rc $rc, '$out'"
# a missing explore script: exit 2 before the session makes its file
out=$("$CM" explore new.cmdb missing.explore --model microchaos-pd --cell-size 1,1 2>&1); rc=$?
[ $rc -eq 2 ] && [ ! -e new.cmdb ] || fail "explore with a missing script: rc $rc, '$out'"

# one explore step computes no more than --mem holds (12 bytes a cell)
out=$(printf 'view 0:20 -40:40\nview 0:500 -40:40\n' |
  "$CM" explore mem.cmdb - --model microchaos-pd --cell-size 0.5,0.08 --mem 1M 2>&1 > /dev/null); rc=$?
[ $rc -eq 1 ] && grep -q "more than 87381 at once (what the memory budget holds" <<<"$out" \
  || fail "explore beyond --mem: rc $rc, '$out'"
[ "$(sqlite3 mem.cmdb 'SELECT SUM(cells) FROM regions')" = 40000 ] || fail "explore beyond --mem computed cells"

# --- item 2: a window that holds no cell centre: exit 2, nothing written --
for o in "--labels L.npy --window 1:1.5,-1e9:1e9" "--steps S.npy --window 0:500,1:1.01" \
         "--cells C.csv --window 1:1.5,-1e9:1e9" "--flat W.sqlite --window 0:500,1:1.01"; do
  expect_usage "holds no cell centre of the file" export plain.cmdb $o
done
ls L.npy* S.npy* C.csv* W.sqlite* 2> /dev/null && fail "an empty window left a file"
[ "$(sha256sum < plain.cmdb)" = "$sum" ] || fail "plain.cmdb changed"

# --- item 6: palette and labels files that are devices, FIFOs or directories
mkfifo fifo
for o in "--palette /dev/zero" "--labels /dev/zero" "--palette ./fifo" "--labels ./fifo" "--labels ." "--palette ./"; do
  out=$(timeout 20 "$CM" render plain.cmdb --png z.png $o 2>&1 > /dev/null); rc=$?
  [ $rc -eq 2 ] && grep -q "cannot be read" <<<"$out" || fail "render $o: rc $rc, '$out'"
done
out=$(timeout 20 "$CM" solve --cells 20x20 --png z.png --palette /dev/zero 2>&1 > /dev/null); rc=$?
[ $rc -eq 2 ] && grep -q "not a regular file" <<<"$out" || fail "solve --palette /dev/zero: rc $rc, '$out'"
out=$(printf 'render z.png --labels /dev/zero\n' | timeout 20 "$CM" explore plain.cmdb - 2>&1 > /dev/null); rc=$?
[ $rc -eq 1 ] && grep -q "not a regular file" <<<"$out" || fail "explore render --labels /dev/zero: rc $rc, '$out'"
[ ! -e z.png ] || fail "a refused palette or labels file left z.png"
[ "$(sha256sum < plain.cmdb)" = "$sum" ] || fail "plain.cmdb changed"

# --- item 7: temporary outputs of killed runs --------------------------------
# OUT.tmp-N of a process N that no longer runs, ours and not locked, goes
# (with its SQLite companions) when OUT is written again; one whose process
# runs, one locked by a live writer (as another machine's writer on a
# network file system is), a symlink and another user's are kept
for s in "" -journal -wal; do echo stale > "s.png.tmp-999999$s"; done
echo live > "s.png.tmp-$$"
echo locked > s.png.tmp-999998
exec 9< s.png.tmp-999998 && flock -n 9 || fail "flock s.png.tmp-999998"   # held by this shell
ln -s plain.cmdb s.png.tmp-999997
if [ "$(id -u)" = 0 ]; then echo theirs > s.png.tmp-999996; chown 65534 s.png.tmp-999996; fi
"$CM" render plain.cmdb --png s.png --quiet || fail "render over stale temporary files"
for s in "" -journal -wal; do [ ! -e "s.png.tmp-999999$s" ] || fail "stale s.png.tmp-999999$s kept"; done
[ -e "s.png.tmp-$$" ] || fail "the temporary file of a running process was removed"
[ -e s.png.tmp-999998 ] || fail "a temporary file locked by a live writer was removed"
[ -L s.png.tmp-999997 ] || fail "a symlink named like a temporary file was removed"
[ "$(id -u)" != 0 ] || [ -e s.png.tmp-999996 ] || fail "another user's temporary file was removed"
exec 9<&-
rm -f s.png.tmp-*

# A solve stopped in WAL mode, then its file removed, leaves its -wal and
# -shm: a new database at that name would have had the old one's pages read
# into it (the new solve then failed on the old regions' rows, and the file
# held the old cluster). Refused, naming the file, which is kept; the next
# solve, once it is removed, makes a clean file. An -shm alone is removed.
"$CM" solve --cells 60x60 --split 2x2 --db w.cmdb --quiet > /dev/null || fail "solve --db w.cmdb"
python3 - <<'PY' || fail "copy w.cmdb with its WAL"
import os, shutil, sqlite3
# a writer's last commit still in its WAL, copied as a killed writer leaves it
db = sqlite3.connect("w.cmdb", isolation_level=None)
db.execute("PRAGMA journal_mode=WAL")
db.execute("PRAGMA wal_autocheckpoint=0")
db.execute("INSERT INTO meta(key, value) VALUES ('note.left', 'in the WAL only')")
assert os.path.getsize("w.cmdb-wal") > 0
for s in ("", "-wal", "-shm"):
    shutil.copyfile("w.cmdb" + s, "left.cmdb" + s)
PY
rm left.cmdb
wal=$(sha256sum < left.cmdb-wal)
out=$("$CM" solve --cells 40x40 --db left.cmdb --quiet 2>&1)
rc=$?
[ $rc -ne 0 ] && grep -q "left.cmdb-wal (.* bytes) is left from a database left.cmdb that is gone" \
  <<<"$out" || fail "a new database over a stale WAL: exit $rc, '$out'"
[ ! -e left.cmdb ] && [ "$(sha256sum < left.cmdb-wal)" = "$wal" ] || fail "the stale WAL changed"
rm left.cmdb-wal
"$CM" solve --cells 40x40 --db left.cmdb --quiet > /dev/null || fail "solve once the WAL is gone"
[ ! -e left.cmdb-shm ] || "$CM" info left.cmdb > /dev/null || fail "the new file beside an old -shm"
[ "$(sqlite3 left.cmdb 'SELECT COUNT(*) FROM meta WHERE key = "note.left"')" = 0 ] \
  || fail "the old WAL's rows are in the new file"
# a killed export leaves its locked temporary file; the next export removes it
"$CM" solve --cells 1500x1500 --db big.cmdb --quiet || fail "solve big.cmdb"
"$CM" export big.cmdb --cells big.csv --quiet & exporter=$!
for _ in $(seq 200); do compgen -G "big.csv.tmp-*" > /dev/null && break; sleep 0.02; done
sleep 0.2
kill -9 $exporter 2> /dev/null || fail "the export ended before it could be killed"
wait $exporter 2> /dev/null
compgen -G "big.csv.tmp-*" > /dev/null || fail "the killed export left no temporary file (nothing tested)"
"$CM" export plain.cmdb --cells big.csv --quiet || fail "export after a killed one"
! compgen -G "big.csv.tmp-*" > /dev/null || fail "the killed export's temporary file stayed: $(ls big.csv.tmp-*)"

# --- item 8: one exit-code rule, messages that name the user's path ---------
# 2: the user's arguments or files, found before any work
expect_usage "missing.cmdb does not exist" info missing.cmdb
expect_usage "missing.cmdb does not exist" render missing.cmdb --png x.png
expect_usage "missing.cmdb does not exist" export missing.cmdb --groups x.csv
expect_usage "missing.cmdb does not exist" solve --cells 20x20 --db missing.cmdb --resume
expect_usage "cannot read the curves file missing.csv" lyapunov --grid Omega=0.3:0.7:2,S=0.02:0.4:2 --periods 2 --png x.png --curves missing.csv
expect_usage "an output file name is empty" sweep --vary P=0.006,0.007 --cells 40x20 --csv ""
expect_usage "an output file name is empty" export plain.cmdb --groups ""
expect_usage "the directory nodir does not exist" render plain.cmdb --png nodir/x.png
expect_usage "the directory nodir does not exist" solve --cells 20x20 --db nodir/x.cmdb
expect_usage "the directory nodir does not exist" export plain.cmdb --flat nodir/x.sqlite
expect_usage "the directory nodir does not exist" export plain.cmdb --labels nodir/x.npy
expect_usage "the directory nodir does not exist" orbit --from 10,0 --steps 3 --csv nodir/x.csv
mkdir adir
expect_usage "the script adir is a directory" explore plain.cmdb adir
long=$(printf 'n%.0s' $(seq 4190))
expect_usage "the output file name nnnn" render plain.cmdb --png "$long.png"
expect_usage "the output file name nnnn" export plain.cmdb --cells "$long.csv"
# one wording for a stray argument, in every command
for cmd in solve sweep render info export models orbit fixed-points lyapunov simulate bifurcation \
           continue amplitude escape stability horseshoe partition; do
  file=; case $cmd in render|info|export) file=plain.cmdb ;; esac
  expect_usage "unexpected argument 'stray'" $cmd $file stray
  expect_usage "unknown option '--stray'" $cmd $file --stray
done
# a lone "-" is a stray word, not an option (where no output takes it)
for cmd in solve models orbit stability partition; do expect_usage "unexpected argument '-'" $cmd -; done
[ ! -e x.png ] && [ ! -e x.csv ] && [ ! -e x.cmdb ] || fail "a refused command wrote an output"
! compgen -G "*.tmp-*" > /dev/null || fail "refused commands left temporary files: $(ls ./*.tmp-*)"

# A full disk and a read-only directory (a small tmpfs in a private mount
# namespace: root, or an unprivileged user namespace). On a full disk: exit
# 1, the user's path, the reason and the fix, no file left; a solve --db
# keeps what it committed and says how to resume, and the resumed file is
# the solve's without a full disk, cell by cell.
if [ "$(id -u)" = 0 ]; then ns=(unshare -m); else ns=(unshare -rm); fi
if "${ns[@]}" true 2> /dev/null; then
  "$CM" solve --cells 600x600 --split 4x4 --db whole.cmdb --quiet || fail "solve whole.cmdb"
  cat > disk.sh <<'SH'
set -u
CM=$1; mkdir -p small ro
mount -t tmpfs -o size=64k tmpfs small && mount -t tmpfs -o ro,size=64k tmpfs ro || exit 99
check() { # check RC NEEDLE args...: exit RC, a message with NEEDLE, no file left in small
  local want=$1 needle=$2; shift 2
  out=$("$CM" "$@" 2>&1 > /dev/null); rc=$?
  [ $rc -eq "$want" ] && grep -qF -- "$needle" <<<"$out" || echo "FAIL: cellmap $*: rc $rc, '$out'"
  [ -z "$(ls small | grep -v filler)" ] || echo "FAIL: cellmap $* left $(ls small)"
}
head -c 65536 /dev/zero > small/filler 2> /dev/null
full="No space left on device; free space"
check 1 "cannot write small/a.png: $full" render plain.cmdb --png small/a.png
check 1 "cannot write small/a.svg: $full" render plain.cmdb --svg small/a.svg
check 1 "cannot write small/L.npy: $full" export plain.cmdb --labels small/L.npy
check 1 "cannot write small/f.sqlite: $full" export plain.cmdb --flat small/f.sqlite
check 1 "cannot write small/c.csv: $full" export plain.cmdb --cells small/c.csv
check 1 "cannot write small/g.csv: $full" export plain.cmdb --groups small/g.csv
check 1 "cannot write small/x.csv: $full" orbit --from 10,0 --steps 3 --csv small/x.csv
check 2 "cannot write ro/a.png: the directory ro is not writable" render plain.cmdb --png ro/a.png
check 2 "cannot write ro/s.cmdb: the directory ro is not writable" solve --cells 20x20 --db ro/s.cmdb
check 2 "cannot write ro/f.sqlite: the directory ro is not writable" export plain.cmdb --flat ro/f.sqlite
rm small/filler
mount -o remount,size=400k small
out=$("$CM" solve --cells 600x600 --split 4x4 --db small/s.cmdb --quiet 2>&1); rc=$?
[ $rc -eq 1 ] && grep -q "s.cmdb: No space left on device" <<<"$out" && grep -q "small/s.cmdb keeps the [0-9]* regions* joined so far.*--resume" <<<"$out" \
  || echo "FAIL: solve onto a full disk: rc $rc, '$out'"
mount -o remount,size=64m small
"$CM" solve --cells 600x600 --split 4x4 --db small/s.cmdb --resume --quiet || echo "FAIL: the resume after a full disk"
"$CM" export small/s.cmdb --labels a.npy --steps as.npy --quiet && "$CM" export whole.cmdb --labels b.npy --steps bs.npy --quiet \
  && cmp -s a.npy b.npy && cmp -s as.npy bs.npy || echo "FAIL: the resumed file differs from a solve without a full disk"
SH
  "${ns[@]}" bash disk.sh "$CM" > disk.out 2>&1; rc=$?
  [ $rc -ne 99 ] || fail "no tmpfs could be mounted: $(cat disk.out)"
  while read -r line; do fail "${line#FAIL: }"; done < <(grep '^FAIL' disk.out)
else
  echo "reliability_test: no private mount namespace here; the full-disk checks did not run" >&2
fi

[ "$fails" -eq 0 ] && echo "reliability_test: ok"
exit $((fails > 0))
