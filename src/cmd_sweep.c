/* cellmap sweep: simple cell mapping of one region for a list of values of
 * one parameter, counting the attractors and sticking zones (and their
 * basins) whose periodic cells lie in a window, and locating by bisection
 * where those counts change: e.g. the friction level at which sticking
 * zones absorb the outermost micro-chaotic attractors (thesis Fig. 4.30,
 * docs/models.md 8.4). */
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/sweep.h"
#include "src/args.h"
#include "lib/attractor_report.h"
#include "src/attractor_opts.h"
#include "src/commands.h"
#include "lib/json.h"
#include "src/interrupt.h"
#include "src/outfile.h"
#include "lib/param_grid.h"
#include "src/progress.h"

static const char sweep_help[] =
    "usage: cellmap sweep --model NAME [--model-lib P.so] [--param k=v[,k=v]]\n"
    "                     --vary NAME=V1,V2,...|NAME=LO:HI:N\n"
    "                     [--region LO:HI,...] [--cells NxM] [--max-steps S] [--threads T]\n"
    "                     [--near LO:HI[,LO:HI...]] [--refine K] [--csv FILE|-] [--json]\n"
    "                     [--quiet]\n\n"
    "Simple cell mapping of the region for each value of one parameter (as\n"
    "`cellmap solve` would, one value after another). For each value it counts\n"
    "the system's attractors (as solve finds them from the groups' true orbits)\n"
    "and the sticking groups (rest cells: a sticking zone is one group per rest\n"
    "cell) whose centre lies in the --near window (default: anywhere), and their\n"
    "basin cells; --by groups counts cell mapping's groups instead. Where the number of\n"
    "attractors differs between neighbouring values, --refine K bisects the\n"
    "interval K times and reports where it changes: e.g. where a sticking\n"
    "zone absorbs an attractor.\n\n"
    "  --vary NAME=V1,...  the parameter and its values (2..200, increasing); or\n"
    "  --vary NAME=LO:HI:N N values at the centres of N equal steps of LO..HI\n"
    "  --near LO:HI,...    the window of periodic cells counted (one range per\n"
    "                      dimension; fewer ranges leave the other dimensions free)\n"
    "  --refine K          bisection steps per change, 0..40 (default 0)\n"
    "  --csv FILE|-        every value solved, sorted: NAME,attractors,sticking,\n"
    "                      attractor_cells,sticking_cells,groups,sink_cells,seconds\n"
    "  --json              the values solved and the changes found as one JSON\n"
    "                      document on standard output (docs/cellmap.schema.json)\n"
    "  --quiet             no progress line and no report\n"
    "  --max-steps, --threads, --region, --cells, --by, --attractor-steps,\n"
    "  --attractor-tol: as for solve\n";

/* "NAME=V1,V2,..." (increasing) or "NAME=LO:HI:N", 2..MAX_VALUES values */
static bool parse_vary(const char *s, sweep_args *a)
{
    param_axis ax;
    if (!param_axis_parse(s, strlen(s), &ax) || ax.n < 2 || ax.n > MAX_VALUES ||
        strlen(ax.name) >= sizeof a->name)
        return false;
    strcpy(a->name, ax.name);
    a->n_values = ax.n;
    for (int k = 0; k < ax.n; k++)
        a->values[k] = param_axis_value(&ax, k);
    return true;
}

static int parse_args(cli *c, sweep_args *a)
{
    int err = 0, has_vary = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(sweep_help, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (lattice_opts_take(c, &a->lat, &err)) {
        } else if (cli_is(c, "--vary", true, &err)) {
            if (c->value && !parse_vary(c->value, a))
                err = cli_usage_error(c,
                                      "--vary: '%s' is not NAME=V1,V2,... with 2..%d increasing "
                                      "values (e.g. mu=0.09,0.095,0.1,0.105) nor NAME=LO:HI:N "
                                      "(e.g. mu=0.09:0.11:5)",
                                      c->value, MAX_VALUES);
            has_vary = 1;
        } else if (cli_is(c, "--near", true, &err)) {
            if (c->value && !parse_ranges(c->value, a->near_lo, a->near_hi, &a->n_near, CM_MAX_DIM))
                err = cli_usage_error(c, "--near: '%s' is not LO:HI[,LO:HI...] with LO < HI",
                                      c->value);
        } else if (cli_take_int(c, "--refine", 0, MAX_REFINE, &a->refine, &err)) {
        } else if (cli_take_int(c, "--max-steps", 1, MAX_STEPS_LIMIT, &a->max_steps, &err)) {
        } else if (cli_take_int(c, "--threads", 1, THREADS_LIMIT, &a->threads, &err)) {
        } else if (cli_is(c, "--csv", true, &err)) {
            a->csv = c->value;
        } else if (cli_is(c, "--json", false, &err)) {
            a->json = true;
        } else if (by_option_take(c, &a->by, &err)) {
        } else if (attractor_options_take(c, &a->att, &err)) {
        } else if (cli_is(c, "--quiet", false, &err)) {
            a->quiet = true;
        } else {
            err = cli_stray(c);
        }
    }
    if (!err && a->json && a->csv && cm_output_names_stdout(a->csv))
        err = cli_usage_error(c, "--json and --csv - both go to standard output: choose one");
    if (!err && !has_vary)
        err = cli_usage_error(c, "--vary NAME=V1,V2,... is required (e.g. --vary mu=0.09,0.1)");
    return err;
}

