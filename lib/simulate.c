/* lib/simulate.c - a trajectory followed and written (lib/simulate.h). */
#include "lib/simulate.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/grow.h"
#include "lib/figure.h"
#include "models/params.h"

static const char *const row_names[] = {"start", "stick", "break", "turn", "section"};

/* ---- output ---- */

typedef struct polyline {
    double *x, *y;
    size_t n;
} polyline;

enum { BAND_HATCHES = 240, BAND_POINTS_PER_PERIOD = 64, BAND_POINTS_MAX = 20000 };

typedef struct figure_data {
    polyline slip_t, stick_t, slip_p, stick_p;
    double *hatch_t, *hatch_x, *edge_t, *edge_hi, *edge_lo, *sec_x, *sec_v, *stop_x, *stop_v;
    size_t n_edge, n_sec, n_stop;
} figure_data;

static const cm_rgb slip_red = {210, 30, 30}, stick_green = {0, 150, 40},
                    band_light = {190, 210, 250}, band_blue = {40, 80, 220}, black = {0, 0, 0};


/* False only when out of memory. */
static bool add_row(track *tr, double t, double x, double v, int kind)
{
    if (cm_grow((void **)&tr->rows, &tr->cap_rows, tr->n_rows + 1, sizeof *tr->rows) != CM_OK)
        return false;
    tr->rows[tr->n_rows++] = (row){t, x, v, kind};
    return true;
}

static bool add_sample(track *tr, double t, double x, double v, int stuck)
{
    if (cm_grow((void **)&tr->samples, &tr->cap_samples, tr->n_samples + 1, sizeof *tr->samples) !=
        CM_OK)
        return false;
    tr->samples[tr->n_samples++] = (sample){t, x, v, stuck};
    return true;
}

static void on_event(void *user, const cm_fo_event *e)
{
    track *tr = user;
    if (!tr->recording)
        return;
    static const int kinds[] = {
        [CM_FO_EV_STICK] = ROW_STICK, [CM_FO_EV_BREAK] = ROW_BREAK, [CM_FO_EV_TURN] = ROW_TURN};
    const double t = tr->run->t_section + e->s;
    if (!add_row(tr, t, e->x, 0, kinds[e->kind]) ||
        !add_sample(tr, t, e->x, 0, e->mode == CM_FO_STICK))
        tr->out_of_memory = true;
}

/* Samples per period for the pictures: smooth curves, at most ~400k points. */
static int samples_per_period(int shown)
{
    const int per = 400000 / shown;
    return per < 16 ? 16 : per > 256 ? 256 : per;
}

static void record_state(track *tr, const cm_fo_run *r, int kind)
{
    const double t = r->t_section + r->st.s;
    if ((kind >= 0 && !add_row(tr, t, r->st.x, r->st.v, kind)) ||
        !add_sample(tr, t, r->st.x, r->st.v, r->st.mode == CM_FO_STICK))
        tr->out_of_memory = true;
}

/* Follows the run for the requested periods, recording those after the
 * skipped ones; *last receives the last period's tally and z_prev the
 * section point before the last one. False when the motion is lost. */
static bool simulate_follow(const cm_fo *o, const sim_args *a, cm_fo_run *r, track *tr, cm_fo_tally *last,
                   double z_prev[2])
{
    const int per = samples_per_period(a->periods - a->skip);
    tr->run = r;
    z_prev[0] = z_prev[1] = NAN;
    for (int p = 1; p <= a->periods; p++) {
        tr->recording = p > a->skip;
        if (p == a->skip + 1)
            record_state(tr, r, ROW_START);
        if (p == a->periods && r->st.s == 0) {
            z_prev[0] = r->st.x;
            z_prev[1] = r->st.v;
        }
        cm_fo_tally_start(last, r->st.x);
        for (int j = 1; j < per; j++) {
            const double s = j * o->T / per;
            if (s <= r->st.s)
                continue;
            if (!cm_fo_propagate(o, &r->st, s, last, on_event, tr))
                return false;
            if (tr->recording)
                record_state(tr, r, -1);
        }
        if (!cm_fo_run_period(o, r, last, on_event, tr))
            return false;
        if (tr->recording) {
            record_state(tr, r, ROW_SECTION);
            tr->psi_sum += last->x_zero_sum;
        }
    }
    return true;
}

