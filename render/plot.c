#include "render/plot.h"

#include <GL/gl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/gl.h"
#include "render/palette.h"
#include "render/quads.h"

enum { TEX_TILE = 2048, COBWEBS = 12, CIRCLE_SIDES = 24 };

static const cm_rgb switching_colour = {255, 255, 255};
static const cm_rgb manifold_colour = {0, 0, 0};
static const cm_rgb zone_colour = {40, 40, 40};
static const cm_rgb diagonal_colour = {150, 150, 150};
static const cm_rgb graph_colour = {0, 0, 0};

static void colour(cm_rgb c) { glColor3ub(c.r, c.g, c.b); }

/* ---- the part of a panel inside one tile ----------------------------------- */

typedef struct tile {
    int x, y, w, h; /* pixels of the plot */
} tile;

/* The state coordinate k pixels of n into [lo, hi]; exact at both ends so
 * an untiled plot maps its panel exactly onto the view. */
static double at_pixel(double lo, double hi, int k, int n)
{
    return k == 0 ? lo : k == n ? hi : lo + (hi - lo) * k / n;
}

/* Sets viewport, scissor and projection so that GL draws the part of the
 * panel inside the tile. False when they do not meet. The viewport is the
 * whole panel, shifted by the tile's offset, and the scissor the part in
 * the tile: every tile projects the panel as one tile would, so tiles
 * rasterise the lines at the same pixels (render/plot.h). A panel wider
 * than GL's largest viewport is projected part by part instead. */
static bool enter_panel(const cm_gl *gl, const cm_panel *pn, const tile *t, double *px,
                        double *py)
{
    const int x0 = pn->x > t->x ? pn->x : t->x, y0 = pn->y > t->y ? pn->y : t->y;
    const int x1 = pn->x + pn->w < t->x + t->w ? pn->x + pn->w : t->x + t->w;
    const int y1 = pn->y + pn->h < t->y + t->h ? pn->y + pn->h : t->y + t->h;
    if (x0 >= x1 || y0 >= y1)
        return false;
    *px = (pn->hi[0] - pn->lo[0]) / pn->w; /* state units per pixel */
    *py = (pn->hi[1] - pn->lo[1]) / pn->h;
    GLint most[2];
    glGetIntegerv(GL_MAX_VIEWPORT_DIMS, most);
    const cm_gl_rect part = {x0 - t->x, y0 - t->y, x1 - x0, y1 - y0};
    const bool whole = pn->w <= most[0] && pn->h <= most[1];
    const cm_gl_rect view = whole ? (cm_gl_rect){pn->x - t->x, pn->y - t->y, pn->w, pn->h} : part;
    cm_gl_window(gl, &view, &part);
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    if (whole)
        glOrtho(pn->lo[0], pn->hi[0], pn->lo[1], pn->hi[1], -1, 1);
    else
        glOrtho(at_pixel(pn->lo[0], pn->hi[0], x0 - pn->x, pn->w),
                at_pixel(pn->lo[0], pn->hi[0], x1 - pn->x, pn->w),
                at_pixel(pn->hi[1], pn->lo[1], y1 - pn->y, pn->h),
                at_pixel(pn->hi[1], pn->lo[1], y0 - pn->y, pn->h), -1, 1);
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    return true;
}

/* ---- basin raster and markers, on the CPU ------------------------------------- */

/* The panel's axes as GL's projection shows them (render/quads.h). */
static cm_quad_axis axis_x(const cm_panel *pn)
{
    return (cm_quad_axis){pn->lo[0], pn->hi[0], pn->w};
}

static cm_quad_axis axis_y(const cm_panel *pn)
{
    return (cm_quad_axis){pn->lo[1], pn->hi[1], pn->h};
}

/* The pixel of the panel at column c and window row b (rows from the bottom). */
static uint8_t *panel_pixel(const cm_plot *p, const cm_panel *pn, uint8_t *rgba, int fig_width,
                            int c, int b)
{
    const size_t y = (size_t)(p->y + pn->y + pn->h - 1 - b), x = (size_t)(p->x + pn->x + c);
    return rgba + 4 * (y * (size_t)fig_width + x);
}

