/* Measures of a file's basins (lib/measure.h). */
#include "lib/measure.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/attractor_fates.h"
#include "cellmap/clock.h"
#include "lib/export.h"
#include "lib/figure.h"
#include "lib/json.h"
#include "lib/outfile.h"
#include "lib/project.h"

/* The Wada test's verdicts: every boundary cell sees all basins (but for
 * this share), or almost none does (isolated meeting points). */
#define WADA_ALL 0.99
#define WADA_NONE 0.05

measure_args measure_defaults(void)
{
    measure_args a;
    memset(&a, 0, sizeof a);
    a.mem = UINT64_C(256) << 20;
    a.box[0] = 3, a.box[1] = 5, a.box[2] = 7, a.box[3] = 9, a.n_box = 4;
    a.eps_lo = 1, a.eps_hi = 16;
    a.wada_radius = 5;
    a.width = 800, a.height = 1000;
    return a;
}

static cm_status check_args(const measure_args *a, char *msg, size_t msg_size)
{
    if (a->n_box < 0 || a->n_box > MEASURE_MAX_BOXES)
        return cm_fail(CM_EINVAL, msg, msg_size, "give at most %d box sizes", MEASURE_MAX_BOXES);
    for (int k = 0; k < a->n_box; k++)
        if (a->box[k] < 1 || a->box[k] > 1 << 20)
            return cm_fail(CM_EINVAL, msg, msg_size, "box size %d: give 1 .. 2^20 cells",
                           a->box[k]);
    if (a->eps_hi && (a->eps_lo < 1 || a->eps_hi < a->eps_lo || a->eps_hi > 1 << 20))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "eps %d:%d: give 1 <= E0 <= E1 <= 2^20 cells (E0 doubled up to E1)",
                       a->eps_lo, a->eps_hi);
    if (a->samples > MEASURE_MAX_SAMPLES)
        return cm_fail(CM_EINVAL, msg, msg_size, "%llu samples: give at most %llu",
                       (unsigned long long)a->samples, (unsigned long long)MEASURE_MAX_SAMPLES);
    if (a->sample_steps > PROJECT_MAX_STEPS)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a sample's budget of %llu steps: give at most %d",
                       (unsigned long long)a->sample_steps, PROJECT_MAX_STEPS);
    if (a->wada_radius < 0 || a->wada_radius > 16)
        return cm_fail(CM_EINVAL, msg, msg_size, "the Wada radius must be 1..16 (%d)",
                       a->wada_radius);
    return CM_OK;
}

/* ---- the window's labels ---- */

/* One file's labels over a window: given as text (a->window), as the
 * cells of another file's window (box, on the same lattice), or all. */
typedef struct file_labels {
    char model[64];
    char names[2][32];  /* the first two state coordinates' */
    cm_lattice lat;
    cm_box window;
    uint32_t attractors;
    int32_t *label; /* the window's cells, C order */
    int32_t *fate;  /* with samples: each sampled state's fate by its true orbit, or
                       CM_LABEL_UNCOMPUTED for a state in a cell not computed */
    uint64_t fate_steps, fate_same; /* steps taken; fates equal to their cell's label */
    double fate_seconds;
} file_labels;

/* The fates of a->samples random states of the window by their true
 * orbits (the file's model rebuilt from its records, plugins included),
 * those in cells not computed left out (CM_LABEL_UNCOMPUTED). */
