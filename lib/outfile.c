/* lib/outfile.c - output files written whole or not at all (lib/outfile.h). */
#include "lib/outfile.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "render/gl_loader.h"
#include "render/pdf.h"
#include "render/svg.h"

/* A chart's file format by its name's ending: .svg, .pdf, else PNG. */
typedef enum chart_format { CHART_PNG, CHART_SVG, CHART_PDF } chart_format;

static chart_format format_of(const char *path)
{
    const size_t n = path ? strlen(path) : 0;
    if (n > 4 && strcasecmp(path + n - 4, ".svg") == 0)
        return CHART_SVG;
    if (n > 4 && strcasecmp(path + n - 4, ".pdf") == 0)
        return CHART_PDF;
    return CHART_PNG;
}

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
    const chart_format format = format_of(path);
    return format == CHART_PNG ? cm_gl_load(msg, msg_size)
           : format == CHART_PDF ? cm_pdf_load(msg, msg_size)
                                 : CM_OK;
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

/* At most this many pixels a cell in a PDF's rasters (about twice the
 * pixels a cell covers on the page). */
enum { PDF_CELL_PIXELS = 16 };

cm_status outfile_vector(const char *path, bool pdf, svg_writer write, const void *user,
                         char *msg, size_t msg_size)
{
    char *svg = NULL;
    size_t bytes = 0;
    FILE *mem = pdf ? open_memstream(&svg, &bytes) : NULL;
    if (pdf && !mem)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the PDF's SVG");
    outfile o;
    cm_status st = outfile_begin(path, &o, msg, msg_size);
    if (st == CM_OK)
        st = write(pdf ? mem : o.f, user, pdf ? PDF_CELL_PIXELS : 1, msg, msg_size);
    if (mem && fclose(mem) != 0 && st == CM_OK)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the PDF's SVG");
    if (st == CM_OK && pdf)
        st = cm_pdf_from_svg(svg, bytes, o.f, msg, msg_size);
    free(svg);
    if (!o.f) /* outfile_begin failed */
        return st;
    const cm_status end = outfile_end(&o, st == CM_OK, st == CM_OK ? msg : (char[64]){0},
                                      st == CM_OK ? msg_size : 64);
    return st != CM_OK ? st : end;
}

/* Stacked charts and their texts, for charts_svg. */
typedef struct chart_stack {
    const cm_chart *charts;
    int n, width, height;
    const cm_png_text *texts;
    int n_texts;
} chart_stack;

/* The charts one below the other as an SVG document (pixel units); the
 * texts as its description. */
static cm_status charts_svg(FILE *f, const void *user, int cell_pixels, char *msg,
                            size_t msg_size)
{
    const chart_stack *c = user;
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" "
               "width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\" "
               "font-family=\"DejaVu Sans, sans-serif\">\n<desc>",
            c->width, c->height, c->width, c->height);
    for (int k = 0; k < c->n_texts; k++) {
        fprintf(f, "%s%s: ", k ? "; " : "", c->texts[k].key);
        cm_svg_escaped(f, c->texts[k].value);
    }
    fputs("</desc>\n", f);
    cm_status st = CM_OK;
    for (int k = 0, top = 0; k < c->n && st == CM_OK; top += c->charts[k].height, k++)
        st = cm_chart_svg(&c->charts[k], k, top, cell_pixels, f, msg, msg_size);
    fputs("</svg>\n", f);
    return st;
}

/* The panels drawn with one GL context, row 0 at the top, into a PNG. */
static cm_status charts_png(const char *path, const chart_stack *c, char *msg, size_t msg_size)
{
    uint8_t *rgba = cm_cells_array((size_t)c->width * (size_t)c->height * 4);
    cm_status st = rgba ? CM_OK : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the image");
    cm_gl *gl = NULL;
    if (st == CM_OK)
        st = cm_gl_open(&gl, msg, msg_size);
    size_t row = 0;
    for (int k = 0; k < c->n && st == CM_OK; k++) {
        cm_chart_info info;
        st = cm_chart_draw(&c->charts[k], gl, rgba + row * (size_t)c->width * 4, &info, msg,
                           msg_size);
        row += (size_t)c->charts[k].height;
    }
    cm_gl_close(gl);
    if (st == CM_OK)
        st = cm_png_write(path, rgba, c->width, c->height, 0, c->texts, c->n_texts, msg,
                          msg_size);
    free(rgba);
    return st;
}

cm_status outfile_charts(const char *path, const cm_chart *charts, int n_charts,
                         const cm_png_text *texts, int n_texts, char *msg, size_t msg_size)
{
    cm_png_text all[16];
    int n = 0;
    all[n++] = (cm_png_text){"Software", "cellmap " CELLMAP_VERSION};
    for (int k = 0; k < n_texts && n < 16; k++)
        all[n++] = texts[k];
    cm_chart *panels = malloc((size_t)n_charts * sizeof *panels);
    if (!panels)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the charts");
    /* Stacked panels start their plots at the same x, the widest labels'
     * margin, so that a parameter value lines up in every panel. */
    int left = 0, height = 0;
    cm_status st = CM_OK;
    for (int k = 0; k < n_charts && st == CM_OK; k++) {
        cm_chart_info info;
        st = cm_chart_layout(&charts[k], &info, msg, msg_size);
        left = info.plot_x > left ? info.plot_x : left;
        height += charts[k].height;
    }
    for (int k = 0; k < n_charts; k++)
        panels[k] = charts[k], panels[k].min_left = left;
    chart_stack stack = {panels, n_charts, charts[0].width, height, all, n};
    const chart_format format = format_of(path);
    if (st == CM_OK)
        st = format == CHART_PNG ? charts_png(path, &stack, msg, msg_size)
                                 : outfile_vector(path, format == CHART_PDF, charts_svg, &stack,
                                                  msg, msg_size);
    free(panels);
    return st;
}
