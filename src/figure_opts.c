/* src/figure_opts.c - the figure options (src/figure_opts.h). */
#include "src/figure_opts.h"

#include <stdio.h>
#include <string.h>

#include "lib/figure_args.h"
#include "src/attractor_opts.h"
#include "src/outfile.h"

bool png_opts_take(cli *c, png_opts *po, int *err)
{
    if (by_option_take(c, &po->by, err)) {
    } else if (cli_is(c, "--png", true, err)) {
        po->path = c->value;
    } else if (cli_is(c, "--svg", true, err)) {
        po->svg = c->value;
    } else if (cli_is(c, "--pdf", true, err)) {
        po->pdf = c->value;
    } else if (cli_take_size(c, 1, 1, CM_RENDER_MAX_SIDE, &po->width, &po->height, err)) {
    } else if (cli_take_int(c, "--legend", 1, 200, &po->legend_groups, err)) {
    } else {
        for (const char *const *name = png_value_options; *name; name++)
            if (cli_is(c, *name, true, err)) {
                char msg[1024];
                if (c->value && !png_opts_value(po, *name, c->value, msg, sizeof msg))
                    *err = cli_usage_error(c, "%s", msg);
                return true;
            }
        return false;
    }
    return true;
}

int png_opts_check(const cli *c, const png_opts *po)
{
    if (!po->path && !po->svg && !po->pdf &&
        (po->width || po->layers || po->indexed || po->min_basin || po->legend_groups ||
         po->palette || po->title || po->aspect || po->font_size || po->dpi))
        return cli_usage_error(c, "--size, --layers, --png-mode, --min-basin, --legend, "
                                  "--palette, --title, --aspect, --font-size and --dpi describe "
                                  "the image; add --png FILE (or --svg, --pdf FILE)");
    const char *ext = po->path ? strrchr(po->path, '.') : NULL;
    if (ext && (strcmp(ext, ".svg") == 0 || strcmp(ext, ".pdf") == 0))
        return cli_usage_error(c, "--png %s: a basin figure's --png is a PNG; use --%s %s",
                               po->path, ext + 1, po->path);
    if ((po->svg || po->pdf) && po->indexed)
        return cli_usage_error(c, "--svg and --pdf draw a figure; --png-mode indexed applies to "
                                  "--png only");
    if (po->indexed && (po->width || po->layers))
        return cli_usage_error(c, "--png-mode indexed draws one pixel per cell in colour "
                                  "classes; leave out --size and --layers");
    return EXIT_OK;
}

int check_basin_png(const char *cmd, const png_opts *po, const cm_model *m,
                    const cm_lattice *lat, const cm_box *box)
{
    char msg[512];
    const char *const outs[] = {po->path, po->svg, po->pdf};
    const int rc = outfiles_check(cmd, outs, 3);
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