static cm_status sample_fates(const measure_args *a, const exporter *x, file_labels *out,
                              char *msg, size_t msg_size)
{
    cm_model_set set = {0};
    cm_model m;
    const int dim = out->lat.dim;
    double *state = malloc((size_t)a->samples * dim * sizeof *state);
    out->fate = malloc((size_t)a->samples * sizeof *out->fate);
    if (!state || !out->fate) {
        free(state);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %llu samples",
                       (unsigned long long)a->samples);
    }
    cm_status st = model_of_store(x->info, &set, &m, msg, msg_size);
    if (st != CM_OK) {
        cm_model_set_close(&set);
        free(state);
        return cm_fail(st, msg, msg_size, "%s: its true orbits cannot be followed: %s", a->file,
                       msg);
    }
    const double t = cm_seconds();
    cm_sample_states(&out->lat, &out->window, a->seed, a->samples, state);
    st = cm_attractor_fates(&m, &out->lat, &x->att, state, a->samples, a->sample_steps,
                            a->threads, out->fate, &out->fate_steps, msg, msg_size);
    for (uint64_t i = 0; st == CM_OK && i < a->samples; i++) {
        int64_t cell[CM_MAX_DIM];
        uint64_t at = 0;
        const bool in = cm_lattice_cell(&out->lat, state + i * dim, cell) &&
                        cm_box_contains(&out->window, cell);
        for (int d = 0; in && d < dim; d++)
            at = at * (uint64_t)(out->window.hi[d] - out->window.lo[d]) +
                 (uint64_t)(cell[d] - out->window.lo[d]);
        if (!in || out->label[at] == CM_LABEL_UNCOMPUTED)
            out->fate[i] = CM_LABEL_UNCOMPUTED;
        else
            out->fate_same += out->fate[i] == out->label[at];
    }
    out->fate_seconds = cm_seconds() - t;
    cm_model_release(&m);
    cm_model_set_close(&set);
    free(state);
    return st;
}

static cm_status read_labels(const char *file, uint64_t mem, const char *window_text,
                             const cm_box *box, const cm_lattice *same, const work_hooks *hooks,
                             const measure_args *sample, file_labels *out, char *msg,
                             size_t msg_size)
{
    cm_store *s = NULL;
    cm_store_info info;
    cm_cluster c;
    cm_status st = project_probe(file, msg, msg_size);
    if (st == CM_OK)
        st = project_open_cluster(file, mem, &s, &info, &c, msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_box window;
    exporter x;
    memset(&x, 0, sizeof x);
    const cm_attractor_options stored = {0};
    if (same && !cm_lattice_equal(same, &c.lat))
        st = cm_fail(CM_EINVAL, msg, msg_size,
                     "%s has another lattice than the first file: tipping compares two files "
                     "cell by cell, solved on one lattice (the same --region and --cells)",
                     file);
    else if (window_text)
        st = export_window(&c, window_text, &window, msg, msg_size);
    if (st == CM_OK)
        st = exporter_open(&x, s, &info, &c, box ? box : window_text ? &window : NULL, file,
                           &stored, msg, msg_size);
    const uint64_t cells = st == CM_OK ? cm_box_cells(&x.window) : 0;
    if (st == CM_OK && (double)cells * sizeof *out->label > (double)mem)
        st = cm_fail(CM_EINVAL, msg, msg_size,
                     "the window's %llu cells need %.0f MiB of labels, over the budget of %.0f "
                     "MiB: measure a smaller window, or raise the budget",
                     (unsigned long long)cells, (double)cells * 4 / 1048576.0,
                     (double)mem / 1048576.0);
    if (st == CM_OK) {
        snprintf(out->model, sizeof out->model, "%s", info.model);
        const char *names[CM_MAX_DIM];
        project_state_names(&info, names);
        for (int d = 0; d < 2 && d < c.lat.dim; d++)
            snprintf(out->names[d], sizeof out->names[d], "%s", names[d]);
        out->lat = c.lat, out->window = x.window, out->attractors = x.att.n;
        if (!(out->label = malloc(cells * sizeof *out->label)))
            st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %llu labels",
                         (unsigned long long)cells);
    }
    if (st == CM_OK)
        st = export_labels(&x, out->label, hooks, msg, msg_size);
    if (st == CM_OK && sample && sample->samples)
        st = sample_fates(sample, &x, out, msg, msg_size);
    exporter_close(&x);
    project_close(s, &c);
    return st;
}

/* The grid of the file's labels, and the window in r. */
static void grid_of(const file_labels *f, measure_result *r, cm_label_grid *g)
{
    snprintf(r->model, sizeof r->model, "%s", f->model);
    memcpy(r->names, f->names, sizeof r->names);
    r->dim = g->dim = f->lat.dim, r->cells = cm_box_cells(&f->window);
    for (int d = 0; d < r->dim; d++) {
        r->n[d] = g->n[d] = f->window.hi[d] - f->window.lo[d];
        r->lo[d] = f->lat.origin[d] + (double)f->window.lo[d] * f->lat.width[d];
        r->hi[d] = f->lat.origin[d] + (double)f->window.hi[d] * f->lat.width[d];
    }
    g->label = f->label, g->lo = CM_LABEL_OUTSIDE, g->hi = (int32_t)f->attractors;
}

