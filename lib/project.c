/* lib/project.c - a .cmdb project as a whole (lib/project.h). */
#include "lib/project.h"

#include "cellmap/clock.h"

#include <math.h>
#include <stdbool.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cellmap/cover.h"
#include "cellmap/extend.h"
#include "models/ode_flow.h"
#include "models/registry.h"
#include "lib/parse.h"

cm_status project_open_records(const char *path, bool map_reads, cm_store **s,
                               cm_store_info *info, char *msg, size_t msg_size)
{
    cm_status st = cm_store_open(path, 0, s, msg, msg_size);
    if (st == CM_OK && map_reads)
        cm_store_map_reads(*s);
    if (st == CM_OK)
        st = cm_store_snapshot_begin(*s, msg, msg_size);
    if (st == CM_OK)
        st = cm_store_read_info(*s, info, msg, msg_size);
    if (st == CM_OK && info->regions == 0)
        st = cm_fail(CM_EINVAL, msg, msg_size, "%s holds no region yet", path);
    return st;
}

cm_status lattice_of_spec(const lattice_spec *spec, const cm_model *m, const cm_model_set *models,
                          cm_lattice *lat, cm_box *box, char *msg, size_t msg_size)
{
    const cm_model_entry *e = cm_model_set_find(models, m->name, NULL);
    const char *text = spec->region_text ? spec->region_text : e ? e->region : NULL;
    double low[CM_MAX_DIM], high[CM_MAX_DIM];
    int n = 0;
    if (!text)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a region is required for model %s (one LO:HI per dimension)", m->name);
    if (!parse_ranges(text, low, high, &n, CM_MAX_DIM))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the region '%s' is not LO:HI[,LO:HI...] with LO < HI", text);
    if (n != m->dim)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the region has %d range(s) but model %s has dimension %d", n, m->name,
                       m->dim);
    if (spec->n_cells && spec->n_cells != m->dim)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the cells give %d count(s) but model %s has dimension %d", spec->n_cells,
                       m->name, m->dim);
    memset(lat, 0, sizeof *lat);
    memset(box, 0, sizeof *box);
    lat->dim = box->dim = m->dim;
    double total = 1.0;
    for (int d = 0; d < m->dim; d++) {
        const int64_t cells = spec->n_cells ? spec->cells[d] : (m->dim <= 2 ? 1000 : 100);
        lat->origin[d] = low[d];
        lat->width[d] = (high[d] - low[d]) / (double)cells;
        box->hi[d] = cells;
        total *= (double)cells;
    }
    if (total > (double)CM_REGION_MAX_CELLS)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the cells ask for %.0f cells; one region holds at most %llu", total,
                       (unsigned long long)CM_REGION_MAX_CELLS);
    cm_status st = cm_lattice_check(lat, msg, msg_size);
    if (st == CM_OK)
        st = cm_model_check_box(m, lat, box, msg, msg_size);
    return st == CM_OK ? CM_OK : CM_EINVAL;
}

cm_status model_spec_build(const model_spec *spec, cm_model *m, char *msg, size_t msg_size)
{
    return cm_model_set_create(&spec->set, spec->name, spec->texts, spec->n_texts, m, msg,
                               msg_size);
}

cm_status model_spec_region(const model_spec *spec, int dim, double *lo, double *hi, char *msg,
                            size_t msg_size)
{
    const cm_model_entry *e = cm_model_set_find(&spec->set, spec->name, NULL);
    int n = 0;
    if (!e || !e->region || !parse_ranges(e->region, lo, hi, &n, CM_MAX_DIM) || n != dim)
        return cm_fail(CM_EINVAL, msg, msg_size, "model %s has no default region: give the start",
                       spec->name);
    return CM_OK;
}

cm_status model_spec_centre(const model_spec *spec, int dim, double *x, char *msg,
                            size_t msg_size)
{
    double lo[CM_MAX_DIM], hi[CM_MAX_DIM];
    const cm_status st = model_spec_region(spec, dim, lo, hi, msg, msg_size);
    for (int d = 0; d < dim && st == CM_OK; d++)
        x[d] = 0.5 * (lo[d] + hi[d]);
    return st;
}

int model_image(const cm_model *m, const double *x, double *y, double *flight)
{
    if (!cm_model_is_flow(m)) {
        *flight = NAN;
        return m->step(m, x, y);
    }
    double t_end;
    const int rc = cm_flow_map(m, x, y, &t_end, NULL);
    *flight = t_end - m->flow.t0;
    /* the engine's step takes states into periodic coordinates' periods */
    for (int d = 0; rc == CM_STEP_OK && d < m->dim; d++)
        y[d] = cm_model_wrap(m, d, y[d]);
    return rc;
}

