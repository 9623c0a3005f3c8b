/* lib/api.c - libcellmap's public API (cellmap/cellmap.h), its stable and
 * experimental sections, over the library layer (lib/) and, below it, the
 * engine, the models, the .cmdb store and the renderer. */
#define CELLMAP_EXPERIMENTAL /* this file implements both sections */
#include "cellmap/cellmap.h"
#include "cellmap/attractors.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/cluster.h"
#include "cellmap/join.h"
#include "cellmap/outside.h"
#include "cellmap/scm.h"
#include "cellmap/store.h"
#include "models/params.h"
#include "models/registry.h"
#include "render/figure.h"
#include "render/png_out.h"
#include "cellmap/output.h"
#include "lib/api_models.h"
#include "lib/api_ranks.h"
#include "lib/attractor_view.h"
#include "lib/export.h"
#include "lib/figure.h"
#include "lib/parse.h"
#include "lib/project.h"
#include "lib/session.h"
#include "lib/solve.h"


struct cm_system {
    cm_model model;
    const cm_model_entry *entry;
};

struct cm_result {
    cm_lattice lat;
    cm_region cells;       /* group and step of every cell of cells.box */
    cm_group_info *groups; /* entry k: group k + 1 */
    uint64_t sink;
    const cm_model *model; /* the system's or database's, for figures */
    cm_attractor_set att;  /* the system's attractors of the groups */
    int32_t *att_labels;   /* every cell's attractor (cm_attractor_cell_labels) */
};

struct cm_db {
    cm_models models;
    cm_store *store;
    cm_store_info info;
    cm_cluster cluster;
    cm_model model;
};

const char *cm_version(void) { return CELLMAP_VERSION; }

int cm_version_number(void)
{
    int major = 0, minor = 0, patch = 0;
    sscanf(CELLMAP_VERSION, "%d.%d.%d", &major, &minor, &patch);
    return major * 10000 + minor * 100 + patch;
}

/* ---- models -------------------------------------------------------------- */

cm_status cm_models_new(cm_models **out, char *msg, size_t msg_size)
{
    *out = calloc(1, sizeof **out);
    return *out ? CM_OK : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a model set");
}

cm_status cm_models_load(cm_models *set, const char *path, char *msg, size_t msg_size)
{
    return cm_model_set_load(&set->set, path, msg, msg_size);
}

size_t cm_models_count(const cm_models *set)
{
    return cm_model_set_count(set ? &set->set : NULL);
}

const char *cm_models_name(const cm_models *set, size_t i)
{
    const cm_model_entry *e = cm_model_set_at(set ? &set->set : NULL, i);
    return e ? e->name : NULL;
}

void cm_models_free(cm_models *set)
{
    if (!set)
        return;
    cm_model_set_close(&set->set);
    free(set);
}

cm_status cm_system_new(const cm_models *set, const char *name, const char *params,
                            cm_system **out, char *msg, size_t msg_size)
{
    *out = NULL;
    cm_system *s = calloc(1, sizeof *s);
    if (!s)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a system");
    const cm_model_set *ms = set ? &set->set : NULL;
    const char *texts[1] = {params};
    const int n = params && params[0] ? 1 : 0;
    const cm_status st = cm_model_set_create(ms, name ? name : "", texts, n, &s->model, msg,
                                             msg_size);
    if (st != CM_OK) {
        free(s);
        return st;
    }
    s->entry = cm_model_set_find(ms, name, NULL);
    *out = s;
    return CM_OK;
}

int cm_system_dim(const cm_system *s) { return s->model.dim; }

const char *cm_system_name(const cm_system *s) { return s->model.name; }

const char *cm_system_coord(const cm_system *s, int d)
{
    return d >= 0 && d < s->model.dim ? cm_model_coord_name(&s->model, d) : NULL;
}

cm_status cm_system_region(const cm_system *s, double *lo, double *hi)
{
    int n = 0;
    if (!s->entry || !s->entry->region || !parse_ranges(s->entry->region, lo, hi, &n, CM_MAX_DIM) ||
        n != s->model.dim)
        return CM_ENOTFOUND;
    return CM_OK;
}

int cm_system_step(const cm_system *s, const double *x, double *y)
{
    return s->model.step(&s->model, x, y);
}

void cm_system_free(cm_system *s)
{
    if (!s)
        return;
    cm_model_release(&s->model);
    free(s);
}

/* ---- results ------------------------------------------------------------- */

static cm_status grid_lattice(const cm_grid *g, int dim, cm_lattice *lat, cm_box *box, char *msg,
                              size_t msg_size)
{
    if (g->dim != dim)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the grid has dimension %d but the model has dimension %d", g->dim, dim);
    *lat = (cm_lattice){dim, {0}, {0}};
    *box = (cm_box){dim, {0}, {0}};
    for (int d = 0; d < dim; d++) {
        if (!(g->lo[d] < g->hi[d]) || !isfinite(g->hi[d] - g->lo[d]) || g->cells[d] < 1)
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "grid dimension %d: give lo < hi (finite) and at least one cell", d);
        lat->origin[d] = g->lo[d];
        lat->width[d] = (g->hi[d] - g->lo[d]) / (double)g->cells[d];
        box->hi[d] = g->cells[d];
    }
    cm_status st = cm_lattice_check(lat, msg, msg_size);
    if (st == CM_OK)
        st = cm_box_check(box, msg, msg_size);
    if (st == CM_OK && cm_box_cells(box) > CM_REGION_MAX_CELLS)
        st = cm_fail(CM_ETOOBIG, msg, msg_size, "the grid has more than %llu cells",
                     (unsigned long long)CM_REGION_MAX_CELLS);
    return st;
}

