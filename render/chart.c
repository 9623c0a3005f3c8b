#include "render/chart.h"

#include <GL/gl.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/axes.h"
#include "render/png_out.h"
#include "render/svg.h"
#include "render/text.h"

static const cm_rgb ink = {0, 0, 0};
static const cm_rgb paper = {255, 255, 255};
static const cm_rgb not_computed = {225, 225, 225};

/* A sequential scale from pale yellow through orange and red to dark
 * purple: small positive exponents stay visible against white. */
static const cm_rgb scale[] = {
    {255, 237, 160}, {254, 178, 76}, {240, 59, 32}, {189, 0, 38}, {84, 0, 90}};

cm_rgb cm_heat_colour(double v, double max)
{
    const int n = (int)(sizeof scale / sizeof scale[0]) - 1;
    double f = max > 0 ? v / max : 1;
    f = f < 0 ? 0 : f > 1 ? 1 : f;
    const int k = f >= 1 ? n - 1 : (int)(f * n);
    const double t = f * n - k;
    const cm_rgb a = scale[k], b = scale[k + 1];
    return (cm_rgb){(uint8_t)lround(a.r + t * (b.r - a.r)), (uint8_t)lround(a.g + t * (b.g - a.g)),
                    (uint8_t)lround(a.b + t * (b.b - a.b))};
}

static double heat_max(const cm_heat *h)
{
    if (h->max > 0)
        return h->max;
    double m = 0;
    for (size_t k = 0; k < (size_t)h->nx * (size_t)h->ny; k++)
        m = h->v[k] > m ? h->v[k] : m;
    return m;
}

typedef struct layout {
    int font_px; /* the font's size in pixels */
    int left, right, top, bottom, pad, tick, line, ascent, bar;
    cm_ticks tx, ty, tbar;
} layout;

static void plan(const cm_chart *c, const cm_font *f, double hmax, layout *L)
{
    L->ascent = cm_font_ascent(f);
    L->line = cm_font_height(f);
    L->pad = L->line / 3;
    L->tick = L->line / 4 + 1;
    cm_make_ticks(c->lo[0], c->hi[0], &L->tx);
    cm_make_ticks(c->lo[1], c->hi[1], &L->ty);
    L->top = (c->title ? L->line : 0) + 2 * L->pad;
    L->bottom = L->tick + 2 * L->line + L->pad;
    L->left = 2 * L->pad + cm_font_width(f, c->y_name) + cm_ticks_widest(f, &L->ty) + L->tick;
    L->right = 2 * L->pad + cm_font_width(f, "0") / 2;
    L->bar = 0;
    if (c->heat) {
        cm_make_ticks(0, hmax, &L->tbar);
        L->bar = L->line;
        const int name_w = c->heat->name ? cm_font_width(f, c->heat->name) : 0;
        const int labels = L->tick + 2 + cm_ticks_widest(f, &L->tbar);
        L->right += 2 * L->pad + L->bar + (labels > name_w ? labels : name_w);
    }
}

/* ---- the plot, with OpenGL ---- */

static void gl_colour(cm_rgb c) { glColor3ub(c.r, c.g, c.b); }

static void draw_heat(const cm_chart *c, double hmax)
{
    const cm_heat *h = c->heat;
    const double dx = (c->hi[0] - c->lo[0]) / h->nx, dy = (c->hi[1] - c->lo[1]) / h->ny;
    glBegin(GL_QUADS);
    for (int j = 0; j < h->ny; j++)
        for (int i = 0; i < h->nx; i++) {
            const double v = h->v[(size_t)j * (size_t)h->nx + (size_t)i];
            if (v > 0)
                gl_colour(cm_heat_colour(v, hmax));
            else
                gl_colour(isnan(v) ? not_computed : paper);
            const double x0 = c->lo[0] + i * dx, y0 = c->lo[1] + j * dy;
            glVertex2d(x0, y0);
            glVertex2d(x0 + dx, y0);
            glVertex2d(x0 + dx, y0 + dy);
            glVertex2d(x0, y0 + dy);
        }
    glEnd();
}

