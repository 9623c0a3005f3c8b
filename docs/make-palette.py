"""Makes the default palette "cellmap" of render/palette.c:
python3 docs/make-palette.py prints its 24 colours.

Seven colours of Paul Tol's colour-blind-safe bright and vibrant schemes
come first; each further colour is, of the sRGB colours on a grid of step
15 with CIELAB lightness 40..85 and chroma 25..65, the one farthest from
all chosen before, in the distance figures keep touching basins apart by:
the smaller of CIE 1976 Delta E*ab with normal vision and twice Delta E*ab
as deuteranopes and protanopes see the colours (Machado, Oliveira and
Fernandes 2009, full severity). Candidates closer than 30 to the figures'
fixed colours (the sink's red, the grey of sticking zones and its rest
cells, the cream of "other", white, black) are left out."""
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
from colours import lab, linear, DEFICIENCIES  # noqa: E402  the same formulas as the tests

TOL = ["4477aa", "228833", "ccbb44", "66ccee", "aa3377", "ee7733", "009988"]
FIXED = [(214, 39, 40), (180, 180, 180), (96, 96, 96), (250, 244, 184), (255, 255, 255), (0, 0, 0)]
SIZE = 24


def seen(colour):
    lin = [linear(c) for c in colour]
    return [lab(lin)] + [lab([sum(m[k][i] * lin[i] for i in range(3)) for k in range(3)])
                         for m in DEFICIENCIES]


def distance(a, b):
    return min([math.dist(a[0], b[0])] + [2 * math.dist(a[v], b[v]) for v in (1, 2)])


def main():
    fixed = [seen(c) for c in FIXED]
    candidates = []
    for r in range(0, 256, 15):
        for g in range(0, 256, 15):
            for b in range(0, 256, 15):
                s = seen((r, g, b))
                lightness, chroma = s[0][0], math.hypot(s[0][1], s[0][2])
                if 40 <= lightness <= 85 and 25 <= chroma <= 65 and \
                        all(distance(s, f) >= 30 for f in fixed):
                    candidates.append(((r, g, b), s))
    chosen = [tuple(int(h[i:i + 2], 16) for i in (0, 2, 4)) for h in TOL]
    nearest = [min(distance(s, seen(c)) for c in chosen) for _, s in candidates]
    while len(chosen) < SIZE:
        k = max(range(len(candidates)), key=lambda i: (nearest[i], -i))
        chosen.append(candidates[k][0])
        nearest = [min(n, distance(s, candidates[k][1])) for n, (_, s) in zip(nearest, candidates)]
    print(" ".join("%02x%02x%02x" % c for c in chosen))


if __name__ == "__main__":
    main()
