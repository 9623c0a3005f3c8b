/* lib/stability.c - the PD map's analytic charts computed and written
 * (lib/stability.h). */
#include "lib/stability.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/figure.h"
#include "lib/json.h"
#include "models/params.h"

enum { CHARTS = 3 };

void stability_row_at(double alpha, double beta, double P, double D, stab_row *r)
{
    r->P = P;
    cm_pd_stability_at(alpha, beta, P, D, &r->st);
    cm_pd_eigen_curves_at(alpha, beta, P, &r->ec);
    r->m_fix_max = cm_pd_m_fix_max(alpha, P);
    r->m_max = cm_pd_m_max(alpha, P);
    r->x_max_sw = r->m_max >= 0 ? (double)r->m_max / P : NAN;
    r->x_max = P > alpha * alpha ? 1 / (P - alpha * alpha) : NAN;
}

static double n_fixed(const stab_row *r)
{
    return r->m_fix_max >= 0 ? (double)(2 * r->m_fix_max + 1) : NAN;
}

static bool write_csv(const stab_args *a, const stab_row *rows, char *msg, size_t msg_size)
{
    outfile o;
    if (outfile_begin(a->out.csv, &o, msg, msg_size) != CM_OK)
        return false;
    fprintf(o.f, "P,D_b1,D_b0,D_1,D_0,D_c_minus,D_c_plus,m_fix_max,n_fixed,m_max,x_max_sw,x_max\n");
    for (int i = 0; i < a->P.n; i++) {
        const stab_row *r = &rows[i];
        fprintf(o.f, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%lld,%.17g,%lld,%.17g,%.17g\n",
                r->P, r->st.D_b1, r->st.D_b0, r->ec.D_1, r->ec.D_0, r->ec.D_c_minus,
                r->ec.D_c_plus, (long long)r->m_fix_max, n_fixed(r), (long long)r->m_max,
                r->x_max_sw, r->x_max);
    }
    return (outfile_end(&o, true, msg, msg_size) == CM_OK);
}

static cm_chart chart_of(const stab_args *a, int k, double xlo, double xhi, double ylo,
                         double yhi, const char *x_name, const char *y_name, const char *title,
                         const cm_series *series, int n_series)
{
    const int h = a->out.height / CHARTS;
    return (cm_chart){a->out.width,  k < CHARTS - 1 ? h : a->out.height - (CHARTS - 1) * h,
                      {xlo, ylo}, {xhi, yhi},
                      x_name,    y_name,
                      title,     NULL,
                      series,    n_series,
                      figure_font(), 0,
                      NULL,      0};
}

