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
