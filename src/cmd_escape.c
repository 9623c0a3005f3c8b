/* cellmap escape: the transient chaos of the 1-D micro-chaos map with
 * Coulomb friction (thesis 4.3, Figs. 4.5, 4.7): its repeller, the bounds
 * on the escape rate and the mean escape number from the repeller's fractal
 * dimension, the exact mean escape number, an ensemble's and cell
 * mapping's, at one parameter point or along a sweep. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/scm.h"
#include "models/params.h"
#include "models/transient_escape.h"
#include "src/args.h"
#include "src/figure_opts.h"
#include "src/commands.h"
#include "lib/json.h"
#include "src/outfile.h"
#include "src/param_grid.h"

static const char escape_help[] =
    "usage: cellmap escape [--model microchaos-1d-friction] [--param k=v[,k=v]] [--I0 W]\n"
    "                      [--sweep NAME=LO:HI:N] [--cells N] [--ensemble M] [--csv FILE|-]\n"
    "                      [--png FILE] [--size WxH] [--json] [--quiet] [--threads T]\n\n"
    "The transient chaos of the 1-D micro-chaos map with Coulomb friction (4.23)\n"
    "(thesis 4.3, docs/models.md 4.1), where it has one positive fixed point x0* in\n"
    "its repeller's interval I_rep = [x0*, a - c]. A point escapes when an iterate\n"
    "falls below x0*; its escape number is the steps that takes. The mean escape\n"
    "number over I_rep, four ways:\n"
    "  - bounds from the fractal dimension D0 of the repeller (4.28)-(4.32), the\n"
    "    escape rate kappa = (1 - D0) ln a (4.33) and N = 1/(1 - exp(-kappa)) (4.3);\n"
    "    in the border state (|F| <= 0, a <= a_crit) D0 = 0 and N = a/(a - 1) (4.35)\n"
    "  - exactly, on the Markov partition of I_rep cut by the orbit of a - c\n"
    "  - an ensemble of M points at random: its mean, and kappa from the decay of\n"
    "    the survivors\n"
    "  - cell mapping of I_rep in N cells: the mean step number of the cells that\n"
    "    leave it (the sink)\n\n"
    "  --I0 W              set c from |I0| = W (4.27), the thesis' parameter\n"
    "  --sweep NAME=LO:HI:N  a, b or I0 at the centres of N cells of LO:HI (Fig. 4.7:\n"
    "                      --param b=1.3 --I0 0.25 --sweep a=1.2:2.25:64); points\n"
    "                      outside the case of 4.3 are left out of the diagram\n"
    "  --cells N           cells of the cell mapping (default 100000; 0: none)\n"
    "  --ensemble M        points of the ensemble (default 1000000; 0: none)\n"
    "  --csv FILE|-        one line per point: the parameters, x0*, |I_rep|, |F|,\n"
    "                      a_crit, D0, kappa and N from C1 and from C2, the exact mean,\n"
    "                      the partition's intervals, the ensemble's kappa and mean,\n"
    "                      the cell mapping's mean and its cells that never leave\n"
    "  --png FILE          one point: the escape numbers over [0, 1.05 (a - c)] and\n"
    "                      I0, I_rep (Fig. 4.5); a sweep: the mean escape number\n"
    "                      against the swept parameter (Fig. 4.7): by (4.3) from the\n"
    "                      escape rates of the two dimensions and of the ensemble,\n"
    "                      exact, and by cell mapping\n"
    "  --size WxH          image size (default 1000x600)\n"
    "  --json              the summary as JSON on standard output\n"
    "  --quiet             no summary\n"
    "  --threads T         OpenMP threads over the sweep's points (default: all cores)\n";

enum { SEED = 20260412, MAX_PARTITION = 1000000 };

typedef struct esc_args {
    model_opts mo;
    param_axis sweep;
    int has_sweep, has_I0, threads;
    double I0;
    long cells, ensemble;
    chart_outputs out;
} esc_args;

/* Everything at one parameter point. */
typedef struct esc_point {
    bool valid;
    char why[200];
    cm_te t;
    double exact;    /* NaN: no finite Markov partition */
    long partition;
    cm_te_ensemble ens;
    double scm_mean; /* NaN: not computed */
    long scm_stay;   /* cells that never leave: cell-map cycles and their basins */
} esc_point;

