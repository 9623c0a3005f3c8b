#!/usr/bin/env bash
# Regression tests of the hardening issue: every defect an attacker's
# campaign found (damaged files, overflowing arguments, outputs that
# clobbered devices and symlinks, files modified although refused, lost
# stdout, unclear messages, a second writer) reproduced and checked.
# Under the sanitizer build an overflow also fails the test by aborting.
# usage: hardening_test.sh PATH/TO/cellmap PATH/TO/libsync_counter.so
set -u
CM=$1
SYNC_COUNTER=$2
HERE=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
. "$HERE/testlib.sh"
cd "$work"

# expect_damaged FILE "needle" args...: exit 1, "FILE is damaged: ...needle",
# and FILE byte-identical afterwards
expect_damaged() {
  local file=$1 needle=$2; shift 2
  local sum out rc
  sum=$(sha256sum < "$file")
  out=$("$CM" "$@" 2>&1 >/dev/null); rc=$?
  [ "$rc" -eq 1 ] || fail "cellmap $* exited $rc, expected 1 ($out)"
  grep -qF -- "$file is damaged" <<<"$out" || fail "cellmap $*: '$out' does not say $file is damaged"
  grep -qF -- "$needle" <<<"$out" || fail "cellmap $*: '$out' lacks '$needle'"
  [ "$(sha256sum < "$file")" = "$sum" ] || fail "cellmap $* modified $file"
}

# every command that reads a file, and the two that extend one
refuse_everywhere() {
  local file=$1 needle=$2
  expect_damaged "$file" "$needle" info "$file"
  expect_damaged "$file" "$needle" export "$file" --cells c.csv
  expect_damaged "$file" "$needle" render "$file" --png r.png
  expect_damaged "$file" "$needle" export "$file" --cells c.csv --mem 1M
  expect_damaged "$file" "$needle" solve $small --db "$file" --resume
  printf 'view 0:50 -40:40\nstats\nrender e.png 200x200\n' > session.txt
  expect_damaged "$file" "$needle" explore "$file" session.txt --mem 1M
}

small="--cells 100x80 --split 2x2 --threads 2"
"$CM" solve $small --db good.cmdb > /dev/null || fail "solve --db good.cmdb"

# --- memory safety ------------------------------------------------------------
# sweep --vary with more values than a state has dimensions overflowed a
# stack array of the list parser
"$CM" sweep --vary alpha=0.070,0.071,0.072,0.073,0.074,0.075,0.076 --cells 10x10 > sweep.out \
  || fail "sweep with 7 values"
[ "$(grep -c '^alpha = .* attractor(s), ' sweep.out)" = 7 ] || fail "sweep with 7 values: $(cat sweep.out)"
expect_usage "--vary" sweep --vary alpha=0.07,0.071, --cells 10x10
expect_usage "--cells" solve --cells 10x10x10x10x10x10x10x10
# a pan amount longer than explore's buffer, ending in % (found by fuzz_session)
long_amount="$(printf '1%.0s' $(seq 1 80))%"
"$CM" explore pan.cmdb - --model microchaos-pd --cell-size 5,1 > /dev/null 2> err.txt <<EOS
view 0:100 -20:20
pan right $long_amount
EOS
[ $? -eq 1 ] && grep -q "is too long" err.txt || fail "a long pan amount: $(cat err.txt)"
# export --window 0 read before a stack array
expect_usage "the window '0'" export good.cmdb --flat f.sqlite --window 0
[ -e f.sqlite ] && fail "export --window 0 left f.sqlite"
# cells naming groups that do not exist
cp good.cmdb nogroups.cmdb
sqlite3 nogroups.cmdb "DELETE FROM attractors WHERE id > 10"
refuse_everywhere nogroups.cmdb "groups"
cp good.cmdb nogroups2.cmdb # consistent metadata, cells and nodes still name the groups
sqlite3 nogroups2.cmdb "DELETE FROM attractors WHERE id > 10; DELETE FROM basins WHERE grp > 10;
  UPDATE meta SET value = '10' WHERE key = 'groups'"
