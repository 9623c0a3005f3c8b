#include "render/raster.h"

#include <math.h>
#include <omp.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "render/palette.h"

enum { STEP_BINS = 4096 }; /* step numbers above are counted as the last bin */

void cm_slice_of(const cm_lattice *lat, const cm_region *r, const int64_t *slice, int set_slice,
                 cm_slice *g)
{
    const cm_box *b = &r->box;
    int64_t cell[CM_MAX_DIM];
    for (int d = 0; d < b->dim; d++)
        cell[d] = d >= 2 && set_slice ? slice[d] : b->lo[d] + (b->hi[d] - b->lo[d]) / 2;
    cell[0] = b->lo[0];
    if (b->dim > 1)
        cell[1] = b->lo[1];
    g->nx = (uint64_t)(b->hi[0] - b->lo[0]);
    g->ny = b->dim > 1 ? (uint64_t)(b->hi[1] - b->lo[1]) : 1;
    g->base = cm_box_index(b, cell);
    g->row_stride = g->nx;
    g->x0 = lat->origin[0] + (double)b->lo[0] * lat->width[0];
    g->dx = lat->width[0];
    g->y0 = b->dim > 1 ? lat->origin[1] + (double)b->lo[1] * lat->width[1] : 0.0;
    g->dy = b->dim > 1 ? lat->width[1] : 1.0;
}

/* The step number at or below which 99 % of the computed cells lie: one
 * long transient must not wash out the shading of the rest. */
static uint32_t step_cap_of(const cm_region *r, const cm_slice *s)
{
    uint64_t *hist = calloc(STEP_BINS, sizeof *hist);
    if (!hist)
        return 1;
#pragma omp parallel for reduction(+ : hist[:STEP_BINS]) schedule(static)
    for (uint64_t j = 0; j < s->ny; j++)
        for (uint64_t i = 0; i < s->nx; i++) {
            const uint64_t k = s->base + j * s->row_stride + i;
            if (r->group[k] != CM_GROUP_NONE)
                hist[r->step[k] < STEP_BINS ? r->step[k] : STEP_BINS - 1]++;
        }
    uint64_t sum = 0, computed = 0;
    uint32_t cap = 1;
    for (uint32_t b = 0; b < STEP_BINS; b++)
        computed += hist[b];
    for (uint32_t b = 0; b < STEP_BINS && computed; b++) {
        sum += hist[b];
        if (100 * sum >= 99 * computed) {
            cap = b > 1 ? b : 1;
            break;
        }
    }
    free(hist);
    return cap;
}

uint16_t cm_step_shade(double f, int mode)
{
    return (uint16_t)lround(mode == CM_RASTER_STEPS ? 235.0 - 200.0 * f : 256.0 * (1.0 - 0.6 * f));
}

uint32_t cm_step_at(double f, uint32_t step_cap)
{
    return (uint32_t)lround(expm1(f * log1p((double)step_cap)));
}

/* Shade factors in 1/256 for steps 0..cap. */
static void shade_table(uint32_t cap, int mode, uint16_t *table)
{
    for (uint32_t t = 0; t <= cap; t++)
        table[t] = cm_step_shade(log1p((double)t) / log1p((double)cap), mode);
}

static void put_rgb(uint8_t *p, cm_rgb c)
{
    p[0] = c.r;
    p[1] = c.g;
    p[2] = c.b;
}

/* A class-mode pixel: the cell's colour class, periodic cells marked. */
static uint8_t class_of_cell(const cm_raster *ras, uint64_t k)
{
    const cm_region *r = ras->cells;
    const uint32_t grp = r->group[k];
    if (grp == CM_GROUP_NONE)
        return CM_CLASS_NOT_COMPUTED;
    const int cls = grp == 0 ? CM_CLASS_SINK : ras->classes[grp];
    const int marker = cls == CM_CLASS_STICKING ? CM_CLASS_STICKING_MARKER : CM_CLASS_MARKER;
    return (uint8_t)(cm_is_periodic(r, k) ? marker : cls);
}

