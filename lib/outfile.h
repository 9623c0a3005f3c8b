/* lib/outfile.h - output files of the analysis drivers and the commands
 * (CSV, JSON, chart PNGs), written to a temporary file that reaches PATH
 * only when complete (cellmap/output.h: "-" is stdout, devices and FIFOs
 * are written in place, never replaced), so that a failed run never
 * leaves a half-written file. Every call returns a status with the
 * problem, the user's path and the fix in msg; nothing is printed. */
#ifndef CM_LIB_OUTFILE_H
#define CM_LIB_OUTFILE_H

#include <stdbool.h>
#include <stdio.h>

#include "cellmap/output.h"
#include "render/chart.h"
#include "render/png_out.h"

/* The outputs of the analysis drivers and commands (escape, stability,
 * horseshoe, partition, amplitude, simulate, bifurcation): a CSV table
 * and a chart PNG (either NULL: not written; "-": standard output), JSON
 * on standard output, no report (quiet), and the chart's size in pixels. */
typedef struct chart_outputs {
    const char *csv, *png;
    bool json, quiet;
    int width, height;
} chart_outputs;

/* A stream being written to its temporary file. */
typedef struct outfile {
    cm_output out;
    FILE *f;
} outfile;

/* Checks an output path before the work that fills it: a directory, a
 * missing or read-only directory, or a device where a database must go
 * (needs_regular) is refused at once with CM_EINVAL (the user's to fix);
 * another status is a failure of the system (e.g. no file descriptor).
 * NULL: nothing to check. */
cm_status outfile_check_path(const char *path, bool needs_regular, char *msg, size_t msg_size);

/* outfile_check_path for a chart, which also needs OSMesa for a PNG or
 * librsvg for a PDF: loaded now (render/gl_loader.h, render/pdf.h), so
 * that a missing library stops the caller before its work. */
cm_status outfile_check_chart(const char *path, char *msg, size_t msg_size);

/* Opens the temporary file of path for writing into o->f. */
cm_status outfile_begin(const char *path, outfile *o, char *msg, size_t msg_size);

/* Closes o and, when ok (and every write succeeded), renames it into
 * place; else removes it. CM_OK when the file is in place. */
cm_status outfile_end(outfile *o, bool ok, char *msg, size_t msg_size);

/* Writes an SVG document (the writer's, its rasters up to cell_pixels
 * pixels a cell: cm_render_options.svg_cell_pixels) at path, or, with pdf,
 * that SVG drawn as a PDF by render/pdf.h (cell_pixels 16: librsvg smooths
 * images, and cells of several pixels keep their edges). */
typedef cm_status (*svg_writer)(FILE *f, const void *user, int cell_pixels, char *msg,
                                 size_t msg_size);
cm_status outfile_vector(const char *path, bool pdf, svg_writer write, const void *user,
                         char *msg, size_t msg_size);

/* Draws the charts one below the other (all of the first one's width) and
 * writes them at path with the given texts (plus Software): as SVG or PDF
 * where its name ends in .svg or .pdf (any case), else as PNG. */
cm_status outfile_charts(const char *path, const cm_chart *charts, int n_charts,
                         const cm_png_text *texts, int n_texts, char *msg, size_t msg_size);

#endif
