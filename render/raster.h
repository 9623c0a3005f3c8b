/* render/raster.h - the cells of a view's 2-D slice as colours or colour
 * classes, computed on the CPU in parallel before anything is drawn.
 *
 * The slice is dimensions 0 and 1 of a region (one row for 1-D models)
 * through a point of the other dimensions. The raster also collects what the
 * figure needs besides pixels: the periodic cells (drawn as markers), the
 * cells of each group in the slice (the legend's basin shares) and the step
 * number that the shading saturates at.
 */
#ifndef CM_RENDER_RASTER_H
#define CM_RENDER_RASTER_H

#include <stdint.h>

#include "cellmap/scm.h"
#include "render/palette.h"

typedef struct cm_slice {
    uint64_t nx, ny;       /* cells in dims 0 and 1 (ny = 1 for 1-D) */
    uint64_t base;         /* local index of the slice's first cell */
    uint64_t row_stride;   /* local index step along dim 1 */
    double x0, y0, dx, dy; /* state coordinates of the lower corner, cell size */
} cm_slice;

/* The slice through slice[d] (cells, dims >= 2) or, when !set_slice, the
 * middle of the region. */
void cm_slice_of(const cm_lattice *lat, const cm_region *r, const int64_t *slice, int set_slice,
                 cm_slice *out);

typedef struct cm_periodic_cell {
    uint32_t i, j;  /* slice coordinates */
    uint32_t group; /* its group id */
} cm_periodic_cell;

enum cm_raster_mode {
    CM_RASTER_BASIN,  /* group colours */
    CM_RASTER_SHADED, /* group colours darkened with the step number */
    CM_RASTER_STEPS,  /* the step number only, light (short) to dark (long) */
    CM_RASTER_CLASSES /* colour classes (an indexed image), periodic cells marked */
};

typedef struct cm_raster {
    cm_slice s;
    const cm_region *cells; /* the region it shows (borrowed) */
    uint8_t *pixels; /* nx*ny*3 RGB, or nx*ny classes; row 0 is the lowest;
                        NULL until cm_raster_paint */
    uint8_t *rgb;    /* RGB of each group ([0] the sink), from cm_raster_choose */
    uint16_t *shade; /* shade of each step number 0..step_cap, from cm_raster_choose */
    cm_periodic_cell *periodic;
    uint64_t nperiodic;
    uint64_t *group_cells; /* cells of each group in the slice; [0] the sink */
    uint64_t computed;     /* cells of the slice inside the regions */
    uint32_t step_cap;     /* step numbers from here up are shaded darkest */
    uint8_t *classes;      /* class of each group; [0] the sink */
    uint64_t min_basin;    /* groups with smaller basins are drawn as "other" */
    uint32_t other_groups; /* groups in the slice drawn as "other" */
    uint64_t other_cells;  /* their cells in the slice */
    uint32_t colour_repeats; /* coloured groups in the slice beyond the palette's size */
    const cm_palette *palette; /* the group colours (NULL: the default) */
    int mode;                  /* enum cm_raster_mode */
} cm_raster;

/* The step shading (logarithmic: transients are mostly short, and the eye
 * compares ratios) at fraction f in [0, 1] of log(1 + step) / log(1 +
 * step_cap): a factor in 1/256 that darkens group colours (CM_RASTER_SHADED)
 * or a grey level (CM_RASTER_STEPS). */
uint16_t cm_step_shade(double f, int mode);
/* The step number at fraction f of that scale. */
uint32_t cm_step_at(double f, uint32_t step_cap);

/* A raster in steps, because the colours depend on which basins touch
 * in the figure and that on the figure's layout, which the legend (the
 * counts) decides: cm_raster_build counts the cells of each group, decides
 * which are drawn as "other" (basins of fewer than min_basin cells,
 * render/palette.h), the colour repeats and the periodic cells, and gives
 * provisional colours (no neighbour rule); cm_raster_choose then chooses
 * the colours with basins kept apart where their cells lie up to reach_x,
 * reach_y cells apart (cm_touching_reach of the cells and pixels drawn; 1,
 * 1 for one pixel per cell), after which cm_raster_rgb gives any cell's
 * colour; cm_raster_paint chooses and fills the pixels. Which groups are
 * "other" and the counts stay as built. Deterministic whatever the thread
 * count. On failure the raster is left to cm_raster_free. The region must
 * outlive the raster. */
cm_status cm_raster_build(const cm_lattice *lat, const cm_region *r, const cm_group_info *groups,
                          const cm_slice *s, int mode, uint64_t min_basin,
                          const cm_palette *palette, cm_raster *out, char *msg, size_t msg_size);
cm_status cm_raster_choose(const cm_lattice *lat, const cm_region *r, const cm_group_info *groups,
                           uint32_t reach_x, uint32_t reach_y, cm_raster *ras, char *msg,
                           size_t msg_size);
cm_status cm_raster_paint(const cm_lattice *lat, const cm_region *r, const cm_group_info *groups,
                          uint32_t reach_x, uint32_t reach_y, cm_raster *ras, char *msg,
                          size_t msg_size);
void cm_raster_free(cm_raster *ras);

/* The colour of local cell k of the raster's region in an RGB mode (not
 * CM_RASTER_CLASSES), after cm_raster_choose: p[0..2]. */
void cm_raster_rgb(const cm_raster *ras, uint64_t k, uint8_t *p);

/* The colours of n cells of one row, local cells line + col[c] (none where
 * col[c] < 0: that pixel is left as it is), into px + 4 c: a row of RGBA
 * pixels, opaque, as cm_raster_rgb gives each (one call a row, not a
 * pixel). */
void cm_raster_row_rgba(const cm_raster *ras, uint64_t line, const int64_t *col, int n,
                        uint8_t *px);

#endif