const cm_model_lib *model_spec_lib(const model_spec *spec, const char *name)
{
    const cm_model_lib *lib = NULL;
    cm_model_set_find(&spec->set, name, &lib);
    return lib;
}

cm_status project_probe(const char *path, char *msg, size_t msg_size)
{
    return cm_store_probe(path, msg, msg_size);
}

cm_status project_open_cluster(const char *path, uint64_t mem_budget, cm_store **s,
                               cm_store_info *info, cm_cluster *c, char *msg, size_t msg_size)
{
    cm_cluster_init(c, &(cm_lattice){1, {0}, {1}});
    cm_status st = project_open_records(path, false, s, info, msg, msg_size);
    if (st == CM_OK)
        st = cm_store_load_cluster(*s, c, msg, msg_size);
    cm_store_snapshot_end(*s);
    if (st != CM_OK) {
        project_close(*s, c);
        *s = NULL;
        return st;
    }
    c->mem_budget = mem_budget;
    return CM_OK;
}

cm_status project_view_note(cm_store *s, int dims, double lo[2], double hi[2], char *slice,
                            size_t slice_size)
{
    char text[1024], ignored[64];
    slice[0] = '\0';
    if (cm_store_get_note(s, "note.explore.view", text, sizeof text, ignored, sizeof ignored) !=
        CM_OK)
        return CM_ENOTFOUND;
    const char *p = text;
    for (int d = 0; d < dims; d++) {
        const size_t n = strcspn(p, " ");
        char range[256];
        int count = 0;
        snprintf(range, sizeof range, "%.*s", (int)(n < 255 ? n : 255), p);
        if (n == 0 || n > 255 || !parse_ranges(range, &lo[d], &hi[d], &count, 1) || count != 1)
            return CM_EFORMAT;
        p += n + (p[n] == ' ');
    }
    if (strncmp(p, "at ", 3) == 0 && p[3] && !strchr(p + 3, ' '))
        snprintf(slice, slice_size, "%s", p + 3);
    else if (*p)
        return CM_EFORMAT;
    return CM_OK;
}

void project_close(cm_store *s, cm_cluster *c)
{
    char msg[256];
    cm_cluster_free(c);
    cm_store_close(s, msg, sizeof msg);
}

uint64_t project_default_mem(void)
{
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    const uint64_t most = (uint64_t)PROJECT_MEM_MAX_MIB << 20;
    const uint64_t least = (uint64_t)PROJECT_MEM_MIN_MIB << 20;
    if (pages <= 0 || page <= 0)
        return most;
    const uint64_t eighth = (uint64_t)pages * (uint64_t)page / 8;
    return eighth > most ? most : eighth < least ? least : eighth;
}

cm_status project_create(const char *path, const cm_model *m, const cm_model_lib *lib,
                         const cm_lattice *lat, const char *command, const char *plan,
                         cm_store **s, cm_cluster *c, char *msg, size_t msg_size)
{
    const char *epoch = getenv("SOURCE_DATE_EPOCH"); /* reproducible files */
    const cm_store_meta meta = {m,
                                lat,
                                command,
                                plan,
                                CELLMAP_VERSION,
                                epoch ? atoll(epoch) : 0,
                                lib ? lib->path : NULL,
                                lib ? lib->hash : NULL};
    cm_cluster_init(c, lat);
    cm_status st = cm_store_create(path, &meta, s, msg, msg_size);
    if (st == CM_OK) {
        cm_store_attach(*s, c);
        cm_store_set_model(*s, m);
    }
    return st;
}