void cm_raster_rgb(const cm_raster *ras, uint64_t k, uint8_t *p)
{
    const cm_region *r = ras->cells;
    const uint32_t grp = r->group[k];
    if (grp == CM_GROUP_NONE) {
        put_rgb(p, cm_colour_not_computed);
        return;
    }
    const uint8_t *c = ras->rgb + 3 * (size_t)grp;
    if (ras->mode == CM_RASTER_BASIN) {
        p[0] = c[0], p[1] = c[1], p[2] = c[2];
        return;
    }
    const uint16_t shade = ras->shade[r->step[k] < ras->step_cap ? r->step[k] : ras->step_cap];
    if (ras->mode == CM_RASTER_STEPS) {
        p[0] = p[1] = p[2] = (uint8_t)shade;
        return;
    }
    p[0] = (uint8_t)((c[0] * shade) >> 8);
    p[1] = (uint8_t)((c[1] * shade) >> 8);
    p[2] = (uint8_t)((c[2] * shade) >> 8);
}

void cm_raster_row_rgba(const cm_raster *ras, uint64_t line, const int64_t *col, int n,
                        uint8_t *px)
{
    if (ras->mode != CM_RASTER_BASIN) {
        for (int c = 0; c < n; c++)
            if (col[c] >= 0) {
                cm_raster_rgb(ras, line + (uint64_t)col[c], px + 4 * (size_t)c);
                px[4 * (size_t)c + 3] = 255;
            }
        return;
    }
    const uint32_t *group = ras->cells->group + line; /* flat colours: the group's alone */
    for (int c = 0; c < n; c++) {
        if (col[c] < 0)
            continue;
        const uint32_t g = group[col[c]];
        uint8_t *p = px + 4 * (size_t)c;
        if (g == CM_GROUP_NONE) {
            put_rgb(p, cm_colour_not_computed);
            p[3] = 255;
            continue;
        }
        const uint8_t *rgb = ras->rgb + 3 * (size_t)g;
        p[0] = rgb[0], p[1] = rgb[1], p[2] = rgb[2], p[3] = 255;
    }
}

/* The cells of each group in the slice, in parallel over rows: the
 * colours depend on which groups are in view. */
static void count_cells(const cm_region *r, cm_raster *ras)
{
    const cm_slice *s = &ras->s;
    const uint32_t n = r->ngroups + 1;
    uint64_t computed = 0;
#pragma omp parallel reduction(+ : computed)
    {
        uint64_t *mine = calloc(n, sizeof *mine); /* NULL: counted below instead */
#pragma omp for schedule(static)
        for (uint64_t j = 0; j < s->ny; j++)
            for (uint64_t i = 0; i < s->nx; i++) {
                const uint32_t g = r->group[s->base + j * s->row_stride + i];
                if (g != CM_GROUP_NONE) {
                    computed++;
                    if (mine)
                        mine[g]++;
                }
            }
#pragma omp critical
        {
            for (uint32_t g = 0; mine && g < n; g++)
                ras->group_cells[g] += mine[g];
            if (!mine)
                ras->group_cells[0] = UINT64_MAX; /* marks the counts invalid */
        }
        free(mine);
    }
    ras->computed = computed;
}

/* The pixels, in parallel over rows. */
static void fill(cm_raster *ras)
{
    const cm_slice *s = &ras->s;
    const bool classes = ras->mode == CM_RASTER_CLASSES;
    const size_t bytes = classes ? 1 : 3;
#pragma omp parallel for schedule(static)
    for (uint64_t j = 0; j < s->ny; j++)
        for (uint64_t i = 0; i < s->nx; i++) {
            const uint64_t k = s->base + j * s->row_stride + i;
            uint8_t *p = ras->pixels + bytes * (j * s->nx + i);
            if (classes)
                *p = class_of_cell(ras, k);
            else
                cm_raster_rgb(ras, k, p);
        }
}

