/* lib/api_analysis.c - the analysis drivers of libcellmap's experimental
 * section (cellmap/cellmap.h): each fills its lib/ driver's arguments as
 * the command's options would, checks the outputs before the work, then
 * computes and writes through the same driver as the command. */
#define CELLMAP_EXPERIMENTAL
#include "cellmap/cellmap.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cellmap/output.h"
#include "lib/amplitude.h"
#include "lib/api_models.h"
#include "lib/bifurcation.h"
#include "lib/continuation.h"
#include "lib/equilibria.h"
#include "lib/escape.h"
#include "lib/periodic.h"
#include "lib/embedding.h"
#include "lib/exponents.h"
#include "lib/measure.h"
#include "lib/series.h"
#include "models/dde_lyapunov.h"
#include "lib/horseshoe.h"
#include "lib/lyapunov.h"
#include "lib/partition.h"
#include "lib/simulate.h"
#include "lib/stability.h"
#include "lib/sweep.h"
#include "lib/sweep_report.h"

/* ---- what every driver takes ---- */

static const cm_analysis no_analysis = {0};

/* The call's model (its driver's own unless named) into *mo. */
static void model_of(const cm_analysis *a, const char *own, model_spec *mo)
{
    *mo = api_model_spec(a->set, a->model, a->params, own);
}

/* The outputs: the table and figure are checked before any work (a
 * directory, a device, a missing folder; PNG needs OSMesa), the size
 * given (at least the command's min_w x min_h) or the command's (w0 x h0). */
static cm_status outputs_of(const cm_analysis *a, int w0, int h0, int min_w, int min_h,
                            chart_outputs *out, char *msg, size_t msg_size)
{
    if ((a->width != 0 || a->height != 0) &&
        !(a->width >= min_w && a->height >= min_h && a->width <= 4096 && a->height <= 4096))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a figure of %dx%d pixels: give both sides, %dx%d..4096x4096, or 0, 0 "
                       "for the driver's size",
                       a->width, a->height, min_w, min_h);
    if (cm_output_names_stdout(a->csv) && cm_output_names_stdout(a->png))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the table and the figure both to standard output: choose one");
    *out = (chart_outputs){.csv = a->csv, .png = a->png, .quiet = true,
                           .width = a->width ? a->width : w0,
                           .height = a->height ? a->height : h0};
    const cm_status st = outfile_check_path(a->csv, false, msg, msg_size);
    return st != CM_OK ? st : outfile_check_chart(a->png, msg, msg_size);
}

/* A cm_axis as the drivers' axis named name (NULL: the axis' own), n in 1..max. */
static cm_status axis_of(const cm_axis *x, const char *name, int max, param_axis *out, char *msg,
                         size_t msg_size)
{
    name = name ? name : x->name;
    if (!name || !name[0] || strlen(name) >= sizeof out->name)
        return cm_fail(CM_EINVAL, msg, msg_size, "an axis needs a parameter's name (1..31 characters)");
    if (!(x->lo < x->hi) || !isfinite(x->lo) || !isfinite(x->hi) || x->n < 1 || x->n > max)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "axis %s: %g..%g in %d values: need finite LO < HI and 1..%d values", name,
                       x->lo, x->hi, x->n, max);
    *out = (param_axis){.lo = x->lo, .hi = x->hi, .n = x->n};
    snprintf(out->name, sizeof out->name, "%s", name);
    return CM_OK;
}

/* ---- the PD map's charts, the delay map's partition ---- */

cm_status cm_analysis_stability(const cm_analysis *a, const cm_axis *P, const cm_axis *alpha, char *msg,
                       size_t msg_size)
{
    a = a ? a : &no_analysis;
    stab_args sa = stability_defaults();
    model_of(a, sa.mo.name, &sa.mo);
    cm_status st = outputs_of(a, sa.out.width, sa.out.height, 300, 450, &sa.out, msg, msg_size);
    if (st == CM_OK && P && (sa.has_P = 1))
        st = axis_of(P, "P", 100000, &sa.P, msg, msg_size);
    if (st == CM_OK && alpha && (sa.has_alpha = 1))
        st = axis_of(alpha, "alpha", 100000, &sa.alpha, msg, msg_size);
    if (st != CM_OK)
        return st;
    stab_result r;
    st = stability_compute(&sa, &r, msg, msg_size);
    if (st == CM_OK)
        st = stability_write(&sa, &r, msg, msg_size);
    stability_result_free(&r);
    return st;
}

