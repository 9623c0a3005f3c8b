/* src/outfile.c - the command's output files (src/outfile.h): lib/outfile.h,
 * with the problem said as "cellmap CMD: ..." and an exit status. */
#include "src/outfile.h"

static int said(const char *cmd, const char *msg, int rc)
{
    fprintf(stderr, "cellmap %s: %s\n", cmd, msg);
    return rc;
}

int outfile_check(const char *cmd, const char *path, bool needs_regular)
{
    char msg[CM_OUTPUT_PATH_MAX + 256];
    const cm_status st = outfile_check_path(path, needs_regular, msg, sizeof msg);
    if (st == CM_OK)
        return EXIT_OK;
    return said(cmd, msg, st == CM_EINVAL ? EXIT_USAGE : EXIT_FAIL);
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
    char msg[CM_OUTPUT_PATH_MAX + 256];
    const cm_status st = outfile_check_chart(path, msg, sizeof msg);
    if (st == CM_OK)
        return EXIT_OK;
    return said(cmd, msg, st == CM_EINVAL ? EXIT_USAGE : EXIT_FAIL);
}

int chart_outputs_writable(const cli *c, const chart_outputs *o)
{
    const int rc = outfile_check(c->cmd, o->csv, false);
    return rc != EXIT_OK ? rc : chart_png_check(c->cmd, o->png);
}

int analysis_said(const char *cmd, cm_status st, const char *msg)
{
    if (st == CM_OK)
        return EXIT_OK;
    return said(cmd, msg, st == CM_EINVAL ? EXIT_USAGE : EXIT_FAIL);
}

bool outfile_open(const char *cmd, const char *path, outfile *o)
{
    char msg[CM_OUTPUT_PATH_MAX + 256];
    return outfile_begin(path, o, msg, sizeof msg) == CM_OK || said(cmd, msg, 0);
}

bool outfile_close(const char *cmd, outfile *o, bool ok)
{
    char msg[CM_OUTPUT_PATH_MAX + 256];
    const cm_status st = outfile_end(o, ok, msg, sizeof msg);
    if (ok && st != CM_OK)
        said(cmd, msg, 0);
    return ok && st == CM_OK;
}

bool write_chart_png(const char *cmd, const char *path, const cm_chart *charts, int n_charts,
                     const cm_png_text *texts, int n_texts)
{
    char msg[CM_OUTPUT_PATH_MAX + 256];
    return outfile_charts(path, charts, n_charts, texts, n_texts, msg, sizeof msg) == CM_OK ||
           said(cmd, msg, 0);
}
