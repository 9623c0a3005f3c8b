/* The largest Lyapunov exponent of one series by delay embedding
 * (lib/embedding.h). */
#include "lib/embedding.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lib/json.h"
#include "lib/figure.h"
#include "lib/outfile.h"
#include "lib/rows.h"

/* The fraction of false neighbours below which a dimension embeds. */
#define EMBEDS_BELOW 0.01
/* The widest row a series file may have. */
#define LINE_MAX_CHARS 65536
#define MAX_COLUMNS 256

embed_args embedding_defaults(void)
{
    embed_args a;
    memset(&a, 0, sizeof a);
    a.sim = series_defaults();
    a.extrema = 1;
    a.lag = 1, a.steps = 40, a.fnn_dim = 14, a.ratio = 10;
    a.radius[0] = 0.005, a.radius[1] = 0.01, a.radius[2] = 0.02, a.n_radius = 3;
    a.width = 900, a.height = 900;
    return a;
}

bool embedding_values(const char *word, int *extrema)
{
    const bool max = strcmp(word, "max") == 0, min = strcmp(word, "min") == 0;
    *extrema = max ? 1 : min ? -1 : 0;
    return max || min || strcmp(word, "all") == 0;
}

void embedding_take_run(embed_args *e, const exp_args *a)
{
    e->sim.mo = a->mo;
    _Static_assert(sizeof e->sim.from >= sizeof a->from, "a series' start holds the spectrum's");
    memcpy(e->sim.from, a->from, sizeof a->from);
    e->sim.n_from = a->n_from;
    e->sim.time = a->o.transient + a->o.time, e->sim.skip = a->o.transient;
    e->csv = a->csv, e->png = a->png;
    if (a->width) /* given */
        e->width = a->width, e->height = a->height;
}

static cm_status check_args(const embed_args *a, char *msg, size_t msg_size)
{
    const int dims = a->dim_lo ? a->dim_hi - a->dim_lo + 1 : 3;
    if (a->lag < 1 || a->steps < 2 || a->steps > 100000)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the lag must be >= 1 and the steps 2..100000 (lag %d, steps %d)", a->lag,
                       a->steps);
    if (a->dim_lo && (a->dim_lo < 1 || a->dim_hi < a->dim_lo || a->dim_hi > CM_EMBED_MAX_DIM ||
                      dims > EMBED_MAX_DIMS))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the dimensions must be M or M:M2 with 1 <= M <= M2 <= %d, at most %d of "
                       "them (%d:%d)",
                       CM_EMBED_MAX_DIM, EMBED_MAX_DIMS, a->dim_lo, a->dim_hi);
    if (a->fnn_dim < 1 || a->fnn_dim > CM_EMBED_MAX_DIM || !(a->ratio > 0))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "false neighbours need dimensions 1..%d and a threshold > 0 (%d, %g)",
                       CM_EMBED_MAX_DIM, a->fnn_dim, a->ratio);
    if (a->n_radius < 1 || a->n_radius > EMBED_MAX_RADII)
        return cm_fail(CM_EINVAL, msg, msg_size, "give 1..%d radii", EMBED_MAX_RADII);
    for (int k = 0; k < a->n_radius; k++)
        if (!(a->radius[k] > 0 && a->radius[k] <= 1))
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "radius %g: radii are fractions of the series' range, in (0, 1]",
                           a->radius[k]);
    if (a->fit_hi && (a->fit_lo < 0 || a->fit_hi <= a->fit_lo || a->fit_hi > a->steps))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the fit K0:K1 needs 0 <= K0 < K1 <= steps (%d:%d, steps %d)", a->fit_lo,
                       a->fit_hi, a->steps);
    if (a->theiler < 0 || !(a->time_unit >= 0) || a->extrema < -1 || a->extrema > 1)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the Theiler window and the time unit must not be negative");
    return CM_OK;
}

/* ---- the series ---- */

static cm_status take(embed_result *r, const double *t, const double *x, size_t stride, size_t n,
                      int extrema, char *msg, size_t msg_size)
{
    r->s = malloc(n * sizeof *r->s);
    r->ts = t ? malloc(n * sizeof *r->ts) : NULL;
    if (!r->s || (t && !r->ts))
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %zu values", n);
    if (extrema && t) {
        r->n = cm_series_extrema(t, x, stride, n, extrema, r->ts, r->s);
    } else if (extrema) { /* a file without times: the row is the time */
        double *index = malloc(2 * n * sizeof *index);
        if (!index)
            return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %zu values", n);
        for (size_t i = 0; i < n; i++)
            index[i] = (double)i;
        r->n = cm_series_extrema(index, x, stride, n, extrema, index + n, r->s);
        free(index);
    } else {
        for (size_t i = 0; i < n; i++)
            r->s[i] = x[i * stride];
        if (t)
            memcpy(r->ts, t, n * sizeof *t);
        r->n = n;
    }
    return CM_OK;
}