/* Where a result's cells come from, for their attractors: a database
 * (its stored attractors, else found from its cluster), a split solve's
 * cluster, or a single region with its exits (cm_region_settle_exits). */
typedef struct result_source {
    cm_store *store;       /* a database's, or NULL */
    cm_cluster *cluster;   /* the database's or the split's cluster, or NULL */
    const cm_exits *exits; /* a single region's */
    int max_steps;         /* the solve's, for a single region */
} result_source;

/* The attractors of the cluster's groups (read from the store when it
 * has them), cc: the cluster and its exits. */
static cm_status cluster_attractors_of(const cm_model *m, const result_source *from,
                                       cm_cluster_cells *cc, cm_attractor_set *out, char *msg,
                                       size_t msg_size)
{
    cm_cluster *c = cc->c;
    if (from->store) {
        const cm_status st =
            cm_store_get_attractors(from->store, c->lat.dim, c->ngroups, out, NULL, msg, msg_size);
        if (st != CM_ENOTFOUND)
            return st;
    }
    cm_group_info *g = calloc((size_t)c->ngroups + 1, sizeof *g);
    uint64_t sink;
    cm_status st = !g ? cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the groups")
                   : from->store ? cm_store_groups(from->store, g, c->ngroups, &sink, msg, msg_size)
                                 : cm_cluster_describe_new(c, m, g, msg, msg_size);
    if (st == CM_OK)
        st = cm_cluster_attractors(m, cc, g, NULL, out, msg, msg_size);
    free(g);
    return st;
}

/* The result's attractors and every cell's label by them. */
static cm_status result_attractors_of(cm_result *res, const result_source *from, char *msg,
                                      size_t msg_size)
{
    const cm_model *m = res->model;
    cm_exits x = {0}; /* a cluster's */
    cm_cluster_cells cc = {from->cluster, &x, NULL};
    cm_region_cells rc = {&res->cells, m, &res->lat, from->max_steps};
    const cm_computed cells = from->cluster ? cm_cluster_computed(&cc) : cm_region_computed(&rc);
    cm_status st = from->cluster ? cm_cluster_exits(from->cluster, &x, msg, msg_size) : CM_OK;
    if (st == CM_OK)
        st = from->cluster ? cluster_attractors_of(m, from, &cc, &res->att, msg, msg_size)
                           : cm_region_attractors(m, &res->lat, &res->cells, from->max_steps,
                                                  from->exits, res->groups, NULL, &res->att, msg,
                                                  msg_size);
    res->att_labels = st == CM_OK ? malloc((res->cells.ncells + 1) * sizeof *res->att_labels)
                                  : NULL;
    if (st == CM_OK && !res->att_labels)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the labels");
    if (st == CM_OK)
        st = cm_attractor_cell_labels(&res->att, &res->cells, &cells, res->att_labels, msg,
                                      msg_size);
    cm_exits_free(&x);
    return st;
}

/* A result over r's cells (taken), with its groups summarised and their
 * attractors found. */
static cm_status make_result(const cm_model *m, const cm_lattice *lat, cm_region *r,
                             const result_source *from, cm_result **out, char *msg,
                             size_t msg_size)
{
    cm_result *res = calloc(1, sizeof *res);
    if (!res) {
        cm_region_free(r);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a result");
    }
    res->lat = *lat;
    res->cells = *r;
    res->model = m;
    memset(r, 0, sizeof *r);
    cm_status st = cm_scm_describe(m, lat, &res->cells, &res->groups, &res->sink, msg, msg_size);
    if (st == CM_OK)
        st = result_attractors_of(res, from, msg, msg_size);
    if (st != CM_OK) {
        cm_result_free(res);
        return st;
    }
    *out = res;
    return CM_OK;
}

typedef struct solve_progress {
    const cm_solve_options *opt;
    uint32_t nboxes;
} solve_progress;

static int images_progress(void *user, const char *phase, double fraction)
{
    const solve_progress *p = user;
    return strcmp(phase, "images") == 0 ? p->opt->progress(p->opt->user, fraction) : 0;
}

static cm_status region_joined(void *user, cm_cluster *c, uint32_t box,
                               const cm_join_stats *stats, char *msg, size_t msg_size)
{
    (void)c, (void)stats;
    const solve_progress *p = user;
    if (p->opt->progress && p->opt->progress(p->opt->user, (double)(box + 1) / p->nboxes))
        return cm_fail(CM_ECANCELED, msg, msg_size, "cancelled by the progress callback");
    return CM_OK;
}

/* The box as a cluster c (initialised here, freed by the caller) of the
 * split's regions, solved and joined, then flattened into r. */
