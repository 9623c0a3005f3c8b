/* lib/series.c - time series and spectra of flows and of chip-bue
 * (lib/series.h). */
#include "lib/series.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/figure.h"
#include "lib/json.h"
#include "lib/rows.h"
#include "models/ode_flow.h"
#include "models/params.h"
#include "models/power_spectrum.h"

/* The most samples a run keeps (coordinates included). */
#define SERIES_MAX_VALUES 200000000.0

static const char bue_name[] = "chip-bue";

series_args series_defaults(void)
{
    series_args a;
    memset(&a, 0, sizeof a);
    a.time = 100, a.dt = 0.01;
    a.out.width = 900, a.out.height = 800;
    return a;
}

static bool is_bue(const model_spec *mo) { return mo->name && strcmp(mo->name, bue_name) == 0; }

bool series_model(const model_spec *mo)
{
    if (is_bue(mo))
        return true;
    const cm_model_entry *e = cm_model_set_find(&mo->set, mo->name, NULL);
    return e && strcmp(e->name, "friction-oscillator") != 0;
}

/* ---- collecting ---- */

static bool keep(series_result *r, double t, const double *x)
{
    const size_t had = r->cap;
    if (!rows_room((void **)&r->t, &r->cap, r->n, sizeof *r->t))
        return false;
    if (r->cap != had || !r->x) { /* x grows with t, dim values a sample */
        double *xs = realloc(r->x, r->cap * (size_t)r->dim * sizeof *xs);
        if (!xs)
            return false;
        r->x = xs;
    }
    r->t[r->n] = t;
    memcpy(r->x + r->n * (size_t)r->dim, x, (size_t)r->dim * sizeof *x);
    r->n++;
    return true;
}

typedef struct collect {
    series_result *r;
    double skip, first_cross, last_cross;
    bool out_of_memory;
} collect;

static int on_sample(void *user, double t, const double *x)
{
    collect *c = user;
    if (t < c->skip - 1e-9)
        return 0;
    if (!keep(c->r, t, x)) {
        c->out_of_memory = true;
        return 1;
    }
    return 0;
}

static int on_flow(void *user, int kind, double t, const double *y)
{
    if (kind == CM_FLOW_SAMPLE)
        return on_sample(user, t, y);
    collect *c = user;
    series_result *r = c->r;
    if (t < c->skip - 1e-9)
        return 0;
    if (!rows_room((void **)&r->cross, &r->cap_cross, r->n_cross, sizeof *r->cross)) {
        c->out_of_memory = true;
        return 1;
    }
    r->cross[r->n_cross++] = y[r->of];
    if (r->n_cross == 1)
        c->first_cross = t;
    c->last_cross = t;
    return 0;
}

/* ---- the request ---- */

static cm_status check_times(const series_args *a, char *msg, size_t msg_size)
{
    if (!(a->time > 0 && a->dt > 0 && a->skip >= 0 && a->skip < a->time))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the series needs time > 0, dt > 0 and 0 <= skip < time (time %g, dt %g, "
                       "skip %g)",
                       a->time, a->dt, a->skip);
    if ((a->time - a->skip) / a->dt + 1 > SERIES_MAX_VALUES / SERIES_MAX_DIM)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "%.3g samples are too many: sample less often (dt) or over less time",
                       (a->time - a->skip) / a->dt);
    if ((a->time - a->skip) / a->dt < 4)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "fewer than 4 samples after the transient: lengthen time or shorten dt");
    return CM_OK;
}

/* The coordinate a->of names among r's, into r->of. */
static cm_status find_of(const series_args *a, series_result *r, char *msg, size_t msg_size)
{
    if (!a->of)
        return CM_OK;
    char names[256] = "";
    for (int d = 0; d < r->dim; d++) {
        if (strcmp(a->of, r->names[d]) == 0) {
            r->of = d;
            return CM_OK;
        }
        snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", d ? ", " : "",
                 r->names[d]);
    }
    return cm_fail(CM_EINVAL, msg, msg_size, "--of %s: model %s's coordinates are %s", a->of,
                   r->model, names);
}

static cm_status follow_bue(const series_args *a, series_result *r, char *msg, size_t msg_size)
{
    cm_params p;
    cm_status st = cm_chip_bue_params(a->mo.texts, a->mo.n_texts, &p, msg, msg_size);
    if (st != CM_OK)
        return st;
    if (a->n_from)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "chip-bue starts from its start-up (only tau moves until the delay, "
                       "thesis 3.4.1): leave out --from");
    snprintf(r->model, sizeof r->model, "%s", bue_name);
    cm_params_format(&p, r->params, sizeof r->params);
    r->dim = 4;
    for (int d = 0; d < 4; d++)
        snprintf(r->names[d], sizeof r->names[d], "%s", cm_chip_bue_coords[d]);
    if ((st = find_of(a, r, msg, msg_size)) != CM_OK)
        return st;
    cm_chip_bue c;
    cm_dde d;
    cm_chip_bue_of(&p, &c, &d);
    collect co = {r, a->skip, 0, 0, false};
    st = cm_dde_solve(&d, 0, a->time, a->dt, on_sample, &co, NULL, msg, msg_size);
    if (co.out_of_memory)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %zu samples", r->n);
    return st;
}

