/* lib/figure_args.c - the figure options that take a value
 * (lib/figure_args.h). */
#include "lib/figure_args.h"

#include <stdio.h>
#include <string.h>

#include "cellmap/status.h"
#include "lib/parse.h"

const char *const png_value_options[] = {"--layers", "--png-mode", "--min-basin", "--aspect",
                                         "--title",  "--labels",   "--palette",   "--view",
                                         "--font-size", "--dpi",   NULL};

enum { FONT_POINTS_MAX = 96, DPI_MIN = 36, DPI_MAX = 2400 };

static bool bad(char *msg, size_t msg_size, const char *fmt, const char *value)
{
    cm_fail(CM_EINVAL, msg, msg_size, fmt, value);
    return false;
}

static bool take_view(png_opts *po, const char *value, char *msg, size_t msg_size)
{
    int n = 0;
    po->has_view = 1;
    if (parse_ranges(value, po->lo, po->hi, &n, 2) && n == 2 && po->lo[0] < po->hi[0] &&
        po->lo[1] < po->hi[1])
        return true;
    return bad(msg, msg_size, "--view: '%s' must be X0:X1,Y0:Y1 with X0 < X1, Y0 < Y1", value);
}

static bool take_number(const char *name, const char *value, double lo, double hi, double *out,
                        char *msg, size_t msg_size)
{
    if (parse_double(value, out) && *out >= lo && *out <= hi)
        return true;
    cm_fail(CM_EINVAL, msg, msg_size, "%s: '%s' must be a number from %g to %g", name, value, lo,
            hi);
    return false;
}

bool png_opts_value(png_opts *po, const char *name, const char *value, char *msg,
                    size_t msg_size)
{
    if (strcmp(name, "--layers") == 0) {
        char word[64];
        if (parse_layers(value, &po->layers, word, sizeof word))
            return true;
        return bad(msg, msg_size,
                   "--layers: unknown layer '%s' (use basin, steps, attractors, overlays, axes, "
                   "legend, title or all, separated by commas)",
                   word);
    }
    if (strcmp(name, "--png-mode") == 0)
        return parse_png_mode(value, &po->indexed) ||
               bad(msg, msg_size, "--png-mode: '%s' must be rgb or indexed", value);
    if (strcmp(name, "--min-basin") == 0) {
        int64_t v = 0;
        po->min_basin = parse_int64(value, &v) && v >= 1 ? (uint64_t)v : 0;
        return po->min_basin ||
               bad(msg, msg_size, "--min-basin: '%s' must be a whole number of cells, 1 or more",
                   value);
    }
    if (strcmp(name, "--aspect") == 0)
        return parse_aspect(value, &po->aspect) ||
               bad(msg, msg_size,
                   "--aspect: '%s' must be equal, auto or a ratio R (1e-6..1e6: a unit along y "
                   "drawn R times as long as one along x)",
                   value);
    if (strcmp(name, "--title") == 0) {
        po->title = value;
        if (strlen(value) <= 1000)
            return true;
        cm_fail(CM_EINVAL, msg, msg_size, "--title: %zu characters; give at most 1000",
                strlen(value));
        return false;
    }
    if (strcmp(name, "--labels") == 0 || strcmp(name, "--palette") == 0) {
        char why[512];
        const bool ok = strcmp(name, "--labels") == 0
                            ? png_opts_labels(value, po, why, sizeof why)
                            : png_opts_palette(value, po, why, sizeof why);
        if (!ok)
            cm_fail(CM_EINVAL, msg, msg_size, "%s: %s", name, why);
        return ok;
    }
    if (strcmp(name, "--view") == 0)
        return take_view(po, value, msg, msg_size);
    if (strcmp(name, "--font-size") == 0)
        return take_number(name, value, 1, FONT_POINTS_MAX, &po->font_size, msg, msg_size);
    if (strcmp(name, "--dpi") == 0)
        return take_number(name, value, DPI_MIN, DPI_MAX, &po->dpi, msg, msg_size);
    cm_fail(CM_EINVAL, msg, msg_size, "%s is no figure option", name);
    return false;
}