/* ---- one value ---- */

/* ---- the sweep ---- */

/* Changes are changes of the number of attractors: sticking zones are sets
 * of rest cells whose count grows with the zones' width. */
static bool same_counts(const sweep_point *x, const sweep_point *y)
{
    return x->attractors == y->attractors;
}

static void print_point(FILE *out, const char *name, const sweep_point *pt)
{
    fprintf(out, "%s = %-12.9g %3u attractor(s), %3u sticking group(s) in the window; basins %llu and "
           "%llu cells; %u groups; %.2f s\n",
           name, pt->value, pt->attractors, pt->sticking, (unsigned long long)pt->attractor_cells,
           (unsigned long long)pt->sticking_cells, pt->groups, pt->seconds);
}

/* Where the count of attractors changes: between lo and hi. */
typedef struct sweep_change {
    sweep_point lo, hi;
    bool several; /* by more than one: bisection followed one of the changes */
} sweep_change;

/* Bisects between ch->lo and ch->hi (whose counts differ) `refine` times;
 * the solved midpoints are appended to pts. */
static cm_status refine_change(const sweep_args *a, const cm_lattice *lat, const cm_box *box,
                               sweep_change *ch, sweep_point *pts, int *n_pts, char *msg,
                               size_t msg_size)
{
    sweep_point lo = ch->lo, hi = ch->hi;
    for (int k = 0; k < a->refine; k++) {
        if (interrupt_requested())
            return cm_fail(CM_ECANCELED, msg, msg_size, "interrupted");
        sweep_point *mid = &pts[*n_pts];
        const cm_status st =
            sweep_solve_at(a, lat, box, 0.5 * (lo.value + hi.value), mid, msg, msg_size);
        if (st != CM_OK)
            return st;
        ++*n_pts;
        if (same_counts(mid, &lo))
            lo = *mid;
        else
            hi = *mid;
    }
    ch->lo = lo;
    ch->hi = hi;
    return CM_OK;
}

static void print_change(FILE *out, const char *name, const sweep_change *ch)
{
    fprintf(out, "change: %u attractor(s) at %s = %.9g, %u at %.9g (width %.3g)%s\n",
            ch->lo.attractors, name, ch->lo.value, ch->hi.attractors, ch->hi.value,
            ch->hi.value - ch->lo.value,
            ch->several ? "; the interval held more than one change, bisection followed one"
                        : "");
}

static void print_json(const sweep_args *a, const cm_lattice *lat, const cm_box *box,
                       const sweep_point *pts, int n, const sweep_change *changes, int n_changes)
{
    cm_model m;
    char msg[256];
    if (!model_with_values(&a->mo, NULL, NULL, 0, &m, msg, sizeof msg))
        return; /* checked before the sweep */
    json j;
    json_begin(&j, stdout, "sweep");
    json_model(&j, &m);
    cm_model_release(&m);
    json_lattice(&j, lat);
    json_box(&j, "box", lat, box);
    json_str(&j, "parameter", a->name);
    json_array(&j, "points");
    for (int k = 0; k < n; k++) {
        json_object(&j, NULL);
        json_num(&j, "value", pts[k].value);
        json_uint(&j, "attractors", pts[k].attractors);
        json_uint(&j, "sticking", pts[k].sticking);
        json_uint(&j, "attractor_cells", pts[k].attractor_cells);
        json_uint(&j, "sticking_cells", pts[k].sticking_cells);
        json_uint(&j, "groups", pts[k].groups);
        json_uint(&j, "sink_cells", pts[k].sink_cells);
        json_seconds(&j, "seconds", pts[k].seconds);
        json_object_end(&j);
    }
    json_array_end(&j);
    json_array(&j, "changes");
    for (int k = 0; k < n_changes; k++) {
        json_object(&j, NULL);
        json_num(&j, "from", changes[k].lo.value);
        json_num(&j, "to", changes[k].hi.value);
        json_uint(&j, "attractors_from", changes[k].lo.attractors);
        json_uint(&j, "attractors_to", changes[k].hi.attractors);
        json_bool(&j, "several", changes[k].several);
        json_object_end(&j);
    }
    json_array_end(&j);
    json_end(&j);
}

static int by_value(const void *x, const void *y)
{
    const double u = ((const sweep_point *)x)->value, v = ((const sweep_point *)y)->value;
    return (u > v) - (u < v);
}