static cm_status follow_flow(const series_args *a, series_result *r, char *msg, size_t msg_size)
{
    cm_model m;
    cm_status st = model_spec_build(&a->mo, &m, msg, msg_size);
    if (st != CM_OK)
        return st;
    snprintf(r->model, sizeof r->model, "%s", m.name);
    cm_params_format(&m.values, r->params, sizeof r->params);
    r->dim = cm_flow_dim(&m);
    if (!cm_model_is_flow(&m))
        st = cm_fail(CM_EINVAL, msg, msg_size,
                     "model %s is a map: simulate follows flows (chip-4d, chip-workpiece, duffing, "
                     "a plugin's flow), chip-bue and friction-oscillator; a map's orbit is "
                     "`cellmap orbit`",
                     m.name);
    else if (a->n_from && a->n_from != r->dim)
        st = cm_fail(CM_EINVAL, msg, msg_size,
                     "--from has %d value(s) but the flow of model %s has %d coordinates",
                     a->n_from, m.name, r->dim);
    for (int d = 0; d < r->dim && st == CM_OK; d++)
        snprintf(r->names[d], sizeof r->names[d], "%s", cm_flow_coord_name(&m, d));
    if (st == CM_OK)
        st = find_of(a, r, msg, msg_size);
    if (st == CM_OK && a->n_from) {
        memcpy(r->start, a->from, (size_t)r->dim * sizeof *r->start);
    } else if (st == CM_OK) {
        double centre[CM_MAX_DIM];
        st = model_spec_centre(&a->mo, m.dim, centre, msg, msg_size);
        cm_flow_lift(&m, centre, r->start);
    }
    if (st == CM_OK) {
        collect co = {r, m.flow.t0 + a->skip, 0, 0, false};
        double reached;
        const int rc = cm_flow_follow(&m, r->start, m.flow.t0, m.flow.t0 + a->time, a->dt,
                                      on_flow, &co, &reached);
        if (co.out_of_memory || rc == CM_STEP_ABORT)
            st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %zu samples", r->n);
        else if (rc != CM_STEP_OK)
            st = cm_fail(CM_EMODEL, msg, msg_size,
                         "the orbit was lost at t = %.9g (it left the world box, the field "
                         "failed or took too many steps): start elsewhere or tighten the "
                         "tolerances",
                         reached);
        if (r->n_cross >= 2)
            r->mean_return = (co.last_cross - co.first_cross) / (double)(r->n_cross - 1);
    }
    cm_model_release(&m);
    return st;
}

/* The spectrum of coordinate r->of and its summary. */
static cm_status transform(const series_args *a, series_result *r, char *msg, size_t msg_size)
{
    double *v = malloc(r->n * sizeof *v);
    r->m = r->n / 2 + 1;
    r->freq = malloc(2 * r->m * sizeof *r->freq);
    if (!v || !r->freq) {
        free(v);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the spectrum");
    }
    r->power = r->freq + r->m;
    r->lo = INFINITY, r->hi = -INFINITY, r->mean = 0;
    for (size_t i = 0; i < r->n; i++) {
        v[i] = r->x[i * (size_t)r->dim + (size_t)r->of];
        r->lo = fmin(r->lo, v[i]);
        r->hi = fmax(r->hi, v[i]);
        r->mean += v[i] / (double)r->n;
    }
    const cm_status st = cm_power_spectrum(v, r->n, a->dt, r->freq, r->power, msg, msg_size);
    free(v);
    if (st == CM_OK)
        r->n_peaks = cm_spectrum_peaks(r->power, r->m, SERIES_PEAKS, r->peaks);
    return st;
}

cm_status series_compute(const series_args *a, series_result *r, char *msg, size_t msg_size)
{
    memset(r, 0, sizeof *r);
    r->mean_return = NAN;
    cm_status st = check_times(a, msg, msg_size);
    if (st == CM_OK && !(a->time_unit >= 0 && a->fmax >= 0))
        st = cm_fail(CM_EINVAL, msg, msg_size, "the time unit and fmax must not be negative");
    if (st == CM_OK)
        st = is_bue(&a->mo) ? follow_bue(a, r, msg, msg_size) : follow_flow(a, r, msg, msg_size);
    if (st == CM_OK)
        st = transform(a, r, msg, msg_size);
    return st;
}