static bool write_csv(const char *path, const track *tr, char *msg, size_t msg_size)
{
    outfile o;
    if (outfile_begin(path, &o, msg, msg_size) != CM_OK)
        return false;
    fprintf(o.f, "t,x,v,kind\n");
    for (size_t k = 0; k < tr->n_rows; k++) {
        const row *w = &tr->rows[k];
        fprintf(o.f, "%.17g,%.17g,%.17g,%s\n", w->t, w->x, w->v, row_names[w->kind]);
    }
    return (outfile_end(&o, true, msg, msg_size) == CM_OK);
}

static void poly_add(polyline *p, double x, double y)
{
    p->x[p->n] = x;
    p->y[p->n++] = y;
}

/* The samples where the block slips (stuck = 0) or sticks (1), as one
 * polyline broken by NaN; each piece runs up to the sample that ends it so
 * that slip and stick meet. Axes: (t, x), or (x, v) for the phase portrait. */
static void split_track(const track *tr, bool phase, int stuck, polyline *p)
{
    p->n = 0;
    for (size_t k = 0; k < tr->n_samples; k++) {
        const sample *s = &tr->samples[k];
        const bool mine = s->stuck == stuck;
        const bool ends_mine = !mine && k > 0 && tr->samples[k - 1].stuck == stuck;
        if (mine || ends_mine)
            poly_add(p, phase ? s->x : s->t, phase ? s->v : s->x);
        if (ends_mine)
            poly_add(p, NAN, NAN);
    }
}

static void widen(double lo[2], double hi[2], int axis, double v)
{
    if (v < lo[axis])
        lo[axis] = v;
    if (v > hi[axis])
        hi[axis] = v;
}

/* A margin of 4 % around the data of one axis. */
static void pad_axis(double *lo, double *hi)
{
    const double pad = *hi > *lo ? 0.04 * (*hi - *lo) : 0.5;
    *lo -= pad;
    *hi += pad;
}

static void figure_data_free(figure_data *d)
{
    double *all[] = {d->slip_t.x, d->slip_t.y,  d->stick_t.x, d->stick_t.y, d->slip_p.x,
                     d->slip_p.y, d->stick_p.x, d->stick_p.y, d->hatch_t,   d->hatch_x,
                     d->edge_t,   d->edge_hi,   d->edge_lo,   d->sec_x,     d->sec_v,
                     d->stop_x,   d->stop_v};
    for (size_t k = 0; k < sizeof all / sizeof all[0]; k++)
        free(all[k]);
}

static bool figure_data_alloc(figure_data *d, size_t n_samples, size_t n_rows)
{
    memset(d, 0, sizeof *d);
    const size_t line = 2 * n_samples + 2;
    polyline *lines[] = {&d->slip_t, &d->stick_t, &d->slip_p, &d->stick_p};
    bool ok = true;
    for (int k = 0; k < 4; k++) {
        lines[k]->x = malloc(line * sizeof(double));
        lines[k]->y = malloc(line * sizeof(double));
        ok = ok && lines[k]->x && lines[k]->y;
    }
    double **band[] = {&d->hatch_t, &d->hatch_x};
    for (int k = 0; k < 2; k++)
        ok = ok && (*band[k] = malloc(2 * BAND_HATCHES * sizeof(double)));
    double **edges[] = {&d->edge_t, &d->edge_hi, &d->edge_lo};
    for (int k = 0; k < 3; k++)
        ok = ok && (*edges[k] = malloc(BAND_POINTS_MAX * sizeof(double)));
    double **points[] = {&d->sec_x, &d->sec_v, &d->stop_x, &d->stop_v};
    for (int k = 0; k < 4; k++)
        ok = ok && (*points[k] = malloc((n_rows + 1) * sizeof(double)));
    return ok;
}

