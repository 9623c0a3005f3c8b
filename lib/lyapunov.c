/* lib/lyapunov.c - Lyapunov maps computed and written (lib/lyapunov.h). */
#include "lib/lyapunov.h"
#include "lib/rows.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/output.h"
#include "lib/figure.h"
#include "models/friction_oscillator.h"
#include "models/map_lyapunov.h"
#include "lib/parse.h"
#include "models/params.h"

/* The exponent at grid point (i, j); NaN where the model cannot be built
 * (S > S0) or no sample was accepted. */
static double lyapunov_point(const lyap_args *a, int i, int j, int *invalid)
{
    const int idx[2] = {i, j};
    cm_model m;
    if (!model_at_point(&a->mo, a->ax, idx, 2, &m)) {
        *invalid = 1;
        return NAN;
    }
    const cm_fo *o = cm_fo_of_model(&m);
    double lambda = NAN;
    if (o) {
        const double x0 = a->n_from ? a->from[0] : 1 + 0.9 * o->S0, v0 = a->n_from ? a->from[1] : 0;
        if (!cm_fo_lyapunov(o, x0, v0, a->d0, a->periods, &lambda))
            lambda = NAN;
    } else if (!cm_map_lyapunov(&m, a->from, a->d0, a->periods, &lambda)) {
        lambda = NAN;
    }
    cm_model_release(&m);
    return lambda;
}

static bool write_csv(const lyap_args *a, const double *v, char *msg, size_t msg_size)
{
    outfile o;
    if (outfile_begin(a->csv, &o, msg, msg_size) != CM_OK)
        return false;
    fprintf(o.f, "%s,%s,lambda\n", a->ax[0].name, a->ax[1].name);
    for (int j = 0; j < a->ax[1].n; j++)
        for (int i = 0; i < a->ax[0].n; i++)
            fprintf(o.f, "%.17g,%.17g,%.17g\n", param_axis_value(&a->ax[0], i),
                    param_axis_value(&a->ax[1], j), v[(size_t)j * (size_t)a->ax[0].n + (size_t)i]);
    return (outfile_end(&o, true, msg, msg_size) == CM_OK);
}

/* Room for two more points in ov. */
static bool overlay_room(overlay *ov, size_t *cap)
{
    if (ov->n + 2 <= *cap)
        return true;
    const size_t want = *cap ? 2 * *cap : 1024;
    double *nx = realloc(ov->x, want * sizeof *nx);
    if (nx)
        ov->x = nx;
    double *ny = nx ? realloc(ov->y, want * sizeof *ny) : NULL;
    if (ny)
        ov->y = ny, *cap = want;
    return ny != NULL;
}

/* A Hopf curve of `cellmap equilibria --curve` (kind,P,Q,...: rows hopf,
 * by Q and at each Q by P) as one line: the first Hopf point of each Q
 * upwards in Q, then the second downwards, so that the two ends of a
 * curve that turns back in Q meet; later ones (third, ...) apart. */
static cm_status read_hopf_table(const lyap_args *a, FILE *f, const char *head, const char *path,
                                 overlay *ov, size_t *cap, char *msg, size_t msg_size)
{
    char n1[64] = "", n2[64] = "", line[4096];
    if (sscanf(head, "kind,%63[^,],%63[^,\n]", n1, n2) != 2)
        return cm_fail(CM_EINVAL, msg, msg_size, "%s: no kind,P,Q header", path);
    const bool same = strcmp(n1, a->ax[0].name) == 0 && strcmp(n2, a->ax[1].name) == 0;
    const bool swapped = strcmp(n2, a->ax[0].name) == 0 && strcmp(n1, a->ax[1].name) == 0;
    if (!same && !swapped)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "%s is a table in (%s, %s), the grid in (%s, %s)", path, n1, n2,
                       a->ax[0].name, a->ax[1].name);
    double (*pts)[3] = NULL; /* p, q, the point's index at its q */
    size_t n = 0, cap_pts = 0;
    double last_q = NAN;
    int index = 0;
    bool ok = true;
    while (ok && fgets(line, sizeof line, f)) {
        double p, q;
        if (strncmp(line, "hopf,", 5) != 0 || sscanf(line + 5, "%lf,%lf", &p, &q) != 2)
            continue;
        index = q == last_q ? index + 1 : 0;
        last_q = q;
        if (!(ok = rows_room((void **)&pts, &cap_pts, n, sizeof *pts)))
            break;
        pts[n][0] = same ? p : q, pts[n][1] = same ? q : p, pts[n][2] = index;
        n++;
    }
    const int ways[2] = {0, 1};
    for (int w = 0; w < 2 && ok; w++)
        for (size_t i = 0; i < n && ok; i++) {
            const size_t k = ways[w] == 0 ? i : n - 1 - i; /* the second one backwards */
            if ((int)pts[k][2] != w || !(ok = overlay_room(ov, cap)))
                continue;
            if (ov->n_labels < 64 && w == 0 && i == 0) {
                if (ov->n > 0) {
                    ov->x[ov->n] = ov->y[ov->n] = NAN;
                    ov->n++;
                }
                snprintf(ov->texts[ov->n_labels], sizeof ov->texts[0], "Hopf");
                ov->labels[ov->n_labels] = (cm_chart_label){pts[k][0], pts[k][1],
                                                            ov->texts[ov->n_labels]};
                ov->n_labels++;
            }
            ov->x[ov->n] = pts[k][0], ov->y[ov->n] = pts[k][1];
            ov->n++;
        }
    free(pts);
    return ok ? CM_OK : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the curves");
}

