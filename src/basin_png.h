/* src/basin_png.h - the basin PNG that solve and explore write: the image
 * of a flattened region with the provenance text chunks. */
#ifndef CM_SRC_BASIN_PNG_H
#define CM_SRC_BASIN_PNG_H

#include "cellmap/model.h"
#include "cellmap/scm.h"

typedef struct basin_png {
    const char *path;
    const cm_model *model;
    const cm_lattice *lat;
    const cm_region *cells;      /* the cells to draw (group, step) */
    const cm_group_info *groups; /* the groups' summaries, for the colours */
    int width, height;           /* 0: one pixel per cell, at most 4096 */
    double lo[2], hi[2];         /* view in state coordinates; all 0: the cells' box */
} basin_png;

/* Renders and writes the PNG (temporary file, then rename). Prints
 * "cellmap CMD: problem" and returns EXIT_FAIL on failure. */
int write_basin_png(const char *cmd, const basin_png *b);

/* The default size of an image of the box: one pixel per cell, scaled
 * down so that neither side exceeds 4096. */
void default_image_size(const cm_lattice *lat, const cm_box *box, int *width, int *height);

/* The box in state coordinates, "x0:x1,y0:y1,...". */
void format_box(const cm_lattice *lat, const cm_box *box, char *out, size_t size);

#endif