cm_status cm_analysis_partition(const cm_analysis *a, char *msg, size_t msg_size)
{
    a = a ? a : &no_analysis;
    part_args pa = partition_defaults();
    model_of(a, pa.mo.name, &pa.mo);
    cm_status st = outputs_of(a, pa.out.width, pa.out.height, 300, 200, &pa.out, msg, msg_size);
    part_result r;
    if (st == CM_OK)
        st = partition_compute(&pa, &r, msg, msg_size);
    return st == CM_OK ? partition_write(&pa, &r, msg, msg_size) : st;
}

/* ---- the friction oscillator ---- */

cm_status cm_analysis_amplitude(const cm_analysis *a, const cm_axis *omega, int periods, double ymax,
                       char *msg, size_t msg_size)
{
    a = a ? a : &no_analysis;
    amp_args aa = amplitude_defaults();
    model_of(a, aa.mo.name, &aa.mo);
    aa.threads = a->threads;
    aa.periods = periods ? periods : aa.periods;
    aa.ymax = ymax != 0 ? ymax : aa.ymax;
    cm_status st = outputs_of(a, aa.out.width, aa.out.height, 300, 200, &aa.out, msg, msg_size);
    if (st == CM_OK && !omega)
        st = cm_fail(CM_EINVAL, msg, msg_size, "the frequencies Omega are required");
    if (st == CM_OK && (aa.has_omega = 1))
        st = axis_of(omega, "Omega", 100000, &aa.omega, msg, msg_size);
    if (st != CM_OK)
        return st;
    amp_result r;
    st = amplitude_compute(&aa, &r, msg, msg_size);
    if (st == CM_OK)
        st = amplitude_write(&aa, &r, msg, msg_size);
    amplitude_result_free(&r);
    return st;
}

cm_simulate_options cm_simulate_defaults(void)
{
    const sim_args d = simulate_defaults();
    return (cm_simulate_options){.x = d.from[0], .v = d.from[1], .t0 = NAN, .periods = d.periods,
                                 .skip = d.skip};
}

cm_status cm_analysis_simulate(const cm_analysis *a, const cm_simulate_options *o, char *msg,
                      size_t msg_size)
{
    a = a ? a : &no_analysis;
    const cm_simulate_options d = cm_simulate_defaults();
    o = o ? o : &d;
    sim_args sa = simulate_defaults();
    model_of(a, sa.mo.name, &sa.mo);
    sa.from[0] = o->x, sa.from[1] = o->v;
    sa.has_t0 = !isnan(o->t0), sa.t0 = sa.has_t0 ? o->t0 : 0;
    sa.periods = o->periods, sa.skip = o->skip;
    cm_status st = outputs_of(a, sa.out.width, sa.out.height, 300, 400, &sa.out, msg, msg_size);
    if (st != CM_OK)
        return st;
    sim_result r;
    st = simulate_compute(&sa, &r, msg, msg_size);
    if (st == CM_OK)
        st = simulate_write(&sa, &r, msg, msg_size);
    simulate_result_free(&r);
    return st;
}

/* ---- any model: Lyapunov spectra and time series ---- */

cm_exponents_options cm_exponents_defaults(void)
{
    const exp_args d = exponents_defaults();
    return (cm_exponents_options){.time = d.o.time, .transient = d.o.transient,
                                  .renorm = d.o.renorm, .iterations = d.o.iterations,
                                  .skip = d.o.skip, .samples = d.samples, .gs = d.gs,
                                  .q_max = d.q_max};
}

