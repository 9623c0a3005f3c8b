/* lib/escape.c - transient escape computed and written (lib/escape.h). */
#include "lib/escape.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/scm.h"
#include "lib/figure.h"
#include "models/params.h"

/* The mean step number of the cells of I_rep that cell mapping sends to
 * the sink (out of I_rep: escaped), and how many cells never leave. */
static void cell_mapping(const cm_model *m, const cm_te *t, long cells, esc_point *p)
{
    p->scm_mean = NAN;
    p->scm_stay = 0;
    if (cells == 0)
        return;
    const cm_lattice lat = {1, {t->x0}, {t->rep_len / (double)cells}};
    const cm_box box = {1, {0}, {cells}};
    const cm_scm_options opt = {.max_steps = 1, .threads = 1};
    cm_region r;
    char msg[256];
    memset(&r, 0, sizeof r);
    if (cm_region_alloc(&r, &box, msg, sizeof msg) == CM_OK &&
        cm_scm_solve(m, &lat, &opt, &r, msg, sizeof msg) == CM_OK) {
        double sum = 0;
        long left = 0;
        for (uint64_t i = 0; i < r.ncells; i++) {
            if (r.group[i] == 0) {
                sum += r.step[i];
                left++;
            }
        }
        p->scm_stay = (long)r.ncells - left;
        p->scm_mean = left ? sum / (double)left : NAN;
    }
    cm_region_free(&r);
}

/* The model's parameters at sweep index i (or without a sweep): a, b, c. */
static bool point_model(const esc_args *a, int i, cm_model *m, char *why, size_t why_size)
{
    const char *names[2];
    double values[2];
    int n = 0;
    double I0 = a->I0;
    bool has_I0 = a->has_I0;
    if (a->has_sweep && strcmp(a->sweep.name, "I0") == 0) {
        I0 = param_axis_value(&a->sweep, i);
        has_I0 = true;
    } else if (a->has_sweep) {
        names[n] = a->sweep.name;
        values[n++] = param_axis_value(&a->sweep, i);
    }
    if (!model_with_values(&a->mo, names, values, n, m, why, why_size))
        return false;
    if (!has_I0)
        return true;
    /* c from |I0| at this point's a and b */
    const double c =
        cm_te_c_of_I0(cm_params_get(&m->values, "a"), cm_params_get(&m->values, "b"), I0);
    names[n] = "c";
    values[n++] = c;
    cm_model_release(m);
    return model_with_values(&a->mo, names, values, n, m, why, why_size);
}

static void compute_point(const esc_args *a, int i, esc_point *p)
{
    cm_model m;
    memset(p, 0, sizeof *p);
    p->exact = p->scm_mean = p->ens.mean = p->ens.kappa = NAN;
    if (!point_model(a, i, &m, p->why, sizeof p->why))
        return;
    const double av = cm_params_get(&m.values, "a"), bv = cm_params_get(&m.values, "b"),
                 cv = cm_params_get(&m.values, "c");
    p->valid = cm_te_setup(av, bv, cv, &p->t, p->why, sizeof p->why);
    if (p->valid) {
        if (!cm_te_exact_mean(&p->t, MAX_PARTITION, &p->exact, &p->partition))
            p->exact = NAN;
        if (a->ensemble > 0)
            cm_te_ensemble_run(&p->t, a->ensemble, SEED, &p->ens);
        cell_mapping(&m, &p->t, a->cells, p);
    }
    cm_model_release(&m);
}

static int escape_points(const esc_args *a)
{
    return a->has_sweep ? a->sweep.n : 1;
}

static bool write_csv(const esc_args *a, const esc_point *pts, char *msg, size_t msg_size)
{
    outfile o;
    if (outfile_begin(a->out.csv, &o, msg, msg_size) != CM_OK)
        return false;
    fprintf(o.f, "a,b,c,I0,valid,x0,rep_len,F,a_crit,border,D0_C1,D0_C2,kappa_C1,kappa_C2,"
                 "n_esc_C1,n_esc_C2,exact_mean,partition,ensemble_kappa,ensemble_mean,"
                 "scm_mean,scm_stay\n");
    for (int i = 0; i < escape_points(a); i++) {
        const esc_point *p = &pts[i];
        const cm_te *t = &p->t;
        fprintf(o.f, "%.17g,%.17g,%.17g,%.17g,%d", t->a, t->b, t->c, t->I0, p->valid);
        if (!p->valid) {
            fprintf(o.f, ",nan,nan,nan,nan,0,nan,nan,nan,nan,nan,nan,nan,0,nan,nan,nan,0\n");
            continue;
        }
        fprintf(o.f, ",%.17g,%.17g,%.17g,%.17g,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%ld,"
                     "%.17g,%.17g,%.17g,%ld\n",
                t->x0, t->rep_len, t->F, t->a_crit, t->border, t->D0[0], t->D0[1], t->kappa[0],
                t->kappa[1], t->n_esc[0], t->n_esc[1], p->exact, p->partition, p->ens.kappa,
                p->ens.mean, p->scm_mean, p->scm_stay);
    }
    return (outfile_end(&o, true, msg, msg_size) == CM_OK);
}

