#include "render/figure.h"

#include "cellmap/clock.h"

#include "render/figure_parts.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "render/axes.h"
#include "render/gl_loader.h"
#include "render/palette.h"
#include "render/text.h"

enum { OVERLAY_CAP = 1 << 16 }; /* more lines than this would paint the view over */

static const cm_rgb ink = {0, 0, 0};
static const cm_rgb paper = {255, 255, 255};

/* ---- legend --------------------------------------------------------------------- */


typedef struct group_cells {
    uint64_t cells;
    uint32_t id;
} group_cells;

static int more_cells_first(const void *a, const void *b)
{
    const group_cells *x = a, *y = b;
    if (x->cells != y->cells)
        return x->cells > y->cells ? -1 : 1;
    return x->id < y->id ? -1 : x->id > y->id;
}

/* cells' share of all as a legend shows it: two significant digits
 * ("0.023%", "1.5%", "68%"), "< 0.01%" for a share too small for that. */
typedef struct percent_text {
    char s[16];
} percent_text;

static percent_text share(uint64_t cells, uint64_t all)
{
    percent_text t;
    const double p = all ? 100.0 * (double)cells / (double)all : 0.0;
    if (cells > 0 && p < 0.01)
        snprintf(t.s, sizeof t.s, "< 0.01%%");
    else if (p >= 9.95)
        snprintf(t.s, sizeof t.s, "%.0f%%", p);
    else
        snprintf(t.s, sizeof t.s, "%#.2g%%", p); /* "6.0%": both digits */
    return t;
}

static entry *add_entry(legend *lg, cm_rgb swatch, bool has_swatch)
{
    entry *e = &lg->e[lg->n++];
    e->swatch = swatch;
    e->has_swatch = has_swatch;
    return e;
}

enum { LEGEND_GROUPS = 12 }; /* the default of cm_render_options.legend_groups */

/* The entries after the groups: those folded into "other", colours that
 * repeat, cells not computed. */
static void closing_entries(const cm_raster *ras, uint64_t all, int room, legend *lg)
{
    if (ras->other_groups && lg->n < room) {
        entry *e = add_entry(lg, cm_colour_other, true);
        if (ras->min_basin == 2)
            snprintf(e->text, LABEL, "%u single-cell groups  %s", ras->other_groups,
                     share(ras->other_cells, all).s);
        else
            snprintf(e->text, LABEL, "%u groups < %llu cells  %s", ras->other_groups,
                     (unsigned long long)ras->min_basin, share(ras->other_cells, all).s);
    }
    if (ras->colour_repeats && lg->n < room)
        snprintf(add_entry(lg, paper, false)->text, LABEL, "colours repeat: %u groups too many",
                 ras->colour_repeats);
    if (ras->computed < all && lg->n < room)
        snprintf(add_entry(lg, cm_colour_not_computed, true)->text, LABEL, "not computed  %s",
                 share(all - ras->computed, all).s);
}

/* Entries for the sink, the groups in view with the most cells (as many as
 * `room` lines and max_groups allow; the rest summed up in one line), the
 * groups folded into "other", and the cells not computed. */
/* The label given for a group, or NULL. */
static const char *label_of(const cm_render_options *o, const cm_group_info *g, int dim)
{
    for (int k = 0; k < o->n_labels; k++) {
        const cm_group_label *l = &o->labels[k];
        bool same = l->by_anchor || l->id == g->id;
        for (int d = 0; l->by_anchor && d < dim; d++)
            same = same && l->anchor[d] == g->anchor[d];
        if (same)
            return l->text;
    }
    return NULL;
}