cm_status cm_analysis_exponents(const cm_analysis *a, const cm_exponents_options *o,
                                cm_exponents *out, char *msg, size_t msg_size)
{
    a = a ? a : &no_analysis;
    const cm_exponents_options d = cm_exponents_defaults();
    o = o ? o : &d;
    exp_args ea = exponents_defaults();
    model_of(a, ea.mo.name, &ea.mo);
    if (o->n_from < 0 || o->n_from > CM_MAX_DIM)
        return cm_fail(CM_EINVAL, msg, msg_size, "n_from must be 0..%d", CM_MAX_DIM);
    memcpy(ea.from, o->start, sizeof ea.from);
    ea.n_from = o->n_from, ea.of_map = o->of_map != 0, ea.sync = o->sync != 0;
    ea.o = (cm_spectrum_options){.count = o->count, .transient = o->transient, .time = o->time,
                                 .renorm = o->renorm, .iterations = o->iterations,
                                 .skip = o->skip};
    ea.samples = o->samples, ea.gs = o->gs, ea.q_max = o->q_max;
    ea.csv = a->csv, ea.png = a->png;
    chart_outputs co;
    cm_status st = outputs_of(a, ea.width, ea.height, 300, 200, &co, msg, msg_size);
    if (st != CM_OK)
        return st;
    ea.width = co.width, ea.height = co.height;
    if (!(o->samples >= 1 && o->samples <= CM_FARMER_MAX_SAMPLES && o->gs >= 1 && o->q_max > 0))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "samples must be 1..%d, gs >= 1 and q_max > 0 (start from "
                       "cm_exponents_defaults())",
                       CM_FARMER_MAX_SAMPLES);
    exp_result r;
    st = exponents_compute(&ea, &r, msg, msg_size);
    if (st == CM_OK)
        st = exponents_write(&ea, &r, msg, msg_size);
    if (st == CM_OK && out) {
        *out = (cm_exponents){.count = r.s.count, .kaplan_yorke = r.s.kaplan_yorke,
                              .mean_flight = r.mean_flight};
        memcpy(out->lambda, r.s.lambda, sizeof out->lambda);
    }
    exponents_result_free(&r);
    return st;
}

cm_series_options cm_series_defaults(void)
{
    const series_args d = series_defaults();
    return (cm_series_options){.time = d.time, .skip = d.skip, .dt = d.dt};
}

cm_status cm_analysis_series(const cm_analysis *a, const cm_series_options *o, char *msg,
                             size_t msg_size)
{
    a = a ? a : &no_analysis;
    const cm_series_options d = cm_series_defaults();
    o = o ? o : &d;
    series_args sa = series_defaults();
    if (!a->model)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a time series needs a model: a flow (chip-4d, chip-workpiece, duffing, "
                       "a plugin's) or chip-bue");
    model_of(a, NULL, &sa.mo);
    if (!series_model(&sa.mo))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "model %s: a time series follows flows and chip-bue (friction-oscillator: "
                       "cm_analysis_simulate)",
                       a->model);
    if (o->n_from < 0 || o->n_from > SERIES_MAX_DIM)
        return cm_fail(CM_EINVAL, msg, msg_size, "n_from must be 0..%d", SERIES_MAX_DIM);
    memcpy(sa.from, o->start, sizeof sa.from);
    sa.n_from = o->n_from, sa.time = o->time, sa.skip = o->skip, sa.dt = o->dt, sa.of = o->of;
    sa.time_unit = o->time_unit, sa.fmax = o->fmax, sa.spectrum_csv = o->spectrum_csv;
    sa.returns = o->returns != 0;
    cm_status st = outputs_of(a, sa.out.width, sa.out.height, 300, 400, &sa.out, msg, msg_size);
    if (st == CM_OK)
        st = outfile_check_path(o->spectrum_csv, false, msg, msg_size);
    if (st != CM_OK)
        return st;
    series_result r;
    st = series_compute(&sa, &r, msg, msg_size);
    if (st == CM_OK)
        st = series_write(&sa, &r, msg, msg_size);
    series_result_free(&r);
    return st;
}

_Static_assert(sizeof((cm_embedding_options){0}.radius) / sizeof(double) == EMBED_MAX_RADII,
               "cm_embedding_options' radii are the driver's");
_Static_assert(sizeof((cm_embedding){0}.false_neighbours) / sizeof(double) == CM_EMBED_MAX_DIM,
               "cm_embedding's false neighbours are the kernel's");

cm_embedding_options cm_embedding_defaults(void)
{
    const embed_args d = embedding_defaults();
    cm_embedding_options o = {.time = d.sim.time, .dt = d.sim.dt, .values = d.extrema,
                              .lag = d.lag, .steps = d.steps, .fnn_dim = d.fnn_dim,
                              .n_radius = d.n_radius};
    memcpy(o.radius, d.radius, sizeof o.radius);
    return o;
}