static void draw_series(const cm_series *s)
{
    gl_colour(s->colour);
    const float size = s->size > 0 ? s->size : 1;
    if (s->kind == CM_SERIES_POINTS) {
        glPointSize(size);
        glBegin(GL_POINTS);
        for (size_t k = 0; k < s->n; k++)
            glVertex2d(s->x[k], s->y[k]);
        glEnd();
        return;
    }
    glLineWidth(size);
    if (s->kind == CM_SERIES_SEGMENTS) {
        glBegin(GL_LINES);
        for (size_t k = 0; k + 1 < s->n; k += 2) {
            glVertex2d(s->x[k], s->y[k]);
            glVertex2d(s->x[k + 1], s->y[k + 1]);
        }
        glEnd();
        return;
    }
    glBegin(GL_LINE_STRIP);
    for (size_t k = 0; k < s->n; k++) {
        if (isnan(s->x[k]) || isnan(s->y[k])) { /* a break in the line */
            glEnd();
            glBegin(GL_LINE_STRIP);
            continue;
        }
        glVertex2d(s->x[k], s->y[k]);
    }
    glEnd();
}

static cm_status draw_plot(const cm_chart *c, cm_gl *gl, double hmax, int px, int py, int pw,
                           int ph, uint8_t *rgba, char *msg, size_t msg_size)
{
    cm_gl *own = NULL;
    cm_status st = gl ? CM_OK : cm_gl_open(&own, msg, msg_size);
    if (st != CM_OK)
        return st;
    uint8_t *origin = rgba + 4 * ((size_t)py * (size_t)c->width + (size_t)px);
    st = cm_gl_target(gl ? gl : own, origin, c->width, pw, ph, msg, msg_size);
    if (st == CM_OK) {
        glViewport(0, 0, pw, ph);
        glClearColor(1, 1, 1, 1);
        glClear(GL_COLOR_BUFFER_BIT);
        glMatrixMode(GL_PROJECTION);
        glLoadIdentity();
        glOrtho(c->lo[0], c->hi[0], c->lo[1], c->hi[1], -1, 1);
        glMatrixMode(GL_MODELVIEW);
        glLoadIdentity();
        if (c->heat)
            draw_heat(c, hmax);
        for (int k = 0; k < c->n_series; k++)
            draw_series(&c->series[k]);
        st = cm_gl_done(gl ? gl : own, msg, msg_size);
    }
    cm_gl_close(own);
    return st;
}

/* ---- axes, title, colour bar: on the PNG's canvas or as SVG ---- */

static void svg_hex(cm_rgb c, char out[8]) { snprintf(out, 8, "#%02x%02x%02x", c.r, c.g, c.b); }

/* Where the frame, axes, labels, colour bar and title go: the canvas of a
 * PNG (svg NULL) or an SVG stream; text measured with the same font. */
typedef struct painter {
    const cm_canvas *cv;
    const cm_font *font;
    FILE *svg;
} painter;

static void paint_rect(const painter *p, int x, int y, int w, int h, cm_rgb colour)
{
    if (!p->svg) {
        cm_fill_rect(p->cv, x, y, w, h, colour);
        return;
    }
    char hex[8];
    svg_hex(colour, hex);
    fprintf(p->svg, "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"%s\"/>\n", x, y,
            w, h, hex);
}

/* Text with its baseline at y. */
static void paint_text(const painter *p, int x, int y, const char *text)
{
    if (!p->svg) {
        cm_font_draw(p->font, text, x, y, ink, p->cv->rgba, p->cv->w, p->cv->h);
        return;
    }
    fprintf(p->svg, "<text x=\"%d\" y=\"%d\">", x, y);
    cm_svg_escaped(p->svg, text);
    fputs("</text>\n", p->svg);
}

static void frame(const painter *p, int x, int y, int w, int h)
{
    paint_rect(p, x - 1, y - 1, w + 2, 1, ink);
    paint_rect(p, x - 1, y + h, w + 2, 1, ink);
    paint_rect(p, x - 1, y - 1, 1, h + 2, ink);
    paint_rect(p, x + w, y - 1, 1, h + 2, ink);
}

