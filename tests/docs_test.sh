#!/usr/bin/env bash
# What the documentation promises: the README's quick start and glossary
# followed to the letter on a fresh directory, every documented spelling of
# the one vocabulary, the man page against the help texts, the bash
# completion, and what `cmake --install` installs.
# usage: docs_test.sh PATH/TO/cellmap SOURCE_DIR BUILD_DIR
set -u
CM=$(realpath "$1")
SRC=$(realpath "$2")
BUILD=$(realpath "$3")
HERE=$(cd "$(dirname "$0")" && pwd)
. "$HERE/testlib.sh"
enter_workdir

# --- the newcomer's path: the README's two commands, quick start, glossary ---
# The README's first command runs as written (copied from the README now),
# in a fresh copy of the source tree (the files git tracks or would track,
# no build), with a scratch HOME and PATH reset to the system's default.
# Its install goes to a staging root (DESTDIR, cmake's own mechanism) so
# that the test leaves the machine as it was; PATH is the default with
# that root's /usr/local/bin in front, so `cellmap` is found exactly where
# the install put it and nowhere in the build tree.
newcomer=$(python3 - "$SRC/README.md" "$SRC/.ci/run" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
head = text[text.index("## A fresh machine in two commands"):]
head = head[:head.index("\n## ", 1)]
sh = [b for lang, b in re.findall(r"```(\w+)\n(.*?)```", head, re.S) if lang == "sh"]
assert len(sh) == 2 and all(b.count("\n") == 1 for b in sh), "the README opens with two one-line commands: %r" % sh
ci = [l.strip() for l in open(sys.argv[2]) if l.strip() and not l.lstrip().startswith(("#", "set ", "cd "))]
assert ci == [sh[1].strip()], ".ci/run calls %r, the README's second command is %r" % (ci, sh[1].strip())
print(sh[0].strip())
PY
) || fail "the README's two commands"
mkdir fresh home stage
python3 - "$SRC" fresh <<'PY' || fail "copy of the source tree"
import os, shutil, subprocess, sys
src, dst = sys.argv[1], sys.argv[2]
try:
    names = subprocess.run(["git", "-C", src, "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                           capture_output=True, check=True).stdout.decode().split("\0")
except (OSError, subprocess.CalledProcessError):   # not a git checkout: the tree without builds
    names = [os.path.relpath(os.path.join(d, f), src) for d, ds, fs in os.walk(src)
             for f in fs if not os.path.relpath(d, src).startswith(("build", ".git"))]
for n in filter(None, names):
    s = os.path.join(src, n)
    if os.path.lexists(s):
        os.makedirs(os.path.join(dst, os.path.dirname(n)), exist_ok=True)
        shutil.copy2(s, os.path.join(dst, n), follow_symlinks=False)
PY
[ "$(id -u)" -eq 0 ] && key=ENV_SUPATH || key=ENV_PATH
syspath=$(sed -n "s/^$key[[:space:]]*PATH=//p" /etc/login.defs 2>/dev/null)
[ -n "$syspath" ] || syspath=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin
newpath="$work/stage/usr/local/bin:$syspath"
( cd fresh && env -i HOME="$work/home" PATH="$newpath" DESTDIR="$work/stage" \
    bash -c "$newcomer" > ../first.out 2> ../first.err ) || fail "the README's first command failed: $(tail -5 first.err)"
[ -x stage/usr/local/bin/cellmap ] || fail "the README's first command installed no /usr/local/bin/cellmap"
# the README shows basin.png as assets/examples/quick-start.png, which the
# gallery script makes with the same solve
cmp -s fresh/basin.png "$SRC/assets/examples/quick-start.png" \
  || fail "the README's first command made no basin.png, or not the figure the README shows"
[ "$(sqlite3 fresh/basin.cmdb 'SELECT SUM(cells) FROM regions' 2>&1)" = 1000000 ] \
  || fail "the README's first command made no basin.cmdb of 1000000 cells"
# What it printed after the build's lines is the README's block, times
# aside; then the quick start's and the glossary's commands run in the
# same tree with the same PATH.
( cd fresh && env -i HOME="$work/home" PATH="$newpath" python3 - "$SRC/README.md" ../first.out <<'PY' ) || fail "the README's quick start"
import re, subprocess, sys
text = open(sys.argv[1]).read()
head = text[text.index("## A fresh machine in two commands"):]
head = head[:head.index("\n## ", 1)]
promised = re.findall(r"```text\n(.*?)```", head, re.S)[0]
times = lambda s: re.sub(r"\d+\.\d+ (s|ns/cell)", "T", s)
lines = open(sys.argv[2]).read().splitlines()
tail = "\n".join(lines[-len(promised.splitlines()):]) + "\n"
if times(tail) != times(promised):
    for a, b in zip(times(tail).splitlines(), times(promised).splitlines()):
        if a != b:
            print("printed:  " + a + "\npromised: " + b)
    sys.exit(1)
first = re.findall(r"```sh\n(.*?)```", head, re.S)[0]
quick = text[text.index("## Quick start"):text.index("## One vocabulary")]
blocks = re.findall(r"```(\w+)\n(.*?)```", quick, re.S)
assert blocks[0][0] == "sh" and first.strip().endswith("&& " + blocks[0][1].strip()), \
    "the quick start's command %r is not the first command's last step" % blocks[0][1]
def run(cmd):
    return subprocess.run(cmd, shell=True, capture_output=True, text=True, check=True).stdout
for lang, cmd in blocks[1:]:          # the render and glossary commands
    if lang == "sh" and not cmd.startswith("cellmap serve"):  # serve runs until Ctrl-C:
        run(cmd)                                               # serve_test, browser_test
m = re.search(r"```sh\n\s*(sqlite3 basin\.cmdb .*?)\n\s*```\s*\n\s*prints `(\d+)`", text)
assert m, "the glossary's count of single-cell groups"
assert run(m.group(1)).strip() == m.group(2), run(m.group(1))
PY
[ -s fresh/fig.png ] || fail "the quick start made no fig.png"
# The README's Python path on that fresh tree, to the letter: the install
# the first command does (prefix /usr/local), the README's pip command,
# then its Python example with plain python3 and no environment variable.
# In a private mount namespace whose /usr/local is an empty tmpfs, so that
# the machine's is left as it was.
if [ "$(id -u)" = 0 ]; then ns=(unshare -m); else ns=(unshare -rm); fi
if "${ns[@]}" true 2> /dev/null; then
  python3 - "$SRC/README.md" > python.sh <<'PY' || fail "the README's Python install and example"
import re, sys
text = open(sys.argv[1]).read()
part = text[text.index("## From C and Python"):]
part = part[:part.index("\n## ", 1)]
pip = [b.strip() for lang, b in re.findall(r"```(\w+)\n(.*?)```", part, re.S)
       if lang == "sh" and "pip install" in b]
example = [b for lang, b in re.findall(r"```(\w+)\n(.*?)```", part, re.S) if lang == "python"]
assert len(pip) == 1 and len(example) == 1, (pip, len(example))
open("readme_example.py", "w").write(example[0])
print("set -e\nmount -t tmpfs tmpfs /usr/local\ncd fresh\ncmake --install build > ../py-install.log\n"
      + pip[0] + " > ../pip.log 2>&1\ncd ../pyrun\nexec python3 ../readme_example.py")
PY
  mkdir pyrun && cp fresh/basin.cmdb pyrun/
  "${ns[@]}" env -i HOME="$work/home" PATH="$syspath" bash python.sh > python.out 2>&1 \
    || fail "the README's Python install and example, from a fresh tree: $(tail -5 python.out; tail -5 pip.log 2>/dev/null)"
  [ -s pyrun/duffing.png ] && [ -s pyrun/pd-view.png ] && [ -s pyrun/pd.cmdb ] \
    || fail "the README's Python example wrote no duffing.png, pd-view.png or pd.cmdb"
else
  echo "docs_test: no mount namespace here (unshare -m): the README's Python path is not run"
fi
cp fresh/basin.cmdb . 2> /dev/null || "$CM" solve --db basin.cmdb --quiet   # (for what follows)
# from here on, the cellmap under test (the completion asks it too)
mkdir bin && ln -s "$CM" bin/cellmap
export PATH="$work/bin:$PATH"

# --- every documented spelling of the vocabulary works ------------------------
spell() { "$CM" "$@" > /dev/null 2>&1 || fail "documented spelling: cellmap $*"; }
spell solve --model microchaos-pd --param alpha=0.078 --param beta=0,P=0.007,D=0.02 --region 0:500,-40:40 --cells 40x20
spell solve --model microchaos-general --param n=1,d=2,A=1.5,B=-1,K=0.6:0.2:0.1 --region=-6:6,-6:6,-6:6 --cells 8x8x8
spell sweep --vary P=0.006,0.007 --cells 40x20
spell sweep --vary P=0.006:0.008:2 --cells 40x20 --csv -
spell lyapunov --param S0=0.4 --grid Omega=0.49:0.51:2,S=0.3:0.5:2 --periods 5 --csv -
spell lyapunov --param S0=0.4 --grid Omega=0.49,0.5,0.51,S=0.3,0.4 --periods 5 --csv -
spell bifurcation --param S0=0.4,Omega=0.5 --sweep S=0.32,0.4 --transient 5 --record 2 --csv -
spell bifurcation --param S0=0.4,Omega=0.5 --sweep S=0.28:0.44:2 --transient 5 --record 2 --runs-csv -
spell simulate --param S=0.4,S0=0.4,Omega=0.5 --periods 2 --csv -
spell orbit --from 10,0 --steps 3
spell orbit --from 10,0 --steps 3 --csv -
spell fixed-points --range 0:2 --csv -
spell export basin.cmdb --groups - --quiet
spell render basin.cmdb --png - --view 100:200,-10:10
spell escape --param b=1.3 --I0 0.25 --sweep a=1.3:1.5:2 --cells 1000 --ensemble 1000 --csv -
spell stability --param alpha=0.8,beta=0.3,P=0.9,D=0.4 --P 0.65:1.5:20 --csv -
spell partition --param a=1.3,b=0.66 --csv -
spell horseshoe --param alpha=0.77,beta=0.02,D=0.83 --m 3:3 --sweep P=0.65:0.72:5 --periods 8 --csv -
for c in solve sweep explore render info export measure models orbit fixed-points equilibria periodic exponents lyapunov simulate bifurcation continue amplitude escape stability horseshoe partition; do
  spell help $c
  spell $c -h
done
printf 'view 100:200,-10:10\nview 100:200 -10:10\nstats --json\n' | "$CM" explore basin.cmdb - > /dev/null \
  || fail "explore's two box spellings"
[ "$("$CM" orbit --from 10,0 --steps 1 --csv - | head -1)" = "j,x,v" ] || fail "state names in orbit's CSV"

# --- the man page is the help texts ------------------------------------------
[ -s "$BUILD/cellmap.1" ] || fail "the build made no cellmap.1"
"$SRC/docs/make-man.sh" "$CM" now.1 || fail "make-man.sh"
cmp -s now.1 "$BUILD/cellmap.1" || fail "build/cellmap.1 is not what the help texts give now"
python3 - now.1 "$CM" <<'PY' || fail "the man page and --help disagree"
import re, subprocess, sys
man = open(sys.argv[1]).read()
unescape = lambda s: re.sub(r"^\\&", "", s, flags=re.M).replace("\\e", "\\")
commands = re.findall(r"^  ([a-z][a-z-]*) ", subprocess.run([sys.argv[2], "--help"], capture_output=True, text=True).stdout, re.M)
assert len(commands) == 23, commands
for c in commands:
    section = re.search(r"^\.SS " + re.escape(c) + r"\n\.nf\n(.*?)^\.fi$", man, re.S | re.M)
    assert section, c
    helptext = subprocess.run([sys.argv[2], "help", c], capture_output=True, text=True).stdout
    assert unescape(section.group(1)) == helptext, c
PY
MANWIDTH=100 man -l now.1 > man.txt 2> man.err || fail "man cannot show the page: $(cat man.err)"
grep -q "cellmap help COMMAND" man.txt || fail "man page text"

# --- bash completion -----------------------------------------------------------
bash -c '
  source "$1"
  t() { COMP_WORDS=("$@"); COMP_CWORD=$(($# - 1)); _cellmap; echo "${COMPREPLY[*]}"; }
  [ "$(t cellmap so)" = solve ] || exit 1
  [ "$(t cellmap solve --re)" = "--region --resume" ] || exit 2
  [ "$(t cellmap solve --model microchaos-pd-f)" = microchaos-pd-friction ] || exit 3
  [ "$(t cellmap help fi)" = fixed-points ] || exit 4
  [ "$(t cellmap lyapunov --qu)" = --quiet ] || exit 5
' _ "$SRC/assets/completion/cellmap.bash" || fail "bash completion (case $?)"

# --- cmake --install ------------------------------------------------------------
cmake --install "$BUILD" --prefix "$work/prefix" > install.log 2>&1 || fail "cmake --install: $(cat install.log)"
for f in bin/cellmap share/man/man1/cellmap.1 share/bash-completion/completions/cellmap; do
  [ -s "$work/prefix/$f" ] || fail "cmake --install did not install $f"
done
"$work/prefix/bin/cellmap" --version | grep -q "^cellmap " || fail "the installed cellmap does not run"
# under mpirun, the installed cellmap runs the cellmap-mpi installed beside it
[ ! -e "$BUILD/cellmap-mpi" ] || [ -s "$work/prefix/bin/cellmap-mpi" ] ||
  fail "cmake --install did not install cellmap-mpi beside cellmap"

[ $fails -eq 0 ] && echo "docs tests passed"
exit $fails
