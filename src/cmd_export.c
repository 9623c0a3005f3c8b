/* cellmap export: a .cmdb file's groups and cells as CSV, NumPy .npy or a
 * flat SQLite table, for users' own tools. Every output is written to a
 * temporary file and renamed when complete. */
#include <stdio.h>
#include <string.h>

#include "lib/export.h"
#include "lib/project.h"
#include "lib/session.h"
#include "src/args.h"
#include "src/attractor_opts.h"
#include "src/commands.h"
#include "src/interrupt.h"
#include "src/outfile.h"
#include "src/progress.h"

static const char export_help[] =
    "usage: cellmap export FILE.cmdb [--groups OUT.csv] [--cells OUT.csv|OUT.npy]\n"
    "                      [--flat OUT.sqlite] [--labels OUT.npy] [--steps OUT.npy]\n"
    "                      [--window X0:X1[,Y0:Y1...]] [--mem BYTES] [--quiet]\n\n"
    "Writes only complete files: Ctrl-C stops it and leaves no partial file (exit 130).\n\n"
    "  --groups OUT.csv    one row per group: id, period, basin_cells, is_sink (group 0),\n"
    "                      centre, bounds of the periodic cells' centres, anchor cell,\n"
    "                      kind (attractor, sticking zone or the sink), and the system's\n"
    "                      attractor its true orbit reaches (0: it diverges, -1: undecided)\n"
    "  --cells OUT         one row per computed cell: lattice indices ix, iv, ..., cell\n"
    "                      centre x, v, ... (i and the model's state names, as `cellmap\n"
    "                      models` lists them), grp, step, periodic, and the cell's\n"
    "                      attractor (as --labels gives it); CSV with a header, or .npy\n"
    "                      (a structured array with those fields, little-endian)\n"
    "  --flat OUT.sqlite   the same rows as a plain table cells(ix, iv, ..., x, v, ...,\n"
    "                      grp, step, periodic, attractor), with tables groups (as\n"
    "                      --groups, kind\n"
    "                      included), meta (source file, lattice origin and widths,\n"
    "                      state names) and indexes on cells(grp), the cells' indices\n"
    "                      and groups(kind)\n"
    "  --labels OUT.npy    the attractor of every cell as an n-D array: shape = cells per\n"
    "                      dimension (axis k = dimension k), C order, int32 (attractor ids\n"
    "                      from 1; 0 diverged; -2 outside: the sequence left the computed\n"
    "                      cells and its orbit did not come back (--outside-steps), or its\n"
    "                      group's true orbit was undecided; -1 not computed); OUT.json\n"
    "                      beside it holds the lattice, the box, the\n"
    "                      model and each attractor (kind, period, centre)\n"
    "  --by groups         --labels gives cell mapping's groups instead (0 the sink), and\n"
    "                      OUT.json each group (kind, period, centre, colour)\n"
    ATTRACTOR_OPTIONS_HELP
    "  --steps OUT.npy     the same array of step numbers (-1 not computed), with OUT.json\n"
    "  --window X0:X1,...  only cells whose centre lies in this box of state space (for\n"
    "                      --cells, --flat, --labels and --steps)\n"
    "  --mem BYTES         cell arrays to hold in memory while reading (default 256M)\n"
    "  --quiet             no progress line and no count of the cells written\n";

typedef struct export_args {
    const char *file, *groups, *cells, *flat, *window, *labels, *steps;
    uint64_t mem;
    bool quiet;
    int by;                   /* --by: --labels by attractors (default) or groups */
    cm_attractor_options att; /* --attractor-steps, --attractor-tol */
} export_args;

static int ends_with(const char *s, const char *suffix)
{
    const size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcmp(s + n - m, suffix) == 0;
}

/* No output may replace the file exported (or its -wal, -shm), another
 * output, or an array's JSON sidecar. */
static int outputs_apart(const cli *c, const export_args *a)
{
    char labels_json[CM_OUTPUT_PATH_MAX], steps_json[CM_OUTPUT_PATH_MAX], why[2048];
    export_sidecar_path(a->labels ? a->labels : "", labels_json, sizeof labels_json);
    export_sidecar_path(a->steps ? a->steps : "", steps_json, sizeof steps_json);
    const cm_file_use files[] = {
        {a->file, "the database", false, true},
        {a->groups, "--groups", true, false},
        {a->cells, "--cells", true, false},
        {a->flat, "--flat", true, true},
        {a->labels, "--labels", true, false},
        {a->labels ? labels_json : NULL, "--labels' JSON", true, false},
        {a->steps, "--steps", true, false},
        {a->steps ? steps_json : NULL, "--steps' JSON", true, false},
    };
    if (cm_files_apart(files, sizeof files / sizeof *files, why, sizeof why) != CM_OK)
        return cli_usage_error(c, "%s", why);
    return EXIT_OK;
}