static int parse_args(cli *c, esc_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(escape_help, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (cli_is(c, "--I0", true, &err)) {
            if (c->value && (!parse_double(c->value, &a->I0) || !(a->I0 > 0 && a->I0 < 1e6)))
                err = cli_usage_error(c, "--I0: '%s' must be a number in (0, 1e6)", c->value);
            a->has_I0 = 1;
        } else if (cli_is(c, "--sweep", true, &err)) {
            if (c->value && (!param_axis_parse(c->value, strlen(c->value), &a->sweep) ||
                             a->sweep.n > 10000 || !param_axis_even(&a->sweep) ||
                             (strcmp(a->sweep.name, "a") != 0 && strcmp(a->sweep.name, "b") != 0 &&
                              strcmp(a->sweep.name, "I0") != 0)))
                err = cli_usage_error(c,
                                      "--sweep: '%s' is not NAME=LO:HI:N with NAME a, b or I0, "
                                      "LO < HI and 1 <= N <= 10000 (e.g. a=1.2:2.25:64)",
                                      c->value);
            a->has_sweep = 1;
        } else if (cli_is(c, "--cells", true, &err)) {
            int64_t v;
            if (c->value && (!parse_int64(c->value, &v) || v < 0 || v > 100000000))
                err = cli_usage_error(c, "--cells: '%s' must be 0..100000000", c->value);
            else if (c->value)
                a->cells = (long)v;
        } else if (cli_is(c, "--ensemble", true, &err)) {
            int64_t v;
            if (c->value && (!parse_int64(c->value, &v) || v < 0 || v > 1000000000))
                err = cli_usage_error(c, "--ensemble: '%s' must be 0..1000000000", c->value);
            else if (c->value)
                a->ensemble = (long)v;
        } else if (cli_take_int(c, "--threads", 1, THREADS_LIMIT, &a->threads, &err)) {
        } else if (chart_outputs_take(c, &a->out, 300, 200, &err)) {
        } else {
            err = cli_stray(c);
        }
    }
    if (!err && a->has_sweep && strcmp(a->sweep.name, "I0") == 0 && a->has_I0)
        err = cli_usage_error(c, "--sweep I0=... and --I0: choose one");
    if (!err)
        err = chart_outputs_check(c, &a->out);
    return err;
}

/* The mean step number of the cells of I_rep that cell mapping sends to
 * the sink (out of I_rep: escaped), and how many cells never leave. */
static void cell_mapping(const cm_model *m, const cm_te *t, long cells, esc_point *p)
{
    p->scm_mean = NAN;
    p->scm_stay = 0;
    if (cells == 0)
        return;
    const cm_lattice lat = {1, {t->x0}, {t->rep_len / (double)cells}};
    const cm_box box = {1, {0}, {cells}};
    const cm_scm_options opt = {.max_steps = 1, .threads = 1};
    cm_region r;
    char msg[256];
    memset(&r, 0, sizeof r);
    if (cm_region_alloc(&r, &box, msg, sizeof msg) == CM_OK &&
        cm_scm_solve(m, &lat, &opt, &r, msg, sizeof msg) == CM_OK) {
        double sum = 0;
        long left = 0;
        for (uint64_t i = 0; i < r.ncells; i++) {
            if (r.group[i] == 0) {
                sum += r.step[i];
                left++;
            }
        }
        p->scm_stay = (long)r.ncells - left;
        p->scm_mean = left ? sum / (double)left : NAN;
    }
    cm_region_free(&r);
}

/* The model's parameters at sweep index i (or without a sweep): a, b, c. */
static bool point_model(const esc_args *a, int i, cm_model *m, char *why, size_t why_size)
{
    const char *names[2];
    double values[2];
    int n = 0;
    double I0 = a->I0;
    bool has_I0 = a->has_I0;
    if (a->has_sweep && strcmp(a->sweep.name, "I0") == 0) {
        I0 = param_axis_value(&a->sweep, i);
        has_I0 = true;
    } else if (a->has_sweep) {
        names[n] = a->sweep.name;
        values[n++] = param_axis_value(&a->sweep, i);
    }
    if (!model_with_values(&a->mo, names, values, n, m, why, why_size))
        return false;
    if (!has_I0)
        return true;
    /* c from |I0| at this point's a and b */
    const double c =
        cm_te_c_of_I0(cm_params_get(&m->values, "a"), cm_params_get(&m->values, "b"), I0);
    names[n] = "c";
    values[n++] = c;
    cm_model_release(m);
    return model_with_values(&a->mo, names, values, n, m, why, why_size);
}