/* The k-th label in report order: the attractors 1 .. hi, then the
 * diverged (0) and outside (-2) cells; k in 0 .. hi + 1. */
static int32_t ordered_label(int k, int32_t hi)
{
    return k < hi ? k + 1 : k == hi ? CM_LABEL_DIVERGED : CM_LABEL_OUTSIDE;
}

/* The z whose two tails hold alpha of the standard normal distribution
 * (bisection on erfc: 1e-12 in 60 halvings). */
static double normal_quantile(double alpha)
{
    double lo = 0, hi = 40;
    for (int k = 0; k < 60; k++) {
        const double mid = (lo + hi) / 2;
        if (erfc(mid / sqrt(2.0)) > alpha)
            lo = mid;
        else
            hi = mid;
    }
    return (lo + hi) / 2;
}

/* The Wilson score interval of a share p of n samples at z. */
static void wilson(double p, double n, double z, double *lo, double *hi)
{
    const double z2n = z * z / n;
    const double centre = (p + z2n / 2) / (1 + z2n);
    const double half = z / (1 + z2n) * sqrt(p * (1 - p) / n + z2n / (4 * n));
    *lo = centre - half > 0 ? centre - half : 0;
    *hi = centre + half < 1 ? centre + half : 1;
}

/* Each label's cells and share, and with samples their fates' shares
 * with simultaneous 95 % intervals (Bonferroni: each at 1 - 0.05 / k for
 * k labels, so that a lattice whose shares are the true ones lies within
 * all of them 95 times in 100): a label is listed when cells or samples
 * have it. */
static cm_status count_shares(const cm_label_grid *g, const file_labels *f, uint64_t samples,
                              measure_result *r, char *msg, size_t msg_size)
{
    const int labels = g->hi - g->lo + 1;
    uint64_t *count = calloc(2 * (size_t)labels, sizeof *count), *fates = count + labels;
    r->shares = calloc((size_t)labels, sizeof *r->shares);
    if (!count || !r->shares) {
        free(count);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %d labels", labels);
    }
    for (uint64_t k = 0; k < r->cells; k++)
        count[g->label[k] - g->lo]++;
    for (uint64_t i = 0; i < samples; i++)
        fates[f->fate[i] - g->lo]++;
    r->computed = r->cells - count[CM_LABEL_UNCOMPUTED - g->lo];
    r->samples = samples, r->sample_steps = f->fate_steps, r->sample_same = f->fate_same;
    r->sampled = samples - fates[CM_LABEL_UNCOMPUTED - g->lo];
    r->samples_agree = r->sampled > 0;
    int listed = 0;
    for (int k = 0; k <= g->hi + 1; k++)
        listed += count[ordered_label(k, g->hi) - g->lo] || fates[ordered_label(k, g->hi) - g->lo];
    const double z = normal_quantile(0.05 / (listed ? listed : 1));
    for (int k = 0; k <= g->hi + 1; k++) {
        const int32_t label = ordered_label(k, g->hi);
        const uint64_t n = count[label - g->lo], m = fates[label - g->lo];
        if (!n && !m)
            continue;
        const double p = (double)n / (double)r->computed;
        measure_share *s = &r->shares[r->n_shares++];
        memset(s, 0, sizeof *s);
        s->label = label, s->cells = n, s->share = p;
        s->half_width = 1.96 * sqrt(p * (1 - p) / (double)r->computed);
        if (r->sampled) {
            s->sampled = m, s->sampled_share = (double)m / (double)r->sampled;
            wilson(s->sampled_share, (double)r->sampled, z, &s->sampled_lo, &s->sampled_hi);
            s->agrees = p >= s->sampled_lo && p <= s->sampled_hi;
            r->samples_agree = r->samples_agree && s->agrees;
        }
    }
    free(count);
    return CM_OK;
}

