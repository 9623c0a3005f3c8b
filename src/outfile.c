#include "src/outfile.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

bool outfile_open(const char *cmd, const char *path, outfile *o)
{
    o->path = path;
    snprintf(o->tmp, sizeof o->tmp, "%s.tmp-%ld", path, (long)getpid());
    o->f = fopen(o->tmp, "w");
    if (!o->f)
        fprintf(stderr, "cellmap %s: cannot write %s: %s (does the directory exist?)\n", cmd, path,
                strerror(errno));
    return o->f != NULL;
}

bool outfile_close(const char *cmd, outfile *o, bool ok)
{
    ok = !ferror(o->f) && ok;
    ok = fclose(o->f) == 0 && ok;
    if (ok && rename(o->tmp, o->path) != 0) {
        fprintf(stderr, "cellmap %s: cannot rename %s to %s: %s\n", cmd, o->tmp, o->path,
                strerror(errno));
        ok = false;
    }
    if (!ok)
        remove(o->tmp);
    return ok;
}

bool write_chart_png(const char *cmd, const char *path, const cm_chart *chart,
                     const cm_png_text *texts, int n_texts)
{
    char msg[512];
    uint8_t *rgba = malloc((size_t)chart->width * (size_t)chart->height * 4);
    cm_png_text all[16];
    int n = 0;
    all[n++] = (cm_png_text){"Software", "cellmap " CELLMAP_VERSION};
    for (int k = 0; k < n_texts && n < 16; k++)
        all[n++] = texts[k];
    cm_chart_info info;
    cm_status st = rgba ? cm_chart_draw(chart, rgba, &info, msg, sizeof msg)
                        : cm_fail(CM_ENOMEM, msg, sizeof msg, "out of memory for the image");
    if (st == CM_OK)
        st = cm_png_write(path, rgba, chart->width, chart->height, all, n, msg, sizeof msg);
    free(rgba);
    if (st != CM_OK)
        fprintf(stderr, "cellmap %s: %s\n", cmd, msg);
    return st == CM_OK;
}