/* The options as the driver's request. */
static cm_status embedding_request(const cm_analysis *a, const cm_embedding_options *o,
                                   embed_args *e, char *msg, size_t msg_size)
{
    if (o->n_from < 0 || o->n_from > SERIES_MAX_DIM || o->n_radius < 1 ||
        o->n_radius > EMBED_MAX_RADII)
        return cm_fail(CM_EINVAL, msg, msg_size, "n_from must be 0..%d and n_radius 1..%d",
                       SERIES_MAX_DIM, EMBED_MAX_RADII);
    model_of(a, exponents_defaults().mo.name, &e->sim.mo);
    memcpy(e->sim.from, o->start, sizeof e->sim.from);
    e->sim.n_from = o->n_from, e->sim.time = o->transient + o->time;
    e->sim.skip = o->transient, e->sim.dt = o->dt, e->sim.of = o->of;
    e->input = o->input, e->column = o->of, e->extrema = o->values;
    e->dim_lo = o->dim_lo, e->dim_hi = o->dim_hi ? o->dim_hi : o->dim_lo;
    e->lag = o->lag, e->steps = o->steps, e->fnn_dim = o->fnn_dim, e->theiler = o->theiler;
    memcpy(e->radius, o->radius, sizeof e->radius);
    e->n_radius = o->n_radius, e->fit_lo = o->fit_lo, e->fit_hi = o->fit_hi;
    e->time_unit = o->time_unit, e->csv = a->csv, e->png = a->png;
    chart_outputs co;
    const cm_status st = outputs_of(a, e->width, e->height, 300, 400, &co, msg, msg_size);
    e->width = co.width, e->height = co.height;
    return st;
}

cm_status cm_analysis_embedding(const cm_analysis *a, const cm_embedding_options *o,
                                cm_embedding *out, char *msg, size_t msg_size)
{
    a = a ? a : &no_analysis;
    const cm_embedding_options d = cm_embedding_defaults();
    o = o ? o : &d;
    embed_args e = embedding_defaults();
    cm_status st = embedding_request(a, o, &e, msg, msg_size);
    if (st != CM_OK)
        return st;
    embed_result r;
    st = embedding_compute(&e, &r, msg, msg_size);
    if (st == CM_OK)
        st = embedding_write(&e, &r, msg, msg_size);
    if (st == CM_OK && out) {
        *out = (cm_embedding){.n = r.n, .interval = r.interval, .embedding_dim = r.embeds,
                              .fnn_dim = r.fnn_dim, .lambda = r.lambda, .spread = r.spread,
                              .lambda_per_time = r.lambda / r.interval};
        memcpy(out->false_neighbours, r.fnn, (size_t)r.fnn_dim * sizeof *r.fnn);
    }
    embedding_result_free(&r);
    return st;
}

_Static_assert(sizeof((cm_measure_options){0}.box) / sizeof(int) == MEASURE_MAX_BOXES,
               "cm_measure_options' boxes are the driver's");

cm_measure_options cm_measure_defaults(void)
{
    const measure_args d = measure_defaults();
    cm_measure_options o = {.n_box = d.n_box, .eps_lo = d.eps_lo, .eps_hi = d.eps_hi,
                            .wada_radius = d.wada_radius, .mem = d.mem, .seed = 1};
    memcpy(o.box, d.box, sizeof o.box);
    return o;
}

cm_status cm_analysis_measure(const cm_analysis *a, const cm_measure_options *o, cm_measures *out,
                              char *msg, size_t msg_size)
{
    a = a ? a : &no_analysis;
    if (!o || !o->file)
        return cm_fail(CM_EINVAL, msg, msg_size, "which file? set the options' file");
    measure_args m = measure_defaults();
    chart_outputs co;
    cm_status st = outputs_of(a, m.width, m.height, 300, 400, &co, msg, msg_size);
    if (st != CM_OK)
        return st;
    m.png = a->png, m.width = co.width, m.height = co.height;
    m.file = o->file, m.window = o->window, m.to = o->to, m.mem = o->mem;
    memcpy(m.box, o->box, sizeof m.box);
    m.n_box = o->n_box, m.eps_lo = o->eps_lo, m.eps_hi = o->eps_hi;
    m.wada_radius = o->wada_radius, m.wada_asked = o->wada_required != 0, m.csv = a->csv;
    m.samples = o->samples, m.seed = o->seed, m.threads = o->threads;
    m.orbit_eps_lo = o->orbit_eps_lo, m.orbit_eps_hi = o->orbit_eps_hi;
    measure_result r;
    st = measure_compute(&m, NULL, &r, msg, msg_size);
    if (st == CM_OK)
        st = measure_write(&m, &r, msg, msg_size);
    if (st == CM_OK && out)
        *out = (cm_measures){r.cells, r.computed, r.sb_mean,
                             r.sbb_mean, r.alpha, r.alpha_r2, r.has_wada ? r.wada.basins : 0,
                             r.has_wada ? r.wada.fraction[r.wada.radius - 1] : NAN,
                             r.sampled, r.sample_same, r.samples_agree, r.orbit_alpha,
                             r.orbit_alpha_r2};
    measure_result_free(&r);
    return st;
}

