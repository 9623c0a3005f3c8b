/* render/chart.h - data charts: a heat map of a scalar over a parameter
 * grid (Figs. 2.20-2.21), point clouds (bifurcation diagrams, Fig. 2.22,
 * Poincare sections) and polylines (time histories and phase portraits,
 * Figs. 2.3, 2.9, 2.16), with axes, a title and, for heat maps, a colour
 * bar. The plot is drawn with OSMesa, the text with FreeType; the same
 * inputs give the same bytes. Not thread-safe. */
#ifndef CM_RENDER_CHART_H
#define CM_RENDER_CHART_H

#include <stddef.h>
#include <stdio.h>
#include <stdint.h>

#include "cellmap/status.h"
#include "render/gl.h"
#include "render/palette.h"

enum cm_series_kind {
    CM_SERIES_POINTS,  /* one dot per (x, y) */
    CM_SERIES_LINE,    /* a polyline through the points; NaN breaks it */
    CM_SERIES_SEGMENTS /* pairs of points: segments (0,1), (2,3), ... */
};

typedef struct cm_series {
    int kind;
    const double *x, *y;
    size_t n;
    cm_rgb colour;
    float size; /* dot size or line width in pixels; 0: 1 */
} cm_series;

/* A scalar over an nx x ny grid spanning the chart's lo..hi: cell (i, j)
 * covers column i and row j (row 0 at lo[1]); v[j * nx + i]. Only values
 * > 0 are coloured (0..max on a sequential scale); the rest stay white,
 * NaN light grey (not computed). */
typedef struct cm_heat {
    int nx, ny;
    const double *v;
    double max;       /* top of the scale; <= 0: the largest value */
    const char *name; /* label of the colour bar */
} cm_heat;

/* A text at a data point, drawn right of and above it (markers of events). */
typedef struct cm_chart_label {
    double x, y;
    const char *text;
} cm_chart_label;

typedef struct cm_chart {
    int width, height;
    double lo[2], hi[2]; /* the data rectangle */
    const char *x_name, *y_name, *title;
    const cm_heat *heat; /* may be NULL */
    const cm_series *series;
    int n_series;
    const char *font_path;
    int min_left; /* the plot starts at least this many pixels from the left
                     edge (stacked charts share their x axis); 0: as the
                     labels need */
    const cm_chart_label *labels; /* may be NULL; those outside the plot are skipped */
    int n_labels;
} cm_chart;

/* Where the plot went, so that callers and tests can map pixels. */
typedef struct cm_chart_info {
    int plot_x, plot_y, plot_w, plot_h;
    double heat_max;
} cm_chart_info;

/* Labels that fall on one place: each label within dx and dy of an
 * earlier one is left out (text NULL), its text joined to the earlier's
 * ("SN_2a, SN_2s") unless it says the same or there is no room. texts
 * holds n buffers of text_size bytes, labels[i].text pointing at the i-th
 * (or NULL). */
void cm_chart_join_labels(cm_chart_label *labels, int n, char *texts, size_t text_size, double dx,
                          double dy);

/* The colour of a heat value on the scale 0..max. */
cm_rgb cm_heat_colour(double v, double max);

/* Where cm_chart_draw would put the plot (info's plot_*), without drawing. */
cm_status cm_chart_layout(const cm_chart *c, cm_chart_info *info, char *msg, size_t msg_size);

/* Draws into rgba (width*height*4 bytes, row 0 at the top) with the
 * context gl (render/gl.h), or a new one when gl is NULL. */
cm_status cm_chart_draw(const cm_chart *c, cm_gl *gl, uint8_t *rgba, cm_chart_info *info, char *msg,
                        size_t msg_size);

/* The same chart as SVG elements, a group translated down by top pixels
 * (stacked panels), for a document render/ writes around it: its own
 * clip path (index makes its id unique), text in the font's pixels at the
 * places the PNG has it, the heat map embedded as a PNG of up to
 * cell_pixels x cell_pixels pixels a cell (about twice the pixels it covers;
 * 1: one pixel; more for readers that smooth images, render/pdf.h). No
 * OpenGL. */
cm_status cm_chart_svg(const cm_chart *c, int index, int top, int cell_pixels, FILE *f, char *msg,
                       size_t msg_size);

#endif
