/* render/svg.c - figures as SVG (render/svg.h). */
#include "render/svg.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/numtext.h"
#include "render/figure_parts.h"
#include "render/png_out.h"

enum { GRAPH_SAMPLES_PER_PIXEL = 4, COBWEB_STEPS = 400 };

/* State coordinates to the figure's pixels through one panel. */
typedef struct frame_map {
    double x0, y0, sx, sy; /* pixel = x0 + sx * (state - lo) ... */
    double lo[2];
} frame_map;

static frame_map map_of(const cm_plot *p, const cm_panel *pn)
{
    return (frame_map){p->x + pn->x,
                       p->y + pn->y + pn->h,
                       pn->w / (pn->hi[0] - pn->lo[0]),
                       -pn->h / (pn->hi[1] - pn->lo[1]),
                       {pn->lo[0], pn->lo[1]}};
}

static double px_x(const frame_map *m, double x) { return m->x0 + m->sx * (x - m->lo[0]); }
static double px_y(const frame_map *m, double y) { return m->y0 + m->sy * (y - m->lo[1]); }

static void hex(cm_rgb c, char out[8]) { snprintf(out, 8, "#%02x%02x%02x", c.r, c.g, c.b); }

void cm_svg_escaped(FILE *f, const char *s)
{
    for (; *s; s++) {
        if (*s == '&')
            fputs("&amp;", f);
        else if (*s == '<')
            fputs("&lt;", f);
        else if (*s == '>')
            fputs("&gt;", f);
        else
            fputc(*s, f);
    }
}

static void text(FILE *f, double x, double y, const char *anchor, const char *s)
{
    fprintf(f, "<text x=\"%.2f\" y=\"%.2f\" text-anchor=\"%s\">", x, y, anchor);
    cm_svg_escaped(f, s);
    fputs("</text>\n", f);
}

static const char base64_digits[] =
    "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

void cm_svg_base64(FILE *f, const uint8_t *b, size_t n)
{
    for (size_t i = 0; i < n; i += 3) {
        const uint32_t v = (uint32_t)b[i] << 16 | (i + 1 < n ? (uint32_t)b[i + 1] << 8 : 0) |
                           (i + 2 < n ? b[i + 2] : 0);
        fputc(base64_digits[v >> 18 & 63], f);
        fputc(base64_digits[v >> 12 & 63], f);
        fputc(i + 1 < n ? base64_digits[v >> 6 & 63] : '=', f);
        fputc(i + 2 < n ? base64_digits[v & 63] : '=', f);
    }
}

/* First and one past the last cell of n that meet lo..hi. */
static void visible(double origin, double width, uint64_t n, double lo, double hi, uint64_t *a,
                    uint64_t *b)
{
    const double first = floor((lo - origin) / width), last = ceil((hi - origin) / width);
    *a = first < 0 ? 0 : first > (double)n ? n : (uint64_t)first;
    *b = last < (double)*a ? *a : last > (double)n ? n : (uint64_t)last;
}

