/* lib/outfile.c - output files written whole or not at all (lib/outfile.h). */
#include "lib/outfile.h"

#include <errno.h>
#include <stdlib.h>

#include "render/gl_loader.h"

cm_status outfile_check_path(const char *path, bool needs_regular, char *msg, size_t msg_size)
{
    cm_output o;
    if (!path)
        return CM_OK;
    const cm_status st = cm_output_begin(&o, path, needs_regular, msg, msg_size);
    cm_output_abandon(&o);
    return st;
}

cm_status outfile_check_chart(const char *path, char *msg, size_t msg_size)
{
    const cm_status st = outfile_check_path(path, false, msg, msg_size);
    if (st != CM_OK || !path)
        return st;
    return cm_gl_load(msg, msg_size);
}

cm_status outfile_begin(const char *path, outfile *o, char *msg, size_t msg_size)
{
    o->f = NULL;
    const cm_status st = cm_output_begin(&o->out, path, false, msg, msg_size);
    if (st != CM_OK)
        return st;
    o->f = fopen(o->out.tmp, "w");
    if (!o->f) {
        const cm_status failed = cm_output_fail(path, errno, msg, msg_size);
        cm_output_abandon(&o->out);
        return failed;
    }
    return CM_OK;
}

cm_status outfile_end(outfile *o, bool ok, char *msg, size_t msg_size)
{
    cm_status st = cm_output_close_stream(&o->out, o->f, msg, msg_size);
    if (ok && st == CM_OK)
        st = cm_output_commit(&o->out, msg, msg_size);
    cm_output_abandon(&o->out);
    return ok ? st : cm_fail(CM_ECANCELED, msg, msg_size, "not written: the work failed");
}

cm_status outfile_charts(const char *path, const cm_chart *charts, int n_charts,
                         const cm_png_text *texts, int n_texts, char *msg, size_t msg_size)
{
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
        rgba ? CM_OK : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the image");
    /* Stacked panels start their plots at the same x, the widest labels'
     * margin, so that a parameter value lines up in every panel. */
    int left = 0;
    for (int k = 0; k < n_charts && st == CM_OK; k++) {
        cm_chart_info info;
        st = cm_chart_layout(&charts[k], &info, msg, msg_size);
        left = info.plot_x > left ? info.plot_x : left;
    }
    /* row 0 is the top: each panel is the next block of rows, all drawn
     * with one GL context */
    cm_gl *gl = NULL;
    if (st == CM_OK)
        st = cm_gl_open(&gl, msg, msg_size);
    size_t row = 0;
    for (int k = 0; k < n_charts && st == CM_OK; k++) {
        cm_chart panel = charts[k];
        cm_chart_info info;
        panel.min_left = left;
        st = cm_chart_draw(&panel, gl, rgba + row * (size_t)width * 4, &info, msg, msg_size);
        row += (size_t)charts[k].height;
    }
    cm_gl_close(gl);
    if (st == CM_OK)
        st = cm_png_write(path, rgba, width, height, 0, all, n, msg, msg_size);
    free(rgba);
    return st;
}
