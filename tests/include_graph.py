#!/usr/bin/env python3
"""The module graph of the product's layers has no cycle. A module is a
file pair DIR/NAME.c + DIR/NAME.h; a header without a .c (a module's
private header, as cellmap/store_db.h is the store files') stands for
what it includes. Module A depends on module B when A.c's object calls a
function that B.c's object defines (nm, in the build directory), and when
A.c or A.h includes "B.h" and B.h holds code (a static inline function or
a function-like macro); a header of declarations and types alone makes no
dependency of its own (its functions' callers are found by nm). A cycle of modules (A needs B and B needs
A, through any path) is printed and fails the test, as is an include of a
layer above: the layers point one way, src -> lib -> models, render ->
cellmap. The command (src/) is a client of the library: it includes no
header of the engine, the models or the renderer but the public
cellmap/cellmap.h, only lib/'s (and its own), and stays under 6 250 lines.

usage: include_graph.py SOURCE_DIR BUILD_DIR"""
import glob, os, re, subprocess, sys

root = sys.argv[1]
build = sys.argv[2]
LAYERS = {"cellmap": 0, "models": 1, "render": 1, "lib": 2, "src": 3}
edges, problems, has_c, has_code = {}, [], set(), set()
for layer in LAYERS:
    d = os.path.join(root, layer)
    if os.path.isdir(d):
        has_c.update(layer + "/" + n[:-2] for n in os.listdir(d) if n.endswith(".c"))
for layer in LAYERS:
    d = os.path.join(root, layer)
    if not os.path.isdir(d):
        continue
    for name in sorted(os.listdir(d)):
        if not name.endswith((".c", ".h")):
            continue
        module = layer + "/" + name[:-2]
        edges.setdefault(module, set())
        text = open(os.path.join(d, name)).read()
        if name.endswith(".h") and re.search(r"^\s*static inline\b|^\s*#\s*define\s+\w+\(", text, re.M):
            has_code.add(module)
        for inc in re.findall(r'^\s*#\s*include\s+"([^"]+)"', text, re.M):
            target = inc[:-2] if inc.endswith((".h", ".c")) else inc
            top = target.split("/")[0]
            if top not in LAYERS:
                continue
            if LAYERS[top] > LAYERS[layer] or (LAYERS[top] == LAYERS[layer] and top != layer):
                problems.append("%s/%s includes %s: a layer may include only the layers below it" % (layer, name, inc))
            if target != module:
                edges[module].add(target)

# a header-only module stands for what it includes; an include makes a
# dependency only on a header with code
def resolved(m, seen=()):
    if m in has_c or m not in edges:
        return {m} if m in has_code else set()
    out = set()
    for t in edges[m]:
        if t not in seen:
            out |= resolved(t, seen + (m,))
    return out
headers_only = [m for m in edges if m not in has_c]
edges = {m: set().union(*[resolved(t) for t in ts]) - {m} if ts else set()
         for m, ts in edges.items() if m in has_c}

# calls between the modules' objects: undefined symbols of one that another defines
objects = {}
for o in glob.glob(os.path.join(build, "CMakeFiles", "*.dir", "**", "*.o"), recursive=True):
    rel = os.path.relpath(o, os.path.join(build, "CMakeFiles"))
    parts = rel.split(os.sep)[1:]          # DIR/NAME.c.o under TARGET.dir
    if len(parts) == 2 and parts[0] in LAYERS and parts[1].endswith(".c.o"):
        objects.setdefault(parts[0] + "/" + parts[1][:-4], o)
defined, undefined = {}, {}
for m, o in objects.items():
    out = subprocess.run(["nm", o], capture_output=True, text=True).stdout.splitlines()
    for line in out:
        f = line.split()
        if len(f) == 3 and f[1] in "TDBR":
            defined.setdefault(f[2], m)
        elif len(f) == 2 and f[0] == "U":
            undefined.setdefault(m, set()).add(f[1])
for m, syms in undefined.items():
    for s in syms:
        t = defined.get(s)
        if t and t != m and m in edges:
            edges[m].add(t)
if not objects:
    problems.append("no object files under %s/CMakeFiles" % build)

# the command over the library only (6 000 lines for cellmap's 23
# commands; 250 more for serve's options, signals and messages, whose
# HTTP layer is lib/serve.c; 50 more for the environment a command asks
# for by executing itself, src/run_env.c, which cannot live in a library;
# 60 more for solves on MPI ranks: the program cellmap-mpi's entry point,
# src/mpi_main.c, and the command's hand-over to it under mpirun)
SRC_MAX_LINES = 6360
src_lines = 0
for path in sorted(glob.glob(os.path.join(root, "src", "*.[ch]"))):
    text = open(path).read()
    src_lines += text.count("\n")
    for inc in re.findall(r'^\s*#\s*include\s+"([^"]+)"', text, re.M):
        if inc.split("/")[0] in ("cellmap", "models", "render") and inc != "cellmap/cellmap.h":
            problems.append("src/%s includes %s: the command reaches the engine, models and "
                            "renderer through lib/ only" % (os.path.basename(path), inc))
if src_lines >= SRC_MAX_LINES:
    problems.append("src/ has %d lines (at most %d): what is not option parsing, printing or "
                    "exit codes belongs in lib/" % (src_lines, SRC_MAX_LINES - 1))

# Tarjan's strongly connected components: each of more than one module is a cycle
index, low, on, stack, sccs, counter = {}, {}, set(), [], [], [0]
def visit(v):
    index[v] = low[v] = counter[0]
    counter[0] += 1
    stack.append(v)
    on.add(v)
    for w in sorted(edges.get(v, ())):
        if w not in index:
            visit(w)
            low[v] = min(low[v], low[w])
        elif w in on:
            low[v] = min(low[v], index[w])
    if low[v] == index[v]:
        scc = []
        while True:
            w = stack.pop()
            on.discard(w)
            scc.append(w)
            if w == v:
                break
        if len(scc) > 1:
            sccs.append(sorted(scc))
sys.setrecursionlimit(10000)
for v in sorted(edges):
    if v not in index:
        visit(v)
for scc in sccs:
    problems.append("include cycle: " + " <-> ".join(scc))
for p in problems:
    print("FAIL: " + p)
print("include graph: %d modules, %d edges, %d cycles; src/ %d lines" % (len(edges), sum(map(len, edges.values())), len(sccs), src_lines))
sys.exit(1 if problems else 0)
