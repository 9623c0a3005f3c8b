/* cellmap measure: a .cmdb file's basins measured, over lib/measure.h. */
#include <stdio.h>
#include <string.h>

#include "lib/measure.h"
#include "lib/parse.h"
#include "src/args.h"
#include "src/commands.h"
#include "src/interrupt.h"
#include "src/outfile.h"
#include "src/progress.h"

static const char measure_help[] =
    "usage: cellmap measure FILE.cmdb [--window X0:X1[,Y0:Y1...]] [--entropy B[,B...]|none]\n"
    "                       [--uncertainty E0:E1|none] [--wada R|none] [--mem BYTES]\n"
    "                       [--to OTHER.cmdb] [--samples N[:SEED] [--orbit-uncertainty E0:E1]]\n"
    "                       [--threads N] [--csv FILE|-] [--png FILE] [--size WxH] [--json]\n"
    "                       [--quiet]\n\n"
    "Measures the basins of the file's attractors (as `export --labels` labels the\n"
    "cells: 0 diverged and -2 outside count as basins; cells not computed are left\n"
    "out), over the window (default every cell):\n"
    "  - each basin's share of the computed cells (with the 95 % interval of a share\n"
    "    sampled from that many states);\n"
    "  - basin entropy Sb and boundary basin entropy Sbb (Daza et al. 2016) in boxes\n"
    "    of B cells a side, their mean and spread over the sizes; Sbb > log 2 says\n"
    "    the boundary is fractal;\n"
    "  - the fraction f(eps) of cells with another basin eps cells away along an\n"
    "    axis, eps doubling from E0 to E1, and the uncertainty exponent alpha of\n"
    "    f ~ eps^alpha (Grebogi et al. 1983): the boundary's dimension is d - alpha;\n"
    "  - the Wada test: the share of boundary cells that see every basin within r\n"
    "    cells, r = 1..R: Wada (>= 0.99 at R), partially Wada, or not (< 0.05);\n"
    "  - with --to, the tipping probabilities: of each basin's cells, the share that\n"
    "    lies in each basin of OTHER.cmdb (solved on the same lattice, for another\n"
    "    parameter value), over the cells computed in both.\n\n"
    "  --window X0:X1,...  the cells whose centres lie in this box of state space\n"
    "  --entropy B,...     box sizes in cells (default 3,5,7,9)\n"
    "  --uncertainty E0:E1 eps in cells (default 1:16)\n"
    "  --wada R            the largest radius (default 5; with fewer than 3 basins the\n"
    "                      default test is skipped, an explicit one is an error)\n"
    "  --to OTHER.cmdb     the second file of the tipping probabilities\n"
    "  --samples N[:SEED]  also N random states of the window, each followed by the true\n"
    "                      map until it settles on an attractor (at most 10000 steps, 2000\n"
    "                      for flows): the sampled shares, intervals that hold the true\n"
    "                      ones together 95 times in 100, and whether the cells' shares\n"
    "                      lie in them (seed default 1)\n"
    "  --orbit-uncertainty E0:E1  with --samples, f(eps) and alpha by true orbits: the\n"
    "                      share of the states with one eps cells away (along an axis)\n"
    "                      that goes elsewhere, eps doubling from E0 to E1 (may be < 1)\n"
    "  --threads N         threads following them (default: all)\n"
    "  --mem BYTES         memory for the labels and the cluster's pages, half each\n"
    "                      (256M): a window whose labels do not fit is measured in\n"
    "                      slabs; the node labels (4 bytes per node) come on top, and\n"
    "                      while they are made the open nodes' index (70 bytes each)\n"
    "  --csv FILE|-        rows measure,scale,value: share and sampled (the label), sb and\n"
    "                      sbb (the box), uncertain and orbit_uncertain (eps), wada (r),\n"
    "                      tipping (FROM>TO)\n"
    "  --png FILE          a 2-D window's entropy map (the first box size) over f(eps)\n"
    "  --size WxH          its size (default 800x1000)\n"
    "  --json              the result as JSON on standard output\n"
    "  --quiet             no progress line and no summary\n";

static bool none(const char *value) { return value && strcmp(value, "none") == 0; }

