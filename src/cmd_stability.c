/* cellmap stability: the analytic charts of the PD-controlled micro-chaos
 * map (thesis 4.5, App. C.4; Figs. 4.12, 4.14, C.4): the stability domain
 * of the quantisation-free loop in the P-D plane with the eigen-structure
 * curves inside it, the number of regular fixed points against P with the
 * border collisions, the fewest fixed points a stable choice of gains
 * allows against alpha, and the bounds of the control error. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "models/microchaos_pd.h"
#include "models/params.h"
#include "src/args.h"
#include "src/figure_opts.h"
#include "src/commands.h"
#include "lib/json.h"
#include "src/outfile.h"
#include "lib/param_grid.h"

static const char stability_help[] =
    "usage: cellmap stability [--model microchaos-pd] [--param k=v[,k=v]] [--P LO:HI:N]\n"
    "                         [--alpha LO:HI:N] [--csv FILE|-] [--png FILE] [--size WxH]\n"
    "                         [--json] [--quiet]\n\n"
    "The analytic charts of the PD-controlled micro-chaos map (thesis 4.5, App. C.4,\n"
    "docs/models.md 6.5): the domain of gains P, D where x = 0 is asymptotically\n"
    "stable without quantisation, P_min = alpha^2 < P <= P_max and D_b1(P) < D <\n"
    "D_b0(P) (C.45)-(C.47); inside it the curves where trace S = 0 (D_1), det S = 0\n"
    "(D_0) and S has a double eigenvalue (D_c-, D_c+), and the deadbeat point P_quick\n"
    "(C.52)-(C.56); the regular fixed points m = -m_fix,max..m_fix,max (4.73)-(4.75)\n"
    "and their border collisions at P = m alpha^2/(m - 1) (4.72); the strange sets up\n"
    "to m_max (4.76) and the control error m_max/P (4.78), about 1/(P - alpha^2)\n"
    "(4.79)-(4.80). At the --param point it says which; over P it tabulates them.\n\n"
    "  --P LO:HI:N         the values of P for the CSV and the charts (default: N = 400\n"
    "                      from 1.0025 alpha^2 to 1.2 P_max)\n"
    "  --alpha LO:HI:N     alpha for the fewest fixed points (Fig. 4.14, right;\n"
    "                      default 0.05:3:300)\n"
    "  --csv FILE|-        per P: D_b1, D_b0, D_1, D_0, D_c-, D_c+, m_fix_max, the\n"
    "                      number of regular fixed points, m_max, m_max/P, 1/(P - alpha^2)\n"
    "  --png FILE          three charts: the stability domain with the curves and the\n"
    "                      --param point (Figs. 4.12, C.4); the regular fixed points\n"
    "                      against P with the border collisions (Fig. 4.14, left); the\n"
    "                      fewest at P_max against alpha (Fig. 4.14, right)\n"
    "  --size WxH          image size (default 900x1200)\n"
    "  --json              the summary as JSON on standard output\n"
    "  --quiet             no summary\n";

typedef struct stab_args {
    model_opts mo;
    param_axis P, alpha;
    int has_P, has_alpha;
    chart_outputs out;
} stab_args;

static int take_axis(cli *c, const char *opt, const char *name, param_axis *ax, int *has,
                     int *err)
{
    if (!cli_is(c, opt, true, err))
        return 0;
    char text[160];
    snprintf(text, sizeof text, "%s=%s", name, c->value ? c->value : "");
    if (c->value && (!param_axis_parse(text, strlen(text), ax) || ax->n > 100000 ||
                     !param_axis_even(ax) || ax->n < 2))
        *err = cli_usage_error(c, "%s: '%s' is not LO:HI:N with LO < HI and 2 <= N <= 100000",
                               opt, c->value);
    *has = 1;
    return 1;
}

static int parse_args(cli *c, stab_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(stability_help, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (take_axis(c, "--P", "P", &a->P, &a->has_P, &err)) {
        } else if (take_axis(c, "--alpha", "alpha", &a->alpha, &a->has_alpha, &err)) {
            if (!err && a->alpha.lo <= 0)
                err = cli_usage_error(c, "--alpha: alpha must be positive");
        } else if (chart_outputs_take(c, &a->out, 300, 450, &err)) {
        } else {
            err = cli_stray(c);
        }
    }
    if (!err)
        err = chart_outputs_check(c, &a->out);
    return err;
}

/* Everything at one P (alpha, beta of the model). */
typedef struct stab_row {
    double P;
    cm_pd_stability st; /* its D_b0, D_b1 */
    cm_pd_eigen_curves ec;
    int64_t m_fix_max, m_max; /* -1: P <= alpha^2 */
    double x_max_sw, x_max;
} stab_row;

