# Helpers of the shell integration tests; source after setting CM (the
# cellmap binary) and fails=0.
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }

# enter_workdir: work in a fresh directory, removed at exit, with no
# failures counted yet
enter_workdir() {
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  fails=0
  cd "$work" || exit 1
}

# expect_usage "needle" args...: exit 2 and a message containing needle
expect_usage() {
  local needle=$1; shift
  local out rc
  out=$("$CM" "$@" 2>&1 >/dev/null); rc=$?
  [ "$rc" -eq 2 ] || fail "cellmap $* exited $rc, expected 2"
  grep -qF -- "$needle" <<<"$out" || fail "cellmap $*: message '$out' lacks '$needle'"
}

# check_page_bytes FILE.cmdb: the meta value 'page_bytes' (kept at every
# commit, read by info) is the sum of the file's page blobs
check_page_bytes() {
  local kept sum
  kept=$(sqlite3 "$1" "SELECT value FROM meta WHERE key = 'page_bytes'")
  sum=$(sqlite3 "$1" 'SELECT SUM(LENGTH(image) + LENGTH(grp) + LENGTH(step)) FROM pages')
  [ -n "$kept" ] && [ "$kept" = "$sum" ] || fail "$1: meta page_bytes '$kept', its pages $sum bytes"
}

# same_rows A.cmdb B.cmdb QUERY: QUERY runs in both files and gives the
# same rows, at least one (two failed queries print nothing, and nothing
# equals nothing)
same_rows() {
  local a b
  a=$(sqlite3 "$1" "$3") || { echo "same_rows: sqlite3 $1 failed: $3" >&2; return 1; }
  b=$(sqlite3 "$2" "$3") || { echo "same_rows: sqlite3 $2 failed: $3" >&2; return 1; }
  [ -n "$a" ] || { echo "same_rows: no rows in $1: $3" >&2; return 1; }
  [ "$a" = "$b" ]
}

# serve_start FILE [options]: `cellmap serve FILE` on a free port in the
# background, its output in serve.out and serve.err; sets pid and url
serve_start() {
  "$CM" serve "$@" --port 0 > serve.out 2> serve.err &
  pid=$!
  for _ in $(seq 100); do
    url=$(sed -n 's|.* at \(http://[^ ]*\)/ .*|\1|p' serve.out)
    [ -n "$url" ] && return 0
    sleep 0.1
  done
  fail "serve $* did not start: $(cat serve.err)"
  url=http://127.0.0.1:1
}

# serve_stop: SIGTERM, and the server ends with status 0 saying so
serve_stop() {
  kill -TERM "$pid"
  wait "$pid" || fail "serve ended with status $? on SIGTERM: $(cat serve.err)"
  grep -q "terminated, stopped" serve.out || fail "serve did not say it stopped"
}
