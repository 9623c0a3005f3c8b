/* cellmap simulate: one trajectory of the dry friction oscillator, followed
 * exactly (docs/models.md 9), as a CSV of its events and as the thesis' pictures
 * of it: x(t) over the sticking region and the phase portrait (Figs. 2.3,
 * 2.9, 2.16). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/grow.h"
#include "models/friction_oscillator.h"
#include "models/params.h"
#include "src/args.h"
#include "src/figure_opts.h"
#include "src/commands.h"
#include "lib/json.h"
#include "src/outfile.h"

static const char simulate_help[] =
    "usage: cellmap simulate [--model friction-oscillator] [--param k=v[,k=v]] [--from X,V]\n"
    "                        [--t0 T0] [--periods N] [--skip P] [--csv FILE|-] [--png FILE]\n"
    "                        [--json] [--quiet] [--size WxH]\n\n"
    "A trajectory of the dry friction oscillator x'' + x = cos(Omega t) - S f(x')\n"
    "(thesis eq. (2.3)) from (x, x') = (X, V) at time T0, followed exactly\n"
    "(docs/models.md 9) up to the N-th section instant (forcing phase phi) after T0.\n"
    "Prints what the last period did, its Poincare point and Psi.\n\n"
    "  --from X,V          the initial state (default 0,0)\n"
    "  --t0 T0             the initial time (default phi/Omega, a section instant)\n"
    "  --periods N         periods to follow, 1..100000 (default 20)\n"
    "  --skip P            periods left out of the CSV, the PNG and Psi (transients)\n"
    "  --json              the summary as JSON on standard output (docs/cellmap.schema.json)\n"
    "  --quiet             no summary\n"
    "  --csv FILE          t,x,v,kind: the start, every stick, breakaway and turn, and\n"
    "                      the section point ending each period (%.17g)\n"
    "  --png FILE          top: x(t) with the sticking region |x - cos(Omega t)| < S0\n"
    "                      (blue); bottom: the phase portrait with the sticking\n"
    "                      segment and the section points (black). Slip red, stick green\n"
    "  --size WxH          image size, both panels (default 900x1000)\n";

typedef struct sim_args {
    model_opts mo;
    double from[2], t0;
    int has_t0, periods, skip;
    chart_outputs out;
} sim_args;

static int parse_args(cli *c, sim_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        int n = 0;
        if (strcmp(c->opt, "--help") == 0) {
            fputs(simulate_help, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (cli_is(c, "--from", true, &err)) {
            if (c->value && (!parse_doubles(c->value, a->from, &n, 2) || n != 2 ||
                             !isfinite(a->from[0]) || !isfinite(a->from[1])))
                err = cli_usage_error(c, "--from: '%s' is not X,V (two finite numbers)", c->value);
        } else if (cli_is(c, "--t0", true, &err)) {
            if (c->value && (!parse_double(c->value, &a->t0) || !(fabs(a->t0) <= 1e9)))
                err = cli_usage_error(c, "--t0: '%s' must be a time within +-1e9", c->value);
            a->has_t0 = 1;
        } else if (cli_take_int(c, "--periods", 1, 100000, &a->periods, &err)) {
        } else if (cli_take_int(c, "--skip", 0, 100000, &a->skip, &err)) {
        } else if (chart_outputs_take(c, &a->out, 300, 400, &err)) {
        } else {
            err = cli_stray(c);
        }
    }
    if (!err)
        err = chart_outputs_check(c, &a->out);
    if (!err && a->skip >= a->periods)
        err = cli_usage_error(c, "--skip %d leaves nothing of %d periods to show", a->skip,
                              a->periods);
    return err;
}

/* ---- following the trajectory ---- */

enum row_kind { ROW_START, ROW_STICK, ROW_BREAK, ROW_TURN, ROW_SECTION };
static const char *const row_names[] = {"start", "stick", "break", "turn", "section"};

typedef struct row {
    double t, x, v;
    int kind;
} row;

typedef struct sample {
    double t, x, v;
    int stuck;
} sample;