cm_bifurcation_options cm_bifurcation_defaults(void)
{
    const bif_args d = bifurcation_defaults();
    return (cm_bifurcation_options){.runs = d.runs, .transient = d.transient, .record = d.record,
                                    .seed = d.seed};
}

cm_status cm_analysis_bifurcation(const cm_analysis *a, const cm_bifurcation_options *o, char *msg,
                         size_t msg_size)
{
    a = a ? a : &no_analysis;
    if (!o)
        return cm_fail(CM_EINVAL, msg, msg_size, "a bifurcation diagram needs its sweep");
    bif_args ba = bifurcation_defaults();
    model_of(a, ba.mo.name, &ba.mo);
    ba.runs = o->runs, ba.transient = o->transient, ba.record = o->record, ba.seed = o->seed;
    ba.threads = a->threads, ba.runs_csv = o->runs_csv, ba.has_sweep = 1;
    cm_status st = outputs_of(a, ba.out.width, ba.out.height, 300, 450, &ba.out, msg, msg_size);
    if (st == CM_OK)
        st = outfile_check_path(o->runs_csv, false, msg, msg_size);
    if (st == CM_OK)
        st = axis_of(&o->sweep, NULL, PARAM_AXIS_MAX, &ba.sweep, msg, msg_size);
    if (st != CM_OK)
        return st;
    bif_result r;
    st = bifurcation_compute(&ba, NULL, &r, msg, msg_size);
    if (st == CM_OK)
        st = bifurcation_write(&ba, &r, msg, msg_size);
    bifurcation_result_free(&r);
    return st;
}

cm_lyapunov_options cm_lyapunov_defaults(void)
{
    const lyap_args d = lyapunov_defaults();
    return (cm_lyapunov_options){.periods = d.periods, .d0 = d.d0};
}

cm_status cm_analysis_lyapunov(const cm_analysis *a, const cm_lyapunov_options *o, char *msg,
                      size_t msg_size)
{
    a = a ? a : &no_analysis;
    if (!o)
        return cm_fail(CM_EINVAL, msg, msg_size, "a Lyapunov map needs its grid");
    lyap_args la = lyapunov_defaults();
    model_of(a, la.mo.name, &la.mo);
    chart_outputs out;
    cm_status st = outputs_of(a, la.width, la.height, 200, 150, &out, msg, msg_size);
    la.csv = out.csv, la.png = out.png, la.width = out.width, la.height = out.height;
    la.periods = o->periods, la.d0 = o->d0, la.threads = a->threads, la.has_grid = 1;
    if (st == CM_OK && (o->n_from < 0 || o->n_from > CM_MAX_DIM || (o->n_from && !o->from) ||
                        o->n_curves < 0 || o->n_curves > MAX_CURVE_FILES ||
                        (o->n_curves && !o->curves)))
        st = cm_fail(CM_EINVAL, msg, msg_size,
                     "a start of at most %d coordinates and at most %d curve files",
                     CM_MAX_DIM, MAX_CURVE_FILES);
    for (int k = 0; st == CM_OK && k < 2; k++)
        st = axis_of(k ? &o->y : &o->x, NULL, PARAM_AXIS_MAX, &la.ax[k], msg, msg_size);
    if (st != CM_OK)
        return st;
    la.n_from = o->n_from;
    for (int d = 0; d < o->n_from; d++)
        la.from[d] = o->from[d];
    la.n_curves = o->n_curves;
    for (int k = 0; k < o->n_curves; k++)
        la.curves[k] = o->curves[k];
    lyap_result r;
    st = lyapunov_compute(&la, NULL, &r, msg, msg_size);
    if (st == CM_OK)
        st = lyapunov_write(&la, &r, msg, msg_size);
    lyapunov_result_free(&r);
    return st;
}