static cm_status make_legend(const cm_render_options *o, const cm_raster *ras,
                             const cm_group_info *groups, uint32_t ngroups, int dim, int room,
                             int max_groups, int bar_mode, legend *lg, char *msg, size_t msg_size)
{
    lg->bar_mode = bar_mode != CM_RASTER_BASIN && room >= BAR_LINES + 2 ? bar_mode : -1;
    if (lg->bar_mode >= 0)
        room -= BAR_LINES;
    const uint64_t all = ras->s.nx * ras->s.ny;
    group_cells *order = malloc(((size_t)ngroups + 1) * sizeof *order);
    lg->e = calloc((size_t)(room > 0 ? room : 1), sizeof *lg->e);
    lg->n = 0;
    if (!order || !lg->e) {
        free(order);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the legend");
    }
    /* Sticking zones share one grey: unlabelled ones take one line between
     * them (a friction map has hundreds), unless there is only one. */
    uint32_t sticking = 0;
    uint64_t sticking_cells = 0;
    for (uint32_t g = 1; g <= ngroups; g++)
        if (ras->group_cells[g] && ras->classes[g] == CM_CLASS_STICKING &&
            !label_of(o, &groups[g - 1], dim))
            sticking++, sticking_cells += ras->group_cells[g];
    const bool one_sticking_line = sticking > 1;
    uint32_t shown = 0;
    for (uint32_t g = 1; g <= ngroups; g++)
        if (ras->group_cells[g] && ras->classes[g] != CM_CLASS_OTHER &&
            !(one_sticking_line && ras->classes[g] == CM_CLASS_STICKING &&
              !label_of(o, &groups[g - 1], dim)))
            order[shown++] = (group_cells){ras->group_cells[g], g};
    qsort(order, shown, sizeof *order, more_cells_first);
    /* max_groups counts coloured groups: named sticking zones (by
     * attractors: the cells outside) come on top */
    int named_sticking = 0;
    for (uint32_t k = 0; k < shown; k++)
        named_sticking += ras->classes[order[k].id] == CM_CLASS_STICKING;
    const int closing = (ras->other_groups ? 1 : 0) + (ras->colour_repeats ? 1 : 0) +
                        (ras->computed < all ? 1 : 0);
    int slots = room - (ras->group_cells[0] ? 1 : 0) - (one_sticking_line ? 1 : 0) - closing;
    slots = slots < max_groups + named_sticking + 1 ? slots : max_groups + named_sticking + 1;
    if (ras->group_cells[0] && lg->n < room)
        snprintf(add_entry(lg, cm_colour_sink, true)->text, LABEL, "%s  %s",
                 o->sink_label ? o->sink_label : "sink", share(ras->group_cells[0], all).s);
    if (one_sticking_line && lg->n < room)
        snprintf(add_entry(lg, cm_colour_sticking, true)->text, LABEL,
                 "%u sticking zones  %s", sticking, share(sticking_cells, all).s);
    const char *noun = o->group_noun ? o->group_noun : "group";
    for (uint32_t k = 0, listed = 0; k < shown && slots > 0; k++, slots--) {
        if ((slots == 1 && k + 1 < shown) || listed == (uint32_t)max_groups) { /* the rest */
            uint64_t rest = 0;
            for (uint32_t r = k; r < shown; r++)
                rest += order[r].cells;
            snprintf(add_entry(lg, paper, false)->text, LABEL, "+ %u more %s%s  %s", shown - k,
                     noun, shown - k == 1 ? "" : "s", share(rest, all).s);
            break;
        }
        listed += ras->classes[order[k].id] != CM_CLASS_STICKING;
        const uint32_t g = order[k].id;
        const cm_group_info *gi = &groups[g - 1];
        const char *label = label_of(o, gi, dim);
        entry *e = add_entry(lg, cm_class_colour(ras->palette, ras->classes[g]), true);
        e->group = g; /* its colour is chosen once the plot's size is known */
        if (label)
            snprintf(e->text, LABEL, "%s  %s", label, share(order[k].cells, all).s);
        else
            snprintf(e->text, LABEL, "#%u%s p=%u  %s", gi->id,
                     gi->kind == CM_GROUP_STICKING ? " sticking" : "", gi->period,
                     share(order[k].cells, all).s);
    }
    closing_entries(ras, all, room, lg);
    free(order);
    return CM_OK;
}

/* ---- title ---------------------------------------------------------------------- */

/* Whether parameter `name` of m is an integrator's or a section's setting
 * (CM_FLOW_PARAM_SPECS, CM_FLOW_SECTION_PARAM_SPECS), not the system's. */