static cm_status solve_split(const cm_model *m, const cm_lattice *lat, const cm_box *box,
                             const cm_solve_options *opt, const cm_scm_options *scm, cm_cluster *c,
                             cm_region *r, char *msg, size_t msg_size)
{
    project_plan plan = {.nsplit = box->dim, .opt = *scm, .joined = region_joined};
    for (int d = 0; d < box->dim; d++)
        plan.split[d] = opt->split[d] > 0 ? opt->split[d] : 1;
    solve_progress sp = {opt, project_split(&plan, box, NULL)};
    plan.joined_user = &sp;
    cm_cluster_init(c, lat);
    c->keep_exits = 0; /* nothing saves the cluster or reads its images */
    c->threads = opt->threads;
    cm_status st = project_add_box(c, NULL, m, &plan, box, NULL, msg, msg_size);
    if (st == CM_OK)
        st = cm_cluster_flatten(c, box, r, msg, msg_size);
    return st;
}

cm_status cm_solve(const cm_system *s, const cm_grid *grid, const cm_solve_options *opt,
                       cm_result **out, char *msg, size_t msg_size)
{
    *out = NULL;
    const cm_solve_options defaults = {0};
    if (!opt)
        opt = &defaults;
    cm_lattice lat;
    cm_box box;
    cm_status st = grid_lattice(grid, s->model.dim, &lat, &box, msg, msg_size);
    if (st != CM_OK)
        return st;
    bool split = false;
    for (int d = 0; d < box.dim; d++)
        split |= opt->split[d] > 1;
    solve_progress sp = {opt, 1};
    /* a single region records its exits: their orbits are followed */
    cm_scm_options scm = {.max_steps = opt->max_steps,
                          .threads = opt->threads,
                          .progress = opt->progress ? images_progress : NULL,
                          .user = &sp,
                          .record_exits = !split};
    cm_region r;
    cm_cluster c;
    cm_exits exits;
    memset(&r, 0, sizeof r);
    memset(&c, 0, sizeof c);
    memset(&exits, 0, sizeof exits);
    if (split) {
        st = solve_split(&s->model, &lat, &box, opt, &scm, &c, &r, msg, msg_size);
    } else {
        st = cm_region_alloc(&r, &box, msg, msg_size);
        if (st == CM_OK)
            st = cm_scm_solve(&s->model, &lat, &scm, &r, msg, msg_size);
        if (st == CM_ECANCELED)
            cm_fail(st, msg, msg_size, "cancelled by the progress callback");
        if (st == CM_OK)
            st = cm_region_settle_exits(&r, opt->threads, &exits, msg, msg_size);
    }
    const result_source solved = {NULL, split ? &c : NULL, &exits, opt->max_steps};
    if (st == CM_OK)
        st = make_result(&s->model, &lat, &r, &solved, out, msg, msg_size);
    cm_region_free(&r);
    cm_exits_free(&exits);
    if (split)
        cm_cluster_free(&c);
    return st;
}

void cm_result_grid(const cm_result *r, cm_grid *g)
{
    const cm_box *b = &r->cells.box;
    *g = (cm_grid){b->dim, {0}, {0}, {0}};
    cm_box_rect(&r->lat, b, b->dim, g->lo, g->hi);
    for (int d = 0; d < b->dim; d++)
        g->cells[d] = b->hi[d] - b->lo[d];
}

uint64_t cm_result_cells(const cm_result *r) { return r->cells.ncells; }

void cm_result_labels(const cm_result *r, uint32_t *labels)
{
    memcpy(labels, r->cells.group, r->cells.ncells * sizeof *labels);
}

void cm_result_steps(const cm_result *r, uint32_t *steps)
{
    for (uint64_t i = 0; i < r->cells.ncells; i++) /* cells of no region have no step */
        steps[i] = r->cells.group[i] == CM_GROUP_NONE ? 0 : r->cells.step[i];
}

uint32_t cm_result_groups(const cm_result *r) { return r->cells.ngroups; }

cm_status cm_result_group(const cm_result *r, uint32_t id, cm_group_summary *out)
{
    if (id < 1 || id > r->cells.ngroups)
        return CM_ENOTFOUND;
    const cm_group_info *g = &r->groups[id - 1];
    *out = (cm_group_summary){id, g->kind, g->period, g->basin_cells, {0}};
    memcpy(out->centre, g->centre, sizeof out->centre);
    return CM_OK;
}

uint64_t cm_result_sink_cells(const cm_result *r) { return r->sink; }

cm_status cm_result_png(const cm_result *r, const char *path, int width, int height,
                        char *msg, size_t msg_size)
{
    const cm_figure_options o = {.png = path, .width = width, .height = height};
    return cm_result_figure(r, &o, msg, msg_size);
}

void cm_result_free(cm_result *r)
{
    if (!r)
        return;
    cm_region_free(&r->cells);
    free(r->groups);
    cm_attractors_free(&r->att);
    free(r->att_labels);
    free(r);
}

uint32_t cm_result_attractors(const cm_result *r) { return r->att.n; }

cm_status cm_result_attractor(const cm_result *r, uint32_t id, cm_attractor_summary *out)
{
    if (id < 1 || id > r->att.n)
        return CM_ENOTFOUND;
    const cm_attractor *a = &r->att.a[id - 1];
    memset(out, 0, sizeof *out);
    out->id = a->id;
    out->kind = a->kind;
    out->period = a->period;
    out->basin_cells = a->basin_cells;
    out->groups = a->groups;
    memcpy(out->centre, a->centre, sizeof out->centre);
    memcpy(out->lo, a->lo, sizeof out->lo);
    memcpy(out->hi, a->hi, sizeof out->hi);
    memcpy(out->anchor, a->anchor, sizeof out->anchor);
    out->footprint_cells = a->footprint_cells;
    return CM_OK;
}