/* Fig. 4.5: the escape number of points across [0, 1.05 (a - c)], with
 * the ends of I0 and I_rep. */
static bool png_structure(const esc_args *a, const esc_point *p, const char *params, char *msg,
                          size_t msg_size)
{
    const cm_te *t = &p->t;
    const int n = 4 * a->out.width;
    const double hi = 1.05 * t->rep_hi;
    double *x = malloc((size_t)n * 2 * sizeof *x);
    if (!x) {
        snprintf(msg, msg_size, "out of memory for the diagram");
        return false;
    }
    double *y = x + n, top = 1;
    for (int i = 0; i < n; i++) {
        x[i] = hi * (i + 0.5) / n;
        const long k = cm_te_escape_number(t, x[i], 1000);
        y[i] = k < 0 ? NAN : (double)k;
        top = fmax(top, k);
    }
    top = fmin(top, 40);
    const double marks_x[8] = {t->a - t->b - t->c, t->a - t->b - t->c, t->x0, t->x0,
                               t->rep_hi, t->rep_hi, 1, 1};
    const double marks_y[8] = {0, top, 0, top, 0, top, 0, top};
    const cm_rgb black = {0, 0, 0}, red = {215, 48, 39}, blue = {69, 117, 180};
    const cm_series series[] = {
        {CM_SERIES_SEGMENTS, marks_x, marks_y, 2, blue, 1},     /* I0's left end */
        {CM_SERIES_SEGMENTS, marks_x + 2, marks_y + 2, 4, red, 2}, /* I_rep */
        {CM_SERIES_SEGMENTS, marks_x + 6, marks_y + 6, 2, blue, 1},
        {CM_SERIES_POINTS, x, y, (size_t)n, black, 2},
    };
    char title[600];
    snprintf(title, sizeof title,
             "escape numbers (steps to fall below x0*); I0 and x = 1 blue, I_rep red; %s",
             params);
    const cm_chart chart = {a->out.width, a->out.height, {0, 0},  {hi, top + 1}, "x", "escape number",
                            title,    NULL,      series, 4,            figure_font(), 0, NULL, 0};
    const cm_png_text texts[] = {{"Model", a->mo.name}, {"Parameters", params}};
    const bool ok = (outfile_charts(a->out.png, &chart, 1, texts, 2, msg, msg_size) == CM_OK);
    free(x);
    return ok;
}

/* Fig. 4.7: the mean escape number against the swept parameter. */
static bool png_sweep(const esc_args *a, const esc_point *pts, const char *params, char *msg,
                      size_t msg_size)
{
    const int n = a->sweep.n;
    double *v = malloc((size_t)n * 6 * sizeof *v);
    if (!v) {
        snprintf(msg, msg_size, "out of memory for the diagram");
        return false;
    }
    double *xs = v, *lo = v + n, *hi = v + 2 * n, *exact = v + 3 * n, *ens = v + 4 * n,
           *scm = v + 5 * n, top = 1;
    for (int i = 0; i < n; i++) {
        const esc_point *p = &pts[i];
        xs[i] = param_axis_value(&a->sweep, i);
        hi[i] = p->valid ? p->t.n_esc[0] : NAN;
        lo[i] = p->valid ? p->t.n_esc[1] : NAN;
        exact[i] = p->valid ? p->exact : NAN;
        ens[i] = p->valid ? 1 / (1 - exp(-p->ens.kappa)) : NAN; /* (4.3) from its rate */
        scm[i] = p->valid ? p->scm_mean : NAN;
        for (const double *s = hi + i; s <= scm + i; s += n)
            if (isfinite(*s))
                top = fmax(top, *s);
    }
    const cm_rgb blue = {69, 117, 180}, purple = {118, 42, 131}, black = {0, 0, 0},
                 green = {26, 152, 80}, orange = {244, 109, 67};
    const cm_series series[] = {
        {CM_SERIES_LINE, xs, hi, (size_t)n, blue, 2},
        {CM_SERIES_LINE, xs, lo, (size_t)n, purple, 2},
        {CM_SERIES_LINE, xs, exact, (size_t)n, black, 2},
        {CM_SERIES_POINTS, xs, ens, (size_t)n, green, 5},
        {CM_SERIES_POINTS, xs, scm, (size_t)n, orange, 3},
    };
    char title[600];
    snprintf(title, sizeof title,
             "mean escape number: (4.3) from kappa of D0 with C1 (blue), C2 (purple) and of an "
             "ensemble (green); exact (black); cell mapping (orange); %s",
             params);
    const cm_chart chart = {a->out.width,
                            a->out.height,
                            {a->sweep.lo, 0},
                            {a->sweep.hi, 1.1 * top},
                            a->sweep.name,
                            "mean escape number",
                            title,
                            NULL,
                            series,
                            5,
                            figure_font(),
                            0,
                            NULL,
                            0};
    char range[120];
    param_axes_format(&a->sweep, 1, range, sizeof range);
    const cm_png_text texts[] = {{"Model", a->mo.name}, {"Parameters", params}, {"Sweep", range}};
    const bool ok = (outfile_charts(a->out.png, &chart, 1, texts, 3, msg, msg_size) == CM_OK);
    free(v);
    return ok;
}