/* Appends the curves of one file to ov: CM_EINVAL when it is not one of
 * curves in the grid's parameters, CM_ENOMEM. */
static cm_status read_curve_file(const lyap_args *a, const char *path, overlay *ov, size_t *cap,
                                 char *msg, size_t msg_size)
{
    FILE *f = NULL;
    char line[512], n1[64] = "", n2[64] = "", why[CM_OUTPUT_PATH_MAX + 256];
    if (cm_input_open(path, "the curves file", UINT64_C(64) << 20, &f, why, sizeof why) != CM_OK)
        return cm_fail(CM_EINVAL, msg, msg_size, "%s (make it with cellmap continue --curves)",
                       why);
    if (fgets(line, sizeof line, f) && strncmp(line, "kind,", 5) == 0) {
        const cm_status st = read_hopf_table(a, f, line, path, ov, cap, msg, msg_size);
        fclose(f);
        return st;
    }
    if (sscanf(line, "curve,label,%63[^,],%63[^,],x,v", n1, n2) != 2) {
        fclose(f);
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "curves file %s: not a file of curve,label,P,P2,x,v lines (make it with "
                       "cellmap continue --curves) nor a Hopf table of cellmap equilibria --curve",
                       path);
    }
    const bool same = strcmp(n1, a->ax[0].name) == 0 && strcmp(n2, a->ax[1].name) == 0;
    const bool swapped = strcmp(n2, a->ax[0].name) == 0 && strcmp(n1, a->ax[1].name) == 0;
    if (!same && !swapped) {
        fclose(f);
        return cm_fail(CM_EINVAL, msg, msg_size, "curves file %s is in (%s, %s), the grid in (%s, %s)",
                       path, n1, n2, a->ax[0].name, a->ax[1].name);
    }
    int last = -1;
    bool ok = true;
    while (ok && fgets(line, sizeof line, f)) {
        int id;
        char label[32];
        double p1, p2;
        if (sscanf(line, "%d,%31[^,],%lf,%lf", &id, label, &p1, &p2) != 4)
            continue;
        if (!(ok = overlay_room(ov, cap)))
            break;
        if (id != last && ov->n > 0) { /* a break between curves */
            ov->x[ov->n] = ov->y[ov->n] = NAN;
            ov->n++;
        }
        ov->x[ov->n] = same ? p1 : p2;
        ov->y[ov->n] = same ? p2 : p1;
        if (id != last && ov->n_labels < 64) { /* each curve's start */
            snprintf(ov->texts[ov->n_labels], sizeof ov->texts[0], "%s", label);
            ov->labels[ov->n_labels] = (cm_chart_label){ov->x[ov->n], ov->y[ov->n],
                                                        ov->texts[ov->n_labels]};
            ov->n_labels++;
        }
        ov->n++;
        last = id;
    }
    fclose(f);
    return ok ? CM_OK : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the curves");
}

