/* lib/map_bifurcation.c - Monte Carlo bifurcation diagrams of map models
 * (lib/map_bifurcation.h). */
#include "lib/map_bifurcation.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/clock.h"
#include "lib/figure.h"
#include "lib/json.h"
#include "lib/rows.h"
#include "models/ode_flow.h"

bool map_bifurcation_model(const model_spec *mo)
{
    const cm_model_entry *e = cm_model_set_find(&mo->set, mo->name, NULL);
    return e && strcmp(e->name, "friction-oscillator") != 0;
}

/* ---- the runs ---- */

typedef struct branches branches;
static cm_status check_branches(const bif_args *a, const char *coord, char *msg,
                                size_t msg_size);

/* Iterates m from a random start in lo..hi (run `run` of value `value`):
 * a->transient iterates, then a->record kept (coordinate of) in out;
 * false when the orbit is lost. */
static bool one_run(const bif_args *a, const cm_model *m, int value, int run, const double *lo,
                    const double *hi, int of, double *out)
{
    double u[CM_MAX_DIM], x[CM_MAX_DIM], y[CM_MAX_DIM], flight;
    bifurcation_random(a->seed, value, run, m->dim, u);
    for (int d = 0; d < m->dim; d++)
        x[d] = lo[d] + 0.5 * (u[d] + 1) * (hi[d] - lo[d]);
    for (int k = 0; k < a->transient + a->record; k++) {
        if (model_image(m, x, y, &flight) != CM_STEP_OK)
            return false;
        memcpy(x, y, sizeof x);
        if (k >= a->transient)
            out[k - a->transient] = x[of];
    }
    return true;
}

static cm_status check_request(const bif_args *a, const cm_model *m, map_bif_result *r,
                               char *msg, size_t msg_size)
{
    if (!a->has_sweep)
        return cm_fail(CM_EINVAL, msg, msg_size, "a sweep NAME=LO:HI:N is required");
    if (a->runs < 1 || a->runs > 1000 || a->transient < 0 || a->transient > 1000000 ||
        a->record < 1 || a->record > 10000 || (double)a->sweep.n * a->runs * a->record > 1e7)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "runs %d, transient %d, record %d: need 1..1000 runs, 0..10^6 "
                       "iterates of transient, 1..10000 recorded and at most 1e7 points",
                       a->runs, a->transient, a->record);
    r->dim = m->dim;
    for (int d = 0; d < m->dim; d++)
        if (!a->of || strcmp(a->of, cm_model_coord_name(m, d)) == 0) {
            r->of = d;
            snprintf(r->of_name, sizeof r->of_name, "%s", cm_model_coord_name(m, d));
            return CM_OK;
        }
    char names[256] = "";
    for (int d = 0; d < m->dim; d++)
        snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", d ? ", " : "",
                 cm_model_coord_name(m, d));
    return cm_fail(CM_EINVAL, msg, msg_size, "--of %s: model %s's map has the coordinates %s",
                   a->of, m->name, names);
}

