/* src/figure_opts.h - the figure options solve, explore, render and the
 * analysis commands share (--png, --svg, --size, --layers, --png-mode,
 * --view, --min-basin, --palette, --labels, --legend) into lib/figure.h's
 * png_opts, and the figure written with the problem said as "cellmap CMD:
 * ...". */
#ifndef CM_SRC_FIGURE_OPTS_H
#define CM_SRC_FIGURE_OPTS_H

#include "lib/figure.h"
#include "src/args.h"

#define PNG_OPTIONS_HELP                                                                           \
    "  --size WxH          image size in pixels (default: one pixel per cell, at most 4096;\n"     \
    "                      1000 on the longer side for figures with text)\n"                       \
    "  --layers L,...      what to draw: basin, steps (shading by transient length; alone:\n"      \
    "                      step numbers only), attractors, overlays (switching lines, fixed\n"     \
    "                      points, manifolds, sticking zones, repellers orange and escape\n"      \
    "                      intervals blue), axes, legend, title; or all\n"                          \
    "                      (default: basin,attractors)\n"                                          \
    "  --png-mode MODE     rgb (a figure) or indexed (one pixel per cell, its value the\n"         \
    "                      colour class; the classes of groups are in the PNG's texts)\n"          \
    "  --view X0:X1,Y0:Y1  the rectangle of state space to draw (default: all cells;\n"            \
    "                      1-D models ignore Y0:Y1)\n"                                             \
    "  --svg FILE          the same figure as SVG: text and paths, with the basins\n"           \
    "                      embedded as a PNG of one pixel per cell\n"                             \
    "  --min-basin N       draw groups whose basins have fewer than N cells as 'other' (one\n"   \
    "                      muted colour, one legend line); default 2 in figures with a\n"         \
    "                      legend (single-cell groups folded), else 1 (none)\n"                    \
    "  --palette P         group colours: cellmap (default, 24), tol, okabe-ito, tab20,\n"    \
    "                      or a file of #rrggbb lines; touching basins kept apart\n"               \
    "  --labels FILE       the legend's names of groups: lines 'ID TEXT' or, for the same\n"   \
    "                      attractor in any file, 'ANCHOR TEXT' with the anchor cell's\n"      \
    "                      indices as export --groups lists them (e.g. 287,500 SW2)\n"        \
    "  --legend K          list at most K groups in the legend (default 12), the rest in one\n"   \
    "                      line; colours follow each attractor's anchor cell, so the same\n"     \
    "                      attractor has the same colour in every file and view\n"        \
    "  --title TEXT        the title (default: the model and its parameters), wrapped\n"  \
    "  --aspect A          equal (squares drawn square), auto (the plot fills its room) or\n" \
    "                      R (y units R times x's); default equal if the axes share a unit\n"    \
    "  --font-size PT      text size in points: PT*N/72 pixels at --dpi N (96 if not given;\n" \
    "                      default: from --size)\n"                                                \
    "  --dpi N             pixels per inch, written to the PNG and giving the SVG's size in\n" \
    "                      points: --size 1800x1200 --dpi 300 is 6x4 inches\n"

/* Handles the shared options; true if the current option was one of them. */
bool png_opts_take(cli *c, png_opts *po, int *error);
/* Checks the options together (e.g. indexed images take no --size). */
int png_opts_check(const cli *c, const png_opts *po);

/* Checks before anything is computed that the PNG of these options can be
 * written: its paths (src/outfile.h) and, for a figure, its size and room
 * for the text layers over box (or the --view). Prints "cellmap CMD:
 * problem" and returns its exit status if not (EXIT_OK). */
int check_basin_png(const char *cmd, const png_opts *po, const cm_model *m,
                    const cm_lattice *lat, const cm_box *box);

/* Renders and writes the figure (figure_write). Prints "cellmap CMD:
 * problem" and returns EXIT_FAIL on failure. */
int write_basin_png(const char *cmd, const basin_png *b);

#endif
