#include "src/basin_png.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/store.h"
#include "render/basin.h"
#include "render/png_out.h"
#include "src/args.h"

enum { MAX_DEFAULT_SIDE = 4096 };

void default_image_size(const cm_lattice *lat, const cm_box *box, int *width, int *height)
{
    const uint64_t nx = (uint64_t)(box->hi[0] - box->lo[0]);
    const uint64_t ny = lat->dim > 1 ? (uint64_t)(box->hi[1] - box->lo[1]) : 64;
    const uint64_t most = nx > ny ? nx : ny;
    const double shrink = most > MAX_DEFAULT_SIDE ? (double)MAX_DEFAULT_SIDE / (double)most : 1.0;
    *width = (int)((double)nx * shrink + 0.5);
    *height = (int)((double)ny * shrink + 0.5);
    *width = *width < 1 ? 1 : *width;
    *height = *height < 1 ? 1 : *height;
}

void format_box(const cm_lattice *lat, const cm_box *box, char *out, size_t size)
{
    size_t used = 0;
    out[0] = 0;
    for (int d = 0; d < box->dim && used < size; d++)
        used += (size_t)snprintf(out + used, size - used, "%s%.9g:%.9g", d ? "," : "",
                                 lat->origin[d] + (double)box->lo[d] * lat->width[d],
                                 lat->origin[d] + (double)box->hi[d] * lat->width[d]);
}

static cm_status write_file(const basin_png *b, const cm_render_options *ro, const uint8_t *rgba,
                            char *msg, size_t msg_size)
{
    const cm_lattice *lat = b->lat;
    const cm_box *box = &b->cells->box;
    char params[2048], lattice[512], view[CM_MAX_DIM * 64 + 128], cells[CM_MAX_DIM * 64];
    cm_params_json(&b->model->values, params, sizeof params);
    snprintf(lattice, sizeof lattice, "origin %.17g,%.17g width %.17g,%.17g", lat->origin[0],
             lat->dim > 1 ? lat->origin[1] : 0.0, lat->width[0],
             lat->dim > 1 ? lat->width[1] : 0.0);
    format_box(lat, box, cells, sizeof cells);
    snprintf(view, sizeof view, "box %s cells %lldx%lld", cells,
             (long long)(box->hi[0] - box->lo[0]),
             lat->dim > 1 ? (long long)(box->hi[1] - box->lo[1]) : 1LL);
    if (ro->lo[0] != ro->hi[0]) {
        const size_t used = strlen(view);
        snprintf(view + used, sizeof view - used, " view %.9g:%.9g,%.9g:%.9g", ro->lo[0], ro->hi[0],
                 ro->lo[1], ro->hi[1]);
    }
    const cm_png_text texts[] = {{"Software", "cellmap " CELLMAP_VERSION},
                                 {"Model", b->model->name},
                                 {"Parameters", params},
                                 {"Lattice", lattice},
                                 {"View", view}};
    return cm_png_write(b->path, rgba, ro->width, ro->height, texts, 5, msg, msg_size);
}

int write_basin_png(const char *cmd, const basin_png *b)
{
    cm_render_options ro;
    memset(&ro, 0, sizeof ro);
    ro.width = b->width;
    ro.height = b->height;
    if (!ro.width || !ro.height)
        default_image_size(b->lat, &b->cells->box, &ro.width, &ro.height);
    memcpy(ro.lo, b->lo, sizeof ro.lo);
    memcpy(ro.hi, b->hi, sizeof ro.hi);
    ro.markers = 1;
    uint8_t *rgba = malloc((size_t)ro.width * (size_t)ro.height * 4);
    char msg[512];
    if (!rgba) {
        fprintf(stderr, "cellmap %s: out of memory for a %dx%d image\n", cmd, ro.width, ro.height);
        return EXIT_FAIL;
    }
    cm_status st = cm_render_basin(b->lat, b->cells, b->groups, &ro, rgba, msg, sizeof msg);
    if (st == CM_OK)
        st = write_file(b, &ro, rgba, msg, sizeof msg);
    free(rgba);
    if (st != CM_OK) {
        fprintf(stderr, "cellmap %s: %s\n", cmd, msg);
        return EXIT_FAIL;
    }
    return EXIT_OK;
}