cm_continue_options cm_continue_defaults(void)
{
    return (cm_continue_options){.direction = 1};
}

/* The continuation's request from o into ca. */
static cm_status continue_args(const cm_continue_options *o, cont_args *ca, char *msg,
                               size_t msg_size)
{
    if (!o->vary || strlen(o->vary) >= sizeof ca->vary || (o->curve && strlen(o->curve) >= sizeof ca->vary2))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a parameter to vary (S, S0, Omega or phi) is required");
    if (o->n_from < 0 || o->n_from > MAX_STARTS || (o->n_from && !o->from) || o->direction < -1 ||
        o->direction > 1)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "at most %d starts, and a direction of 1 (up), -1 (down) or 0 (both)",
                       MAX_STARTS);
    snprintf(ca->vary, sizeof ca->vary, "%s", o->vary);
    ca->lo = o->lo, ca->hi = o->hi, ca->has_vary = 1;
    ca->down = o->direction < 0, ca->both = o->direction == 0, ca->switch_pd = o->switch_pd;
    ca->n_from = o->n_from;
    for (int k = 0; k < o->n_from; k++)
        memcpy(ca->from[k], o->from[k], sizeof ca->from[k]);
    ca->period = o->period, ca->max_points = o->max_points, ca->events = o->events;
    if (o->curve)
        snprintf(ca->vary2, sizeof ca->vary2, "%s", o->curve);
    ca->lo2 = o->lo2, ca->hi2 = o->hi2, ca->curves = o->curves, ca->quiet = true;
    return CM_OK;
}

cm_status cm_analysis_continue(const cm_analysis *a, const cm_continue_options *o, char *msg,
                      size_t msg_size)
{
    a = a ? a : &no_analysis;
    if (!o)
        return cm_fail(CM_EINVAL, msg, msg_size, "a continuation needs its parameter");
    cont_args ca = {0};
    model_of(a, "friction-oscillator", &ca.mo);
    cm_status st = continue_args(o, &ca, msg, msg_size);
    chart_outputs out;
    if (st == CM_OK) /* the diagram's own default size (continuation_layout) */
        st = outputs_of(a, 0, 0, 300, 300, &out, msg, msg_size);
    ca.csv = a->csv, ca.png = a->png, ca.width = a->width, ca.height = a->height;
    if (st == CM_OK)
        st = outfile_check_path(o->events, false, msg, msg_size);
    if (st == CM_OK)
        st = outfile_check_path(o->curves, false, msg, msg_size);
    if (st != CM_OK)
        return st;
    cont_result r;
    st = continuation_compute(&ca, &r, msg, msg_size);
    if (st == CM_OK)
        st = continuation_write(&ca, &r, msg, msg_size);
    continuation_result_free(&r);
    return st;
}

/* ---- the micro-chaos maps ---- */

cm_horseshoe_options cm_horseshoe_defaults(void)
{
    return (cm_horseshoe_options){.periods = horseshoe_defaults().periods};
}

cm_status cm_analysis_horseshoe(const cm_analysis *a, const cm_horseshoe_options *o, char *msg,
                       size_t msg_size)
{
    a = a ? a : &no_analysis;
    const cm_horseshoe_options d = cm_horseshoe_defaults();
    o = o ? o : &d;
    hs_args ha = horseshoe_defaults();
    model_of(a, ha.mo.name, &ha.mo);
    ha.has_m = o->m0 != 0 || o->m1 != 0, ha.m0 = o->m0, ha.m1 = o->m1;
    ha.periods = o->periods, ha.crisis = o->crisis, ha.has_sweep = o->sweep != NULL;
    cm_status st = outputs_of(a, ha.out.width, ha.out.height, 300, 200, &ha.out, msg, msg_size);
    if (st == CM_OK && o->sweep)
        st = axis_of(o->sweep, "P", 10000, &ha.sweep, msg, msg_size);
    if (st != CM_OK)
        return st;
    hs_result r;
    st = horseshoe_compute(&ha, &r, msg, msg_size);
    if (st == CM_OK)
        st = horseshoe_write(&ha, &r, msg, msg_size);
    horseshoe_result_free(&r);
    return st;
}

cm_escape_options cm_escape_defaults(void)
{
    const esc_args d = escape_defaults();
    return (cm_escape_options){.cells = d.cells, .ensemble = d.ensemble};
}

