#!/usr/bin/env bash
# PDF and SVG for papers (render/pdf.h, docs/testing.md): a basin figure's
# --pdf and every chart's --png FILE.pdf / FILE.svg have the layout of the
# PNG: the PDF's page is the figure's size in points (--dpi), and drawn
# back at that resolution by poppler (pdftoppm, an independent reader) it
# matches the PNG but for antialiasing (tests/pdfcompare.py: the mean
# difference and the share of pixels that differ much both bounded); the
# same command gives the same bytes; a PDF onto the database or with
# --png-mode indexed, or a basin figure's --png FILE.pdf, is refused.
# usage: pdf_test.sh PATH/TO/cellmap
set -u
CM=$1
HERE=$(cd "$(dirname "$0")" && pwd)
. "$HERE/testlib.sh"
enter_workdir

basin=(--cells 200x200 --dpi 150)
"$CM" solve "${basin[@]}" --png b.png --pdf b.pdf --svg b.svg --db b.cmdb --quiet > /dev/null \
  || fail "solve --pdf"
"$CM" solve "${basin[@]}" --pdf b2.pdf --quiet > /dev/null || fail "solve --pdf again"
cmp -s b.pdf b2.pdf || fail "the same command gave two PDFs"
"$CM" render b.cmdb --pdf r.pdf --png r.png --size 800x600 --dpi 150 || fail "render --pdf"
head -c 5 b.pdf | grep -q "%PDF-" || fail "b.pdf is not a PDF"
grep -aq "MediaBox \[ 0 0 480 480 \]" b.pdf || fail "the page is not 1000 px at 150 dpi = 480 pt"
pdftoppm -r 150 -png -singlefile b.pdf bp || fail "pdftoppm b.pdf"
python3 "$HERE/pdfcompare.py" b.png bp.png 6 0.03 || fail "the basin PDF differs from its PNG"
pdftoppm -r 150 -png -singlefile r.pdf rp || fail "pdftoppm r.pdf"
python3 "$HERE/pdfcompare.py" r.png rp.png 6 0.03 || fail "render's PDF differs from its PNG"

# charts: a stack of three with fills and labels, a heat map with its colour bar
"$CM" stability --model microchaos-delay --png d.png --quiet || fail "stability png"
"$CM" stability --model microchaos-delay --png d.pdf --quiet || fail "stability pdf"
"$CM" stability --model microchaos-delay --png d.svg --quiet || fail "stability svg"
head -c 5 d.svg | grep -q "<?xml" || fail "d.svg is not SVG"
pdftoppm -r 96 -png -singlefile d.pdf dp || fail "pdftoppm d.pdf"
python3 "$HERE/pdfcompare.py" d.png dp.png 6 0.03 || fail "the chart PDF differs from its PNG"
heat=(--param S0=0.4 --grid Omega=0.2:0.7:20,S=0.005:0.4:16 --periods 100 --quiet)
"$CM" lyapunov "${heat[@]}" --png l.png > /dev/null || fail "lyapunov png"
"$CM" lyapunov "${heat[@]}" --png l.pdf > /dev/null || fail "lyapunov pdf"
pdftoppm -r 96 -png -singlefile l.pdf lp || fail "pdftoppm l.pdf"
python3 "$HERE/pdfcompare.py" l.png lp.png 6 0.03 || fail "the heat map PDF differs from its PNG"

expect_usage "use --pdf b.pdf" solve --png b.pdf
expect_usage "--png-mode indexed applies to --png only" solve --pdf x.pdf --png-mode indexed
expect_usage "the PDF" render b.cmdb --pdf b.cmdb
[ -f b.cmdb ] && "$CM" info b.cmdb > /dev/null || fail "the database was touched"
[ $fails -eq 0 ] && echo "PDF and SVG match the PNGs"
exit $((fails > 0))
