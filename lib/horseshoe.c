/* lib/horseshoe.c - horseshoes computed and written (lib/horseshoe.h). */
#include "lib/horseshoe.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/figure.h"
void horseshoe_item_at(double alpha, double beta, double P, double D, int64_t m, int n, hs_item *it)
{
    it->P = P;
    cm_pd_horseshoe_at(alpha, beta, P, D, m, &it->h);
    it->periodic = cm_pd_horseshoe_periodic(alpha, beta, P, D, m, n);
    it->entropy = it->periodic ? log((double)it->periodic) / n : NAN;
}

static bool write_csv(const hs_args *a, const hs_item *items, int count, char *msg,
                         size_t msg_size)
{
    outfile o;
    if (outfile_begin(a->out.csv, &o, msg, msg_size) != CM_OK)
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
    return (outfile_end(&o, true, msg, msg_size) == CM_OK);
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
                      double beta, double P, double D, const char *params, char *msg,
                      size_t msg_size)
{
    cm_pd_coef k;
    cm_pd_coefficients(alpha, beta, P, D, &k);
    const size_t cap = (size_t)count * 8 * 2;
    double *v = malloc(cap * 4 * 2 * sizeof *v);
    if (!v) {
        snprintf(msg, msg_size, "out of memory for the figure");
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
    const bool ok = (outfile_charts(a->out.png, &chart, 1, texts, 2, msg, msg_size) == CM_OK);
    free(v);
    return ok;
}

/* Writes a chart over the swept P with the PNG's text chunks. */
static bool write_sweep_chart(const hs_args *a, const cm_chart *chart, const char *params,
                              char *msg, size_t msg_size)
{
    char range[120];
    param_axes_format(&a->sweep, 1, range, sizeof range);
    const cm_png_text texts[] = {{"Model", a->mo.name}, {"Parameters", params}, {"Sweep", range}};
    return (outfile_charts(a->out.png, chart, 1, texts, 3, msg, msg_size) == CM_OK);
}

/* Fig. 4.20: at each P and m, attractor or repeller (which way its orbits
 * escape), as coloured marks; nothing beyond m_max. */
static bool png_crisis(const hs_args *a, const hs_item *items, int nm, double alpha,
                       const char *params, char *msg, size_t msg_size)
{
    const int np = a->sweep.n;
    const size_t n = (size_t)np * (size_t)nm;
    double *v = malloc(n * 2 * sizeof *v);
    size_t *counts = calloc(5, sizeof *counts);
    if (!v || !counts) {
        free(v);
        free(counts);
        snprintf(msg, msg_size, "out of memory for the figure");
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
    const bool ok = write_sweep_chart(a, &chart, params, msg, msg_size);
    free(v);
    free(counts);
    return ok;
}

/* Fig. 4.17: the entropy estimate against P, a line per m. */
static bool png_sweep(const hs_args *a, const hs_item *items, int nm, const char *params,
                      char *msg, size_t msg_size)
{
    const int np = a->sweep.n;
    double *v = malloc((size_t)np * (size_t)(nm + 1) * sizeof *v);
    if (!v) {
        snprintf(msg, msg_size, "out of memory for the figure");
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
    const bool ok = write_sweep_chart(a, &chart, params, msg, msg_size);
    free(v);
    return ok;
}

static bool write_png(const hs_args *a, const hs_item *items, int nm, int count, double alpha,
                         double beta, double P, double D, const char *params, char *msg,
                         size_t msg_size)
{
    return a->crisis      ? png_crisis(a, items, nm, alpha, params, msg, msg_size)
           : a->has_sweep ? png_sweep(a, items, nm, params, msg, msg_size)
                          : png_point(a, items, count, alpha, beta, P, D, params, msg, msg_size);
}

hs_args horseshoe_defaults(void)
{
    return (hs_args){.mo = {.name = "microchaos-pd"}, .periods = 12,
                     .out = {.width = 1000, .height = 600}};
}

/* The request's own limits (the command checks them as it parses). */
static cm_status check_request(const hs_args *a, char *msg, size_t msg_size)
{
    if (a->has_m && !(a->m0 >= 1 && a->m1 >= a->m0 && a->m1 - a->m0 <= 1000))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "lines %lld:%lld: need 1 <= M0 <= M1 <= M0 + 1000", (long long)a->m0,
                       (long long)a->m1);
    if (a->periods < 1 || a->periods > 20)
        return cm_fail(CM_EINVAL, msg, msg_size, "period %d is not in 1..20", a->periods);
    if (a->has_sweep && (strcmp(a->sweep.name, "P") != 0 || a->sweep.n < 1 ||
                         a->sweep.n > 10000 || !param_axis_even(&a->sweep)))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the sweep must be P=LO:HI:K with LO < HI and 1 <= K <= 10000");
    if (a->crisis && !a->has_sweep)
        return cm_fail(CM_EINVAL, msg, msg_size, "the crisis chart needs a sweep of P");
    return CM_OK;
}

cm_status horseshoe_compute(hs_args *a, hs_result *r, char *msg, size_t msg_size)
{
    *r = (hs_result){0};
    cm_status st = check_request(a, msg, msg_size);
    if (st == CM_OK)
        st = param_sweep_base(&a->mo, "microchaos-pd", a->has_sweep ? &a->sweep : NULL,
                              a->has_sweep, &r->base, msg, msg_size);
    if (st != CM_OK)
        return st;
    r->alpha = cm_params_get(&r->base, "alpha"), r->beta = cm_params_get(&r->base, "beta");
    r->P = cm_params_get(&r->base, "P"), r->D = cm_params_get(&r->base, "D");
    if (!a->has_m) {
        const int64_t m_max = cm_pd_m_max(r->alpha, r->P);
        if (m_max < 1 || m_max > 1000)
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "m_max = %lld at these parameters (P <= alpha^2, or too many lines); "
                           "give the lines M0:M1",
                           (long long)m_max);
        a->m0 = 1, a->m1 = m_max;
    }
    const int nm = (int)(a->m1 - a->m0 + 1), np = a->has_sweep ? a->sweep.n : 1;
    r->items = calloc((size_t)nm * (size_t)np, sizeof *r->items);
    if (!r->items)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory");
    for (int i = 0; i < np; i++)
        for (int j = 0; j < nm; j++)
            horseshoe_item_at(r->alpha, r->beta,
                              a->has_sweep ? param_axis_value(&a->sweep, i) : r->P, r->D,
                              a->m0 + j, a->periods, &r->items[(size_t)i * (size_t)nm + (size_t)j]);
    r->nm = nm, r->count = nm * np;
    return CM_OK;
}

cm_status horseshoe_write(const hs_args *a, const hs_result *r, char *msg, size_t msg_size)
{
    char params[400];
    const char *const skip[] = {a->has_sweep ? "P" : "", NULL};
    cm_params_format_with(&r->base, skip, params, sizeof params);
    const bool ok = (!a->out.csv || write_csv(a, r->items, r->count, msg, msg_size)) &&
                    (!a->out.png || write_png(a, r->items, r->nm, r->count, r->alpha, r->beta,
                                              r->P, r->D, params, msg, msg_size));
    return ok ? CM_OK : CM_EIO;
}

void horseshoe_result_free(hs_result *r)
{
    free(r->items);
    r->items = NULL;
}