/* The classes of the groups in view, and what was folded into "other";
 * touching: NULL before the view's neighbours are known. */
static void classify_groups(const cm_lattice *lat, const cm_region *r, const cm_group_info *groups,
                            const cm_touching *touching, cm_raster *ras)
{
    ras->classes[0] = CM_CLASS_SINK;
    ras->colour_repeats =
        cm_palette_classes(ras->palette, groups, r->ngroups, lat, ras->group_cells + 1,
                           ras->min_basin, touching, ras->classes + 1);
    ras->other_groups = 0;
    ras->other_cells = 0;
    for (uint32_t g = 1; g <= r->ngroups; g++)
        if (ras->group_cells[g] && ras->classes[g] == CM_CLASS_OTHER) {
            ras->other_groups++;
            ras->other_cells += ras->group_cells[g];
        }
}

/* The periodic cells of rows [j0, j1) of the slice in order, appended to
 * *list (of *n, room for *cap). False: out of memory. */
static bool periodic_rows(const cm_region *r, const cm_slice *s, uint64_t j0, uint64_t j1,
                          cm_periodic_cell **list, uint64_t *n, uint64_t *cap)
{
    for (uint64_t j = j0; j < j1; j++)
        for (uint64_t i = 0; i < s->nx; i++) {
            const uint64_t k = s->base + j * s->row_stride + i;
            if (!cm_is_periodic(r, k))
                continue;
            if (*n == *cap) {
                *cap = *cap ? 2 * *cap : 1024;
                cm_periodic_cell *p = realloc(*list, *cap * sizeof *p);
                if (!p)
                    return false;
                *list = p;
            }
            (*list)[(*n)++] = (cm_periodic_cell){(uint32_t)i, (uint32_t)j, r->group[k]};
        }
    return true;
}

/* The periodic cells in slice order: each thread finds those of its rows,
 * and the threads' lists are joined in row order, so that the order does
 * not depend on the threads. */
static cm_status collect_periodic(const cm_region *r, cm_raster *ras, char *msg, size_t msg_size)
{
    const cm_slice *s = &ras->s;
    const int nt = omp_get_max_threads();
    cm_periodic_cell **part = calloc((size_t)nt, sizeof *part);
    uint64_t *count = calloc((size_t)nt, sizeof *count);
    int ok = part && count;
    if (ok) {
#pragma omp parallel num_threads(nt) reduction(&& : ok)
        {
            const uint64_t t = (uint64_t)omp_get_thread_num();
            const uint64_t threads = (uint64_t)omp_get_num_threads();
            uint64_t cap = 0;
            ok = periodic_rows(r, s, s->ny * t / threads, s->ny * (t + 1) / threads, &part[t],
                               &count[t], &cap);
        }
    }
    uint64_t total = 0;
    for (int t = 0; ok && t < nt; t++)
        total += count[t];
    ras->periodic = ok ? malloc((size_t)(total + 1) * sizeof *ras->periodic) : NULL;
    ok = ras->periodic != NULL;
    for (int t = 0; ok && t < nt; t++) {
        if (count[t])
            memcpy(ras->periodic + ras->nperiodic, part[t], (size_t)count[t] * sizeof *part[t]);
        ras->nperiodic += count[t];
    }
    for (int t = 0; part && t < nt; t++)
        free(part[t]);
    free(part);
    free(count);
    return ok ? CM_OK : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for periodic cells");
}

