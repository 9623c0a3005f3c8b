#include "render/plot.h"

#include <GL/gl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/gl.h"
#include "render/palette.h"

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
 * panel inside the tile. False when they do not meet. */
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
    cm_gl_window(gl, x0 - t->x, y0 - t->y, x1 - x0, y1 - y0);
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glOrtho(at_pixel(pn->lo[0], pn->hi[0], x0 - pn->x, pn->w),
            at_pixel(pn->lo[0], pn->hi[0], x1 - pn->x, pn->w),
            at_pixel(pn->hi[1], pn->lo[1], y1 - pn->y, pn->h),
            at_pixel(pn->hi[1], pn->lo[1], y0 - pn->y, pn->h), -1, 1);
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    return true;
}

/* ---- basin raster ------------------------------------------------------------ */

static void draw_texture_tile(const cm_raster *ras, uint64_t i0, uint64_t j0, uint64_t w,
                              uint64_t h)
{
    const cm_slice *s = &ras->s;
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, (GLint)s->nx);
    glPixelStorei(GL_UNPACK_SKIP_PIXELS, (GLint)i0);
    glPixelStorei(GL_UNPACK_SKIP_ROWS, (GLint)j0);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB, (GLsizei)w, (GLsizei)h, 0, GL_RGB, GL_UNSIGNED_BYTE,
                 ras->pixels);
    const double x0 = s->x0 + (double)i0 * s->dx, x1 = x0 + (double)w * s->dx;
    const double y0 = s->y0 + (double)j0 * s->dy, y1 = y0 + (double)h * s->dy;
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

/* The cells [i0, i1) of n along one axis that show in the state range
 * [lo, hi], rounded outwards to whole texture tiles. */
static void visible_cells(double origin, double width, uint64_t n, double lo, double hi,
                          uint64_t *i0, uint64_t *i1)
{
    double a = floor((lo - origin) / width) - 1, b = ceil((hi - origin) / width) + 1;
    a = a < 0 ? 0 : a > (double)n ? (double)n : a;
    b = b < 0 ? 0 : b > (double)n ? (double)n : b;
    *i0 = (uint64_t)a / TEX_TILE * TEX_TILE;
    *i1 = (uint64_t)b;
}

static void draw_raster(const cm_raster *ras, const double lo[2], const double hi[2])
{
    const cm_slice *s = &ras->s;
    uint64_t i0, i1, j0, j1;
    visible_cells(s->x0, s->dx, s->nx, lo[0], hi[0], &i0, &i1);
    visible_cells(s->y0, s->dy, s->ny, lo[1], hi[1], &j0, &j1);
    if (s->ny == 1) { /* a 1-D strip fills its panel's height */
        j0 = 0;
        j1 = 1;
    }
    GLuint tex = 0;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glEnable(GL_TEXTURE_2D);
    glColor3ub(255, 255, 255);
    for (uint64_t j = j0; j < j1; j += TEX_TILE)
        for (uint64_t i = i0; i < i1; i += TEX_TILE)
            draw_texture_tile(ras, i, j, i1 - i < TEX_TILE ? i1 - i : TEX_TILE,
                              j1 - j < TEX_TILE ? j1 - j : TEX_TILE);
    glDisable(GL_TEXTURE_2D);
    glDeleteTextures(1, &tex);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glPixelStorei(GL_UNPACK_SKIP_PIXELS, 0);
    glPixelStorei(GL_UNPACK_SKIP_ROWS, 0);
}

/* Periodic cells of one kind as squares of at least p->marker pixels a
 * side, so that a one-cell attractor stays visible at any zoom. */