/* The cells of the view as an embedded PNG, a pixel per cell (or k x k). */
static cm_status raster(FILE *f, const figure *F, char *msg, size_t msg_size)
{
    const cm_raster *ras = &F->w.ras;
    const cm_slice *s = &ras->s;
    const cm_panel *pn = &F->p.basin;
    uint64_t i0, i1, j0 = 0, j1 = 1;
    visible(s->x0, s->dx, s->nx, pn->lo[0], pn->hi[0], &i0, &i1);
    if (s->ny > 1)
        visible(s->y0, s->dy, s->ny, pn->lo[1], pn->hi[1], &j0, &j1);
    const uint64_t w = i1 - i0, h = j1 - j0;
    if (w == 0 || h == 0)
        return CM_OK;
    if (w > CM_RENDER_MAX_SIDE * 4 || h > CM_RENDER_MAX_SIDE * 4)
        return cm_fail(CM_EINVAL, msg, msg_size, "%llux%llu cells are too many to embed in an "
                       "SVG; choose a smaller --view", (unsigned long long)w, (unsigned long long)h);
    const frame_map m = map_of(&F->p, pn);
    const double x = px_x(&m, s->x0 + (double)i0 * s->dx);
    const double x1 = px_x(&m, s->x0 + (double)i1 * s->dx);
    const double y = s->ny > 1 ? px_y(&m, s->y0 + (double)j1 * s->dy) : m.y0 - pn->h;
    const double y1 = s->ny > 1 ? px_y(&m, s->y0 + (double)j0 * s->dy) : m.y0;
    /* each cell k x k pixels where asked, about twice the pixels it covers */
    uint64_t k = 1;
    if (F->o.svg_cell_pixels > 1) {
        const double across = fmax((x1 - x) / (double)w, (y1 - y) / (double)h);
        k = (uint64_t)fmin(F->o.svg_cell_pixels, fmax(1, ceil(2 * across)));
    }
    const uint64_t pw = w * k, ph = h * k;
    uint8_t *rgba = malloc((size_t)(pw * ph * 4));
    if (!rgba)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the SVG's raster");
    for (uint64_t j = 0; j < ph; j++) /* PNG row 0 is the top: the highest cells */
        for (uint64_t i = 0; i < pw; i++) {
            uint8_t *dst = rgba + 4 * (j * pw + i);
            cm_raster_rgb(ras, s->base + (j1 - 1 - j / k) * s->row_stride + i0 + i / k, dst);
            dst[3] = 255;
        }
    uint8_t *png = NULL;
    size_t n = 0;
    cm_status st = cm_png_encode(rgba, (int)pw, (int)ph, &png, &n, msg, msg_size);
    free(rgba);
    if (st != CM_OK)
        return st;
    fprintf(f,
            "<image x=\"%.3f\" y=\"%.3f\" width=\"%.3f\" height=\"%.3f\" "
            "preserveAspectRatio=\"none\" style=\"image-rendering:pixelated\" "
            "clip-path=\"url(#basin)\" href=\"data:image/png;base64,",
            x, y, x1 - x, y1 - y);
    cm_svg_base64(f, png, n);
    fputs("\"/>\n", f);
    free(png);
    return CM_OK;
}

/* Periodic cells of one kind, at least p.marker pixels a side (as the PNG
 * draws them). */
static void markers(FILE *f, const figure *F, int kind)
{
    const cm_raster *ras = &F->w.ras;
    const cm_slice *s = &ras->s;
    const cm_panel *pn = &F->p.basin;
    const frame_map m = map_of(&F->p, pn);
    const double w = fmax(fabs(m.sx * s->dx), F->p.marker);
    const double h = s->ny == 1 ? pn->h : fmax(fabs(m.sy * s->dy), F->p.marker);
    char colour[8];
    hex(kind == CM_GROUP_STICKING ? cm_colour_sticking_marker : cm_colour_marker, colour);
    fprintf(f, "<g fill=\"%s\" clip-path=\"url(#basin)\">\n", colour);
    for (uint64_t k = 0; k < ras->nperiodic; k++) {
        const cm_periodic_cell *c = &ras->periodic[k];
        if (F->p.groups[c->group - 1].kind != kind)
            continue;
        const double cx = px_x(&m, s->x0 + (c->i + 0.5) * s->dx);
        const double cy = s->ny == 1 ? m.y0 - pn->h / 2 : px_y(&m, s->y0 + (c->j + 0.5) * s->dy);
        if (cx + w / 2 < m.x0 || cx - w / 2 > m.x0 + pn->w)
            continue;
        fprintf(f, "<rect x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" height=\"%.2f\"/>\n", cx - w / 2,
                cy - h / 2, w, h);
    }
    fputs("</g>\n", f);
}

static void segments(FILE *f, const cm_overlay_list *ov, const frame_map *m, int kind,
                     const char *style)
{
    fprintf(f, "<path %s d=\"", style);
    for (size_t k = 0; k < ov->count; k++)
        if (ov->items[k].kind == kind)
            fprintf(f, "M%.2f %.2fL%.2f %.2f", px_x(m, ov->items[k].a[0]),
                    px_y(m, ov->items[k].a[1]), px_x(m, ov->items[k].b[0]),
                    px_y(m, ov->items[k].b[1]));
    fputs("\"/>\n", f);
}

