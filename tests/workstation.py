"""The command's work done from Python (tests/workstation_test.sh compares
what it writes with what the command writes, as it does tests/workstation.c's):
py_split.cmdb (solve --db --split 2x2), py_resumed.cmdb (cancelled after its
first join, then resumed), py_partial.cmdb (the cancelled file, for the
command to resume), py_ext.cmdb (--extend 3), py_explore.cmdb and py_view.png
(20 pans of 10 % and a render), py_added.cmdb and py_extended.cmdb (a tile
grown by a box and by 3 extension steps), py_labels.npy (export --labels)."""
import shutil

import cellmap

PD = dict(alpha=0.078, beta=0, P=0.007, D=0.02)
REGION, CELLS = [(0, 500), (-40, 40)], (200, 100)

cellmap.create("py_split.cmdb", "microchaos-pd", REGION, CELLS, split=(2, 2), threads=2, **PD)

try:
    cellmap.create("py_resumed.cmdb", "microchaos-pd", REGION, CELLS, split=(2, 2), threads=2,
                   progress=lambda fraction: 0 < fraction < 1, **PD)
    raise SystemExit("the cancelled solve was not cancelled")
except cellmap.CellmapError as e:
    assert "cancelled" in str(e), e
shutil.copyfile("py_resumed.cmdb", "py_partial.cmdb")
db = cellmap.resume("py_resumed.cmdb", "microchaos-pd", REGION, CELLS, split=(2, 2), threads=2,
                    **PD)
assert db.params == {"alpha": 0.078, "beta": 0, "P": 0.007, "D": 0.02}, db.params

cellmap.create("py_ext.cmdb", "microchaos-pd", [(0, 100), (-40, 40)], (100, 100), extend=3,
               threads=2, **PD)

with cellmap.Session("py_explore.cmdb", model="microchaos-pd", cell_size=(0.5, 0.08),
                     threads=2, **PD) as s:
    s.view([(0, 50), (-4, 4)])
    for _ in range(20):  # pan right 10%
        (lo, hi), _ = s.bounds
        s.pan(0, 10 * ((hi - lo) / 100))
    s.figure("py_view.png")
    # the print options reach the figure: 150 dpi in the PNG (pHYs, per
    # metre), the SVG 72/150 pt a pixel with 8-point text (17 pixels)
    s.figure("py_print.png", svg="py_print.svg", layers=("basin", "axes", "title"), width=600,
             height=400, title="print", aspect="auto", dpi=150, font_size=8)
    png = open("py_print.png", "rb").read()
    assert png[png.index(b"pHYs") + 4:][:9] == bytes.fromhex("0000171200001712 01".replace(" ", "")), png[:80]
    svg = open("py_print.svg").read()
    assert 'width="288pt" height="192pt"' in svg and 'font-size="17"' in svg and ">print<" in svg, svg[:300]
    view = s.read()
    assert view.labels.shape == (100, 100) and (view.labels >= 0).all()  # every cell computed
    # a point query says what read() says of the cell holding the state
    width = [(view.hi[d] - view.lo[d]) / view.cells[d] for d in range(2)]
    for i, j in ((0, 0), (37, 81), (99, 99), (50, 3)):
        q = s.query([view.lo[0] + (i + 0.3) * width[0], view.lo[1] + (j + 0.6) * width[1]])
        assert (q["label"], q["step"], q["attractor"]) == (
            view.labels[i, j], view.steps[i, j], view.attractor_labels[i, j]), (i, j, q)
    assert s.query([view.hi[0] + 100, 0])["label"] == -1  # a cell no region covers

cellmap.create("py_added.cmdb", "microchaos-pd", [(0, 100), (-40, 40)], (100, 100), threads=2,
               **PD)
assert cellmap.add_box("py_added.cmdb", [(100, 200), (-40, 40)], threads=2) == 100 * 100
cellmap.create("py_extended.cmdb", "microchaos-pd", [(0, 100), (-40, 40)], (100, 100),
               threads=2, **PD)
assert cellmap.extend("py_extended.cmdb", [(0, 100), (-40, 40)], 3, threads=2) == 3

cellmap.export("py_split.cmdb", labels="py_labels.npy")
print("workstation.py: done")