static bool write_png(const stab_args *a, const cm_params *p, const stab_row *rows,
                      double alpha, double beta, double P0, double D0, char *msg, size_t msg_size)
{
    const int n = a->P.n, na = a->alpha.n;
    /* 7 curves over P, the steps of N (2 points per P), border collisions,
     * N at P_max over alpha */
    double *v = malloc(((size_t)n * 12 + (size_t)na * 4 + 400) * sizeof *v);
    if (!v) {
        snprintf(msg, msg_size, "out of memory for the charts");
        return false;
    }
    double *Ps = v, *curves[6], *nx = v + 7 * (size_t)n, *ny = nx + 2 * (size_t)n,
           *ax = ny + 2 * (size_t)n, *ay = ax + 2 * (size_t)na, *bx = ay + 2 * (size_t)na,
           *by = bx + 200;
    for (int k = 0; k < 6; k++)
        curves[k] = v + (size_t)(k + 1) * (size_t)n;
    double dlo = INFINITY, dhi = -INFINITY, ntop = 1;
    for (int i = 0; i < n; i++) {
        const stab_row *r = &rows[i];
        Ps[i] = r->P;
        const double in_domain = r->P > alpha * alpha ? 1 : NAN; /* the curves live there */
        const double ds[6] = {r->st.D_b0, r->st.D_b1, r->ec.D_1 * in_domain,
                              r->ec.D_0 * in_domain, r->ec.D_c_minus, r->ec.D_c_plus};
        for (int k = 0; k < 6; k++)
            curves[k][i] = ds[k];
        for (int k = 0; k < 2; k++)
            if (isfinite(ds[k]))
                dlo = fmin(dlo, ds[k]), dhi = fmax(dhi, ds[k]);
        /* N as steps: (P_i, N_i) to (P_i+1, N_i) */
        nx[2 * i] = r->P;
        nx[2 * i + 1] = i + 1 < n ? rows[i + 1].P : r->P;
        ny[2 * i] = ny[2 * i + 1] = n_fixed(r);
        if (isfinite(n_fixed(r)))
            ntop = fmax(ntop, n_fixed(r));
    }
    ntop = fmin(ntop, 41);
    int nb = 0; /* border collisions P = m alpha^2/(m - 1) in the P range */
    for (int m = 2; m < 100 && nb < 100; m++) {
        const double Pc = m * alpha * alpha / (m - 1);
        if (Pc < a->P.lo || Pc > a->P.hi)
            continue;
        bx[2 * nb] = bx[2 * nb + 1] = Pc;
        by[2 * nb] = 0, by[2 * nb + 1] = ntop + 1;
        nb++;
    }
    double atop = 1;
    for (int i = 0; i < na; i++) {
        const double al = param_axis_value(&a->alpha, i), Pm = cm_pd_P_max(al, beta);
        const int64_t m = cm_pd_m_fix_max(al, Pm);
        ax[2 * i] = al;
        ax[2 * i + 1] = i + 1 < na ? param_axis_value(&a->alpha, i + 1) : al;
        ay[2 * i] = ay[2 * i + 1] = m >= 0 ? (double)(2 * m + 1) : NAN;
        if (m >= 0)
            atop = fmax(atop, (double)(2 * m + 1));
    }
    const double Pmax = cm_pd_P_max(alpha, beta), Pq = cm_pd_P_quick(alpha, beta);
    cm_pd_eigen_curves q;
    cm_pd_eigen_curves_at(alpha, beta, Pq, &q);
    const double mark_x[3] = {Pmax, Pq, P0}, mark_y[3] = {cm_pd_D_at_P_max(alpha, beta), q.D_0, D0};
    const double wall_x[2] = {alpha * alpha, alpha * alpha}, wall_y[2] = {dlo, dhi};
    const cm_rgb black = {0, 0, 0}, blue = {69, 117, 180}, green = {26, 152, 80},
                 purple = {118, 42, 131}, red = {215, 48, 39}, grey = {150, 150, 150};
    const cm_series domain[] = {
        {CM_SERIES_LINE, Ps, curves[0], (size_t)n, black, 2},
        {CM_SERIES_LINE, Ps, curves[1], (size_t)n, black, 2},
        {CM_SERIES_SEGMENTS, wall_x, wall_y, 2, black, 2},
        {CM_SERIES_LINE, Ps, curves[2], (size_t)n, blue, 1},
        {CM_SERIES_LINE, Ps, curves[3], (size_t)n, green, 1},
        {CM_SERIES_LINE, Ps, curves[4], (size_t)n, purple, 1},
        {CM_SERIES_LINE, Ps, curves[5], (size_t)n, purple, 1},
        {CM_SERIES_POINTS, mark_x, mark_y, 2, black, 7},
        {CM_SERIES_POINTS, mark_x + 2, mark_y + 2, isfinite(P0) && isfinite(D0) ? 1 : 0, red, 9},
    };
    const cm_series fixed[] = {
        {CM_SERIES_SEGMENTS, bx, by, (size_t)(2 * nb), grey, 1},
        {CM_SERIES_SEGMENTS, nx, ny, (size_t)(2 * n), black, 2},
    };
    const cm_series fewest[] = {{CM_SERIES_SEGMENTS, ax, ay, (size_t)(2 * na), black, 2}};
    char params[400], t1[700], t2[200], t3[200];
    cm_params_format(p, params, sizeof params);
    snprintf(t1, sizeof t1,
             "stability domain (black), trace S = 0 (blue), det S = 0 (green), double "
             "eigenvalue (purple), P_max, P_quick; %s (red)",
             params);
    snprintf(t2, sizeof t2, "regular fixed points (4.73); border collisions at P = m alpha^2/(m-1)");
    snprintf(t3, sizeof t3, "the fewest regular fixed points in the stability domain, at P_max "
                            "(beta = %s)", CM_NUM(beta));
    const double pad = 0.05 * (dhi - dlo);
    const cm_chart charts[CHARTS] = {
        chart_of(a, 0, a->P.lo, a->P.hi, dlo - pad, dhi + pad, "P", "D", t1, domain, 9),
        chart_of(a, 1, a->P.lo, a->P.hi, 0, ntop + 1, "P", "fixed points", t2, fixed, 2),
        chart_of(a, 2, a->alpha.lo, a->alpha.hi, 0, atop + 1, "alpha", "fixed points", t3,
                 fewest, 1),
    };
    const cm_png_text texts[] = {{"Model", a->mo.name}, {"Parameters", params}};
    const bool ok = (outfile_charts(a->out.png, charts, CHARTS, texts, 2, msg, msg_size) == CM_OK);
    free(v);
    return ok;
}

stab_args stability_defaults(void)
{
    return (stab_args){.mo = {.name = "microchaos-pd"}, .out = {.width = 900, .height = 1200}};
}