/* Where each basin of the first file lies in the second's, cell by cell
 * (cells computed in both). */
static cm_status tipping(const cm_label_grid *g, const file_labels *to, measure_result *r,
                         char *msg, size_t msg_size)
{
    const int32_t to_hi = (int32_t)to->attractors;
    const size_t na = (size_t)(g->hi - g->lo + 1), nb = (size_t)to_hi + 3;
    uint64_t *count = calloc(na * nb, sizeof *count);
    r->tips = calloc(na * nb, sizeof *r->tips);
    if (!count || !r->tips) {
        free(count);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the tipping table");
    }
    for (uint64_t k = 0; k < r->cells; k++) {
        const int32_t from = g->label[k], into = to->label[k];
        if (from != CM_LABEL_UNCOMPUTED && into != CM_LABEL_UNCOMPUTED)
            count[(size_t)(from - g->lo) * nb + (size_t)(into - CM_LABEL_OUTSIDE)]++;
    }
    for (int i = 0; i <= g->hi + 1; i++) {
        const int32_t from = ordered_label(i, g->hi);
        const uint64_t *row = count + (size_t)(from - g->lo) * nb;
        uint64_t total = 0;
        for (size_t j = 0; j < nb; j++)
            total += row[j];
        for (int j = 0; j <= to_hi + 1; j++) {
            const int32_t into = ordered_label(j, to_hi);
            const uint64_t n = row[into - CM_LABEL_OUTSIDE];
            if (n)
                r->tips[r->n_tips++] = (measure_tip){from, into, n, (double)n / (double)total};
        }
    }
    free(count);
    return CM_OK;
}

/* ---- the measures ---- */

static void mean_spread(const double *v, int n, double *mean, double *spread)
{
    double s = 0, s2 = 0;
    int k = 0;
    for (int i = 0; i < n; i++)
        if (!isnan(v[i]))
            s += v[i], s2 += v[i] * v[i], k++;
    *mean = k ? s / k : NAN;
    *spread = k ? sqrt(fmax(0, s2 / k - *mean * *mean)) : NAN;
}

/* The first box size's map for the figure, x fastest as a heat map has it
 * (the kernel's boxes are in C order, dimension 0 slowest). */
static cm_status entropy_map(const cm_label_grid *g, int box, measure_result *r, char *msg,
                             size_t msg_size)
{
    const int64_t nx = g->n[0] / box, ny = g->n[1] / box;
    double *boxes = malloc((size_t)(nx * ny) * sizeof *boxes);
    r->entropy_map = malloc((size_t)(nx * ny) * sizeof *r->entropy_map);
    cm_entropy e;
    cm_status st = boxes && r->entropy_map
                       ? cm_basin_entropy(g, box, &e, boxes, msg, msg_size)
                       : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the entropy map");
    for (int64_t i = 0; st == CM_OK && i < nx; i++)
        for (int64_t j = 0; j < ny; j++)
            r->entropy_map[j * nx + i] = boxes[i * ny + j];
    r->map_n[0] = nx, r->map_n[1] = ny;
    free(boxes);
    return st;
}

static cm_status entropies(const measure_args *a, const cm_label_grid *g, measure_result *r,
                           char *msg, size_t msg_size)
{
    double sb[MEASURE_MAX_BOXES], sbb[MEASURE_MAX_BOXES];
    for (int k = 0; k < a->n_box; k++) {
        const cm_status st = cm_basin_entropy(g, a->box[k], &r->entropy[k], NULL, msg, msg_size);
        if (st != CM_OK)
            return st;
        sb[k] = r->entropy[k].sb, sbb[k] = r->entropy[k].sbb;
        r->n_entropy++;
    }
    mean_spread(sb, a->n_box, &r->sb_mean, &r->sb_spread);
    mean_spread(sbb, a->n_box, &r->sbb_mean, &r->sbb_spread);
    return CM_OK;
}