/* ---- writing ---- */

static cm_status write_samples(const char *path, const series_result *r, char *msg,
                               size_t msg_size)
{
    outfile o;
    cm_status st = outfile_begin(path, &o, msg, msg_size);
    if (st != CM_OK)
        return st;
    fprintf(o.f, "t");
    for (int d = 0; d < r->dim; d++)
        fprintf(o.f, ",%s", r->names[d]);
    fprintf(o.f, "\n");
    for (size_t i = 0; i < r->n; i++) {
        fprintf(o.f, "%.17g", r->t[i]);
        for (int d = 0; d < r->dim; d++)
            fprintf(o.f, ",%.17g", r->x[i * (size_t)r->dim + (size_t)d]);
        fprintf(o.f, "\n");
    }
    return outfile_end(&o, true, msg, msg_size);
}

static cm_status write_spectrum(const char *path, const series_args *a, const series_result *r,
                                char *msg, size_t msg_size)
{
    outfile o;
    cm_status st = outfile_begin(path, &o, msg, msg_size);
    if (st != CM_OK)
        return st;
    fprintf(o.f, "frequency%s,power\n", a->time_unit > 0 ? ",frequency_hz" : "");
    for (size_t k = 0; k < r->m; k++) {
        fprintf(o.f, "%.17g", r->freq[k]);
        if (a->time_unit > 0)
            fprintf(o.f, ",%.17g", r->freq[k] / a->time_unit);
        fprintf(o.f, ",%.17g\n", r->power[k]);
    }
    return outfile_end(&o, true, msg, msg_size);
}

static void pad(double *lo, double *hi)
{
    const double margin = *hi > *lo ? 0.04 * (*hi - *lo) : 0.5;
    *lo -= margin, *hi += margin;
}

static cm_status write_figure(const series_args *a, const series_result *r, char *msg,
                              size_t msg_size)
{
    const double unit = a->time_unit > 0 ? a->time_unit : 1;
    /* fmax is in Hz given the unit */
    const double top = a->fmax > 0 ? fmin(a->fmax * unit, r->freq[r->m - 1]) : r->freq[r->m - 1];
    size_t shown = 1; /* bins 1 .. shown - 1: the mean's bin 0 left out */
    while (shown < r->m && r->freq[shown] <= top)
        shown++;
    double *hist = malloc((r->n + 2 * shown) * sizeof *hist);
    if (!hist)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the figure");
    double *fx = hist + r->n, *fy = fx + shown, plo = INFINITY, phi = -INFINITY;
    for (size_t i = 0; i < r->n; i++)
        hist[i] = r->x[i * (size_t)r->dim + (size_t)r->of];
    size_t nf = 0;
    for (size_t k = 1; k < shown; k++) {
        fx[nf] = r->freq[k] / unit;
        fy[nf] = log10(fmax(r->power[k], 1e-300));
        plo = fmin(plo, fy[nf]), phi = fmax(phi, fy[nf]);
        nf++;
    }
    /* the spectrum's lowest decades are the transform's noise: show 8 */
    plo = fmax(plo, phi - 8);
    double ylo = r->lo, yhi = r->hi;
    pad(&ylo, &yhi);
    pad(&plo, &phi);
    static const cm_rgb ink = {20, 60, 160};
    const cm_series history = {CM_SERIES_LINE, r->t, hist, r->n, ink, 1};
    const cm_series spectrum = {CM_SERIES_LINE, fx, fy, nf, ink, 1};
    char title_top[128], title_bottom[256], x_bottom[64];
    /* the parameters go into the PNG's text, not the title */
    snprintf(title_top, sizeof title_top, "%s(t), %s", r->names[r->of], r->model);
    snprintf(title_bottom, sizeof title_bottom, "power spectrum of %s (Hann window)",
             r->names[r->of]);
    snprintf(x_bottom, sizeof x_bottom, "%s", a->time_unit > 0 ? "frequency [Hz]"
                                                               : "frequency [1/time unit]");
    /* the return map (x_k, x_k+1) of the crossings, as Fig. 3.6 */
    const bool returns = a->returns;
    const int panels = returns ? 3 : 2, h_panel = a->out.height / panels;
    double rlo = INFINITY, rhi = -INFINITY;
    for (size_t k = 0; returns && k < r->n_cross; k++)
        rlo = fmin(rlo, r->cross[k]), rhi = fmax(rhi, r->cross[k]);
    pad(&rlo, &rhi);
    const cm_series return_map = {CM_SERIES_POINTS, r->cross, r->cross + 1,
                                  returns ? r->n_cross - 1 : 0, ink, 3};
    char title_returns[160], x_returns[48], y_returns[48];
    snprintf(title_returns, sizeof title_returns,
             "return map of %s at the section (%zu crossings, mean return %.4g)", r->names[r->of],
             r->n_cross, r->mean_return);
    snprintf(x_returns, sizeof x_returns, "%s_k", r->names[r->of]);
    snprintf(y_returns, sizeof y_returns, "%s_k+1", r->names[r->of]);
    const cm_chart charts[3] = {
        {a->out.width, h_panel, {r->t[0], ylo}, {r->t[r->n - 1], yhi}, "t", r->names[r->of],
         title_top, NULL, &history, 1, figure_font(), 0, NULL, 0},
        {a->out.width, returns ? h_panel : a->out.height - h_panel, {nf ? fx[0] : 0, plo},
         {nf ? fx[nf - 1] : 1, phi}, x_bottom, "log10 power", title_bottom, NULL, &spectrum, 1,
         figure_font(), 0, NULL, 0},
        {a->out.width, a->out.height - 2 * h_panel, {rlo, rlo}, {rhi, rhi}, x_returns, y_returns,
         title_returns, NULL, &return_map, 1, figure_font(), 0, NULL, 0},
    };
    char times[128];
    snprintf(times, sizeof times, "to %s, shown after %s, every %s", CM_NUM(a->time),
             CM_NUM(a->skip), CM_NUM(a->dt));
    const cm_png_text texts[] = {{"Model", r->model}, {"Parameters", r->params}, {"Times", times}};
    const cm_status st = outfile_charts(a->out.png, charts, panels, texts, 3, msg, msg_size);
    free(hist);
    return st;
}