static cm_status simulated(const embed_args *a, embed_result *r, char *msg, size_t msg_size)
{
    series_result sr;
    cm_status st = series_compute(&a->sim, &sr, msg, msg_size);
    if (st == CM_OK) {
        snprintf(r->source, sizeof r->source, "%s (%s)", sr.model, sr.params);
        snprintf(r->name, sizeof r->name, "%s", sr.names[sr.of]);
        st = take(r, sr.t, sr.x + sr.of, (size_t)sr.dim, sr.n, a->extrema, msg, msg_size);
    }
    series_result_free(&sr);
    return st;
}

/* Splits a CSV line at commas in place; returns the fields. */
static int split(char *line, char **f)
{
    int n = 0;
    line[strcspn(line, "\r\n")] = 0;
    for (char *p = line; n < MAX_COLUMNS; p++) {
        f[n++] = p;
        p += strcspn(p, ",");
        if (!*p)
            break;
        *p = 0;
    }
    return n;
}

typedef struct table {
    double *t, *x;
    size_t n, cap, cap_x;
} table;

static bool table_put(table *tb, double t, double x, bool timed)
{
    if (!rows_room((void **)&tb->x, &tb->cap_x, tb->n, sizeof *tb->x) ||
        (timed && !rows_room((void **)&tb->t, &tb->cap, tb->n, sizeof *tb->t)))
        return false;
    tb->x[tb->n] = x;
    if (timed)
        tb->t[tb->n] = t;
    tb->n++;
    return true;
}

/* The column named `column` (NULL: the first but t) and t's in the
 * header; the column's name into name. */
static int header_columns(char *line, const char *column, int *col_t, char *name,
                          size_t name_size)
{
    char *f[MAX_COLUMNS];
    const int n = split(line, f);
    int col = -1;
    *col_t = -1;
    for (int i = 0; i < n; i++) {
        if (strcmp(f[i], "t") == 0 && *col_t < 0)
            *col_t = i;
        else if (col < 0 && (column ? strcmp(f[i], column) == 0 : true))
            col = i;
    }
    if (col >= 0)
        snprintf(name, name_size, "%s", f[col]);
    return col;
}

static cm_status read_rows(FILE *f, const char *path, int col, int col_t, table *tb, char *line,
                           char *msg, size_t msg_size)
{
    for (size_t row = 2; fgets(line, LINE_MAX_CHARS, f); row++) {
        if (line[0] == '#' || line[strspn(line, " \t\r\n")] == 0)
            continue;
        char *v[MAX_COLUMNS], *end_x, *end_t = NULL;
        const int n = split(line, v);
        if (n <= col || n <= col_t)
            return cm_fail(CM_EINVAL, msg, msg_size, "%s:%zu: %d fields, too few for the column",
                           path, row, n);
        const double x = strtod(v[col], &end_x);
        const double t = col_t >= 0 ? strtod(v[col_t], &end_t) : 0;
        if (end_x == v[col] || *end_x || (col_t >= 0 && (end_t == v[col_t] || *end_t)))
            return cm_fail(CM_EINVAL, msg, msg_size, "%s:%zu: '%s' is not a number", path, row,
                           end_x == v[col] || *end_x ? v[col] : v[col_t]);
        if (!table_put(tb, t, x, col_t >= 0))
            return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory at %s:%zu", path, row);
    }
    return CM_OK;
}

static cm_status from_file(const embed_args *a, embed_result *r, char *msg, size_t msg_size)
{
    FILE *f = strcmp(a->input, "-") == 0 ? stdin : fopen(a->input, "r");
    if (!f)
        return cm_fail(CM_EINVAL, msg, msg_size, "%s cannot be read: give a CSV file whose "
                       "header names its columns", a->input);
    char *line = malloc(LINE_MAX_CHARS);
    table tb = {0};
    int col_t = -1, col = -1;
    cm_status st = line ? CM_OK : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory");
    if (st == CM_OK && fgets(line, LINE_MAX_CHARS, f))
        col = header_columns(line, a->column, &col_t, r->name, sizeof r->name);
    if (st == CM_OK && col < 0)
        st = cm_fail(CM_EINVAL, msg, msg_size,
                     "%s: no column %s in its header: name one of the columns it has",
                     a->input, a->column ? a->column : "besides t");
    if (st == CM_OK) {
        snprintf(r->source, sizeof r->source, "%s, column %s", a->input, r->name);
        st = read_rows(f, a->input, col, col_t, &tb, line, msg, msg_size);
    }
    if (f != stdin)
        fclose(f);
    if (st == CM_OK)
        st = take(r, tb.t, tb.x, 1, tb.n, a->extrema, msg, msg_size);
    free(line);
    free(tb.t);
    free(tb.x);
    return st;
}