static bool integrator_setting(const cm_model *m, const char *name)
{
    static const char *const settings[] = {"method", "abs_tol", "rel_tol", "world",
                                           "t_max",  "event_tol"};
    if (!m->flow.field)
        return false;
    for (size_t k = 0; k < sizeof settings / sizeof settings[0]; k++)
        if (strcmp(name, settings[k]) == 0)
            return true;
    return false;
}

void figure_title(const cm_model *m, char *out, size_t size)
{
    size_t used = (size_t)snprintf(out, size, "%s ", m->name);
    const cm_params *p = &m->values;
    for (int k = 0; k < p->count && p->spec && p->spec[k].name && used < size; k++) {
        if (integrator_setting(m, p->spec[k].name))
            continue;
        used += (size_t)snprintf(out + used, size - used, " %s=", p->spec[k].name);
        if (p->spec[k].choices && used < size) { /* the word, as --param takes it */
            cm_param_choice_name(p->spec[k].choices, (int)p->value[k].v[0], out + used,
                                 size - used);
            used += strlen(out + used);
            continue;
        }
        for (int i = 0; i < p->value[k].count && used < size; i++)
            used +=
                (size_t)snprintf(out + used, size - used, "%s%s", i ? ":" : "", CM_NUM(p->value[k].v[i]));
    }
}

/* The title (o->title, else the model's) wrapped at spaces onto lines of
 * at most max_w pixels; a word wider than a line has one to itself (and
 * may overflow it), and only a title of more than TITLE_LINES lines is
 * cut, with "...". */
static void wrap_title(const cm_render_options *o, const cm_font *f, int max_w, layout *L)
{
    char text[1024] = "";
    if (o->title)
        snprintf(text, sizeof text, "%s", o->title);
    else if (o->model)
        figure_title(o->model, text, sizeof text);
    L->title_lines = 0;
    const char *p = text;
    while (*p == ' ')
        p++;
    while (*p && L->title_lines < TITLE_LINES) {
        char *line = L->title[L->title_lines++];
        size_t n = 0;
        line[0] = '\0';
        for (;;) { /* add words while they fit */
            const size_t word = strcspn(p, " ");
            char trial[256];
            snprintf(trial, sizeof trial, "%s%s%.*s", line, n ? " " : "", (int)word, p);
            if (n && cm_font_width(f, trial) > max_w)
                break;
            snprintf(line, 256, "%s", trial);
            n++;
            p += word;
            while (*p == ' ')
                p++;
            if (!*p)
                break;
        }
    }
    if (*p) { /* more than TITLE_LINES lines: the rest cut */
        char *last = L->title[TITLE_LINES - 1];
        const size_t n = strlen(last);
        snprintf(last + (n > 252 ? 252 : n), 4, "...");
    }
}

/* ---- layout --------------------------------------------------------------------- */


static bool has_text(unsigned layers) { return layers & CM_LAYERS_TEXT; }

/* Margins of everything but the legend's width. */
static void margins(const cm_render_options *o, const cm_font *f, int dim, layout *L)
{
    const bool axes = o->layers & CM_LAYER_AXES;
    L->ascent = f ? cm_font_ascent(f) : 0;
    L->line = f ? cm_font_height(f) : 0;
    L->pad = L->fs / 2;
    L->tick = L->fs / 3 + 1;
    const char *const *names = o->model ? o->model->coord_names : NULL;
    L->xname = names ? names[0] : dim == 1 ? "x" : "x0";
    if (dim == 1)
        snprintf(L->yname_buf, sizeof L->yname_buf, "f(%s)", L->xname);
    else
        snprintf(L->yname_buf, sizeof L->yname_buf, "%s", names ? names[1] : "x1");
    L->yname = L->yname_buf;
    L->title_lines = 0;
    if (o->layers & CM_LAYER_TITLE)
        wrap_title(o, f, o->width - 2 * L->pad, L);
    L->top = o->layers & CM_LAYER_TITLE ? L->title_lines * L->line + 2 * L->pad
             : f                         ? L->pad + L->ascent / 2
                                         : 0;
    L->bottom = axes ? L->tick + 2 * L->line + L->pad : f ? L->pad : 0;
    L->left = axes ? 2 * L->pad + cm_font_width(f, L->yname) + cm_ticks_widest(f, &L->ty) + L->tick
              : f  ? L->pad
                   : 0;
    L->right = f ? 2 * L->pad : 0;
}

