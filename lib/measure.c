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
    if (a->orbit_eps_hi > 0 && (!a->samples || !(a->orbit_eps_lo > 0) ||
                                a->orbit_eps_lo > a->orbit_eps_hi || a->orbit_eps_hi > 1 << 20))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "uncertainty by true orbits: give samples, and 0 < E0 <= E1 <= 2^20 "
                       "cells (%g:%g)",
                       a->orbit_eps_lo, a->orbit_eps_hi);
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

/* One file open for reading its labels over a window: given as text
 * (a->window), as the cells of another file's window (box, on the same
 * lattice), or all. Its cluster is paged within the budget. */
typedef struct source {
    cm_store *s;
    cm_store_info info;
    cm_cluster c;
    exporter x;
    bool cluster, exporting; /* what is open */
} source;

static void source_close(source *src)
{
    if (src->exporting)
        exporter_close(&src->x);
    if (src->cluster)
        project_close(src->s, &src->c);
    src->cluster = src->exporting = false;
}

static cm_status source_open(const char *file, uint64_t mem, const char *window_text,
                             const cm_box *box, const cm_lattice *same, source *src, char *msg,
                             size_t msg_size)
{
    memset(src, 0, sizeof *src);
    cm_status st = project_probe(file, msg, msg_size);
    if (st == CM_OK)
        st = project_open_cluster(file, mem, &src->s, &src->info, &src->c, msg, msg_size);
    if (st != CM_OK)
        return st;
    src->cluster = true;
    cm_box window;
    const cm_attractor_options stored = {0};
    if (same && !cm_lattice_equal(same, &src->c.lat))
        st = cm_fail(CM_EINVAL, msg, msg_size,
                     "%s has another lattice than the first file: tipping compares two files "
                     "cell by cell, solved on one lattice (the same --region and --cells)",
                     file);
    else if (window_text)
        st = export_window(&src->c, window_text, &window, msg, msg_size);
    if (st == CM_OK)
        st = exporter_open(&src->x, src->s, &src->info, &src->c,
                           box ? box : window_text ? &window : NULL, file, &stored, msg,
                           msg_size);
    src->exporting = st == CM_OK;
    if (st == CM_OK) /* the exits' fates are not needed once the nodes have labels */
        st = exporter_labels_only(&src->x, msg, msg_size);
    if (st != CM_OK)
        source_close(src);
    return st;
}

/* Rows lo .. hi - 1 (along dimension 0, counted from the window's first)
 * of the window, as a box. */
static cm_box rows_box(const cm_box *window, int64_t lo, int64_t hi)
{
    cm_box b = *window;
    b.lo[0] = window->lo[0] + lo, b.hi[0] = window->lo[0] + hi;
    return b;
}

/* The sampled states (cellmap/attractor_fates.h): each one's fate and its
 * cell's index in the window (UINT64_MAX: outside it). */
typedef struct sampled {
    uint64_t n;
    int32_t *fate; /* CM_LABEL_UNCOMPUTED once its cell proves not computed */
    uint64_t *at;
    uint64_t steps, same;
    double seconds;
} sampled;

/* log f against log eps by least squares over the fractions above 0:
 * the slope and R^2 (NAN with fewer than 2). */
static void fit_alpha(const double *eps, const double *f, int count, double *alpha, double *r2)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
    int n = 0;
    for (int k = 0; k < count; k++) {
        if (!(f[k] > 0))
            continue;
        const double x = log(eps[k]), y = log(f[k]);
        sx += x, sy += y, sxx += x * x, sxy += x * y, syy += y * y, n++;
    }
    const double vx = n * sxx - sx * sx, vy = n * syy - sy * sy, c = n * sxy - sx * sy;
    *alpha = n >= 2 && vx > 0 ? c / vx : NAN;
    *r2 = n >= 2 && vx > 0 && vy > 0 ? c * c / (vx * vy) : NAN;
}

