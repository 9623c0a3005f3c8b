#!/usr/bin/env bash
# The shell tests may not compare two command substitutions directly
# ([ "$(a)" = "$(b)" ], diff <(a) <(b)): when both commands fail, both
# print nothing and the comparison passes. Capture each with its exit
# status checked (x=$(a) && y=$(b) && [ -n "$x" ] && [ "$x" = "$y" ]), or
# use testlib.sh's same_rows for two databases.
# usage: suite_lint.sh
HERE=$(cd "$(dirname "$0")" && pwd)
bad=$(grep -nE '"\$\([^(].*\)" *!?= *"\$\([^(]|(diff|cmp)( -[a-z]+)* <\(.*<\(' $(ls "$HERE"/*.sh | grep -v /suite_lint.sh))
if [ -n "$bad" ]; then
  echo "FAIL: comparisons of two command substitutions (both empty when both fail):" >&2
  echo "$bad" >&2
  exit 1
fi
echo "suite_lint: ok"