/* ---- the analysis ---- */

/* Each curve's fit: a->fit_lo..fit_hi, else from step 1 to where the
 * curve has risen half of its rise from step 1 (the straight part of a
 * chaotic series' curve lies below its saturation). */
static void fit(const embed_args *a, embed_curve *c, int steps)
{
    if (a->fit_hi) {
        c->fit_lo = a->fit_lo, c->fit_hi = a->fit_hi;
    } else {
        double top = c->S[1];
        for (int k = 1; k <= steps; k++)
            top = fmax(top, c->S[k]);
        int k = 3;
        while (k < steps && c->S[k] - c->S[1] < 0.5 * (top - c->S[1]))
            k++;
        c->fit_lo = 1, c->fit_hi = k;
    }
    c->slope = c->n_ref ? cm_index_slope(c->S, c->fit_lo, c->fit_hi) : NAN;
}

static cm_status false_neighbours(const embed_args *a, embed_result *r, char *msg,
                                  size_t msg_size)
{
    const cm_fnn_options fo = {a->lag, a->fnn_dim, a->ratio, (size_t)a->theiler};
    cm_status st = cm_false_neighbours(r->s, r->n, &fo, r->fnn, msg, msg_size);
    if (st != CM_OK)
        return st;
    r->fnn_dim = a->fnn_dim;
    for (int m = 1; m <= a->fnn_dim && !r->embeds; m++)
        if (r->fnn[m - 1] < EMBEDS_BELOW)
            r->embeds = m;
    return CM_OK;
}

static cm_status curves(const embed_args *a, embed_result *r, char *msg, size_t msg_size)
{
    int lo = a->dim_lo, hi = a->dim_hi;
    if (!lo) { /* the least dimension that embeds, else the one with fewest false */
        lo = r->embeds ? r->embeds : 1;
        for (int m = 2; !r->embeds && m <= a->fnn_dim; m++)
            if (r->fnn[m - 1] < r->fnn[lo - 1])
                lo = m;
        hi = lo + 2 > CM_EMBED_MAX_DIM ? CM_EMBED_MAX_DIM : lo + 2;
    }
    r->steps = a->steps;
    double sum = 0, sum2 = 0;
    int fitted = 0;
    for (int m = lo; m <= hi; m++) {
        for (int k = 0; k < a->n_radius; k++) {
            embed_curve *c = &r->curve[r->n_curves++];
            c->dim = m, c->radius = a->radius[k] * (r->hi - r->lo);
            if (!(c->S = malloc((size_t)(a->steps + 1) * sizeof *c->S)))
                return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the curves");
            const cm_kantz_options ko = {m, a->lag, c->radius, (size_t)a->theiler, a->steps};
            const cm_status st = cm_kantz_divergence(r->s, r->n, &ko, c->S, &c->n_ref, msg,
                                                     msg_size);
            if (st != CM_OK)
                return st;
            fit(a, c, a->steps);
            if (!isnan(c->slope))
                sum += c->slope, sum2 += c->slope * c->slope, fitted++;
        }
    }
    if (!fitted)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "no vector of the %zu has a neighbour within the radii: enlarge --radius "
                       "or give a longer series",
                       r->n);
    r->lambda = sum / fitted;
    r->spread = sqrt(fmax(0, sum2 / fitted - r->lambda * r->lambda));
    return CM_OK;
}

