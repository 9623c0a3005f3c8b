/* render/palette.h - colours of basins. A group's colour follows from its
 * identity (its anchor cell), not from its id, so re-solving keeps colours. */
#ifndef CM_RENDER_PALETTE_H
#define CM_RENDER_PALETTE_H

#include <stdint.h>

#include "cellmap/scm.h"

typedef struct cm_rgb {
    uint8_t r, g, b;
} cm_rgb;

extern const cm_rgb cm_colour_sink;            /* transient to the sink (red, as the thesis) */
extern const cm_rgb cm_colour_not_computed;    /* cells outside every region */
extern const cm_rgb cm_colour_marker;          /* periodic cells (black dots) */
extern const cm_rgb cm_colour_sticking;        /* basins of sticking zones (grey, Fig. 4.30) */
extern const cm_rgb cm_colour_sticking_marker; /* the sticking zones' rest cells */

/* Colours of groups 1..n (entry k for group k+1). Sticking zones are grey;
 * every other group takes the palette
 * colour its anchor hashes to, or the next one not yet taken by a group with
 * a smaller anchor, so up to the palette size all groups differ. */
void cm_palette_assign(const cm_group_info *groups, uint32_t n, int dim, cm_rgb *colours);

#endif
