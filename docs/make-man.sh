#!/bin/sh
# Makes the man page cellmap.1 from the program's own help texts, so the
# two cannot drift: `cellmap --help` gives the synopsis and the command
# list, `cellmap help COMMAND` each command's section.
# usage: docs/make-man.sh PATH/TO/cellmap OUT.1
set -eu
CM=$1
OUT=$2
tmp="$OUT.tmp-$$"
trap 'rm -f "$tmp"' EXIT

# roff: a backslash is \e; a line may not start with . or '
escape() { sed -e 's/\\/\\e/g' -e "s/^\\([.']\\)/\\\\\\&\\1/"; }

version=$("$CM" --version | sed 's/^cellmap //')
commands=$("$CM" --help | sed -n 's/^  \([a-z][a-z-]*\) .*/\1/p')
{
  printf '.TH CELLMAP 1 "" "cellmap %s" "User Commands"\n' "$version"
  printf '.SH NAME\ncellmap \\- cell mapping: basins of attraction and attractors of dynamical systems\n'
  printf '.SH SYNOPSIS\n.B cellmap\n.I COMMAND\n[\\fIOPTIONS\\fR]\n.br\n.B cellmap help\n.I COMMAND\n'
  printf '.SH DESCRIPTION\n.nf\n'
  "$CM" --help | escape
  printf '.fi\n.SH COMMANDS\n'
  for c in $commands; do
    printf '.SS %s\n.nf\n' "$c"
    "$CM" help "$c" | escape
    printf '.fi\n'
  done
  printf '.SH EXIT STATUS\n0 success, 1 failure, 2 bad usage, 130 stopped by Ctrl-C.\n'
  printf '.SH FILES\n.I docs/cellmap.schema.json\nin the source tree: the schema of every command'"'"'s --json output.\n'
  printf '.SH SEE ALSO\nThe README and docs/ of the cellmap sources: models.md, format.md, gallery.md.\n'
} > "$tmp"
mv "$tmp" "$OUT"
trap - EXIT