/* ---- axes ----------------------------------------------------------------------- */

static void x_axis(const layout *L, const cm_panel *pn, int ox, int oy, const cm_font *f,
                   const cm_canvas *c)
{
    const int base = oy + pn->y + pn->h;
    int last_right = INT32_MIN / 2;
    for (int k = 0; k < L->tx.n; k++) {
        const int x = ox + pn->x + cm_axis_px(L->tx.v[k], pn->lo[0], pn->hi[0], pn->w);
        cm_fill_rect(c, x, base, 1, L->tick, ink);
        const int w = cm_font_width(f, L->tx.label[k]);
        if (x - w / 2 <= last_right + L->pad)
            continue; /* no overlapping labels */
        cm_font_draw(f, L->tx.label[k], x - w / 2, base + L->tick + L->ascent, ink, c->rgba, c->w,
                     c->h);
        last_right = x - w / 2 + w;
    }
    const int nw = cm_font_width(f, L->xname);
    cm_font_draw(f, L->xname, ox + pn->x + pn->w / 2 - nw / 2, base + L->tick + L->line + L->ascent,
                 ink, c->rgba, c->w, c->h);
}

static void y_axis(const layout *L, const cm_panel *pn, int ox, int oy, const cm_font *f,
                   const cm_canvas *c)
{
    const int x0 = ox + pn->x;
    for (int k = 0; k < L->ty.n; k++) {
        const int y = oy + pn->y + pn->h - 1 - cm_axis_px(L->ty.v[k], pn->lo[1], pn->hi[1], pn->h);
        cm_fill_rect(c, x0 - L->tick, y, L->tick, 1, ink);
        const int w = cm_font_width(f, L->ty.label[k]);
        cm_font_draw(f, L->ty.label[k], x0 - L->tick - 2 - w, y + L->ascent / 2 - 1, ink, c->rgba,
                     c->w, c->h);
    }
    cm_font_draw(f, L->yname, L->pad, oy + pn->y + pn->h / 2 + L->ascent / 2, ink, c->rgba, c->w,
                 c->h);
}

static void frame(const cm_panel *pn, int ox, int oy, const cm_canvas *c)
{
    const int x = ox + pn->x, y = oy + pn->y;
    cm_fill_rect(c, x - 1, y - 1, pn->w + 2, 1, ink);
    cm_fill_rect(c, x - 1, y + pn->h, pn->w + 2, 1, ink);
    cm_fill_rect(c, x - 1, y - 1, 1, pn->h + 2, ink);
    cm_fill_rect(c, x + pn->w, y - 1, 1, pn->h + 2, ink);
}

uint8_t figure_bar_grey(int mode, double f)
{
    const int s = cm_step_shade(f, mode);
    return (uint8_t)(mode == CM_RASTER_STEPS ? s : (255 * s) >> 8);
}

/* The step bar: light (no steps) at the top to dark (the cap) at the
 * bottom, labelled with step numbers on the shading's log scale. */
static void draw_step_bar(const legend *lg, const cm_raster *ras, const layout *L, int x, int y,
                          const cm_font *f, const cm_canvas *c)
{
    const int box = L->ascent, top = y + L->line + L->pad, h = (BAR_LINES - 2) * L->line;
    cm_font_draw(f, BAR_TITLE, x, y + L->ascent, ink, c->rgba, c->w, c->h);
    cm_fill_rect(c, x, top - 1, box + 2, h + 2, ink);
    for (int r = 0; r < h; r++) {
        const uint8_t g = figure_bar_grey(lg->bar_mode, h > 1 ? (double)r / (h - 1) : 0);
        cm_fill_rect(c, x + 1, top + r, box, 1, (cm_rgb){g, g, g});
    }
    for (int k = 0; k <= 2; k++) {
        char label[32];
        const uint32_t steps = cm_step_at(k / 2.0, ras->step_cap);
        snprintf(label, sizeof label, k == 2 ? "%u or more" : "%u", steps);
        cm_font_draw(f, label, x + box + L->pad, top + k * (h - 1) / 2 + L->ascent / 2, ink, c->rgba,
                     c->w, c->h);
    }
}

