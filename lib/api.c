/* libcellmap's public API (cellmap/cellmap.h) over the engine, the models,
 * the .cmdb store and the renderer: the one module of the library that
 * sees all of them, as the command does. */
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
#include "lib/parse.h"
#include "lib/attractor_view.h"
#include "lib/project.h"


struct cm_models {
    cm_model_set set;
};

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
    cm_cluster_cells cc = {from->cluster, &x};
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
    if (width == 0 && height == 0) {
        cm_grid g;
        cm_result_grid(r, &g);
        const double w = g.hi[0] - g.lo[0], h = r->lat.dim > 1 ? g.hi[1] - g.lo[1] : w;
        width = w >= h ? 1000 : (int)fmax(200, 1000 * w / h);
        height = h >= w ? 1000 : (int)fmax(200, 1000 * h / w);
    }
    if (width < 1 || height < 1 || width > CM_RENDER_MAX_SIDE || height > CM_RENDER_MAX_SIDE)
        return cm_fail(CM_EINVAL, msg, msg_size, "image size %dx%d: each side must be 1..%d",
                       width, height, CM_RENDER_MAX_SIDE);
    const char *font = getenv("CELLMAP_FONT");
    /* by the system's attractors, as `cellmap solve --png` draws it */
    cm_group_label names[64];
    cm_render_options o = {
        .width = width,
        .height = height,
        .layers = CM_LAYER_BASIN | CM_LAYER_ATTRACTORS | CM_LAYER_OVERLAYS | CM_LAYER_AXES |
                  CM_LAYER_LEGEND | CM_LAYER_TITLE,
        .model = r->model,
        .font_path = font && font[0] ? font : CELLMAP_FONT_PATH,
        .min_basin = 2,
        .labels = names,
        .sink_label = "diverged",
    };
    uint8_t *rgba = malloc((size_t)width * (size_t)height * 4);
    if (!rgba)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a %dx%d image", width, height);
    cm_render_info info;
    cm_region view;
    cm_group_info *groups = NULL;
    uint32_t n = 0;
    cm_status st = cm_render_check(&o, r->lat.dim, msg, msg_size);
    if (st == CM_OK)
        st = cm_region_alloc(&view, &r->cells.box, msg, msg_size);
    if (st == CM_OK) {
        memcpy(view.group, r->cells.group, view.ncells * sizeof *view.group);
        memcpy(view.step, r->cells.step, view.ncells * sizeof *view.step);
        memcpy(view.image, r->cells.image, view.ncells * sizeof *view.image);
        st = attractor_view(&r->att, &view, r->att_labels, &groups, &n, msg, msg_size);
        o.n_labels = attractor_legend(&r->att, n, names, 0, 64);
        if (st == CM_OK)
            st = cm_render_figure(&r->lat, &view, groups, &o, rgba, &info, msg, msg_size);
        cm_region_free(&view);
        free(groups);
    }
    const cm_png_text texts[] = {{"Software", "libcellmap " CELLMAP_VERSION},
                                 {"Model", r->model->name}};
    if (st == CM_OK)
        st = cm_png_write(path, rgba, width, height, texts, 2, msg, msg_size);
    free(rgba);
    return st;
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
