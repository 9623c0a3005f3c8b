"""Reads an 8-bit RGB/RGBA PNG with zlib alone (no imaging library on CI)
and checks pixels: python3 pngcheck.py FILE.png CHECKS.json.

CHECKS.json: {"view": [x0, x1, y0, y1], "size": [w, h],
  "black_near": [[x, y, radius_px], ...],   # a marker pixel within radius
  "colour_at": [[x, y, [r, g, b]], ...]}    # the pixel's exact colour
Points are in state coordinates of the view; row 0 is the top (y1)."""
import json, struct, sys, zlib


def read_png(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, texts = 8, b"", {}
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, colour = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and colour in (2, 6), (depth, colour)
            bpp = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
        elif kind == b"tEXt":
            k, v = body.split(b"\0", 1)
            texts[k.decode("latin-1")] = v.decode("latin-1")
        pos += 12 + n
    raw, stride, rows, prev = zlib.decompress(idat), w * bpp, [], bytearray(w * bpp)
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            p = a + b - c
            pred = [0, a, b, (a + b) // 2,
                    a if abs(p - a) <= abs(p - b) and abs(p - a) <= abs(p - c) else b if abs(p - b) <= abs(p - c) else c][f]
            line[i] = (line[i] + pred) & 255
        rows.append(line)
        prev = line
    return w, h, bpp, rows, texts


def main():
    w, h, bpp, rows, texts = read_png(sys.argv[1])
    checks = json.load(open(sys.argv[2]))
    assert [w, h] == checks["size"], ("size", w, h)
    assert texts.get("Software", "").startswith("cellmap"), texts
    x0, x1, y0, y1 = checks["view"]
    pixel = lambda x, y: (int((x - x0) / (x1 - x0) * w), int((y1 - y) / (y1 - y0) * h))
    rgb = lambda px, py: tuple(rows[py][px * bpp:px * bpp + 3])
    bad = []
    for x, y, r in checks.get("black_near", []):
        px, py = pixel(x, y)
        if not any(rgb(i, j) == (0, 0, 0) for i in range(max(px - r, 0), min(px + r + 1, w))
                   for j in range(max(py - r, 0), min(py + r + 1, h))):
            bad.append("no attractor marker within %d px of (%g, %g) = pixel (%d, %d)" % (r, x, y, px, py))
    for x, y, colour in checks.get("colour_at", []):
        px, py = pixel(x, y)
        if list(rgb(px, py)) != colour:
            bad.append("pixel (%d, %d) at (%g, %g) is %s, expected %s" % (px, py, x, y, rgb(px, py), colour))
    for b in bad:
        print(sys.argv[1] + ": " + b)
    sys.exit(1 if bad else 0)


main()