static void put(uint8_t *px, cm_rgb c)
{
    px[0] = c.r, px[1] = c.g, px[2] = c.b, px[3] = 255;
}

/* The plot's background: what GL's clear gave, the colour of cells not
 * computed. */
static void fill_plot(const cm_plot *p, uint8_t *rgba, int fig_width)
{
#pragma omp parallel for schedule(static)
    for (int y = 0; y < p->h; y++)
        for (int x = 0; x < p->w; x++)
            put(rgba + 4 * ((size_t)(p->y + y) * (size_t)fig_width + (size_t)(p->x + x)),
                cm_colour_not_computed);
}

/* The cells [i0, i1) of n along one axis that show in the state range
 * [lo, hi], rounded outwards to whole texture tiles (the quads GL drew). */
static void visible_cells(double origin, double width, uint64_t n, double lo, double hi,
                          uint64_t *i0, uint64_t *i1)
{
    double a = floor((lo - origin) / width) - 1, b = ceil((hi - origin) / width) + 1;
    a = a < 0 ? 0 : a > (double)n ? (double)n : a;
    b = b < 0 ? 0 : b > (double)n ? (double)n : b;
    *i0 = (uint64_t)a / TEX_TILE * TEX_TILE;
    *i1 = (uint64_t)b;
}

/* The cell shown at each pixel of one axis (-1: none), the raster's tiles
 * of TEX_TILE cells each one quad as GL drew them. */
static void cells_of_pixels(const cm_quad_axis *ax, double origin, double width, uint64_t i0,
                            uint64_t i1, int64_t *cell)
{
    for (int k = 0; k < ax->n; k++)
        cell[k] = -1;
    for (uint64_t i = i0; i < i1; i += TEX_TILE) {
        const uint64_t n = i1 - i < TEX_TILE ? i1 - i : TEX_TILE;
        const double a = origin + (double)i * width;
        cm_quad_texels(ax, a, a + (double)n * width, n, (int64_t)i, cell);
    }
}

static cm_status draw_raster(const cm_plot *p, uint8_t *rgba, int fig_width, char *msg,
                             size_t msg_size)
{
    const cm_panel *pn = &p->basin;
    const cm_slice *s = &p->ras->s;
    uint64_t i0, i1, j0, j1;
    visible_cells(s->x0, s->dx, s->nx, pn->lo[0], pn->hi[0], &i0, &i1);
    visible_cells(s->y0, s->dy, s->ny, pn->lo[1], pn->hi[1], &j0, &j1);
    if (s->ny == 1) { /* a 1-D strip fills its panel's height */
        j0 = 0;
        j1 = 1;
    }
    int64_t *col = malloc((size_t)pn->w * sizeof *col), *row = malloc((size_t)pn->h * sizeof *row);
    int *blank = malloc((size_t)pn->w * sizeof *blank); /* the columns that show no cell */
    if (!col || !row || !blank) {
        free(col);
        free(row);
        free(blank);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the raster's pixels");
    }
    const cm_quad_axis ax = axis_x(pn), ay = axis_y(pn);
    cells_of_pixels(&ax, s->x0, s->dx, i0, i1, col);
    cells_of_pixels(&ay, s->y0, s->dy, j0, j1, row);
    int nblank = 0;
    for (int c = 0; c < pn->w; c++)
        if (col[c] < 0)
            blank[nblank++] = c;
#pragma omp parallel for schedule(static)
    for (int b = 0; b < pn->h; b++) { /* every pixel of the panel: a cell's, or the background */
        uint8_t *px = panel_pixel(p, pn, rgba, fig_width, 0, b);
        if (row[b] < 0) {
            for (int c = 0; c < pn->w; c++)
                put(px + 4 * (size_t)c, cm_colour_not_computed);
            continue;
        }
        cm_raster_row_rgba(p->ras, s->base + (uint64_t)row[b] * s->row_stride, col, pn->w, px);
        for (int k = 0; k < nblank; k++)
            put(px + 4 * (size_t)blank[k], cm_colour_not_computed);
    }
    free(col);
    free(row);
    free(blank);
    return CM_OK;
}

