#include "render/basin.h"

#include <GL/osmesa.h>
#include <stdlib.h>
#include <string.h>

#include "render/palette.h"

enum { TILE = 2048 }; /* texture tile edge in cells; below every GL's maximum */

typedef struct slice_geometry {
    uint64_t nx, ny;       /* cells of the region in dims 0 and 1 (ny = 1 for 1-D) */
    uint64_t base;         /* local index of cell (lo0, lo1, slice...) */
    uint64_t row_stride;   /* local index step along dim 1 */
    double x0, y0, dx, dy; /* state coordinates of the slice's lower corner, cell size */
} slice_geometry;

static void make_geometry(const cm_lattice *lat, const cm_region *r, const cm_render_options *opt,
                          slice_geometry *g)
{
    const cm_box *b = &r->box;
    int64_t cell[CM_MAX_DIM];
    for (int d = 0; d < b->dim; d++)
        cell[d] = d >= 2 && opt->set_slice ? opt->slice[d] : b->lo[d] + (b->hi[d] - b->lo[d]) / 2;
    cell[0] = b->lo[0];
    if (b->dim > 1)
        cell[1] = b->lo[1];
    g->nx = (uint64_t)(b->hi[0] - b->lo[0]);
    g->ny = b->dim > 1 ? (uint64_t)(b->hi[1] - b->lo[1]) : 1;
    g->base = cm_box_index(b, cell);
    g->row_stride = g->nx;
    g->x0 = lat->origin[0] + (double)b->lo[0] * lat->width[0];
    g->dx = lat->width[0];
    g->y0 = b->dim > 1 ? lat->origin[1] + (double)b->lo[1] * lat->width[1] : 0.0;
    g->dy = b->dim > 1 ? lat->width[1] : 1.0;
}

/* Colour of one cell of the slice. */
static cm_rgb cell_colour(const cm_region *r, const cm_rgb *colours, uint64_t index)
{
    const uint32_t grp = r->group[index];
    if (grp == CM_GROUP_NONE)
        return cm_colour_not_computed;
    return grp == 0 ? cm_colour_sink : colours[grp - 1];
}

/* Draws one texture tile of cells [i0, i0+w) x [j0, j0+h) of the slice. */
static void draw_tile(const cm_region *r, const slice_geometry *g, const cm_rgb *colours,
                      uint64_t i0, uint64_t j0, uint64_t w, uint64_t h, uint8_t *texels)
{
    for (uint64_t j = 0; j < h; j++)
        for (uint64_t i = 0; i < w; i++) {
            const cm_rgb c = cell_colour(r, colours, g->base + (j0 + j) * g->row_stride + i0 + i);
            uint8_t *t = texels + 3 * (j * w + i);
            t[0] = c.r;
            t[1] = c.g;
            t[2] = c.b;
        }
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB, (GLsizei)w, (GLsizei)h, 0, GL_RGB, GL_UNSIGNED_BYTE,
                 texels);
    const double x0 = g->x0 + (double)i0 * g->dx, x1 = x0 + (double)w * g->dx;
    const double y0 = g->y0 + (double)j0 * g->dy, y1 = y0 + (double)h * g->dy;
    glBegin(GL_QUADS);
    glTexCoord2d(0, 0);
    glVertex2d(x0, y0);
    glTexCoord2d(1, 0);
    glVertex2d(x1, y0);
    glTexCoord2d(1, 1);
    glVertex2d(x1, y1);
    glTexCoord2d(0, 1);
    glVertex2d(x0, y1);
    glEnd();
}

static cm_status draw_raster(const cm_region *r, const slice_geometry *g, const cm_rgb *colours,
                             char *msg, size_t msg_size)
{
    uint8_t *texels = malloc(3 * (size_t)TILE * TILE);
    if (!texels)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for texture tiles");
    GLuint tex = 0;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glEnable(GL_TEXTURE_2D);
    glColor3ub(255, 255, 255);
    for (uint64_t j0 = 0; j0 < g->ny; j0 += TILE)
        for (uint64_t i0 = 0; i0 < g->nx; i0 += TILE)
            draw_tile(r, g, colours, i0, j0, g->nx - i0 < TILE ? g->nx - i0 : TILE,
                      g->ny - j0 < TILE ? g->ny - j0 : TILE, texels);
    glDisable(GL_TEXTURE_2D);
    glDeleteTextures(1, &tex);
    free(texels);
    return CM_OK;
}

/* The periodic cells of the groups of one kind as squares of at least 3x3
 * pixels. */
