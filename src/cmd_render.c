/* cellmap render: a figure (or an indexed image) of any view of a .cmdb
 * cluster database, without computing anything. */
#include <math.h>
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
    "usage: cellmap render FILE.cmdb --png OUT.png|--svg OUT.svg [--view X0:X1,Y0:Y1] [--slice Z[,W...]]\n"
    "                      [--size WxH] [--layers L,...] [--png-mode rgb|indexed] [--mem BYTES]\n"
    "                      [--quiet]\n\n"
    "Draws the basins of a cluster database (made by solve --db or explore). Cells of the\n"
    "view that were never computed are drawn as not computed.\n\n"
    "  --png FILE          the image (written to a temporary file, renamed)\n" PNG_OPTIONS_HELP
    "                      (default here: the view the last explore session saved, else\n"
    "                      the cluster's bounding box)\n"
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
    if (!err && !a->png.path && !a->png.svg)
        err = cli_usage_error(c, "where to? add --png OUT.png (or --svg OUT.svg)");
    if (!err)
        err = png_opts_check(c, &a->png);
    char why[2048];
    if (!err && !png_opts_apart(&a->png, a->file, false, why, sizeof why))
        err = cli_usage_error(c, "%s", why);
    return err;
}

/* The cells to draw: the view's rectangle, and the slice in dims 3... */
static int cells_to_draw(const cli *c, const render_args *a, cm_store *s, const cm_cluster *cl,
                         double lo[2], double hi[2], cm_box *box)
{
    const cm_lattice *lat = &cl->lat;
    cm_box bounds;
    cm_cluster_bounds(cl, &bounds);
    const int dims = lat->dim < 2 ? lat->dim : 2;
    if (a->png.has_view) {
        memcpy(lo, a->png.lo, 2 * sizeof *lo);
        memcpy(hi, a->png.hi, 2 * sizeof *hi);
    } else if (project_view_note(s, dims, lo, hi, (char[256]){0}, 256) != CM_OK) {
        cm_box_rect(lat, &bounds, dims, lo, hi);
    }
    if (lat->dim == 1)
        lo[1] = hi[1] = 0;
    view_cells(lat, lo, hi, &bounds, box);
    if (!a->slice_text)
        return EXIT_OK;
    double v[CM_MAX_DIM];
    int n = 0;
    if (!parse_doubles(a->slice_text, v, &n, CM_MAX_DIM) || n != lat->dim - 2)
        return cli_usage_error(c, "--slice: '%s' must be %d coordinate(s) of dimensions 3..",
                               a->slice_text, lat->dim > 2 ? lat->dim - 2 : 0);
    for (int d = 2; d < lat->dim; d++) {
        box->lo[d] = (int64_t)floor((v[d - 2] - lat->origin[d]) / lat->width[d]);
        box->hi[d] = box->lo[d] + 1;
    }
    return EXIT_OK;
}

/* The progress line while the view's cells are read, and Ctrl-C. */
static int reading(void *user, const char *phase, double fraction)
{
    progress *p = user;
    (void)phase;
    progress_say(p, (uint64_t)(fraction * (double)p->total), "reading the view");
    return interrupt_requested();
}

static int run_render(const cli *c, const render_args *a, cm_store *s, const cm_store_info *info,
                      cm_cluster *cl)
{
    char msg[1024];
    cm_model m;
    cm_region flat;
    cm_box box;
    double lo[2], hi[2];
    uint64_t sink = 0;
    memset(&flat, 0, sizeof flat);
    int rc = cells_to_draw(c, a, s, cl, lo, hi, &box);
    if (rc != EXIT_OK)
        return rc;
    cm_model_set set = {0};
    if (model_of_store(info, &set, &m, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "cellmap render: %s: %s\n", a->file, msg);
        return EXIT_FAIL;
    }
    cm_group_info *groups = calloc((size_t)cl->ngroups + 1, sizeof *groups);
    cm_status st = groups ? cm_store_groups(s, groups, cl->ngroups, &sink, msg, sizeof msg)
                          : cm_fail(CM_ENOMEM, msg, sizeof msg, "out of memory for groups");
    progress pr;
    progress_start(&pr, "render", "cells", cm_box_cells(&box), a->quiet);
    interrupt_catch();
    cm_attractor_set att;
    memset(&att, 0, sizeof att);
    cluster_ends ends;
    memset(&ends, 0, sizeof ends);
    if (st == CM_OK && a->png.by == BY_ATTRACTORS)
        st = cluster_ends_open(&ends, cl, msg, sizeof msg);
    if (st == CM_OK && a->png.by == BY_ATTRACTORS)
        st = file_attractors(s, info, &m, &ends, groups, &a->att, &att, msg, sizeof msg);
    if (st == CM_OK)
        st = cm_cluster_flatten_progress(cl, &box, &flat, reading, &pr, msg, sizeof msg);
    progress_end(&pr);
    rc = EXIT_FAIL;
    if (st == CM_ECANCELED) {
        fprintf(stderr, "cellmap render: interrupted (Ctrl-C) while reading the view; nothing "
                        "written\n");
        rc = EXIT_INTERRUPTED;
    } else if (st != CM_OK) {
        fprintf(stderr, "cellmap render: %s\n", msg);
    } else {
        const basin_png png = {&a->png, &m, &cl->lat, &flat, groups, {lo[0], lo[1]},
                               {hi[0], hi[1]}, NULL, a->png.by == BY_ATTRACTORS ? &att : NULL,
                               &ends.computed, NULL};
        rc = write_basin_png("render", &png);
    }
    cm_region_free(&flat);
    cluster_ends_close(&ends);
    cm_attractors_free(&att);
    free(groups);
    cm_model_release(&m);
    return rc;
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
    const char *const outs[] = {a.png.path, a.png.svg};
    int werr = cli_input_check("render", a.file);
    if (werr == EXIT_OK)
        werr = outfiles_check("render", outs, 2);
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