static void compute_point(const esc_args *a, int i, esc_point *p)
{
    cm_model m;
    memset(p, 0, sizeof *p);
    p->exact = p->scm_mean = p->ens.mean = p->ens.kappa = NAN;
    if (!point_model(a, i, &m, p->why, sizeof p->why))
        return;
    const double av = cm_params_get(&m.values, "a"), bv = cm_params_get(&m.values, "b"),
                 cv = cm_params_get(&m.values, "c");
    p->valid = cm_te_setup(av, bv, cv, &p->t, p->why, sizeof p->why);
    if (p->valid) {
        if (!cm_te_exact_mean(&p->t, MAX_PARTITION, &p->exact, &p->partition))
            p->exact = NAN;
        if (a->ensemble > 0)
            cm_te_ensemble_run(&p->t, a->ensemble, SEED, &p->ens);
        cell_mapping(&m, &p->t, a->cells, p);
    }
    cm_model_release(&m);
}

static int points_of(const esc_args *a)
{
    return a->has_sweep ? a->sweep.n : 1;
}

static bool write_csv(const esc_args *a, const esc_point *pts)
{
    outfile o;
    if (!outfile_open("escape", a->out.csv, &o))
        return false;
    fprintf(o.f, "a,b,c,I0,valid,x0,rep_len,F,a_crit,border,D0_C1,D0_C2,kappa_C1,kappa_C2,"
                 "n_esc_C1,n_esc_C2,exact_mean,partition,ensemble_kappa,ensemble_mean,"
                 "scm_mean,scm_stay\n");
    for (int i = 0; i < points_of(a); i++) {
        const esc_point *p = &pts[i];
        const cm_te *t = &p->t;
        fprintf(o.f, "%.17g,%.17g,%.17g,%.17g,%d", t->a, t->b, t->c, t->I0, p->valid);
        if (!p->valid) {
            fprintf(o.f, ",nan,nan,nan,nan,0,nan,nan,nan,nan,nan,nan,nan,0,nan,nan,nan,0\n");
            continue;
        }
        fprintf(o.f, ",%.17g,%.17g,%.17g,%.17g,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%ld,"
                     "%.17g,%.17g,%.17g,%ld\n",
                t->x0, t->rep_len, t->F, t->a_crit, t->border, t->D0[0], t->D0[1], t->kappa[0],
                t->kappa[1], t->n_esc[0], t->n_esc[1], p->exact, p->partition, p->ens.kappa,
                p->ens.mean, p->scm_mean, p->scm_stay);
    }
    return outfile_close("escape", &o, true);
}

/* Fig. 4.5: the escape number of points across [0, 1.05 (a - c)], with
 * the ends of I0 and I_rep. */
static bool png_structure(const esc_args *a, const esc_point *p, const char *params)
{
    const cm_te *t = &p->t;
    const int n = 4 * a->out.width;
    const double hi = 1.05 * t->rep_hi;
    double *x = malloc((size_t)n * 2 * sizeof *x);
    if (!x) {
        fprintf(stderr, "cellmap escape: out of memory for the diagram\n");
        return false;
    }
    double *y = x + n, top = 1;
    for (int i = 0; i < n; i++) {
        x[i] = hi * (i + 0.5) / n;
        const long k = cm_te_escape_number(t, x[i], 1000);
        y[i] = k < 0 ? NAN : (double)k;
        top = fmax(top, k);
    }
    top = fmin(top, 40);
    const double marks_x[8] = {t->a - t->b - t->c, t->a - t->b - t->c, t->x0, t->x0,
                               t->rep_hi, t->rep_hi, 1, 1};
    const double marks_y[8] = {0, top, 0, top, 0, top, 0, top};
    const cm_rgb black = {0, 0, 0}, red = {215, 48, 39}, blue = {69, 117, 180};
    const cm_series series[] = {
        {CM_SERIES_SEGMENTS, marks_x, marks_y, 2, blue, 1},     /* I0's left end */
        {CM_SERIES_SEGMENTS, marks_x + 2, marks_y + 2, 4, red, 2}, /* I_rep */
        {CM_SERIES_SEGMENTS, marks_x + 6, marks_y + 6, 2, blue, 1},
        {CM_SERIES_POINTS, x, y, (size_t)n, black, 2},
    };
    char title[600];
    snprintf(title, sizeof title,
             "escape numbers (steps to fall below x0*); I0 and x = 1 blue, I_rep red; %s",
             params);
    const cm_chart chart = {a->out.width, a->out.height, {0, 0},  {hi, top + 1}, "x", "escape number",
                            title,    NULL,      series, 4,            figure_font(), 0, NULL, 0};
    const cm_png_text texts[] = {{"Model", a->mo.name}, {"Parameters", params}};
    const bool ok = write_chart_png("escape", a->out.png, &chart, 1, texts, 2);
    free(x);
    return ok;
}

