/* render/figure.h - basin and attractor figures, drawn off-screen.
 *
 * A figure is the plot of a view (basin raster, attractor markers, the
 * model's overlays; for 1-D models the map's graph with cobwebs above a basin
 * strip) and, when their layers are asked for, axes with ticks in state
 * coordinates, a legend of the groups in view and a title with the model and
 * its parameters. The caller's RGBA buffer holds width*height*4 bytes, row 0
 * at the top. Without axes, legend and title the plot fills the image.
 *
 * The view is a rectangle of state space in dimensions 0 and 1; models of
 * more than two dimensions are drawn as the slice through slice[d] (cell
 * coordinates) in the others. Deterministic: the same inputs give the same
 * bytes whatever the thread count. Not thread-safe.
 */
#ifndef CM_RENDER_FIGURE_H
#define CM_RENDER_FIGURE_H

#include <stdint.h>

#include "cellmap/model.h"
#include "cellmap/scm.h"
#include "render/plot.h"

enum { CM_RENDER_MAX_SIDE = 16384, CM_RENDER_MAX_FONT = 512 };

/* A legend's own name for a group, by id or by anchor cell (lattice
 * indices: the same attractor in any file of the same lattice). */
typedef struct cm_group_label {
    bool by_anchor;
    uint32_t id;
    int64_t anchor[CM_MAX_DIM];
    char text[64];
} cm_group_label;

typedef struct cm_render_options {
    int width, height;         /* pixels, 1..CM_RENDER_MAX_SIDE */
    double lo[2], hi[2];       /* view in state coordinates; all zero: the region */
    int64_t slice[CM_MAX_DIM]; /* cells of dimensions >= 2; used when set_slice */
    int set_slice;             /* 0: the middle of the region */
    unsigned layers;           /* enum cm_layer; 0: basin and attractors */
    const cm_model *model;     /* overlays, title, axis names, the 1-D graph; may be NULL */
    const char *font_path;     /* TrueType font for axes, legend and title */
    cm_gl *gl;                 /* a kept GL context (render/gl.h); NULL: a new one if
                                  the figure needs GL (cm_plot_needs_gl) */
    uint64_t min_basin;        /* groups with smaller basins are drawn and listed as
                                  "other" (0, 1: none) */
    int legend_groups;         /* the most groups the legend lists (0: 12) */
    const struct cm_palette *palette; /* group colours (render/palette.h); NULL: the default */
    const cm_group_label *labels;     /* the legend's names of groups (n_labels of them) */
    int n_labels;
    const char *sink_label;           /* the legend's name of label 0; NULL: "sink" */
    const char *group_noun;           /* what the legend calls a group; NULL: "group" */
    const char *title;                /* the title; NULL: the model and its parameters (a
                                         flow's integrator settings left out); wrapped */
    double aspect;                    /* 2-D views: a state unit along dimension 1 drawn
                                         `aspect` times as long as one along dimension 0 (1:
                                         equal, a square of state space is square), the plot
                                         the largest such rectangle in its room;
                                         0: the plot fills its room */
    double font_px;                   /* the text's size (the font's em) in pixels; 0: from
                                         the image's size (1/45 of its shorter side, 10..48) */
    double dpi;                       /* pixels per inch: the SVG's size in points (width
                                         72/dpi pt a pixel); 0: its size in pixels */
    int svg_cell_pixels;              /* the SVG's basin raster repeats each cell up to this
                                         many pixels a side, about twice the pixels it
                                         covers (0, 1: once): for readers that smooth images
                                         (librsvg, render/pdf.h) */
} cm_render_options;

/* What was drawn: for provenance, tests and benchmarks. */
typedef struct cm_render_info {
    int plot_x, plot_y, plot_w, plot_h;     /* the basin panel's pixels, row 0 at the top */
    double lo[2], hi[2];                    /* the state rectangle it shows */
    int graph_x, graph_y, graph_w, graph_h; /* 1-D models: the graph panel (x_j, x_j+1 both
                                               over lo[0]..hi[0]); else all 0 */
    int tiles;                              /* GL tiles drawn */
    int overlays_truncated;                 /* the model had more overlays than were drawn */
    double raster_s, gl_s, text_s;          /* seconds: cells to colours, the plot drawn (the
                                               raster, GL's lines), labels */
} cm_render_info;

/* Checks, before anything is computed, that an image of these options can
 * be drawn (size, font, and room for the plot beside the text layers of a
 * view of o->lo..o->hi in a model of dimension dim); cm_render_figure may
 * still find a legend too wide for it. Loads OSMesa (render/gl_loader.h)
 * when the figure draws with GL (cm_plot_needs_gl), so that a missing
 * library stops a command before its work. */
cm_status cm_render_check(const cm_render_options *o, int dim, char *msg, size_t msg_size);

cm_status cm_render_figure(const cm_lattice *lat, const cm_region *r, const cm_group_info *groups,
                           const cm_render_options *opt, uint8_t *rgba, cm_render_info *info,
                           char *msg, size_t msg_size);

#endif
