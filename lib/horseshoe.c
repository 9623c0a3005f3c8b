/* lib/horseshoe.c - horseshoes computed and written (lib/horseshoe.h). */
#include "lib/horseshoe.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/figure.h"
#include "lib/json.h"
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

/* Appends the pieces' outlines as segments to x, y from k on (room for
 * them all: at most CM_POLYGON_MAX segments a piece). */
static size_t pieces(cm_polygon *pc, int n, double *x, double *y, size_t k)
{
    for (int i = 0; i < n; i++)
        k = polygon(pc[i].p, pc[i].n, x, y, k);
    return k;
}

/* Figs. 4.15, 4.16 and 4.18: per m, L and R, their images (the first:
 * f_l(L), f_r(R)) and pre-images (models/pd_strips.h), and SW_m. */
static bool png_point(const hs_args *a, const hs_item *items, int count, double alpha,
                      double beta, double P, double D, const char *params, char *msg,
                      size_t msg_size)
{
    enum { PIECES = 1 << CM_STRIP_MAX_STEPS };
    /* per m: L, R, and up to PIECES images and pre-images of each */
    const size_t cap = (size_t)count * (8 + 4 * (size_t)PIECES * CM_POLYGON_MAX) * 2;
    double *v = malloc(cap * 6 * 2 * sizeof *v);
    cm_polygon *pc = malloc(PIECES * sizeof *pc);
    if (!v || !pc) {
        free(v);
        free(pc);
        snprintf(msg, msg_size, "out of memory for the figure");
        return false;
    }
    double *xs[6], *ys[6];
    size_t ns[6] = {0};
    for (int s = 0; s < 6; s++)
        xs[s] = v + (size_t)s * 2 * cap, ys[s] = xs[s] + cap;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    bool ok = true;
    for (int i = 0; i < count && ok; i++) {
        const cm_pd_horseshoe *h = &items[i].h;
        double T[2][4][2] = {{{h->x_l[0], h->x_l[1]}, {h->RULS[0], h->RULS[1]},
                              {h->RUSW[0], h->RUSW[1]}, {h->LUSW[0], h->LUSW[1]}},
                             {{h->LUSW[0], h->LUSW[1]}, {h->RUSW[0], h->RUSW[1]},
                              {h->x_r[0], h->x_r[1]}, {h->LURS[0], h->LURS[1]}}};
        for (int side = 0; side < 2 && ok; side++) {
            for (int c = 0; c < 4; c++)
                for (int d = 0; d < 2; d++)
                    lo[d] = fmin(lo[d], T[side][c][d]), hi[d] = fmax(hi[d], T[side][c][d]);
            ns[side] = polygon(T[side], 4, xs[side], ys[side], ns[side]);
            int n = cm_pd_strip_images(alpha, beta, P, D, h->m, side, a->images, pc, PIECES);
            ok = n >= 0;
            ns[2 + side] = pieces(pc, ok ? n : 0, xs[2 + side], ys[2 + side], ns[2 + side]);
            n = a->preimages ? cm_pd_strip_preimages(alpha, beta, P, D, h->m, side, a->preimages,
                                                     pc, PIECES)
                             : 0;
            ok = ok && n >= 0;
            ns[4 + side] = pieces(pc, ok ? n : 0, xs[4 + side], ys[4 + side], ns[4 + side]);
        }
    }
    free(pc);
    if (!ok) {
        free(v);
        snprintf(msg, msg_size, "a piece of the images or pre-images has too many corners");
        return false;
    }
    const double pad[2] = {0.15 * (hi[0] - lo[0]), 0.6 * (hi[1] - lo[1])};
    const cm_rgb red = {215, 48, 39}, blue = {69, 117, 180}, pink = {244, 165, 130},
                 sky = {146, 197, 222}, dark_red = {165, 0, 38}, dark_blue = {49, 54, 149};
    const cm_series series[] = {
        {CM_SERIES_SEGMENTS, xs[2], ys[2], ns[2], pink, 1},
        {CM_SERIES_SEGMENTS, xs[3], ys[3], ns[3], sky, 1},
        {CM_SERIES_SEGMENTS, xs[4], ys[4], ns[4], dark_red, 1},
        {CM_SERIES_SEGMENTS, xs[5], ys[5], ns[5], dark_blue, 1},
        {CM_SERIES_SEGMENTS, xs[0], ys[0], ns[0], red, 2},
        {CM_SERIES_SEGMENTS, xs[1], ys[1], ns[1], blue, 2},
    };
    char title[800], what[160];
    if (a->images == 1 && !a->preimages)
        snprintf(what, sizeof what, "f_l(L) and f_r(R) (light)");
    else if (!a->preimages)
        snprintf(what, sizeof what, "their images f^%d (light)", a->images);
    else
        snprintf(what, sizeof what, "images f^%d (light), pre-images f^-%d (dark)",
                 a->images, a->preimages);
    char lines[80];
    snprintf(lines, sizeof lines, count > 1 ? "SW_%lld..%lld" : "SW_%lld", (long long)items[0].h.m,
             (long long)items[count - 1].h.m);
    snprintf(title, sizeof title, "horseshoes: L (red), R (blue), %s at %s; %s", what, lines,
             params);
    const cm_chart chart = {a->out.width,
                            a->out.height,
                            {lo[0] - pad[0], lo[1] - pad[1]},
                            {hi[0] + pad[0], hi[1] + pad[1]},
                            "x",
                            "x'",
                            title,
                            NULL,
                            series,
                            6,
                            figure_font(),
                            0,
                            NULL,
                            0};
    const cm_png_text texts[] = {{"Model", a->mo.name}, {"Parameters", params}};
    ok = (outfile_charts(a->out.png, &chart, 1, texts, 2, msg, msg_size) == CM_OK);
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

/* Fig. 4.19: over the P-D plane, where SW_m is a full binary shift (a
 * light fill per m, in vertical runs of the plane's cells) and where each
 * of its four escape conditions changes (dots in m's darker colour: the
 * thesis' straight lines). */
static bool png_plane(const hs_args *a, double alpha, double beta, int nm, const char *params,
                      char *msg, size_t msg_size)
{
    const int np = a->sweep.n, nd = a->plane.n, shown = nm < 6 ? nm : 6;
    const size_t cap = (size_t)np * (size_t)nd * 2 + 2;
    double *v = malloc(cap * 4 * (size_t)shown * sizeof *v);
    unsigned char *flags = calloc((size_t)nd * 2, 1); /* escape bits of this and the last column */
    if (!v || !flags) {
        free(v);
        free(flags);
        snprintf(msg, msg_size, "out of memory for the figure");
        return false;
    }
    const cm_rgb fills[6] = {{253, 219, 199}, {209, 229, 240}, {217, 240, 211},
                             {231, 212, 232}, {254, 224, 182}, {224, 224, 224}},
                 lines[6] = {{215, 48, 39}, {69, 117, 180}, {26, 152, 80},
                             {118, 42, 131}, {230, 97, 1}, {0, 0, 0}};
    cm_series series[12];
    const double dD = (a->plane.hi - a->plane.lo) / nd;
    for (int j = 0; j < shown; j++) {
        double *fx = v + (size_t)j * 4 * cap, *fy = fx + cap, *ex = fy + cap, *ey = ex + cap;
        size_t nf = 0, ne = 0;
        for (int i = 0; i < np; i++) {
            const double P = param_axis_value(&a->sweep, i);
            unsigned char *col = flags + (size_t)(i % 2) * (size_t)nd,
                          *last = flags + (size_t)((i + 1) % 2) * (size_t)nd;
            double start = NAN;
            for (int r = 0; r <= nd; r++) {
                const double D = r < nd ? param_axis_value(&a->plane, r) : NAN;
                cm_pd_horseshoe h = {0};
                if (r < nd)
                    cm_pd_horseshoe_at(alpha, beta, P, D, a->m0 + j, &h);
                if (r < nd && h.full_shift && isnan(start))
                    start = D - dD / 2;
                if ((r == nd || !h.full_shift) && !isnan(start)) {
                    fx[nf] = fx[nf + 1] = P, fy[nf] = start;
                    fy[nf + 1] = r == nd ? a->plane.hi : D - dD / 2;
                    nf += 2, start = NAN;
                }
                if (r == nd)
                    break;
                col[r] = (unsigned char)(h.escape[0] | h.escape[1] << 1 | h.escape[2] << 2 |
                                         h.escape[3] << 3);
                if (r > 0 && col[r] != col[r - 1]) /* a line between this row and the last */
                    ex[ne] = P, ey[ne++] = D - dD / 2;
                else if (i > 0 && col[r] != last[r]) /* or between this column and the last */
                    ex[ne] = P - (a->sweep.hi - a->sweep.lo) / np / 2, ey[ne++] = D;
            }
        }
        const float w = (float)ceil((double)a->out.width / np) + 1;
        series[j] = (cm_series){CM_SERIES_SEGMENTS, fx, fy, nf, fills[j], w};
        series[shown + j] = (cm_series){CM_SERIES_POINTS, ex, ey, ne, lines[j], 2};
    }
    free(flags);
    static const char *const names[6] = {"red", "blue", "green", "purple", "orange", "black"};
    char title[700], colours[80] = "";
    for (int j = 0; j < shown; j++)
        snprintf(colours + strlen(colours), sizeof colours - strlen(colours), "%s%s",
                 j ? ", " : "", names[j]);
    snprintf(title, sizeof title, "full binary shifts at SW_%lld..%lld (%s) and their escape "
             "lines; %s", (long long)a->m0, (long long)(a->m0 + shown - 1), colours, params);
    const cm_chart chart = {a->out.width,     a->out.height,
                            {a->sweep.lo, a->plane.lo}, {a->sweep.hi, a->plane.hi},
                            "P",          "D",       title,  NULL,
                            series,       2 * shown, figure_font(), 0,
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
           : a->has_plane ? png_plane(a, alpha, beta, nm, params, msg, msg_size)
           : a->has_sweep ? png_sweep(a, items, nm, params, msg, msg_size)
                          : png_point(a, items, count, alpha, beta, P, D, params, msg, msg_size);
}

hs_args horseshoe_defaults(void)
{
    return (hs_args){.mo = {.name = "microchaos-pd"}, .periods = 12, .images = 1,
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
    if (a->images < 1 || a->images > CM_STRIP_MAX_STEPS || a->preimages < 0 ||
        a->preimages > CM_STRIP_MAX_STEPS)
        return cm_fail(CM_EINVAL, msg, msg_size, "images %d, pre-images %d: need 1..%d and 0..%d",
                       a->images, a->preimages, CM_STRIP_MAX_STEPS, CM_STRIP_MAX_STEPS);
    if (a->has_plane && (!a->has_sweep || a->crisis || strcmp(a->plane.name, "D") != 0 ||
                         a->plane.n < 2 || a->plane.n > 10000 || !param_axis_even(&a->plane)))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the plane needs a sweep of P, no crisis chart, and D=LO:HI:K with LO < HI "
                       "and 2 <= K <= 10000");
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
    const char *const skip[] = {a->has_sweep ? "P" : "", a->has_plane ? "D" : "", NULL};
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

void horseshoe_report_item(FILE *f, const hs_args *a, const hs_item *it)
{
    const cm_pd_horseshoe *h = &it->h;
    fprintf(f, "SW_%lld: %s%s; escape conditions %d%d%d%d; N_%d = %llu, entropy >= %.6g\n",
            (long long)h->m, h->stretches ? "repeller" : "attractor",
            h->full_shift ? ", a full binary shift" : "", h->escape[0], h->escape[1],
            h->escape[2], h->escape[3], a->periods, (unsigned long long)it->periodic,
            it->entropy);
}

void horseshoe_json(const hs_args *a, const hs_result *r)
{
    json j;
    json_begin(&j, stdout, "horseshoe");
    param_base_json(&j, a->mo.name, &r->base);
    if (a->has_sweep)
        param_axes_json(&j, "sweep", &a->sweep, 1);
    json_int(&j, "periods", a->periods);
    json_array(&j, "lines");
    for (int i = 0; i < r->count; i++) {
        const cm_pd_horseshoe *h = &r->items[i].h;
        json_object(&j, NULL);
        json_num(&j, "P", r->items[i].P);
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
        json_uint(&j, "periodic", r->items[i].periodic);
        json_num(&j, "entropy", r->items[i].entropy);
        json_object_end(&j);
    }
    json_array_end(&j);
    json_end(&j);
}