cm_status map_bifurcation_compute(const bif_args *a, const work_hooks *h, map_bif_result *r,
                                  char *msg, size_t msg_size)
{
    memset(r, 0, sizeof *r);
    cm_status st = param_sweep_base(&a->mo, NULL, &a->sweep, 1, &r->base, msg, msg_size);
    const int n_values = a->sweep.n;
    cm_model *models = st == CM_OK ? calloc((size_t)n_values, sizeof *models) : NULL;
    if (st == CM_OK && !models)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %d models", n_values);
    for (int i = 0; i < n_values && st == CM_OK; i++)
        r->n_valid += model_at_point(&a->mo, &a->sweep, &i, 1, &models[i]);
    const cm_model *any = NULL;
    for (int i = 0; i < n_values && st == CM_OK && !any; i++)
        any = models[i].name ? &models[i] : NULL;
    if (st == CM_OK && !any)
        st = cm_fail(CM_EINVAL, msg, msg_size, "no value of %s gives a model", a->sweep.name);
    double lo[CM_MAX_DIM], hi[CM_MAX_DIM];
    if (st == CM_OK)
        st = check_request(a, any, r, msg, msg_size);
    if (st == CM_OK)
        st = model_spec_region(&a->mo, any->dim, lo, hi, msg, msg_size);
    if (st == CM_OK) /* the tables drawn later are checked before the work */
        st = check_branches(a, r->of_name, msg, msg_size);
    const size_t n_runs = (size_t)n_values * (size_t)a->runs, rec = (size_t)a->record;
    if (st == CM_OK) {
        r->points = malloc(n_runs * rec * sizeof *r->points);
        r->lost = calloc(n_runs, sizeof *r->lost);
        if (!r->points || !r->lost)
            st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %zu runs", n_runs);
    }
    int stopped = 0;
    const double t0 = cm_seconds();
    uint64_t done = 0, lost = 0;
    if (st == CM_OK) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(a->threads ? a->threads : omp_get_max_threads()) reduction(| : stopped) reduction(+ : lost)
        for (size_t k = 0; k < n_runs; k++) {
            const int i = (int)(k / (size_t)a->runs), run = (int)(k % (size_t)a->runs);
            double *out = r->points + k * rec;
            for (size_t j = 0; j < rec; j++)
                out[j] = NAN;
            if (!models[i].name || stopped || (stopped = work_stop(h) != NULL))
                continue;
            if (!one_run(a, &models[i], i, run, lo, hi, r->of, out)) {
                r->lost[k] = true;
                lost++;
                for (size_t j = 0; j < rec; j++)
                    out[j] = NAN;
            }
            work_tick(h, &done);
        }
    }
    r->done = done;
    r->n_lost = lost;
    r->followed = done - lost;
    r->seconds = cm_seconds() - t0;
    for (int i = 0; models && i < n_values; i++)
        cm_model_release(&models[i]);
    free(models);
    if (st == CM_OK && stopped)
        st = work_canceled(h, msg, msg_size);
    return st;
}

/* ---- the branches drawn over the points ---- */

/* The branches of the tables: stable and unstable polylines (NAN breaks). */
struct branches {
    double *x[2], *y[2]; /* [0] stable, [1] unstable */
    size_t n[2], cap[2];
};

static bool put(branches *b, int k, double x, double y)
{
    const size_t had = b->cap[k];
    if (!rows_room((void **)&b->x[k], &b->cap[k], b->n[k], sizeof *b->x[k]))
        return false;
    if (b->cap[k] != had || !b->y[k]) { /* y grows with x */
        double *ys = realloc(b->y[k], b->cap[k] * sizeof *ys);
        if (!ys)
            return false;
        b->y[k] = ys;
    }
    b->x[k][b->n[k]] = x, b->y[k][b->n[k]] = y;
    b->n[k]++;
    return true;
}

/* Splits a CSV line in place into at most max fields. */
static int fields(char *line, char **f, int max)
{
    int n = 0;
    for (char *s = line; n < max; s++) {
        f[n++] = s;
        s = strchr(s, ',');
        if (!s)
            break;
        *s = 0;
    }
    return n;
}

enum { MAX_FIELDS = 64 };

/* The column indices of a table's header: kind, the parameter, the
 * coordinate, the stability (unstable or outside) and the period (-1: none). */
static bool header(char *line, const char *param, const char *coord, int *col)
{
    char *f[MAX_FIELDS];
    const int n = fields(line, f, MAX_FIELDS);
    for (int k = 0; k < 5; k++)
        col[k] = -1;
    for (int i = 0; i < n; i++) {
        f[i][strcspn(f[i], "\r\n")] = 0;
        const char *name = f[i];
        const int k = strcmp(name, "kind") == 0                                        ? 0
                      : strcmp(name, param) == 0                                       ? 1
                      : strcmp(name, coord) == 0                                       ? 2
                      : strcmp(name, "unstable") == 0 || strcmp(name, "outside") == 0 ? 3
                      : strcmp(name, "period") == 0                                    ? 4
                                                                                       : -1;
        if (k >= 0 && col[k] < 0)
            col[k] = i;
    }
    return col[0] >= 0 && col[1] >= 0 && col[2] >= 0 && col[3] >= 0;
}

