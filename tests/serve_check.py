"""Checks of `cellmap serve`'s answers (tests/serve_test.sh), with zlib and
struct alone (no imaging library or numpy on CI).

  serve_check.py tile TILE.png INFO.json LABELS.npy Z X Y
      tile (Z, X, Y)'s pixels are the labels `cellmap export --labels`
      gives for its cells (LABELS.npy of the tile's window, and its .json;
      cells beyond it not computed; at zoom Z < 0 each pixel the most
      frequent label of its block): each pixel has its label's legend
      colour in INFO.json (/info), or black on an attractor's footprint
      (zoom 0).
  serve_check.py tile-ids TILE.png LABELS.npy Z X Y
      the same where the attractors' colours are not known (a refined
      level's ids): each attractor's pixels one colour of its own, the
      fates without one their fixed colours.
  serve_check.py steps TILE.png STEPS.npy Z X Y
      a steps tile (zoom 0) against `export --steps`: one grey per step
      number, darker as they rise (to 64), white where none is computed.
  serve_check.py same A.npy B.npy
      two label arrays are equal up to the numbering of attractors (a
      one-to-one map of ids above 0; every other value equal).
  serve_check.py equal A.npy B.npy
      two arrays are equal.
  serve_check.py json FILE KEY...
      FILE is JSON with every KEY; prints them."""
import json, struct, sys
from array import array

from pngcheck import read_png


def read_npy(path):
    """A little-endian int32 or int64 .npy array in C order: (shape, values)."""
    data = open(path, "rb").read()
    assert data[:6] == b"\x93NUMPY", path
    major = data[6]
    n, start = (struct.unpack("<H", data[8:10])[0], 10) if major == 1 else (struct.unpack("<I", data[8:12])[0], 12)
    header = eval(data[start:start + n].decode("latin-1"))  # a Python dict literal
    assert not header["fortran_order"], header
    code = {"<i4": "i", "<i8": "q"}[header["descr"]]
    values = array(code)
    values.frombytes(data[start + n:])
    return tuple(header["shape"]), values


def colour_of(hex_text):
    return tuple(int(hex_text[i:i + 2], 16) for i in (1, 3, 5))


FATES = {0: (214, 39, 40), -2: (180, 180, 180), -1: (255, 255, 255)}


def tile_and_cells(png, npy_path, zoom, tx, ty):
    """Tile (zoom, tx, ty)'s pixels, and for its pixel (px, py) (row 0 at
    the top) the values of its block of cells in an `export` array (its
    .json beside it says where its box starts; cells beyond it -1: export's
    box is the cluster's part of the window)."""
    w, h, bpp, rows, _ = read_png(png)
    assert (w, h) == (256, 256), (w, h)
    shape, values = read_npy(npy_path)
    first = json.load(open(npy_path[:-4] + ".json"))["first_cell"]
    k = 1 << -zoom
    lo0, lo1 = tx * 256 * k, -(ty + 1) * 256 * k  # the tile's first cell

    def value(c0, c1):
        i, j = c0 - first[0], c1 - first[1]
        return values[i * shape[1] + j] if 0 <= i < shape[0] and 0 <= j < shape[1] else -1

    pixel = lambda px, py: tuple(rows[py][px * bpp:px * bpp + 3])
    block = lambda px, py: [value(lo0 + px * k + c, lo1 + (255 - py) * k + r)
                            for c in range(k) for r in range(k)]
    return pixel, block, k


def check_tile(png, info_path, labels_path, zoom, tx, ty):
    """info_path None: the attractors' colours are not known (their ids are
    another level's), only that each has one, its own."""
    pixel, cells, k = tile_and_cells(png, labels_path, zoom, tx, ty)
    if info_path:
        colour = {e["label"]: colour_of(e["colour"]) for e in json.load(open(info_path))["legend"]}
        assert len(set(colour.values())) == len(colour), "two legend entries share a colour"
    else:
        colour = dict(FATES)
    bad = []
    for py in range(256):
        for px in range(256):
            block = cells(px, py)
            # ties: the lowest id the tile gives them (diverged, attractors,
            # outside, not computed)
            rank = lambda v: v if v >= 0 else {-2: 1 << 40, -1: 1 << 41}[v]
            want = min(set(block), key=lambda v: (-block.count(v), rank(v)))
            got = pixel(px, py)
            if got == (0, 0, 0) and k == 1 and want > 0:
                continue  # a footprint cell of its attractor
            if not info_path and want > 0 and want not in colour and got not in colour.values():
                colour[want] = got  # an attractor's colour: one of its own
            if got != colour.get(want):
                bad.append((px, py, want, got))
    if bad:
        sys.exit("%s: %d pixels differ from the labels, first %s" % (png, len(bad), bad[:5]))


def check_steps(png, steps_path, zoom, tx, ty):
    """A steps tile: grey levels that fall (darker) as step numbers rise, to
    the cap 64; one grey per step number; white where nothing is computed
    (export's -1)."""
    pixel, cells, _ = tile_and_cells(png, steps_path, zoom, tx, ty)
    assert zoom == 0, "steps are checked at one pixel per cell"
    grey, bad = {}, []
    for py in range(256):
        for px in range(256):
            step = cells(px, py)[0]
            got = pixel(px, py)
            if step < 0:
                if got != (255, 255, 255):
                    bad.append((px, py, step, got))
                continue
            if got[0] != got[1] or got[1] != got[2] or grey.setdefault(min(step, 64), got) != got:
                bad.append((px, py, step, got))
    levels = sorted(grey.items())
    if any(a[1][0] < b[1][0] for a, b in zip(levels, levels[1:])) or len(levels) < 2:
        bad.append("greys do not darken with the step: %s" % levels[:10])
    if bad:
        sys.exit("%s: %d pixels wrong, first %s" % (png, len(bad), bad[:5]))


def same_up_to_ids(a_path, b_path):
    sa, a = read_npy(a_path)
    sb, b = read_npy(b_path)
    assert sa == sb, (sa, sb)
    forward, backward, bad = {}, {}, 0
    for x, y in zip(a, b):
        if x > 0 and y > 0:
            bad += forward.setdefault(x, y) != y or backward.setdefault(y, x) != x
        else:
            bad += x != y
    if bad:
        sys.exit("%s and %s: %d cells differ" % (a_path, b_path, bad))


def main():
    what = sys.argv[1]
    if what == "tile":
        check_tile(sys.argv[2], sys.argv[3], sys.argv[4], *map(int, sys.argv[5:8]))
    elif what == "tile-ids":
        check_tile(sys.argv[2], None, sys.argv[3], *map(int, sys.argv[4:7]))
    elif what == "steps":
        check_steps(sys.argv[2], sys.argv[3], *map(int, sys.argv[4:7]))
    elif what == "same":
        same_up_to_ids(sys.argv[2], sys.argv[3])
    elif what == "equal":
        if read_npy(sys.argv[2]) != read_npy(sys.argv[3]):
            sys.exit("%s and %s differ" % (sys.argv[2], sys.argv[3]))
    elif what == "json":
        doc = json.load(open(sys.argv[2]))
        print(" ".join(json.dumps(doc[key]) for key in sys.argv[3:]))
    else:
        sys.exit("unknown check " + what)


if __name__ == "__main__":
    main()
