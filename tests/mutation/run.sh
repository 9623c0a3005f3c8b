#!/usr/bin/env bash
# A small mutation runner: applies each mutant of a list (FILE | SED SCRIPT
# | what it breaks; fields split at the first and last " | ") to a copy of the tracked sources, one at a time, builds
# it (release) and runs the test suite (ctest, stopping at the first
# failure). A mutant is killed when a test fails, survives when all pass.
# Prints each outcome and the score.
# usage: tests/mutation/run.sh [MUTANTS_FILE] [CTEST_REGEX]
set -u
src=$(cd "$(dirname "$0")/../.." && pwd)
list=${1:-$src/tests/mutation/mutants.txt}
regex=${2:-.}
tree=$(mktemp -d)
trap 'rm -rf "$tree"' EXIT
git -C "$src" ls-files -z | (cd "$src" && xargs -0 tar cf -) | tar xf - -C "$tree"
cmake -S "$tree" -B "$tree/build" -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$tree/build" -j "$(nproc)" > /dev/null || { echo "the unmutated tree does not build"; exit 1; }
killed=0 survived=0 total=0
trim() { sed 's/^ *//; s/ *$//' <<<"$1"; }
while IFS= read -r line <&3; do
  case $line in '' | '#'*) continue ;; esac
  # FILE | SCRIPT | WHAT: split at the first and the last " | " (scripts may hold "||")
  file=$(trim "${line%% | *}")
  rest=${line#* | }
  what=$(trim "${rest##* | }")
  script=$(trim "${rest% | *}")
  cp "$tree/$file" "$tree/$file.orig"
  sed -i -e "$script" "$tree/$file"
  if cmp -s "$tree/$file" "$tree/$file.orig"; then
    echo "NOT APPLIED  $file: $what"
  elif ! cmake --build "$tree/build" -j "$(nproc)" > /dev/null 2>&1; then
    echo "NO BUILD     $file: $what"
  else
    total=$((total + 1))
    start=$(date +%s)
    if ctest --test-dir "$tree/build" -j "$(nproc)" -R "$regex" --stop-on-failure > "$tree/ctest.log" 2>&1; then
      survived=$((survived + 1))
      echo "SURVIVED     $file: $what"
    else
      killed=$((killed + 1))
      by=$(grep -m1 -o '[A-Za-z_0-9]* (Failed)\|[A-Za-z_0-9]* (SEGFAULT)\|[A-Za-z_0-9]* (Subprocess aborted)' "$tree/ctest.log")
      echo "killed       $file: $what   [$by, $(( $(date +%s) - start )) s]"
    fi
  fi
  mv "$tree/$file.orig" "$tree/$file"
  touch "$tree/$file"
done 3< "$list"
cmake --build "$tree/build" -j "$(nproc)" > /dev/null 2>&1
echo "mutation score: $killed of $total killed ($(( total ? 100 * killed / total : 0 )) %)"