/* The sticking region |x - cos(Omega t)| < S0 over ta..tb: hatches and edges. */
static void sticking_band(const cm_fo *o, double ta, double tb, figure_data *d)
{
    for (int k = 0; k < BAND_HATCHES; k++) {
        const double t = ta + (k + 0.5) * (tb - ta) / BAND_HATCHES, c = cos(o->Omega * t);
        d->hatch_t[2 * k] = d->hatch_t[2 * k + 1] = t;
        d->hatch_x[2 * k] = c - o->S0;
        d->hatch_x[2 * k + 1] = c + o->S0;
    }
    double n = ceil((tb - ta) / o->T * BAND_POINTS_PER_PERIOD) + 1;
    d->n_edge = n > BAND_POINTS_MAX ? BAND_POINTS_MAX : (size_t)n;
    for (size_t k = 0; k < d->n_edge; k++) {
        const double t = ta + (double)k * (tb - ta) / (double)(d->n_edge - 1),
                     c = cos(o->Omega * t);
        d->edge_t[k] = t;
        d->edge_hi[k] = c + o->S0;
        d->edge_lo[k] = c - o->S0;
    }
}

static bool write_png(const sim_args *a, const cm_model *m, const cm_fo *o, const track *tr,
                        char *msg, size_t msg_size)
{
    figure_data d;
    bool ok = figure_data_alloc(&d, tr->n_samples, tr->n_rows);
    if (!ok) {
        figure_data_free(&d);
        snprintf(msg, msg_size, "out of memory for the picture");
        return false;
    }
    split_track(tr, false, 0, &d.slip_t);
    split_track(tr, false, 1, &d.stick_t);
    split_track(tr, true, 0, &d.slip_p);
    split_track(tr, true, 1, &d.stick_p);
    for (size_t k = 0; k < tr->n_rows; k++) {
        const row *w = &tr->rows[k];
        if (w->kind == ROW_SECTION) {
            d.sec_x[d.n_sec] = w->x;
            d.sec_v[d.n_sec++] = w->v;
        } else if (w->kind == ROW_STICK) {
            d.stop_x[d.n_stop] = w->x;
            d.stop_v[d.n_stop++] = 0;
        }
    }
    const double ta = tr->samples[0].t, tb = tr->samples[tr->n_samples - 1].t;
    sticking_band(o, ta, tb, &d);
    /* ranges: the trajectory and the sticking region, |x| <= 1 + S0 */
    double lo_t[2] = {ta, -1 - o->S0}, hi_t[2] = {tb, 1 + o->S0};
    double lo_p[2] = {-1 - o->S0, 0}, hi_p[2] = {1 + o->S0, 0};
    for (size_t k = 0; k < tr->n_samples; k++) {
        widen(lo_t, hi_t, 1, tr->samples[k].x);
        widen(lo_p, hi_p, 0, tr->samples[k].x);
        widen(lo_p, hi_p, 1, tr->samples[k].v);
    }
    pad_axis(&lo_t[1], &hi_t[1]);
    pad_axis(&lo_p[0], &hi_p[0]);
    pad_axis(&lo_p[1], &hi_p[1]);
    if (!(tb > ta))
        hi_t[0] = ta + o->T;
    const double stick_seg_x[2] = {-1 - o->S0, 1 + o->S0}, stick_seg_v[2] = {0, 0};
    const cm_series top[] = {
        {CM_SERIES_SEGMENTS, d.hatch_t, d.hatch_x, 2 * BAND_HATCHES, band_light, 1},
        {CM_SERIES_LINE, d.edge_t, d.edge_hi, d.n_edge, band_blue, 1},
        {CM_SERIES_LINE, d.edge_t, d.edge_lo, d.n_edge, band_blue, 1},
        {CM_SERIES_LINE, d.slip_t.x, d.slip_t.y, d.slip_t.n, slip_red, 1.5f},
        {CM_SERIES_LINE, d.stick_t.x, d.stick_t.y, d.stick_t.n, stick_green, 3},
    };
    const cm_series bottom[] = {
        {CM_SERIES_LINE, stick_seg_x, stick_seg_v, 2, band_light, 7},
        {CM_SERIES_LINE, d.slip_p.x, d.slip_p.y, d.slip_p.n, slip_red, 1.5f},
        {CM_SERIES_POINTS, d.stop_x, d.stop_v, d.n_stop, stick_green, 7},
        {CM_SERIES_POINTS, d.sec_x, d.sec_v, d.n_sec, black, 5},
    };
    char params[400], title_top[512], start[160], periods[64];
    cm_params_format(&m->values, params, sizeof params);
    snprintf(title_top, sizeof title_top, "x(t), %s %s", m->name, params);
    const int h_top = a->out.height / 2;
    const cm_chart charts[2] = {
        {a->out.width,
         h_top,
         {lo_t[0], lo_t[1]},
         {hi_t[0], hi_t[1]},
         "t",
         "x",
         title_top,
         NULL,
         top,
         5,
         figure_font(),
         0,
         NULL,
         0},
        {a->out.width,
         a->out.height - h_top,
         {lo_p[0], lo_p[1]},
         {hi_p[0], hi_p[1]},
         "x",
         "v",
         "phase portrait; slip red, stick green, section points black",
         NULL,
         bottom,
         4,
         figure_font(),
         0,
         NULL,
         0},
    };
    snprintf(start, sizeof start, "t0=%s,x=%s,v=%s", CM_NUM(a->t0), CM_NUM(a->from[0]),
             CM_NUM(a->from[1]));
    snprintf(periods, sizeof periods, "%d (the first %d not shown)", a->periods, a->skip);
    const cm_png_text texts[] = {
        {"Model", m->name}, {"Parameters", params}, {"Start", start}, {"Periods", periods}};
    ok = (outfile_charts(a->out.png, charts, 2, texts, 4, msg, msg_size) == CM_OK);
    figure_data_free(&d);
    return ok;
}

