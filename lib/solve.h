/* lib/solve.h - a solve as `cellmap solve` and the library run one: the
 * cells of a box mapped in one region, or as a cluster of regions (a
 * split, adaptive extension, a database, a view cut from one), or through
 * Stage 1 of a join only; then the groups summarised, the system's
 * attractors found with the true map and stored, the figure drawn and the
 * database completed.
 *
 * A database (q->db) is new, replacing an older cellmap database at its
 * path only when solve_finish says the cluster is complete, or resumed
 * (q->resume) when it was made by the same model, parameters, lattice and
 * plan. Every join is committed as it happens, so a stopped or failed
 * solve leaves a file that a resumed one completes (solve_replacing says
 * whether the file is a new one, which then stays as it was).
 *
 * Nothing is printed: results, times and the extension's steps are
 * returned, and long work reports through q->hooks (cells done; a stop
 * request ends the solve with CM_ECANCELED after the last commit). */
#ifndef CM_LIB_SOLVE_H
#define CM_LIB_SOLVE_H

#include <stdbool.h>

#include "cellmap/join_stage1.h"
#include "lib/attractor_report.h"
#include "lib/figure.h"
#include "lib/json.h"
#include "lib/project.h"
#include "lib/ranks.h"
#include "lib/work.h"

/* The most extension steps one solve takes (--extend). */
enum { SOLVE_MAX_EXTEND = 1000 };

typedef struct solve_request {
    const cm_model *model;
    const cm_model_lib *lib; /* the plugin the model comes from (NULL: built in) */
    cm_lattice lat;
    cm_box box;          /* the cells solved */
    project_plan plan;   /* split, options, extension, bounds; plan.joined is the driver's */
    bool cluster;        /* as a cluster of regions (implied by a split, extend or db) */
    bool stage1;         /* the split's regions through Stage 1 of their join only */
    const char *db;      /* the database, or NULL */
    bool resume;         /* resume db instead of replacing it */
    const char *command; /* the command line, for the file's provenance */
    uint64_t mem;        /* the cluster's memory budget in bytes (0: with a database
                            project_default_mem(), else none: nothing to page to) */
    cm_attractor_options att;
    bool slow_share;     /* measure a single region's slow directions (cm_scm_slow_share) */
    const work_hooks *hooks;
    project_step_fn step_done; /* after each extension step (may be NULL) */
    void *step_user;
    solve_ranks *ranks; /* MPI ranks that share the solve (lib/ranks.h); NULL: this process */
} solve_request;

typedef struct solve_result {
    cm_box box;     /* the region, or the cluster's bounding box */
    uint64_t cells; /* cells computed (the bounding box has others) */
    uint64_t sink;  /* cells of the sink's domain */
    uint32_t ngroups;
    cm_group_info *groups;   /* in id order */
    double slow[CM_MAX_DIM]; /* cm_scm_slow_share of a single region; NaN: unknown */
    cm_attractor_set att;    /* the attractors the groups' true orbits give */
    double att_seconds;
    /* the two phases' names and durations: images and classification, or
     * regions and joins and the summary, or regions and stage 1 */
    const char *first, *second;
    double t1, t2;
    double join_seconds; /* of t1, a cluster's: its joins (on the joining thread) */
    project_step steps[SOLVE_MAX_EXTEND]; /* the extension's steps */
    int nsteps;
    char stop[1100];       /* why the extension ended */
    cm_stage1_stats stage1; /* q->stage1: what Stage 1 did with the sink */
    uint32_t stage1_regions;
    int upgraded_from;     /* a resumed file's format was upgraded from this version */
    /* the cells: a single region's, and its exits; or the cluster, its
     * exits and its database */
    cm_region r;
    cm_exits exits;
    cm_cluster c;
    cluster_ends joined;
    cm_store *store;
    bool worker; /* this rank solved regions for rank 0: it has nothing to report */
    const solve_ranks *ranks; /* the ranks that shared the solve, with rank 0's
                                 traffic (q->ranks); NULL: one process */
} solve_result;

/* Whether a solve of `cells` cells (extended or not) is better run on one
 * thread than on all: below 32 768 cells without an extension, waking a
 * second thread for each of its short parallel regions costs more than it
 * saves (2 vCPUs: 128 x 128 cells, figure included, 16 ms on one thread
 * against 27 on two; 256 x 256, 62 against 50; docs/engine.md). The results
 * are the same for any number of threads. The caller, which owns the
 * process's OpenMP settings, decides what to do with it. */
bool solve_small(uint64_t cells, bool extends);

/* Solves, summarises and finds the attractors (stored in the database).
 * *r is initialised here; solve_result_free frees it whatever the status. */
cm_status solve_run(const solve_request *q, solve_result *r, char *msg, size_t msg_size);

/* For a rank that cannot go as far as solve_run (its request failed
 * before): the step every rank takes there (lib/ranks.h, step 2), so that
 * the others fail with it instead of waiting. */
void solve_ranks_refuse(solve_ranks *rk);

/* With q->ranks: the "ranks" object of solve --json (their count, the
 * regions the workers solved, the bytes rank 0 received and sent, and those
 * per cell computed). Nothing for a solve in one process. */
void solve_json_ranks(json *j, const solve_result *r);

/* Draws the solved cells, or those of po's view (cells outside the cluster
 * drawn as not computed), as po says (lib/figure.h). */
cm_status solve_draw(const solve_request *q, solve_result *r, const png_opts *po, char *msg,
                     size_t msg_size);

/* Completes the database (a new one replaces the older file at its path). */
cm_status solve_finish(solve_result *r, char *msg, size_t msg_size);

/* Whether the database is a new one that replaces a file only once complete. */
bool solve_replacing(const solve_result *r);

/* What the database wrote and paged. */
void solve_store_stats(const solve_result *r, cm_store_stats *out);

void solve_result_free(solve_result *r);

#endif