static void axes(const cm_chart *c, const layout *L, const painter *p, const cm_chart_info *in)
{
    const int base = in->plot_y + in->plot_h;
    int last_right = -1000000;
    for (int k = 0; k < L->tx.n; k++) {
        const int x = in->plot_x + cm_axis_px(L->tx.v[k], c->lo[0], c->hi[0], in->plot_w);
        paint_rect(p, x, base, 1, L->tick, ink);
        const int w = cm_font_width(p->font, L->tx.label[k]);
        if (x - w / 2 <= last_right + L->pad)
            continue;
        paint_text(p, x - w / 2, base + L->tick + L->ascent, L->tx.label[k]);
        last_right = x - w / 2 + w;
    }
    const int nw = cm_font_width(p->font, c->x_name);
    paint_text(p, in->plot_x + in->plot_w / 2 - nw / 2, base + L->tick + L->line + L->ascent,
               c->x_name);
    for (int k = 0; k < L->ty.n; k++) {
        const int y =
            in->plot_y + in->plot_h - 1 - cm_axis_px(L->ty.v[k], c->lo[1], c->hi[1], in->plot_h);
        paint_rect(p, in->plot_x - L->tick, y, L->tick, 1, ink);
        const int w = cm_font_width(p->font, L->ty.label[k]);
        paint_text(p, in->plot_x - L->tick - 2 - w, y + L->ascent / 2 - 1, L->ty.label[k]);
    }
    paint_text(p, L->pad, in->plot_y + in->plot_h / 2 + L->ascent / 2, c->y_name);
}

static void colour_bar(const cm_chart *c, const layout *L, const painter *p, double hmax,
                       const cm_chart_info *in)
{
    const int x = in->plot_x + in->plot_w + 3 * L->pad, y = in->plot_y + L->line,
              h = in->plot_h - L->line;
    for (int j = 0; j < h; j++) /* top = max */
        paint_rect(p, x, y + j, L->bar, 1, cm_heat_colour(hmax * (h - 1 - j) / (h - 1), hmax));
    frame(p, x, y, L->bar, h);
    for (int k = 0; k < L->tbar.n; k++) {
        const int ty = y + h - 1 - cm_axis_px(L->tbar.v[k], 0, hmax, h - 1);
        paint_rect(p, x + L->bar, ty, L->tick, 1, ink);
        paint_text(p, x + L->bar + L->tick + 2, ty + L->ascent / 2 - 1, L->tbar.label[k]);
    }
    if (c->heat->name)
        paint_text(p, x, in->plot_y + L->ascent, c->heat->name);
}

/* The labels, each right of and above its point, kept inside the plot. */
static void draw_labels(const cm_chart *c, const layout *L, const painter *p,
                        const cm_chart_info *in)
{
    for (int k = 0; k < c->n_labels; k++) {
        const cm_chart_label *l = &c->labels[k];
        const double fx = (l->x - c->lo[0]) / (c->hi[0] - c->lo[0]);
        const double fy = (l->y - c->lo[1]) / (c->hi[1] - c->lo[1]);
        if (!(fx >= 0 && fx <= 1 && fy >= 0 && fy <= 1) || !l->text)
            continue;
        const int w = cm_font_width(p->font, l->text);
        int x = in->plot_x + (int)lround(fx * in->plot_w) + 4;
        int y = in->plot_y + (int)lround((1 - fy) * in->plot_h) - 4;
        if (x + w > in->plot_x + in->plot_w - 2) /* near the right edge: left of the point */
            x -= w + 8;
        if (y - L->ascent < in->plot_y + 2)
            y = in->plot_y + 2 + L->ascent;
        paint_text(p, x, y, l->text);
    }
}

/* Everything around the plot. */
static void decorate(const cm_chart *c, const layout *L, const painter *p, double hmax,
                     const cm_chart_info *in)
{
    frame(p, in->plot_x, in->plot_y, in->plot_w, in->plot_h);
    axes(c, L, p, in);
    draw_labels(c, L, p, in);
    if (c->heat)
        colour_bar(c, L, p, hmax, in);
    if (c->title)
        paint_text(p, L->pad, L->pad + L->ascent, c->title);
}

void cm_chart_join_labels(cm_chart_label *labels, int n, char *texts, size_t text_size, double dx,
                          double dy)
{
    for (int i = 0; i < n; i++)
        for (int j = 0; j < i && labels[i].text; j++) {
            if (!labels[j].text || !(fabs(labels[i].x - labels[j].x) < dx) ||
                !(fabs(labels[i].y - labels[j].y) < dy))
                continue;
            char *into = texts + (size_t)j * text_size;
            const size_t used = strlen(into), more = strlen(labels[i].text);
            if (!strstr(into, labels[i].text) && used + 2 + more < text_size)
                snprintf(into + used, text_size - used, ", %s", labels[i].text);
            labels[i].text = NULL;
        }
}

