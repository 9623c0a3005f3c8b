/* cellmap horseshoe: the Smale horseshoes of the PD-controlled micro-chaos
 * map at its switching lines (thesis 4.5.3, Figs. 4.15-4.19): the
 * trapezoids L and R, the four escape conditions of a full binary shift,
 * attractor or repeller, and the periodic points of the restricted maps,
 * whose growth bounds the topological entropy from below; at one parameter
 * point or along a sweep of P (Fig. 4.17). */
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

static const char horseshoe_help[] =
    "usage: cellmap horseshoe [--model microchaos-pd] [--param k=v[,k=v]] [--m M0:M1]\n"
    "                         [--periods N] [--sweep P=LO:HI:K [--crisis]] [--csv FILE|-]\n"
    "                         [--png FILE] [--size WxH] [--json] [--quiet]\n\n"
    "The horseshoes of the PD micro-chaos map (thesis 4.5.3, docs/models.md 6.6): at\n"
    "each switching line SW_m the parallelogram Q_m between the fixed points x_(m-1)*\n"
    "and x_m*, bounded by their stable and unstable manifolds and cut by SW_m into\n"
    "the trapezoids L and R; the four escape conditions (f_l of the corners LUSW and\n"
    "RUSW right of W_R^S, f_r of them left of W_L^S): any of them, and an image leaves\n"
    "Q_m (a repeller; none: an attractor); all four, and the map on Q_m is conjugate\n"
    "to a full binary shift. N_n, the points of period n whose orbits follow their\n"
    "symbols (the band left or right of SW_m) inside Q_m, gives the lower estimate\n"
    "log(N_n)/n of the topological entropy: log 2 on a full horseshoe.\n\n"
    "  --m M0:M1           the switching lines, 1 <= M0 <= M1 (default 1 to m_max, 4.76)\n"
    "  --periods N         the period of the estimate, 1..20 (default 12)\n"
    "  --sweep P=LO:HI:K   the entropy estimate against P (Fig. 4.17), at each m\n"
    "  --crisis            with --sweep: the PNG is the crisis chart of Fig. 4.20 instead:\n"
    "                      at each P and SW_m, an attractor (green), or a repeller whose\n"
    "                      orbits escape away from the origin (Out: red), towards it (In:\n"
    "                      blue) or both (purple); beyond m_max (4.76) nothing (grey)\n"
    "  --csv FILE|-        per m (and P): the corners, the escape conditions, attractor\n"
    "                      or repeller, full shift, N_n and the entropy estimate\n"
    "  --png FILE          one point: L and R (red, blue), their images f_l(L), f_r(R)\n"
    "                      and the switching lines (Figs. 4.15, 4.16); a sweep: the\n"
    "                      entropy estimate against P per m (Fig. 4.17)\n"
    "  --size WxH          image size (default 1000x600)\n"
    "  --json              the summary as JSON on standard output\n"
    "  --quiet             no summary\n";

typedef struct hs_args {
    model_opts mo;
    int64_t m0, m1;
    int has_m, periods, has_sweep, crisis;
    param_axis sweep;
    chart_outputs out;
} hs_args;

static int parse_args(cli *c, hs_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(horseshoe_help, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (cli_is(c, "--m", true, &err)) {
            long long lo, hi;
            char tail;
            if (c->value && (sscanf(c->value, "%lld:%lld%c", &lo, &hi, &tail) != 2 || lo < 1 ||
                             hi < lo || hi - lo > 1000))
                err = cli_usage_error(c, "--m: '%s' is not M0:M1 with 1 <= M0 <= M1 <= M0 + 1000",
                                      c->value);
            else if (c->value)
                a->m0 = lo, a->m1 = hi;
            a->has_m = 1;
        } else if (cli_take_int(c, "--periods", 1, 20, &a->periods, &err)) {
        } else if (cli_is(c, "--crisis", false, &err)) {
            a->crisis = 1;
        } else if (cli_is(c, "--sweep", true, &err)) {
            if (c->value && (!param_axis_parse(c->value, strlen(c->value), &a->sweep) ||
                             strcmp(a->sweep.name, "P") != 0 || a->sweep.n > 10000 ||
                             !param_axis_even(&a->sweep)))
                err = cli_usage_error(c, "--sweep: '%s' is not P=LO:HI:K with LO < HI and "
                                         "1 <= K <= 10000",
                                      c->value);
            a->has_sweep = 1;
        } else if (chart_outputs_take(c, &a->out, 300, 200, &err)) {
        } else {
            err = cli_stray(c);
        }
    }
    if (!err)
        err = chart_outputs_check(c, &a->out);
    if (!err && a->crisis && !a->has_sweep)
        err = cli_usage_error(c, "--crisis charts a sweep: give --sweep P=LO:HI:K too");
    return err;
}