/* Periodic cells are squares of at least p->marker pixels a side, so
 * that a one-cell attractor stays visible at any zoom: their half sides in
 * state units. */
static void marker_half_sides(const cm_plot *p, double *hx, double *hy)
{
    const cm_panel *pn = &p->basin;
    const cm_slice *s = &p->ras->s;
    const double px = (pn->hi[0] - pn->lo[0]) / pn->w, py = (pn->hi[1] - pn->lo[1]) / pn->h;
    const double least = p->marker / 2;
    *hx = s->dx / 2 > least * px ? s->dx / 2 : least * px;
    *hy = s->ny == 1               ? (pn->hi[1] - pn->lo[1]) / 2
          : s->dy / 2 > least * py ? s->dy / 2
                                   : least * py;
}

/* The square of periodic cell c in state coordinates: x0, x1, y0, y1. */
static void marker_square(const cm_plot *p, const cm_periodic_cell *c, double hx, double hy,
                          double q[4])
{
    const cm_panel *pn = &p->basin;
    const cm_slice *s = &p->ras->s;
    const double cx = s->x0 + ((double)c->i + 0.5) * s->dx;
    const double cy =
        s->ny == 1 ? (pn->lo[1] + pn->hi[1]) / 2 : s->y0 + ((double)c->j + 0.5) * s->dy;
    q[0] = cx - hx, q[1] = cx + hx, q[2] = cy - hy, q[3] = cy + hy;
}

static cm_rgb marker_colour(int kind)
{
    return kind == CM_GROUP_STICKING ? cm_colour_sticking_marker : cm_colour_marker;
}

/* The markers of one kind of group, on the CPU (when GL draws nothing
 * else; else gl_markers). */
static void cpu_markers(const cm_plot *p, int kind, uint8_t *rgba, int fig_width)
{
    double hx, hy, q[4];
    marker_half_sides(p, &hx, &hy);
    const cm_quad_axis ax = axis_x(&p->basin), ay = axis_y(&p->basin);
    for (uint64_t k = 0; k < p->ras->nperiodic; k++) {
        const cm_periodic_cell *c = &p->ras->periodic[k];
        if (p->groups[c->group - 1].kind != kind)
            continue;
        marker_square(p, c, hx, hy, q);
        int x0, x1, y0, y1;
        cm_quad_span(&ax, q[0], q[1], &x0, &x1);
        cm_quad_span(&ay, q[2], q[3], &y0, &y1);
        for (int b = y0; b < y1; b++)
            for (int x = x0; x < x1; x++)
                put(panel_pixel(p, &p->basin, rgba, fig_width, x, b), marker_colour(kind));
    }
}

/* The same with GL, between the overlays' lines and points. */
static void gl_markers(const cm_plot *p, int kind)
{
    double hx, hy, q[4];
    marker_half_sides(p, &hx, &hy);
    colour(marker_colour(kind));
    glBegin(GL_QUADS);
    for (uint64_t k = 0; k < p->ras->nperiodic; k++) {
        const cm_periodic_cell *c = &p->ras->periodic[k];
        if (p->groups[c->group - 1].kind != kind)
            continue;
        marker_square(p, c, hx, hy, q);
        glVertex2d(q[0], q[2]);
        glVertex2d(q[1], q[2]);
        glVertex2d(q[1], q[3]);
        glVertex2d(q[0], q[3]);
    }
    glEnd();
}

/* ---- overlays ------------------------------------------------------------------ */