static bool write_png(const esc_args *a, const esc_point *pts, const char *params, char *msg,
                      size_t msg_size)
{
    return a->has_sweep ? png_sweep(a, pts, params, msg, msg_size)
                        : png_structure(a, &pts[0], params, msg, msg_size);
}

esc_args escape_defaults(void)
{
    return (esc_args){.mo = {.name = "microchaos-1d-friction"}, .cells = 100000,
                      .ensemble = 1000000, .out = {.width = 1000, .height = 600}};
}

/* The request's own limits (the command checks them as it parses). */
static cm_status check_request(const esc_args *a, char *msg, size_t msg_size)
{
    if (a->has_I0 && !(a->I0 > 0 && a->I0 < 1e6))
        return cm_fail(CM_EINVAL, msg, msg_size, "I0 = %g must be in (0, 1e6)", a->I0);
    if (a->has_sweep &&
        (a->sweep.n < 1 || a->sweep.n > 10000 || !param_axis_even(&a->sweep) ||
         (strcmp(a->sweep.name, "a") != 0 && strcmp(a->sweep.name, "b") != 0 &&
          strcmp(a->sweep.name, "I0") != 0)))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the sweep must be NAME=LO:HI:N with NAME a, b or I0, LO < HI and 1 <= N "
                       "<= 10000 (e.g. a=1.2:2.25:64)");
    if (a->has_sweep && strcmp(a->sweep.name, "I0") == 0 && a->has_I0)
        return cm_fail(CM_EINVAL, msg, msg_size, "a sweep of I0 and a fixed I0: choose one");
    if (a->cells < 0 || a->cells > 100000000 || a->ensemble < 0 || a->ensemble > 1000000000)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "cells %ld and ensemble %ld: need 0..10^8 and 0..10^9", a->cells,
                       a->ensemble);
    return CM_OK;
}

cm_status escape_compute(const esc_args *a, esc_result *r, char *msg, size_t msg_size)
{
    *r = (esc_result){0};
    const bool sweeps_param = a->has_sweep && strcmp(a->sweep.name, "I0") != 0;
    cm_status st = check_request(a, msg, msg_size);
    if (st == CM_OK)
        st = param_sweep_base(&a->mo, "microchaos-1d-friction", sweeps_param ? &a->sweep : NULL,
                              sweeps_param ? 1 : 0, &r->base, msg, msg_size);
    if (st != CM_OK)
        return st;
    const int n = escape_points(a);
    esc_point *pts = r->pts = calloc((size_t)n, sizeof *pts);
    if (!pts)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %d points", n);
    r->n = n;
#pragma omp parallel for schedule(dynamic, 1) num_threads(a->threads ? a->threads : omp_get_max_threads())
    for (int i = 0; i < n; i++)
        compute_point(a, i, &pts[i]);
    for (int i = 0; i < n; i++)
        r->valid += pts[i].valid;
    if (!a->has_sweep && !pts[0].valid)
        return cm_fail(CM_EINVAL, msg, msg_size, "%s; choose other parameters", pts[0].why);
    return CM_OK;
}

cm_status escape_write(const esc_args *a, const esc_result *r, char *msg, size_t msg_size)
{
    char params[400];
    const char *const skip[] = {a->has_sweep ? a->sweep.name : "", a->has_I0 ? "c" : "", NULL};
    cm_params_format_with(&r->base, skip, params, sizeof params);
    if (a->has_I0) {
        const size_t used = strlen(params);
        snprintf(params + used, sizeof params - used, "%s|I0|=%s", used ? "," : "", CM_NUM(a->I0));
    }
    const bool ok = (!a->out.csv || write_csv(a, r->pts, msg, msg_size)) &&
                    (!a->out.png || write_png(a, r->pts, params, msg, msg_size));
    return ok ? CM_OK : CM_EIO;
}

void escape_result_free(esc_result *r)
{
    free(r->pts);
    r->pts = NULL;
}