cm_status embedding_compute(const embed_args *a, embed_result *r, char *msg, size_t msg_size)
{
    memset(r, 0, sizeof *r);
    r->interval = NAN;
    cm_status st = check_args(a, msg, msg_size);
    if (st == CM_OK)
        st = a->input ? from_file(a, r, msg, msg_size) : simulated(a, r, msg, msg_size);
    if (st != CM_OK)
        return st;
    r->lo = INFINITY, r->hi = -INFINITY;
    for (size_t i = 0; i < r->n; i++)
        r->lo = fmin(r->lo, r->s[i]), r->hi = fmax(r->hi, r->s[i]);
    if (!(r->hi > r->lo))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the series (%zu %s) is constant or empty: it has no dynamics to embed%s",
                       r->n, a->extrema > 0 ? "maxima" : a->extrema < 0 ? "minima" : "values",
                       a->extrema ? " (follow the orbit longer, or analyse every sample)" : "");
    if (r->ts && r->n >= 2)
        r->interval = (r->ts[r->n - 1] - r->ts[0]) / (double)(r->n - 1);
    st = false_neighbours(a, r, msg, msg_size);
    if (st == CM_OK)
        st = curves(a, r, msg, msg_size);
    return st;
}

/* ---- writing ---- */

/* One row per curve and step: a table any tool reads without parsing
 * column names. */
static cm_status write_csv(const char *path, const embed_result *r, char *msg, size_t msg_size)
{
    outfile o;
    cm_status st = outfile_begin(path, &o, msg, msg_size);
    if (st != CM_OK)
        return st;
    fprintf(o.f, "dim,radius,k,S\n");
    for (int c = 0; c < r->n_curves; c++)
        for (int k = 0; k <= r->steps; k++)
            fprintf(o.f, "%d,%.17g,%d,%.17g\n", r->curve[c].dim, r->curve[c].radius, k,
                    r->curve[c].S[k]);
    return outfile_end(&o, true, msg, msg_size);
}

/* Colours of the dimensions' curves (radii share their dimension's). */
static const cm_rgb dim_colours[EMBED_MAX_DIMS] = {
    {20, 60, 160}, {200, 60, 30}, {30, 140, 60},  {140, 60, 160},
    {200, 140, 0}, {0, 150, 170}, {120, 120, 120}, {0, 0, 0},
};
static const char *const dim_colour_names[EMBED_MAX_DIMS] = {
    "blue", "red", "green", "purple", "orange", "cyan", "grey", "black",
};

/* "S(k): m = 10 blue, 11 red; 3 radii; slope 0.19 per value (k = 1..6)" */
static void curves_title(const embed_args *a, const embed_result *r, char *title, size_t size)
{
    const int lo = r->curve[0].dim, hi = r->curve[r->n_curves - 1].dim;
    size_t at = (size_t)snprintf(title, size, "S(k): m =");
    for (int m = lo; m <= hi && at < size; m++)
        at += (size_t)snprintf(title + at, size - at, "%s %d %s", m > lo ? "," : "", m,
                               dim_colour_names[m - lo]);
    if (at < size)
        snprintf(title + at, size - at, "; %d radii; mean slope %.3g per value", a->n_radius,
                 r->lambda);
    if (a->fit_hi && at < size) {
        at = strlen(title);
        snprintf(title + at, size - at, " over k = %d..%d", a->fit_lo, a->fit_hi);
    }
}

static cm_status write_figure(const embed_args *a, const embed_result *r, char *msg,
                              size_t msg_size)
{
    const size_t lag = (size_t)a->lag, pairs = r->n > lag ? r->n - lag : 0;
    double *ks = malloc((size_t)(r->steps + 1) * sizeof *ks);
    if (!ks)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the figure");
    double slo = INFINITY, shi = -INFINITY;
    cm_series lines[EMBED_MAX_CURVES];
    for (int k = 0; k <= r->steps; k++)
        ks[k] = k;
    for (int c = 0; c < r->n_curves; c++) {
        const embed_curve *cv = &r->curve[c];
        lines[c] = (cm_series){CM_SERIES_LINE, ks, cv->S, cv->n_ref ? (size_t)r->steps + 1 : 0,
                               dim_colours[cv->dim - r->curve[0].dim], 1.5f};
        for (int k = 0; cv->n_ref && k <= r->steps; k++)
            slo = fmin(slo, cv->S[k]), shi = fmax(shi, cv->S[k]);
    }
    const double margin = 0.04 * (r->hi - r->lo), smargin = 0.04 * (shi - slo) + 1e-9;
    static const cm_rgb ink = {20, 60, 160};
    const cm_series cloud = {CM_SERIES_POINTS, r->s, r->s + lag, pairs, ink, 3};
    char x_top[80], y_top[80], title_top[160], title_bottom[200];
    const char *which = a->extrema > 0 ? "maxima" : a->extrema < 0 ? "minima" : "values";
    snprintf(x_top, sizeof x_top, "%s_n", r->name);
    snprintf(y_top, sizeof y_top, "%s_n+%d", r->name, a->lag);
    snprintf(title_top, sizeof title_top, "delay projection of %zu successive %s of %s", r->n,
             which, r->name);
    curves_title(a, r, title_bottom, sizeof title_bottom);
    const int h_top = a->height / 2;
    const cm_chart charts[2] = {
        {a->width, h_top, {r->lo - margin, r->lo - margin}, {r->hi + margin, r->hi + margin},
         x_top, y_top, title_top, NULL, &cloud, 1, figure_font(), 0, NULL, 0},
        {a->width, a->height - h_top, {0, slo - smargin}, {r->steps, shi + smargin},
         "k (values later)", "S(k)", title_bottom, NULL, lines, r->n_curves, figure_font(), 0,
         NULL, 0},
    };
    const cm_png_text texts[] = {{"Source", r->source}};
    const cm_status st = outfile_charts(a->png, charts, 2, texts, 1, msg, msg_size);
    free(ks);
    return st;
}