void cm_result_attractor_labels(const cm_result *r, int32_t *labels)
{
    memcpy(labels, r->att_labels, r->cells.ncells * sizeof *labels);
}

/* ---- databases ----------------------------------------------------------- */

cm_status cm_db_open(const char *path, cm_db **out, char *msg, size_t msg_size)
{
    *out = NULL;
    cm_db *db = calloc(1, sizeof *db);
    if (!db)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a database");
    cm_cluster_init(&db->cluster, &(cm_lattice){1, {0}, {1}});
    cm_status st = cm_store_open(path, 0, &db->store, msg, msg_size);
    if (st == CM_OK)
        st = cm_store_snapshot_begin(db->store, msg, msg_size);
    if (st == CM_OK)
        st = cm_store_read_info(db->store, &db->info, msg, msg_size);
    if (st == CM_OK)
        st = cm_store_load_cluster(db->store, &db->cluster, msg, msg_size);
    if (db->store)
        cm_store_snapshot_end(db->store);
    if (st == CM_OK && db->cluster.nregions == 0)
        st = cm_fail(CM_EINVAL, msg, msg_size, "%s holds no region yet", path);
    if (st == CM_OK)
        st = model_of_store(&db->info, &db->models.set, &db->model, msg, msg_size);
    if (st == CM_OK)
        cm_store_set_model(db->store, &db->model);
    if (st != CM_OK) {
        cm_db_close(db);
        return st;
    }
    db->cluster.mem_budget = (uint64_t)256 << 20; /* regions are read back on demand */
    *out = db;
    return CM_OK;
}

const char *cm_db_model(const cm_db *db) { return db->info.model; }

const char *cm_db_params(const cm_db *db) { return db->info.params; }

void cm_db_grid(const cm_db *db, cm_grid *g)
{
    cm_box box;
    cm_cluster_bounds(&db->cluster, &box);
    const cm_lattice *lat = &db->cluster.lat;
    *g = (cm_grid){box.dim, {0}, {0}, {0}};
    cm_box_rect(lat, &box, box.dim, g->lo, g->hi);
    for (int d = 0; d < box.dim; d++)
        g->cells[d] = box.hi[d] - box.lo[d];
}

/* The cells of the lattice that meet lo..hi, within the cluster's bounds. */
static cm_status view_box(const cm_db *db, const double *lo, const double *hi, cm_box *box,
                          char *msg, size_t msg_size)
{
    const cm_lattice *lat = &db->cluster.lat;
    cm_box bounds;
    cm_cluster_bounds(&db->cluster, &bounds);
    *box = bounds;
    if (!lo && !hi)
        return CM_OK;
    if (!lo || !hi)
        return cm_fail(CM_EINVAL, msg, msg_size, "give both lo and hi, or neither");
    for (int d = 0; d < lat->dim; d++) {
        if (!(lo[d] < hi[d]))
            return cm_fail(CM_EINVAL, msg, msg_size, "view dimension %d: lo must be below hi", d);
        /* a view edge on a cell border takes no cell beyond it */
        const int64_t a = cm_lattice_border(lat, d, lo[d], 0);
        const int64_t b = cm_lattice_border(lat, d, hi[d], 1);
        box->lo[d] = a > bounds.lo[d] ? a : bounds.lo[d];
        box->hi[d] = b < bounds.hi[d] ? b : bounds.hi[d];
        if (box->lo[d] >= box->hi[d])
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "the view misses the cluster in dimension %d (cellmap info lists "
                           "its bounds)",
                           d);
    }
    if (cm_box_cells(box) > CM_REGION_MAX_CELLS)
        return cm_fail(CM_ETOOBIG, msg, msg_size, "the view has more than %llu cells",
                       (unsigned long long)CM_REGION_MAX_CELLS);
    return CM_OK;
}

cm_status cm_db_read(cm_db *db, const double *lo, const double *hi, cm_result **out,
                         char *msg, size_t msg_size)
{
    *out = NULL;
    cm_box box;
    cm_status st = view_box(db, lo, hi, &box, msg, msg_size);
    cm_region r;
    memset(&r, 0, sizeof r);
    if (st == CM_OK)
        st = cm_cluster_flatten(&db->cluster, &box, &r, msg, msg_size);
    if (st != CM_OK)
        return st;
    const result_source stored = {db->store, &db->cluster, NULL, 0};
    return make_result(&db->model, &db->cluster.lat, &r, &stored, out, msg, msg_size);
}

void cm_db_close(cm_db *db)
{
    if (!db)
        return;
    if (db->model.step)
        cm_model_release(&db->model);
    cm_cluster_free(&db->cluster);
    cm_store_close(db->store, NULL, 0);
    cm_model_set_close(&db->models.set);
    free(db);
}

/* ==== experimental ======================================================== */

/* ---- systems given as a function ---- */

typedef struct function_model {
    cm_step_fn fn;
    void *user;
    char name[64];
} function_model;

static int function_step(const cm_model *m, const double *x, double *y)
{
    const function_model *f = m->ctx;
    return f->fn(f->user, x, y);
}

static void function_free(void *ctx) { free(ctx); }

static const cm_param_spec no_params[] = {{NULL, NULL, 0, 0, 0, NULL, NULL}};