static void draw_segments(const cm_overlay_list *ov, int kind, cm_rgb c, float width,
                          GLushort stipple, int factor)
{
    colour(c);
    glLineWidth(width);
    if (stipple) {
        glEnable(GL_LINE_STIPPLE);
        glLineStipple(factor, stipple);
    }
    glBegin(GL_LINES);
    for (size_t k = 0; k < ov->count; k++)
        if (ov->items[k].kind == kind) {
            glVertex2d(ov->items[k].a[0], ov->items[k].a[1]);
            glVertex2d(ov->items[k].b[0], ov->items[k].b[1]);
        }
    glEnd();
    glDisable(GL_LINE_STIPPLE);
    glLineWidth(1.0f);
}

/* A circle of r pixels around (x, y): filled, or a ring of the line width. */
static void draw_circle(double x, double y, double rx, double ry, bool filled, float width)
{
    if (filled) {
        glBegin(GL_POLYGON);
    } else {
        glLineWidth(width);
        glBegin(GL_LINE_LOOP);
    }
    for (int k = 0; k < CIRCLE_SIDES; k++) {
        const double a = 6.283185307179586 * k / CIRCLE_SIDES;
        glVertex2d(x + rx * cos(a), y + ry * sin(a));
    }
    glEnd();
    glLineWidth(1.0f);
}

/* The discs of point overlays, ringed black: regular fixed points white,
 * virtual ones only the ring (Figs. 4.13, 4.26); switching line collisions
 * red, higher-order ones orange (Figs. 4.34, 4.35). False: not a point. */
static bool point_style(int kind, bool *filled, cm_rgb *fill)
{
    *filled = kind != CM_OVERLAY_FIXED_VIRTUAL;
    *fill = kind == CM_OVERLAY_FIXED_REGULAR ? switching_colour
            : kind == CM_OVERLAY_COLLISION   ? cm_colour_collision
                                             : cm_colour_collision_higher;
    return kind == CM_OVERLAY_FIXED_REGULAR || kind == CM_OVERLAY_FIXED_VIRTUAL ||
           kind == CM_OVERLAY_COLLISION || kind == CM_OVERLAY_COLLISION_HIGHER;
}

static void draw_points(const cm_overlay_list *ov, double px, double py, int lw)
{
    const double r = 2.0 + 1.5 * lw;
    for (size_t k = 0; k < ov->count; k++) {
        const cm_overlay *o = &ov->items[k];
        bool filled;
        cm_rgb fill;
        if (!point_style(o->kind, &filled, &fill))
            continue;
        if (filled) {
            colour(fill);
            draw_circle(o->a[0], o->a[1], r * px, r * py, true, 0);
        }
        colour(manifold_colour);
        draw_circle(o->a[0], o->a[1], r * px, r * py, false, (float)lw);
    }
}

/* on_paper: see cm_layers_on_paper */
static void draw_overlay_lines(const cm_overlay_list *ov, int lw, bool on_paper)
{
    draw_segments(ov, CM_OVERLAY_REPELLER, cm_colour_repeller, (float)(3 * lw), 0, 1);
    draw_segments(ov, CM_OVERLAY_ESCAPE, cm_colour_escape, (float)(3 * lw), 0, 1);
    draw_segments(ov, CM_OVERLAY_STICKING_ZONE, zone_colour, (float)(2 * lw + 1), 0, 1);
    draw_segments(ov, CM_OVERLAY_SWITCHING_LINE, on_paper ? manifold_colour : switching_colour,
                  (float)lw, 0, 1);
    draw_segments(ov, CM_OVERLAY_UNSTABLE_MANIFOLD, manifold_colour, (float)lw, 0x00FF, 2 * lw);
    draw_segments(ov, CM_OVERLAY_STABLE_MANIFOLD, manifold_colour, (float)lw, 0x3333, 2 * lw);
}

/* ---- the 1-D graph -------------------------------------------------------------- */

/* The map's graph as dense dots: a micro-chaos map jumps at every level,
 * and dots show the jumps without drawing false vertical connectors. */