/* Checks the model, the parameter, the window, the lattice and every value. */
static int check_setup(const cli *c, const sweep_args *a, cm_lattice *lat, cm_box *box)
{
    cm_model m;
    int err = model_opts_build(c, &a->mo, &m);
    if (err)
        return err;
    if (cm_params_find(&m.values, a->name) < 0)
        err = cli_usage_error(c, "--vary: '%s' is not a parameter of %s (`cellmap models`)",
                              a->name, m.name);
    if (!err && a->n_near > m.dim)
        err = cli_usage_error(c, "--near has %d range(s) but model %s has dimension %d", a->n_near,
                              m.name, m.dim);
    if (!err)
        err = lattice_opts_build(c, &a->lat, &m, &a->mo.set, lat, box);
    cm_model_release(&m);
    for (int k = 0; k < a->n_values && !err; k++) {
        const char *name = a->name;
        char msg[256];
        if (!model_with_values(&a->mo, &name, &a->values[k], 1, &m, msg, sizeof msg))
            err = cli_usage_error(c, "--vary: %s = %s: %s", a->name, CM_NUM(a->values[k]), msg);
        else
            cm_model_release(&m);
    }
    return err;
}

int cmd_sweep(int argc, char **argv)
{
    cli c = {"sweep", argc, argv, 0, NULL, NULL};
    sweep_args a;
    memset(&a, 0, sizeof a);
    a.mo.name = "microchaos-pd";
    int rc = parse_args(&c, &a);
    if (rc)
        return rc < 0 ? EXIT_OK : rc;
    const int werr = outfile_check("sweep", a.csv, false);
    if (werr != EXIT_OK)
        return werr;
    cm_lattice lat;
    cm_box box;
    if ((rc = check_setup(&c, &a, &lat, &box)))
        return rc;
    sweep_point *pts = malloc((size_t)(a.n_values * (1 + a.refine)) * sizeof *pts);
    sweep_change *changes = malloc((size_t)a.n_values * sizeof *changes);
    if (!pts || !changes) {
        fprintf(stderr, "cellmap sweep: out of memory\n");
        free(pts);
        free(changes);
        return EXIT_FAIL;
    }
    /* the text report goes where no other output goes; not with --json */
    FILE *text = a.json || a.quiet ? NULL : report_stream(a.csv, NULL, NULL);
    char msg[512];
    int n = 0, n_changes = 0;
    cm_status st = CM_OK;
    progress pr;
    progress_start(&pr, "sweep", "values", (uint64_t)a.n_values, a.quiet);
    interrupt_catch();
    for (int k = 0; k < a.n_values && st == CM_OK; k++) {
        st = interrupt_requested() ? cm_fail(CM_ECANCELED, msg, sizeof msg, "interrupted")
                                   : sweep_solve_at(&a, &lat, &box, a.values[k], &pts[n], msg,
                                                    sizeof msg);
        progress_end(&pr); /* the report's line goes below the progress line */
        if (st == CM_OK && text)
            print_point(text, a.name, &pts[n]);
        n += st == CM_OK;
        progress_say(&pr, (uint64_t)n, NULL);
    }
    /* the listed values are pts[0 .. n_values-1]; refinements follow them */
    for (int k = 1; k < a.n_values && st == CM_OK; k++)
        if (!same_counts(&pts[k - 1], &pts[k])) {
            sweep_change *ch = &changes[n_changes++];
            ch->lo = pts[k - 1];
            ch->hi = pts[k];
            ch->several = ch->lo.attractors > ch->hi.attractors + 1 ||
                          ch->hi.attractors > ch->lo.attractors + 1;
            if (a.refine)
                st = refine_change(&a, &lat, &box, ch, pts, &n, msg, sizeof msg);
            if (st == CM_OK && a.refine && text)
                print_change(text, a.name, ch);
        }
    if (st == CM_OK && !n_changes && text)
        fprintf(text, "no change of the counts between %s = %s and %s\n", a.name,
                CM_NUM(a.values[0]), CM_NUM(a.values[a.n_values - 1]));
    progress_end(&pr);
    if (st == CM_ECANCELED) {
        free(pts);
        free(changes);
        return interrupt_stopped("sweep", (uint64_t)n, (uint64_t)(n > a.n_values ? n : a.n_values),
                                 "values");
    }
    if (st != CM_OK)
        fprintf(stderr, "cellmap sweep: %s = %s: %s\n", a.name, CM_NUM(pts[n].value), msg);
    qsort(pts, (size_t)n, sizeof *pts, by_value);
    const bool ok = st == CM_OK && (!a.csv || sweep_write_csv(&a, pts, n, msg, sizeof msg));
    if (st == CM_OK && !ok)
        fprintf(stderr, "cellmap sweep: %s\n", msg);
    if (ok && a.json)
        print_json(&a, &lat, &box, pts, n, changes, n_changes);
    free(pts);
    free(changes);
    return ok ? EXIT_OK : EXIT_FAIL;
}