/* Opens the chart's font and plans its layout: info gets the plot's place. */
static cm_status measure(const cm_chart *c, cm_font **f, layout *L, cm_chart_info *info, char *msg,
                         size_t msg_size)
{
    memset(info, 0, sizeof *info);
    if (!(c->hi[0] > c->lo[0]) || !(c->hi[1] > c->lo[1]) || !isfinite(c->hi[0] - c->lo[0]) ||
        !isfinite(c->hi[1] - c->lo[1]))
        return cm_fail(CM_EINVAL, msg, msg_size, "the chart's ranges must be finite and not empty");
    /* legible in print: 1/45 of the shorter side, or 1/64 of the width for
     * the flat panels of a stack (14 pixels in a 900-pixel figure) */
    const int side = c->width < c->height ? c->width : c->height;
    const int size = side / 45 > c->width / 64 ? side / 45 : c->width / 64;
    L->font_px = size < 12 ? 12 : size > 48 ? 48 : size;
    cm_status st = cm_font_open(c->font_path, L->font_px, f, msg, msg_size);
    if (st != CM_OK)
        return st;
    const double hmax = c->heat ? heat_max(c->heat) : 0;
    info->heat_max = hmax;
    plan(c, *f, hmax > 0 ? hmax : 1, L);
    if (c->min_left > L->left)
        L->left = c->min_left;
    info->plot_x = L->left;
    info->plot_y = L->top;
    info->plot_w = c->width - L->left - L->right;
    info->plot_h = c->height - L->top - L->bottom;
    if (info->plot_w < 16 || info->plot_h < 16 || c->width > 4096 || c->height > 4096)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a %dx%d chart leaves no room for its plot (charts take 200x150 to "
                       "4096x4096)",
                       c->width, c->height);
    return CM_OK;
}

cm_status cm_chart_layout(const cm_chart *c, cm_chart_info *info, char *msg, size_t msg_size)
{
    cm_font *f = NULL;
    layout L;
    const cm_status st = measure(c, &f, &L, info, msg, msg_size);
    cm_font_close(f);
    return st;
}

cm_status cm_chart_draw(const cm_chart *c, cm_gl *gl, uint8_t *rgba, cm_chart_info *info, char *msg,
                        size_t msg_size)
{
    cm_font *f = NULL;
    layout L;
    cm_status st = measure(c, &f, &L, info, msg, msg_size);
    const double hmax = info->heat_max > 0 ? info->heat_max : 1;
    const cm_canvas cv = {rgba, c->width, c->height};
    if (st == CM_OK) {
        cm_fill_rect(&cv, 0, 0, c->width, c->height, paper);
        st = draw_plot(c, gl, hmax, info->plot_x, info->plot_y, info->plot_w, info->plot_h, rgba,
                       msg, msg_size);
    }
    if (st == CM_OK)
        decorate(c, &L, &(const painter){&cv, f, NULL}, hmax, info);
    cm_font_close(f);
    return st;
}

/* ---- the same chart as SVG ---- */

static double svg_x(const cm_chart *c, const cm_chart_info *in, double x)
{
    return in->plot_x + (x - c->lo[0]) / (c->hi[0] - c->lo[0]) * in->plot_w;
}

static double svg_y(const cm_chart *c, const cm_chart_info *in, double y)
{
    return in->plot_y + in->plot_h - (y - c->lo[1]) / (c->hi[1] - c->lo[1]) * in->plot_h;
}

/* The heat map as an embedded PNG, each cell k x k pixels (at most about
 * twice the pixels it covers). */