cm_status embedding_write(const embed_args *a, const embed_result *r, char *msg, size_t msg_size)
{
    cm_status st = CM_OK;
    if (a->csv)
        st = write_csv(a->csv, r, msg, msg_size);
    if (st == CM_OK && a->png)
        st = write_figure(a, r, msg, msg_size);
    return st;
}

void embedding_report(FILE *f, const embed_args *a, const embed_result *r)
{
    fprintf(f, "series: %zu %s of %s, from %s\n", r->n,
            a->extrema > 0 ? "maxima" : a->extrema < 0 ? "minima" : "values", r->name, r->source);
    if (!isnan(r->interval))
        fprintf(f, "mean time between them: %.6g\n", r->interval);
    fprintf(f, "false nearest neighbours (lag %d, threshold %g):", a->lag, a->ratio);
    for (int m = 1; m <= r->fnn_dim; m++)
        fprintf(f, " m=%d %.3f", m, r->fnn[m - 1]);
    if (r->embeds)
        fprintf(f, "\nembedding dimension: %d (the least with < 1 %% false)\n", r->embeds);
    else
        fprintf(f, "\nno dimension up to %d has < 1 %% false: noise, or too short a series\n",
                r->fnn_dim);
    for (int c = 0; c < r->n_curves; c++) {
        const embed_curve *cv = &r->curve[c];
        fprintf(f, "  m = %2d, radius %-9.3g %7zu references, slope %.4g over k = %d..%d\n",
                cv->dim, cv->radius, cv->n_ref, cv->slope, cv->fit_lo, cv->fit_hi);
    }
    fprintf(f, "largest Lyapunov exponent: %.4g per value (spread %.2g)", r->lambda, r->spread);
    if (!isnan(r->interval)) {
        fprintf(f, ", %.4g per unit time", r->lambda / r->interval);
        if (a->time_unit > 0)
            fprintf(f, ", %.4g 1/s", r->lambda / r->interval / a->time_unit);
    }
    fprintf(f, "\n");
}

void embedding_json(FILE *f, const embed_args *a, const embed_result *r)
{
    json j;
    json_begin(&j, f, "exponents");
    json_str(&j, "of", "series");
    json_str(&j, "source", r->source);
    json_str(&j, "quantity", r->name);
    json_str(&j, "values", a->extrema > 0 ? "maxima" : a->extrema < 0 ? "minima" : "samples");
    json_uint(&j, "n", r->n);
    json_num(&j, "interval", r->interval);
    json_nums(&j, "false_neighbours", r->fnn, r->fnn_dim);
    json_int(&j, "embedding_dim", r->embeds);
    json_array(&j, "curves");
    for (int c = 0; c < r->n_curves; c++) {
        const embed_curve *cv = &r->curve[c];
        const double range[2] = {cv->fit_lo, cv->fit_hi};
        json_object(&j, NULL);
        json_int(&j, "dim", cv->dim);
        json_num(&j, "radius", cv->radius);
        json_uint(&j, "references", cv->n_ref);
        json_nums(&j, "fit", range, 2);
        json_num(&j, "slope", cv->slope);
        json_object_end(&j);
    }
    json_array_end(&j);
    json_num(&j, "lambda", r->lambda);
    json_num(&j, "spread", r->spread);
    json_num(&j, "lambda_per_time", r->lambda / r->interval);
    if (a->time_unit > 0)
        json_num(&j, "lambda_per_second", r->lambda / r->interval / a->time_unit);
    json_end(&j);
}

void embedding_result_free(embed_result *r)
{
    for (int c = 0; c < r->n_curves; c++)
        free(r->curve[c].S);
    free(r->s);
    free(r->ts);
    memset(r, 0, sizeof *r);
}
