#include "cellmap/join_stage1.h"

#include <stdlib.h>
#include <string.h>

#include "cellmap/classify.h"
#include "cellmap/lattice.h"

/* Stage-1 values of a cell besides group ids */
#define UNSET UINT32_MAX
#define PENDING (UINT32_MAX - 1)

/* Where an exit to cell t leads in Stage 1: a group of the region holding
 * t (in the joint id space), PENDING into its sink domain, 0 beyond every
 * region. */
static uint32_t exit_value(const cm_region *regions, uint32_t n, const uint32_t *base,
                           uint32_t self, const int64_t *t)
{
    for (uint32_t m = 0; m < n; m++) {
        if (m == self || !cm_box_contains(&regions[m].box, t))
            continue;
        const uint32_t g = regions[m].group[cm_box_index(&regions[m].box, t)];
        return g && !cm_is_node_ref(g) ? base[m] + g : PENDING;
    }
    return 0;
}

/* The Stage-1 value of every cell of region k into val, reading only the
 * regions as solved: a chain of sink cells is walked once, up to a cell
 * with a value or the chain's exit, and every cell on it takes the value
 * found there (chains of sink cells never close: a cycle would be a group). */
static void region_values(const cm_region *regions, uint32_t n, const uint32_t *base, uint32_t k,
                          uint32_t *val, uint32_t *path)
{
    const cm_region *r = &regions[k];
    for (uint64_t i = 0; i < r->ncells; i++)
        val[i] = r->group[i] && !cm_is_node_ref(r->group[i]) ? base[k] + r->group[i] : UNSET;
    for (uint64_t i = 0; i < r->ncells; i++) {
        uint64_t len = 0, j = i;
        uint32_t v;
        for (;;) {
            if (val[j] != UNSET) {
                v = val[j];
                break;
            }
            path[len++] = (uint32_t)j;
            const uint32_t img = r->image[j];
            if (img < r->ncells) {
                j = img;
                continue;
            }
            const int64_t e = cm_image_exit_index(img);
            v = e >= 0 ? exit_value(regions, n, base, k, cm_region_exit(r, (uint64_t)e)) : 0;
            break;
        }
        while (len > 0)
            val[path[--len]] = v;
    }
}

static void count_case(uint32_t v, cm_stage1_stats *stats)
{
    stats->sink_cells++;
    if (v == PENDING)
        stats->pending++;
    else if (v == 0)
        stats->to_sink++;
    else
        stats->to_group++;
}

cm_status cm_join_stage1(cm_region *regions, uint32_t n, uint8_t **pending, cm_stage1_stats *stats,
                         char *msg, size_t msg_size)
{
    memset(stats, 0, sizeof *stats);
    uint64_t most = 0;
    for (uint32_t k = 0; k < n; k++) {
        if (!regions[k].exits_recorded)
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "region %u was solved without its exits; Stage 1 needs them", k);
        most = regions[k].ncells > most ? regions[k].ncells : most;
    }
    uint32_t *base = calloc(n + 1, sizeof *base), *path = malloc(most * sizeof *path);
    uint32_t **vals = calloc(n, sizeof *vals);
    cm_status st = base && path && vals ? CM_OK : CM_ENOMEM;
    for (uint32_t k = 0; k < n && st == CM_OK; k++) {
        base[k + 1] = base[k] + regions[k].ngroups;
        if (!(vals[k] = malloc(regions[k].ncells * sizeof **vals)))
            st = CM_ENOMEM;
    }
    /* every region's values from the regions as solved, then all written */
    for (uint32_t k = 0; k < n && st == CM_OK; k++)
        region_values(regions, n, base, k, vals[k], path);
    for (uint32_t k = 0; k < n && st == CM_OK; k++) {
        cm_region *r = &regions[k];
        for (uint64_t i = 0; i < r->ncells; i++) {
            const uint32_t v = vals[k][i];
            if (r->group[i] == 0 || cm_is_node_ref(r->group[i]))
                count_case(v, stats);
            if (pending)
                pending[k][i] = v == PENDING;
            r->group[i] = v == PENDING ? 0 : v;
        }
        r->ngroups = base[n];
    }
    for (uint32_t k = 0; vals && k < n; k++)
        free(vals[k]);
    free(vals);
    free(path);
    free(base);
    return st == CM_OK ? CM_OK : cm_fail(st, msg, msg_size, "out of memory for Stage 1");
}