/* log f against log eps by least squares: the slope and R^2. */
static void fit_alpha(measure_result *r)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
    int n = 0;
    for (int k = 0; k < r->n_eps; k++) {
        if (!(r->uncertain[k] > 0))
            continue;
        const double x = log(r->eps[k]), y = log(r->uncertain[k]);
        sx += x, sy += y, sxx += x * x, sxy += x * y, syy += y * y, n++;
    }
    const double vx = n * sxx - sx * sx, vy = n * syy - sy * sy, c = n * sxy - sx * sy;
    r->alpha = n >= 2 && vx > 0 ? c / vx : NAN;
    r->alpha_r2 = n >= 2 && vx > 0 && vy > 0 ? c * c / (vx * vy) : NAN;
}

static cm_status uncertain(const measure_args *a, const cm_label_grid *g, measure_result *r,
                           char *msg, size_t msg_size)
{
    for (int e = a->eps_lo; e <= a->eps_hi && r->n_eps < MEASURE_MAX_EPS; e *= 2) {
        const cm_status st = cm_uncertain_fraction(g, e, &r->uncertain[r->n_eps],
                                                   &r->counted[r->n_eps], msg, msg_size);
        if (st != CM_OK)
            return st;
        r->eps[r->n_eps++] = e;
    }
    fit_alpha(r);
    return CM_OK;
}

static cm_status wada(const measure_args *a, const cm_label_grid *g, measure_result *r,
                      char *msg, size_t msg_size)
{
    const cm_status st = cm_wada_test(g, a->wada_radius, &r->wada, msg, msg_size);
    r->has_wada = st == CM_OK;
    return st == CM_EINVAL && !a->wada_asked && r->wada.basins < 3 ? CM_OK : st;
}

cm_status measure_compute(const measure_args *a, const work_hooks *hooks, measure_result *r,
                          char *msg, size_t msg_size)
{
    memset(r, 0, sizeof *r);
    r->sb_mean = r->sb_spread = r->sbb_mean = r->sbb_spread = r->alpha = r->alpha_r2 = NAN;
    file_labels from = {0}, to = {0};
    cm_label_grid g = {0};
    double t = cm_seconds();
    cm_status st = check_args(a, msg, msg_size);
    if (st == CM_OK)
        st = read_labels(a->file, a->mem, a->window, NULL, NULL, hooks, a, &from, msg,
                         msg_size);
    if (st == CM_OK) {
        grid_of(&from, r, &g);
        st = count_shares(&g, &from, a->samples, r, msg, msg_size);
    }
    if (st == CM_OK && a->to)
        st = read_labels(a->to, a->mem, NULL, &from.window, &from.lat, hooks, NULL, &to, msg,
                         msg_size);
    if (st == CM_OK && a->to) {
        snprintf(r->to_model, sizeof r->to_model, "%s", to.model);
        st = tipping(&g, &to, r, msg, msg_size);
    }
    r->seconds_sample = from.fate_seconds;
    r->seconds_read = cm_seconds() - t - r->seconds_sample, t = cm_seconds();
    if (st == CM_OK && a->png && (g.dim != 2 || !a->n_box || !a->eps_hi))
        st = cm_fail(CM_EINVAL, msg, msg_size,
                     "the figure maps basin entropy over a 2-D window beside the uncertain "
                     "fractions: it needs a 2-D model (this one has %d dimensions), --entropy "
                     "and --uncertainty",
                     g.dim);
    if (st == CM_OK && a->n_box)
        st = entropies(a, &g, r, msg, msg_size);
    if (st == CM_OK && a->png)
        st = entropy_map(&g, a->box[0], r, msg, msg_size);
    r->seconds_entropy = cm_seconds() - t, t = cm_seconds();
    if (st == CM_OK && a->eps_hi)
        st = uncertain(a, &g, r, msg, msg_size);
    r->seconds_uncertain = cm_seconds() - t, t = cm_seconds();
    if (st == CM_OK && a->wada_radius)
        st = wada(a, &g, r, msg, msg_size);
    r->seconds_wada = cm_seconds() - t;
    free(from.label);
    free(from.fate);
    free(to.label);
    return st;
}

/* ---- writing ---- */

static const char *wada_verdict(const cm_wada *w)
{
    const double all = w->fraction[w->radius - 1];
    return all >= WADA_ALL ? "Wada" : all >= WADA_NONE ? "partially Wada" : "not Wada";
}