/* Fig. 4.7: the mean escape number against the swept parameter. */
static bool png_sweep(const esc_args *a, const esc_point *pts, const char *params)
{
    const int n = a->sweep.n;
    double *v = malloc((size_t)n * 6 * sizeof *v);
    if (!v) {
        fprintf(stderr, "cellmap escape: out of memory for the diagram\n");
        return false;
    }
    double *xs = v, *lo = v + n, *hi = v + 2 * n, *exact = v + 3 * n, *ens = v + 4 * n,
           *scm = v + 5 * n, top = 1;
    for (int i = 0; i < n; i++) {
        const esc_point *p = &pts[i];
        xs[i] = param_axis_value(&a->sweep, i);
        hi[i] = p->valid ? p->t.n_esc[0] : NAN;
        lo[i] = p->valid ? p->t.n_esc[1] : NAN;
        exact[i] = p->valid ? p->exact : NAN;
        ens[i] = p->valid ? 1 / (1 - exp(-p->ens.kappa)) : NAN; /* (4.3) from its rate */
        scm[i] = p->valid ? p->scm_mean : NAN;
        for (const double *s = hi + i; s <= scm + i; s += n)
            if (isfinite(*s))
                top = fmax(top, *s);
    }
    const cm_rgb blue = {69, 117, 180}, purple = {118, 42, 131}, black = {0, 0, 0},
                 green = {26, 152, 80}, orange = {244, 109, 67};
    const cm_series series[] = {
        {CM_SERIES_LINE, xs, hi, (size_t)n, blue, 2},
        {CM_SERIES_LINE, xs, lo, (size_t)n, purple, 2},
        {CM_SERIES_LINE, xs, exact, (size_t)n, black, 2},
        {CM_SERIES_POINTS, xs, ens, (size_t)n, green, 5},
        {CM_SERIES_POINTS, xs, scm, (size_t)n, orange, 3},
    };
    char title[600];
    snprintf(title, sizeof title,
             "mean escape number: (4.3) from kappa of D0 with C1 (blue), C2 (purple) and of an "
             "ensemble (green); exact (black); cell mapping (orange); %s",
             params);
    const cm_chart chart = {a->out.width,
                            a->out.height,
                            {a->sweep.lo, 0},
                            {a->sweep.hi, 1.1 * top},
                            a->sweep.name,
                            "mean escape number",
                            title,
                            NULL,
                            series,
                            5,
                            figure_font(),
                            0,
                            NULL,
                            0};
    char range[120];
    param_axes_format(&a->sweep, 1, range, sizeof range);
    const cm_png_text texts[] = {{"Model", a->mo.name}, {"Parameters", params}, {"Sweep", range}};
    const bool ok = write_chart_png("escape", a->out.png, &chart, 1, texts, 3);
    free(v);
    return ok;
}

static void json_point(json *j, const esc_point *p)
{
    const cm_te *t = &p->t;
    json_object(j, NULL);
    json_num(j, "a", t->a);
    json_num(j, "b", t->b);
    json_num(j, "c", t->c);
    json_bool(j, "valid", p->valid);
    if (!p->valid) {
        json_str(j, "why", p->why);
    } else {
        json_num(j, "I0", t->I0);
        json_nums(j, "I_rep", (const double[2]){t->x0, t->rep_hi}, 2);
        json_num(j, "F", t->F);
        json_num(j, "a_crit", t->a_crit);
        json_bool(j, "border", t->border);
        json_nums(j, "D0", t->D0, 2);
        json_nums(j, "kappa", t->kappa, 2);
        json_nums(j, "n_esc", t->n_esc, 2);
        json_num(j, "exact_mean", p->exact);
        json_int(j, "partition", (int)p->partition);
        json_num(j, "ensemble_kappa", p->ens.kappa);
        json_num(j, "ensemble_mean", p->ens.mean);
        json_num(j, "scm_mean", p->scm_mean);
        json_int(j, "scm_stay", (int)p->scm_stay);
    }
    json_object_end(j);
}

