"""Reads an 8-bit RGB, RGBA or palette PNG with zlib alone (no imaging
library on CI) and checks pixels: python3 pngcheck.py FILE.png CHECKS.json.

CHECKS.json: {"view": [x0, x1, y0, y1], "size": [w, h],
  "black_near": [[x, y, radius_px], ...],          # a marker pixel within radius
  "colour_near": [[x, y, radius_px, [r, g, b]], ...],  # that colour within radius
  "colour_at": [[x, y, [r, g, b]], ...],           # the pixel's exact colour
  "not_colour_at": [[x, y, [r, g, b]], ...],       # any other colour
  "texts": {"Key": "prefix", ...}}                 # text chunks start so
Points are in state coordinates of the view, which fills the plot rectangle
the PNG's View text names ("plot X,Y WxH"), else the whole image; row 0 is
the top (y1)."""
import json, re, struct, sys, zlib


def read_png(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, texts, palette = 8, b"", {}, None
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, colour = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and colour in (2, 3, 6), (depth, colour)
            bpp = {2: 3, 3: 1, 6: 4}[colour]
        elif kind == b"PLTE":
            palette = [tuple(body[i:i + 3]) for i in range(0, n, 3)]
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
    if palette is not None:  # expand indices to RGB
        rows = [bytearray(b for i in row for b in palette[i]) for row in rows]
        bpp = 3
    return w, h, bpp, rows, texts


def main():
    w, h, bpp, rows, texts = read_png(sys.argv[1])
    checks = json.load(open(sys.argv[2]))
    assert [w, h] == checks["size"], ("size", w, h)
    assert texts.get("Software", "").startswith("cellmap"), texts
    x0, x1, y0, y1 = checks["view"]
    plot = re.search(r"plot (\d+),(\d+) (\d+)x(\d+)", texts.get("View", ""))
    ox, oy, pw, ph = map(int, plot.groups()) if plot else (0, 0, w, h)
    pixel = lambda x, y: (ox + int((x - x0) / (x1 - x0) * pw), oy + int((y1 - y) / (y1 - y0) * ph))
    rgb = lambda px, py: tuple(rows[py][px * bpp:px * bpp + 3])
    bad = []
    near = [(x, y, r, [0, 0, 0]) for x, y, r in checks.get("black_near", [])]
    for x, y, r, colour in near + checks.get("colour_near", []):
        px, py = pixel(x, y)
        if not any(list(rgb(i, j)) == colour for i in range(max(px - r, 0), min(px + r + 1, w))
                   for j in range(max(py - r, 0), min(py + r + 1, h))):
            bad.append("no pixel %s within %d px of (%g, %g) = pixel (%d, %d)" % (colour, r, x, y, px, py))
    for x, y, colour in checks.get("colour_at", []):
        px, py = pixel(x, y)
        if list(rgb(px, py)) != colour:
            bad.append("pixel (%d, %d) at (%g, %g) is %s, expected %s" % (px, py, x, y, rgb(px, py), colour))
    for x, y, colour in checks.get("not_colour_at", []):
        px, py = pixel(x, y)
        if list(rgb(px, py)) == colour:
            bad.append("pixel (%d, %d) at (%g, %g) is %s, expected another colour" % (px, py, x, y, colour))
    for key, prefix in checks.get("texts", {}).items():
        if not texts.get(key, "").startswith(prefix):
            bad.append("text %s is %r, expected it to start with %r" % (key, texts.get(key), prefix))
    for b in bad:
        print(sys.argv[1] + ": " + b)
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
