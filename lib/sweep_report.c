/* What a sweep found, written (lib/sweep_report.h). */
#include "lib/sweep_report.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lib/figure.h"
#include "lib/json.h"
#include "lib/outfile.h"
#include "lib/param_grid.h"
#include "render/palette.h"

void sweep_print_point(FILE *f, const char *name, const sweep_point *pt)
{
    fprintf(f, "%s = %-12.9g %3u attractor(s), %3u sticking group(s) in the window; basins %llu "
               "and %llu cells; %u groups; %.2f s\n",
            name, pt->value, pt->attractors, pt->sticking, (unsigned long long)pt->attractor_cells,
            (unsigned long long)pt->sticking_cells, pt->groups, pt->seconds);
}

void sweep_print_change(FILE *f, const char *name, const sweep_change *ch)
{
    fprintf(f, "change: %u attractor(s) at %s = %.9g, %u at %.9g (width %.3g)%s\n",
            ch->lo.attractors, name, ch->lo.value, ch->hi.attractors, ch->hi.value,
            ch->hi.value - ch->lo.value,
            ch->several ? "; more than one attractor changes within it" : "");
}

/* The shares besides the tracked attractors, in the figure's order. */
enum { RESTS = 5 };
static const char *const rest_name[RESTS] = {"sticking", "elsewhere", "diverged", "outside",
                                             "undecided"};

static uint64_t rest_cells(const sweep_point *p, int k)
{
    const uint64_t c[RESTS] = {p->sticking_cells, p->elsewhere_cells, p->diverged_cells,
                               p->outside_cells, p->undecided_cells};
    return c[k];
}

static const char *event_word(int kind)
{
    static const char *const word[] = {"appears", "vanishes", "merges", "collapses"};
    return word[kind];
}

void sweep_print_tracked(FILE *f, const sweep_args *a, const sweep_result *r)
{
    if (a->by != BY_ATTRACTORS)
        return;
    fprintf(f, "%u attractor(s) tracked; basin shares of the region's cells (seeded: found by "
               "the true map, no cell of its basin on the lattice):\n",
            r->tracked);
    for (int k = 0; k < r->n; k++) {
        const sweep_point *p = &r->pts[k];
        fprintf(f, "%s = %-12.9g", a->name, p->value);
        for (uint32_t j = 0; j < p->attractors; j++)
            if (p->att[j].seeded)
                fprintf(f, "  #%u seeded", p->att[j].id);
            else
                fprintf(f, "  #%u %.4f", p->att[j].id,
                        (double)p->att[j].basin_cells / (double)p->cells);
        for (int i = 0; i < RESTS; i++)
            if (rest_cells(p, i))
                fprintf(f, "  %s %.4f", rest_name[i], (double)rest_cells(p, i) / (double)p->cells);
        fputc('\n', f);
    }
    for (int k = 0; k < r->n_events; k++) {
        const sweep_event *e = &r->events[k];
        fprintf(f, "attractor #%u %s", e->id, event_word(e->kind));
        if (e->kind == SWEEP_MERGES)
            fprintf(f, " into #%u", e->into);
        fprintf(f, " between %s = %.9g and %.9g (width %.3g)\n", a->name, e->from, e->to,
                e->to - e->from);
    }
}

static void json_attractors(json *j, const sweep_point *p, int dim)
{
    json_array(j, "tracked");
    for (uint32_t k = 0; k < p->attractors; k++) {
        const sweep_attractor *t = &p->att[k];
        json_object(j, NULL);
        json_uint(j, "id", t->id);
        json_str(j, "kind", cm_attractor_kind_name(t->kind));
        json_uint(j, "period", t->period);
        json_nums(j, "centre", t->centre, dim);
        json_uint(j, "cells", t->basin_cells);
        json_num(j, "share", (double)t->basin_cells / (double)p->cells);
        if (t->seeded)
            json_bool(j, "seeded", true);
        json_object_end(j);
    }
    json_array_end(j);
    json_uint(j, "cells", p->cells);
    for (int i = 0; i < RESTS; i++) {
        char key[32];
        snprintf(key, sizeof key, "%s_cells", rest_name[i]);
        json_uint(j, key, rest_cells(p, i));
    }
}

