/* lib/delay_domains.c - the delay map's parameter domains written
 * (lib/delay_domains.h). */
#include "lib/delay_domains.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/numtext.h"
#include "lib/figure.h"

enum { CHARTS = 3, ROWS = 1000, CURVES = 12, MAX_RUNS = 4 };

delay_point delay_point_at(double a, double b)
{
    delay_point p = {a, b, {0}, cm_delay_bands_visited(a, b, 0.37, 0.61, 2000, 20000)};
    cm_delay_domains_at(a, b, &p.in);
    return p;
}

typedef bool (*domain_test)(const cm_delay_domains *d);
static bool in_g(const cm_delay_domains *d) { return d->stable; }
static bool in_01(const cm_delay_domains *d) { return d->d01; }
static bool in_012(const cm_delay_domains *d) { return d->d012; }
static bool in_mu_sl(const cm_delay_domains *d) { return d->mu_sl; }
static bool in_su_ml(const cm_delay_domains *d) { return d->su_ml; }

/* A domain filled by vertical runs of the classification itself (so the
 * chart shows what cm_delay_domains_at says, not a second derivation), a
 * run per column, and the domain's centre for its label. */
typedef struct fill {
    double *x, *y;
    size_t n;
    double centre[2];
} fill;

static bool fill_domain(domain_test in, double alo, double ahi, fill *f)
{
    f->x = malloc(sizeof(double) * 4 * DELAY_COLUMNS * MAX_RUNS);
    f->y = f->x ? f->x + 2 * DELAY_COLUMNS * MAX_RUNS : NULL;
    f->n = 0;
    if (!f->x)
        return false;
    double sa = 0, sb = 0, cells = 0;
    for (int i = 0; i < DELAY_COLUMNS; i++) {
        const double a = alo + (ahi - alo) * (i + 0.5) / DELAY_COLUMNS;
        int runs = 0;
        double start = NAN;
        for (int j = 0; j <= ROWS; j++) {
            const double b = (j + 0.5) / ROWS;
            cm_delay_domains d;
            cm_delay_domains_at(a, b, &d);
            const bool inside = j < ROWS && in(&d);
            if (inside) {
                sa += a, sb += b, cells++;
                if (isnan(start))
                    start = b - 0.5 / ROWS;
            } else if (!isnan(start)) {
                if (runs++ < MAX_RUNS) {
                    f->x[f->n] = f->x[f->n + 1] = a;
                    f->y[f->n] = start, f->y[f->n + 1] = b - 0.5 / ROWS;
                    f->n += 2;
                }
                start = NAN;
            }
        }
    }
    f->centre[0] = cells ? sa / cells : NAN, f->centre[1] = cells ? sb / cells : NAN;
    return true;
}

/* The curve of one field of cm_delay_curves over the a axis, NaN outside
 * 0 <= b <= 1 (charts draw what they are given). */
static void curve(size_t field, double alo, double ahi, double *x, double *y)
{
    for (int i = 0; i < DELAY_COLUMNS; i++) {
        x[i] = alo + (ahi - alo) * i / (DELAY_COLUMNS - 1);
        cm_delay_curves c;
        cm_delay_curves_at(x[i], &c);
        double v;
        memcpy(&v, (const char *)&c + field, sizeof v);
        y[i] = v >= 0 && v <= 1 ? v : NAN;
    }
}

#define FIELD(f) offsetof(cm_delay_curves, f)

typedef struct named_curve {
    size_t field;
    const char *name;
    double label_a; /* where its name goes */
    cm_rgb colour;
} named_curve;

/* The colours as initialisers (static tables need constant expressions). */
#define BLACK {0, 0, 0}
#define RED {215, 48, 39}
#define BLUE {69, 117, 180}
#define GREEN {26, 152, 80}
#define PURPLE {118, 42, 131}
#define ORANGE {230, 97, 1}
#define BROWN {140, 81, 10}

/* Fig. 4.10's curves (the first four bound '01', the last five '012'). */
static const named_curve curves_4_10[] = {
    {FIELD(n_sup0), "n_sup^0", 1.34, BLUE},   {FIELD(n_inf1), "n_inf^1", 1.05, BLUE},
    {FIELD(d1), "d^1", 1.22, BLUE},           {FIELD(d0), "d^0", 1.18, BROWN},
    {FIELD(d2), "d^2", 1.42, GREEN},          {FIELD(n_sup1), "n_sup^1", 1.30, GREEN},
    {FIELD(g_sup0), "g_sup^0", 1.36, GREEN},  {FIELD(g_inf2), "g_inf^2", 1.13, GREEN},
};
/* Fig. C.3's. */
static const named_curve curves_c_3[] = {
    {FIELD(c_mu), "c_m^u", 1.08, ORANGE},
    {FIELD(c_sl), "c_s^l", 1.36, ORANGE},
    {FIELD(c_su), "c_s^u", 1.14, PURPLE},
    {FIELD(c_ml), "c_m^l", 1.39, PURPLE},
};

