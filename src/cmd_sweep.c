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
#include "lib/sweep_report.h"
#include "src/args.h"
#include "lib/attractor_report.h"
#include "src/attractor_opts.h"
#include "src/commands.h"
#include "src/interrupt.h"
#include "src/outfile.h"
#include "lib/param_grid.h"
#include "src/progress.h"

static const char sweep_help[] =
    "usage: cellmap sweep --model NAME [--model-lib P.so] [--param k=v[,k=v]]\n"
    "                     --vary NAME=V1,V2,...|NAME=LO:HI:N\n"
    "                     [--region LO:HI,...] [--cells NxM] [--max-steps S] [--threads T]\n"
    "                     [--near LO:HI[,LO:HI...]] [--refine K] [--match-within F]\n"
    "                     [--csv FILE|-] [--fractions FILE|-] [--png FILE] [--size WxH]\n"
    "                     [--keep DIR] [--no-seeds] [--json] [--quiet]\n\n"
    "Simple cell mapping of the region for each value of one parameter (as\n"
    "`cellmap solve` would, one value after another). For each value it counts\n"
    "the system's attractors (as solve finds them from the groups' true orbits)\n"
    "and the sticking groups (rest cells: a sticking zone is one group per rest\n"
    "cell) whose centre lies in the --near window (default: anywhere), and their\n"
    "basin cells; --by groups counts cell mapping's groups instead. The attractors\n"
    "are tracked from value to value: two of neighbouring values are one when their\n"
    "centres lie within F of the region's extent in every dimension (nearest pairs\n"
    "first); an attractor without a match appears (taking back the id of one that\n"
    "vanished there before), vanishes, or merges into a chaotic one whose bounds\n"
    "hold it; a basin that falls below half its cells collapses. Where they change\n"
    "between neighbouring values, --refine K bisects the interval K times (up to\n"
    "four changes each): e.g. where a sticking zone absorbs an attractor. An\n"
    "attractor of one value that no attractor of a neighbouring value matches is\n"
    "followed there by the true map from its smallest cell: when it persists nearby\n"
    "it is kept there too, 'seeded', with no basin cells (the lattice shows none),\n"
    "so births and deaths are where the true orbits have them (--no-seeds: where\n"
    "the lattice shows them).\n\n"
    "  --vary NAME=V1,...  the parameter and its values (2..200, increasing); or\n"
    "  --vary NAME=LO:HI:N N values at the centres of N equal steps of LO..HI\n"
    "  --near LO:HI,...    the window of periodic cells counted (one range per\n"
    "                      dimension; fewer ranges leave the other dimensions free)\n"
    "  --refine K          bisection steps per change, 0..40 (default 0)\n"
    "  --match-within F    the tracking's distance, a share of the region (default 0.05)\n"
    "  --fractions FILE|-  each value's basin shares: NAME,basin,kind,period,cells,share,\n"
    "                      centre_0,...; basin an attractor's id, or sticking, elsewhere\n"
    "                      (attractors outside --near), diverged, outside, undecided\n"
    "  --png FILE          the shares stacked against the parameter; --size WxH (900x560)\n"
    "  --keep DIR          each value solved into DIR/NAME=VALUE.cmdb (made if missing) as\n"
    "                      `solve --db` would, its attractors stored: query, render,\n"
    "                      export or measure each (e.g. tipping: measure A --to B)\n"
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
        } else if (cli_is(c, "--fractions", true, &err)) {
            a->fractions = c->value;
        } else if (cli_is(c, "--png", true, &err)) {
            a->png = c->value;
        } else if (cli_is(c, "--keep", true, &err)) {
            a->keep = c->value;
        } else if (cli_is(c, "--no-seeds", false, &err)) {
            a->no_seeds = true;
        } else if (cli_take_size(c, 300, 200, 4096, &a->width, &a->height, &err)) {
        } else if (cli_take_double(c, "--match-within", 1e-9, 1, &a->match, &err)) {
        } else if (by_option_take(c, &a->by, &err)) {
        } else if (attractor_options_take(c, &a->att, &err)) {
        } else if (cli_is(c, "--quiet", false, &err)) {
            a->quiet = true;
        } else {
            err = cli_stray(c);
        }
    }
    if (!err && a->json + cm_output_names_stdout(a->csv) + cm_output_names_stdout(a->fractions) +
                        cm_output_names_stdout(a->png) > 1)
        err = cli_usage_error(c, "two outputs to standard output: choose one");
    if (!err && !has_vary)
        err = cli_usage_error(c, "--vary NAME=V1,V2,... is required (e.g. --vary mu=0.09,0.1)");
    return err;
}

/* The report as the sweep goes: a line per point and per change, below
 * the progress line. */
typedef struct reporter {
    FILE *text; /* NULL: none */
    progress *pr;
} reporter;

static void said_point(void *user, const sweep_args *a, const sweep_point *pt)
{
    const reporter *r = user;
    progress_end(r->pr);
    if (r->text)
        sweep_print_point(r->text, a->name, pt);
}

static void said_change(void *user, const sweep_args *a, const sweep_change *ch)
{
    const reporter *r = user;
    if (r->text)
        sweep_print_change(r->text, a->name, ch);
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
    int werr = outfile_check("sweep", a.csv, false);
    if (werr == EXIT_OK)
        werr = outfile_check("sweep", a.fractions, false);
    if (werr == EXIT_OK)
        werr = chart_png_check("sweep", a.png);
    if (werr != EXIT_OK)
        return werr;
    char msg[512], command[4096];
    join_argv(argc + 1, argv - 1, command, sizeof command);
    a.command = command;
    sweep_result r = {0};
    if (sweep_check_setup(&a, &r, msg, sizeof msg) != CM_OK)
        return cli_usage_error(&c, "%s", msg);
    progress pr;
    progress_start(&pr, "sweep", "values", (uint64_t)a.n_values, a.quiet);
    const work_hooks hooks = progress_hooks(&pr);
    /* the text report goes where no other output goes; not with --json */
    reporter rep = {a.json || a.quiet ? NULL : report_stream(a.csv, NULL, NULL), &pr};
    interrupt_catch();
    cm_status st =
        sweep_compute(&a, &hooks, &(sweep_report){said_point, said_change, &rep}, &r, msg, sizeof msg);
    if (st == CM_OK && !r.n_changes && rep.text)
        fprintf(rep.text, "no change of the counts between %s = %s and %s\n", a.name,
                CM_NUM(a.values[0]), CM_NUM(a.values[a.n_values - 1]));
    progress_end(&pr);
    if (st == CM_ECANCELED) {
        sweep_result_free(&r);
        return interrupt_stopped("sweep", (uint64_t)r.n,
                                 (uint64_t)(r.n > a.n_values ? r.n : a.n_values), "values");
    }
    if (st != CM_OK)
        fprintf(stderr, "cellmap sweep: %s = %s: %s\n", a.name, CM_NUM(r.failed_value), msg);
    bool ok = st == CM_OK && (!a.csv || sweep_write_csv(&a, r.pts, r.n, msg, sizeof msg));
    if (st == CM_OK && !ok)
        fprintf(stderr, "cellmap sweep: %s\n", msg);
    if (ok && (a.fractions || a.png) && sweep_write_tracked(&a, &r, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "cellmap sweep: %s\n", msg);
        ok = false;
    }
    if (ok && a.json)
        sweep_json(stdout, &a, &r);
    else if (ok && rep.text)
        sweep_print_tracked(rep.text, &a, &r);
    sweep_result_free(&r);
    return ok ? EXIT_OK : EXIT_FAIL;
}