static void overlays(FILE *f, const figure *F, const cm_panel *pn)
{
    const cm_overlay_list *ov = F->p.overlays;
    const frame_map m = map_of(&F->p, pn);
    const int lw = F->p.line_width;
    char style[160], colour[8];
    fputs("<g fill=\"none\" clip-path=\"url(#panel)\">\n", f);
    hex(cm_colour_repeller, colour);
    snprintf(style, sizeof style, "stroke=\"%s\" stroke-width=\"%d\"", colour, 3 * lw);
    segments(f, ov, &m, CM_OVERLAY_REPELLER, style);
    hex(cm_colour_escape, colour);
    snprintf(style, sizeof style, "stroke=\"%s\" stroke-width=\"%d\"", colour, 3 * lw);
    segments(f, ov, &m, CM_OVERLAY_ESCAPE, style);
    snprintf(style, sizeof style, "stroke=\"#282828\" stroke-width=\"%d\"", 2 * lw + 1);
    segments(f, ov, &m, CM_OVERLAY_STICKING_ZONE, style);
    const bool on_paper = pn == &F->p.graph || cm_layers_on_paper(F->p.layers);
    snprintf(style, sizeof style, "stroke=\"%s\" stroke-width=\"%d\"",
             on_paper ? "#000000" : "#ffffff", lw); /* white over basins, black on paper */
    segments(f, ov, &m, CM_OVERLAY_SWITCHING_LINE, style);
    snprintf(style, sizeof style, "stroke=\"#000000\" stroke-width=\"%d\" stroke-dasharray=\"%d %d\"",
             lw, 16 * lw, 16 * lw);
    segments(f, ov, &m, CM_OVERLAY_UNSTABLE_MANIFOLD, style);
    snprintf(style, sizeof style, "stroke=\"#000000\" stroke-width=\"%d\" stroke-dasharray=\"%d %d\"",
             lw, 4 * lw, 4 * lw);
    segments(f, ov, &m, CM_OVERLAY_STABLE_MANIFOLD, style);
    const double r = 2.0 + 1.5 * lw;
    for (size_t k = 0; k < ov->count; k++) {
        const cm_overlay *o = &ov->items[k];
        const char *fill = o->kind == CM_OVERLAY_FIXED_REGULAR   ? "#ffffff"
                           : o->kind == CM_OVERLAY_FIXED_VIRTUAL ? "none"
                                                                 : NULL;
        if (o->kind == CM_OVERLAY_COLLISION || o->kind == CM_OVERLAY_COLLISION_HIGHER) {
            hex(o->kind == CM_OVERLAY_COLLISION ? cm_colour_collision : cm_colour_collision_higher,
                colour);
            fill = colour;
        }
        if (fill)
            fprintf(f,
                    "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"%.2f\" fill=\"%s\" stroke=\"#000000\" "
                    "stroke-width=\"%d\"/>\n",
                    px_x(&m, o->a[0]), px_y(&m, o->a[1]), r, fill, lw);
    }
    fputs("</g>\n", f);
}

/* 1-D maps: the diagonal, the graph as dots and a cobweb per attractor. */
static void graph(FILE *f, const figure *F)
{
    const cm_plot *p = &F->p;
    const cm_panel *pn = &p->graph;
    const frame_map m = map_of(p, pn);
    const cm_model *model = p->model;
    const int lw = p->line_width;
    fprintf(f, "<g clip-path=\"url(#graph)\" stroke-width=\"%d\">\n", lw);
    fprintf(f, "<path stroke=\"#969696\" d=\"M%.2f %.2fL%.2f %.2f\"/>\n", px_x(&m, pn->lo[0]),
            px_y(&m, pn->lo[0]), px_x(&m, pn->hi[0]), px_y(&m, pn->hi[0]));
    fprintf(f, "<path stroke=\"#000000\" stroke-linecap=\"round\" d=\"");
    const int samples = GRAPH_SAMPLES_PER_PIXEL * pn->w;
    for (int k = 0; k < samples; k++) {
        const double x = pn->lo[0] + (k + 0.5) * (pn->hi[0] - pn->lo[0]) / samples;
        double y;
        if (model->step(model, &x, &y) == CM_STEP_OK)
            fprintf(f, "M%.2f %.2fh0", px_x(&m, x), px_y(&m, y));
    }
    fputs("\"/>\n", f);
    const cm_raster *ras = p->ras;
    for (uint64_t k = 0; (p->layers & CM_LAYER_ATTRACTORS) && k < ras->nperiodic; k++) {
        const uint32_t g = ras->periodic[k].group;
        bool first = p->groups[g - 1].kind == CM_GROUP_ATTRACTOR;
        for (uint64_t q = 0; q < k && first; q++) /* one cobweb per group */
            first = ras->periodic[q].group != g;
        if (!first)
            continue;
        char colour[8];
        hex(cm_class_colour(ras->palette, ras->classes[g]), colour);
        double x = ras->s.x0 + (ras->periodic[k].i + 0.5) * ras->s.dx;
        fprintf(f, "<path fill=\"none\" stroke=\"%s\" d=\"M%.2f %.2f", colour, px_x(&m, x),
                px_y(&m, x));
        const uint32_t steps = 2 * p->groups[g - 1].period + 16;
        for (uint32_t t = 0; t < steps && t < COBWEB_STEPS; t++) {
            double y;
            if (model->step(model, &x, &y) != CM_STEP_OK)
                break;
            fprintf(f, "L%.2f %.2fL%.2f %.2f", px_x(&m, x), px_y(&m, y), px_x(&m, y), px_y(&m, y));
            x = y;
        }
        fputs("\"/>\n", f);
    }
    fputs("</g>\n", f);
}