cm_status cm_analysis_escape(const cm_analysis *a, const cm_escape_options *o, char *msg, size_t msg_size)
{
    a = a ? a : &no_analysis;
    const cm_escape_options d = cm_escape_defaults();
    o = o ? o : &d;
    esc_args ea = escape_defaults();
    model_of(a, ea.mo.name, &ea.mo);
    ea.has_I0 = o->I0 != 0, ea.I0 = o->I0, ea.has_sweep = o->sweep != NULL;
    ea.cells = o->cells, ea.ensemble = o->ensemble, ea.threads = a->threads;
    cm_status st = outputs_of(a, ea.out.width, ea.out.height, 300, 200, &ea.out, msg, msg_size);
    if (st == CM_OK && o->sweep)
        st = axis_of(o->sweep, NULL, 10000, &ea.sweep, msg, msg_size);
    if (st != CM_OK)
        return st;
    esc_result r;
    st = escape_compute(&ea, &r, msg, msg_size);
    if (st == CM_OK)
        st = escape_write(&ea, &r, msg, msg_size);
    escape_result_free(&r);
    return st;
}

/* ---- flows: equilibria ---- */

/* A cm_branch as the drivers' branch_spec; extra: a setting that needs a
 * branch (a Hopf curve, a cascade) is given. */
static cm_status branch_of(const cm_branch *in, bool extra, branch_spec *b, char *msg,
                           size_t msg_size)
{
    if (!in->from || in->n_from < 1 || in->n_from > CM_MAX_DIM)
        return cm_fail(CM_EINVAL, msg, msg_size, "a start (from) of 1..%d coordinates is needed",
                       CM_MAX_DIM);
    if (in->name && (!in->name[0] || strlen(in->name) >= sizeof b->name))
        return cm_fail(CM_EINVAL, msg, msg_size, "a branch needs a parameter's name");
    if (in->max_points < 10 || in->max_points > 1000000 || in->direction < -1 ||
        in->direction > 1 || !(in->ds_max >= 0) || (!in->name && (extra || in->direction)))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a branch's settings: 10..1000000 points, a direction of -1, 0 or 1, "
                       "ds_max >= 0; a direction, a Hopf curve or a cascade only with a branch");
    memcpy(b->from, in->from, (size_t)in->n_from * sizeof *in->from);
    b->n_from = in->n_from;
    snprintf(b->name, sizeof b->name, "%s", in->name ? in->name : "");
    b->lo = in->lo, b->hi = in->hi, b->direction = in->direction, b->ds_max = in->ds_max;
    b->max_points = in->max_points;
    return CM_OK;
}

cm_equilibria_options cm_equilibria_defaults(void)
{
    const eq_args d = equilibria_defaults();
    return (cm_equilibria_options){.b = {.max_points = d.b.max_points}};
}

cm_status cm_analysis_equilibria(const cm_analysis *a, const cm_equilibria_options *o, char *msg,
                                 size_t msg_size)
{
    a = a ? a : &no_analysis;
    const cm_equilibria_options d = cm_equilibria_defaults();
    o = o ? o : &d;
    eq_args ea = equilibria_defaults();
    model_of(a, ea.mo.name, &ea.mo);
    ea.csv = a->csv;
    cm_status st = a->png ? cm_fail(CM_EINVAL, msg, msg_size,
                                    "equilibria draws no figure: give csv only")
                          : branch_of(&o->b, o->curve != NULL, &ea.b, msg, msg_size);
    if (st == CM_OK)
        st = outfile_check_path(a->csv, false, msg, msg_size);
    if (st == CM_OK && o->curve) {
        ea.has_curve = true;
        st = axis_of(o->curve, NULL, PARAM_AXIS_MAX, &ea.curve, msg, msg_size);
    }
    if (st != CM_OK)
        return st;
    eq_result r;
    st = equilibria_compute(&ea, &r, msg, msg_size);
    if (st == CM_OK)
        st = equilibria_write(&ea, &r, msg, msg_size);
    equilibria_result_free(&r);
    return st;
}

/* ---- any map: periodic orbits ---- */

cm_periodic_options cm_periodic_defaults(void)
{
    const po_args d = periodic_defaults();
    return (cm_periodic_options){.b = {.max_points = d.b.max_points}, .period = d.period};
}