static void draw_legend(const legend *lg, const layout *L, int x, int y, const cm_font *f,
                        const cm_canvas *c)
{
    const int box = L->ascent;
    for (int k = 0; k < lg->n; k++) {
        const int base = y + (k + 1) * L->line;
        if (lg->e[k].has_swatch) {
            cm_fill_rect(c, x, base - box, box, box, ink);
            cm_fill_rect(c, x + 1, base - box + 1, box - 2, box - 2, lg->e[k].swatch);
        }
        cm_font_draw(f, lg->e[k].text, x + box + L->pad, base, ink, c->rgba, c->w, c->h);
    }
}

/* ---- the figure ----------------------------------------------------------------- */

static void default_view(const cm_slice *s, int dim, const cm_render_options *o, double lo[2],
                         double hi[2])
{
    lo[0] = o->lo[0];
    hi[0] = o->hi[0];
    lo[1] = o->lo[1];
    hi[1] = o->hi[1];
    if (lo[0] == hi[0]) {
        lo[0] = s->x0;
        hi[0] = s->x0 + (double)s->nx * s->dx;
    }
    if (lo[1] == hi[1] || dim == 1) {
        lo[1] = s->y0;
        hi[1] = s->y0 + (double)s->ny * s->dy;
    }
}

static int raster_mode(unsigned layers)
{
    if (layers & CM_LAYER_STEPS)
        return layers & CM_LAYER_BASIN ? CM_RASTER_SHADED : CM_RASTER_STEPS;
    return CM_RASTER_BASIN;
}

/* Splits the plot into panels: 2-D, one basin panel; 1-D, the map's graph
 * above a basin strip. */
static void make_panels(cm_plot *p, int dim, const double lo[2], const double hi[2], int gap)
{
    memset(&p->graph, 0, sizeof p->graph);
    p->basin = (cm_panel){0, 0, p->w, p->h, {lo[0], lo[1]}, {hi[0], hi[1]}};
    if (dim != 1 || !p->model || p->h < 8)
        return;
    const int strip = p->h / 5 > 1 ? p->h / 5 : 1;
    gap = gap < p->h - strip - 1 ? gap : 0;
    p->graph = (cm_panel){0, 0, p->w, p->h - strip - gap, {lo[0], lo[0]}, {hi[0], hi[0]}};
    p->basin.y = p->h - strip;
    p->basin.h = strip;
}


static void work_free(work *w)
{
    cm_raster_free(&w->ras);
    free(w->ov.items);
    cm_font_close(w->font);
    free(w->lg.e);
}

static cm_status check_options(const cm_render_options *o, char *msg, size_t msg_size)
{
    if (o->width < 1 || o->height < 1 || o->width > CM_RENDER_MAX_SIDE ||
        o->height > CM_RENDER_MAX_SIDE)
        return cm_fail(CM_EINVAL, msg, msg_size, "image size %dx%d: each side must be 1..%d",
                       o->width, o->height, CM_RENDER_MAX_SIDE);
    if (has_text(o->layers) && !o->font_path)
        return cm_fail(CM_EINVAL, msg, msg_size, "axes, legend and title need a font");
    if ((o->layers & CM_LAYER_TITLE) && !o->model && !o->title)
        return cm_fail(CM_EINVAL, msg, msg_size, "a title needs the model or its text");
    if (!(o->font_px >= 0 && o->font_px <= CM_RENDER_MAX_FONT))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a font of %g pixels: give 0 (from the image's size) up to %d; at --dpi "
                       "D a font of P points is P*D/72 pixels",
                       o->font_px, CM_RENDER_MAX_FONT);
    if (!(o->dpi == 0 || (o->dpi >= 1 && o->dpi <= 1e5)))
        return cm_fail(CM_EINVAL, msg, msg_size, "%g pixels per inch: give 0 or 1..100000",
                       o->dpi);
    return CM_OK;
}