/* One switching line at one P. */
typedef struct hs_item {
    double P;
    cm_pd_horseshoe h;
    uint64_t periodic; /* N_n */
    double entropy;    /* log(N_n)/n; NaN for N_n = 0 */
} hs_item;

static void item_at(double alpha, double beta, double P, double D, int64_t m, int n, hs_item *it)
{
    it->P = P;
    cm_pd_horseshoe_at(alpha, beta, P, D, m, &it->h);
    it->periodic = cm_pd_horseshoe_periodic(alpha, beta, P, D, m, n);
    it->entropy = it->periodic ? log((double)it->periodic) / n : NAN;
}

static bool write_csv(const hs_args *a, const hs_item *items, int count)
{
    outfile o;
    if (!outfile_open("horseshoe", a->out.csv, &o))
        return false;
    fprintf(o.f, "P,m,RULS_x,RULS_v,LURS_x,LURS_v,RUSW_x,RUSW_v,LUSW_x,LUSW_v,"
                 "escape_l_LUSW,escape_l_RUSW,escape_r_LUSW,escape_r_RUSW,kind,full_shift,"
                 "periods,periodic,entropy\n");
    for (int i = 0; i < count; i++) {
        const cm_pd_horseshoe *h = &items[i].h;
        fprintf(o.f, "%.17g,%lld,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%d,%d,%d,%d,%s,%d,"
                     "%d,%llu,%.17g\n",
                items[i].P, (long long)h->m, h->RULS[0], h->RULS[1], h->LURS[0], h->LURS[1],
                h->RUSW[0], h->RUSW[1], h->LUSW[0], h->LUSW[1], h->escape[0], h->escape[1],
                h->escape[2], h->escape[3], h->stretches ? "repeller" : "attractor",
                h->full_shift, a->periods, (unsigned long long)items[i].periodic,
                items[i].entropy);
    }
    return outfile_close("horseshoe", &o, true);
}

/* Appends the closed polygon p (n corners) as segments to x, y. (Not
 * const: C11 converts no double (*)[2] to const double (*)[2].) */
static size_t polygon(double (*p)[2], int n, double *x, double *y, size_t k)
{
    for (int i = 0; i < n; i++) {
        x[k] = p[i][0], y[k++] = p[i][1];
        x[k] = p[(i + 1) % n][0], y[k++] = p[(i + 1) % n][1];
    }
    return k;
}