static cm_status svg_heat(FILE *f, const cm_chart *c, const cm_chart_info *in, double hmax,
                          int k, char *msg, size_t msg_size)
{
    const cm_heat *h = c->heat;
    const double across = fmax((double)in->plot_w / h->nx, (double)in->plot_h / h->ny);
    k = (int)fmin(k, fmax(1, ceil(2 * across)));
    const size_t w = (size_t)h->nx * (size_t)k, ht = (size_t)h->ny * (size_t)k;
    uint8_t *rgba = malloc(w * ht * 4);
    if (!rgba)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the chart's SVG");
    for (size_t j = 0; j < ht; j++) /* row 0 is the top: the highest cells */
        for (size_t i = 0; i < w; i++) {
            const size_t row = (size_t)h->ny - 1 - j / (size_t)k, column = i / (size_t)k;
            const double v = h->v[row * (size_t)h->nx + column];
            const cm_rgb col = v > 0 ? cm_heat_colour(v, hmax) : isnan(v) ? not_computed : paper;
            uint8_t *p = rgba + 4 * (j * w + i);
            p[0] = col.r, p[1] = col.g, p[2] = col.b, p[3] = 255;
        }
    uint8_t *png = NULL;
    size_t n = 0;
    const cm_status st = cm_png_encode(rgba, (int)w, (int)ht, &png, &n, msg, msg_size);
    free(rgba);
    if (st != CM_OK)
        return st;
    fprintf(f, "<image x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" preserveAspectRatio=\"none\" "
               "style=\"image-rendering:pixelated\" href=\"data:image/png;base64,",
            in->plot_x, in->plot_y, in->plot_w, in->plot_h);
    cm_svg_base64(f, png, n);
    fputs("\"/>\n", f);
    free(png);
    return CM_OK;
}

/* A series as one path: squares for points (GL's points), segments or a
 * polyline broken at NaN. */
static void svg_series(FILE *f, const cm_chart *c, const cm_chart_info *in, const cm_series *s)
{
    char hex[8];
    svg_hex(s->colour, hex);
    const double size = s->size > 0 ? s->size : 1;
    if (s->kind == CM_SERIES_POINTS)
        fprintf(f, "<path fill=\"%s\" d=\"", hex);
    else
        fprintf(f, "<path fill=\"none\" stroke=\"%s\" stroke-width=\"%g\" d=\"", hex, size);
    bool pen_down = false;
    for (size_t k = 0; k < s->n; k++) {
        const double x = svg_x(c, in, s->x[k]), y = svg_y(c, in, s->y[k]);
        if (!isfinite(x) || !isfinite(y)) {
            pen_down = false;
            continue;
        }
        if (s->kind == CM_SERIES_POINTS)
            fprintf(f, "M%.2f %.2fh%gv%gh%gz", x - size / 2, y - size / 2, size, size, -size);
        else if (s->kind == CM_SERIES_SEGMENTS)
            fprintf(f, "%c%.2f %.2f", k % 2 == 0 ? 'M' : 'L', x, y);
        else
            fprintf(f, "%c%.2f %.2f", pen_down ? 'L' : 'M', x, y), pen_down = true;
    }
    fputs("\"/>\n", f);
}

cm_status cm_chart_svg(const cm_chart *c, int index, int top, int cell_pixels, FILE *f, char *msg,
                       size_t msg_size)
{
    cm_font *font = NULL;
    layout L;
    cm_chart_info in;
    cm_status st = measure(c, &font, &L, &in, msg, msg_size);
    const double hmax = in.heat_max > 0 ? in.heat_max : 1;
    if (st == CM_OK) {
        fprintf(f, "<g transform=\"translate(0 %d)\" font-size=\"%d\">\n", top, L.font_px);
        paint_rect(&(const painter){NULL, font, f}, 0, 0, c->width, c->height, paper);
        fprintf(f, "<clipPath id=\"plot%d\"><rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\"/>"
                   "</clipPath>\n",
                index, in.plot_x, in.plot_y, in.plot_w, in.plot_h);
        if (c->heat)
            st = svg_heat(f, c, &in, hmax, cell_pixels > 1 ? cell_pixels : 1, msg, msg_size);
    }
    if (st == CM_OK) {
        fprintf(f, "<g clip-path=\"url(#plot%d)\">\n", index);
        for (int k = 0; k < c->n_series; k++)
            svg_series(f, c, &in, &c->series[k]);
        fputs("</g>\n", f);
        decorate(c, &L, &(const painter){NULL, font, f}, hmax, &in);
        fputs("</g>\n", f);
    }
    cm_font_close(font);
    return st;
}