/* Text needs a plot of 16 pixels a side beside it; a bare image any size. */
static cm_status check_room(const cm_render_options *o, const layout *L, char *msg,
                            size_t msg_size)
{
    const int least = has_text(o->layers) ? 16 : 1;
    if (o->width - L->left - L->right < least || o->height - L->top - L->bottom < least)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "%dx%d leaves no room for the plot beside axes, legend and title; enlarge "
                       "--size or leave those layers out",
                       o->width, o->height);
    return CM_OK;
}

/* The text's size in pixels: the options', or 1/45 of the image's
 * shorter side within 10..48. */
static int font_pixels(const cm_render_options *o)
{
    if (o->font_px > 0)
        return (int)lround(o->font_px);
    const int small = o->width < o->height ? o->width : o->height;
    return small / 45 < 10 ? 10 : small / 45 > 48 ? 48 : small / 45;
}

cm_status cm_render_check(const cm_render_options *opt, int dim, char *msg, size_t msg_size)
{
    cm_render_options o = *opt;
    o.layers = o.layers ? o.layers : CM_LAYER_BASIN | CM_LAYER_ATTRACTORS;
    cm_status st = check_options(&o, msg, msg_size);
    if (st == CM_OK && cm_plot_needs_gl(o.layers, o.model, dim))
        st = cm_gl_load(msg, msg_size); /* a missing OSMesa stops the command before its work */
    if (st != CM_OK || !has_text(o.layers))
        return st;
    layout L;
    memset(&L, 0, sizeof L);
    L.fs = font_pixels(&o);
    cm_font *font = NULL;
    st = cm_font_open(o.font_path, L.fs, &font, msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_make_ticks(o.lo[0], o.hi[0], &L.tx);
    cm_make_ticks(dim == 1 ? o.lo[0] : o.lo[1], dim == 1 ? o.hi[0] : o.hi[1], &L.ty);
    margins(&o, font, dim, &L);
    if (o.layers & CM_LAYER_LEGEND) /* at least the sink's entry */
        L.right = 3 * L.pad + L.ascent + cm_font_width(font, "sink");
    cm_font_close(font);
    return check_room(&o, &L, msg, msg_size);
}

/* Everything computed before pixels: raster, overlays, font, margins. */
static cm_status prepare(const cm_lattice *lat, const cm_region *r, const cm_group_info *groups,
                         const cm_render_options *o, const cm_slice *s, const double lo[2],
                         const double hi[2], work *w, layout *L, char *msg, size_t msg_size)
{
    const int dim = r->box.dim;
    cm_status st =
        cm_raster_build(lat, r, groups, s, raster_mode(o->layers), o->min_basin, o->palette,
                        &w->ras, msg, msg_size);
    if (st == CM_OK && o->model && o->model->overlays && (o->layers & CM_LAYER_OVERLAYS)) {
        w->ov.items = malloc(OVERLAY_CAP * sizeof *w->ov.items);
        w->ov.cap = w->ov.items ? OVERLAY_CAP : 0;
        const double glo[2] = {lo[0], dim == 1 ? lo[0] : lo[1]};
        const double ghi[2] = {hi[0], dim == 1 ? hi[0] : hi[1]};
        if (!w->ov.items)
            st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for overlays");
        else
            o->model->overlays(o->model, glo, ghi, &w->ov);
    }
    L->fs = font_pixels(o);
    if (st == CM_OK && has_text(o->layers))
        st = cm_font_open(o->font_path, L->fs, &w->font, msg, msg_size);
    if (st == CM_OK) {
        cm_make_ticks(lo[0], hi[0], &L->tx);
        cm_make_ticks(dim == 1 ? lo[0] : lo[1], dim == 1 ? hi[0] : hi[1], &L->ty);
        margins(o, w->font, dim, L);
    }
    if (st == CM_OK && (o->layers & CM_LAYER_LEGEND)) {
        const int room = (o->height - L->top - L->bottom) / (L->line > 0 ? L->line : 1);
        st = make_legend(o, &w->ras, groups, r->ngroups, dim, room,
                         o->legend_groups > 0 ? o->legend_groups : LEGEND_GROUPS,
                         raster_mode(o->layers), &w->lg, msg, msg_size);
        int widest_entry = w->lg.bar_mode >= 0 ? cm_font_width(w->font, BAR_TITLE) : 0;
        for (int k = 0; k < w->lg.n; k++) {
            const int ew = cm_font_width(w->font, w->lg.e[k].text);
            widest_entry = ew > widest_entry ? ew : widest_entry;
        }
        L->right = 3 * L->pad + L->ascent + widest_entry;
    }
    return st == CM_OK ? check_room(o, L, msg, msg_size) : st;
}

static void draw_text_layers(const cm_render_options *o, const work *w, const layout *L,
                             const cm_plot *p, const cm_canvas *c)
{
    if (o->layers & CM_LAYER_AXES) {
        frame(&p->basin, p->x, p->y, c);
        x_axis(L, &p->basin, p->x, p->y, w->font, c);
        const cm_panel *yp = p->graph.w > 0 ? &p->graph : &p->basin;
        if (p->graph.w > 0)
            frame(&p->graph, p->x, p->y, c);
        y_axis(L, yp, p->x, p->y, w->font, c);
    }
    if (o->layers & CM_LAYER_LEGEND) {
        draw_legend(&w->lg, L, p->x + p->w + 2 * L->pad, p->y, w->font, c);
        if (w->lg.bar_mode >= 0)
            draw_step_bar(&w->lg, &w->ras, L, p->x + p->w + 2 * L->pad,
                          p->y + (w->lg.n + 1) * L->line, w->font, c);
    }
    for (int k = 0; k < L->title_lines; k++)
        cm_font_draw(w->font, L->title[k], L->pad, L->pad + L->ascent + k * L->line, ink, c->rgba,
                     c->w, c->h);
}

/* The plot shrunk to the largest rectangle of its room whose pixels per
 * state unit along y are `aspect` times those along x: at the room's left
 * (the legend follows it), centred from top to bottom. */
static void keep_aspect(double aspect, const double lo[2], const double hi[2], cm_plot *p)
{
    const double ratio = aspect * (hi[1] - lo[1]) / (hi[0] - lo[0]); /* height / width */
    if (!(ratio > 0) || !isfinite(ratio))
        return;
    int w = p->w, h = (int)lround(p->w * ratio);
    if (h > p->h) {
        h = p->h;
        w = (int)lround(p->h / ratio);
    }
    w = w < 1 ? 1 : w, h = h < 1 ? 1 : h;
    p->y += (p->h - h) / 2;
    p->w = w, p->h = h;
}

/* The raster's colours, chosen for the basins that touch at the plot's
 * resolution, and the legend's swatches to match. */
static cm_status paint(const cm_lattice *lat, const cm_region *r, const cm_group_info *groups,
                       figure *F, char *msg, size_t msg_size)
{
    const cm_slice *s = &F->s;
    const double view_x = (F->hi[0] - F->lo[0]) / s->dx, view_y = (F->hi[1] - F->lo[1]) / s->dy;
    const uint32_t reach_x = cm_touching_reach((uint64_t)ceil(view_x), F->p.basin.w);
    const uint32_t reach_y =
        r->box.dim > 1 ? cm_touching_reach((uint64_t)ceil(view_y), F->p.basin.h) : 1;
    cm_status st = cm_raster_choose(lat, r, groups, reach_x, reach_y, &F->w.ras, msg, msg_size);
    for (int k = 0; st == CM_OK && k < F->w.lg.n; k++)
        if (F->w.lg.e[k].group)
            F->w.lg.e[k].swatch =
                cm_class_colour(F->w.ras.palette, F->w.ras.classes[F->w.lg.e[k].group]);
    return st;
}

cm_status figure_begin(const cm_lattice *lat, const cm_region *r, const cm_group_info *groups,
                       const cm_render_options *opt, figure *F, char *msg, size_t msg_size)
{
    memset(F, 0, sizeof *F);
    F->o = *opt;
    F->o.layers = F->o.layers ? F->o.layers : CM_LAYER_BASIN | CM_LAYER_ATTRACTORS;
    cm_status st = check_options(&F->o, msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_slice_of(lat, r, F->o.slice, F->o.set_slice, &F->s);
    default_view(&F->s, r->box.dim, &F->o, F->lo, F->hi);
    st = prepare(lat, r, groups, &F->o, &F->s, F->lo, F->hi, &F->w, &F->L, msg, msg_size);
    const layout *L = &F->L;
    F->p = (cm_plot){&F->w.ras,
                     groups,
                     F->w.ov.items ? &F->w.ov : NULL,
                     F->o.model,
                     F->o.layers,
                     L->left,
                     L->top,
                     F->o.width - L->left - L->right,
                     F->o.height - L->top - L->bottom,
                     {0},
                     {0},
                     0,
                     3,
                     F->o.gl};
    if (st == CM_OK && F->o.aspect > 0 && r->box.dim >= 2)
        keep_aspect(F->o.aspect, F->lo, F->hi, &F->p);
    if (st == CM_OK) {
        const int small = F->p.w < F->p.h ? F->p.w : F->p.h;
        F->p.line_width = small / 700 > 1 ? small / 700 : 1;
        /* attractors visible in print: 5 px on a 700-px plot, never under 3 */
        F->p.marker = small / 140.0 > 3 ? small / 140.0 : 3;
        make_panels(&F->p, r->box.dim, F->lo, F->hi, L->line ? L->line / 2 : 4);
        st = paint(lat, r, groups, F, msg, msg_size);
    }
    return st;
}

void figure_end(figure *F) { work_free(&F->w); }

cm_status cm_render_figure(const cm_lattice *lat, const cm_region *r, const cm_group_info *groups,
                           const cm_render_options *opt, uint8_t *rgba, cm_render_info *info,
                           char *msg, size_t msg_size)
{
    memset(info, 0, sizeof *info);
    figure F;
    double t0 = cm_seconds();
    cm_status st = figure_begin(lat, r, groups, opt, &F, msg, msg_size);
    info->raster_s = cm_seconds() - t0;
    const cm_render_options *o = &F.o;
    const cm_plot *p = &F.p;
    const cm_canvas c = {rgba, o->width, o->height};
    if (st == CM_OK) {
        /* the margins; GL paints the plot itself */
        cm_fill_rect(&c, 0, 0, o->width, p->y, paper);
        cm_fill_rect(&c, 0, p->y + p->h, o->width, o->height - p->y - p->h, paper);
        cm_fill_rect(&c, 0, p->y, p->x, p->h, paper);
        cm_fill_rect(&c, p->x + p->w, p->y, o->width - p->x - p->w, p->h, paper);
        t0 = cm_seconds();
        st = cm_plot_draw(p, rgba, o->width, &info->tiles, msg, msg_size);
        info->gl_s = cm_seconds() - t0;
    }
    if (st == CM_OK && F.w.font) {
        t0 = cm_seconds();
        draw_text_layers(o, &F.w, &F.L, p, &c);
        info->text_s = cm_seconds() - t0;
    }
    if (st == CM_OK) {
        info->plot_x = p->x + p->basin.x;
        info->plot_y = p->y + p->basin.y;
        info->plot_w = p->basin.w;
        info->plot_h = p->basin.h;
        if (p->graph.w > 0) {
            info->graph_x = p->x + p->graph.x;
            info->graph_y = p->y + p->graph.y;
            info->graph_w = p->graph.w;
            info->graph_h = p->graph.h;
        }
        memcpy(info->lo, F.lo, sizeof info->lo);
        memcpy(info->hi, F.hi, sizeof info->hi);
        info->overlays_truncated = F.w.ov.truncated;
    }
    figure_end(&F);
    return st;
}