/* Figs. 4.15-4.16: per m, L and R, f_l(L) and f_r(R), and SW_m. */
static bool png_point(const hs_args *a, const hs_item *items, int count, double alpha,
                      double beta, double P, double D, const char *params)
{
    cm_pd_coef k;
    cm_pd_coefficients(alpha, beta, P, D, &k);
    const size_t cap = (size_t)count * 8 * 2;
    double *v = malloc(cap * 4 * 2 * sizeof *v);
    if (!v) {
        fprintf(stderr, "cellmap horseshoe: out of memory for the figure\n");
        return false;
    }
    double *xs[4], *ys[4];
    size_t ns[4] = {0, 0, 0, 0};
    for (int s = 0; s < 4; s++)
        xs[s] = v + (size_t)s * 2 * cap, ys[s] = xs[s] + cap;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int i = 0; i < count; i++) {
        const cm_pd_horseshoe *h = &items[i].h;
        double L[4][2] = {{h->x_l[0], h->x_l[1]}, {h->RULS[0], h->RULS[1]},
                          {h->RUSW[0], h->RUSW[1]}, {h->LUSW[0], h->LUSW[1]}};
        double R[4][2] = {{h->LUSW[0], h->LUSW[1]}, {h->RUSW[0], h->RUSW[1]},
                          {h->x_r[0], h->x_r[1]}, {h->LURS[0], h->LURS[1]}};
        double fL[4][2], fR[4][2];
        for (int c = 0; c < 4; c++) {
            const double ql = (double)(h->m - 1), qr = (double)h->m;
            fL[c][0] = k.A[0] * L[c][0] + k.A[1] * L[c][1] + k.b[0] * ql;
            fL[c][1] = k.A[2] * L[c][0] + k.A[3] * L[c][1] + k.b[1] * ql;
            fR[c][0] = k.A[0] * R[c][0] + k.A[1] * R[c][1] + k.b[0] * qr;
            fR[c][1] = k.A[2] * R[c][0] + k.A[3] * R[c][1] + k.b[1] * qr;
            for (int d = 0; d < 2; d++) {
                lo[d] = fmin(lo[d], fmin(L[c][d], R[c][d]));
                hi[d] = fmax(hi[d], fmax(L[c][d], R[c][d]));
            }
        }
        ns[0] = polygon(L, 4, xs[0], ys[0], ns[0]);
        ns[1] = polygon(R, 4, xs[1], ys[1], ns[1]);
        ns[2] = polygon(fL, 4, xs[2], ys[2], ns[2]);
        ns[3] = polygon(fR, 4, xs[3], ys[3], ns[3]);
    }
    const double pad[2] = {0.15 * (hi[0] - lo[0]), 0.6 * (hi[1] - lo[1])};
    const cm_rgb red = {215, 48, 39}, blue = {69, 117, 180}, pink = {244, 165, 130},
                 sky = {146, 197, 222};
    const cm_series series[] = {
        {CM_SERIES_SEGMENTS, xs[2], ys[2], ns[2], pink, 1},
        {CM_SERIES_SEGMENTS, xs[3], ys[3], ns[3], sky, 1},
        {CM_SERIES_SEGMENTS, xs[0], ys[0], ns[0], red, 2},
        {CM_SERIES_SEGMENTS, xs[1], ys[1], ns[1], blue, 2},
    };
    char title[600];
    snprintf(title, sizeof title,
             "horseshoes: L (red), R (blue), f_l(L) and f_r(R) (light) at SW_%lld..%lld; %s",
             (long long)items[0].h.m, (long long)items[count - 1].h.m, params);
    const cm_chart chart = {a->out.width,
                            a->out.height,
                            {lo[0] - pad[0], lo[1] - pad[1]},
                            {hi[0] + pad[0], hi[1] + pad[1]},
                            "x",
                            "x'",
                            title,
                            NULL,
                            series,
                            4,
                            figure_font(),
                            0,
                            NULL,
                            0};
    const cm_png_text texts[] = {{"Model", a->mo.name}, {"Parameters", params}};
    const bool ok = write_chart_png("horseshoe", a->out.png, &chart, 1, texts, 2);
    free(v);
    return ok;
}

/* Writes a chart over the swept P with the PNG's text chunks. */
static bool write_sweep_chart(const hs_args *a, const cm_chart *chart, const char *params)
{
    char range[120];
    param_axes_format(&a->sweep, 1, range, sizeof range);
    const cm_png_text texts[] = {{"Model", a->mo.name}, {"Parameters", params}, {"Sweep", range}};
    return write_chart_png("horseshoe", a->out.png, chart, 1, texts, 3);
}

/* Fig. 4.20: at each P and m, attractor or repeller (which way its orbits
 * escape), as coloured marks; nothing beyond m_max. */