static void axes(FILE *f, const figure *F)
{
    const layout *L = &F->L;
    const cm_plot *p = &F->p;
    const cm_panel *xp = &p->basin, *yp = p->graph.w > 0 ? &p->graph : &p->basin;
    fputs("<g fill=\"none\" stroke=\"#000000\" stroke-width=\"1\">\n", f);
    for (int k = 0; k < 2; k++) {
        const cm_panel *pn = k ? &p->graph : &p->basin;
        if (pn->w > 0)
            fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%d\" height=\"%d\"/>\n",
                    p->x + pn->x - 0.5, p->y + pn->y - 0.5, pn->w + 1, pn->h + 1);
    }
    const double base = p->y + xp->y + xp->h;
    for (int k = 0; k < L->tx.n; k++) {
        const double x = p->x + xp->x + cm_axis_px(L->tx.v[k], xp->lo[0], xp->hi[0], xp->w) + 0.5;
        fprintf(f, "<path d=\"M%.1f %.1fv%d\"/>\n", x, base, L->tick);
    }
    for (int k = 0; k < L->ty.n; k++) {
        const double y =
            p->y + yp->y + yp->h - 1 - cm_axis_px(L->ty.v[k], yp->lo[1], yp->hi[1], yp->h) + 0.5;
        fprintf(f, "<path d=\"M%d %.1fh%d\"/>\n", p->x + yp->x - L->tick, y, L->tick);
    }
    fputs("</g>\n<g fill=\"#000000\">\n", f);
    int last_right = INT32_MIN / 2;
    for (int k = 0; k < L->tx.n; k++) { /* labels that would overlap are left out, as in PNGs */
        const int x = p->x + xp->x + cm_axis_px(L->tx.v[k], xp->lo[0], xp->hi[0], xp->w);
        const int w = cm_font_width(F->w.font, L->tx.label[k]);
        if (x - w / 2 <= last_right + L->pad)
            continue;
        text(f, x, base + L->tick + L->ascent, "middle", L->tx.label[k]);
        last_right = x - w / 2 + w;
    }
    text(f, p->x + xp->x + xp->w / 2.0, base + L->tick + L->line + L->ascent, "middle", L->xname);
    for (int k = 0; k < L->ty.n; k++) {
        const int y = p->y + yp->y + yp->h - 1 - cm_axis_px(L->ty.v[k], yp->lo[1], yp->hi[1], yp->h);
        text(f, p->x + yp->x - L->tick - 2, y + L->ascent / 2.0 - 1, "end", L->ty.label[k]);
    }
    text(f, L->pad, p->y + yp->y + yp->h / 2.0 + L->ascent / 2.0, "start", L->yname);
    fputs("</g>\n", f);
}

/* The step bar as the PNG draws it, its shading a gradient. */
static void step_bar(FILE *f, const figure *F, int x, int y)
{
    const layout *L = &F->L;
    const int box = L->ascent, top = y + L->line + L->pad, h = (BAR_LINES - 2) * L->line;
    text(f, x, y + L->ascent, "start", BAR_TITLE);
    fputs("<linearGradient id=\"steps\" x1=\"0\" y1=\"0\" x2=\"0\" y2=\"1\">", f);
    for (int k = 0; k <= 16; k++) {
        const uint8_t g = figure_bar_grey(F->w.lg.bar_mode, k / 16.0);
        fprintf(f, "<stop offset=\"%g\" stop-color=\"#%02x%02x%02x\"/>", k / 16.0, g, g, g);
    }
    fputs("</linearGradient>\n", f);
    fprintf(f,
            "<rect x=\"%.1f\" y=\"%.1f\" width=\"%d\" height=\"%d\" fill=\"url(#steps)\" "
            "stroke=\"#000000\"/>\n",
            x + 0.5, top - 0.5, box + 1, h + 1);
    for (int k = 0; k <= 2; k++) {
        char label[32];
        const uint32_t steps = cm_step_at(k / 2.0, F->w.ras.step_cap);
        snprintf(label, sizeof label, k == 2 ? "%u or more" : "%u", steps);
        text(f, x + box + L->pad, top + k * (h - 1) / 2 + L->ascent / 2.0, "start", label);
    }
}