/* The eps-uncertain fractions by true orbits: each sampled state whose
 * fate is decided, against the 2d states eps cells away along the axes
 * (all decided too, else the state is not counted). A fraction resting on
 * fewer than ORBIT_FIT_LEAST uncertain states (its relative error over
 * 1/3) is left out of the fit. */
#define ORBIT_FIT_LEAST 10
static cm_status orbit_uncertainty(const measure_args *a, const cm_model *m, const source *src,
                                   const double *state, const sampled *smp, measure_result *r,
                                   char *msg, size_t msg_size)
{
    const cm_lattice *lat = &src->c.lat;
    const int dim = lat->dim;
    const uint64_t n = a->samples, near = 2 * (uint64_t)dim;
    double *moved = malloc((size_t)(n * near * dim) * sizeof *moved);
    int32_t *fate = malloc((size_t)(n * near) * sizeof *fate);
    double fit_f[MEASURE_MAX_EPS]; /* the fractions fitted */
    cm_status st = moved && fate ? CM_OK
                                 : cm_fail(CM_ENOMEM, msg, msg_size,
                                           "out of memory for the states eps away");
    for (double eps = a->orbit_eps_lo; st == CM_OK && eps <= a->orbit_eps_hi * (1 + 1e-12) &&
                                       r->n_orbit_eps < MEASURE_MAX_EPS;
         eps *= 2) {
        for (uint64_t i = 0; i < n; i++)
            for (uint64_t j = 0; j < near; j++) {
                double *x = moved + (i * near + j) * dim;
                memcpy(x, state + i * dim, (size_t)dim * sizeof *x);
                x[j / 2] += (j % 2 ? -eps : eps) * lat->width[j / 2];
            }
        uint64_t steps = 0, counted = 0, uncertain = 0;
        st = cm_attractor_fates(m, lat, &src->x.att, moved, n * near, a->sample_steps,
                                a->threads, fate, &steps, msg, msg_size);
        for (uint64_t i = 0; st == CM_OK && i < n; i++) {
            bool decided = smp->fate[i] != CM_LABEL_OUTSIDE, differs = false;
            for (uint64_t j = 0; j < near; j++) {
                decided = decided && fate[i * near + j] != CM_LABEL_OUTSIDE;
                differs = differs || fate[i * near + j] != smp->fate[i];
            }
            counted += decided, uncertain += decided && differs;
        }
        const int k = r->n_orbit_eps++;
        r->orbit_eps[k] = eps, r->orbit_counted[k] = counted;
        r->orbit_uncertain[k] = counted ? (double)uncertain / (double)counted : NAN;
        fit_f[k] = uncertain >= ORBIT_FIT_LEAST ? r->orbit_uncertain[k] : 0;
    }
    fit_alpha(r->orbit_eps, fit_f, r->n_orbit_eps, &r->orbit_alpha, &r->orbit_alpha_r2);
    free(moved);
    free(fate);
    return st;
}

static cm_status sample_fates(const measure_args *a, const source *src, sampled *out,
                              measure_result *r, char *msg, size_t msg_size)
{
    const cm_lattice *lat = &src->c.lat;
    const cm_box *w = &src->x.window;
    const int dim = lat->dim;
    double *state = malloc((size_t)a->samples * dim * sizeof *state);
    out->n = a->samples;
    out->fate = malloc((size_t)a->samples * sizeof *out->fate);
    out->at = malloc((size_t)a->samples * sizeof *out->at);
    if (!state || !out->fate || !out->at) {
        free(state);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %llu samples",
                       (unsigned long long)a->samples);
    }
    cm_model_set set = {0};
    cm_model m;
    cm_status st = model_of_store(&src->info, &set, &m, msg, msg_size);
    if (st != CM_OK) {
        cm_model_set_close(&set);
        free(state);
        return cm_fail(st, msg, msg_size, "%s: its true orbits cannot be followed: %s", a->file,
                       msg);
    }
    const double t = cm_seconds();
    cm_sample_states(lat, w, a->seed, a->samples, state);
    st = cm_attractor_fates(&m, lat, &src->x.att, state, a->samples, a->sample_steps,
                            a->threads, out->fate, &out->steps, msg, msg_size);
    if (st == CM_OK && a->orbit_eps_hi > 0)
        st = orbit_uncertainty(a, &m, src, state, out, r, msg, msg_size);
    for (uint64_t i = 0; i < a->samples; i++) {
        int64_t cell[CM_MAX_DIM];
        const bool in = cm_lattice_cell(lat, state + i * dim, cell) && cm_box_contains(w, cell);
        out->at[i] = in ? 0 : UINT64_MAX;
        for (int d = 0; in && d < dim; d++)
            out->at[i] = out->at[i] * (uint64_t)(w->hi[d] - w->lo[d]) +
                         (uint64_t)(cell[d] - w->lo[d]);
    }
    out->seconds = cm_seconds() - t;
    cm_model_release(&m);
    cm_model_set_close(&set);
    free(state);
    return st;
}