typedef struct chart_parts {
    cm_series series[16];
    cm_chart_label labels[16];
    int n_series, n_labels;
} chart_parts;

static void add_fill(chart_parts *p, const fill *f, cm_rgb colour, float width, const char *name)
{
    p->series[p->n_series++] = (cm_series){CM_SERIES_SEGMENTS, f->x, f->y, f->n, colour, width};
    if (name && isfinite(f->centre[0]))
        p->labels[p->n_labels++] = (cm_chart_label){f->centre[0], f->centre[1], name};
}

static void add_curves(chart_parts *p, const named_curve *nc, int n, double alo, double ahi,
                       double *xy)
{
    for (int k = 0; k < n; k++) {
        double *x = xy + (size_t)2 * k * DELAY_COLUMNS, *y = x + DELAY_COLUMNS;
        curve(nc[k].field, alo, ahi, x, y);
        p->series[p->n_series++] =
            (cm_series){CM_SERIES_LINE, x, y, DELAY_COLUMNS, nc[k].colour, 2};
        cm_delay_curves c;
        cm_delay_curves_at(nc[k].label_a, &c);
        double v;
        memcpy(&v, (const char *)&c + nc[k].field, sizeof v);
        p->labels[p->n_labels++] = (cm_chart_label){nc[k].label_a, v, nc[k].name};
    }
}

/* G's edges b = a - 1 and b = 1, and the model's point. */
static void add_edges_and_point(chart_parts *p, double ahi, const delay_point *pt, double *xy)
{
    xy[0] = 1, xy[1] = 1, xy[2] = 1, xy[3] = ahi;     /* x of (1,0)-(1,1), (1,1)-(ahi,1) */
    xy[4] = 0, xy[5] = 1, xy[6] = 1, xy[7] = 1;       /* their y */
    xy[8] = 1, xy[9] = ahi;                           /* b = a - 1 */
    xy[10] = 0, xy[11] = ahi - 1;
    p->series[p->n_series++] = (cm_series){CM_SERIES_SEGMENTS, xy, xy + 4, 4, (cm_rgb)BLACK, 2};
    p->series[p->n_series++] = (cm_series){CM_SERIES_LINE, xy + 8, xy + 10, 2, (cm_rgb)BLACK, 2};
    p->series[p->n_series++] = (cm_series){CM_SERIES_POINTS, &pt->a, &pt->b, 1, (cm_rgb)RED, 9};
}

static cm_chart chart_of(const chart_outputs *out, int k, double ahi, const char *title,
                         const chart_parts *p)
{
    const int h = out->height / CHARTS;
    return (cm_chart){out->width,    k < CHARTS - 1 ? h : out->height - (CHARTS - 1) * h,
                      {1, 0},        {ahi, 1},
                      "a",           "b",
                      title,         NULL,
                      p->series,     p->n_series,
                      figure_font(), 0,
                      p->labels,     p->n_labels};
}

static bool write_png(const chart_outputs *out, const char *model, const cm_params *base,
                      const delay_point *pt, char *msg, size_t msg_size)
{
    const double a_all = 2, a_near = 1.45;
    const cm_rgb light_blue = {198, 219, 239}, light_green = {199, 233, 192},
                 light_grey = {225, 225, 225}, light_orange = {253, 208, 162},
                 light_purple = {218, 218, 235};
    enum { FILLS = 5 };
    fill f[FILLS] = {{0}}; /* G; '01' (in two charts); '012'; the two partition domains */
    double *xy = malloc(sizeof(double) * 2 * DELAY_COLUMNS * 12 + 3 * 12 * sizeof(double));
    bool ok = xy && fill_domain(in_g, 1, a_all, &f[0]) && fill_domain(in_01, 1, a_near, &f[1]) &&
              fill_domain(in_012, 1, a_near, &f[2]) && fill_domain(in_mu_sl, 1, a_near, &f[3]) &&
              fill_domain(in_su_ml, 1, a_near, &f[4]);
    if (!ok) {
        snprintf(msg, msg_size, "out of memory for the charts");
    } else {
        const float w = (float)ceil(2.0 * out->width / DELAY_COLUMNS) + 1;
        double *edges = xy + (size_t)2 * DELAY_COLUMNS * 12;
        chart_parts parts[CHARTS];
        memset(parts, 0, sizeof parts);
        add_fill(&parts[0], &f[0], light_blue, w, "G");
        add_edges_and_point(&parts[0], a_all, pt, edges);
        add_fill(&parts[1], &f[1], light_blue, w, "01");
        add_fill(&parts[1], &f[2], light_green, w, "012");
        add_curves(&parts[1], curves_4_10, 8, 1, a_near, xy);
        add_edges_and_point(&parts[1], a_near, pt, edges + 12);
        add_fill(&parts[2], &f[1], light_grey, w, NULL);
        add_fill(&parts[2], &f[3], light_orange, w, NULL);
        add_fill(&parts[2], &f[4], light_purple, w, NULL);
        add_curves(&parts[2], curves_c_3, 4, 1, a_near, xy + (size_t)16 * DELAY_COLUMNS);
        add_edges_and_point(&parts[2], a_near, pt, edges + 24);
        char params[400];
        cm_params_format(base, params, sizeof params);
        const cm_chart charts[CHARTS] = {
            chart_of(out, 0, a_all, "the stable domain G of x_(j+1) = a x_j - b x_(j-1) (4.39, "
                                    "Fig. 4.8); the model's (a, b) red", &parts[0]),
            chart_of(out, 1, a_near, "attractors on U_0, U_1 ('01') and U_0..U_2 ('012'): whole "
                                     "basic branches (App. C.3.1, Fig. 4.10)", &parts[1]),
            chart_of(out, 2, a_near, "primitive partitions in '01' (grey): c_m^u <= b <= c_s^l "
                                     "(orange), c_s^u <= b <= c_m^l (purple) (Fig. C.3)",
                     &parts[2]),
        };
        const cm_png_text texts[] = {{"Model", model}, {"Parameters", params}};
        ok = outfile_charts(out->png, charts, CHARTS, texts, 2, msg, msg_size) == CM_OK;
    }
    for (int k = 0; k < FILLS; k++)
        free(f[k].x);
    free(xy);
    return ok;
}

