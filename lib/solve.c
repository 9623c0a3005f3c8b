/* lib/solve.c - a solve from the cells to the stored attractors (lib/solve.h). */
#include "lib/solve.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A cm_progress_fn for a solve in one region: the phase's share of the
 * cells, and the stop request. */
static int whole_progress(void *user, const char *phase, double fraction)
{
    const solve_request *q = user;
    char what[64];
    snprintf(what, sizeof what, "%s %.0f%%", phase, 100 * fraction);
    work_progress(q->hooks, (uint64_t)(fraction * (double)cm_box_cells(&q->box)), what);
    return work_stop(q->hooks) != NULL;
}

/* What cluster_progress reports to and adds the joins' time into. */
typedef struct cluster_watch {
    const solve_request *q;
    solve_result *r;
} cluster_watch;

/* A cm_joined_fn for a cluster (after the join's commit): the regions
 * joined, and the stop request, which ends the solve with what is
 * committed. */
static cm_status cluster_progress(void *user, cm_cluster *c, uint32_t box,
                                  const cm_join_stats *stats, char *msg, size_t msg_size)
{
    const cluster_watch *w = user;
    const solve_request *q = w->q;
    (void)box;
    w->r->join_seconds += stats->seconds;
    char what[64];
    snprintf(what, sizeof what, "%u region%s joined", c->nregions, c->nregions == 1 ? "" : "s");
    work_progress(q->hooks, c->cells, what);
    return work_check(q->hooks, msg, msg_size);
}

static cm_status solve_whole(const solve_request *q, solve_result *r, char *msg, size_t msg_size)
{
    /* exits recorded: their orbits are followed (cm_region_settle_exits) */
    const cm_scm_options opt = {.max_steps = q->plan.opt.max_steps,
                                .threads = q->plan.opt.threads,
                                .progress = whole_progress,
                                .user = (void *)q,
                                .record_exits = 1};
    r->first = "images";
    r->second = "classification";
    cm_status st = cm_region_alloc(&r->r, &q->box, msg, msg_size);
    const double t0 = cm_seconds();
    if (st == CM_OK)
        st = cm_scm_images(q->model, &q->lat, &opt, &r->r, msg, msg_size);
    const double t1 = cm_seconds();
    if (st == CM_OK) /* classification cannot stop half-way */
        st = work_check(q->hooks, msg, msg_size);
    if (st == CM_OK)
        st = cm_scm_classify(&r->r, q->plan.opt.threads, msg, msg_size);
    r->t1 = t1 - t0;
    r->t2 = cm_seconds() - t1;
    return st;
}

/* The regions of the split solved alone and taken through Stage 1 of
 * their join only (thesis Fig. 4.27), flattened into r->r. */
static cm_status solve_stage1(const solve_request *q, solve_result *r, char *msg,
                              size_t msg_size)
{
    const project_plan *plan = &q->plan;
    const uint32_t n = project_split(plan, &q->box, NULL);
    cm_box *boxes = malloc(n * sizeof *boxes);
    cm_region *parts = calloc(n, sizeof *parts);
    cm_status st =
        boxes && parts ? CM_OK : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the regions");
    r->first = "regions";
    r->second = "stage 1";
    const double t0 = cm_seconds();
    if (st == CM_OK)
        project_split(plan, &q->box, boxes);
    for (uint32_t k = 0; k < n && st == CM_OK; k++) {
        st = cm_region_alloc(&parts[k], &boxes[k], msg, msg_size);
        if (st == CM_OK)
            st = cm_scm_solve(q->model, &q->lat, &plan->opt, &parts[k], msg, msg_size);
    }
    const double t1 = cm_seconds();
    if (st == CM_OK)
        st = cm_join_stage1(parts, n, NULL, &r->stage1, msg, msg_size);
    if (st == CM_OK)
        st = cm_flat_alloc(&q->box, parts[0].ngroups, &r->r, msg, msg_size);
    for (uint32_t k = 0; k < n && st == CM_OK; k++)
        cm_flat_copy(&parts[k], &r->r);
    r->t1 = t1 - t0;
    r->t2 = cm_seconds() - t1;
    r->stage1_regions = n;
    for (uint32_t k = 0; parts && k < n; k++)
        cm_region_free(&parts[k]);
    free(parts);
    free(boxes);
    return st;
}

/* What a resumed file must have been made with. */
typedef struct solve_fit {
    const cm_model *m;
    const cm_lattice *lat;
    const char *plan, *db;
} solve_fit;

