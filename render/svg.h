/* render/svg.h - a figure as SVG: the same layout as cm_render_figure, with
 * the basin raster embedded as a PNG of one pixel per cell of the view and
 * everything else - frame, ticks, labels, legend, title, overlays, the
 * attractors' cells, the 1-D map's graph - as SVG text and paths, so the
 * figure scales in a paper. Needs no OpenGL. */
#ifndef CM_RENDER_SVG_H
#define CM_RENDER_SVG_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "render/figure.h"

/* Writes the figure of these options (as cm_render_figure draws it) to f. */
cm_status cm_render_svg(const cm_lattice *lat, const cm_region *r, const cm_group_info *groups,
                        const cm_render_options *opt, FILE *f, char *msg, size_t msg_size);

/* Helpers the charts' SVG shares (render/chart.h): text with &, < and >
 * escaped; bytes in base64 (embedded PNGs). */
void cm_svg_escaped(FILE *f, const char *s);
void cm_svg_base64(FILE *f, const uint8_t *b, size_t n);

#endif