for args in "export nogroups2.cmdb --cells c.csv" "render nogroups2.cmdb --png r.png"; do
  expect_damaged nogroups2.cmdb "is damaged" $args
done
printf 'view 0:50 -40:40\nstats\n' > stats.txt
expect_damaged nogroups2.cmdb "is damaged" explore nogroups2.cmdb stats.txt
# pages that decode but belong to another region
cp good.cmdb swapped.cmdb
sqlite3 swapped.cmdb "UPDATE pages SET region = -region WHERE region IN (1, 2);
  UPDATE pages SET region = 2 WHERE region = -1; UPDATE pages SET region = 1 WHERE region = -2"
for args in "export swapped.cmdb --cells c.csv" "render swapped.cmdb --png r.png"; do
  expect_damaged swapped.cmdb "region" $args
done
expect_damaged swapped.cmdb "region" explore swapped.cmdb stats.txt --mem 1M
# a page whose cells were changed (it still decodes: written by SQLite's zeroblob-free path)
cp good.cmdb steps.cmdb
sqlite3 steps.cmdb "UPDATE pages SET step = (SELECT step FROM pages WHERE region = 2) WHERE region = 1"
expect_damaged steps.cmdb "region 1" export steps.cmdb --cells c.csv
# a page row that holds more cells than a page may
cp good.cmdb bigpage.cmdb
sqlite3 bigpage.cmdb "UPDATE pages SET cells = 70000 WHERE region = 1"
expect_damaged bigpage.cmdb "region 1" export bigpage.cmdb --cells c.csv

# explore's notes: a view or depth out of the world
"$CM" explore notes.cmdb - --model microchaos-pd --cell-size 5,1 > /dev/null <<< "view 0:50 -10:10" \
  || fail "explore notes.cmdb"
for view in "0:1e300 -10:10" "0:50" "nan:1 0:1" "5:1 0:1"; do
  cp notes.cmdb view.cmdb
  sqlite3 view.cmdb "UPDATE meta SET value = '$view' WHERE key = 'note.explore.view'"
  expect_damaged view.cmdb "view note" explore view.cmdb stats.txt
done

# --- undefined behaviour: values out of range in a file or an argument -------
for bound in "lo|[-9223372036854775808,0]" "lo|[1e300,0]" "lo|[-1e300,0]" "lo|[0.5,0]" \
             "lo|[NaN,0]" "hi|[9223372036854775807,40]" "hi|[-1e300,40]" "hi|[1e300,40]"; do
  cp good.cmdb bounds.cmdb
  sqlite3 bounds.cmdb "UPDATE regions SET ${bound%|*} = '${bound#*|}' WHERE id = 1"
  refuse_everywhere bounds.cmdb "region 1"
done
for change in "lattice_origin|[1e308,0]" "lattice_width|[1e-320,1]" "lattice_width|[0,1]" \
              "lattice_width|[-1,1]" "lattice_origin|[nan,0]"; do
  cp good.cmdb lattice.cmdb
  sqlite3 lattice.cmdb "UPDATE meta SET value = '${change#*|}' WHERE key = '${change%|*}'"
  refuse_everywhere lattice.cmdb "lattice"
done
expect_usage "--range" fixed-points --range -9223372036854775807:9223372036854775807
expect_usage "--range" fixed-points --range -1125899906842624:1125899906842624

# --- outputs never clobber what is not theirs ----------------------------------
# (a device node of the test's own, like /dev/full, so that a defect that
# replaces it cannot damage the machine's)
if [ "$(id -u)" = 0 ] && mknod full c 1 7 2> /dev/null; then
  "$CM" export good.cmdb --groups full 2> err.txt; rc=$?
  [ $rc -eq 1 ] && grep -q "No space left on device" err.txt || fail "--groups full: $rc $(cat err.txt)"
  [ -c full ] || fail "the device node is no longer a device"
  ln -s full full-link.csv
  "$CM" export good.cmdb --groups full-link.csv 2> /dev/null && fail "--groups to a link to a full device"
  [ -c full ] && [ -L full-link.csv ] || fail "the link or the device it leads to was replaced"
  for cmd in "orbit --model microchaos-1d --param a=3.5,b=2.8 --from 0.5 --steps 2" \
             "fixed-points --model microchaos-1d --param a=3.5,b=2.8" "info good.cmdb" \
             "solve --cells 20x20 --json" "models"; do
    "$CM" $cmd > full 2> err.txt; rc=$?
    [ $rc -eq 1 ] && grep -q "standard output: No space left" err.txt \
      || fail "$cmd > full exited $rc: $(cat err.txt)"
  done
