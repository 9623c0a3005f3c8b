"""The analysis commands done from Python (tests/workstation_test.sh runs
the same settings through the command and through tests/workstation.c and
compares the files byte for byte): PREFIX_NAME.csv and .png for stability,
partition, amplitude, horseshoe, escape, simulate, bifurcation (and its
runs), lyapunov, sweep, continue (and its events), exponents, the time
series of chip-bue (and its spectrum), the exponent of a series
(embedding), equilibria and periodic (their tables), and the measures of
a file (their table). The tables the
functions return are checked against the files they read them from.
usage: workstation_analysis.py PREFIX"""
import os
import sys

import numpy as np

import cellmap
from cellmap import analysis as an

p = sys.argv[1] + "_"


def out(name, png=True):
    return dict(csv=p + name + ".csv", png=p + name + ".png" if png else None)


def rows(table, path):
    """the table has a row per data line of its CSV, and its header's columns"""
    with open(path, encoding="utf-8") as f:
        lines = f.read().splitlines()
    assert list(table.dtype.names) == lines[0].split(","), (path, table.dtype.names, lines[0])
    assert len(table) == len(lines) - 1 and len(table) > 0, (path, len(table), len(lines))
    return table


rows(an.stability(P=(0.007, 0.02, 50), alpha=(0.1, 1, 20), **out("stability")),
     p + "stability.csv")
rows(an.partition(params="a=1.3,b=0.66", **out("partition")), p + "partition.csv")
amp = rows(an.amplitude((0.2, 2, 20), periods=50, **out("amplitude")), p + "amplitude.csv")
assert np.allclose(amp["Omega"], 0.2 + (np.arange(20) + 0.5) * 0.09), amp["Omega"]
rows(an.horseshoe(m=(1, 3), periods=6, **out("horseshoe")), p + "horseshoe.csv")
rows(an.escape(cells=1000, ensemble=1000, **out("escape")), p + "escape.csv")
rows(an.simulate((1, 0), periods=5, **out("simulate")), p + "simulate.csv")
pts, runs = an.bifurcation(("S", 0.1, 0.3, 4), runs=2, transient=20, record=5,
                           runs_csv=p + "bifurcation_runs.csv", **out("bifurcation"))
rows(pts, p + "bifurcation.csv")
assert len(rows(runs, p + "bifurcation_runs.csv")) == 8
rows(an.lyapunov(("Omega", 0.4, 0.6, 3), ("S", 0.1, 0.2, 3), periods=50, **out("lyapunov")),
     p + "lyapunov.csv")
counts, shares = an.sweep("P", [0.006, 0.007], region=[(0, 100), (-10, 10)], cells=(50, 50),
                          fractions_csv=p + "sweep_fractions.csv", keep=p + "kept",
                          **out("sweep"))
rows(counts, p + "sweep.csv")
rows(shares, p + "sweep_fractions.csv")
for value in (0.006, 0.007):
    assert abs(shares[shares["P"] == value]["share"].sum() - 1) < 1e-12, shares
pts, events = an.continuation(("S", 0.02, 0.4), max_points=50, events=p + "continue_events.csv",
                              **out("continue"))
rows(pts, p + "continue.csv")
rows(events, p + "continue_events.csv")
eq = rows(an.equilibria((1, 0.1, 0.2, 0.25), branch=("xi", 3, 15), curve=("zeta", 20, 21, 2),
                        csv=p + "equilibria.csv"), p + "equilibria.csv")
assert list(eq["kind"]) == ["hopf"] * 4 and list(eq["zeta"]) == [20.25] * 2 + [20.75] * 2, eq
po = rows(an.periodic((1.05, 0.2, 0.27), settle=100, branch=("xi", 2.9, 4.1), direction=1,
                      cascade=2, params="xi=2.9", csv=p + "periodic.csv"), p + "periodic.csv")
assert list(po["period"][po["kind"] == "pd"]) == [1, 2], po
ex, table = an.exponents((1, 0.1, 0.2, 0.3), time=20, transient=5, params="xi=4.8",
                         **out("exponents"))
rows(table, p + "exponents.csv")
assert len(ex["lambda"]) == 4 and ex["lambda"][0] == table["lambda_1"][-1], (ex, table[-1])
samples, spectrum = an.series("chip-bue", time=50, dt=0.05, of="tau", time_unit=1e-3,
                              spectrum_csv=p + "series_spectrum.csv", **out("series"))
rows(samples, p + "series.csv")
rows(spectrum, p + "series_spectrum.csv")
assert list(samples.dtype.names) == ["t", "T0", "T", "gamma", "tau"], samples.dtype.names
em, curves = an.embedding("tau2", start=(1, 0.1, 0.2, 0.3), time=200, transient=10, dt=0.005,
                          steps=10, params="xi=4.8", **out("embedding"))
rows(curves, p + "embedding.csv")
assert em["embedding_dim"] == 3 and 0.2 < em["lambda"] < 0.5, em
ms, table = an.measure(p + "split.cmdb", to=p + "resumed.cmdb", window="0:100,-40:40",
                       samples=2000, **out("measure"))
rows(table, p + "measure.csv")
shares = table[table["measure"] == "share"]
assert ms["computed"] > 0 and abs(shares["value"].sum() - 1) < 1e-12, (ms, shares)
sampled = table[table["measure"] == "sampled"]
assert 0 < ms["sampled_as_labelled"] <= ms["sampled"] <= 2000, ms
assert abs(sampled["value"].sum() - 1) < 1e-12 and len(sampled) == len(shares), sampled

# without files: the tables alone, from temporary files
t = an.partition(params={"a": 1.3, "b": 0.66})
assert len(t) == 9, t
# errors name the problem, without command-line flags
for call, words in ((lambda: an.stability(P=(0.02, 0.01, 5)), "LO < HI"),
                    (lambda: an.sweep("Q", [1, 2]), "'Q' is not a parameter"),
                    (lambda: an.continuation(("S", 0.02, 0.2), params="S=0.3"),
                     "outside the range S=0.02:0.2"),
                    (lambda: an.partition(params="a=1.3,b=0.66", png="x.png", size=(10, 10)),
                     "300x200..4096x4096"),
                    (lambda: an.simulate(periods=5, csv=".", png="y.png"), "."),
                    (lambda: an.bifurcation(("S", 0.1, 0.3, 0)), "1..2000 values"),
                    (lambda: an.equilibria((1, 0.1, 0.2)), "the flow of model chip-4d has 4"),
                    (lambda: an.equilibria((1, 0.1, 0.2, 0.25), branch=("xi", 5, 6)),
                     "must hold the model's xi = 4.8")):
    try:
        call()
        raise SystemExit("no error where %r was expected" % words)
    except cellmap.CellmapError as e:
        assert words in str(e) and "--" not in str(e), str(e)
assert not os.path.exists("x.png") and not os.path.exists("y.png"), "a refused call wrote"
print("workstation_analysis.py: done")