static void draw_markers(const cm_plot *p, const cm_panel *pn, int kind, double px, double py)
{
    const cm_slice *s = &p->ras->s;
    const double least = p->marker / 2;
    const double hx = s->dx / 2 > least * px ? s->dx / 2 : least * px;
    const double hy = s->ny == 1               ? (pn->hi[1] - pn->lo[1]) / 2
                      : s->dy / 2 > least * py ? s->dy / 2
                                               : least * py;
    colour(kind == CM_GROUP_STICKING ? cm_colour_sticking_marker : cm_colour_marker);
    glBegin(GL_QUADS);
    for (uint64_t k = 0; k < p->ras->nperiodic; k++) {
        const cm_periodic_cell *c = &p->ras->periodic[k];
        if (p->groups[c->group - 1].kind != kind)
            continue;
        const double cx = s->x0 + ((double)c->i + 0.5) * s->dx;
        const double cy =
            s->ny == 1 ? (pn->lo[1] + pn->hi[1]) / 2 : s->y0 + ((double)c->j + 0.5) * s->dy;
        if (cx + hx < pn->lo[0] || cx - hx > pn->hi[0] || cy + hy < pn->lo[1] ||
            cy - hy > pn->hi[1])
            continue;
        glVertex2d(cx - hx, cy - hy);
        glVertex2d(cx + hx, cy - hy);
        glVertex2d(cx + hx, cy + hy);
        glVertex2d(cx - hx, cy + hy);
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

/* ---- one tile ------------------------------------------------------------------- */

static void draw_basin_panel(const cm_gl *gl, const cm_plot *p, const tile *t)
{
    double px, py;
    if (!enter_panel(gl, &p->basin, t, &px, &py))
        return;
    if (p->layers & (CM_LAYER_BASIN | CM_LAYER_STEPS))
        draw_raster(p->ras, p->basin.lo, p->basin.hi);
    const bool graph = p->graph.w > 0;
    if (p->overlays && !graph && (p->layers & CM_LAYER_OVERLAYS))
        draw_overlay_lines(p->overlays, p->line_width, cm_layers_on_paper(p->layers));
    if (p->layers & CM_LAYER_ATTRACTORS) { /* attractors last: they stay black */
        draw_markers(p, &p->basin, CM_GROUP_STICKING, px, py);
        draw_markers(p, &p->basin, CM_GROUP_ATTRACTOR, px, py);
    }
    if (p->overlays && !graph && (p->layers & CM_LAYER_OVERLAYS))
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

static cm_status draw_tile(cm_gl *gl, const cm_plot *p, const tile *t, uint8_t *rgba,
                           int fig_width, char *msg, size_t msg_size)
{
    uint8_t *origin =
        rgba + 4 * ((size_t)(p->y + t->y) * (size_t)fig_width + (size_t)(p->x + t->x));
    const cm_status st = cm_gl_target(gl, origin, fig_width, t->w, t->h, msg, msg_size);
    if (st != CM_OK)
        return st;
    glDisable(GL_SCISSOR_TEST);
    glViewport(0, 0, t->w, t->h);
    const cm_rgb bg = cm_colour_not_computed;
    glClearColor(bg.r / 255.0f, bg.g / 255.0f, bg.b / 255.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    glEnable(GL_SCISSOR_TEST);
    draw_basin_panel(gl, p, t);
    draw_graph_panel(gl, p, t);
    return cm_gl_done(gl, msg, msg_size);
}

cm_status cm_plot_draw(const cm_plot *p, uint8_t *rgba, int fig_width, int *tiles, char *msg,
                       size_t msg_size)
{
    *tiles = 0;
    cm_gl *own = NULL;
    cm_status st = p->gl ? CM_OK : cm_gl_open(&own, msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_gl *gl = p->gl ? p->gl : own;
    for (int y = 0; y < p->h && st == CM_OK; y += CM_PLOT_TILE)
        for (int x = 0; x < p->w && st == CM_OK; x += CM_PLOT_TILE) {
            const tile t = {x, y, p->w - x < CM_PLOT_TILE ? p->w - x : CM_PLOT_TILE,
                            p->h - y < CM_PLOT_TILE ? p->h - y : CM_PLOT_TILE};
            st = draw_tile(gl, p, &t, rgba, fig_width, msg, msg_size);
            ++*tiles;
        }
    cm_gl_close(own);
    return st;
}
