/* cellmap render: a figure (or an indexed image) of any view of a .cmdb
 * cluster database, without computing anything. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "src/args.h"
#include "lib/attractor_report.h"
#include "src/attractor_opts.h"
#include "src/outfile.h"
#include "src/figure_opts.h"
#include "src/commands.h"
#include "src/interrupt.h"
#include "src/progress.h"
#include "lib/project.h"

static const char render_help[] =
    "usage: cellmap render FILE.cmdb --png OUT.png|--svg|--pdf OUT [--view X0:X1,Y0:Y1] [--slice Z[,W...]]\n"
    "                      [--size WxH] [--layers L,...] [--png-mode rgb|indexed] [--mem BYTES]\n"
    "                      [--quiet]\n\n"
    "Draws the basins of a cluster database (made by solve --db or explore). Cells of the\n"
    "view that were never computed are drawn as not computed.\n\n"
    "  --png FILE          the image (written to a temporary file, renamed)\n" PNG_OPTIONS_HELP;
/* two strings: one would pass the 4095 characters C11 promises a literal */
static const char render_help_rest[] =
    "  --view's default here: the view the last explore session saved, else the cluster's\n"
    "  bounding box\n"
    "  --slice Z,...       models of more than two dimensions: the point of dimensions\n"
    "                      3.. the 2-D slice passes through (default: the cluster's middle)\n"
    BY_OPTION_HELP ATTRACTOR_OPTIONS_HELP
    "  --mem BYTES         cell arrays to hold in memory while reading (default 256M)\n"
    "  --quiet             no progress line while the view's cells are read\n";

typedef struct render_args {
    const char *file;
    png_opts png;
    cm_attractor_options att; /* --attractor-steps, --attractor-tol */
    const char *slice_text;
    uint64_t mem;
    bool quiet;
} render_args;

static int parse_render(cli *c, render_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(render_help, stdout);
            fputs(render_help_rest, stdout);
            return -1;
        } else if (png_opts_take(c, &a->png, &err)) {
        } else if (attractor_options_take(c, &a->att, &err)) {
        } else if (cli_is(c, "--slice", true, &err)) {
            a->slice_text = c->value;
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
        err = cli_usage_error(c, "which file? usage: cellmap render FILE.cmdb --png OUT.png");
    if (!err && !png_opts_draws(&a->png))
        err = cli_usage_error(c, "where to? add --png OUT.png (or --svg OUT.svg, --pdf OUT.pdf)");
    if (!err)
        err = png_opts_check(c, &a->png);
    char why[2048];
    if (!err && !png_opts_apart(&a->png, a->file, false, why, sizeof why))
        err = cli_usage_error(c, "%s", why);
    return err;
}

/* The figure of the file's view: the problem said, and the exit status. */
static int run_render(const cli *c, const render_args *a, cm_store *s, const cm_store_info *info,
                      cm_cluster *cl)
{
    char msg[1024];
    double lo[2], hi[2];
    cm_box box;
    cm_status st = figure_file_view(s, cl, &a->png, a->slice_text, lo, hi, &box, msg, sizeof msg);
    if (st != CM_OK)
        return cli_usage_error(c, "%s", msg);
    progress pr;
    progress_start(&pr, "render", "cells", cm_box_cells(&box), a->quiet);
    interrupt_catch();
    const work_hooks hooks = progress_hooks(&pr);
    st = figure_of_file(s, info, cl, a->file, &a->png, &box, lo, hi, &a->att, &hooks, msg,
                        sizeof msg);
    progress_end(&pr);
    if (st == CM_ECANCELED) {
        fprintf(stderr, "cellmap render: interrupted (Ctrl-C) while reading the view; nothing "
                        "written\n");
        return EXIT_INTERRUPTED;
    }
    if (st != CM_OK) {
        fprintf(stderr, "cellmap render: %s\n", msg);
        return EXIT_FAIL;
    }
    return EXIT_OK;
}

int cmd_render(int argc, char **argv)
{
    cli c = {"render", argc, argv, 0, NULL, NULL};
    render_args a;
    memset(&a, 0, sizeof a);
    a.mem = UINT64_C(256) << 20;
    const int rc = parse_render(&c, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;
    const char *const outs[] = {a.png.path, a.png.svg, a.png.pdf};
    int werr = cli_input_check("render", a.file);
    if (werr == EXIT_OK)
        werr = outfiles_check("render", outs, 3);
    if (werr != EXIT_OK)
        return werr;
    cm_store *s = NULL;
    cm_store_info info;
    cm_cluster cl;
    if (cli_open_read("render", a.file, a.mem, &s, &info, &cl) != EXIT_OK)
        return EXIT_FAIL;
    const int result = run_render(&c, &a, s, &info, &cl);
    project_close(s, &cl);
    return result;
}