fi
echo precious > target.csv
ln -s target.csv link.csv
"$CM" export good.cmdb --groups link.csv || fail "export to a symlink"
[ -L link.csv ] || fail "the symlink was replaced"
head -1 target.csv | grep -q "^id,period" || fail "the symlink's target was not written"
mkfifo fifo.csv
timeout 20 cat fifo.csv > from-fifo.csv & # (a replaced FIFO would never be written)
reader=$!
"$CM" export good.cmdb --groups fifo.csv || fail "export to a FIFO"
wait $reader
[ -p fifo.csv ] || fail "the FIFO was replaced"
cmp -s from-fifo.csv target.csv || fail "the FIFO did not get the groups"
"$CM" export good.cmdb --groups /dev/stdout > via-stdout.csv || fail "--groups /dev/stdout"
cmp -s via-stdout.csv target.csv || fail "--groups /dev/stdout differs"
"$CM" export good.cmdb --groups - > dash.csv || fail "--groups -"
cmp -s dash.csv target.csv || fail "--groups - differs"
[ -e ./- ] && fail "a file named - was written"
"$CM" solve --cells 40x40 --png - > dash.png 2> summary.txt || fail "solve --png -"
[ "$(head -c 4 dash.png | od -An -c | tr -d ' ')" = "211PNG" ] || fail "--png - is not a PNG"
grep -q "^model microchaos-pd" summary.txt || fail "solve --png -: the summary is not on stderr"
"$CM" export good.cmdb --flat - > flat.sqlite || fail "--flat -"
[ "$(sqlite3 flat.sqlite 'SELECT COUNT(*) FROM cells')" = 8000 ] || fail "--flat - cells"
expect_usage "only one of" export good.cmdb --groups - --cells -
expect_usage "both write to stdout" solve --png - --json
mkdir adir
for args in "export good.cmdb --groups adir" "solve --cells 20x20 --png adir" \
            "solve --cells 20x20 --db adir"; do
  "$CM" $args > /dev/null 2> err.txt && fail "$args succeeded"
  grep -q "adir is a directory" err.txt || fail "$args: $(cat err.txt)"
done
if [ -c full ]; then
  "$CM" solve --cells 20x20 --db full > /dev/null 2> err.txt && fail "--db on a device"
  grep -q "not a regular file" err.txt || fail "--db on a device: $(cat err.txt)"
  [ -c full ] || fail "--db replaced a device"
fi
# the image is checked before anything is computed
"$CM" solve --cells 2000x2000 --png small.png --size 40x40 --layers all > /dev/null 2> err.txt \
  && fail "a 40x40 figure with every layer"
grep -q "leaves no room" err.txt || fail "image size message: $(cat err.txt)"
"$CM" solve --cells 10x10 --png tiny.png > /dev/null || fail "a 10x10 bare image"

# --- refused and replaced files ----------------------------------------------------
# solve --db over an older cluster: the old one stays until the new one is complete
cp good.cmdb old.cmdb
sum=$(sha256sum < old.cmdb)
"$CM" solve --cells 3000x3000 --split 30x30 --threads 1 --db old.cmdb > /dev/null 2>&1 &
solver=$!
# killed once it writes the new cluster beside the old one
for _ in $(seq 200); do compgen -G "old.cmdb.tmp-*" > /dev/null && break; sleep 0.02; done
kill -9 $solver 2> /dev/null || fail "the solve over old.cmdb ended before it could be interrupted"
wait $solver 2> /dev/null
[ "$(sha256sum < old.cmdb)" = "$sum" ] || fail "an interrupted solve --db changed the older cluster"
rm -f old.cmdb.tmp-*
"$CM" solve --cells 60x60 --db old.cmdb > /dev/null || fail "solve --db over an older cluster"
[ "$(sqlite3 old.cmdb 'SELECT SUM(cells) FROM regions')" = 3600 ] || fail "the new cluster is not in place"
ls | grep -q 'tmp-' && fail "temporary files left behind"