static void draw_markers(const cm_region *r, const cm_group_info *groups, int kind,
                         const slice_geometry *g, double px, double py)
{
    const double hx = g->dx / 2 > 1.5 * px ? g->dx / 2 : 1.5 * px;
    const double hy = g->dy / 2 > 1.5 * py ? g->dy / 2 : 1.5 * py;
    const cm_rgb c = kind == CM_GROUP_STICKING ? cm_colour_sticking_marker : cm_colour_marker;
    glColor3ub(c.r, c.g, c.b);
    glBegin(GL_QUADS);
    for (uint64_t j = 0; j < g->ny; j++)
        for (uint64_t i = 0; i < g->nx; i++) {
            const uint64_t k = g->base + j * g->row_stride + i;
            if (!cm_is_periodic(r, k) || groups[r->group[k] - 1].kind != kind)
                continue;
            const double cx = g->x0 + ((double)i + 0.5) * g->dx;
            const double cy = g->y0 + ((double)j + 0.5) * g->dy;
            glVertex2d(cx - hx, cy - hy);
            glVertex2d(cx + hx, cy - hy);
            glVertex2d(cx + hx, cy + hy);
            glVertex2d(cx - hx, cy + hy);
        }
    glEnd();
}

cm_status cm_render_basin(const cm_lattice *lat, const cm_region *r, const cm_group_info *groups,
                          const cm_render_options *opt, uint8_t *rgba, char *msg, size_t msg_size)
{
    if (opt->width < 1 || opt->height < 1)
        return cm_fail(CM_EINVAL, msg, msg_size, "image size must be at least 1x1");
    slice_geometry g;
    make_geometry(lat, r, opt, &g);
    double lo[2] = {opt->lo[0], opt->lo[1]}, hi[2] = {opt->hi[0], opt->hi[1]};
    if (lo[0] == hi[0]) { /* default view: the whole region */
        lo[0] = g.x0;
        hi[0] = g.x0 + (double)g.nx * g.dx;
    }
    if (lo[1] == hi[1] || r->box.dim == 1) {
        lo[1] = g.y0;
        hi[1] = g.y0 + (double)g.ny * g.dy;
    }
    cm_rgb *colours = malloc((r->ngroups + 1) * sizeof *colours);
    if (!colours)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for colours");
    cm_palette_assign(groups, r->ngroups, lat->dim, colours);

    OSMesaContext ctx = OSMesaCreateContextExt(OSMESA_RGBA, 0, 0, 0, NULL);
    if (!ctx) {
        free(colours);
        return cm_fail(CM_ERENDER, msg, msg_size, "cannot create an OSMesa context");
    }
    cm_status st = CM_OK;
    GLint max_w = 0, max_h = 0;
    if (!OSMesaMakeCurrent(ctx, rgba, GL_UNSIGNED_BYTE, opt->width, opt->height)) {
        st = cm_fail(CM_ERENDER, msg, msg_size, "OSMesaMakeCurrent failed for %dx%d", opt->width,
                     opt->height);
    } else {
        OSMesaGetIntegerv(OSMESA_MAX_WIDTH, &max_w);
        OSMesaGetIntegerv(OSMESA_MAX_HEIGHT, &max_h);
        if (opt->width > max_w || opt->height > max_h)
            st = cm_fail(CM_ERENDER, msg, msg_size, "image %dx%d exceeds OSMesa's %dx%d",
                         opt->width, opt->height, max_w, max_h);
    }
    if (st == CM_OK) {
        OSMesaPixelStore(OSMESA_Y_UP, 0); /* row 0 at the top, as PNG wants */
        glViewport(0, 0, opt->width, opt->height);
        glMatrixMode(GL_PROJECTION);
        glLoadIdentity();
        glOrtho(lo[0], hi[0], lo[1], hi[1], -1, 1);
        glMatrixMode(GL_MODELVIEW);
        glLoadIdentity();
        const cm_rgb bg = cm_colour_not_computed;
        glClearColor(bg.r / 255.0f, bg.g / 255.0f, bg.b / 255.0f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
        st = draw_raster(r, &g, colours, msg, msg_size);
        const double px = (hi[0] - lo[0]) / opt->width, py = (hi[1] - lo[1]) / opt->height;
        /* attractors last: their black dots stay visible beside sticking zones */
        if (st == CM_OK && opt->markers) {
            draw_markers(r, groups, CM_GROUP_STICKING, &g, px, py);
            draw_markers(r, groups, CM_GROUP_ATTRACTOR, &g, px, py);
        }
        glFinish(); /* the buffer is complete only now */
        if (glGetError() != GL_NO_ERROR && st == CM_OK)
            st = cm_fail(CM_ERENDER, msg, msg_size, "OpenGL reported an error while drawing");
    }
    OSMesaDestroyContext(ctx);
    free(colours);
    return st;
}