cm_status cm_analysis_periodic(const cm_analysis *a, const cm_periodic_options *o, char *msg,
                               size_t msg_size)
{
    a = a ? a : &no_analysis;
    const cm_periodic_options d = cm_periodic_defaults();
    o = o ? o : &d;
    po_args pa = periodic_defaults();
    model_of(a, pa.mo.name, &pa.mo);
    pa.settle = o->settle, pa.period = o->period, pa.cascade = o->cascade, pa.csv = a->csv;
    cm_status st = a->png ? cm_fail(CM_EINVAL, msg, msg_size,
                                    "periodic draws no figure: give csv only")
                          : branch_of(&o->b, o->cascade != 0, &pa.b, msg, msg_size);
    if (st == CM_OK)
        st = outfile_check_path(a->csv, false, msg, msg_size);
    if (st != CM_OK)
        return st;
    po_result r;
    st = periodic_compute(&pa, &r, msg, msg_size);
    if (st == CM_OK)
        st = periodic_write(&pa, &r, msg, msg_size);
    periodic_result_free(&r);
    return st;
}

/* ---- any model: a parameter swept ---- */

/* The sweep's request from o into sa. */
static cm_status sweep_args_of(const cm_sweep_options *o, sweep_args *sa, char *msg,
                               size_t msg_size)
{
    if (!o->name || strlen(o->name) >= sizeof sa->name || o->n_values < 2 ||
        o->n_values > MAX_VALUES || !o->values)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a sweep needs a parameter's name and 2..%d increasing values", MAX_VALUES);
    if (o->n_cells < 0 || o->n_cells > CM_MAX_DIM || (o->n_cells && !o->cells) || o->n_near < 0 ||
        o->n_near > CM_MAX_DIM || (o->n_near && (!o->near_lo || !o->near_hi)))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "cells and the window: at most %d dimensions each", CM_MAX_DIM);
    snprintf(sa->name, sizeof sa->name, "%s", o->name);
    sa->n_values = o->n_values;
    memcpy(sa->values, o->values, (size_t)o->n_values * sizeof *o->values);
    sa->lat.region_text = o->region;
    sa->lat.n_cells = o->n_cells;
    for (int d = 0; d < o->n_cells; d++)
        sa->lat.cells[d] = o->cells[d];
    sa->n_near = o->n_near;
    for (int d = 0; d < o->n_near; d++)
        sa->near_lo[d] = o->near_lo[d], sa->near_hi[d] = o->near_hi[d];
    sa->refine = o->refine, sa->max_steps = o->max_steps;
    sa->fractions = o->fractions, sa->match = o->match_within, sa->keep = o->keep;
    sa->no_seeds = o->no_seeds != 0;
    sa->command = "libcellmap cm_analysis_sweep";
    sa->by = o->by_groups ? BY_GROUPS : BY_ATTRACTORS, sa->quiet = true;
    return CM_OK;
}

cm_status cm_analysis_sweep(const cm_analysis *a, const cm_sweep_options *o, char *msg, size_t msg_size)
{
    a = a ? a : &no_analysis;
    if (!o)
        return cm_fail(CM_EINVAL, msg, msg_size, "a sweep needs its parameter and values");
    sweep_args sa;
    memset(&sa, 0, sizeof sa);
    model_of(a, "microchaos-pd", &sa.mo);
    sa.threads = a->threads, sa.csv = a->csv, sa.png = a->png;
    sa.width = a->width, sa.height = a->height;
    cm_status st = sweep_args_of(o, &sa, msg, msg_size);
    if (st == CM_OK)
        st = outfile_check_path(a->csv, false, msg, msg_size);
    if (st == CM_OK)
        st = outfile_check_path(o->fractions, false, msg, msg_size);
    if (st == CM_OK && a->png)
        st = outfile_check_chart(a->png, msg, msg_size);
    if (st != CM_OK)
        return st;
    sweep_result r;
    st = sweep_check_setup(&sa, &r, msg, msg_size);
    if (st == CM_OK)
        st = sweep_compute(&sa, NULL, NULL, &r, msg, msg_size);
    if (st == CM_OK && sa.csv && !sweep_write_csv(&sa, r.pts, r.n, msg, msg_size))
        st = CM_EIO;
    if (st == CM_OK)
        st = sweep_write_tracked(&sa, &r, msg, msg_size);
    sweep_result_free(&r);
    return st;
}