static bool png_crisis(const hs_args *a, const hs_item *items, int nm, double alpha,
                       const char *params)
{
    const int np = a->sweep.n;
    const size_t n = (size_t)np * (size_t)nm;
    double *v = malloc(n * 2 * sizeof *v);
    size_t *counts = calloc(5, sizeof *counts);
    if (!v || !counts) {
        free(v);
        free(counts);
        fprintf(stderr, "cellmap horseshoe: out of memory for the figure\n");
        return false;
    }
    /* kinds: 0 attractor, 1 out, 2 in, 3 both, 4 beyond m_max; the marks
     * sorted by kind, a series each */
    size_t at[5] = {0}, fill[5] = {0};
    for (int pass = 0; pass < 2; pass++) {
        for (size_t i = 0; i < n; i++) {
            const hs_item *it = &items[i];
            const cm_pd_horseshoe *h = &it->h;
            const bool out = h->escape[0] || h->escape[1], in = h->escape[2] || h->escape[3];
            const int kind = h->m > cm_pd_m_max(alpha, it->P) ? 4
                             : out && in                        ? 3
                             : out                              ? 1
                             : in                               ? 2
                                                                : 0;
            if (pass == 0) {
                counts[kind]++;
            } else {
                const size_t k = at[kind] + fill[kind]++;
                v[k] = it->P;
                v[n + k] = (double)h->m;
            }
        }
        for (int k = 1; pass == 0 && k < 5; k++)
            at[k] = at[k - 1] + counts[k - 1];
    }
    const cm_rgb colours[5] = {{26, 152, 80}, {215, 48, 39}, {69, 117, 180}, {118, 42, 131},
                               {200, 200, 200}};
    cm_series series[5];
    for (int k = 0; k < 5; k++)
        series[k] = (cm_series){CM_SERIES_POINTS, v + at[k], v + n + at[k], counts[k], colours[k], 6};
    char title[600];
    snprintf(title, sizeof title,
             "crisis chart: attractor (green), repeller escaping out (red), in (blue), both "
             "(purple), beyond m_max (grey); %s",
             params);
    const cm_chart chart = {a->out.width,     a->out.height, {a->sweep.lo, (double)a->m0 - 0.5},
                            {a->sweep.hi, (double)a->m1 + 0.5},
                            "P",          "m",       title,  NULL,
                            series,       5,         figure_font(), 0,
                            NULL,         0};
    const bool ok = write_sweep_chart(a, &chart, params);
    free(v);
    free(counts);
    return ok;
}

/* Fig. 4.17: the entropy estimate against P, a line per m. */
static bool png_sweep(const hs_args *a, const hs_item *items, int nm, const char *params)
{
    const int np = a->sweep.n;
    double *v = malloc((size_t)np * (size_t)(nm + 1) * sizeof *v);
    if (!v) {
        fprintf(stderr, "cellmap horseshoe: out of memory for the figure\n");
        return false;
    }
    double *Ps = v;
    for (int i = 0; i < np; i++)
        Ps[i] = param_axis_value(&a->sweep, i);
    cm_series series[64];
    const cm_rgb colours[6] = {{215, 48, 39}, {69, 117, 180}, {26, 152, 80},
                               {118, 42, 131}, {244, 109, 67}, {0, 0, 0}};
    const int shown = nm < 64 ? nm : 64;
    for (int j = 0; j < shown; j++) {
        double *h = v + (size_t)(j + 1) * (size_t)np;
        for (int i = 0; i < np; i++)
            h[i] = items[(size_t)i * (size_t)nm + (size_t)j].entropy;
        series[j] = (cm_series){CM_SERIES_LINE, Ps, h, (size_t)np, colours[j % 6], 2};
    }
    char title[600];
    snprintf(title, sizeof title,
             "topological entropy, lower estimate log(N_%d)/%d, at SW_%lld..%lld (colours in "
             "order: red, blue, green, purple, orange, black); %s",
             a->periods, a->periods, (long long)a->m0, (long long)a->m1, params);
    const cm_chart chart = {a->out.width,     a->out.height, {a->sweep.lo, 0}, {a->sweep.hi, 0.8},
                            "P",          "h",       title,            NULL,
                            series,       shown,     figure_font(),    0,
                            NULL,         0};
    const bool ok = write_sweep_chart(a, &chart, params);
    free(v);
    return ok;
}

static void print_item(FILE *f, const hs_args *a, const hs_item *it)
{
    const cm_pd_horseshoe *h = &it->h;
    fprintf(f, "SW_%lld: %s%s; escape conditions %d%d%d%d; N_%d = %llu, entropy >= %.6g\n",
            (long long)h->m, h->stretches ? "repeller" : "attractor",
            h->full_shift ? ", a full binary shift" : "", h->escape[0], h->escape[1],
            h->escape[2], h->escape[3], a->periods, (unsigned long long)it->periodic,
            it->entropy);
}