static void row_at(double alpha, double beta, double P, double D, stab_row *r)
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

static bool write_csv(const stab_args *a, const stab_row *rows)
{
    outfile o;
    if (!outfile_open("stability", a->out.csv, &o))
        return false;
    fprintf(o.f, "P,D_b1,D_b0,D_1,D_0,D_c_minus,D_c_plus,m_fix_max,n_fixed,m_max,x_max_sw,x_max\n");
    for (int i = 0; i < a->P.n; i++) {
        const stab_row *r = &rows[i];
        fprintf(o.f, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%lld,%.17g,%lld,%.17g,%.17g\n",
                r->P, r->st.D_b1, r->st.D_b0, r->ec.D_1, r->ec.D_0, r->ec.D_c_minus,
                r->ec.D_c_plus, (long long)r->m_fix_max, n_fixed(r), (long long)r->m_max,
                r->x_max_sw, r->x_max);
    }
    return outfile_close("stability", &o, true);
}

enum { CHARTS = 3 };

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
                      double alpha, double beta, double P0, double D0)
{
    const int n = a->P.n, na = a->alpha.n;
    /* 7 curves over P, the steps of N (2 points per P), border collisions,
     * N at P_max over alpha */
    double *v = malloc(((size_t)n * 12 + (size_t)na * 4 + 400) * sizeof *v);
    if (!v) {
        fprintf(stderr, "cellmap stability: out of memory for the charts\n");
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
    const bool ok = write_chart_png("stability", a->out.png, charts, CHARTS, texts, 2);
    free(v);
    return ok;
}

static void print_summary(FILE *f, double alpha, double beta, double P, double D)
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
    row_at(alpha, beta, P, D, &r);
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

static void print_json(const stab_args *a, const cm_params *p, double alpha, double beta,
                       double P, double D)
{
    stab_row r;
    row_at(alpha, beta, P, D, &r);
    const double Pq = cm_pd_P_quick(alpha, beta);
    cm_pd_eigen_curves q;
    cm_pd_eigen_curves_at(alpha, beta, Pq, &q);
    json j;
    json_begin(&j, stdout, "stability");
    param_base_json(&j, a->mo.name, p);
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

int cmd_stability(int argc, char **argv)
{
    cli c = {"stability", argc, argv, 0, NULL, NULL};
    stab_args a = {.mo = {.name = "microchaos-pd"}, .out = {.width = 900, .height = 1200}};
    const int perr = parse_args(&c, &a);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    const int werr = chart_outputs_writable(&c, &a.out);
    if (werr != EXIT_OK)
        return werr;
    cm_params base;
    const int verr = sweep_check(&c, &a.mo, "microchaos-pd", NULL, 0, &base);
    if (verr)
        return verr;
    const double alpha = cm_params_get(&base, "alpha"), beta = cm_params_get(&base, "beta"),
                 P = cm_params_get(&base, "P"), D = cm_params_get(&base, "D");
    if (!a.has_P) {
        const double lo = 1.0025 * alpha * alpha, hi = 1.2 * cm_pd_P_max(alpha, beta);
        a.P = (param_axis){.lo = lo, .hi = hi, .n = 400};
        snprintf(a.P.name, sizeof a.P.name, "P");
    }
    if (!a.has_alpha) {
        a.alpha = (param_axis){.lo = 0.05, .hi = 3, .n = 300};
        snprintf(a.alpha.name, sizeof a.alpha.name, "alpha");
    }
    stab_row *rows = calloc((size_t)a.P.n, sizeof *rows);
    if (!rows) {
        fprintf(stderr, "cellmap stability: out of memory for %d values of P\n", a.P.n);
        return EXIT_FAIL;
    }
    for (int i = 0; i < a.P.n; i++)
        row_at(alpha, beta, param_axis_value(&a.P, i), D, &rows[i]);
    if (a.out.json)
        print_json(&a, &base, alpha, beta, P, D);
    else if (!a.out.quiet)
        print_summary(report_stream(a.out.csv, a.out.png, NULL), alpha, beta, P, D);
    bool ok = true;
    if (a.out.csv)
        ok = write_csv(&a, rows);
    if (ok && a.out.png)
        ok = write_png(&a, &base, rows, alpha, beta, P, D);
    free(rows);
    return ok ? EXIT_OK : EXIT_FAIL;
}