cm_status series_write(const series_args *a, const series_result *r, char *msg, size_t msg_size)
{
    cm_status st = CM_OK;
    if (a->out.png && a->returns && r->n_cross < 3)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a return map needs 3 crossings of the section after the transient, and "
                       "%s crossed it %zu times: follow it longer, or leave out --returns",
                       r->model, r->n_cross);
    if (a->out.csv)
        st = write_samples(a->out.csv, r, msg, msg_size);
    if (st == CM_OK && a->spectrum_csv)
        st = write_spectrum(a->spectrum_csv, a, r, msg, msg_size);
    if (st == CM_OK && a->out.png)
        st = write_figure(a, r, msg, msg_size);
    return st;
}

void series_report(FILE *out, const series_args *a, const series_result *r)
{
    fprintf(out, "followed %s to t = %s: %zu samples of %d coordinates from t = %s\n", r->model,
            CM_NUM(a->time), r->n, r->dim, CM_NUM(r->t[0]));
    fprintf(out, "%s in [%.9g, %.9g], mean %.9g\n", r->names[r->of], r->lo, r->hi, r->mean);
    if (r->n_cross >= 2)
        fprintf(out, "%zu section crossings, mean return time %.9g\n", r->n_cross,
                r->mean_return);
    fprintf(out, "spectrum of %s, largest peaks:", r->names[r->of]);
    for (size_t k = 0; k < r->n_peaks; k++) {
        const double f = r->freq[r->peaks[k]];
        fprintf(out, "%s %.6g", k ? "," : "", f);
        if (a->time_unit > 0)
            fprintf(out, " (%.6g Hz)", f / a->time_unit);
    }
    fprintf(out, "\n");
}

void series_json(FILE *f, const series_args *a, const series_result *r)
{
    json j;
    json_begin(&j, f, "simulate");
    json_str(&j, "model", r->model);
    json_str(&j, "params_text", r->params);
    json_num(&j, "time", a->time);
    json_num(&j, "skip", a->skip);
    json_num(&j, "dt", a->dt);
    json_uint(&j, "samples", r->n);
    json_str(&j, "of", r->names[r->of]);
    json_nums(&j, "range", (const double[2]){r->lo, r->hi}, 2);
    json_num(&j, "mean", r->mean);
    json_uint(&j, "crossings", r->n_cross);
    if (r->n_cross >= 2)
        json_num(&j, "mean_return", r->mean_return);
    json_array(&j, "peaks");
    for (size_t k = 0; k < r->n_peaks; k++) {
        json_object(&j, NULL);
        json_num(&j, "frequency", r->freq[r->peaks[k]]);
        if (a->time_unit > 0)
            json_num(&j, "frequency_hz", r->freq[r->peaks[k]] / a->time_unit);
        json_num(&j, "power", r->power[r->peaks[k]]);
        json_object_end(&j);
    }
    json_array_end(&j);
    json_end(&j);
}

void series_result_free(series_result *r)
{
    free(r->cross);
    free(r->t);
    free(r->x);
    free(r->freq);
    memset(r, 0, sizeof *r);
}
