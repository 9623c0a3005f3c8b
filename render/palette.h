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

/* Colour classes: the figure's colours, numbered. An indexed PNG stores
 * the class of each cell; its palette is cm_class_colour of each class. */
enum cm_colour_class {
    CM_CLASS_NOT_COMPUTED = 0,
    CM_CLASS_SINK,
    CM_CLASS_MARKER,          /* periodic cells of attractors */
    CM_CLASS_STICKING,        /* basins of sticking zones */
    CM_CLASS_STICKING_MARKER, /* rest cells of sticking zones */
    CM_CLASS_FIRST_GROUP      /* then one class per categorical colour */
};
int cm_class_count(void);
cm_rgb cm_class_colour(int cls);

/* Classes of groups 1..n (entry k for group k+1). Sticking zones are grey;
 * every other group takes the palette colour its anchor hashes to, or the
 * next one not yet taken by a group with a smaller anchor, so up to the
 * palette size all groups differ. */
void cm_palette_classes(const cm_group_info *groups, uint32_t n, int dim, uint8_t *classes);

#endif
