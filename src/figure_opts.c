/* src/figure_opts.c - the figure options (src/figure_opts.h). */
#include "src/figure_opts.h"

#include <stdio.h>
#include <string.h>

#include "src/attractor_opts.h"
#include "src/outfile.h"

bool png_opts_take(cli *c, png_opts *po, int *err)
{
    if (by_option_take(c, &po->by, err)) {
    } else if (cli_is(c, "--png", true, err)) {
        po->path = c->value;
    } else if (cli_is(c, "--svg", true, err)) {
        po->svg = c->value;
    } else if (cli_take_size(c, 1, 1, CM_RENDER_MAX_SIDE, &po->width, &po->height, err)) {
    } else if (cli_is(c, "--layers", true, err)) {
        char bad[64];
        if (c->value && !parse_layers(c->value, &po->layers, bad, sizeof bad))
            *err = cli_usage_error(c,
                                   "--layers: unknown layer '%s' (use basin, steps, attractors, "
                                   "overlays, axes, legend, title or all, separated by commas)",
                                   bad);
    } else if (cli_is(c, "--png-mode", true, err)) {
        if (c->value && !parse_png_mode(c->value, &po->indexed))
            *err = cli_usage_error(c, "--png-mode: '%s' must be rgb or indexed", c->value);
    } else if (cli_is(c, "--min-basin", true, err)) {
        int64_t v = 0;
        if (c->value && (!parse_int64(c->value, &v) || v < 1))
            *err = cli_usage_error(c, "--min-basin: '%s' must be a whole number of cells, 1 or more",
                                   c->value);
        po->min_basin = (uint64_t)v;
    } else if (cli_take_int(c, "--legend", 1, 200, &po->legend_groups, err)) {
    } else if (cli_is(c, "--aspect", true, err)) {
        if (c->value && !parse_aspect(c->value, &po->aspect))
            *err = cli_usage_error(c,
                                   "--aspect: '%s' must be equal, auto or a ratio R (1e-6..1e6: a "
                                   "unit along y drawn R times as long as one along x)",
                                   c->value);
    } else if (cli_is(c, "--title", true, err)) {
        po->title = c->value;
        if (c->value && strlen(c->value) > 1000)
            *err = cli_usage_error(c, "--title: %zu characters; give at most 1000",
                                   strlen(c->value));
    } else if (cli_is(c, "--labels", true, err)) {
        char msg[512];
        if (c->value && !png_opts_labels(c->value, po, msg, sizeof msg))
            *err = cli_usage_error(c, "--labels: %s", msg);
    } else if (cli_is(c, "--palette", true, err)) {
        char msg[512];
        if (c->value && !png_opts_palette(c->value, po, msg, sizeof msg))
            *err = cli_usage_error(c, "--palette: %s", msg);
    } else if (cli_is(c, "--view", true, err)) {
        int n = 0;
        if (c->value && (!parse_ranges(c->value, po->lo, po->hi, &n, 2) || n != 2 ||
                         !(po->lo[0] < po->hi[0] && po->lo[1] < po->hi[1])))
            *err = cli_usage_error(c, "--view: '%s' must be X0:X1,Y0:Y1 with X0 < X1, Y0 < Y1",
                                   c->value);
        po->has_view = 1;
    } else {
        return false;
    }
    return true;
}

int png_opts_check(const cli *c, const png_opts *po)
{
    if (!po->path && !po->svg &&
        (po->width || po->layers || po->indexed || po->min_basin || po->legend_groups ||
         po->palette || po->title || po->aspect))
        return cli_usage_error(c, "--size, --layers, --png-mode, --min-basin, --legend, "
                                  "--palette, --title and --aspect describe the image; add --png "
                                  "FILE (or --svg FILE)");
    if (po->svg && po->indexed)
        return cli_usage_error(c, "--svg draws a figure; --png-mode indexed applies to --png "
                                  "only");
    if (po->indexed && (po->width || po->layers))
        return cli_usage_error(c, "--png-mode indexed draws one pixel per cell in colour "
                                  "classes; leave out --size and --layers");
    return EXIT_OK;
}

int check_basin_png(const char *cmd, const png_opts *po, const cm_model *m,
                    const cm_lattice *lat, const cm_box *box)
{
    char msg[512];
    const char *const outs[] = {po->path, po->svg};
    const int rc = outfiles_check(cmd, outs, 2);
    if (rc != EXIT_OK)
        return rc;
    if (figure_check_layout(po, m, lat, box, msg, sizeof msg) == CM_OK)
        return EXIT_OK;
    fprintf(stderr, "cellmap %s: %s\n", cmd, msg);
    return EXIT_FAIL;
}

int write_basin_png(const char *cmd, const basin_png *b)
{
    char msg[1024];
    if (figure_write(b, msg, sizeof msg) == CM_OK)
        return EXIT_OK;
    fprintf(stderr, "cellmap %s: %s\n", cmd, msg);
    return EXIT_FAIL;
}