static bool write_csv(const char *path, char *msg, size_t msg_size)
{
    outfile o;
    if (outfile_begin(path, &o, msg, msg_size) != CM_OK)
        return false;
    fprintf(o.f, "a,n_sup0,n_inf1,n_sup1,d0,d1,d2,g_sup0,g_inf2,c_mu,c_sl,c_su,c_ml\n");
    for (int i = 0; i < DELAY_COLUMNS; i++) {
        const double a = 1 + (double)(i + 1) / DELAY_COLUMNS;
        cm_delay_curves c;
        cm_delay_curves_at(a, &c);
        fprintf(o.f,
                "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n",
                a, c.n_sup0, c.n_inf1, c.n_sup1, c.d0, c.d1, c.d2, c.g_sup0, c.g_inf2, c.c_mu,
                c.c_sl, c.c_su, c.c_ml);
    }
    return outfile_end(&o, true, msg, msg_size) == CM_OK;
}

cm_status delay_domains_write(const chart_outputs *out, const char *model, const cm_params *base,
                              const delay_point *pt, char *msg, size_t msg_size)
{
    bool ok = !out->csv || write_csv(out->csv, msg, msg_size);
    ok = ok && (!out->png || write_png(out, model, base, pt, msg, msg_size));
    return ok ? CM_OK : CM_EIO;
}

/* The bands as text: "0, 1, 2" or "none". */
static void bands_text(uint32_t bands, char *out, size_t size)
{
    size_t n = 0;
    out[0] = '\0';
    for (int k = 0; k < 31 && n < size; k++)
        if (bands >> k & 1)
            n += (size_t)snprintf(out + n, size - n, "%s%d", n ? ", " : "", k);
    if (!bands)
        snprintf(out, size, "none (the orbit leaves the positive bands)");
}

void delay_domains_report(FILE *f, const delay_point *pt)
{
    const cm_delay_domains *d = &pt->in;
    char bands[160];
    bands_text(pt->bands, bands, sizeof bands);
    fprintf(f, "a = %s, b = %s: %s the stable domain G (a > 1, b < 1, b > a - 1; 4.39)\n",
            CM_NUM(pt->a), CM_NUM(pt->b), d->stable ? "in" : "outside");
    const char *domain = d->d01    ? "domain '01': the attractor is whole basic branches on U_0, "
                                     "U_1"
                         : d->d012 ? "domain '012': the attractor is whole basic branches on "
                                     "U_0, U_1, U_2"
                                   : "in neither '01' nor '012' (App. C.3.1)";
    fprintf(f, "  %s\n", domain);
    if (d->d01)
        fprintf(f, "  primitive partition (App. C.3.2): %s\n",
                d->mu_sl   ? "c_m^u <= b <= c_s^l (C.38), (C.40)"
                : d->su_ml ? "c_s^u <= b <= c_m^l (C.41), (C.42)"
                           : "neither condition holds");
    fprintf(f, "  an orbit from (0.37, 0.61) lands on U_k for k = %s (steps 2000..22000)\n", bands);
}

void delay_domains_json(json *j, const delay_point *pt)
{
    json_bool(j, "stable", pt->in.stable);
    json_bool(j, "domain_01", pt->in.d01);
    json_bool(j, "domain_012", pt->in.d012);
    json_bool(j, "partition_mu_sl", pt->in.mu_sl);
    json_bool(j, "partition_su_ml", pt->in.su_ml);
    json_array(j, "bands");
    for (int k = 0; k < 31; k++)
        if (pt->bands >> k & 1)
            json_int(j, NULL, k);
    json_array_end(j);
}