cm_status cm_system_from_function(const char *name, int dim, cm_step_fn fn, void *user,
                                  cm_system **out, char *msg, size_t msg_size)
{
    *out = NULL;
    if (!name || !name[0] || strlen(name) > 63)
        return cm_fail(CM_EINVAL, msg, msg_size, "a function system needs a name of 1..63 "
                       "characters");
    if (dim < 1 || dim > CM_MAX_DIM)
        return cm_fail(CM_EINVAL, msg, msg_size, "dimension %d: give 1..%d", dim, CM_MAX_DIM);
    if (!fn)
        return cm_fail(CM_EINVAL, msg, msg_size, "no step function given");
    cm_system *s = calloc(1, sizeof *s);
    function_model *f = calloc(1, sizeof *f);
    if (!s || !f) {
        free(s);
        free(f);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a system");
    }
    *f = (function_model){fn, user, {0}};
    snprintf(f->name, sizeof f->name, "%s", name);
    cm_model *m = &s->model;
    m->name = f->name;
    m->dim = dim;
    m->params = no_params;
    m->values.spec = no_params;
    m->ctx = f;
    m->destroy = function_free;
    m->step = function_step;
    /* a status other than CM_STEP_* stops the run, as a plugin's does */
    const cm_status st = cm_model_wrap_periods(m, true, msg, msg_size);
    if (st != CM_OK) {
        cm_system_free(s);
        return st;
    }
    *out = s;
    return CM_OK;
}

/* ---- figures ---- */

/* The figure options as the pipeline takes them (po is filled; files it
 * names are read now). */
static cm_status figure_opts_of(const cm_figure_options *o, png_opts *po, char *msg,
                                size_t msg_size)
{
    memset(po, 0, sizeof *po);
    po->path = o->png;
    po->svg = o->svg;
    po->pdf = o->pdf;
    po->width = o->width;
    po->height = o->height;
    po->layers = o->layers;
    po->default_layers = all_layers;
    po->indexed = o->indexed != 0;
    po->by = o->by_groups ? BY_GROUPS : BY_ATTRACTORS;
    po->min_basin = o->min_basin;
    po->legend_groups = o->legend;
    po->title = o->title;
    po->aspect = o->aspect;
    po->font_size = o->font_size;
    po->dpi = o->dpi;
    if (!o->png && !o->svg && !o->pdf)
        return cm_fail(CM_EINVAL, msg, msg_size, "a figure needs a png, an svg or a pdf path");
    if ((o->width == 0) != (o->height == 0) || o->width < 0 || o->height < 0 ||
        o->width > CM_RENDER_MAX_SIDE || o->height > CM_RENDER_MAX_SIDE)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "image size %dx%d: give both sides 1..%d, or 0, 0 for the default",
                       o->width, o->height, CM_RENDER_MAX_SIDE);
    if (o->layers & ~all_layers & ~(unsigned)CM_FIGURE_STEPS)
        return cm_fail(CM_EINVAL, msg, msg_size, "layers 0x%x: use CM_FIGURE_* bits", o->layers);
    if (o->indexed && (o->svg || o->pdf || o->width || o->layers))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "an indexed PNG has one pixel per cell: give no svg, pdf, size or layers");
    if (o->legend < 0 || o->legend > 200)
        return cm_fail(CM_EINVAL, msg, msg_size, "legend %d: give 0..200 groups", o->legend);
    if (!(o->aspect == 0 || o->aspect == ASPECT_AUTO || (o->aspect >= 1e-6 && o->aspect <= 1e6)))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "aspect %g: give 0 (the model's), -1 (auto) or a ratio 1e-6..1e6", o->aspect);
    if (!(o->font_size == 0 || (o->font_size >= 1 && o->font_size <= 96)))
        return cm_fail(CM_EINVAL, msg, msg_size, "font_size %g: give 1..96 points, or 0",
                       o->font_size);
    if (!(o->dpi == 0 || (o->dpi >= 36 && o->dpi <= 2400)))
        return cm_fail(CM_EINVAL, msg, msg_size, "dpi %g: give 36..2400, or 0", o->dpi);
    if (o->title && strlen(o->title) > 1000)
        return cm_fail(CM_EINVAL, msg, msg_size, "title: %zu characters; give at most 1000",
                       strlen(o->title));
    char why[400];
    if (o->palette && !png_opts_palette(o->palette, po, why, sizeof why))
        return cm_fail(CM_EINVAL, msg, msg_size, "palette: %s", why);
    if (o->labels && !png_opts_labels(o->labels, po, why, sizeof why))
        return cm_fail(CM_EINVAL, msg, msg_size, "labels: %s", why);
    return CM_OK;
}

cm_status cm_result_figure(const cm_result *r, const cm_figure_options *o, char *msg,
                           size_t msg_size)
{
    png_opts po;
    cm_status st = figure_opts_of(o, &po, msg, msg_size);
    if (st == CM_OK)
        st = figure_check(&po, r->model, &r->lat, &r->cells.box, msg, msg_size);
    const basin_png b = {&po,  r->model, &r->lat, &r->cells, r->groups, {0, 0}, {0, 0}, NULL,
                         po.by == BY_ATTRACTORS ? &r->att : NULL, NULL, r->att_labels, NULL};
    return st == CM_OK ? figure_write(&b, msg, msg_size) : st;
}

/* ---- projects ---- */

/* The progress of a library call told as the caller's fraction, and its
 * cancel as the stop request. */