static void print_point(FILE *f, const esc_args *a, const esc_point *p)
{
    const cm_te *t = &p->t;
    fprintf(f, "a = %s, b = %s, c = %s (|I0| = %s): ", CM_NUM(t->a), CM_NUM(t->b), CM_NUM(t->c),
            CM_NUM(t->I0));
    if (!p->valid) {
        fprintf(f, "%s\n", p->why);
        return;
    }
    fprintf(f, "I_rep = [%.6g, %.6g], |F| = %.6g (4.28), a_crit = %.6g (4.34)\n", t->x0, t->rep_hi,
            t->F, t->a_crit);
    if (t->border)
        fprintf(f, "  border state: D0 = 0, kappa = ln a = %.6g, N = a/(a - 1) = %.9g (4.35)\n",
                t->kappa[0], t->n_esc[0]);
    else
        fprintf(f, "  D0 %.6g .. %.6g (4.32), kappa %.6g .. %.6g (4.33), N %.6g .. %.6g (4.3)\n",
                t->D0[1], t->D0[0], t->kappa[0], t->kappa[1], t->n_esc[1], t->n_esc[0]);
    if (isnan(p->exact))
        fprintf(f, "  exact mean escape number: the orbit of a - c stays in I_rep\n");
    else
        fprintf(f, "  exact mean escape number %.9g (Markov partition of %ld intervals)\n",
                p->exact, p->partition);
    if (a->ensemble > 0)
        fprintf(f, "  ensemble of %ld: mean %.6g, kappa %.6g (steps %d..%d)\n", p->ens.points,
                p->ens.mean, p->ens.kappa, p->ens.fit_from, p->ens.fit_to);
    if (a->cells > 0)
        fprintf(f, "  cell mapping on %ld cells: mean step number %.6g (%ld cells never leave)\n",
                a->cells, p->scm_mean, p->scm_stay);
}

int cmd_escape(int argc, char **argv)
{
    cli c = {"escape", argc, argv, 0, NULL, NULL};
    esc_args a = {.mo = {.name = "microchaos-1d-friction"}, .cells = 100000,
                  .ensemble = 1000000, .out = {.width = 1000, .height = 600}};
    const int perr = parse_args(&c, &a);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    const int werr = chart_outputs_writable(&c, &a.out);
    if (werr != EXIT_OK)
        return werr;
    cm_params base;
    param_axis none = {0};
    const bool sweeps_param = a.has_sweep && strcmp(a.sweep.name, "I0") != 0;
    const int verr = sweep_check(&c, &a.mo, "microchaos-1d-friction", sweeps_param ? &a.sweep : &none,
                                 sweeps_param ? 1 : 0, &base);
    if (verr)
        return verr;
    const int n = points_of(&a);
    esc_point *pts = calloc((size_t)n, sizeof *pts);
    if (!pts) {
        fprintf(stderr, "cellmap escape: out of memory for %d points\n", n);
        return EXIT_FAIL;
    }
#pragma omp parallel for schedule(dynamic, 1) num_threads(a.threads ? a.threads : omp_get_max_threads())
    for (int i = 0; i < n; i++)
        compute_point(&a, i, &pts[i]);
    int valid = 0;
    for (int i = 0; i < n; i++)
        valid += pts[i].valid;
    if (!a.has_sweep && !pts[0].valid) {
        fprintf(stderr, "cellmap escape: %s; choose other parameters\n", pts[0].why);
        free(pts);
        return EXIT_USAGE;
    }
    char params[400];
    const char *const skip[] = {a.has_sweep ? a.sweep.name : "", a.has_I0 ? "c" : "", NULL};
    cm_params_format_with(&base, skip, params, sizeof params);
    if (a.has_I0) {
        const size_t used = strlen(params);
        snprintf(params + used, sizeof params - used, "%s|I0|=%s", used ? "," : "", CM_NUM(a.I0));
    }
    if (a.out.json) {
        json j;
        json_begin(&j, stdout, "escape");
        param_base_json(&j, a.mo.name, &base);
        if (a.has_I0) /* c at each point from it */
            json_num(&j, "I0", a.I0);
        if (a.has_sweep)
            param_axes_json(&j, "sweep", &a.sweep, 1);
        json_int(&j, "cells", (int)a.cells);
        json_int(&j, "ensemble", (int)a.ensemble);
        json_array(&j, "points");
        for (int i = 0; i < n; i++)
            json_point(&j, &pts[i]);
        json_array_end(&j);
        json_end(&j);
    } else if (!a.out.quiet) {
        FILE *f = report_stream(a.out.csv, a.out.png, NULL);
        if (a.has_sweep)
            fprintf(f, "%d points, %d in the case of 4.3 (one positive fixed point in I_rep)\n", n,
                    valid);
        else
            print_point(f, &a, &pts[0]);
    }
    bool ok = true;
    if (a.out.csv)
        ok = write_csv(&a, pts);
    if (ok && a.out.png)
        ok = a.has_sweep ? png_sweep(&a, pts, params) : png_structure(&a, &pts[0], params);
    free(pts);
    return ok ? EXIT_OK : EXIT_FAIL;
}