cm_status stability_compute(stab_args *a, stab_result *r, char *msg, size_t msg_size)
{
    *r = (stab_result){0};
    if ((a->has_P && a->P.n < 2) || (a->has_alpha && a->alpha.n < 2))
        return cm_fail(CM_EINVAL, msg, msg_size, "the axes need at least 2 values");
    if (a->has_alpha && a->alpha.lo <= 0)
        return cm_fail(CM_EINVAL, msg, msg_size, "alpha must be positive");
    const cm_status st = param_sweep_base(&a->mo, "microchaos-pd", NULL, 0, &r->base, msg, msg_size);
    if (st != CM_OK)
        return st;
    r->alpha = cm_params_get(&r->base, "alpha"), r->beta = cm_params_get(&r->base, "beta");
    r->P = cm_params_get(&r->base, "P"), r->D = cm_params_get(&r->base, "D");
    if (!a->has_P) {
        a->P = (param_axis){.lo = 1.0025 * r->alpha * r->alpha,
                            .hi = 1.2 * cm_pd_P_max(r->alpha, r->beta), .n = 400};
        snprintf(a->P.name, sizeof a->P.name, "P");
    }
    if (!a->has_alpha) {
        a->alpha = (param_axis){.lo = 0.05, .hi = 3, .n = 300};
        snprintf(a->alpha.name, sizeof a->alpha.name, "alpha");
    }
    r->rows = calloc((size_t)a->P.n, sizeof *r->rows);
    if (!r->rows)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %d values of P", a->P.n);
    for (int i = 0; i < a->P.n; i++)
        stability_row_at(r->alpha, r->beta, param_axis_value(&a->P, i), r->D, &r->rows[i]);
    return CM_OK;
}

cm_status stability_write(const stab_args *a, const stab_result *r, char *msg, size_t msg_size)
{
    bool ok = !a->out.csv || write_csv(a, r->rows, msg, msg_size);
    ok = ok && (!a->out.png || write_png(a, &r->base, r->rows, r->alpha, r->beta, r->P, r->D, msg,
                                         msg_size));
    return ok ? CM_OK : CM_EIO;
}

void stability_result_free(stab_result *r)
{
    free(r->rows);
    r->rows = NULL;
}

void stability_report(FILE *f, double alpha, double beta, double P, double D)
{
    const double Pmax = cm_pd_P_max(alpha, beta), Pq = cm_pd_P_quick(alpha, beta);
    cm_pd_eigen_curves q;
    cm_pd_eigen_curves_at(alpha, beta, Pq, &q);
    fprintf(f, "alpha = %s, beta = %s: x = 0 is stable without quantisation for %.9g < P <= "
               "%.9g (P_max, where D = %.9g), D_b1(P) < D < D_b0(P) (C.45)-(C.47)\n",
            CM_NUM(alpha), CM_NUM(beta), alpha * alpha, Pmax, cm_pd_D_at_P_max(alpha, beta));
    fprintf(f, "  deadbeat (both eigenvalues of S zero): P_quick = %.9g, D = %.9g (C.56)\n", Pq,
            q.D_0);
    stab_row r;
    stability_row_at(alpha, beta, P, D, &r);
    fprintf(f, "at P = %s, D = %s: %s", CM_NUM(P), CM_NUM(D),
            r.st.stable ? "stable" : "not stable");
    if (P > alpha * alpha)
        fprintf(f, " (D_b1 = %.9g, D_b0 = %.9g)", r.st.D_b1, r.st.D_b0);
    fprintf(f, "\n");
    if (r.m_fix_max < 0) {
        fprintf(f, "  P <= alpha^2: the fixed points are unbounded (4.73 needs P > alpha^2)\n");
        return;
    }
    fprintf(f, "  regular fixed points m = -%lld..%lld: %lld (4.73)-(4.75); strange sets up to "
               "|m| = %lld at x = m/P (4.76)\n",
            (long long)r.m_fix_max, (long long)r.m_fix_max, (long long)(2 * r.m_fix_max + 1),
            (long long)r.m_max);
    fprintf(f, "  control error: m_max/P = %.9g (4.78), 1/(P - alpha^2) = %.9g (4.79)-(4.80)\n",
            r.x_max_sw, r.x_max);
}

void stability_json(const char *model, const cm_params *p, double alpha, double beta, double P,
                    double D)
{
    stab_row r;
    stability_row_at(alpha, beta, P, D, &r);
    const double Pq = cm_pd_P_quick(alpha, beta);
    cm_pd_eigen_curves q;
    cm_pd_eigen_curves_at(alpha, beta, Pq, &q);
    json j;
    json_begin(&j, stdout, "stability");
    param_base_json(&j, model, p);
    json_num(&j, "P_min", alpha * alpha);
    json_num(&j, "P_max", cm_pd_P_max(alpha, beta));
    json_num(&j, "D_at_P_max", cm_pd_D_at_P_max(alpha, beta));
    json_nums(&j, "quick", (const double[2]){Pq, q.D_0}, 2);
    json_bool(&j, "stable", r.st.stable);
    json_nums(&j, "D_range", (const double[2]){r.st.D_b1, r.st.D_b0}, 2);
    json_int(&j, "m_fix_max", r.m_fix_max);
    json_int(&j, "n_fixed", r.m_fix_max >= 0 ? 2 * r.m_fix_max + 1 : -1);
    json_int(&j, "m_max", r.m_max);
    json_num(&j, "x_max_sw", r.x_max_sw);
    json_num(&j, "x_max", r.x_max);
    json_end(&j);
}