/* The entropy map over the uncertain fractions, log-log with the fit. */
static cm_status write_figure(const measure_args *a, const measure_result *r, char *msg,
                              size_t msg_size)
{
    double lx[MEASURE_MAX_EPS], ly[MEASURE_MAX_EPS], fit_x[2], fit_y[2];
    double ylo = INFINITY, yhi = -INFINITY, ymean = 0, xmean = 0;
    int n = 0;
    for (int k = 0; k < r->n_eps; k++)
        if (r->uncertain[k] > 0) {
            lx[n] = log10(r->eps[k]), ly[n] = log10(r->uncertain[k]);
            ylo = fmin(ylo, ly[n]), yhi = fmax(yhi, ly[n]);
            xmean += lx[n], ymean += ly[n], n++;
        }
    if (n < 2)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the figure's log-log plot needs 2 eps with uncertain cells, and %d have "
                       "any: widen --uncertainty",
                       n);
    xmean /= n, ymean /= n;
    fit_x[0] = lx[0], fit_x[1] = lx[n - 1];
    for (int k = 0; k < 2; k++) /* the fit passes through the means */
        fit_y[k] = ymean + r->alpha * (fit_x[k] - xmean);
    const double box = a->box[0], pad = 0.05 * (yhi - ylo) + 0.05;
    const double hi[2] = {r->lo[0] + (double)r->map_n[0] * box * (r->hi[0] - r->lo[0]) / r->n[0],
                          r->lo[1] + (double)r->map_n[1] * box * (r->hi[1] - r->lo[1]) / r->n[1]};
    const cm_heat heat = {(int)r->map_n[0], (int)r->map_n[1], r->entropy_map, 0,
                          "box entropy"};
    static const cm_rgb ink = {20, 60, 160}, fit_ink = {200, 60, 30};
    const cm_series series[2] = {{CM_SERIES_POINTS, lx, ly, (size_t)n, ink, 7},
                                 {CM_SERIES_LINE, fit_x, fit_y, 2, fit_ink, 2}};
    char top[160], bottom[160];
    snprintf(top, sizeof top, "%s: basin entropy in boxes of %d cells (Sb %.4f, Sbb %.4f)",
             r->model, a->box[0], r->entropy[0].sb, r->entropy[0].sbb);
    snprintf(bottom, sizeof bottom, "uncertain fraction f(eps): alpha %.4f, boundary dimension "
             "%.4f", r->alpha, r->dim - r->alpha);
    const int h_top = a->height * 3 / 5;
    const cm_chart charts[2] = {
        {a->width, h_top, {r->lo[0], r->lo[1]}, {hi[0], hi[1]}, r->names[0], r->names[1], top,
         &heat, NULL, 0,
         figure_font(), 0, NULL, 0},
        {a->width, a->height - h_top, {lx[0] - 0.1, ylo - pad}, {lx[n - 1] + 0.1, yhi + pad},
         "log10 eps [cells]", "log10 f", bottom, NULL, series, 2, figure_font(), 0, NULL, 0},
    };
    /* the model, not the file, so that a copy of a file draws the same bytes */
    const cm_png_text texts[] = {{"Model", r->model}};
    return outfile_charts(a->png, charts, 2, texts, 1, msg, msg_size);
}