static int parse_export(cli *c, export_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(export_help, stdout);
            return -1;
        } else if (cli_is(c, "--groups", true, &err)) {
            a->groups = c->value;
        } else if (cli_is(c, "--cells", true, &err)) {
            a->cells = c->value;
            if (a->cells && !ends_with(a->cells, ".csv") && !ends_with(a->cells, ".npy") &&
                !cm_output_names_stdout(a->cells))
                err = cli_usage_error(c, "--cells: '%s' must end in .csv or .npy (or be - for CSV "
                                         "on stdout)", a->cells);
        } else if (cli_is(c, "--flat", true, &err)) {
            a->flat = c->value;
        } else if (cli_is(c, "--labels", true, &err) || cli_is(c, "--steps", true, &err)) {
            const bool labels = strncmp(c->opt, "--labels", 8) == 0;
            if (c->value && !ends_with(c->value, ".npy"))
                err = cli_usage_error(c, "%s: '%s' must end in .npy (its JSON sidecar goes "
                                         "beside it)", labels ? "--labels" : "--steps", c->value);
            *(labels ? &a->labels : &a->steps) = c->value;
        } else if (cli_is(c, "--window", true, &err)) {
            a->window = c->value;
        } else if (by_option_take(c, &a->by, &err)) {
        } else if (attractor_options_take(c, &a->att, &err)) {
        } else if (cli_take_mem(c, &a->mem, &err)) {
        } else if (cli_is(c, "--quiet", false, &err)) {
            a->quiet = true;
        } else if (c->opt[0] != '-' && !a->file) {
            a->file = c->opt;
        } else {
            err = cli_stray(c);
        }
    }
    if (!err && !a->file)
        err = cli_usage_error(c, "which file? usage: cellmap export FILE.cmdb --cells OUT.csv");
    if (!err && !a->groups && !a->cells && !a->flat && !a->labels && !a->steps)
        err = cli_usage_error(c,
                              "nothing to export: add --groups, --cells, --flat, --labels or --steps");
    if (!err && a->window && !a->cells && !a->flat && !a->labels && !a->steps)
        err = cli_usage_error(c, "--window applies to --cells, --flat, --labels and --steps");
    const char *const outs[3] = {a->groups, a->cells, a->flat};
    int to_stdout = 0;
    for (int k = 0; k < 3; k++)
        to_stdout += outs[k] && cm_output_names_stdout(outs[k]);
    if (!err && to_stdout > 1)
        err = cli_usage_error(c, "only one of --groups, --cells and --flat can go to stdout");
    return err ? err : outputs_apart(c, a);
}

static int export_failed(const char *msg, cm_status st)
{
    fprintf(stderr, "cellmap export: %s\n", msg);
    return st == CM_ECANCELED ? EXIT_INTERRUPTED : EXIT_FAIL;
}

/* Every output but --groups alone, from the file's cluster. */
static int run_export(const cli *cl, const export_args *a, cm_store *s, const cm_store_info *info,
                      cm_cluster *c)
{
    char msg[1024];
    cm_box window;
    if (a->window && export_window(c, a->window, &window, msg, sizeof msg) != CM_OK)
        return cli_usage_error(cl, "%s", msg);
    exporter x;
    cm_status st = exporter_open(&x, s, info, c, a->window ? &window : NULL, a->file, &a->att,
                                 msg, sizeof msg);
    if (st == CM_OK && a->groups)
        st = export_groups(&x, a->groups, msg, sizeof msg);
    int rc = st == CM_OK ? EXIT_OK : export_failed(msg, st);
    progress pr;
    interrupt_catch();
    const work_hooks hooks = progress_hooks(&pr);
    if (rc == EXIT_OK && (a->cells || a->flat)) {
        uint64_t rows = 0;
        progress_start(&pr, "export", "cells", cm_box_cells(&x.window), a->quiet);
        st = export_cells(&x, a->cells, a->flat, &hooks, &rows, msg, sizeof msg);
        progress_end(&pr);
        if (st != CM_OK)
            rc = export_failed(msg, st);
        else if (!a->quiet)
            fprintf(report_stream(a->groups, a->cells, a->flat), "exported %llu cells\n",
                    (unsigned long long)rows);
    }
    if (rc == EXIT_OK && (a->labels || a->steps)) {
        progress_start(&pr, "export", "cells", cm_box_cells(&x.window), a->quiet);
        st = export_arrays(&x, a->labels, a->steps, a->by == BY_GROUPS, &hooks, msg, sizeof msg);
        progress_end(&pr);
        if (st != CM_OK)
            rc = export_failed(msg, st);
    }
    exporter_close(&x);
    return rc;
}

int cmd_export(int argc, char **argv)
{
    cli c = {"export", argc, argv, 0, NULL, NULL};
    export_args a;
    memset(&a, 0, sizeof a);
    a.mem = UINT64_C(256) << 20;
    const int rc = parse_export(&c, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;
    const char *const outs[] = {a.groups, a.cells, a.flat, a.labels, a.steps};
    int werr = cli_input_check("export", a.file);
    if (werr == EXIT_OK)
        werr = outfiles_check("export", outs, 5);
    if (werr != EXIT_OK)
        return werr;
    if (a.groups && !a.cells && !a.flat && !a.labels && !a.steps && !a.window) {
        /* the groups are records: the cluster (its node tables, open
         * nodes) is loaded only to find attractors the file lacks */
        char msg[1024];
        const cm_status st = export_groups_of_file(a.file, a.groups, &a.att, msg, sizeof msg);
        if (st != CM_ENOTFOUND)
            return st == CM_OK ? EXIT_OK : export_failed(msg, st);
    }
    cm_store *s = NULL;
    cm_store_info info;
    cm_cluster cl;
    if (cli_open_read("export", a.file, a.mem, &s, &info, &cl) != EXIT_OK)
        return EXIT_FAIL;
    const int result = run_export(&c, &a, s, &info, &cl);
    project_close(s, &cl);
    return result;
}

int cmd_export_in(int argc, char **argv, session *open)
{
    cli c = {"export", argc, argv, 0, NULL, NULL};
    export_args a;
    memset(&a, 0, sizeof a);
    const int rc = parse_export(&c, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;
    const char *const outs[] = {a.groups, a.cells, a.flat, a.labels, a.steps};
    const int werr = outfiles_check("export", outs, 5);
    if (werr != EXIT_OK)
        return werr;
    char msg[1024];
    cm_store_info info;
    if (session_records(open, &info, msg, sizeof msg) != CM_OK)
        return export_failed(msg, CM_EIO);
    return run_export(&c, &a, open->store, &info, &open->c);
}
