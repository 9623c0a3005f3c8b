/* lib/amplitude.c - the amplitude-frequency diagram written (lib/amplitude.h). */
#include "lib/amplitude.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/figure.h"
#include "models/params.h"

/* Series of the diagram: a line per kind of x0 (NaN breaks it where the
 * kind changes), the limits, the simulation and the columns. */
typedef struct diagram {
    double *omega, *x0[3], *slip, *turn, *sim, *cols_x, *cols_y;
} diagram;

static bool write_csv(const amp_args *a, const cm_fo_amplitude *v, char *msg, size_t msg_size)
{
    outfile o;
    if (outfile_begin(a->out.csv, &o, msg, msg_size) != CM_OK)
        return false;
    fprintf(o.f, "Omega,x0,slip_limit,turn_limit,valid,mult_max,stable,sim_amplitude,sim_sticks\n");
    for (int i = 0; i < a->omega.n; i++) {
        const cm_fo_amplitude *p = &v[i];
        fprintf(o.f, "%.17g,%.17g,%.17g,%.17g,%d,%.17g,%d,%.17g,%.17g\n",
                param_axis_value(&a->omega, i), p->x0, p->slip_limit, p->turn_limit, p->valid,
                p->mult_max, p->stable, p->sim_amplitude, p->sim_sticks);
    }
    return (outfile_end(&o, true, msg, msg_size) == CM_OK);
}

static bool write_png(const amp_args *a, const cm_params *p, const cm_fo_amplitude *v,
                         char *msg, size_t msg_size)
{
    const int n = a->omega.n;
    diagram d;
    double *all = malloc((size_t)n * 11 * sizeof *all);
    if (!all) {
        snprintf(msg, msg_size, "out of memory for the diagram");
        return false;
    }
    d.omega = all, d.x0[0] = all + n, d.x0[1] = all + 2 * n, d.x0[2] = all + 3 * n;
    d.slip = all + 4 * n, d.turn = all + 5 * n, d.sim = all + 6 * n;
    d.cols_x = all + 7 * n, d.cols_y = all + 9 * n;
    double top = 1; /* without --ymax: what the simulation and the columns reach */
    for (int i = 0; i < n; i++) {
        const cm_fo_amplitude *q = &v[i];
        const double w = param_axis_value(&a->omega, i);
        const int kind = !q->valid ? 2 : q->stable ? 0 : 1;
        d.omega[i] = w;
        for (int k = 0; k < 3; k++)
            d.x0[k][i] = k == kind ? q->x0 : NAN;
        d.slip[i] = q->slip_limit;
        d.turn[i] = q->turn_limit;
        d.sim[i] = q->sim_amplitude;
        d.cols_x[2 * i] = d.cols_x[2 * i + 1] = w;
        d.cols_y[2 * i] = 0;
        d.cols_y[2 * i + 1] = isnan(q->sim_sticks) ? 0 : q->sim_sticks / 10;
        top = fmax(top, isnan(q->sim_amplitude) ? 0 : q->sim_amplitude);
        top = fmax(top, d.cols_y[2 * i + 1]);
    }
    const cm_rgb green = {26, 152, 80}, red = {215, 48, 39}, grey = {170, 170, 170},
                 blue = {69, 117, 180}, purple = {118, 42, 131}, black = {0, 0, 0},
                 orange = {253, 174, 97};
    const cm_series series[] = {
        {CM_SERIES_SEGMENTS, d.cols_x, d.cols_y, (size_t)(2 * n), orange, 3},
        {CM_SERIES_LINE, d.omega, d.slip, (size_t)n, blue, 1},
        {CM_SERIES_LINE, d.omega, d.turn, (size_t)n, purple, 1},
        {CM_SERIES_POINTS, d.omega, d.sim, (size_t)n, black, 5}, /* under the line, as diamonds */
        {CM_SERIES_LINE, d.omega, d.x0[2], (size_t)n, grey, 2},
        {CM_SERIES_LINE, d.omega, d.x0[1], (size_t)n, red, 2},
        {CM_SERIES_LINE, d.omega, d.x0[0], (size_t)n, green, 2},
    };
    char params[400], title[640];
    const char *const skip[] = {"Omega", NULL};
    cm_params_format_with(p, skip, params, sizeof params);
    snprintf(title, sizeof title,
             "x0 (2.25) stable/unstable/invalid; S0/Omega^2, S H_max; simulation, N/10; %s",
             params);
    const cm_chart chart = {a->out.width,
                            a->out.height,
                            {a->omega.lo, 0},
                            {a->omega.hi, a->ymax > 0 ? a->ymax : 1.15 * top},
                            "Omega",
                            "x",
                            title,
                            NULL,
                            series,
                            (int)(sizeof series / sizeof series[0]),
                            figure_font(),
                            0,
                            NULL,
                            0};
    char range[96];
    snprintf(range, sizeof range, "Omega=%s:%s:%d", CM_NUM(a->omega.lo), CM_NUM(a->omega.hi),
             a->omega.n);
    const cm_png_text texts[] = {{"Model", a->mo.name}, {"Parameters", params}, {"Omega", range}};
    const bool ok = (outfile_charts(a->out.png, &chart, 1, texts, 3, msg, msg_size) == CM_OK);
    free(all);
    return ok;
}