cm_status lyapunov_read_curves(const lyap_args *a, overlay *ov, char *msg, size_t msg_size)
{
    size_t cap = 0;
    cm_status st = CM_OK;
    for (int k = 0; k < a->n_curves && st == CM_OK; k++)
        st = read_curve_file(a, a->curves[k], ov, &cap, msg, msg_size);
    return st;
}

void lyapunov_overlay_free(overlay *ov)
{
    free(ov->x);
    free(ov->y);
}

static bool write_png(const lyap_args *a, const char *model, const cm_params *p, const double *v,
                      overlay *ov, char *msg, size_t msg_size)
{
    /* both ways of a curve, and curves of one point, start at one place */
    cm_chart_join_labels(ov->labels, ov->n_labels, ov->texts[0], sizeof ov->texts[0],
                         0.05 * (a->ax[0].hi - a->ax[0].lo), 0.03 * (a->ax[1].hi - a->ax[1].lo));
    const cm_series curves = {CM_SERIES_LINE, ov->x, ov->y, ov->n, (cm_rgb){0, 0, 0}, 2};
    char title[512], params[400], grid[200];
    const char *const swept[] = {a->ax[0].name, a->ax[1].name, NULL}; /* in Grid instead */
    cm_params_format_with(p, swept, params, sizeof params);
    param_axes_format(a->ax, 2, grid, sizeof grid);
    snprintf(title, sizeof title, "largest Lyapunov exponent, %s, %d %s", model, a->periods,
             strcmp(model, "friction-oscillator") == 0 ? "periods" : "iterates");
    const cm_heat heat = {a->ax[0].n, a->ax[1].n, v, 0, "lambda > 0"};
    const cm_chart chart = {a->width,
                            a->height,
                            {a->ax[0].lo, a->ax[1].lo},
                            {a->ax[0].hi, a->ax[1].hi},
                            a->ax[0].name,
                            a->ax[1].name,
                            title,
                            &heat,
                            &curves,
                            ov->n > 0,
                            figure_font(),
                            0,
                            ov->labels,
                            ov->n_labels};
    char periods[32];
    snprintf(periods, sizeof periods, "%d", a->periods);
    const bool fo = strcmp(model, "friction-oscillator") == 0;
    const cm_png_text texts[] = {{"Model", model},
                                 {"Parameters", params},
                                 {"Grid", grid},
                                 {"Periods", periods},
                                 {"Estimator", fo ? "docs/models.md 9.8 (renormalised two trajectories)"
                                                  : "docs/models.md 11.3 (finite differences on the map)"}};
    return (outfile_charts(a->png, &chart, 1, texts, 5, msg, msg_size) == CM_OK);
}

lyap_args lyapunov_defaults(void)
{
    return (lyap_args){.mo = {.name = "friction-oscillator"},
                       .periods = 600,
                       .d0 = 1e-8,
                       .width = 900,
                       .height = 700,
                       .every = 3,
                       .runs = 200,
                       .seed = 1,
                       .escape = 0.01};
}

/* The request's own limits (the command checks them as it parses). */
static cm_status check_request(const lyap_args *a, char *msg, size_t msg_size)
{
    if (!a->has_grid || a->ax[0].n < 1 || a->ax[1].n < 1)
        return cm_fail(CM_EINVAL, msg, msg_size, "a grid X=LO:HI:N,Y=LO:HI:M is required");
    for (int k = 0; k < 2; k++)
        if (!param_axis_even(&a->ax[k]))
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "the values of %s are not evenly spaced, and the heat map's cells "
                           "would not sit on them; give %s=LO:HI:N",
                           a->ax[k].name, a->ax[k].name);
    if (a->periods < 1 || a->periods > 1000000 || !(a->d0 >= 1e-9 && a->d0 <= 1e-3))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "periods %d, d0 %g: need 1..10^6 periods and d0 in 1e-9..1e-3",
                       a->periods, a->d0);
    if (a->n_curves < 0 || a->n_curves > MAX_CURVE_FILES || (a->n_curves && !a->png))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "up to %d curve files, drawn over the heat map (give its PNG too)",
                       MAX_CURVE_FILES);
    return CM_OK;
}

/* The start of a model other than the friction oscillator: a->from, with
 * its dimension checked, or the centre of the model's example region. */
