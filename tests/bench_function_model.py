"""A map given as a Python function against the same map as a compiled
plugin: the Henon map (examples/plugin/henon.c) solved both ways must agree
cell for cell (labels, steps, attractor labels); prints each one's cost in
microseconds per cell.
usage: bench_function_model.py LIBHENON.so [CELLS_A_SIDE] (default 200)"""
import sys
import time

import numpy as np

import cellmap

A, B = 1.4, 0.3


def henon(x):
    y0 = 1 - A * x[0] * x[0] + x[1]
    return None if not abs(y0) < 1e100 else [y0, B * x[0]]


n = int(sys.argv[2]) if len(sys.argv) > 2 else 200
region, cells = [(-1.5, 1.5), (-0.45, 0.45)], (n, n)
plugin = cellmap.System("henon", plugins=[sys.argv[1]], a=A, b=B)
function = cellmap.System.from_function("henon", 2, henon)
assert function.step([0.1, 0.2]) == plugin.step([0.1, 0.2])
timing = {}
for name, system, threads in (("plugin", plugin, 1), ("function", function, 1)):
    t0 = time.perf_counter()
    timing[name] = cellmap.solve(system, region=region, cells=cells, threads=threads)
    timing[name + "_s"] = time.perf_counter() - t0
p, f = timing["plugin"], timing["function"]
for what in ("labels", "steps", "attractor_labels"):
    assert (getattr(p, what) == getattr(f, what)).all(), "%s differ" % what
assert len(p.attractors) == len(f.attractors) >= 1
print("henon %dx%d: plugin %.3f us/cell, Python function %.3f us/cell (%.0fx); "
      "labels, steps and attractor labels equal cell for cell"
      % (n, n, 1e6 * timing["plugin_s"] / (n * n), 1e6 * timing["function_s"] / (n * n),
         timing["function_s"] / timing["plugin_s"]))
