#include "src/outfile.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "render/gl_loader.h"

int outfile_check(const char *cmd, const char *path, bool needs_regular)
{
    char msg[CM_OUTPUT_PATH_MAX + 256];
    cm_output o;
    if (!path)
        return EXIT_OK;
    const cm_status st = cm_output_begin(&o, path, needs_regular, msg, sizeof msg);
    cm_output_abandon(&o);
    if (st == CM_OK)
        return EXIT_OK;
    fprintf(stderr, "cellmap %s: %s\n", cmd, msg);
    return st == CM_EINVAL ? EXIT_USAGE : EXIT_FAIL;
}

int outfiles_check(const char *cmd, const char *const *paths, int n)
{
    for (int k = 0; k < n; k++) {
        const int rc = outfile_check(cmd, paths[k], false);
        if (rc != EXIT_OK)
            return rc;
    }
    return EXIT_OK;
}

int chart_png_check(const char *cmd, const char *path)
{
    char msg[1024];
    const int rc = outfile_check(cmd, path, false);
    if (rc != EXIT_OK)
        return rc;
    if (path && cm_gl_load(msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "cellmap %s: %s\n", cmd, msg);
        return EXIT_FAIL;
    }
    return EXIT_OK;
}

int chart_outputs_writable(const cli *c, const chart_outputs *o)
{
    const int rc = outfile_check(c->cmd, o->csv, false);
    return rc != EXIT_OK ? rc : chart_png_check(c->cmd, o->png);
}

bool outfile_open(const char *cmd, const char *path, outfile *o)
{
    char msg[CM_OUTPUT_PATH_MAX + 256];
    o->f = NULL;
    if (cm_output_begin(&o->out, path, false, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "cellmap %s: %s\n", cmd, msg);
        return false;
    }
    o->f = fopen(o->out.tmp, "w");
    if (!o->f) {
        cm_output_fail(path, errno, msg, sizeof msg);
        fprintf(stderr, "cellmap %s: %s\n", cmd, msg);
        cm_output_abandon(&o->out);
    }
    return o->f != NULL;
}

bool outfile_close(const char *cmd, outfile *o, bool ok)
{
    char msg[CM_OUTPUT_PATH_MAX + 256];
    cm_status st = cm_output_close_stream(&o->out, o->f, msg, sizeof msg);
    if (ok && st == CM_OK)
        st = cm_output_commit(&o->out, msg, sizeof msg);
    if (ok && st != CM_OK) {
        fprintf(stderr, "cellmap %s: %s\n", cmd, msg);
        ok = false;
    }
    cm_output_abandon(&o->out);
    return ok;
}

bool write_chart_png(const char *cmd, const char *path, const cm_chart *charts, int n_charts,
                     const cm_png_text *texts, int n_texts)
{
    char msg[512];
    const int width = charts[0].width;
    int height = 0;
    for (int k = 0; k < n_charts; k++)
        height += charts[k].height;
    uint8_t *rgba = malloc((size_t)width * (size_t)height * 4);
    cm_png_text all[16];
    int n = 0;
    all[n++] = (cm_png_text){"Software", "cellmap " CELLMAP_VERSION};
    for (int k = 0; k < n_texts && n < 16; k++)
        all[n++] = texts[k];
    cm_status st =
        rgba ? CM_OK : cm_fail(CM_ENOMEM, msg, sizeof msg, "out of memory for the image");
    /* Stacked panels start their plots at the same x, the widest labels'
     * margin, so that a parameter value lines up in every panel. */
    int left = 0;
    for (int k = 0; k < n_charts && st == CM_OK; k++) {
        cm_chart_info info;
        st = cm_chart_layout(&charts[k], &info, msg, sizeof msg);
        left = info.plot_x > left ? info.plot_x : left;
    }
    /* row 0 is the top: each panel is the next block of rows, all drawn
     * with one GL context */
    cm_gl *gl = NULL;
    if (st == CM_OK)
        st = cm_gl_open(&gl, msg, sizeof msg);
    size_t row = 0;
    for (int k = 0; k < n_charts && st == CM_OK; k++) {
        cm_chart panel = charts[k];
        cm_chart_info info;
        panel.min_left = left;
        st = cm_chart_draw(&panel, gl, rgba + row * (size_t)width * 4, &info, msg, sizeof msg);
        row += (size_t)charts[k].height;
    }
    cm_gl_close(gl);
    if (st == CM_OK)
        st = cm_png_write(path, rgba, width, height, all, n, msg, sizeof msg);
    free(rgba);
    if (st != CM_OK)
        fprintf(stderr, "cellmap %s: %s\n", cmd, msg);
    return st == CM_OK;
}