cm_status project_resume(const char *path, project_fits_fn fits, void *user, cm_store **s,
                         cm_store_info *info, cm_cluster *c, int *upgraded_from, char *msg,
                         size_t msg_size)
{
    /* read-only until the file proves to be the caller's: a refused file
     * is never written */
    cm_store *check = NULL;
    const cm_model *model = NULL;
    cm_status st = cm_store_open(path, 0, &check, msg, msg_size);
    if (st == CM_OK)
        st = cm_store_read_info(check, info, msg, msg_size);
    if (st == CM_OK) { /* damaged attractors refuse the file as any damage does */
        const cm_status a =
            cm_store_check_attractors(check, info->lattice.dim, info->groups, msg, msg_size);
        st = a == CM_ENOTFOUND ? CM_OK : a;
    }
    cm_store_close(check, NULL, 0);
    if (st == CM_OK)
        st = fits(user, info, &model, msg, msg_size);
    int upgraded = 0;
    *upgraded_from = 0;
    if (st == CM_OK && info->version < CM_STORE_VERSION) {
        st = cm_store_upgrade(path, model, &upgraded, msg, msg_size);
        if (st == CM_OK && upgraded)
            *upgraded_from = info->version;
    }
    if (st == CM_OK)
        st = cm_store_open(path, 1, s, msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_store_set_model(*s, model);
    return cm_store_load_cluster(*s, c, msg, msg_size);
}

void project_state_names(const cm_store_info *info, const char **names)
{
    cm_model m;
    char msg[256];
    cm_model_set set = {0};
    const bool known = model_of_store(info, &set, &m, msg, sizeof msg) == CM_OK;
    if (!known)
        memset(&m, 0, sizeof m); /* a model this cellmap lacks: x0, x1, ... */
    for (int d = 0; d < CM_MAX_DIM; d++)
        names[d] = cm_model_coord_name(&m, d); /* static strings: they outlive m */
    if (known)
        cm_model_release(&m);
}

/* The parameters JSON of a file ({"k":1.5,"mode":"output","K":[1,2]}) as
 * the "k=v,..." text models are built from. False if it is not such JSON. */
static bool params_text(const char *json, char *out, size_t size)
{
    size_t used = 0;
    const char *p = json;
    if (size)
        out[0] = 0; /* a model without parameters: "{}" */
    if (*p++ != '{')
        return false;
    while (*p && *p != '}') {
        const char *key = p + 1, *end = *p == '"' ? strchr(key, '"') : NULL;
        if (!end || end[1] != ':')
            return false;
        used += (size_t)snprintf(out + used, size > used ? size - used : 0,
                                 "%s%.*s=", used ? "," : "", (int)(end - key), key);
        p = end + 2;
        const char *stop = *p == '[' ? "]" : *p == '"' ? "\"" : ",}";
        if (*p == '[' || *p == '"')
            p++;
        const size_t len = strcspn(p, stop);
        for (size_t i = 0; i < len && used + 1 < size; i++)
            out[used++] = p[i] == ',' ? ':' : p[i];
        out[used < size ? used : size - 1] = 0;
        p += len;
        if (*stop != ',' && *p++ == 0)
            return false;
        if (*p == ',')
            p++;
    }
    return *p == '}' && used < size;
}

/* A plugin model's library: the one given (--model-lib) or the one the
 * file records, and the same file it was made with. */
static cm_status plugin_of_store(const cm_store_info *info, cm_model_set *set, char *msg,
                                 size_t msg_size)
{
    const cm_model_lib *lib;
    if (!cm_model_set_find(set, info->model, &lib)) {
        if (!info->model_lib[0])
            return cm_fail(CM_ENOTFOUND, msg, msg_size,
                           "its model '%s' is unknown to this cellmap (`cellmap models`)",
                           info->model);
        char why[1400];
        if (cm_model_set_load(set, info->model_lib, why, sizeof why) != CM_OK ||
            !cm_model_set_find(set, info->model, &lib))
            return cm_fail(CM_ENOTFOUND, msg, msg_size,
                           "its model '%s' comes from the plugin %s, which cannot be loaded "
                           "(%.600s): load the plugin from where it is now",
                           info->model, info->model_lib, why);
    }
    if (lib && info->model_lib_hash[0] && strcmp(lib->hash, info->model_lib_hash) != 0)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "its model '%s' was made with plugin %s of hash %s; %s has hash %s: the "
                       "plugin changed since, and its results could differ (rebuild the plugin "
                       "as it was, or solve again)",
                       info->model, info->model_lib, info->model_lib_hash, lib->path, lib->hash);
    return CM_OK;
}

cm_status model_of_store(const cm_store_info *info, cm_model_set *set, cm_model *m, char *msg,
                         size_t msg_size)
{
    char text[4096], again[4096];
    const char *texts[1] = {text};
    if (!params_text(info->params, text, sizeof text))
        return cm_fail(CM_EINVAL, msg, msg_size, "its parameters '%s' are not readable",
                       info->params);
    cm_status st = plugin_of_store(info, set, msg, msg_size);
    if (st == CM_OK)
        st = cm_model_set_create(set, info->model, texts, 1, m, msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_params_json(&m->values, again, sizeof again);
    if (strcmp(again, info->params) != 0) {
        cm_model_release(m);
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "its parameters %s do not rebuild exactly; this cellmap reads them as "
                       "something else",
                       info->params);
    }
    return CM_OK;
}

/* ---- growing a project: regions and extension ---------------------------- */