typedef struct call_hooks {
    cm_solve_progress_fn progress;
    void *user;
    double total;
    int cancelled;
} call_hooks;

static void call_progress(void *user, uint64_t done, const char *what)
{
    call_hooks *h = user;
    (void)what;
    if (h->progress && !h->cancelled && h->progress(h->user, fmin(1, (double)done / h->total)))
        h->cancelled = 1;
}

static const char *call_stop(void *user)
{
    const call_hooks *h = user;
    return h->cancelled ? "cancelled by the progress callback" : NULL;
}

static cm_status db_solve(const cm_models *set, const char *name, const char *params,
                          const cm_grid *grid, const char *path, const cm_db_options *o,
                          bool resume, char *msg, size_t msg_size)
{
    const cm_db_options none = {0};
    o = o ? o : &none;
    if (!path || !path[0])
        return cm_fail(CM_EINVAL, msg, msg_size, "a database needs a path");
    if (o->extend < 0 || o->extend > SOLVE_MAX_EXTEND || o->threads < 0 || o->max_steps < 0 ||
        o->max_steps > PROJECT_MAX_STEPS || !(o->escape_below >= 0 && o->escape_below <= 1))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "options: extend 0..%d, threads >= 0, max_steps 0..%d, escape_below 0..1",
                       SOLVE_MAX_EXTEND, PROJECT_MAX_STEPS);
    const cm_model_set *ms = set ? &set->set : NULL;
    const char *texts[1] = {params};
    cm_model m;
    cm_status st = cm_model_set_create(ms, name ? name : "", texts, params && params[0] ? 1 : 0,
                                       &m, msg, msg_size);
    if (st != CM_OK)
        return st;
    solve_request q;
    memset(&q, 0, sizeof q);
    st = grid_lattice(grid, m.dim, &q.lat, &q.box, msg, msg_size);
    bool split = false;
    for (int d = 0; d < m.dim; d++)
        split |= o->split[d] > 0;
    if (st == CM_OK)
        st = cm_model_check_box(&m, &q.lat, &q.box, msg, msg_size);
    q.model = &m;
    cm_model_set_find(ms, m.name, &q.lib);
    q.plan.nsplit = split ? m.dim : 0;
    for (int d = 0; d < m.dim; d++) {
        q.plan.split[d] = o->split[d] > 0 ? o->split[d] : 1;
        if (split && q.plan.split[d] > q.box.hi[d] && st == CM_OK)
            st = cm_fail(CM_EINVAL, msg, msg_size, "split: %lld parts in dimension %d, which "
                         "has %lld cells", (long long)q.plan.split[d], d, (long long)q.box.hi[d]);
    }
    q.plan.opt = (cm_scm_options){.max_steps = o->max_steps, .threads = o->threads,
                                  .record_exits = 1};
    q.plan.extend = o->extend;
    q.plan.escape_below = o->escape_below;
    q.cluster = true;
    q.db = path;
    q.resume = resume;
    q.command = o->command ? o->command : "libcellmap";
    q.mem = o->mem;
    call_hooks h = {o->progress, o->user, (double)cm_box_cells(&q.box), 0};
    const work_hooks hooks = {call_progress, call_stop, &h};
    q.hooks = &hooks;
    q.ranks = api_ranks_solve(o->ranks);
    solve_result *r = st == CM_OK ? malloc(sizeof *r) : NULL;
    if (st == CM_OK && !r)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a solve");
    if (st == CM_OK)
        st = solve_run(&q, r, msg, msg_size);
    else if (q.ranks) /* the other ranks learn that this one cannot solve */
        solve_ranks_refuse(q.ranks);
    if (st == CM_OK)
        st = solve_finish(r, msg, msg_size);
    if (r)
        solve_result_free(r);
    free(r);
    cm_model_release(&m);
    return st;
}

cm_status cm_db_create(const cm_models *set, const char *name, const char *params,
                       const cm_grid *grid, const char *path, const cm_db_options *o, char *msg,
                       size_t msg_size)
{
    return db_solve(set, name, params, grid, path, o, false, msg, msg_size);
}

cm_status cm_db_resume(const cm_models *set, const char *name, const char *params,
                       const cm_grid *grid, const char *path, const cm_db_options *o, char *msg,
                       size_t msg_size)
{
    return db_solve(set, name, params, grid, path, o, true, msg, msg_size);
}

