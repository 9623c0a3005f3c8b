"""The colours of basins that touch in a figure, from its pixels:
python3 colours.py FILE.png MIN prints the pairs of colours that meet
side by side in the plot rectangle (the PNG's View text) and fails if any
pair lies closer than MIN in the distance the README documents: the
smaller of CIE 1976 Delta E*ab with normal vision and twice Delta E*ab as
deuteranopes and protanopes see the colours (Machado, Oliveira and
Fernandes 2009, full severity). Pure white (cells not computed) and black
(markers, lines) are no basin's colour and are left out."""
import math, re, sys

from pngcheck import read_png

DEFICIENCIES = (
    ((0.367322, 0.860646, -0.227968), (0.280085, 0.672501, 0.047413), (-0.011820, 0.042940, 0.968881)),
    ((0.152286, 1.052583, -0.204868), (0.114503, 0.786281, 0.099216), (-0.003882, -0.048116, 1.051998)),
)


def linear(v):
    c = v / 255.0
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def lab(rgb):  # linear RGB in [0, 1] to CIELAB (D65)
    r, g, b = (min(max(c, 0.0), 1.0) for c in rgb)
    x = (0.4124564 * r + 0.3575761 * g + 0.1804375 * b) / 0.95047
    y = 0.2126729 * r + 0.7151522 * g + 0.0721750 * b
    z = (0.0193339 * r + 0.1191920 * g + 0.9503041 * b) / 1.08883
    f = lambda t: t ** (1 / 3) if t > (6 / 29) ** 3 else t / (3 * (6 / 29) ** 2) + 4 / 29
    return 116 * f(y) - 16, 500 * (f(x) - f(y)), 200 * (f(y) - f(z))


def seen(colour):
    lin = [linear(c) for c in colour]
    views = [lab(lin)]
    for m in DEFICIENCIES:
        views.append(lab([sum(m[k][i] * lin[i] for i in range(3)) for k in range(3)]))
    return views


def distance(a, b):
    sa, sb = seen(a), seen(b)
    return min([math.dist(sa[0], sb[0])] + [2 * math.dist(sa[v], sb[v]) for v in (1, 2)])


def touching_colours(path):
    w, h, bpp, rows, texts = read_png(path)
    x0, y0, pw, ph = map(int, re.search(r"plot (\d+),(\d+) (\d+)x(\d+)", texts["View"]).groups())
    skip = {(0, 0, 0), (255, 255, 255)}
    px = lambda x, y: tuple(rows[y][bpp * x:bpp * x + 3])
    pairs = set()
    for y in range(y0, y0 + ph):
        for x in range(x0, x0 + pw):
            a = px(x, y)
            for b in ((px(x + 1, y),) if x + 1 < x0 + pw else ()) + ((px(x, y + 1),) if y + 1 < y0 + ph else ()):
                if a != b and a not in skip and b not in skip:
                    pairs.add((min(a, b), max(a, b)))
    return pairs


def main():
    pairs = touching_colours(sys.argv[1])
    least = float(sys.argv[2])
    close = sorted((distance(a, b), a, b) for a, b in pairs)
    colours = {c for p in pairs for c in p}
    print("%s: %d colours, %d touching pairs, closest %.1f" %
          (sys.argv[1], len(colours), len(pairs), close[0][0] if close else float("inf")))
    bad = [c for c in close if c[0] < least]
    for d, a, b in bad:
        print("  %s and %s touch at distance %.1f < %g" % (a, b, d, least))
    sys.exit(1 if bad or not pairs else 0)


if __name__ == "__main__":
    main()
