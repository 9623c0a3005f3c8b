/* render/figure_parts.h - what cm_render_figure and cm_render_svg share:
 * the figure prepared before anything is drawn (raster, overlays, font,
 * margins, legend, panels). Internal to render/. */
#ifndef CM_RENDER_FIGURE_PARTS_H
#define CM_RENDER_FIGURE_PARTS_H

#include <stdbool.h>

#include "render/axes.h"
#include "render/figure.h"
#include "render/palette.h"
#include "render/plot.h"
#include "render/raster.h"
#include "render/text.h"

enum { LABEL = 96 }; /* characters of a legend line */

typedef struct entry {
    char text[LABEL];
    cm_rgb swatch;
    bool has_swatch;
    uint32_t group; /* the group whose colour the swatch shows (0: a fixed colour) */
} entry;

typedef struct legend {
    int n;
    entry *e;
    int bar_mode; /* a colour bar of step numbers below the entries: the raster
                     mode (CM_RASTER_SHADED or _STEPS), or -1 for none */
} legend;

enum { BAR_LINES = 7 }; /* lines of the legend a step bar takes */
#define BAR_TITLE "step number"

/* The grey of the step bar at fraction f (0: no steps, 1: the cap). */
uint8_t figure_bar_grey(int mode, double f);

enum { TITLE_LINES = 6 }; /* a title wraps onto at most this many lines */

typedef struct layout {
    int fs, pad, tick, line, ascent;
    int left, right, top, bottom;
    cm_ticks tx, ty;
    const char *xname, *yname;
    char yname_buf[64];
    char title[TITLE_LINES][256]; /* the title's lines, wrapped to the image's width */
    int title_lines;
} layout;

typedef struct work {
    cm_raster ras;
    cm_overlay_list ov;
    cm_font *font;
    legend lg;
} work;

/* A figure ready to draw: options with defaults filled in, the view, the
 * raster, overlays, font, layout, legend and the plot's panels. */
typedef struct figure {
    cm_render_options o;
    cm_slice s;
    double lo[2], hi[2];
    work w;
    layout L;
    cm_plot p;
} figure;

/* Prepares the figure of these options; figure_end frees it (also after
 * a failure). */
cm_status figure_begin(const cm_lattice *lat, const cm_region *r, const cm_group_info *groups,
                       const cm_render_options *opt, figure *F, char *msg, size_t msg_size);
void figure_end(figure *F);

/* The model and its parameters, for the title (a flow's integrator
 * settings left to the provenance). */
void figure_title(const cm_model *m, char *out, size_t size);

#endif
