"""Compares a figure's PNG with its PDF drawn back by poppler at the same
resolution: python3 pdfcompare.py A.png B.png MEAN SHARE. Passes when the
sizes agree, the mean absolute difference per channel is below MEAN and
the share of pixels that differ by more than 64 in some channel (text and
lines antialiased differently, not a shifted or missing part) is below
SHARE. Pure Python (tests/pngcheck.py reads the PNGs)."""
import sys

from pngcheck import read_png


def main():
    wa, ha, pa, ra, _ = read_png(sys.argv[1])
    wb, hb, pb, rb, _ = read_png(sys.argv[2])
    mean_max, share_max = float(sys.argv[3]), float(sys.argv[4])
    assert (wa, ha) == (wb, hb), ("sizes", (wa, ha), (wb, hb))
    total, far = 0, 0
    for y in range(ha):
        a, b = ra[y], rb[y]
        for x in range(wa):
            d = [abs(a[x * pa + c] - b[x * pb + c]) for c in range(3)]
            total += sum(d)
            far += max(d) > 64
    mean, share = total / (3 * wa * ha), far / (wa * ha)
    print("%s vs %s: mean difference %.2f, %.2f %% of pixels far" % (sys.argv[1], sys.argv[2],
                                                                    mean, 100 * share))
    assert mean < mean_max and share < share_max, (mean, share)


main()