static int parse_args(cli *c, measure_args *a, bool *json, bool *quiet)
{
    int err = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(measure_help, stdout);
            return -1;
        } else if (cli_is(c, "--window", true, &err)) {
            a->window = c->value;
        } else if (cli_is(c, "--entropy", true, &err)) {
            double box[MEASURE_MAX_BOXES];
            a->n_box = 0;
            if (c->value && !none(c->value) &&
                !parse_doubles(c->value, box, &a->n_box, MEASURE_MAX_BOXES))
                err = cli_usage_error(c, "--entropy: '%s' is not B[,B...] (at most %d sizes)",
                                      c->value, MEASURE_MAX_BOXES);
            for (int k = 0; k < a->n_box; k++)
                a->box[k] = box[k] == (int)box[k] ? (int)box[k] : 0;
        } else if (cli_is(c, "--uncertainty", true, &err)) {
            a->eps_hi = 0;
            if (c->value && !none(c->value) && !parse_int_span(c->value, &a->eps_lo, &a->eps_hi))
                err = cli_usage_error(c, "--uncertainty: '%s' is not E0:E1", c->value);
        } else if (cli_is(c, "--wada", true, &err)) {
            a->wada_radius = 0, a->wada_asked = !none(c->value);
            if (a->wada_asked && c->value && !(parse_int_span(c->value, &a->wada_radius,
                                                              &a->wada_radius)))
                err = cli_usage_error(c, "--wada: '%s' is not a radius in cells", c->value);
        } else if (cli_is(c, "--to", true, &err)) {
            a->to = c->value;
        } else if (cli_is(c, "--samples", true, &err)) {
            int64_t n = 0, seed = 1;
            char text[64];
            snprintf(text, sizeof text, "%s", c->value ? c->value : "1");
            char *colon = strchr(text, ':');
            if (colon)
                *colon = 0;
            if (!parse_int64(text, &n) || n < 1 ||
                (colon && (!parse_int64(colon + 1, &seed) || seed < 0)))
                err = cli_usage_error(c, "--samples: give N[:SEED], N >= 1, SEED >= 0");
            a->samples = (uint64_t)n, a->seed = (uint64_t)seed;
        } else if (cli_is(c, "--orbit-uncertainty", true, &err)) {
            int n = 0;
            if (c->value && (!parse_ranges(c->value, &a->orbit_eps_lo, &a->orbit_eps_hi, &n, 1) ||
                             !(a->orbit_eps_lo > 0)))
                err = cli_usage_error(c, "--orbit-uncertainty: '%s' is not E0:E1, 0 < E0 < E1 "
                                         "(cells)", c->value);
        } else if (cli_take_int(c, "--threads", 1, THREADS_LIMIT, &a->threads, &err)) {
        } else if (cli_take_mem(c, &a->mem, &err)) {
        } else if (cli_is(c, "--csv", true, &err)) {
            a->csv = c->value;
        } else if (cli_is(c, "--png", true, &err)) {
            a->png = c->value;
        } else if (cli_take_size(c, 300, 400, 4096, &a->width, &a->height, &err)) {
        } else if (cli_is(c, "--json", false, &err)) {
            *json = true;
        } else if (cli_is(c, "--quiet", false, &err)) {
            *quiet = true;
        } else if (c->opt[0] != '-' && !a->file) {
            a->file = c->opt;
        } else {
            err = cli_stray(c);
        }
    }
    if (!err && !a->file)
        err = cli_usage_error(c, "which file? usage: cellmap measure FILE.cmdb");
    if (!err && *json + cm_output_names_stdout(a->csv) + cm_output_names_stdout(a->png) > 1)
        err = cli_usage_error(c, "two outputs to standard output: choose one");
    char why[1024];
    const cm_file_use files[] = {{a->file, "the database", false, true},
                                 {a->to, "--to", false, true},
                                 {a->csv, "--csv", true, false},
                                 {a->png, "--png", true, false}};
    if (!err && cm_files_apart(files, 4, why, sizeof why) != CM_OK)
        err = cli_usage_error(c, "%s", why);
    return err;
}

int cmd_measure(int argc, char **argv)
{
    cli c = {"measure", argc, argv, 0, NULL, NULL};
    measure_args a = measure_defaults();
    bool json = false, quiet = false;
    const int perr = parse_args(&c, &a, &json, &quiet);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    int werr = cli_input_check("measure", a.file);
    if (werr == EXIT_OK && a.to)
        werr = cli_input_check("measure", a.to);
    if (werr == EXIT_OK)
        werr = outfile_check("measure", a.csv, false);
    if (werr == EXIT_OK)
        werr = chart_png_check("measure", a.png);
    if (werr != EXIT_OK)
        return werr;
    char msg[1024];
    progress pr;
    interrupt_catch();
    const work_hooks hooks = progress_hooks(&pr);
    progress_start(&pr, "measure", "cells", 0, quiet || json);
    measure_result r;
    cm_status st = measure_compute(&a, &hooks, &r, msg, sizeof msg);
    progress_end(&pr);
    if (st == CM_OK) {
        if (json)
            measure_json(stdout, &r);
        else if (!quiet)
            measure_report(report_stream(a.csv, a.png, NULL), &r);
        st = measure_write(&a, &r, msg, sizeof msg);
    }
    measure_result_free(&r);
    return analysis_said(c.cmd, st, msg);
}
