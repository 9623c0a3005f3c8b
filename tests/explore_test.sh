#!/usr/bin/env bash
# Integration tests of `cellmap explore` (issue 5): the example sessions and
# their pictures, a session against a single solve of the union cell by
# cell, thread counts, kill and replay, malformed commands, the prompt.
# usage: explore_test.sh PATH/TO/cellmap SOURCE_DIR
set -u
CM=$1
SRC=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
. "$SRC/tests/testlib.sh"
cd "$work"

# --- the example sessions of assets/examples, pixels checked ---------------
for script in "$SRC"/assets/examples/*.explore; do
  name=$(basename "$script" .explore)
  read -r -a opts <<<"$(sed -n 's/^# options://p' "$script")"
  "$CM" explore "$name.cmdb" "$script" "${opts[@]}" > "$name.out" || fail "example $name failed"
  python3 "$SRC/tests/pngcheck.py" "$name.png" "$SRC/assets/examples/$name.check.json" ||
    fail "example $name: pixels"
done

# --- a session keeps one GL context: its renders equal fresh ones ----------
# Figures with other layers and sizes in between must not leave GL state
# behind: each render's bytes equal those of a new process drawing it.
pd_opts="--model microchaos-pd --param alpha=0.078,beta=0,P=0.007,D=0.02 --cell-size 0.5,0.08"
"$CM" explore gl.cmdb - $pd_opts > /dev/null <<'S' || fail "session with several renders"
view 100:200 -8:8
render first.png 500x300
render all.png 700x500 --layers all
pan right 20%
render panned.png 400x400 --layers basin,steps,axes
pan left 20%
render again.png 500x300
S
cmp -s first.png again.png || fail "the same view rendered twice in a session differs"
for f in all panned; do
  case $f in
    all) cmd="view 100:200 -8:8
render fresh-$f.png 700x500 --layers all" ;;
    panned) cmd="view 120:220 -8:8
render fresh-$f.png 400x400 --layers basin,steps,axes" ;;
  esac
  "$CM" explore gl.cmdb - > /dev/null <<<"$cmd" || fail "fresh render $f"
  cmp -s "$f.png" "fresh-$f.png" || fail "render $f in a session differs from a fresh process's"
done

# --- renders after pans equal a fresh process's -----------------------------
# A session keeps what its renders found following exits (exit_memo.h) and
# drops what each pan's regions may change; a new process follows every
# exit of its view. The file's last view is the session's.
{ echo "view 100:200 -8:8"; for k in 1 2 3 4 5 6; do echo "pan right 10%"; echo "render pan$k.png"; done; } |
  "$CM" explore memo.cmdb - $pd_opts > /dev/null || fail "session of pans and renders"
"$CM" explore memo.cmdb - > /dev/null <<<"render fresh-pan6.png" || fail "fresh render after pans"
cmp -s pan6.png fresh-pan6.png || fail "a render after pans differs from a fresh process's"

# --- a session equals a single solve of the union of its views ------------
# Views inside 100:300 x -16:16 with pans and zooms, then the whole box.
pd="--model microchaos-pd --param alpha=0.078,beta=0,P=0.007,D=0.02"
lattice="--cell-size 0.5,0.08 --origin 100,-16"
cat > union.explore <<'S'
view 150:200 -4:4
pan right 25%
pan right 30c
pan up 2.5
pan left 50%
zoom 0.5
goto 150 -8
zoom 4
# the whole box: every remaining strip
view 100:300 -16:16
S
for t in 1 2; do
  rm -f "union$t.cmdb"
  "$CM" explore "union$t.cmdb" union.explore $pd $lattice --threads $t > "union$t.out" ||
    fail "union session ($t threads) failed"
  "$CM" export "union$t.cmdb" --cells "union$t.csv" || fail "export union$t"
done
cmp -s union1.csv union2.csv || fail "the session's cells differ between 1 and 2 threads"
grep -q "computed" union1.out || fail "the session computed nothing"
"$CM" solve $pd --region 100:300,-16:16 --cells 400x400 --db whole.cmdb > /dev/null ||
  fail "single solve failed"
"$CM" export whole.cmdb --cells whole.csv || fail "export whole"
python3 - union1.csv whole.csv <<'PY' || fail "session and single solve differ"
import csv, sys
def cells(path):
    rows = {}
    for r in csv.DictReader(open(path)):
        rows[(int(r["ix"]), int(r["iv"]))] = (int(r["grp"]), int(r["step"]), int(r["periodic"]))
    return rows
a, b = cells(sys.argv[1]), cells(sys.argv[2])
assert len(a) == 400 * 400, len(a)
assert set(a) == set(b), "different cells"
fwd, back, bad = {}, {}, 0
for k in a:
    (ga, sa, pa), (gb, sb, pb) = a[k], b[k]
    if sa != sb or pa != pb or fwd.setdefault(ga, gb) != gb or back.setdefault(gb, ga) != ga or (ga == 0) != (gb == 0):
        bad += 1
assert bad == 0, "%d cells differ" % bad
print("union: %d cells equal, %d groups" % (len(a), len(fwd)))
PY

# --- a session killed at random moments and replayed ----------------------
cat > long.explore <<'S'
view 0:250 -40:40
pan right 20%
pan right 20%
pan up 10%
zoom 0.5
pan left 25%
pan down 100c
zoom 0.8
S
"$CM" explore ref.cmdb long.explore $pd $lattice > /dev/null || fail "reference session failed"
"$CM" export ref.cmdb --cells ref.csv --groups ref-groups.csv || fail "export ref"
for delay in 0.15 0.35 0.6 0.9 1.3; do
  "$CM" explore killed.cmdb long.explore $pd $lattice > /dev/null 2>&1 &
  pid=$!
  sleep "$delay"
  kill -9 "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null
done
"$CM" explore killed.cmdb long.explore $pd $lattice > replay.out ||
  fail "the replay after kills failed"
"$CM" export killed.cmdb --cells killed.csv --groups killed-groups.csv || fail "export killed"
check_page_bytes killed.cmdb
check_page_bytes ref.cmdb
cmp -s ref.csv killed.csv || fail "cells after kills and replay differ from an uninterrupted session"
cmp -s ref-groups.csv killed-groups.csv || fail "groups after kills and replay differ"
# a finished session replayed computes nothing
"$CM" explore killed.cmdb long.explore > again.out || fail "second replay failed"
grep -q "computed" again.out && fail "a replay of a finished session computed cells again"
# adaptive extension from the view adds the tile of the view's size where
# the most sequences escape, and only the cells the cluster lacks
printf 'view 100:150 -4:4\nextend auto 2\n' > extend.explore
"$CM" explore extend.cmdb extend.explore $pd $lattice > extend.out || fail "extend auto failed"
[ "$(grep -c '^extend auto [12]: tile .*computed 10000 cells' extend.out)" -eq 2 ] ||
  fail "extend auto: $(cat extend.out)"

# a session killed inside `extend auto N` and replayed ends as one run
# would have left it: the journal in the file records each step's tile
# before it is computed, so the replay completes the interrupted step and
# does not repeat the steps done (a replay used to extend N times more)
fine="--cell-size 0.05,0.008"
printf 'view 100:150 -4:4\nextend auto 2\npan right 10%%\nextend auto 5\nview 100:150 -4:4\n' > ext.explore
"$CM" explore ext-ref.cmdb ext.explore $pd $fine > /dev/null || fail "the reference extend session"
journal() { sqlite3 -readonly "$1" "SELECT value FROM meta WHERE key = 'note.explore.journal'" 2> /dev/null; }
journal ext-ref.cmdb | grep -q " complete$" || fail "the finished run's journal: $(journal ext-ref.cmdb)"
for stop in "line 2 step 2" "line 4 step 2" "line 4 step 4"; do
  "$CM" explore ext-kill.cmdb ext.explore $pd $fine > /dev/null 2>&1 &
  pid=$!
  for _ in $(seq 1500); do journal ext-kill.cmdb | grep -q "$stop" && break; sleep 0.01; done
  kill -9 $pid 2> /dev/null || fail "the extend session ended before '$stop'"
  wait $pid 2> /dev/null
done
journal ext-kill.cmdb | grep -q "line 4 step" || fail "not killed inside the second extend: $(journal ext-kill.cmdb)"
# killed between two lines, after the first extend line was done: the
# replay does not extend that line again (the zoom between takes ~0.3 s)
printf 'view 100:150 -4:4\nextend auto 1\nzoom 0.5\nextend auto 2\n' > ext2.explore
"$CM" explore ext2-ref.cmdb ext2.explore $pd $fine > /dev/null || fail "the reference of the second extend session"
"$CM" explore ext2-kill.cmdb ext2.explore $pd $fine > /dev/null 2>&1 &
pid=$!
for _ in $(seq 3000); do journal ext2-kill.cmdb | grep -q "line 2 done" && break; sleep 0.005; done
kill -9 $pid 2> /dev/null || fail "the second extend session ended before it was killed"
wait $pid 2> /dev/null
journal ext2-kill.cmdb | grep -q "line 2 done" || fail "not killed between the lines: $(journal ext2-kill.cmdb)"
"$CM" explore ext2-kill.cmdb ext2.explore $pd $fine > ext2-replay.out || fail "the replay after a kill between lines"
grep -q "^resuming this script's run that stopped after line 2" ext2-replay.out || fail "the replay: $(head -2 ext2-replay.out)"
same_rows ext2-kill.cmdb ext2-ref.cmdb "SELECT lo || ' ' || hi FROM regions ORDER BY lo, hi" ||
  fail "a kill between lines: the regions differ from one run's (the done extend line ran again?)"
"$CM" explore ext-kill.cmdb ext.explore $pd $fine > ext-replay.out || fail "the replay after kills in extend auto"
grep -q "^resuming this script's run that stopped in line 4 (extend auto, step [0-9]*)" ext-replay.out \
  || fail "the replay did not say it resumes: $(head -3 ext-replay.out)"
same_rows ext-kill.cmdb ext-ref.cmdb "SELECT lo || ' ' || hi FROM regions ORDER BY lo, hi" ||
  fail "the regions after kills in extend auto differ from one run's"
"$CM" export ext-ref.cmdb --labels ext-ref.npy --quiet && "$CM" export ext-kill.cmdb --labels ext-kill.npy --quiet &&
  cmp -s ext-ref.npy ext-kill.npy || fail "the cells after kills in extend auto differ from one run's"
# a run of another script, or of this one after its end, is a new run
"$CM" explore ext-ref.cmdb ext.explore $pd $fine > ext-again.out || fail "the finished script run again"
grep -q "resuming" ext-again.out && fail "a finished run was resumed"
[ "$(grep -c '^extend auto [0-9]*: tile' ext-again.out)" -eq 7 ] || fail "a new run of the script did not extend 7 times"

# --- malformed commands: line number, message, exit 1, work kept ---------
check_bad() { # check_bad 'line' 'needle'
  rm -f bad.cmdb
  printf 'view 100:150 -4:4\n%s\nview 150:200 -4:4\n' "$1" > bad.explore
  local out rc
  out=$("$CM" explore bad.cmdb bad.explore $pd $lattice 2>&1 >/dev/null); rc=$?
  [ "$rc" -eq 1 ] || fail "'$1' exited $rc, expected 1"
  grep -qF -- "bad.explore:2: " <<<"$out" || fail "'$1': no line number in '$out'"
  grep -qF -- "$2" <<<"$out" || fail "'$1': message '$out' lacks '$2'"
  "$CM" info bad.cmdb | grep -q "regions 1, cells 10000" || fail "'$1': the first view was not kept"
}
check_bad "fly away" "unknown command 'fly'"
check_bad "pan sideways 10%" "not left, right, up or down"
check_bad "pan left" "usage: pan"
check_bad "pan left -3" "not a positive amount"
check_bad "pan left 10x" "not a positive amount"
check_bad "zoom 0" "not a positive factor"
check_bad "zoom 1000" "below the lattice's resolution"
check_bad "view 5:1 0:1" "not LO:HI"
check_bad "view 0:1" "usage: view"
check_bad "view 0:1 0:1 at 3" "more than two dimensions"
# `at` on a model of three dimensions: the depth -2:2 is the cells [-2, 2)
# of dimension 3 (width 0.5); the centre of its last cell and its lower
# bound are slices of it, its upper bound and anything below it are not
d3=(--model microchaos-general --param n=1,d=2,A=1.5,B=-1,K=0.6:0.2:0.1 --cell-size 0.5,0.5,0.5
    --depth=-2:2)
for z in 1.75 -2 2 -2.01; do
  rm -f d3.cmdb
  out=$(printf 'view -2:2 -2:2 at %s\n' "$z" | "$CM" explore d3.cmdb - "${d3[@]}" 2>&1); rc=$?
  case $z in # a slice is shown at its cell's centre
    1.75|-2) [ $rc -eq 0 ] && grep -qF "view -2:2 -2:2 at ${z/#-2/-1.75}; computed 512 cells" <<<"$out" \
      || fail "at $z inside the depth: rc $rc, '$out'" ;;
    *) [ $rc -eq 1 ] && grep -qF "stdin:1: view: x = $z is outside the session's depth" <<<"$out" \
      || fail "at $z outside the depth: rc $rc, '$out'" ;;
  esac
done
# render in a session takes the figure options of `cellmap render`
printf 'view 100:200,-16:16\nrender opts.svg 800x600 --layers all --palette okabe-ito --legend 2 --min-basin 5 --by groups\n' |
  "$CM" explore opts.cmdb - $pd $lattice > /dev/null 2>&1 || fail "render with figure options"
python3 - opts.svg <<'PY' || fail "the session's figure options"
import sys, xml.etree.ElementTree as ET
texts = [t.text for t in ET.parse(sys.argv[1]).getroot().iter("{http://www.w3.org/2000/svg}text")]
groups = [t for t in texts if t.startswith("#")]
assert len(groups) == 2 and any(t.startswith("+ ") for t in texts), texts   # --legend 2
assert any("groups < 5 cells" in t for t in texts), texts                    # --min-basin 5
PY
check_bad "view 0:1,0:1,0:1" "not X0:X1,Y0:Y1"
# the command line's box form, X0:X1,Y0:Y1, is the same view
printf 'view 100:200,-16:16\nstats --json\n' | "$CM" explore comma.cmdb - $pd $lattice 2>/dev/null \
  | grep '^{' > comma.json || fail "view X0:X1,Y0:Y1"
printf 'view 100:200 -16:16\nstats --json\n' | "$CM" explore words.cmdb - $pd $lattice 2>/dev/null \
  | grep '^{' > words.json || fail "view X0:X1 Y0:Y1"
[ -s comma.json ] && python3 -c "import json,sys; a,b=(json.load(open(f)) for f in sys.argv[1:]); \
a['cluster'].pop('file_bytes'); b['cluster'].pop('file_bytes'); assert a == b and a['box'] == [[100,200],[-16,16]]" \
  comma.json words.json || fail "the two view forms differ"
check_bad "view 0:1e300 0:1" "leave the world"
check_bad "view 0:100000000 -4:4" "new cells, more than"
check_bad "goto 1" "usage: goto"
check_bad "goto x y" "not a number"
check_bad "extend manual" "usage: extend auto"
check_bad "extend auto 0" "integer in 1..1000"
check_bad "render" "usage: render"
check_bad "render out.png 0x5" "WIDTHxHEIGHT"
check_bad "stats now" "usage: stats"
check_bad 'render "out.png' "is not closed"
check_bad "export --bogus" "export failed"
# before the first view
rm -f fresh.cmdb
printf 'pan left 10%%\n' > first.explore
out=$("$CM" explore fresh.cmdb first.explore $pd $lattice 2>&1); rc=$?
[ "$rc" -eq 1 ] && grep -qF "first.explore:1: pan: there is no view yet" <<<"$out" ||
  fail "pan before view: rc $rc, '$out'"
# an export before any region (the session's own cluster is empty; the
# fuzz target found the engine reading a NULL array here)
rm -f fresh.cmdb
printf 'export --groups g0.csv\n' > empty.explore
out=$("$CM" explore fresh.cmdb empty.explore $pd $lattice 2>&1); rc=$?
[ "$rc" -eq 1 ] && grep -qF "fresh.cmdb holds no region yet" <<<"$out" && [ ! -e g0.csv ] ||
  fail "export before any region: rc $rc, '$out'"
# bad options
out=$("$CM" explore nofile.cmdb first.explore 2>&1); rc=$?
[ "$rc" -eq 2 ] && grep -qF "does not exist; a new file needs a model" <<<"$out" ||
  fail "missing file without --model: rc $rc, '$out'"
out=$("$CM" explore union1.cmdb first.explore --model microchaos-1d 2>&1); rc=$?
[ "$rc" -eq 1 ] && grep -qF "holds model microchaos-pd" <<<"$out" ||
  fail "another model for an existing file: rc $rc, '$out'"
out=$("$CM" explore x.cmdb --model microchaos-pd 2>&1); rc=$?
[ "$rc" -eq 2 ] && grep -qF -- "the cell size needs 2" <<<"$out" || fail "no --cell-size: rc $rc, '$out'"
out=$("$CM" explore x.cmdb missing.explore $pd $lattice 2>&1); rc=$?
[ "$rc" -eq 2 ] && grep -qF "cannot open the script missing.explore" <<<"$out" && [ ! -e x.cmdb ] ||
  fail "missing script: rc $rc, '$out'"

# --- stdin, a file made by solve, and export in a session ----------------
printf 'pan right 10%%\nstats\nexport --groups g.csv\nsave\nquit\npan right 10%%\n' |
  "$CM" explore whole.cmdb - > solvefile.out || fail "exploring a solve file from stdin failed"
grep -q "^pan right 10%: view 120:320 -16:16; computed 16000 cells" solvefile.out ||
  fail "pan of a solve file: $(head -1 solvefile.out)"
[ "$(grep -c '^pan' solvefile.out)" -eq 1 ] || fail "quit did not end the session"
[ -s g.csv ] || fail "export in a session wrote nothing"
"$CM" explore whole.cmdb - <<<"stats" | grep -q "^view 120:320 -16:16" ||
  fail "the saved view was not restored"

# --- the prompt goes on after an error ---------------------------------
python3 - "$CM" <<'PY' || fail "prompt session"
import os, pty, sys, time
pid, fd = pty.fork()
if pid == 0:
    os.execv(sys.argv[1], [sys.argv[1], "explore", "whole.cmdb"])
out = b""
def read_until(token, limit=20):
    global out
    end = time.time() + limit
    while token not in out and time.time() < end:
        try:
            out += os.read(fd, 4096)
        except OSError:
            break
    return token in out
assert read_until(b"explore> "), out
os.write(fd, b"pan nowhere 1\n")
assert read_until(b"line 1: pan: 'nowhere'"), out
os.write(fd, b"pan left 10%\n")
assert read_until(b"pan left 10%: view"), out
os.write(fd, b"quit\n")
_, status = os.waitpid(pid, 0)
assert os.WEXITSTATUS(status) == 0, status
PY

# --- its OpenMP threads sleep when idle, unless the user chose -------------
# (src/run_env.h) libgomp shows the spin count it runs with; the
# command runs itself again with OMP_WAIT_POLICY=passive, so the last
# display is the one its work runs under.
spin_of() { # spin_of [VAR=VALUE]: the last spin count explore's libgomp shows
  env "$@" OMP_DISPLAY_ENV=verbose "$CM" explore whole.cmdb - <<<"stats" 2>&1 >/dev/null |
    sed -n "s/^ *GOMP_SPINCOUNT = '\([0-9]*\)'.*/\1/p" | tail -1
}
[ "$(spin_of X=1)" = 0 ] || fail "explore's threads spin when idle: $(spin_of X=1)"
[ "$(spin_of OMP_WAIT_POLICY=active)" != 0 ] || fail "explore overrode OMP_WAIT_POLICY=active"
[ "$(spin_of GOMP_SPINCOUNT=1234)" = 1234 ] || fail "explore overrode GOMP_SPINCOUNT"

[ "$fails" -eq 0 ] && echo "explore_test: all passed" || { echo "explore_test: $fails failed"; exit 1; }