/* A project_fits_fn: the same model, parameters, lattice and plan. */
static cm_status same_solve(void *user, const cm_store_info *info, const cm_model **model,
                            char *msg, size_t msg_size)
{
    const solve_fit *f = user;
    char params[4096];
    cm_params_json(&f->m->values, params, sizeof params);
    const char *differs = strcmp(info->model, f->m->name)             ? "model"
                          : strcmp(info->params, params)              ? "parameters"
                          : !cm_lattice_equal(&info->lattice, f->lat) ? "lattice (region, cells)"
                          : strcmp(info->plan, f->plan)               ? "plan (split, extend, ...)"
                                                                      : NULL;
    if (differs)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "%s was made by another solve (its %s differs): resume with the options "
                       "of: %s",
                       f->db, differs, info->command);
    *model = f->m;
    return CM_OK;
}

/* The database: a new one, or the saved cluster, which must come from the
 * same model, parameters, lattice and plan. */
static cm_status open_store(const solve_request *q, const char *plan, solve_result *r, char *msg,
                            size_t msg_size)
{
    if (!q->resume)
        return project_create(q->db, q->model, q->lib, &q->lat, q->command, plan, &r->store,
                              &r->c, msg, msg_size);
    solve_fit fit = {q->model, &q->lat, plan, q->db};
    cm_store_info info;
    return project_resume(q->db, same_solve, &fit, &r->store, &info, &r->c, &r->upgraded_from,
                          msg, msg_size);
}

/* A cluster of regions: the box cut as the plan says, then extended. */
static cm_status solve_cluster(const solve_request *q, solve_result *r, char *msg,
                               size_t msg_size)
{
    project_plan plan = q->plan;
    cluster_watch watch = {q, r};
    plan.joined = cluster_progress;
    plan.joined_user = &watch;
    char plan_text[1024];
    project_plan_text(&plan, &q->box, plan_text, sizeof plan_text);
    cm_status st = CM_OK;
    if (q->db)
        st = open_store(q, plan_text, r, msg, msg_size);
    else
        cm_cluster_init(&r->c, &q->lat);
    r->c.keep_exits = q->db != NULL; /* only a database saves them; no image is read */
    r->c.threads = plan.opt.threads;
    r->c.mem_budget = q->mem ? q->mem : q->db ? project_default_mem() : 0;
    r->c.source = q->ranks && q->ranks->size > 1 ? &q->ranks->source : NULL;
    r->first = "regions and joins";
    r->second = "summary";
    const double t0 = cm_seconds();
    if (st == CM_OK)
        st = project_add_box(&r->c, r->store, q->model, &plan, &q->box, NULL, msg, msg_size);
    if (st == CM_OK && plan.extend > 0)
        st = project_extend(&r->c, r->store, q->model, &plan, &q->box, q->step_done, q->step_user,
                            &r->nsteps, r->stop, sizeof r->stop, msg, msg_size);
    r->t1 = cm_seconds() - t0;
    return st;
}

/* The summary of a cluster: from the database when there is one, else
 * from the periodic cells the cluster noted and its basin counts (no cell
 * is read either way). */
static cm_status summarise_cluster(const solve_request *q, solve_result *r, char *msg,
                                   size_t msg_size)
{
    cm_cluster *c = &r->c;
    cm_cluster_bounds(c, &r->box);
    r->cells = c->cells;
    r->ngroups = c->ngroups;
    r->groups = calloc((size_t)c->ngroups + 1, sizeof *r->groups);
    if (!r->groups)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %u groups", c->ngroups);
    if (r->store)
        return cm_store_groups(r->store, r->groups, c->ngroups, &r->sink, msg, msg_size);
    r->sink = cm_cluster_sink_cells(c);
    return cm_cluster_describe_new(c, q->model, r->groups, msg, msg_size);
}

/* The summary of a single region (or Stage 1's flattened regions). */
static cm_status summarise_region(const solve_request *q, solve_result *r, char *msg,
                                  size_t msg_size)
{
    const int threads = q->plan.opt.threads;
    cm_status st = q->stage1 ? CM_OK : cm_region_settle_exits(&r->r, threads, &r->exits, msg,
                                                               msg_size);
    r->box = r->r.box;
    r->cells = r->r.ncells;
    r->ngroups = r->r.ngroups;
    if (st == CM_OK && q->slow_share)
        cm_scm_slow_share(&r->r, threads, r->slow);
    if (st == CM_OK)
        st = cm_scm_describe(q->model, &q->lat, &r->r, &r->groups, &r->sink, msg, msg_size);
    return st;
}