void project_plan_text(const project_plan *p, const cm_box *box, char *out, size_t size)
{
    size_t used = 0;
    used += (size_t)snprintf(out + used, size - used, "box");
    for (int d = 0; d < box->dim && used < size; d++)
        used += (size_t)snprintf(out + used, size - used, " %lld:%lld", (long long)box->lo[d],
                                 (long long)box->hi[d]);
    for (int d = 0; d < p->nsplit && used < size; d++)
        used += (size_t)snprintf(out + used, size - used, "%s%lld", d ? "x" : " split ",
                                 (long long)p->split[d]);
    if (used < size)
        snprintf(out + used, size - used, " max-steps %d extend %d escape-below %.17g bounds %s",
                 p->opt.max_steps, p->extend, p->escape_below,
                 p->bounds_text ? p->bounds_text : "-");
}

cm_status project_plan_int(const char *plan, const char *key, int lo, int hi, int *value)
{
    const size_t n = strlen(key);
    for (const char *p = plan; p && *p; p = strchr(p, ' '), p = p ? p + 1 : NULL) {
        if (strncmp(p, key, n) != 0 || p[n] != ' ')
            continue;
        char *end;
        errno = 0;
        const long v = strtol(p + n + 1, &end, 10);
        if (end == p + n + 1 || (*end && *end != ' ') || errno || v < lo || v > hi)
            return CM_EFORMAT;
        *value = (int)v;
        return CM_OK;
    }
    return CM_ENOTFOUND;
}

/* Splits into more boxes than this are joined in scan order along their
 * short side (cm_boxes_scan_order). */
#define SCAN_ORDER_FROM 64

uint32_t project_split(const project_plan *p, const cm_box *box, cm_box *boxes)
{
    int64_t parts[CM_MAX_DIM];
    uint32_t n = 1;
    for (int d = 0; d < box->dim; d++) {
        const int64_t size = box->hi[d] - box->lo[d];
        parts[d] = d < p->nsplit ? (p->split[d] < size ? p->split[d] : size) : 1;
        n *= (uint32_t)parts[d];
    }
    for (uint32_t k = 0; boxes && k < n; k++) {
        uint32_t rest = k;
        boxes[k] = *box;
        for (int d = 0; d < box->dim; d++) {
            const int64_t i = rest % (uint32_t)parts[d], size = box->hi[d] - box->lo[d];
            rest /= (uint32_t)parts[d];
            boxes[k].lo[d] = box->lo[d] + size * i / parts[d];
            boxes[k].hi[d] = box->lo[d] + size * (i + 1) / parts[d];
        }
    }
    /* many regions are scanned along the grid's short side, so that the
     * regions a join reads are few and recent (paging keeps them); fewer
     * keep the row order earlier files have */
    if (boxes && n > SCAN_ORDER_FROM)
        cm_boxes_scan_order(boxes, n); /* unsorted if out of memory */
    return n;
}

static bool has_box(const cm_cluster *c, const cm_box *box)
{
    for (uint32_t k = 0; k < c->nregions; k++)
        if (memcmp(c->regions[k].r.box.lo, box->lo, sizeof box->lo) == 0 &&
            memcmp(c->regions[k].r.box.hi, box->hi, sizeof box->hi) == 0)
            return true;
    return false;
}

/* What project_add_box does after each join: commit, then the plan's callback. */
typedef struct after_join {
    cm_store *s;
    const project_plan *p;
} after_join;

static cm_status joined(void *user, cm_cluster *c, uint32_t box, const cm_join_stats *stats,
                        char *msg, size_t msg_size)
{
    const after_join *a = user;
    cm_status st = a->s ? cm_store_commit_join(a->s, c, box, stats, msg, msg_size) : CM_OK;
    if (st == CM_OK && a->p->joined)
        st = a->p->joined(a->p->joined_user, c, box, stats, msg, msg_size);
    return st;
}

cm_status project_solve_boxes(cm_cluster *c, cm_store *s, const cm_model *m,
                              const cm_scm_options *opt, const cm_box *boxes, uint32_t n,
                              cm_joined_fn then, void *user, cm_join_stats *stats, char *msg,
                              size_t msg_size)
{
    const project_plan p = {.joined = then, .joined_user = user};
    after_join a = {s, &p};
    return cm_cluster_solve_boxes(c, m, boxes, n, opt, joined, &a, stats, msg, msg_size);
}