cm_status cm_raster_build(const cm_lattice *lat, const cm_region *r, const cm_group_info *groups,
                          const cm_slice *s, int mode, uint64_t min_basin,
                          const cm_palette *palette, cm_raster *ras, char *msg, size_t msg_size)
{
    memset(ras, 0, sizeof *ras);
    ras->s = *s;
    ras->mode = mode;
    ras->min_basin = min_basin;
    ras->palette = palette;
    ras->cells = r;
    if (s->nx > UINT32_MAX || s->ny > UINT32_MAX)
        return cm_fail(CM_EINVAL, msg, msg_size, "the slice is too large to draw");
    ras->group_cells = calloc((size_t)r->ngroups + 1, sizeof *ras->group_cells);
    ras->classes = calloc((size_t)r->ngroups + 1, 1);
    ras->rgb = malloc(3 * ((size_t)r->ngroups + 1));
    cm_status st = CM_OK;
    if (!ras->group_cells || !ras->classes || !ras->rgb)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a %llux%llu raster",
                     (unsigned long long)s->nx, (unsigned long long)s->ny);
    if (st == CM_OK) {
        count_cells(r, ras);
        if (ras->group_cells[0] == UINT64_MAX)
            st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for basin counts");
    }
    if (st == CM_OK) {
        classify_groups(lat, r, groups, NULL, ras);
        ras->step_cap = mode == CM_RASTER_SHADED || mode == CM_RASTER_STEPS ? step_cap_of(r, s) : 1;
        st = collect_periodic(r, ras, msg, msg_size);
    }
    if (st != CM_OK)
        cm_raster_free(ras);
    return st;
}

/* Whether two or more groups in view take palette colours (else no
 * neighbour can be too close to another). */
static bool several_coloured(const cm_region *r, const cm_raster *ras)
{
    uint32_t coloured = 0;
    for (uint32_t g = 1; g <= r->ngroups && coloured < 2; g++)
        coloured += ras->group_cells[g] && ras->classes[g] >= CM_CLASS_FIRST_GROUP;
    return coloured >= 2 || (coloured == 1 && ras->group_cells[0]);
}

cm_status cm_raster_choose(const cm_lattice *lat, const cm_region *r, const cm_group_info *groups,
                           uint32_t reach_x, uint32_t reach_y, cm_raster *ras, char *msg,
                           size_t msg_size)
{
    const cm_slice *s = &ras->s;
    cm_status st = CM_OK;
    if (ras->mode != CM_RASTER_STEPS && several_coloured(r, ras)) {
        cm_touching touching;
        st = cm_touching_collect(r->group + s->base, s->nx, s->ny, s->row_stride, reach_x, reach_y,
                                 &touching, msg, msg_size);
        if (st == CM_OK)
            classify_groups(lat, r, groups, &touching, ras);
        cm_touching_free(&touching);
    }
    if (st != CM_OK)
        return st;
    free(ras->shade);
    ras->shade = malloc(((size_t)ras->step_cap + 1) * sizeof *ras->shade);
    if (!ras->shade)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for shades");
    shade_table(ras->step_cap, ras->mode, ras->shade);
    for (uint32_t g = 0; g <= r->ngroups; g++)
        put_rgb(ras->rgb + 3 * (size_t)g, cm_class_colour(ras->palette, ras->classes[g]));
    return CM_OK;
}

cm_status cm_raster_paint(const cm_lattice *lat, const cm_region *r, const cm_group_info *groups,
                          uint32_t reach_x, uint32_t reach_y, cm_raster *ras, char *msg,
                          size_t msg_size)
{
    const cm_status st = cm_raster_choose(lat, r, groups, reach_x, reach_y, ras, msg, msg_size);
    if (st != CM_OK)
        return st;
    free(ras->pixels);
    ras->pixels = malloc(ras->s.nx * ras->s.ny * (ras->mode == CM_RASTER_CLASSES ? 1 : 3));
    if (!ras->pixels)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a %llux%llu raster",
                       (unsigned long long)ras->s.nx, (unsigned long long)ras->s.ny);
    fill(ras);
    return CM_OK;
}

void cm_raster_free(cm_raster *ras)
{
    free(ras->pixels);
    free(ras->rgb);
    free(ras->shade);
    free(ras->periodic);
    free(ras->group_cells);
    free(ras->classes);
    memset(ras, 0, sizeof *ras);
}