int cmd_horseshoe(int argc, char **argv)
{
    cli c = {"horseshoe", argc, argv, 0, NULL, NULL};
    hs_args a = {.mo = {.name = "microchaos-pd"},
                 .periods = 12,
                 .out = {.width = 1000, .height = 600}};
    const int perr = parse_args(&c, &a);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    const int werr = chart_outputs_writable(&c, &a.out);
    if (werr != EXIT_OK)
        return werr;
    cm_params base;
    const int verr =
        sweep_check(&c, &a.mo, "microchaos-pd", a.has_sweep ? &a.sweep : NULL, a.has_sweep, &base);
    if (verr)
        return verr;
    const double alpha = cm_params_get(&base, "alpha"), beta = cm_params_get(&base, "beta"),
                 P = cm_params_get(&base, "P"), D = cm_params_get(&base, "D");
    if (!a.has_m) {
        const int64_t m_max = cm_pd_m_max(alpha, P);
        if (m_max < 1 || m_max > 1000) {
            fprintf(stderr, "cellmap horseshoe: m_max = %lld at these parameters (P <= alpha^2, "
                            "or too many lines); give --m M0:M1\n",
                    (long long)m_max);
            return EXIT_USAGE;
        }
        a.m0 = 1, a.m1 = m_max;
    }
    const int nm = (int)(a.m1 - a.m0 + 1), np = a.has_sweep ? a.sweep.n : 1;
    hs_item *items = calloc((size_t)nm * (size_t)np, sizeof *items);
    if (!items) {
        fprintf(stderr, "cellmap horseshoe: out of memory\n");
        return EXIT_FAIL;
    }
    for (int i = 0; i < np; i++)
        for (int j = 0; j < nm; j++)
            item_at(alpha, beta, a.has_sweep ? param_axis_value(&a.sweep, i) : P, D, a.m0 + j,
                    a.periods, &items[(size_t)i * (size_t)nm + (size_t)j]);
    const int count = nm * np;
    char params[400];
    const char *const skip[] = {a.has_sweep ? "P" : "", NULL};
    cm_params_format_with(&base, skip, params, sizeof params);
    if (a.out.json) {
        json j;
        json_begin(&j, stdout, "horseshoe");
        param_base_json(&j, a.mo.name, &base);
        if (a.has_sweep)
            param_axes_json(&j, "sweep", &a.sweep, 1);
        json_int(&j, "periods", a.periods);
        json_array(&j, "lines");
        for (int i = 0; i < count; i++) {
            const cm_pd_horseshoe *h = &items[i].h;
            json_object(&j, NULL);
            json_num(&j, "P", items[i].P);
            json_int(&j, "m", h->m);
            json_nums(&j, "RULS", h->RULS, 2);
            json_nums(&j, "LURS", h->LURS, 2);
            json_nums(&j, "RUSW", h->RUSW, 2);
            json_nums(&j, "LUSW", h->LUSW, 2);
            json_array(&j, "escape");
            for (int e = 0; e < 4; e++)
                json_bool(&j, NULL, h->escape[e]);
            json_array_end(&j);
            json_str(&j, "kind", h->stretches ? "repeller" : "attractor");
            json_bool(&j, "full_shift", h->full_shift);
            json_uint(&j, "periodic", items[i].periodic);
            json_num(&j, "entropy", items[i].entropy);
            json_object_end(&j);
        }
        json_array_end(&j);
        json_end(&j);
    } else if (!a.out.quiet) {
        FILE *f = report_stream(a.out.csv, a.out.png, NULL);
        if (a.has_sweep)
            fprintf(f, "%d values of P at SW_%lld..%lld\n", np, (long long)a.m0, (long long)a.m1);
        else
            for (int i = 0; i < count; i++)
                print_item(f, &a, &items[i]);
    }
    bool ok = true;
    if (a.out.csv)
        ok = write_csv(&a, items, count);
    if (ok && a.out.png)
        ok = a.crisis      ? png_crisis(&a, items, nm, alpha, params)
             : a.has_sweep ? png_sweep(&a, items, nm, params)
                           : png_point(&a, items, count, alpha, beta, P, D, params);
    free(items);
    return ok ? EXIT_OK : EXIT_FAIL;
}