static cm_status read_table(const char *path, const char *param, const char *coord, branches *b,
                            char *msg, size_t msg_size)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return cm_fail(CM_EINVAL, msg, msg_size, "%s: cannot be read (a table of `cellmap "
                       "equilibria` or `cellmap periodic` --csv)", path);
    char line[8192];
    int col[5];
    if (!fgets(line, sizeof line, f) || !header(line, param, coord, col)) {
        fclose(f);
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "%s: no columns kind, %s, %s and unstable or outside: give a table of "
                       "`cellmap equilibria` or `cellmap periodic` --csv over %s",
                       path, param, coord, param);
    }
    int last = -1;
    double last_period = NAN, px = NAN, py = NAN;
    cm_status st = CM_OK;
    while (st == CM_OK && fgets(line, sizeof line, f)) {
        char *v[MAX_FIELDS];
        const int n = fields(line, v, MAX_FIELDS);
        if (n <= col[1] || n <= col[2] || n <= col[3] || strcmp(v[col[0]], "point") != 0)
            continue;
        char *end[4];
        const double p = strtod(v[col[1]], &end[0]), x = strtod(v[col[2]], &end[1]),
                     out = strtod(v[col[3]], &end[2]);
        const double period = col[4] >= 0 && n > col[4] ? strtod(v[col[4]], &end[3]) : 0;
        if (end[0] == v[col[1]] || end[1] == v[col[2]] || end[2] == v[col[3]]) {
            st = cm_fail(CM_EINVAL, msg, msg_size, "%s: a point row that is not numbers", path);
            break;
        }
        const int k = out > 0 ? 1 : 0;
        const bool new_branch = period != last_period;
        if (new_branch || k != last) {
            /* break both lines; a change of stability joins at the last point */
            bool ok = true;
            for (int j = 0; j < 2; j++)
                ok = ok && (b->n[j] == 0 || put(b, j, NAN, NAN));
            if (ok && !new_branch && last >= 0)
                ok = put(b, k, px, py);
            if (!ok)
                st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the branches");
        }
        if (st == CM_OK && !put(b, k, p, x))
            st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the branches");
        last = k, last_period = period, px = p, py = x;
    }
    fclose(f);
    return st;
}

static void branches_free(branches *b)
{
    for (int j = 0; j < 2; j++)
        free(b->x[j]), free(b->y[j]);
}

static cm_status check_branches(const bif_args *a, const char *coord, char *msg,
                                size_t msg_size)
{
    cm_status st = CM_OK;
    for (int k = 0; k < a->n_branches && st == CM_OK; k++) {
        branches b = {0};
        st = read_table(a->branches[k], a->sweep.name, coord, &b, msg, msg_size);
        branches_free(&b);
    }
    return st;
}

/* ---- writing ---- */

static cm_status write_csv(const bif_args *a, const map_bif_result *r, char *msg,
                           size_t msg_size)
{
    outfile o;
    cm_status st = outfile_begin(a->out.csv, &o, msg, msg_size);
    if (st != CM_OK)
        return st;
    fprintf(o.f, "%s,run,%s\n", a->sweep.name, r->of_name);
    const size_t rec = (size_t)a->record;
    for (int i = 0; i < a->sweep.n; i++)
        for (int run = 0; run < a->runs; run++) {
            const double *pts = r->points + ((size_t)i * (size_t)a->runs + (size_t)run) * rec;
            for (size_t j = 0; j < rec; j++)
                if (!isnan(pts[j]))
                    fprintf(o.f, "%.17g,%d,%.17g\n", param_axis_value(&a->sweep, i), run, pts[j]);
        }
    return outfile_end(&o, true, msg, msg_size);
}