static void draw_graph(const cm_model *m, const cm_panel *pn, int lw)
{
    colour(diagonal_colour);
    glLineWidth((float)lw);
    glBegin(GL_LINES);
    glVertex2d(pn->lo[0], pn->lo[0]);
    glVertex2d(pn->hi[0], pn->hi[0]);
    glEnd();
    colour(graph_colour);
    glPointSize((float)lw);
    glBegin(GL_POINTS);
    const int samples = 8 * pn->w;
    for (int k = 0; k < samples; k++) {
        const double x = pn->lo[0] + (k + 0.5) * (pn->hi[0] - pn->lo[0]) / samples;
        double y;
        if (m->step(m, &x, &y) == CM_STEP_OK)
            glVertex2d(x, y);
    }
    glEnd();
    glPointSize(1.0f);
    glLineWidth(1.0f);
}

/* A cobweb from one periodic cell of each attractor (at most COBWEBS), in the
 * colour of its basin: (x, x) -> (x, f(x)) -> (f(x), f(x)) -> ... */
static void draw_cobwebs(const cm_plot *p, int lw)
{
    const cm_raster *ras = p->ras;
    uint32_t drawn[COBWEBS];
    int n = 0;
    glLineWidth((float)lw);
    for (uint64_t k = 0; k < ras->nperiodic && n < COBWEBS; k++) {
        const uint32_t g = ras->periodic[k].group;
        bool seen = p->groups[g - 1].kind != CM_GROUP_ATTRACTOR;
        for (int q = 0; q < n && !seen; q++)
            seen = drawn[q] == g;
        if (seen)
            continue;
        drawn[n++] = g;
        colour(cm_class_colour(ras->palette, ras->classes[g]));
        double x = ras->s.x0 + (ras->periodic[k].i + 0.5) * ras->s.dx;
        const uint32_t steps = 2 * p->groups[g - 1].period + 16;
        glBegin(GL_LINE_STRIP);
        glVertex2d(x, x);
        for (uint32_t t = 0; t < steps && t < 400; t++) {
            double y;
            if (p->model->step(p->model, &x, &y) != CM_STEP_OK)
                break;
            glVertex2d(x, y);
            glVertex2d(y, y);
            x = y;
        }
        glEnd();
    }
    glLineWidth(1.0f);
}

/* ---- GL's layers, tile by tile ------------------------------------------------- */

/* Whether GL has anything to draw: the model's overlays or a 1-D graph. */
static bool gl_draws(const cm_plot *p)
{
    return p->graph.w > 0 ||
           (p->overlays && p->overlays->count && (p->layers & CM_LAYER_OVERLAYS));
}

/* The overlays' lines, the markers over them, and the overlays' points
 * over those (a 1-D plot's overlays go on its graph). */
static void draw_basin_panel(const cm_gl *gl, const cm_plot *p, const tile *t)
{
    double px, py;
    if (!enter_panel(gl, &p->basin, t, &px, &py))
        return;
    const bool overlays = p->overlays && p->graph.w <= 0 && (p->layers & CM_LAYER_OVERLAYS);
    if (overlays)
        draw_overlay_lines(p->overlays, p->line_width, cm_layers_on_paper(p->layers));
    if (p->layers & CM_LAYER_ATTRACTORS) { /* attractors last: they stay black */
        gl_markers(p, CM_GROUP_STICKING);
        gl_markers(p, CM_GROUP_ATTRACTOR);
    }
    if (overlays)
        draw_points(p->overlays, px, py, p->line_width);
}

static void draw_graph_panel(const cm_gl *gl, const cm_plot *p, const tile *t)
{
    double px, py;
    if (p->graph.w <= 0 || !enter_panel(gl, &p->graph, t, &px, &py))
        return;
    draw_graph(p->model, &p->graph, p->line_width);
    if (p->layers & CM_LAYER_ATTRACTORS)
        draw_cobwebs(p, p->line_width);
    if (p->overlays && (p->layers & CM_LAYER_OVERLAYS)) {
        draw_overlay_lines(p->overlays, p->line_width, true);
        draw_points(p->overlays, px, py, p->line_width);
    }
}

/* One tile, drawn onto a transparent scratch image and laid over the
 * figure where GL drew (nothing blends, so a drawn pixel is opaque). */