void sweep_json(FILE *f, const sweep_args *a, const sweep_result *r)
{
    cm_model m;
    char msg[256];
    if (!model_with_values(&a->mo, NULL, NULL, 0, &m, msg, sizeof msg))
        return; /* checked before the sweep */
    json j;
    json_begin(&j, f, "sweep");
    json_model(&j, &m);
    cm_model_release(&m);
    json_lattice(&j, &r->lat);
    json_box(&j, "box", &r->lat, &r->box);
    json_str(&j, "parameter", a->name);
    json_array(&j, "points");
    for (int k = 0; k < r->n; k++) {
        const sweep_point *p = &r->pts[k];
        json_object(&j, NULL);
        json_num(&j, "value", p->value);
        json_uint(&j, "attractors", p->attractors);
        json_uint(&j, "sticking", p->sticking);
        json_uint(&j, "attractor_cells", p->attractor_cells);
        json_uint(&j, "sticking_cells", p->sticking_cells);
        json_uint(&j, "groups", p->groups);
        json_uint(&j, "sink_cells", p->sink_cells);
        if (a->by == BY_ATTRACTORS)
            json_attractors(&j, p, r->lat.dim);
        json_seconds(&j, "seconds", p->seconds);
        json_object_end(&j);
    }
    json_array_end(&j);
    json_array(&j, "changes");
    for (int k = 0; k < r->n_changes; k++) {
        const sweep_change *c = &r->changes[k];
        json_object(&j, NULL);
        json_num(&j, "from", c->lo.value);
        json_num(&j, "to", c->hi.value);
        json_uint(&j, "attractors_from", c->lo.attractors);
        json_uint(&j, "attractors_to", c->hi.attractors);
        json_bool(&j, "several", c->several);
        json_object_end(&j);
    }
    json_array_end(&j);
    if (a->by == BY_ATTRACTORS) {
        json_uint(&j, "tracked", r->tracked);
        json_array(&j, "events");
        for (int k = 0; k < r->n_events; k++) {
            const sweep_event *e = &r->events[k];
            json_object(&j, NULL);
            json_str(&j, "event", event_word(e->kind));
            json_uint(&j, "id", e->id);
            if (e->kind == SWEEP_MERGES)
                json_uint(&j, "into", e->into);
            json_num(&j, "from", e->from);
            json_num(&j, "to", e->to);
            json_object_end(&j);
        }
        json_array_end(&j);
    }
    json_end(&j);
}

static cm_status write_fractions(const sweep_args *a, const sweep_result *r, char *msg,
                                 size_t msg_size)
{
    outfile o;
    cm_status st = outfile_begin(a->fractions, &o, msg, msg_size);
    if (st != CM_OK)
        return st;
    fprintf(o.f, "%s,basin,kind,period,cells,share", a->name);
    for (int d = 0; d < r->lat.dim; d++)
        fprintf(o.f, ",centre_%d", d);
    fputc('\n', o.f);
    for (int k = 0; k < r->n; k++) {
        const sweep_point *p = &r->pts[k];
        for (uint32_t j = 0; j < p->attractors; j++) {
            const sweep_attractor *t = &p->att[j];
            fprintf(o.f, "%.17g,%u,%s,%u,%llu,%.17g", p->value, t->id,
                    cm_attractor_kind_name(t->kind), t->period,
                    (unsigned long long)t->basin_cells,
                    (double)t->basin_cells / (double)p->cells);
            for (int d = 0; d < r->lat.dim; d++)
                fprintf(o.f, ",%.17g", t->centre[d]);
            fputc('\n', o.f);
        }
        for (int i = 0; i < RESTS; i++) {
            fprintf(o.f, "%.17g,%s,,,%llu,%.17g", p->value, rest_name[i],
                    (unsigned long long)rest_cells(p, i),
                    (double)rest_cells(p, i) / (double)p->cells);
            for (int d = 0; d < r->lat.dim; d++)
                fputc(',', o.f);
            fputc('\n', o.f);
        }
    }
    return outfile_end(&o, true, msg, msg_size);
}

/* Band b's share at point p: tracked attractor id b + 1, then the rests. */
static double band_share(const sweep_point *p, uint32_t b, uint32_t tracked)
{
    if (b >= tracked)
        return (double)rest_cells(p, (int)(b - tracked)) / (double)p->cells;
    for (uint32_t j = 0; j < p->attractors; j++)
        if (p->att[j].id == b + 1)
            return (double)p->att[j].basin_cells / (double)p->cells;
    return 0;
}

