/* render/pdf.h - PDF for papers: an SVG of render/ (a basin figure or a
 * chart) drawn onto a PDF page by librsvg through cairo (Debian's
 * librsvg2-2 and libcairo2), so the PDF has the SVG's layout by
 * construction: vector lines and text, the basin raster as an image. The
 * page is the SVG's size in points (its width and height in pt, or in
 * pixels at 96 per inch). The same SVG gives the same bytes (cairo's
 * creation date is left out). Both libraries are loaded when the first PDF
 * is written, so commands that write none never map them. Thread-safe. */
#ifndef CM_RENDER_PDF_H
#define CM_RENDER_PDF_H

#include <stddef.h>
#include <stdio.h>

#include "cellmap/status.h"

/* Loads librsvg and cairo (once per process); CM_ERENDER naming what is
 * missing and the package that has it. */
cm_status cm_pdf_load(char *msg, size_t msg_size);

/* Writes the SVG document svg (n bytes) as a one-page PDF to out. */
cm_status cm_pdf_from_svg(const char *svg, size_t n, FILE *out, char *msg, size_t msg_size);

#endif