typedef struct track {
    const cm_fo_run *run;
    int recording;
    row *rows;
    uint64_t n_rows, cap_rows;
    sample *samples;
    uint64_t n_samples, cap_samples;
    double psi_sum; /* x at the velocity zeros while recording (Psi, thesis 2.6.1) */
    bool out_of_memory;
} track;

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
static bool follow(const cm_fo *o, const sim_args *a, cm_fo_run *r, track *tr, cm_fo_tally *last,
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

/* ---- output ---- */

static bool write_csv(const char *path, const track *tr)
{
    outfile o;
    if (!outfile_open("simulate", path, &o))
        return false;
    fprintf(o.f, "t,x,v,kind\n");
    for (size_t k = 0; k < tr->n_rows; k++) {
        const row *w = &tr->rows[k];
        fprintf(o.f, "%.17g,%.17g,%.17g,%s\n", w->t, w->x, w->v, row_names[w->kind]);
    }
    return outfile_close("simulate", &o, true);
}

typedef struct polyline {
    double *x, *y;
    size_t n;
} polyline;

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

enum { BAND_HATCHES = 240, BAND_POINTS_PER_PERIOD = 64, BAND_POINTS_MAX = 20000 };

typedef struct figure_data {
    polyline slip_t, stick_t, slip_p, stick_p;
    double *hatch_t, *hatch_x, *edge_t, *edge_hi, *edge_lo, *sec_x, *sec_v, *stop_x, *stop_v;
    size_t n_edge, n_sec, n_stop;
} figure_data;

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

static const cm_rgb slip_red = {210, 30, 30}, stick_green = {0, 150, 40},
                    band_light = {190, 210, 250}, band_blue = {40, 80, 220}, black = {0, 0, 0};

static bool write_png(const sim_args *a, const cm_model *m, const cm_fo *o, const track *tr)
{
    figure_data d;
    bool ok = figure_data_alloc(&d, tr->n_samples, tr->n_rows);
    if (!ok) {
        figure_data_free(&d);
        fprintf(stderr, "cellmap simulate: out of memory for the picture\n");
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
    ok = write_chart_png("simulate", a->out.png, charts, 2, texts, 4);
    figure_data_free(&d);
    return ok;
}

static void print_json(const sim_args *a, const cm_model *m, const cm_fo_run *r,
                       const cm_fo_tally *last, const double z_prev[2], double psi)
{
    json j;
    json_begin(&j, stdout, "simulate");
    json_model(&j, m);
    json_nums(&j, "from", a->from, 2);
    json_num(&j, "t0", a->t0);
    json_int(&j, "periods", a->periods);
    json_int(&j, "skip", a->skip);
    json_num(&j, "t_end", r->t_section);
    json_object(&j, "last_period");
    json_int(&j, "sticks", last->n_stick);
    json_int(&j, "turns", last->n_turn);
    json_int(&j, "breakaways", last->n_break);
    json_nums(&j, "x_range", (const double[2]){last->x_min, last->x_max}, 2);
    json_object_end(&j);
    json_nums(&j, "poincare_point", (const double[2]){r->st.x, r->st.v}, 2);
    if (!isnan(z_prev[0]))
        json_num(&j, "fixed_point_residual", hypot(r->st.x - z_prev[0], r->st.v - z_prev[1]));
    json_num(&j, "psi", psi);
    json_num(&j, "psi_per_period", psi / (a->periods - a->skip));
    json_end(&j);
}

static void print_summary(const sim_args *a, const cm_model *m, const cm_fo_run *r,
                          const cm_fo_tally *last, const double z_prev[2], double psi)
{
    if (a->out.json) {
        print_json(a, m, r, last, z_prev, psi);
        return;
    }
    if (a->out.quiet)
        return;
    FILE *out = report_stream(a->out.csv, a->out.png, NULL);
    fprintf(out, "followed %d periods from (x, v) = (%s, %s) at t = %s to t = %s\n", a->periods,
            CM_NUM(a->from[0]), CM_NUM(a->from[1]), CM_NUM(a->t0), CM_NUM(r->t_section));
    fprintf(out, "last period: %d sticks, %d turns, %d breakaways; x in [%.9g, %.9g]\n", last->n_stick,
           last->n_turn, last->n_break, last->x_min, last->x_max);
    fprintf(out, "Poincare point (%s, %s)", CM_NUM(r->st.x), CM_NUM(r->st.v));
    if (!isnan(z_prev[0])) {
        const double res = hypot(r->st.x - z_prev[0], r->st.v - z_prev[1]);
        fprintf(out, "; |P(z) - z| = %.3g%s", res, res < 1e-9 ? " (a fixed point of the map)" : "");
    }
    fprintf(out, "\nPsi over the %d periods shown = %.9g (%.9g per period)\n", a->periods - a->skip, psi,
           psi / (a->periods - a->skip));
}

int cmd_simulate(int argc, char **argv)
{
    cli c = {"simulate", argc, argv, 0, NULL, NULL};
    sim_args a = {
        .mo = {.name = "friction-oscillator"}, .periods = 20, .out = {.width = 900, .height = 1000}};
    const int perr = parse_args(&c, &a);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    const int werr = chart_outputs_writable(&c, &a.out);
    if (werr != EXIT_OK)
        return werr;
    cm_model m;
    const int merr = model_opts_build(&c, &a.mo, &m);
    if (merr)
        return merr;
    const cm_fo *o = cm_fo_of_model(&m);
    if (!o) {
        cm_model_release(&m);
        return cli_usage_error(&c, "model %s: simulate follows friction-oscillator only",
                               a.mo.name);
    }
    if (!a.has_t0)
        a.t0 = o->phi / o->Omega;
    cm_fo_run r;
    cm_fo_run_start(o, a.t0, a.from[0], a.from[1], &r);
    track tr = {0};
    cm_fo_tally last;
    double z_prev[2];
    bool ok = follow(o, &a, &r, &tr, &last, z_prev) && !tr.out_of_memory;
    if (tr.out_of_memory)
        fprintf(stderr, "cellmap simulate: out of memory for the trajectory\n");
    else if (!ok)
        fprintf(stderr,
                "cellmap simulate: the motion could not be followed beyond t = %s (more "
                "than %d events in a period)\n",
                CM_NUM(r.t_section + r.st.s), CM_FO_MAX_EVENTS);
    if (ok) {
        print_summary(&a, &m, &r, &last, z_prev, fabs(tr.psi_sum));
        if (a.out.csv)
            ok = write_csv(a.out.csv, &tr);
        if (ok && a.out.png)
            ok = write_png(&a, &m, o, &tr);
    }
    free(tr.rows);
    free(tr.samples);
    cm_model_release(&m);
    return ok ? EXIT_OK : EXIT_FAIL;
}
