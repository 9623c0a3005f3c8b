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
refused_apart "--png a.cmdb is the database a.cmdb" a.cmdb render a.cmdb --png a.cmdb
refused_apart "--svg a.cmdb is the database a.cmdb" a.cmdb render a.cmdb --svg a.cmdb
refused_apart "--groups d.cmdb is the database d.cmdb" d.cmdb export d.cmdb --groups d.cmdb
refused_apart "--groups d.cmdb is the database" d.cmdb export d.cmdb --cells - --groups d.cmdb
refused_apart "--flat e.cmdb is the database e.cmdb" e.cmdb export e.cmdb --flat e.cmdb
refused_apart "-wal file of the database a.cmdb" a.cmdb render a.cmdb --png a.cmdb-wal
refused_apart "-shm file of the database e.cmdb" e.cmdb export e.cmdb --cells e.cmdb-shm.csv \
  --flat e.cmdb-shm
# through a symlink, a hard link and another spelling of the path
ln -s g.cmdb g.png
refused_apart "--png g.png is the database g.cmdb" g.cmdb render g.cmdb --png g.png
ln h.cmdb h-link.png
refused_apart "--png h-link.png is the database h.cmdb" h.cmdb render h.cmdb --png h-link.png
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
expect_usage "--png pal.txt is --palette pal.txt" render a.cmdb --palette pal.txt --png pal.txt
expect_usage "--svg lab.txt is --labels lab.txt" render a.cmdb --labels lab.txt --svg lab.txt
cmp -s pal.txt pal.orig && cmp -s lab.txt lab.orig || fail "a palette or label file was changed"
# two outputs of one command, an array's JSON sidecar included
refused_apart "--steps x.npy and --labels x.npy are the same file" plain.cmdb \
  export plain.cmdb --labels x.npy --steps x.npy
refused_apart "--labels' JSON y.json and --groups y.json" plain.cmdb \
  export plain.cmdb --labels y.npy --groups y.json
refused_apart "--svg z.png and --png z.png" plain.cmdb render plain.cmdb --png z.png --svg z.png
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
[ $rc -eq 1 ] && grep -q "more than 87381 at once (what --mem holds" <<<"$out" \
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

[ "$fails" -eq 0 ] && echo "reliability_test: ok"
exit $((fails > 0))