cm_status measure_write(const measure_args *a, const measure_result *r, char *msg,
                        size_t msg_size)
{
    if (a->png) {
        const cm_status st = write_figure(a, r, msg, msg_size);
        if (st != CM_OK)
            return st;
    }
    if (!a->csv)
        return CM_OK;
    outfile o;
    const cm_status st = outfile_begin(a->csv, &o, msg, msg_size);
    if (st != CM_OK)
        return st;
    fprintf(o.f, "measure,scale,value\n");
    for (int k = 0; k < r->n_shares; k++)
        fprintf(o.f, "share,%d,%.17g\n", r->shares[k].label, r->shares[k].share);
    for (int k = 0; r->sampled && k < r->n_shares; k++)
        fprintf(o.f, "sampled,%d,%.17g\n", r->shares[k].label, r->shares[k].sampled_share);
    for (int k = 0; k < r->n_entropy; k++)
        fprintf(o.f, "sb,%d,%.17g\nsbb,%d,%.17g\n", r->entropy[k].eps, r->entropy[k].sb,
                r->entropy[k].eps, r->entropy[k].sbb);
    for (int k = 0; k < r->n_eps; k++)
        fprintf(o.f, "uncertain,%g,%.17g\n", r->eps[k], r->uncertain[k]);
    for (int k = 0; r->has_wada && k < r->wada.radius; k++)
        fprintf(o.f, "wada,%d,%.17g\n", k + 1, r->wada.fraction[k]);
    for (int k = 0; k < r->n_tips; k++)
        fprintf(o.f, "tipping,%d>%d,%.17g\n", r->tips[k].from, r->tips[k].to,
                r->tips[k].probability);
    return outfile_end(&o, true, msg, msg_size);
}

static const char *label_name(int32_t label, char *buf, size_t size)
{
    if (label == CM_LABEL_DIVERGED)
        return "diverged";
    if (label == CM_LABEL_OUTSIDE)
        return "outside";
    snprintf(buf, size, "attractor %d", label);
    return buf;
}

void measure_report(FILE *f, const measure_result *r)
{
    fprintf(f, "%s: %llu cells (", r->model, (unsigned long long)r->cells);
    for (int d = 0; d < r->dim; d++)
        fprintf(f, "%s%lld", d ? " x " : "", (long long)r->n[d]);
    fprintf(f, "), %llu computed\n", (unsigned long long)r->computed);
    for (int k = 0; k < r->n_shares; k++) {
        char name[32];
        const measure_share *s = &r->shares[k];
        fprintf(f, "  %-13s %12llu cells  %.4f (+- %.4f)", label_name(s->label, name, sizeof name),
                (unsigned long long)s->cells, s->share, s->half_width);
        if (r->sampled)
            fprintf(f, "  sampled %.4f [%.4f, %.4f]%s", s->sampled_share, s->sampled_lo,
                    s->sampled_hi, s->agrees ? "" : " differs");
        fputc('\n', f);
    }
    if (r->samples)
        fprintf(f, "true orbits of %llu random states (%llu in computed cells, %.1f steps "
                   "each, %.2f %% ending where their cell's label says): %s\n",
                (unsigned long long)r->samples, (unsigned long long)r->sampled,
                (double)r->sample_steps / (double)r->samples,
                r->sampled ? 100.0 * (double)r->sample_same / (double)r->sampled : 0.0,
                !r->sampled        ? "none lies in a computed cell"
                : r->samples_agree ? "every cell share lies in its interval (95 % together)"
                                   : "some cell shares lie outside their intervals (95 % "
                                     "together): the lattice is too coarse for them");
    for (int k = 0; k < r->n_entropy; k++) {
        const cm_entropy *e = &r->entropy[k];
        fprintf(f, "basin entropy, boxes of %d: Sb %.4f, Sbb %.4f (%llu of %llu boxes on a "
                   "boundary)\n",
                e->eps, e->sb, e->sbb, (unsigned long long)e->boundary,
                (unsigned long long)e->boxes);
    }
    if (r->n_entropy)
        fprintf(f, "Sb %.4f +- %.4f, Sbb %.4f +- %.4f over the boxes: %s\n", r->sb_mean,
                r->sb_spread, r->sbb_mean, r->sbb_spread,
                r->sbb_mean > log(2.0) ? "Sbb > log 2, the boundary is fractal"
                                       : "Sbb <= log 2 (says nothing of the boundary)");
    for (int k = 0; k < r->n_eps; k++)
        fprintf(f, "uncertain at eps %g cells: %.5f of %llu cells\n", r->eps[k], r->uncertain[k],
                (unsigned long long)r->counted[k]);
    if (r->n_eps)
        fprintf(f, "uncertainty exponent %.4f (R^2 %.4f), boundary dimension %.4f\n", r->alpha,
                r->alpha_r2, r->dim - r->alpha);
    if (r->has_wada) {
        fprintf(f, "Wada test: %d basins, %llu boundary cells; seeing all within r:",
                r->wada.basins, (unsigned long long)r->wada.boundary);
        for (int k = 0; k < r->wada.radius; k++)
            fprintf(f, " %d: %.4f", k + 1, r->wada.fraction[k]);
        fprintf(f, "; %s\n", wada_verdict(&r->wada));
    }
    for (int k = 0; k < r->n_tips; k++) {
        char from[32], to[32];
        const measure_tip *t = &r->tips[k];
        fprintf(f, "tipping: %-13s -> %-13s %12llu cells  %.4f\n",
                label_name(t->from, from, sizeof from), label_name(t->to, to, sizeof to),
                (unsigned long long)t->cells, t->probability);
    }
}