/* Sections recorded per simulation. */
enum { RECORD = 40 };

amp_args amplitude_defaults(void)
{
    return (amp_args){.mo = {.name = "friction-oscillator"}, .periods = 400, .ymax = 5,
                      .out = {.width = 1000, .height = 700}};
}

cm_status amplitude_compute(const amp_args *a, amp_result *r, char *msg, size_t msg_size)
{
    *r = (amp_result){0};
    const param_axis *om = &a->omega;
    if (!a->has_omega || !(om->lo > 0 && om->lo < om->hi) || om->n < 1 || om->n > 100000 ||
        !param_axis_even(om))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the frequencies Omega must be LO:HI:N with 0 < LO < HI and 1 <= N <= "
                       "100000 (e.g. 0.1:3:300)");
    if (a->periods < 50 || a->periods > 100000)
        return cm_fail(CM_EINVAL, msg, msg_size, "periods: %d is not in 50..100000", a->periods);
    if (!(a->ymax > 0 && a->ymax < 1e6))
        return cm_fail(CM_EINVAL, msg, msg_size, "ymax %g must be in (0, 1e6)", a->ymax);
    cm_status st = param_sweep_base(&a->mo, "friction-oscillator", om, 1, &r->base, msg, msg_size);
    if (st != CM_OK)
        return st;
    const int n = om->n;
    r->v = calloc((size_t)n, sizeof *r->v);
    if (!r->v)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %d frequencies", n);
    int invalid = 0;
    cm_fo_amplitude *v = r->v;
#pragma omp parallel for schedule(dynamic, 1) num_threads(a->threads ? a->threads : omp_get_max_threads()) reduction(| : invalid)
    for (int i = 0; i < n; i++) {
        const int idx[1] = {i};
        cm_model m;
        if (!model_at_point(&a->mo, om, idx, 1, &m)) {
            invalid = 1;
            v[i] = (cm_fo_amplitude){NAN, NAN, NAN, false, NAN, false, NAN, NAN};
            continue;
        }
        cm_fo_amplitude_at(cm_fo_of_model(&m), a->periods, RECORD, &v[i]);
        cm_model_release(&m);
    }
    r->invalid = invalid;
    for (int i = 0; i < n; i++) {
        r->valid += v[i].valid;
        r->stable += v[i].stable;
        r->lost += isnan(v[i].sim_amplitude);
    }
    return CM_OK;
}

cm_status amplitude_write(const amp_args *a, const amp_result *r, char *msg, size_t msg_size)
{
    const bool ok = (!a->out.csv || write_csv(a, r->v, msg, msg_size)) &&
                    (!a->out.png || write_png(a, &r->base, r->v, msg, msg_size));
    return ok ? CM_OK : CM_EIO;
}

void amplitude_result_free(amp_result *r)
{
    free(r->v);
    r->v = NULL;
}