static cm_status start_of(lyap_args *a, char *msg, size_t msg_size)
{
    const cm_model_entry *e = cm_model_set_find(&a->mo.set, a->mo.name, NULL);
    cm_model m;
    const cm_status st =
        model_spec_build(&a->mo, &m, msg, msg_size);
    if (st != CM_OK)
        return st;
    const int dim = m.dim;
    cm_model_release(&m);
    if (a->n_from && a->n_from != dim)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the start has %d value(s) but model %s has dimension %d", a->n_from,
                       e->name, dim);
    if (a->n_from)
        return CM_OK;
    a->n_from = dim;
    return model_spec_centre(&a->mo, dim, a->from, msg, msg_size);
}

/* The exponents of every grid point into r->v. */
static void compute_map(const lyap_args *a, const work_hooks *h, lyap_result *r, int *stopped)
{
    const size_t nx = (size_t)a->ax[0].n, n = r->points;
    double *v = r->v;
    int invalid = 0, stop = 0;
    uint64_t done = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(a->threads ? a->threads : omp_get_max_threads()) reduction(| : invalid, stop)
    for (size_t k = 0; k < n; k++) {
        if (stop || (stop = work_stop(h) != NULL)) { /* the points left are skipped */
            v[k] = NAN;
            continue;
        }
        v[k] = lyapunov_point(a, (int)(k % nx), (int)(k / nx), &invalid);
        work_tick(h, &done);
    }
    r->invalid = invalid, r->done = done, *stopped = stop;
}

cm_status lyapunov_compute(lyap_args *a, const work_hooks *h, lyap_result *r, char *msg,
                           size_t msg_size)
{
    *r = (lyap_result){0};
    cm_status st = check_request(a, msg, msg_size);
    if (st == CM_OK) /* the parameters without the grid's; S0 >= S is checked per point */
        st = param_sweep_base(&a->mo, NULL, a->ax, 2, &r->base, msg, msg_size);
    if (st == CM_OK && strcmp(a->mo.name, "friction-oscillator") != 0)
        st = start_of(a, msg, msg_size);
    if (st == CM_OK)
        st = lyapunov_read_curves(a, &r->ov, msg, msg_size);
    if (st != CM_OK)
        return st;
    r->points = (size_t)a->ax[0].n * (size_t)a->ax[1].n;
    r->v = malloc(r->points * sizeof *r->v);
    if (!r->v)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %zu grid points", r->points);
    const double t0 = cm_seconds();
    int stopped = 0;
    compute_map(a, h, r, &stopped);
    if (stopped)
        return work_canceled(h, msg, msg_size);
    r->seconds = cm_seconds() - t0;
    for (size_t k = 0; k < r->points; k++) {
        r->computed += !isnan(r->v[k]);
        r->positive += r->v[k] > 0;
        if (!(r->v[r->best] >= r->v[k]))
            r->best = k;
    }
    return CM_OK;
}

cm_status lyapunov_write(const lyap_args *a, lyap_result *r, char *msg, size_t msg_size)
{
    if (r->computed == 0)
        return cm_fail(CM_ERANGE, msg, msg_size, "no grid point could be computed (%s)",
                       strcmp(a->mo.name, "friction-oscillator") == 0
                           ? "is S <= S0 anywhere?"
                           : "every orbit from the start left the world or had no image");
    const bool ok = (!a->csv || write_csv(a, r->v, msg, msg_size)) &&
                    (!a->png || write_png(a, a->mo.name, &r->base, r->v, &r->ov, msg,
                                          msg_size));
    return ok ? CM_OK : CM_EIO;
}

void lyapunov_result_free(lyap_result *r)
{
    free(r->v);
    r->v = NULL;
    lyapunov_overlay_free(&r->ov);
}

cm_status lyapunov_fo_base(const lyap_args *a, const char *method, cm_params *base, char *msg,
                           size_t msg_size)
{
    if (strcmp(a->mo.name, "friction-oscillator") != 0)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "--method %s follows the dry friction oscillator: use --model "
                       "friction-oscillator (the default)",
                       method);
    const cm_status st = param_sweep_base(&a->mo, NULL, &a->q, 0, base, msg, msg_size);
    if (st != CM_OK)
        return st;
    const double S = cm_params_get(base, "S"), S0 = cm_params_get(base, "S0");
    return S <= S0 ? CM_OK
                   : cm_fail(CM_EINVAL, msg, msg_size,
                             "S = %g is above S0 = %g: static friction must be at least the "
                             "kinetic one",
                             S, S0);
}