static cm_status write_png(const bif_args *a, const map_bif_result *r, char *msg, size_t msg_size)
{
    const size_t rec = (size_t)a->record, n_all = (size_t)a->sweep.n * (size_t)a->runs * rec;
    double *px = malloc(2 * n_all * sizeof *px);
    branches b = {0};
    cm_status st = px ? CM_OK : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the figure");
    for (int k = 0; k < a->n_branches && st == CM_OK; k++)
        st = read_table(a->branches[k], a->sweep.name, r->of_name, &b, msg, msg_size);
    if (st != CM_OK) {
        free(px);
        branches_free(&b);
        return st;
    }
    double *py = px + n_all, lo = INFINITY, hi = -INFINITY;
    size_t n = 0;
    for (size_t k = 0; k < n_all; k++) {
        if (isnan(r->points[k]))
            continue;
        px[n] = param_axis_value(&a->sweep, (int)(k / rec / (size_t)a->runs));
        py[n] = r->points[k];
        lo = fmin(lo, py[n]), hi = fmax(hi, py[n]);
        n++;
    }
    for (int j = 0; j < 2; j++)
        for (size_t k = 0; k < b.n[j]; k++)
            if (isfinite(b.y[j][k]) && b.x[j][k] >= a->sweep.lo && b.x[j][k] <= a->sweep.hi)
                lo = fmin(lo, b.y[j][k]), hi = fmax(hi, b.y[j][k]);
    if (!(lo <= hi))
        lo = 0, hi = 1;
    const double pad = hi > lo ? 0.04 * (hi - lo) : 0.5;
    static const cm_rgb dots = {20, 60, 160}, stable = {0, 0, 0}, unstable = {210, 30, 30};
    const cm_series series[3] = {{CM_SERIES_POINTS, px, py, n, dots, 2},
                                 {CM_SERIES_LINE, b.x[0], b.y[0], b.n[0], stable, 2},
                                 {CM_SERIES_LINE, b.x[1], b.y[1], b.n[1], unstable, 1.5f}};
    char title[256], params[1024], runs[160];
    snprintf(title, sizeof title, "%s against %s, %s%s", r->of_name, a->sweep.name,
             a->mo.name, a->n_branches ? "; branches: stable black, unstable red" : "");
    cm_params_format(&r->base, params, sizeof params);
    snprintf(runs, sizeof runs, "%d runs a value, seed %lld; %d transient and %d recorded iterates",
             a->runs, a->seed, a->transient, a->record);
    const cm_chart chart = {a->out.width, a->out.height, {a->sweep.lo, lo - pad},
                            {a->sweep.hi, hi + pad}, a->sweep.name, r->of_name, title, NULL,
                            series, 3, figure_font(), 0, NULL, 0};
    const cm_png_text texts[] = {{"Model", a->mo.name}, {"Parameters", params}, {"Runs", runs}};
    st = outfile_charts(a->out.png, &chart, 1, texts, 3, msg, msg_size);
    free(px);
    branches_free(&b);
    return st;
}

cm_status map_bifurcation_write(const bif_args *a, const map_bif_result *r, char *msg,
                                size_t msg_size)
{
    cm_status st = CM_OK;
    if (a->out.csv)
        st = write_csv(a, r, msg, msg_size);
    if (st == CM_OK && a->out.png)
        st = write_png(a, r, msg, msg_size);
    return st;
}

void map_bifurcation_report(FILE *f, const bif_args *a, const map_bif_result *r)
{
    const uint64_t not_computed = (uint64_t)(a->sweep.n - r->n_valid) * (uint64_t)a->runs;
    if (a->out.json) {
        json j;
        json_begin(&j, f, "bifurcation");
        param_base_json(&j, a->mo.name, &r->base);
        param_axes_json(&j, "sweep", &a->sweep, 1);
        json_int(&j, "runs", a->runs);
        json_int(&j, "transient", a->transient);
        json_int(&j, "record", a->record);
        json_int(&j, "seed", a->seed);
        json_uint(&j, "followed", r->followed);
        json_uint(&j, "lost", r->n_lost);
        json_uint(&j, "not_computed", not_computed);
        json_seconds(&j, "seconds", r->seconds);
        json_end(&j);
        return;
    }
    fprintf(f,
            "%d values of %s x %d runs in %.2f s: %llu runs followed, %llu lost%s\n", a->sweep.n,
            a->sweep.name, a->runs, r->seconds, (unsigned long long)r->followed,
            (unsigned long long)r->n_lost,
            not_computed ? "; values where the model cannot be built are not computed" : "");
}

void map_bifurcation_free(map_bif_result *r)
{
    free(r->points);
    free(r->lost);
    memset(r, 0, sizeof *r);
}