# --- durability: commits are synced to the disk (the WAL is synced: SQLite's
# synchronous is not OFF)
# (ASan wants to be first among the libraries; the counter only wraps two calls)
SYNC_COUNT_FILE=$work/syncs.txt LD_PRELOAD=$SYNC_COUNTER \
ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}verify_asan_link_order=0 \
  "$CM" solve $small --db synced.cmdb > /dev/null || fail "solve under the sync counter"
[ "$(cat syncs.txt 2> /dev/null || echo 0)" -gt 0 ] || fail "solve --db never synced its write-ahead log"

# --- messages ------------------------------------------------------------------------
cp good.cmdb nometa.cmdb
sqlite3 nometa.cmdb "DELETE FROM meta WHERE key = 'model'"
expect_damaged nometa.cmdb "its meta table has no 'model'" info nometa.cmdb
# a second writer is refused at once; readers go on
mkfifo hold
"$CM" explore good.cmdb hold > holder.txt 2>&1 &
holder=$!
exec 3> hold
echo "view 0:50 -40:40" >&3
# until the session answered, so holds its lock (a loaded machine may take a while)
for _ in $(seq 200); do [ -s holder.txt ] && break; sleep 0.05; done
"$CM" solve $small --db good.cmdb --resume > /dev/null 2> err.txt; rc=$?
[ $rc -eq 1 ] && grep -q "good.cmdb is in use by another cellmap process" err.txt \
  || fail "a second writer: $rc $(cat err.txt)"
"$CM" info good.cmdb > /dev/null || fail "info while another process writes"
exec 3>&-
wait $holder || fail "the first writer failed"

# The GL stack (OSMesa, else EGL) is loaded only to draw: commands that draw
# nothing run without either, and one that would draw stops before its
# work, naming the libraries
ldd "$CM" | grep -qE "OSMesa|libEGL" && fail "cellmap links OSMesa or EGL at start"
export CELLMAP_OSMESA=$work/no-such-libOSMesa.so CELLMAP_EGL=$work/no-such-libEGL.so
"$CM" solve --cells 40x40 > out.txt 2> err.txt || fail "solve without a PNG needs OSMesa: $(cat err.txt)"
"$CM" info good.cmdb > /dev/null 2> err.txt || fail "info needs OSMesa: $(cat err.txt)"
"$CM" export good.cmdb --cells cells.csv 2> err.txt || fail "export needs OSMesa: $(cat err.txt)"
# a figure without lines needs no GL at all
"$CM" render good.cmdb --png g.png --layers basin,attractors > /dev/null 2> err.txt \
  || fail "a bare figure needs OSMesa: $(cat err.txt)"
[ -s g.png ] || fail "the bare figure without OSMesa was not written"
rm -f g.png
for args in "solve --cells 40x40 --png g.png" "render good.cmdb --png g.png --layers basin,overlays" \
            "lyapunov --grid S=0:0.5:2,Omega=0.5:1:2 --periods 5 --png g.png" \
            "simulate --model friction-oscillator --from 0.1,0 --periods 5 --png g.png"; do
  $CM $args > out.txt 2> err.txt; rc=$?
  [ $rc -eq 1 ] && grep -q "cannot load a GL library.*no-such-libOSMesa.*no-such-libEGL.*libosmesa6" err.txt \
    || fail "cellmap $args without OSMesa: exit $rc, $(cat err.txt)"
  [ -s out.txt ] && fail "cellmap $args worked before finding OSMesa missing: $(head -2 out.txt)"
  [ -e g.png ] && fail "cellmap $args left g.png"
done
unset CELLMAP_OSMESA CELLMAP_EGL

[ $fails -eq 0 ] && echo "hardening_test: all passed"
exit $((fails > 0))
