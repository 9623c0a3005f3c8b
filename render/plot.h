/* render/plot.h - the plot of a figure: the basin raster, the attractor
 * markers, the model's overlays and, for 1-D models, the map's graph with a
 * cobweb of each attractor.
 *
 * The raster is drawn on the CPU, at the pixels GL gives a texture
 * (render/quads.h), and so are the markers when nothing else is drawn: a
 * figure without lines needs no GL. The lines and points (overlays, the
 * 1-D graph) are drawn off-screen with OSMesa or EGL (render/gl.h) onto a
 * transparent tile, with the markers between them, and laid over the
 * plot. GL draws in
 * tiles of at most CM_PLOT_TILE pixels a side, each projecting the whole
 * panel as one tile would (only the window offset differs: lines land on
 * the same pixels; in a 3000-pixel 1-D graph one dot of 9 million moved),
 * so the figure may be larger than
 * the largest viewport, and Mesa's buffer stays small: it is new memory
 * for every context, and on a VM whose page faults cost 10 us a 2918 x
 * 3839 buffer took 120 ms to touch (issue 51; 12 tiles of 1024 take 48 ms
 * in all). Everything goes straight into the plot's
 * rectangle of the caller's RGBA figure (row 0 at the top). Deterministic:
 * the tiling depends on sizes only. Not thread-safe (one GL context at a
 * time per thread).
 */
#ifndef CM_RENDER_PLOT_H
#define CM_RENDER_PLOT_H

#include <stdbool.h>
#include <stdint.h>

#include "cellmap/model.h"
#include "render/gl.h"
#include "render/raster.h"

enum { CM_PLOT_TILE = 1024 };

/* Layers of a figure (render options and the command line's --layers). */
enum cm_layer {
    CM_LAYER_BASIN = 1 << 0,
    CM_LAYER_STEPS = 1 << 1, /* with BASIN: shading; alone: step numbers only */
    CM_LAYER_ATTRACTORS = 1 << 2,
    CM_LAYER_OVERLAYS = 1 << 3,
    CM_LAYER_AXES = 1 << 4,
    CM_LAYER_LEGEND = 1 << 5,
    CM_LAYER_TITLE = 1 << 6
};
/* Switching lines are white over basins and step shading, and black on
 * paper: where neither is drawn (Fig. 4.34), and on a map's graph. */
static inline bool cm_layers_on_paper(unsigned layers)
{
    return !(layers & (CM_LAYER_BASIN | CM_LAYER_STEPS));
}

/* The layers drawn with text, which need a font and margins. */
#define CM_LAYERS_TEXT (CM_LAYER_AXES | CM_LAYER_LEGEND | CM_LAYER_TITLE)

/* A rectangle of pixels (relative to the plot, row 0 at the top) showing a
 * rectangle of state space. */
typedef struct cm_panel {
    int x, y, w, h;
    double lo[2], hi[2];
} cm_panel;

typedef struct cm_plot {
    const cm_raster *ras;
    const cm_group_info *groups;     /* ids 1..n */
    const cm_overlay_list *overlays; /* NULL: none */
    const cm_model *model;           /* for the 1-D graph */
    unsigned layers;
    int x, y, w, h; /* the plot's rectangle in the figure */
    cm_panel basin; /* where the cells go */
    cm_panel graph; /* 1-D models: the map's graph (w == 0: none) */
    int line_width; /* pixels */
    double marker;  /* pixels: the least side of a periodic cell's square (>= 3) */
    cm_gl *gl;      /* the context to draw with; NULL: one of its own when needed */
} cm_plot;

/* Whether a plot of these layers of model m (NULL: none) of dimension dim
 * may draw with GL: the model's overlays and a 1-D map's graph. */
bool cm_plot_needs_gl(unsigned layers, const cm_model *m, int dim);

/* Draws the plot into rgba, a figure of fig_width columns (and at least
 * y + h rows). Returns the number of GL tiles drawn in *tiles. */
cm_status cm_plot_draw(const cm_plot *p, uint8_t *rgba, int fig_width, int *tiles, char *msg,
                       size_t msg_size);

#endif