/* How the window is read: whole when its labels (of every file) fit half
 * the budget, else in slabs of `core` rows along dimension 0 with `halo`
 * rows each side, their labels within that half (the clusters' pages
 * share the other: labels_budget, pages_budget). */
typedef struct plan {
    int64_t rows, row_cells, core, halo;
    int files;
    bool whole;
} plan;

static uint64_t labels_budget(const measure_args *a) { return a->mem / 2; }

static uint64_t pages_budget(const measure_args *a) { return a->mem / 2 / (a->to ? 2 : 1); }

static cm_status plan_of(const measure_args *a, const cm_box *window, plan *p, char *msg,
                         size_t msg_size)
{
    memset(p, 0, sizeof *p);
    p->rows = window->hi[0] - window->lo[0];
    p->row_cells = (int64_t)(cm_box_cells(window) / (uint64_t)p->rows);
    p->files = a->to ? 2 : 1;
    const double row_bytes = (double)p->row_cells * sizeof(int32_t) * p->files;
    const double budget = (double)labels_budget(a);
    p->whole = row_bytes * (double)p->rows <= budget;
    if (p->whole) {
        p->core = p->rows;
        return CM_OK;
    }
    for (int k = 0; k < a->n_box; k++)
        p->halo = a->box[k] - 1 > p->halo ? a->box[k] - 1 : p->halo;
    p->halo = a->eps_hi > p->halo ? a->eps_hi : p->halo;
    p->halo = a->wada_radius > p->halo ? a->wada_radius : p->halo;
    p->core = (int64_t)(budget / row_bytes) - 2 * p->halo;
    if (p->core < 1)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a slab of the window (a row of %lld cells and the %lld rows each side "
                       "the measures look at) needs %.1f MiB of labels, over half the budget "
                       "of %.1f MiB: raise the budget, or measure a narrower window",
                       (long long)p->row_cells, (long long)p->halo,
                       row_bytes * (double)(1 + 2 * p->halo) / 1048576.0,
                       (double)a->mem / 1048576.0);
    p->core = p->core < p->rows ? p->core : p->rows;
    return CM_OK;
}

/* ---- the shares ---- */

/* The k-th label in report order: the attractors 1 .. hi, then the
 * diverged (0) and outside (-2) cells; k in 0 .. hi + 1. */
static int32_t ordered_label(int k, int32_t hi)
{
    return k < hi ? k + 1 : k == hi ? CM_LABEL_DIVERGED : CM_LABEL_OUTSIDE;
}

/* What the first pass counts over the window's cells (label - lo
 * indices, lo = CM_LABEL_OUTSIDE). */
typedef struct tallies {
    int32_t hi, to_hi;       /* the two files' largest attractor ids */
    uint64_t *cells;         /* per label */
    uint64_t *fates;         /* per label: the samples' fates */
    uint64_t *tips;          /* per (label, to-label) */
} tallies;

static size_t tip_columns(const tallies *t) { return (size_t)t->to_hi + 3; }