/* The system's attractors over the groups, stored in the database. */
static cm_status find_attractors(const solve_request *q, solve_result *r, char *msg,
                                 size_t msg_size)
{
    const double t0 = cm_seconds();
    cm_attractor_options o = q->att;
    o.threads = q->plan.opt.threads;
    /* the cells' groups: the region's, or the cluster's (resolved on the way) */
    cm_status st = r->r.group ? cm_region_attractors(q->model, &q->lat, &r->r,
                                                     q->plan.opt.max_steps, &r->exits, r->groups,
                                                     &o, &r->att, msg, msg_size)
                              : cluster_ends_open(&r->joined, &r->c, msg, msg_size);
    if (st == CM_OK && !r->r.group)
        st = cm_cluster_attractors(q->model, &r->joined.cc, r->groups, &o, &r->att, msg,
                                   msg_size);
    if (st != CM_OK)
        return st;
    if (q->stage1) { /* its sink is Stage 1's: pending, not followed */
        r->att.outside_steps = 0;
        r->att.outside_cells = r->sink;
    }
    r->att_seconds = cm_seconds() - t0;
    cm_attractor_options used;
    cm_attractor_defaults(q->model, &o, &used);
    used.threads = 0;
    return r->store ? cm_store_put_attractors(r->store, &r->att, &used, q->lat.dim, msg, msg_size)
                    : CM_OK;
}

bool solve_small(uint64_t cells, bool extends) { return !extends && cells < 32768; }

/* Whether a solve on q->ranks can share its regions among them: the same
 * answer on every rank, which all give. */
static cm_status ranks_can_share(const solve_request *q, char *msg, size_t msg_size)
{
    const int n = q->ranks->size;
    if (!q->cluster || q->stage1)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a solve on %d ranks shares its regions among them: split the box "
                       "(--split) or extend it (--extend)%s, or run it without mpirun",
                       n, q->stage1 ? "; --stage1 runs in one process" : "");
    const uint32_t regions = project_split(&q->plan, &q->box, NULL);
    if (q->plan.extend == 0 && regions < (uint32_t)n)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "%d ranks for %u region%s: run at most %u (mpirun -n %u), or split the "
                       "box into more regions (--split)",
                       n, regions, regions == 1 ? "" : "s", regions, regions);
    return CM_OK;
}

/* What a rank is to solve, as text: the model, its parameters, the
 * lattice and the plan (the box, split, steps, extension). */
static void solve_what(const solve_request *q, char *out, size_t size)
{
    char params[4096], plan[1024];
    cm_params_json(&q->model->values, params, sizeof params);
    project_plan_text(&q->plan, &q->box, plan, sizeof plan);
    size_t used = (size_t)snprintf(out, size, "%s %s %s", q->model->name, params, plan);
    for (int d = 0; d < q->lat.dim && used < size; d++)
        used += (size_t)snprintf(out + used, size - used, " %.17g+%.17g", q->lat.origin[d],
                                 q->lat.width[d]);
}

/* The start of a solve on several ranks: every rank checks that it can
 * go on, and all agree; a worker then solves rank 0's boxes until it is
 * told to stop (r->worker). */
static cm_status ranks_begin(const solve_request *q, solve_result *r, char *msg, size_t msg_size)
{
    solve_ranks *rk = q->ranks;
    const cm_status st = ranks_can_share(q, msg, msg_size);
    bool all_ok, differs;
    int failed;
    char what[4096 + 1200];
    solve_what(q, what, sizeof what);
    rk->ready(rk, st == CM_OK, what, &all_ok, &failed, &differs);
    if (st != CM_OK)
        return st;
    if (differs)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "rank %d was asked for another solve than rank 0 (its model, parameters, "
                       "lattice or plan differ): give every rank the same arguments",
                       failed);
    if (!all_ok)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "rank %d could not start the solve (rerun with CELLMAP_RANKS_STDERR=1 "
                       "to see every rank's messages)",
                       failed);
    if (rk->rank == 0)
        return CM_OK;
    r->worker = true;
    return rk->serve(rk, q->model, &q->lat, q->plan.opt.max_steps, q->plan.opt.threads, msg,
                     msg_size);
}