void measure_json(FILE *f, const measure_result *r)
{
    json j;
    json_begin(&j, f, "measure");
    json_str(&j, "model", r->model);
    json_uint(&j, "cells", r->cells);
    json_uint(&j, "computed", r->computed);
    json_array(&j, "shares");
    for (int k = 0; k < r->n_shares; k++) {
        json_object(&j, NULL);
        json_int(&j, "label", r->shares[k].label);
        json_uint(&j, "cells", r->shares[k].cells);
        json_num(&j, "share", r->shares[k].share);
        json_num(&j, "half_width", r->shares[k].half_width);
        if (r->sampled) {
            json_uint(&j, "sampled", r->shares[k].sampled);
            json_num(&j, "sampled_share", r->shares[k].sampled_share);
            json_num(&j, "sampled_lo", r->shares[k].sampled_lo);
            json_num(&j, "sampled_hi", r->shares[k].sampled_hi);
            json_bool(&j, "agrees", r->shares[k].agrees);
        }
        json_object_end(&j);
    }
    json_array_end(&j);
    if (r->samples) {
        json_uint(&j, "samples", r->samples);
        json_uint(&j, "samples_in_computed_cells", r->sampled);
        json_uint(&j, "sample_steps", r->sample_steps);
        json_uint(&j, "samples_as_labelled", r->sample_same);
        json_bool(&j, "samples_agree", r->samples_agree);
    }
    json_array(&j, "entropy");
    for (int k = 0; k < r->n_entropy; k++) {
        const cm_entropy *e = &r->entropy[k];
        json_object(&j, NULL);
        json_int(&j, "box", e->eps);
        json_uint(&j, "boxes", e->boxes);
        json_uint(&j, "boundary_boxes", e->boundary);
        json_num(&j, "sb", e->sb);
        json_num(&j, "sbb", e->sbb);
        json_object_end(&j);
    }
    json_array_end(&j);
    if (r->n_entropy) {
        json_num(&j, "sb_mean", r->sb_mean);
        json_num(&j, "sb_spread", r->sb_spread);
        json_num(&j, "sbb_mean", r->sbb_mean);
        json_num(&j, "sbb_spread", r->sbb_spread);
    }
    if (r->n_eps) {
        json_nums(&j, "eps", r->eps, r->n_eps);
        json_nums(&j, "uncertain", r->uncertain, r->n_eps);
        json_num(&j, "alpha", r->alpha);
        json_num(&j, "alpha_r2", r->alpha_r2);
    }
    if (r->has_wada) {
        json_object(&j, "wada");
        json_int(&j, "basins", r->wada.basins);
        json_uint(&j, "boundary_cells", r->wada.boundary);
        json_nums(&j, "fraction", r->wada.fraction, r->wada.radius);
        json_str(&j, "verdict", wada_verdict(&r->wada));
        json_object_end(&j);
    }
    if (r->to_model[0]) {
        json_array(&j, "tipping");
        for (int k = 0; k < r->n_tips; k++) {
            json_object(&j, NULL);
            json_int(&j, "from", r->tips[k].from);
            json_int(&j, "to", r->tips[k].to);
            json_uint(&j, "cells", r->tips[k].cells);
            json_num(&j, "probability", r->tips[k].probability);
            json_object_end(&j);
        }
        json_array_end(&j);
    }
    json_end(&j);
}

void measure_result_free(measure_result *r)
{
    free(r->shares);
    free(r->tips);
    free(r->entropy_map);
    memset(r, 0, sizeof *r);
}