cm_status simulate_oscillator(const model_spec *mo, const char *what, cm_model *m,
                              const cm_fo **o, char *msg, size_t msg_size)
{
    const cm_status st = model_spec_build(mo, m, msg, msg_size);
    if (st != CM_OK)
        return st;
    *o = cm_fo_of_model(m);
    return *o ? CM_OK
              : cm_fail(CM_EINVAL, msg, msg_size, "model %s: %s follows friction-oscillator only",
                        mo->name, what);
}

sim_args simulate_defaults(void)
{
    return (sim_args){.mo = {.name = "friction-oscillator"}, .periods = 20,
                      .out = {.width = 900, .height = 1000}};
}

/* The request's own limits (the command checks them as it parses). */
static cm_status check_request(const sim_args *a, char *msg, size_t msg_size)
{
    if (!isfinite(a->from[0]) || !isfinite(a->from[1]))
        return cm_fail(CM_EINVAL, msg, msg_size, "the start (x, v) must be two finite numbers");
    if (a->has_t0 && !(fabs(a->t0) <= 1e9))
        return cm_fail(CM_EINVAL, msg, msg_size, "t0 must be a time within +-1e9");
    if (a->periods < 1 || a->periods > 100000 || a->skip < 0 || a->skip >= a->periods)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "periods %d, skip %d: need 1..100000 periods and fewer skipped",
                       a->periods, a->skip);
    return CM_OK;
}

cm_status simulate_compute(sim_args *a, sim_result *r, char *msg, size_t msg_size)
{
    *r = (sim_result){0};
    cm_status st = check_request(a, msg, msg_size);
    if (st == CM_OK)
        st = simulate_oscillator(&a->mo, "simulate", &r->m, &r->o, msg, msg_size);
    if (st != CM_OK)
        return st;
    if (!a->has_t0)
        a->t0 = r->o->phi / r->o->Omega;
    cm_fo_run_start(r->o, a->t0, a->from[0], a->from[1], &r->r);
    const bool followed = simulate_follow(r->o, a, &r->r, &r->tr, &r->last, r->z_prev);
    if (r->tr.out_of_memory)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the trajectory");
    if (!followed)
        return cm_fail(CM_EIO, msg, msg_size,
                       "the motion could not be followed beyond t = %s (more than %d events in a "
                       "period)",
                       CM_NUM(r->r.t_section + r->r.st.s), CM_FO_MAX_EVENTS);
    return CM_OK;
}

cm_status simulate_write(const sim_args *a, const sim_result *r, char *msg, size_t msg_size)
{
    const bool ok = (!a->out.csv || write_csv(a->out.csv, &r->tr, msg, msg_size)) &&
                    (!a->out.png || write_png(a, &r->m, r->o, &r->tr, msg, msg_size));
    return ok ? CM_OK : CM_EIO;
}

void simulate_result_free(sim_result *r)
{
    free(r->tr.rows);
    free(r->tr.samples);
    r->tr = (track){0};
    cm_model_release(&r->m);
}