static cm_status draw_tile(cm_gl *gl, const cm_plot *p, const tile *t, uint8_t *scratch,
                           uint8_t *rgba, int fig_width, char *msg, size_t msg_size)
{
    cm_status st = cm_gl_target(gl, scratch, t->w, t->w, t->h, msg, msg_size);
    if (st != CM_OK)
        return st;
    glDisable(GL_SCISSOR_TEST);
    glViewport(0, 0, t->w, t->h);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT);
    glEnable(GL_SCISSOR_TEST);
    draw_basin_panel(gl, p, t);
    draw_graph_panel(gl, p, t);
    st = cm_gl_done(gl, msg, msg_size);
    if (st != CM_OK)
        return st;
#pragma omp parallel for schedule(static)
    for (int y = 0; y < t->h; y++) {
        const uint8_t *from = scratch + 4 * (size_t)y * (size_t)t->w;
        uint8_t *to = rgba + 4 * ((size_t)(p->y + t->y + y) * (size_t)fig_width +
                                  (size_t)(p->x + t->x));
        for (int x = 0; x < t->w; x++)
            if (from[4 * x + 3])
                memcpy(to + 4 * x, from + 4 * x, 4);
    }
    return CM_OK;
}

static cm_status draw_gl(cm_gl *gl, const cm_plot *p, uint8_t *rgba, int fig_width, int *tiles,
                         char *msg, size_t msg_size)
{
    const int side_w = p->w < CM_PLOT_TILE ? p->w : CM_PLOT_TILE;
    const int side_h = p->h < CM_PLOT_TILE ? p->h : CM_PLOT_TILE;
    uint8_t *scratch = cm_cells_array(4 * (size_t)side_w * (size_t)side_h); /* few page faults */
    if (!scratch)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a %dx%d GL tile", side_w,
                       side_h);
    cm_status st = CM_OK;
    for (int y = 0; y < p->h && st == CM_OK; y += CM_PLOT_TILE)
        for (int x = 0; x < p->w && st == CM_OK; x += CM_PLOT_TILE) {
            const tile t = {x, y, p->w - x < CM_PLOT_TILE ? p->w - x : CM_PLOT_TILE,
                            p->h - y < CM_PLOT_TILE ? p->h - y : CM_PLOT_TILE};
            st = draw_tile(gl, p, &t, scratch, rgba, fig_width, msg, msg_size);
            ++*tiles;
        }
    free(scratch);
    return st;
}

bool cm_plot_needs_gl(unsigned layers, const cm_model *m, int dim)
{
    return m && (dim == 1 || ((layers & CM_LAYER_OVERLAYS) && m->overlays));
}

cm_status cm_plot_draw(const cm_plot *p, uint8_t *rgba, int fig_width, int *tiles, char *msg,
                       size_t msg_size)
{
    *tiles = 0;
    const bool raster = (p->layers & (CM_LAYER_BASIN | CM_LAYER_STEPS)) != 0;
    const bool whole = p->basin.x == 0 && p->basin.y == 0 && p->basin.w == p->w &&
                       p->basin.h == p->h;
    if (!raster || !whole) /* the raster draws every pixel of its panel */
        fill_plot(p, rgba, fig_width);
    cm_status st = raster ? draw_raster(p, rgba, fig_width, msg, msg_size) : CM_OK;
    if (st != CM_OK)
        return st;
    if (!gl_draws(p)) {
        if (p->layers & CM_LAYER_ATTRACTORS) { /* attractors last: they stay black */
            cpu_markers(p, CM_GROUP_STICKING, rgba, fig_width);
            cpu_markers(p, CM_GROUP_ATTRACTOR, rgba, fig_width);
        }
        return CM_OK;
    }
    cm_gl *own = NULL;
    if (!p->gl)
        st = cm_gl_open(&own, msg, msg_size);
    if (st == CM_OK)
        st = draw_gl(p->gl ? p->gl : own, p, rgba, fig_width, tiles, msg, msg_size);
    cm_gl_close(own);
    return st;
}