cm_status project_add_box(cm_cluster *c, cm_store *s, const cm_model *m, const project_plan *p,
                          const cm_box *box, cm_join_stats *stats, char *msg, size_t msg_size)
{
    const uint32_t n = project_split(p, box, NULL);
    cm_box *boxes = malloc(n * sizeof *boxes);
    if (!boxes)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the regions");
    project_split(p, box, boxes);
    uint32_t todo = 0; /* parts a resumed cluster has are skipped */
    for (uint32_t k = 0; k < n; k++)
        if (!has_box(c, &boxes[k]))
            boxes[todo++] = boxes[k];
    const cm_status st = project_solve_boxes(c, s, m, &p->opt, boxes, todo, p->joined,
                                             p->joined_user, stats, msg, msg_size);
    free(boxes);
    return st;
}

/* Extension steps a resumed cluster has done, and the tile of a step that
 * was interrupted between its regions (or the empty box). */
static int steps_done(const project_plan *p, const cm_cluster *c, const cm_box *tile,
                      cm_box *partial)
{
    const uint32_t per_tile = project_split(p, tile, NULL);
    const uint32_t extra = c->nregions > per_tile ? c->nregions - per_tile : 0;
    memset(partial, 0, sizeof *partial);
    if (extra % per_tile)
        cm_extend_tile(tile, p->bounds, c->regions[c->nregions - 1].r.box.lo, partial);
    return (int)((extra + per_tile - 1) / per_tile);
}

cm_status project_extend_tiles(cm_cluster *c, const cm_box *tile, const cm_box *bounds, int first,
                               int last, const cm_box *recorded_first, project_tile_fn compute,
                               void *user, int *done, char *stop, size_t stop_size, char *msg,
                               size_t msg_size)
{
    *done = 0;
    for (int k = first; k <= last; k++) {
        cm_extend_choice choice;
        memset(&choice, 0, sizeof choice);
        const double started = cm_seconds();
        const bool recorded = recorded_first && k == first;
        cm_status st = CM_OK;
        if (recorded)
            choice.box = *recorded_first;
        else
            st = cm_extend_choose(c, tile, bounds, &choice, msg, msg_size);
        if (st == CM_OK)
            st = compute(user, k, &choice, recorded, started, msg, msg_size);
        if (st == CM_ENOTFOUND) { /* nothing (enough) escapes next to the cluster: done */
            snprintf(stop, stop_size, "%s", msg);
            return CM_OK;
        }
        if (st != CM_OK)
            return st;
        ++*done;
    }
    return CM_OK;
}

/* A solve's extension step: below the plan's escaping fraction it ends;
 * else the tile is cut and solved as the plan says, and said. */
typedef struct plan_extension {
    cm_cluster *c;
    cm_store *s;
    const cm_model *m;
    const project_plan *p;
    int before; /* the steps a resumed cluster had done */
    project_step_fn step_done;
    void *user;
} plan_extension;

static cm_status plan_tile(void *user, int k, const cm_extend_choice *choice, bool recorded,
                           double started, char *msg, size_t msg_size)
{
    const plan_extension *x = user;
    (void)recorded;
    const double fraction = (double)choice->all_escaping / (double)choice->cluster_cells;
    if (fraction < x->p->escape_below)
        return cm_fail(CM_ENOTFOUND, msg, msg_size, "escaping fraction %.4g is below %.4g",
                       fraction, x->p->escape_below);
    cm_join_stats stats;
    const cm_status st = project_add_box(x->c, x->s, x->m, x->p, &choice->box, &stats, msg,
                                         msg_size);
    if (st != CM_OK)
        return st;
    const project_step step = {choice->box,           choice->escaping,  choice->all_escaping,
                               choice->cluster_cells, stats.new_groups, stats.straddling_groups,
                               cm_seconds() - started};
    if (x->step_done)
        x->step_done(x->user, &step, k - x->before - 1);
    return CM_OK;
}

cm_status project_extend(cm_cluster *c, cm_store *s, const cm_model *m, const project_plan *p,
                         const cm_box *tile, project_step_fn step_done, void *user, int *steps,
                         char *stop, size_t stop_size, char *msg, size_t msg_size)
{
    cm_box partial;
    const int done = steps_done(p, c, tile, &partial);
    cm_status st = CM_OK;
    *steps = 0;
    if (partial.dim) /* a step interrupted between its regions is finished first */
        st = project_add_box(c, s, m, p, &partial, NULL, msg, msg_size);
    snprintf(stop, stop_size, "%d extension steps done", p->extend);
    const plan_extension x = {c, s, m, p, done, step_done, user};
    if (st == CM_OK)
        st = project_extend_tiles(c, tile, p->bounds, done + 1, p->extend, NULL, plan_tile,
                                  (void *)&x, steps, stop, stop_size, msg, msg_size);
    return st;
}