static void legend_and_title(FILE *f, const figure *F)
{
    const layout *L = &F->L;
    const cm_plot *p = &F->p;
    if (F->o.layers & CM_LAYER_LEGEND) {
        const int x = p->x + p->w + 2 * L->pad, box = L->ascent;
        fputs("<g>\n", f);
        for (int k = 0; k < F->w.lg.n; k++) {
            const entry *e = &F->w.lg.e[k];
            const int base = p->y + (k + 1) * L->line;
            if (e->has_swatch) {
                char colour[8];
                hex(e->swatch, colour);
                fprintf(f,
                        "<rect x=\"%.1f\" y=\"%.1f\" width=\"%d\" height=\"%d\" fill=\"%s\" "
                        "stroke=\"#000000\"/>\n",
                        x + 0.5, base - box + 0.5, box - 1, box - 1, colour);
            }
            text(f, x + box + L->pad, base, "start", e->text);
        }
        if (F->w.lg.bar_mode >= 0)
            step_bar(f, F, x, p->y + (F->w.lg.n + 1) * L->line);
        fputs("</g>\n", f);
    }
    for (int k = 0; k < L->title_lines; k++)
        text(f, L->pad, L->pad + L->ascent + k * L->line, "start", L->title[k]);
}

static void clip(FILE *f, const char *id, const cm_plot *p, const cm_panel *pn)
{
    fprintf(f, "<clipPath id=\"%s\"><rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\"/></clipPath>\n",
            id, p->x + pn->x, p->y + pn->y, pn->w, pn->h);
}

cm_status cm_render_svg(const cm_lattice *lat, const cm_region *r, const cm_group_info *groups,
                        const cm_render_options *opt, FILE *f, char *msg, size_t msg_size)
{
    figure F;
    cm_status st = figure_begin(lat, r, groups, opt, &F, msg, msg_size);
    if (st != CM_OK) {
        figure_end(&F);
        return st;
    }
    const cm_render_options *o = &F.o;
    const cm_plot *p = &F.p;
    const bool has_graph = p->graph.w > 0;
    /* at a resolution, the size in points (72 an inch) a paper keeps */
    const double unit = o->dpi > 0 ? 72 / o->dpi : 1;
    fprintf(f,
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.6g%s\" height=\"%.6g%s\" "
            "viewBox=\"0 0 %d %d\" font-family=\"DejaVu Sans, sans-serif\" font-size=\"%d\">\n",
            o->width * unit, o->dpi > 0 ? "pt" : "", o->height * unit, o->dpi > 0 ? "pt" : "",
            o->width, o->height, F.L.fs);
    fputs("<defs>\n", f);
    clip(f, "basin", p, &p->basin);
    clip(f, "panel", p, has_graph ? &p->graph : &p->basin);
    if (has_graph)
        clip(f, "graph", p, &p->graph);
    fputs("</defs>\n", f);
    fprintf(f, "<rect width=\"%d\" height=\"%d\" fill=\"#ffffff\"/>\n", o->width, o->height);
    if (o->layers & (CM_LAYER_BASIN | CM_LAYER_STEPS))
        st = raster(f, &F, msg, msg_size);
    if (st == CM_OK && p->overlays && !has_graph && (o->layers & CM_LAYER_OVERLAYS))
        overlays(f, &F, &p->basin);
    if (st == CM_OK && (o->layers & CM_LAYER_ATTRACTORS)) {
        markers(f, &F, CM_GROUP_STICKING);
        markers(f, &F, CM_GROUP_ATTRACTOR);
    }
    if (st == CM_OK && has_graph) {
        graph(f, &F);
        if (p->overlays && (o->layers & CM_LAYER_OVERLAYS))
            overlays(f, &F, &p->graph);
    }
    if (st == CM_OK && (o->layers & CM_LAYER_AXES))
        axes(f, &F);
    if (st == CM_OK)
        legend_and_title(f, &F);
    fputs("</svg>\n", f);
    figure_end(&F);
    return st;
}
