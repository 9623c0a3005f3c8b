#!/usr/bin/env python3
"""Fig. 4.30: where do sticking zones absorb the outermost attractor (SW_4)?

Sweeps the friction level mu of microchaos-pd-friction (alpha = 6.53e-3,
beta = 0, P = 5.5e-5, D = 2.5e-3) with `cellmap solve --json` on two
lattices and prints, for each mu, the basin cells (over all groups near the
switching line SW_4, x = 4/P) of attractors and of sticking zones:
  coarse: the Fig. 4.30 window [-1e5, 1e5] x [-601.5, 601.5], 250 x 3 cells;
  fine:   [71500, 74000] x [-10.05, 10.05] around SW_4, 2.5 x 0.1 cells.
MODELS.md 8.4 estimates the onset at mu = alpha^2 m_max / P - (m_max - 1).

usage: fig-4.30-sweep.py PATH/TO/cellmap [mu ...]
"""
import json
import subprocess
import sys

ALPHA, P = 6.53e-3, 5.5e-5
LATTICES = {
    "coarse": ("-100000:100000,-601.5:601.5", "800x401"),
    "fine": ("71500:74000,-10.05:10.05", "1000x201"),
}


def near_sw4(cellmap, mu, region, cells):
    out = subprocess.run(
        [cellmap, "solve", "--model", "microchaos-pd-friction", "--param", "mu=%.6g" % mu,
         "--region=" + region, "--cells", cells, "--max-steps", "100000", "--json"],
        capture_output=True, text=True, check=True).stdout
    basins = {"attractor": 0, "sticking": 0}
    for g in json.loads(out)["groups"]:
        if abs(g["centre"][0] - 4 / P) < 0.05 / P:
            basins[g["kind"]] += g["basin"]
    return basins


def main():
    cellmap = sys.argv[1]
    mus = [float(a) for a in sys.argv[2:]] or [0.09, 0.095, 0.097, 0.098, 0.1, 0.101, 0.1012, 0.105]
    print("analytic onset (MODELS.md 8.4): mu = %.5f" % (ALPHA**2 * 4 / P - 3))
    print("%8s %24s %24s" % ("mu", "coarse: attractor/sticking", "fine: attractor/sticking"))
    for mu in mus:
        row = [near_sw4(cellmap, mu, *LATTICES[k]) for k in ("coarse", "fine")]
        print("%8.4f %24s %24s" % (mu, "%d / %d" % (row[0]["attractor"], row[0]["sticking"]),
                                    "%d / %d" % (row[1]["attractor"], row[1]["sticking"])))


if __name__ == "__main__":
    main()