cm_status cm_db_export(const char *path, const double *lo, const double *hi, const char *labels,
                       const char *steps, int by_groups, char *msg, size_t msg_size)
{
    if (!labels && !steps)
        return cm_fail(CM_EINVAL, msg, msg_size, "nothing to export: give labels or steps");
    if ((lo == NULL) != (hi == NULL))
        return cm_fail(CM_EINVAL, msg, msg_size, "give both lo and hi, or neither");
    cm_store *s = NULL;
    cm_store_info info;
    cm_cluster c;
    cm_status st = project_probe(path, msg, msg_size);
    if (st == CM_OK)
        st = project_open_cluster(path, (uint64_t)256 << 20, &s, &info, &c, msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_box window, *w = NULL;
    if (lo) { /* the ranges as text that reads back exactly */
        char text[CM_MAX_DIM * 2 * CM_NUM_TEXT + 16];
        size_t used = 0;
        for (int d = 0; d < c.lat.dim && used < sizeof text; d++)
            used += (size_t)snprintf(text + used, sizeof text - used, "%s%.17g:%.17g",
                                     d ? "," : "", lo[d], hi[d]);
        st = export_window(&c, text, &window, msg, msg_size);
        w = &window;
    }
    exporter x;
    memset(&x, 0, sizeof x);
    const cm_attractor_options stored = {0};
    if (st == CM_OK)
        st = exporter_open(&x, s, &info, &c, w, path, &stored, msg, msg_size);
    if (st == CM_OK)
        st = export_arrays(&x, labels, steps, by_groups != 0, NULL, msg, msg_size);
    exporter_close(&x);
    project_close(s, &c);
    return st;
}

/* ---- sessions ---- */

struct cm_session {
    session s;
    char path[CM_OUTPUT_PATH_MAX];
};

cm_status cm_session_open(const char *path, const cm_session_options *o, cm_session **out,
                          char *msg, size_t msg_size)
{
    *out = NULL;
    const cm_session_options none = {0};
    o = o ? o : &none;
    if (!path || !path[0] || strlen(path) >= CM_OUTPUT_PATH_MAX)
        return cm_fail(CM_EINVAL, msg, msg_size, "a session needs a path (shorter than %d)",
                       CM_OUTPUT_PATH_MAX);
    cm_session *cs = calloc(1, sizeof *cs);
    if (!cs)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a session");
    snprintf(cs->path, sizeof cs->path, "%s", path);
    session_options so;
    memset(&so, 0, sizeof so);
    so.path = cs->path;
    so.mo = api_model_spec(o->set, o->model, o->params, NULL);
    for (int d = 0; d < CM_MAX_DIM && o->cell_size[d] > 0; d++)
        so.n_cell_size = d + 1;
    memcpy(so.cell_size, o->cell_size, sizeof so.cell_size);
    memcpy(so.origin, o->origin, sizeof so.origin);
    so.n_origin = so.n_cell_size;
    so.depth_text = o->depth;
    so.max_steps = o->max_steps;
    so.threads = o->threads;
    so.mem = o->mem;
    so.command = o->command ? o->command : "libcellmap";
    session_opened opened;
    const cm_status st = session_open(&cs->s, &so, &opened, msg, msg_size);
    if (st != CM_OK) {
        char ignored[64];
        session_close(&cs->s, ignored, sizeof ignored);
        free(cs);
        return st;
    }
    *out = cs;
    return CM_OK;
}

static cm_status session_to(cm_session *s, const double *lo, const double *hi, const char *verb,
                            uint64_t *new_cells, char *msg, size_t msg_size)
{
    session_work done;
    const cm_status st = session_move(&s->s, lo, hi, NULL, verb, &done, msg, msg_size);
    if (new_cells)
        *new_cells = st == CM_OK ? done.cells : 0;
    return st;
}

cm_status cm_session_view(cm_session *s, const double *lo, const double *hi,
                          uint64_t *new_cells, char *msg, size_t msg_size)
{
    return session_to(s, lo, hi, "view", new_cells, msg, msg_size);
}

cm_status cm_session_bounds(const cm_session *s, double *lo, double *hi)
{
    if (!s->s.have_view)
        return CM_ENOTFOUND;
    memcpy(lo, s->s.lo, (size_t)s->s.view_dims * sizeof *lo);
    memcpy(hi, s->s.hi, (size_t)s->s.view_dims * sizeof *hi);
    return CM_OK;
}

cm_status cm_session_pan(cm_session *s, int d, double by, uint64_t *new_cells, char *msg,
                         size_t msg_size)
{
    cm_status st = session_need_view(&s->s, "pan", msg, msg_size);
    if (st == CM_OK && (d < 0 || d >= s->s.view_dims || !isfinite(by)))
        st = cm_fail(CM_EINVAL, msg, msg_size, "pan: dimension %d of %d, by a finite amount", d,
                     s->s.view_dims);
    if (st != CM_OK)
        return st;
    double lo[2] = {s->s.lo[0], s->s.lo[1]}, hi[2] = {s->s.hi[0], s->s.hi[1]};
    lo[d] += by;
    hi[d] += by;
    return session_to(s, lo, hi, "pan", new_cells, msg, msg_size);
}

cm_status cm_session_zoom(cm_session *s, double factor, uint64_t *new_cells, char *msg,
                          size_t msg_size)
{
    cm_status st = session_need_view(&s->s, "zoom", msg, msg_size);
    if (st == CM_OK && !(factor > 0 && isfinite(factor)))
        st = cm_fail(CM_EINVAL, msg, msg_size, "zoom: the factor must be positive");
    if (st != CM_OK)
        return st;
    double lo[2] = {0, 0}, hi[2] = {0, 0};
    for (int d = 0; d < s->s.view_dims; d++) { /* as the explore language's zoom */
        const double mid = 0.5 * (s->s.lo[d] + s->s.hi[d]),
                     half = 0.5 * (s->s.hi[d] - s->s.lo[d]) / factor;
        lo[d] = mid - half;
        hi[d] = mid + half;
    }
    return session_to(s, lo, hi, "zoom", new_cells, msg, msg_size);
}

static void count_step(void *user, const session_step *step)
{
    (void)step;
    ++*(int *)user;
}

cm_status cm_session_extend(cm_session *s, int steps, int *done, char *msg, size_t msg_size)
{
    int n = 0;
    session_extended how;
    const cm_status st = session_extend(&s->s, NULL, steps, count_step, &n, &how, msg, msg_size);
    if (done)
        *done = n;
    return st;
}

cm_status cm_session_read(cm_session *s, cm_result **out, char *msg, size_t msg_size)
{
    *out = NULL;
    cm_status st = session_need_view(&s->s, "read", msg, msg_size);
    cm_box box;
    cm_region r;
    memset(&r, 0, sizeof r);
    session_shown_cells(&s->s, &box);
    if (st == CM_OK)
        st = cm_cluster_flatten(&s->s.c, &box, &r, msg, msg_size);
    if (st != CM_OK)
        return st;
    /* the attractors found over the whole cluster, as render finds them */
    const result_source cluster = {NULL, &s->s.c, NULL, 0};
    return make_result(&s->s.model, &s->s.c.lat, &r, &cluster, out, msg, msg_size);
}

cm_status cm_session_query(cm_session *s, const double *x, cm_cell_info *out, char *msg,
                           size_t msg_size)
{
    memset(out, 0, sizeof *out);
    const cm_lattice *lat = &s->s.c.lat;
    for (int d = 0; d < lat->dim; d++)
        if (!isfinite(x[d]))
            return cm_fail(CM_EINVAL, msg, msg_size, "a query needs %d finite coordinates",
                           lat->dim);
    if (!cm_lattice_cell(lat, x, out->cell))
        return cm_fail(CM_EINVAL, msg, msg_size, "the state is outside the lattice's world");
    cm_lattice_centre(lat, out->cell, out->centre);
    cm_box box = {.dim = lat->dim};
    for (int d = 0; d < lat->dim; d++)
        box.lo[d] = out->cell[d], box.hi[d] = out->cell[d] + 1;
    cm_region r;
    memset(&r, 0, sizeof r);
    cm_status st = cm_cluster_flatten(&s->s.c, &box, &r, msg, msg_size);
    cm_result *res = NULL;
    const result_source cluster = {NULL, &s->s.c, NULL, 0};
    if (st == CM_OK)
        st = make_result(&s->s.model, lat, &r, &cluster, &res, msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_result_labels(res, &out->label);
    cm_result_steps(res, &out->step);
    cm_result_attractor_labels(res, &out->attractor);
    cm_result_free(res);
    return CM_OK;
}

cm_status cm_session_figure(cm_session *s, const cm_figure_options *o, char *msg,
                            size_t msg_size)
{
    png_opts po;
    const cm_status st = figure_opts_of(o, &po, msg, msg_size);
    return st == CM_OK ? session_render(&s->s, &po, msg, msg_size) : st;
}

cm_status cm_session_close(cm_session *s, char *msg, size_t msg_size)
{
    if (!s)
        return CM_OK;
    const cm_status st = session_close(&s->s, msg, msg_size);
    free(s);
    return st;
}

/* ---- databases grown in place ---- */

/* The session a database is grown through: the file's own model, lattice
 * and max steps; o's threads, memory and provenance. */
static cm_status grown_session(const char *path, const cm_db_options *o, cm_session **s,
                               char *msg, size_t msg_size)
{
    const cm_db_options none = {0};
    o = o ? o : &none;
    if (api_ranks_solve(o->ranks)) /* each rank would write the file */
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a database grows in one process: call cm_db_add_box and cm_db_extend "
                       "on rank 0 alone, without ranks (cm_db_create and cm_db_resume share "
                       "theirs, --extend included)");
    const cm_session_options so = {.max_steps = o->max_steps, .threads = o->threads,
                                   .mem = o->mem, .command = o->command};
    return cm_session_open(path, &so, s, msg, msg_size);
}

/* Closes the session of a grown database: st, or the close's failure
 * when the work succeeded (its message then in msg). */
static cm_status grown_close(cm_session *s, cm_status st, char *msg, size_t msg_size)
{
    char close_msg[512];
    const cm_status closed = cm_session_close(s, close_msg, sizeof close_msg);
    return st != CM_OK || closed == CM_OK ? st : cm_fail(closed, msg, msg_size, "%s", close_msg);
}

cm_status cm_db_add_box(const char *path, const double *lo, const double *hi,
                        const cm_db_options *o, uint64_t *new_cells, char *msg, size_t msg_size)
{
    cm_session *s = NULL;
    cm_status st = grown_session(path, o, &s, msg, msg_size);
    cm_box box;
    session_work work = {0};
    if (st == CM_OK)
        st = session_rect_box(&s->s, lo, hi, &box, msg, msg_size);
    if (st == CM_OK)
        st = session_add_box(&s->s, &box, &work, msg, msg_size);
    if (new_cells)
        *new_cells = work.cells;
    return grown_close(s, st, msg, msg_size);
}

cm_status cm_db_extend(const char *path, const double *lo, const double *hi, int steps,
                       const cm_db_options *o, int *done, char *msg, size_t msg_size)
{
    cm_session *s = NULL;
    cm_status st = grown_session(path, o, &s, msg, msg_size);
    cm_box tile;
    int n = 0;
    session_extended how;
    if (st == CM_OK)
        st = session_rect_box(&s->s, lo, hi, &tile, msg, msg_size);
    if (st == CM_OK)
        st = session_extend(&s->s, &tile, steps, count_step, &n, &how, msg, msg_size);
    if (done)
        *done = n;
    return grown_close(s, st, msg, msg_size);
}