static cm_rgb band_colour(uint32_t b, uint32_t tracked)
{
    static const cm_rgb undecided = {120, 120, 120};
    const cm_rgb rest[RESTS] = {cm_colour_sticking, cm_colour_other, cm_colour_sink,
                                cm_colour_not_computed, undecided};
    const cm_palette *pal = cm_palette_default();
    return b < tracked ? pal->colour[b % (uint32_t)pal->n] : rest[b - tracked];
}

/* The figure: each band a vertical segment per pixel column of the
 * parameter's range, its shares interpolated between the values solved;
 * each band named where it is widest. */
static cm_status write_figure(const sweep_args *a, const sweep_result *r, char *msg,
                              size_t msg_size)
{
    const int width = a->width ? a->width : 900, height = a->height ? a->height : 560;
    const int columns = width, bands = (int)r->tracked + RESTS;
    const double x0 = r->pts[0].value, x1 = r->pts[r->n - 1].value;
    double *xy = calloc((size_t)bands * columns * 4, sizeof *xy), *cum = calloc(columns, sizeof *cum);
    cm_series *series = calloc((size_t)bands, sizeof *series);
    cm_chart_label *labels = calloc((size_t)bands, sizeof *labels);
    char *texts = calloc((size_t)bands, 32);
    if (!xy || !cum || !series || !labels || !texts) {
        free(xy), free(cum), free(series), free(labels), free(texts);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the figure");
    }
    int n_series = 0, n_labels = 0;
    for (int b = 0; b < bands; b++) {
        double *x = xy + (size_t)b * columns * 4, *y = x + 2 * columns, widest = 0;
        int at = 0;
        for (int c = 0, k = 0; c < columns; c++) {
            const double v = x0 + (x1 - x0) * (c + 0.5) / columns;
            while (k + 2 < r->n && r->pts[k + 1].value < v)
                k++;
            const sweep_point *p = &r->pts[k], *q = &r->pts[k + (r->n > 1)];
            const double t = q->value > p->value ? (v - p->value) / (q->value - p->value) : 0;
            const double s = (1 - t) * band_share(p, (uint32_t)b, r->tracked) +
                             t * band_share(q, (uint32_t)b, r->tracked);
            x[2 * c] = x[2 * c + 1] = v, y[2 * c] = cum[c], y[2 * c + 1] = cum[c] + s;
            cum[c] += s;
            if (s > widest)
                widest = s, at = c;
        }
        if (widest == 0)
            continue;
        series[n_series++] = (cm_series){CM_SERIES_SEGMENTS, x, y, 2 * (size_t)columns,
                                         band_colour((uint32_t)b, r->tracked), 2};
        char *text = texts + (size_t)b * 32;
        if (b < (int)r->tracked)
            snprintf(text, 32, "#%d", b + 1);
        else
            snprintf(text, 32, "%s", rest_name[b - (int)r->tracked]);
        if (widest > 0.03)
            labels[n_labels++] = (cm_chart_label){x[2 * at], (y[2 * at] + y[2 * at + 1]) / 2, text};
    }
    char title[200];
    snprintf(title, sizeof title, "basin shares of %u tracked attractor(s) against %s; %d event(s)",
             r->tracked, a->name, r->n_events);
    const cm_chart chart = {width, height, {x0, 0}, {x1, 1}, a->name, "share of the region's cells",
                            title, NULL, series, n_series, figure_font(), 0, labels, n_labels};
    const cm_png_text png_texts[] = {{"Parameter", a->name}};
    const cm_status st = outfile_charts(a->png, &chart, 1, png_texts, 1, msg, msg_size);
    free(xy), free(cum), free(series), free(labels), free(texts);
    return st;
}

cm_status sweep_write_tracked(const sweep_args *a, const sweep_result *r, char *msg,
                              size_t msg_size)
{
    cm_status st = CM_OK;
    if (a->fractions)
        st = write_fractions(a, r, msg, msg_size);
    if (st == CM_OK && a->png && r->n > 0)
        st = write_figure(a, r, msg, msg_size);
    return st;
}