void solve_ranks_refuse(solve_ranks *rk)
{
    bool all_ok, differs;
    int failed;
    rk->ready(rk, false, NULL, &all_ok, &failed, &differs);
}

cm_status solve_run(const solve_request *q, solve_result *r, char *msg, size_t msg_size)
{
    memset(r, 0, sizeof *r);
    for (int d = 0; d < CM_MAX_DIM; d++)
        r->slow[d] = NAN; /* known for a single region only */
    const bool ranked = q->ranks && q->ranks->size > 1;
    cm_status st = ranked ? ranks_begin(q, r, msg, msg_size) : CM_OK;
    if (st != CM_OK || r->worker)
        return st;
    if (!q->stage1 && q->cluster) {
        const double t0 = cm_seconds();
        st = solve_cluster(q, r, msg, msg_size);
        if (ranked) { /* the workers' part is done */
            st = q->ranks->stop(q->ranks, st);
            r->ranks = q->ranks;
        }
        if (st == CM_OK)
            st = summarise_cluster(q, r, msg, msg_size);
        r->t2 = cm_seconds() - t0 - r->t1;
    } else {
        st = q->stage1 ? solve_stage1(q, r, msg, msg_size) : solve_whole(q, r, msg, msg_size);
        if (st == CM_OK)
            st = summarise_region(q, r, msg, msg_size);
    }
    return st == CM_OK ? find_attractors(q, r, msg, msg_size) : st;
}

void solve_json_ranks(json *j, const solve_result *r)
{
    const solve_ranks *rk = r->ranks;
    if (!rk)
        return;
    json_object(j, "ranks");
    json_int(j, "count", rk->size);
    json_uint(j, "regions_from_workers", rk->regions_received);
    json_array(j, "regions_by_rank");
    for (int k = 0; k < rk->size; k++)
        json_uint(j, NULL, rk->regions_by_rank[k]);
    json_array_end(j);
    json_uint(j, "bytes_received", rk->bytes_received);
    json_uint(j, "bytes_sent", rk->bytes_sent);
    const double bytes = (double)(rk->bytes_received + rk->bytes_sent);
    json_num(j, "bytes_per_cell", r->cells ? bytes / (double)r->cells : 0);
    json_object_end(j);
}

cm_status solve_draw(const solve_request *q, solve_result *r, const png_opts *po, char *msg,
                     size_t msg_size)
{
    basin_png png = {po, q->model, &q->lat, &r->r, r->groups, {0, 0}, {0, 0}, NULL,
                     po->by == BY_ATTRACTORS ? &r->att : NULL, NULL, NULL, NULL};
    /* where the sink cells' sequences leave the cells drawn */
    cm_region_cells whole = {&r->r, q->model, &q->lat, q->plan.opt.max_steps};
    const cm_computed region = cm_region_computed(&whole);
    png.computed = r->r.group ? &region : &r->joined.computed;
    cm_status st = CM_OK;
    if (po->has_view) {
        cm_box box;
        view_cells(&q->lat, po->lo, po->hi, &r->box, &box);
        cm_region_free(&r->r);
        memcpy(png.lo, po->lo, sizeof png.lo);
        memcpy(png.hi, po->hi, sizeof png.hi);
        st = cm_cluster_flatten(&r->c, &box, &r->r, msg, msg_size);
    } else if (!r->r.group) {
        st = cm_cluster_flatten(&r->c, &r->box, &r->r, msg, msg_size);
    }
    return st == CM_OK ? figure_write(&png, msg, msg_size) : st;
}

cm_status solve_finish(solve_result *r, char *msg, size_t msg_size)
{
    const cm_status st = r->store ? cm_store_finish(r->store, msg, msg_size) : CM_OK;
    r->store = NULL;
    return st;
}

bool solve_replacing(const solve_result *r) { return r->store && cm_store_replacing(r->store); }

void solve_store_stats(const solve_result *r, cm_store_stats *out)
{
    cm_store_get_stats(r->store, out);
}

void solve_result_free(solve_result *r)
{
    char ignored[256];
    cm_store_close(r->store, ignored, sizeof ignored);
    r->store = NULL;
    cluster_ends_close(&r->joined); /* before its cluster: it gives back its reserve */
    cm_cluster_free(&r->c);
    free(r->groups);
    r->groups = NULL;
    cm_attractors_free(&r->att);
    cm_exits_free(&r->exits);
    cm_region_free(&r->r);
}