/* Counts the labels of window cells first .. first + n - 1 (and the
 * second file's), and checks the samples whose cells are among them. */
static void tally_cells(tallies *t, const int32_t *label, const int32_t *to_label,
                        uint64_t first, uint64_t n, sampled *smp)
{
    for (uint64_t k = 0; k < n; k++) {
        const int32_t from = label[k];
        t->cells[from - CM_LABEL_OUTSIDE]++;
        if (to_label && from != CM_LABEL_UNCOMPUTED && to_label[k] != CM_LABEL_UNCOMPUTED)
            t->tips[(size_t)(from - CM_LABEL_OUTSIDE) * tip_columns(t) +
                    (size_t)(to_label[k] - CM_LABEL_OUTSIDE)]++;
    }
    for (uint64_t i = 0; i < smp->n; i++) {
        if (smp->at[i] == UINT64_MAX || smp->at[i] < first || smp->at[i] >= first + n)
            continue;
        const int32_t own = label[smp->at[i] - first];
        if (own == CM_LABEL_UNCOMPUTED)
            smp->fate[i] = CM_LABEL_UNCOMPUTED;
        else
            smp->same += smp->fate[i] == own;
    }
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
static cm_status shares_of(tallies *t, const sampled *smp, measure_result *r, char *msg,
                           size_t msg_size)
{
    const int labels = t->hi - CM_LABEL_OUTSIDE + 1;
    r->shares = calloc((size_t)labels, sizeof *r->shares);
    if (!r->shares)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %d labels", labels);
    for (uint64_t i = 0; i < smp->n; i++)
        t->fates[smp->fate[i] - CM_LABEL_OUTSIDE]++;
    r->computed = r->cells - t->cells[CM_LABEL_UNCOMPUTED - CM_LABEL_OUTSIDE];
    r->samples = smp->n, r->sample_steps = smp->steps, r->sample_same = smp->same;
    r->sampled = smp->n - t->fates[CM_LABEL_UNCOMPUTED - CM_LABEL_OUTSIDE];
    r->samples_agree = r->sampled > 0;
    int listed = 0;
    for (int k = 0; k <= t->hi + 1; k++)
        listed += t->cells[ordered_label(k, t->hi) - CM_LABEL_OUTSIDE] ||
                  t->fates[ordered_label(k, t->hi) - CM_LABEL_OUTSIDE];
    const double z = normal_quantile(0.05 / (listed ? listed : 1));
    for (int k = 0; k <= t->hi + 1; k++) {
        const int32_t label = ordered_label(k, t->hi);
        const uint64_t n = t->cells[label - CM_LABEL_OUTSIDE];
        const uint64_t m = t->fates[label - CM_LABEL_OUTSIDE];
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
    return CM_OK;
}

/* Where each basin of the first file lies in the second's, cell by cell
 * (cells computed in both). */
static cm_status tips_of(const tallies *t, measure_result *r, char *msg, size_t msg_size)
{
    const size_t nb = tip_columns(t);
    r->tips = calloc((size_t)(t->hi + 3) * nb, sizeof *r->tips);
    if (!r->tips)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the tipping table");
    for (int i = 0; i <= t->hi + 1; i++) {
        const int32_t from = ordered_label(i, t->hi);
        const uint64_t *row = t->tips + (size_t)(from - CM_LABEL_OUTSIDE) * nb;
        uint64_t total = 0;
        for (size_t j = 0; j < nb; j++)
            total += row[j];
        for (int j = 0; j <= t->to_hi + 1; j++) {
            const int32_t into = ordered_label(j, t->to_hi);
            const uint64_t n = row[into - CM_LABEL_OUTSIDE];
            if (n)
                r->tips[r->n_tips++] = (measure_tip){from, into, n, (double)n / (double)total};
        }
    }
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

/* The second pass's sums over the slabs. */
typedef struct sums {
    uint64_t uncertain[MEASURE_MAX_EPS];
    double *map_boxes; /* the first box size's boxes, C order (dimension 0 slowest) */
} sums;

/* Basin entropy on one slab g (its first row: window row `row0`),
 * summed into r, the first box size's map into s->map_boxes. */
static cm_status slab_entropy(const measure_args *a, const cm_label_grid *g, measure_result *r,
                              sums *s, char *msg, size_t msg_size)
{
    for (int k = 0; k < a->n_box; k++) {
        const int eps = a->box[k];
        const int64_t first = (g->row0 + g->core_lo + eps - 1) / eps; /* its first box row */
        cm_entropy e;
        double *map = k == 0 && s->map_boxes ? s->map_boxes + first * (g->n[1] / eps) : NULL;
        const cm_status st = cm_basin_entropy(g, eps, &e, map, msg, msg_size);
        if (st != CM_OK)
            return st;
        cm_entropy *t = &r->entropy[k];
        t->eps = eps, t->boxes += e.boxes, t->boundary += e.boundary;
        t->sum += e.sum, t->sum_boundary += e.sum_boundary;
    }
    return CM_OK;
}

static cm_status slab_uncertain(const measure_args *a, const cm_label_grid *g,
                                measure_result *r, sums *s, char *msg, size_t msg_size)
{
    int k = 0;
    for (int e = a->eps_lo; e <= a->eps_hi && k < MEASURE_MAX_EPS; e *= 2, k++) {
        double f;
        uint64_t counted, uncertain;
        const cm_status st = cm_uncertain_fraction(g, e, &f, &counted, &uncertain, msg,
                                                   msg_size);
        if (st != CM_OK)
            return st;
        r->eps[k] = e, r->counted[k] += counted, s->uncertain[k] += uncertain;
    }
    r->n_eps = k;
    return CM_OK;
}

static cm_status slab_wada(const measure_args *a, const cm_label_grid *g, measure_result *r,
                           char *msg, size_t msg_size)
{
    cm_wada w;
    const cm_status st = cm_wada_test(g, a->wada_radius, &w, msg, msg_size);
    if (st != CM_OK)
        return st;
    r->wada.basins = w.basins, r->wada.radius = w.radius, r->wada.boundary += w.boundary;
    for (int k = 0; k < w.radius; k++)
        r->wada.seeing[k] += w.seeing[k];
    return CM_OK;
}

/* The measures' results from the slabs' sums. */
static void finish_measures(const measure_args *a, const sums *s, measure_result *r)
{
    double sb[MEASURE_MAX_BOXES], sbb[MEASURE_MAX_BOXES];
    for (int k = 0; k < a->n_box; k++) {
        cm_entropy *e = &r->entropy[k];
        e->sb = e->boxes ? e->sum / (double)e->boxes : NAN;
        e->sbb = e->boundary ? e->sum_boundary / (double)e->boundary : NAN;
        sb[k] = e->sb, sbb[k] = e->sbb;
    }
    r->n_entropy = a->n_box;
    mean_spread(sb, a->n_box, &r->sb_mean, &r->sb_spread);
    mean_spread(sbb, a->n_box, &r->sbb_mean, &r->sbb_spread);
    for (int k = 0; k < r->n_eps; k++)
        r->uncertain[k] = r->counted[k] ? (double)s->uncertain[k] / (double)r->counted[k] : NAN;
    if (r->n_eps)
        fit_alpha(r->eps, r->uncertain, r->n_eps, &r->alpha, &r->alpha_r2);
    for (int k = 0; r->has_wada && k < r->wada.radius; k++)
        r->wada.fraction[k] =
            r->wada.boundary ? (double)r->wada.seeing[k] / (double)r->wada.boundary : NAN;
}

/* The entropy map for the figure, x fastest as a heat map has it. */
static cm_status map_of(const measure_args *a, const sums *s, measure_result *r, char *msg,
                        size_t msg_size)
{
    const int64_t nx = r->n[0] / a->box[0], ny = r->n[1] / a->box[0];
    r->entropy_map = malloc((size_t)(nx * ny) * sizeof *r->entropy_map);
    if (!r->entropy_map)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the entropy map");
    for (int64_t i = 0; i < nx; i++)
        for (int64_t j = 0; j < ny; j++)
            r->entropy_map[j * nx + i] = s->map_boxes[i * ny + j];
    r->map_n[0] = nx, r->map_n[1] = ny;
    return CM_OK;
}

/* ---- the passes ---- */

/* The labels of rows lo .. hi - 1 of the window, of both files. */
static cm_status read_rows(source *src, source *to, int64_t lo, int64_t hi, int32_t *label,
                           int32_t *to_label, const work_hooks *hooks, double *seconds, char *msg,
                           size_t msg_size)
{
    const double t = cm_seconds();
    const cm_box box = rows_box(&src->x.window, lo, hi);
    cm_status st = export_labels(&src->x, &box, label, hooks, msg, msg_size);
    if (st == CM_OK && to)
        st = export_labels(&to->x, &box, to_label, hooks, msg, msg_size);
    *seconds += cm_seconds() - t;
    return st;
}

/* The window's place and size in r. */
static void describe(const source *src, measure_result *r)
{
    const cm_lattice *lat = &src->c.lat;
    const cm_box *w = &src->x.window;
    snprintf(r->model, sizeof r->model, "%s", src->info.model);
    const char *names[CM_MAX_DIM];
    project_state_names(&src->info, names);
    for (int d = 0; d < 2 && d < lat->dim; d++)
        snprintf(r->names[d], sizeof r->names[d], "%s", names[d]);
    r->dim = lat->dim, r->cells = cm_box_cells(w);
    for (int d = 0; d < r->dim; d++) {
        r->n[d] = w->hi[d] - w->lo[d];
        r->lo[d] = lat->origin[d] + (double)w->lo[d] * lat->width[d];
        r->hi[d] = lat->origin[d] + (double)w->hi[d] * lat->width[d];
    }
}

/* What the request asks that the window cannot give, before any reading. */
static cm_status check_window(const measure_args *a, const measure_result *r, char *msg,
                              size_t msg_size)
{
    if (a->png && (r->dim != 2 || !a->n_box || !a->eps_hi))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the figure maps basin entropy over a 2-D window beside the uncertain "
                       "fractions: it needs a 2-D model (this one has %d dimensions), --entropy "
                       "and --uncertainty",
                       r->dim);
    for (int k = 0; k < a->n_box; k++)
        for (int d = 0; d < r->dim; d++)
            if (r->n[d] < a->box[k])
                return cm_fail(CM_EINVAL, msg, msg_size,
                               "boxes of %d cells a side do not fit the window's %lld cells "
                               "along dimension %d: choose a smaller box or a larger window",
                               a->box[k], (long long)r->n[d], d + 1);
    return CM_OK;
}

/* The first pass: every label counted, the second file's beside it, the
 * samples checked against their cells. */
static cm_status count_pass(source *src, source *to, const plan *p, int32_t *label,
                            int32_t *to_label, tallies *t, sampled *smp,
                            const work_hooks *hooks, double *reading, char *msg,
                            size_t msg_size)
{
    for (int64_t c0 = 0; c0 < p->rows; c0 += p->core) {
        const int64_t c1 = c0 + p->core < p->rows ? c0 + p->core : p->rows;
        const cm_status st = read_rows(src, to, c0, c1, label, to_label, hooks, reading, msg,
                                       msg_size);
        if (st != CM_OK)
            return st;
        tally_cells(t, label, to_label, (uint64_t)(c0 * p->row_cells),
                    (uint64_t)((c1 - c0) * p->row_cells), smp);
    }
    return CM_OK;
}

/* The second pass: each slab (with the rows around it) measured. */
static cm_status measure_pass(const measure_args *a, source *src, const plan *p,
                              int32_t *label, int32_t hi, int basins, measure_result *r,
                              sums *s, const work_hooks *hooks, char *msg, size_t msg_size)
{
    cm_status st = CM_OK;
    for (int64_t c0 = 0; st == CM_OK && c0 < p->rows; c0 += p->core) {
        const int64_t c1 = c0 + p->core < p->rows ? c0 + p->core : p->rows;
        /* a whole window is one slab without a halo, read by the first pass */
        const int64_t lo = c0 - p->halo > 0 ? c0 - p->halo : 0;
        const int64_t top = c1 + p->halo < p->rows ? c1 + p->halo : p->rows;
        if (!p->whole)
            st = read_rows(src, NULL, lo, top, label, NULL, hooks, &r->seconds_read, msg,
                           msg_size);
        cm_label_grid g = {.dim = r->dim, .label = label, .lo = CM_LABEL_OUTSIDE, .hi = hi,
                           .row0 = lo, .window_rows = p->rows, .core_lo = c0 - lo,
                           .core_hi = c1 - lo, .basins = basins};
        memcpy(g.n, r->n, sizeof g.n);
        g.n[0] = top - lo;
        double t = cm_seconds();
        if (st == CM_OK && a->n_box)
            st = slab_entropy(a, &g, r, s, msg, msg_size);
        r->seconds_entropy += cm_seconds() - t, t = cm_seconds();
        if (st == CM_OK && a->eps_hi)
            st = slab_uncertain(a, &g, r, s, msg, msg_size);
        r->seconds_uncertain += cm_seconds() - t, t = cm_seconds();
        if (st == CM_OK && r->has_wada)
            st = slab_wada(a, &g, r, msg, msg_size);
        r->seconds_wada += cm_seconds() - t;
    }
    return st;
}

/* The basins the window holds (labels of computed cells). */
static int basins_of(const tallies *t)
{
    int n = 0;
    for (int32_t l = CM_LABEL_OUTSIDE; l <= t->hi; l++)
        n += l != CM_LABEL_UNCOMPUTED && t->cells[l - CM_LABEL_OUTSIDE] > 0;
    return n;
}

typedef struct buffers {
    int32_t *label, *to_label;
    sampled smp;
    tallies t;
    sums s;
} buffers;

static cm_status buffers_alloc(const measure_args *a, const plan *p, const source *src,
                               const source *to, buffers *b, char *msg, size_t msg_size)
{
    const int64_t held = p->core + 2 * p->halo; /* whole: the rows, no halo */
    const size_t n = (size_t)((held < p->rows ? held : p->rows) * p->row_cells);
    b->label = malloc(n * sizeof *b->label);
    b->to_label = to ? malloc(n * sizeof *b->to_label) : NULL;
    b->t.hi = (int32_t)src->x.att.n, b->t.to_hi = to ? (int32_t)to->x.att.n : 0;
    b->t.cells = calloc((size_t)b->t.hi + 3, sizeof *b->t.cells);
    b->t.fates = calloc((size_t)b->t.hi + 3, sizeof *b->t.fates);
    b->t.tips = to ? calloc(((size_t)b->t.hi + 3) * tip_columns(&b->t), sizeof *b->t.tips) : NULL;
    const int64_t map_boxes = a->png ? (p->rows / a->box[0]) * (src->x.window.hi[1] -
                                                                 src->x.window.lo[1]) / a->box[0]
                                     : 0;
    b->s.map_boxes = a->png ? calloc((size_t)map_boxes + 1, sizeof *b->s.map_boxes) : NULL;
    if (!b->label || (to && (!b->to_label || !b->t.tips)) || !b->t.cells || !b->t.fates ||
        (a->png && !b->s.map_boxes))
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %zu labels", n);
    return CM_OK;
}

static void buffers_free(buffers *b)
{
    free(b->label), free(b->to_label);
    free(b->smp.fate), free(b->smp.at);
    free(b->t.cells), free(b->t.fates), free(b->t.tips);
    free(b->s.map_boxes);
}

cm_status measure_compute(const measure_args *a, const work_hooks *hooks, measure_result *r,
                          char *msg, size_t msg_size)
{
    memset(r, 0, sizeof *r);
    r->sb_mean = r->sb_spread = r->sbb_mean = r->sbb_spread = r->alpha = r->alpha_r2 = NAN;
    r->orbit_alpha = r->orbit_alpha_r2 = NAN;
    source src = {0}, to = {0};
    buffers b;
    memset(&b, 0, sizeof b);
    plan p;
    cm_status st = check_args(a, msg, msg_size);
    if (st == CM_OK)
        st = source_open(a->file, pages_budget(a), a->window, NULL, NULL, &src, msg, msg_size);
    if (st == CM_OK && a->to)
        st = source_open(a->to, pages_budget(a), NULL, &src.x.window, &src.c.lat, &to, msg,
                         msg_size);
    if (st == CM_OK) {
        describe(&src, r);
        snprintf(r->to_model, sizeof r->to_model, "%s", a->to ? to.info.model : "");
        st = check_window(a, r, msg, msg_size);
    }
    if (st == CM_OK)
        st = plan_of(a, &src.x.window, &p, msg, msg_size);
    r->slabs = st == CM_OK ? (p.rows + p.core - 1) / p.core : 0;
    if (st == CM_OK && a->samples)
        st = sample_fates(a, &src, &b.smp, r, msg, msg_size);
    r->seconds_sample = b.smp.seconds;
    if (st == CM_OK)
        st = buffers_alloc(a, &p, &src, a->to ? &to : NULL, &b, msg, msg_size);
    if (st == CM_OK)
        st = count_pass(&src, a->to ? &to : NULL, &p, b.label, b.to_label, &b.t, &b.smp, hooks,
                        &r->seconds_read, msg, msg_size);
    if (st == CM_OK)
        st = shares_of(&b.t, &b.smp, r, msg, msg_size);
    if (st == CM_OK && a->to)
        st = tips_of(&b.t, r, msg, msg_size);
    const int basins = st == CM_OK ? basins_of(&b.t) : 0;
    if (st == CM_OK && a->wada_radius && a->wada_asked && basins < 3)
        st = cm_fail(CM_EINVAL, msg, msg_size,
                     "the Wada test needs 3 or more basins, and the window has %d: with 2 "
                     "every boundary cell touches both",
                     basins);
    r->has_wada = a->wada_radius && basins >= 3;
    if (st == CM_OK && (a->n_box || a->eps_hi || r->has_wada))
        st = measure_pass(a, &src, &p, b.label, b.t.hi, basins, r, &b.s, hooks, msg, msg_size);
    if (st == CM_OK)
        finish_measures(a, &b.s, r);
    if (st == CM_OK && a->png)
        st = map_of(a, &b.s, r, msg, msg_size);
    buffers_free(&b);
    source_close(&to);
    source_close(&src);
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
    for (int k = 0; k < r->n_orbit_eps; k++)
        fprintf(o.f, "orbit_uncertain,%.17g,%.17g\n", r->orbit_eps[k], r->orbit_uncertain[k]);
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
    for (int k = 0; k < r->n_orbit_eps; k++)
        fprintf(f, "uncertain by true orbits at eps %g cells: %.5f of %llu states\n",
                r->orbit_eps[k], r->orbit_uncertain[k], (unsigned long long)r->orbit_counted[k]);
    if (r->n_orbit_eps)
        fprintf(f, "uncertainty exponent by true orbits %.4f (R^2 %.4f), boundary dimension "
                   "%.4f\n",
                r->orbit_alpha, r->orbit_alpha_r2, r->dim - r->orbit_alpha);
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
    if (r->n_orbit_eps) {
        json_nums(&j, "orbit_eps", r->orbit_eps, r->n_orbit_eps);
        json_nums(&j, "orbit_uncertain", r->orbit_uncertain, r->n_orbit_eps);
        json_num(&j, "orbit_alpha", r->orbit_alpha);
        json_num(&j, "orbit_alpha_r2", r->orbit_alpha_r2);
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
