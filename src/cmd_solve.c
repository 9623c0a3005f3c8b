/* cellmap solve: simple cell mapping of one region, with a summary, a basin
 * PNG and a .cmdb database. */
#include <math.h>

#include "cellmap/clock.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/stat.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "cellmap/join.h"
#include "cellmap/output.h"
#include "cellmap/join_stage1.h"
#include "cellmap/scm.h"
#include "cellmap/store.h"
#include "models/registry.h"
#include "src/interrupt.h"
#include "lib/json.h"
#include "src/outfile.h"
#include "src/progress.h"
#include "lib/project.h"
#include "src/args.h"
#include "lib/attractor_report.h"
#include "src/attractor_opts.h"
#include "src/figure_opts.h"
#include "src/commands.h"

static const char solve_help[] =
    "usage: cellmap solve [--model NAME] [--param k=v[,k=v]] [--region LO:HI[,LO:HI...]]\n"
    "                     [--cells N[xM...]] [--split K[xL...]] [--max-steps K]\n"
    "                     [--extend N [--escape-below F] [--bounds LO:HI[,LO:HI...]]]\n"
    "                     [--threads T]\n"
    "                     [--png FILE] [--svg FILE] [--size WxH] [--layers L,...] [--png-mode rgb|indexed]\n"
    "                     [--view X0:X1,Y0:Y1] [--db FILE [--resume] [--mem BYTES]] [--json]\n"
    "                     [--stage1]\n\n"
    "Simple cell mapping (centre-point method) of a box of state space cut into\n"
    "cells, then the system's attractors: each periodic cell group is checked by\n"
    "the true map from its anchor cell (true period, or aperiodic with the cells\n"
    "its orbit visits), and groups whose true orbits end on one attractor are one\n"
    "(docs/engine.md, \"Attractors\"). Prints the attractors, then the groups.\n"
    "Without options it solves the thesis' C-SCM example (4.6.3):\n"
    "microchaos-pd, alpha=0.078, beta=0, P=0.007, D=0.02 on 0:500,-40:40.\n\n"
    "  --model NAME        a model of `cellmap models` (default microchaos-pd)\n"
    "  --model-lib P.so    load the models of a plugin (repeatable; examples/plugin/)\n"
    "  --param k=v,...     parameters (repeatable; vectors as v1:v2:...)\n"
    "  --region LO:HI,...  the box, one range per state dimension\n"
    "                      (default: the model's example region)\n"
    "  --cells NxM...      cells per dimension (default 1000 per dimension, 100 in 3-D+)\n"
    "  --split KxL...      solve the box as K x L x ... regions concurrently and join\n"
    "                      them into one cluster (same result; uses every core)\n"
    "  --extend N          adaptive extension (4.6.4): then add, N times, the neighbouring\n"
    "                      box of the region's size where the most sequences escape\n"
    "  --escape-below F    stop extending once the sequences of fewer than this fraction\n"
    "                      of the cluster's cells escape into the world (default 0: never)\n"
    "  --bounds LO:HI,...  extend only within this box of state space (default: anywhere)\n"
    "  --max-steps K       re-step while the image stays in its own cell (default 1)\n"
    "  --threads T         OpenMP threads for the images (default: all cores)\n"
    ATTRACTOR_OPTIONS_HELP BY_OPTION_HELP;
/* The rest of the help (one string would exceed what C compilers must take). */
static const char solve_help_outputs[] =
    "  --png FILE          write a figure of the basins: basin, attractors, overlays,\n"
    "                      axes, legend and title (--layers basin,attractors: the bare\n"
    "                      image of one pixel per cell)\n" PNG_OPTIONS_HELP
    "  --db FILE           write the cluster to a .cmdb SQLite database as it is solved,\n"
    "                      one transaction per region (replaces an older .cmdb only)\n"
    "  --resume            continue the solve saved in --db FILE (same options) after\n"
    "                      it was interrupted; a finished file is only summarised\n"
    "  --mem BYTES         bound the cell arrays held in memory (e.g. 512M, 2G; node\n"
    "                      tables take a quarter more); regions are paged to and from\n"
    "                      --db FILE (same results)\n"
    "  --json              print the summary as JSON\n"
    "  --quiet             no progress line and no summary (--json still prints)\n"
    "  --stage1            stop the join of the --split regions after Stage 1 (thesis\n"
    "                      Alg. C.5, Fig. 4.27): sink cells leading into another region's\n"
    "                      groups take their group; those leading into its sink domain\n"
    "                      (pending, left to Stage 2) stay in the sink\n";

/* Most regions --split may cut the box into; most --extend steps. */
enum { MAX_SPLIT = 4096, MAX_EXTEND = 1000 };

typedef struct solve_args {
    model_opts mo;
    lattice_opts lat;
    int64_t split[CM_MAX_DIM];
    int n_split;
    int max_steps, threads, json, stage1, quiet;
    FILE *report; /* the summary: stdout, or stderr when the PNG goes to stdout */
    int extend;
    double escape_below;
    const char *bounds_text;
    png_opts png;
    const char *db;
    int resume;
    uint64_t mem;
    cm_attractor_options att;
} solve_args;

static int parse_solve(cli *c, solve_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        int64_t v;
        if (strcmp(c->opt, "--help") == 0) {
            fputs(solve_help, stdout);
            fputs(solve_help_outputs, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (attractor_options_take(c, &a->att, &err)) {
        } else if (lattice_opts_take(c, &a->lat, &err)) {
        } else if (cli_is(c, "--split", true, &err)) {
            if (c->value && !parse_counts(c->value, a->split, &a->n_split, CM_MAX_DIM))
                err = cli_usage_error(c, "--split: '%s' is not K[xL...] with positive integers",
                                      c->value);
        } else if (cli_is(c, "--extend", true, &err)) {
            if (c->value && (!parse_int64(c->value, &v) || v < 1 || v > MAX_EXTEND))
                err = cli_usage_error(c, "--extend: '%s' must be an integer in 1..%d", c->value,
                                      MAX_EXTEND);
            else if (c->value)
                a->extend = (int)v;
        } else if (cli_is(c, "--escape-below", true, &err)) {
            if (c->value && (!parse_double(c->value, &a->escape_below) ||
                             !(a->escape_below >= 0 && a->escape_below <= 1)))
                err =
                    cli_usage_error(c, "--escape-below: '%s' must be a fraction in 0..1", c->value);
        } else if (cli_is(c, "--bounds", true, &err)) {
            a->bounds_text = c->value;
        } else if (cli_take_int(c, "--max-steps", 1, MAX_STEPS_LIMIT, &a->max_steps, &err)) {
        } else if (cli_take_int(c, "--threads", 1, THREADS_LIMIT, &a->threads, &err)) {
        } else if (png_opts_take(c, &a->png, &err)) {
        } else if (cli_is(c, "--db", true, &err)) {
            a->db = c->value;
        } else if (cli_is(c, "--resume", false, &err)) {
            a->resume = 1;
        } else if (cli_take_mem(c, &a->mem, &err)) {
        } else if (cli_is(c, "--json", false, &err)) {
            a->json = 1;
        } else if (cli_is(c, "--quiet", false, &err)) {
            a->quiet = 1;
        } else if (cli_is(c, "--stage1", false, &err)) {
            a->stage1 = 1;
        } else {
            err = cli_stray(c);
        }
    }
    if (!err)
        err = png_opts_check(c, &a->png);
    char why[2048];
    if (!err && !png_opts_apart(&a->png, a->db, true, why, sizeof why))
        err = cli_usage_error(c, "%s", why);
    if (!err && !a->extend && (a->bounds_text || a->escape_below > 0))
        err = cli_usage_error(c, "--bounds and --escape-below apply to --extend; add --extend N");
    if (!err && a->stage1 && (!a->n_split || a->extend || a->db || a->png.has_view))
        err = cli_usage_error(c, "--stage1 shows the regions of --split after Stage 1 of their "
                                 "join; it takes --split and no --extend, --db or --view");
    if (!err && !a->db && (a->resume || a->mem))
        err = cli_usage_error(c, "--resume and --mem need a database to page to; add --db FILE");
    const bool png_to_stdout = a->png.path && cm_output_names_stdout(a->png.path);
    if (!err && png_to_stdout && a->json)
        err = cli_usage_error(c, "--png %s and --json would both write to stdout; give the PNG "
                                 "a file name",
                              a->png.path);
    a->report = png_to_stdout ? stderr : stdout;
    return err;
}

/* Lattice and box from --region and --cells, checked against --split. */
static int make_lattice(const cli *c, const solve_args *a, const cm_model *m, cm_lattice *lat,
                        cm_box *box)
{
    const int err = lattice_opts_build(c, &a->lat, m, &a->mo.set, lat, box);
    if (err)
        return err;
    if (a->n_split && a->n_split != m->dim)
        return cli_usage_error(c, "--split has %d count(s) but model %s has dimension %d",
                               a->n_split, m->name, m->dim);
    double parts = 1.0;
    for (int d = 0; d < a->n_split; d++) {
        parts *= (double)a->split[d];
        if (a->split[d] > box->hi[d])
            return cli_usage_error(c,
                                   "--split: %lld parts in dimension %d, but it has only "
                                   "%lld cells",
                                   (long long)a->split[d], d + 1, (long long)box->hi[d]);
    }
    if (parts > MAX_SPLIT)
        return cli_usage_error(c, "--split asks for %.0f regions; at most %d", parts, MAX_SPLIT);
    return EXIT_OK;
}

/* --bounds as a box of cells (the cells the bounds touch); it must hold
 * the region. */
static int make_bounds(const cli *c, const solve_args *a, const cm_lattice *lat, const cm_box *box,
                       cm_box *bounds)
{
    double lo[CM_MAX_DIM], hi[CM_MAX_DIM];
    int n = 0;
    *bounds = *box;
    if (!a->bounds_text)
        return EXIT_OK;
    if (!parse_ranges(a->bounds_text, lo, hi, &n, CM_MAX_DIM))
        return cli_usage_error(c, "--bounds: '%s' is not LO:HI[,LO:HI...] with LO < HI",
                               a->bounds_text);
    if (n != lat->dim)
        return cli_usage_error(c, "--bounds has %d range(s) but the model has dimension %d", n,
                               lat->dim);
    for (int d = 0; d < n; d++) {
        if (fabs(lo[d]) > 1e15 || fabs(hi[d]) > 1e15 ||
            fabs((hi[d] - lo[d]) / lat->width[d]) > 1e15)
            return cli_usage_error(c, "--bounds: range %d is too large for the lattice", d + 1);
        bounds->lo[d] = cm_lattice_border(lat, d, lo[d], 0);
        bounds->hi[d] = cm_lattice_border(lat, d, hi[d], 1);
        if (bounds->lo[d] > box->lo[d] || bounds->hi[d] < box->hi[d])
            return cli_usage_error(c, "--bounds must contain the region (dimension %d)", d + 1);
    }
    return EXIT_OK;
}

static int larger_basin_first(const void *a, const void *b)
{
    const cm_group_info *x = a, *y = b;
    if (x->basin_cells != y->basin_cells)
        return x->basin_cells > y->basin_cells ? -1 : 1;
    return x->id < y->id ? -1 : (x->id > y->id);
}

/* The text summary lists the groups with the largest basins first; --json
 * lists all of them in id order. */
enum { TEXT_GROUPS = 20 };

typedef struct extend_log {
    project_step steps[MAX_EXTEND];
    int n;
    char stop[1100]; /* why the extension ended */
} extend_log;

/* Durations of the two phases of a solve: images and classification, or,
 * with --split, the regions (solved concurrently) and their joins. */
typedef struct timing {
    const char *first, *second;
    double t1, t2;
} timing;

/* What the summary and the JSON report. */
typedef struct summary {
    cm_box box;     /* the region, or the cluster's bounding box */
    uint64_t cells; /* cells computed (the bounding box has others) */
    uint64_t sink;  /* cells of the sink's domain */
    uint32_t ngroups;
    cm_group_info *groups; /* in id order */
    double slow[CM_MAX_DIM]; /* cm_scm_slow_share of a single region; NaN: unknown */
    cm_attractor_set att;    /* the attractors the groups' true orbits give */
    double att_seconds;
    cm_exits exits;          /* a single region's (cm_region_settle_exits) */
    cluster_ends joined;     /* a cluster's exits, for its attractors and figure */
} summary;

/* A share of slow cells (cm_scm_slow_share) above which the summary says so. */
#define SLOW_SHARE 0.25

static void print_text(FILE *out, const cm_model *m, const cm_lattice *lat, const summary *sum,
                       const timing *t, const extend_log *log)
{
    char params[2048];
    cm_params_json(&m->values, params, sizeof params);
    const uint64_t cells = sum->cells, box_cells = cm_box_cells(&sum->box), sink = sum->sink;
    const cm_group_info *g = sum->groups;
    const uint32_t ngroups = sum->ngroups;
    if (log)
        fprintf(out, "extension stopped: %s\n", log->stop);
    fprintf(out, "model %s %s\n", m->name, params);
    fprintf(out, "cells %llu", (unsigned long long)cells);
    if (cells != box_cells)
        fprintf(out, " (of %llu in the bounding box; the others not computed)",
               (unsigned long long)box_cells);
    fprintf(out, "\n");
    fprintf(out, "time: %s %.3f s, %s %.3f s (%.1f ns/cell), attractors %.3f s (%llu steps)\n",
            t->first, t->t1, t->second, t->t2, 1e9 * (t->t1 + t->t2) / (double)cells,
            sum->att_seconds, (unsigned long long)sum->att.steps);
    attractor_text(out, lat, &sum->att, cells, TEXT_GROUPS);
    fprintf(out, "cell groups %u (simple cell mapping's periodic groups; the sink %llu cells, "
                 "%.1f%%):\n",
            ngroups, (unsigned long long)sink, 100.0 * (double)sink / (double)cells);
    cm_group_info *sorted = malloc((ngroups + 1) * sizeof *sorted);
    if (!sorted)
        return;
    memcpy(sorted, g, ngroups * sizeof *sorted);
    qsort(sorted, ngroups, sizeof *sorted, larger_basin_first);
    fprintf(out, "%6s %8s %12s  %-9s %6s  %s\n", "group", "period", "basin", "kind", "attr.",
            "centre");
    for (uint32_t k = 0; k < ngroups && k < TEXT_GROUPS; k++) {
        char centre[CM_MAX_DIM * CM_NUM_TEXT], attractor[16];
        cm_point_text(lat, sorted[k].centre, ", ", centre, sizeof centre);
        const uint32_t at = sum->att.of_group[sorted[k].id];
        snprintf(attractor, sizeof attractor, at == CM_FATE_DIVERGED     ? "div."
                                              : at == CM_FATE_UNRESOLVED ? "?"
                                                                         : "%u",
                 at);
        fprintf(out, "%6u %8u %12llu  %-9s %6s  (%s)\n", sorted[k].id, sorted[k].period,
                (unsigned long long)sorted[k].basin_cells, cm_group_kind_name(sorted[k].kind),
                attractor, centre);
    }
    if (ngroups > TEXT_GROUPS)
        fprintf(out, "... and %u smaller groups (--json lists all)\n", ngroups - TEXT_GROUPS);
    for (int d = 0; d < lat->dim && lat->dim > 1; d++)
        if (sum->slow[d] > SLOW_SHARE)
            fprintf(out, "note: %.0f%% of the cells that move stay in their own %s slab: the "
                         "map moves less than a cell per step in %s, which cell mapping cannot "
                         "follow (a slowly decaying %s never decays); finer cells in %s give "
                         "the true picture (docs/engine.md, \"Slow directions\")\n",
                    100 * sum->slow[d], cm_model_coord_name(m, d), cm_model_coord_name(m, d),
                    cm_model_coord_name(m, d), cm_model_coord_name(m, d));
    free(sorted);
}

static void print_json_extension(json *j, const cm_lattice *lat, const extend_log *log)
{
    json_object(j, "extension");
    json_array(j, "steps");
    for (int k = 0; k < log->n; k++) {
        const project_step *s = &log->steps[k];
        json_object(j, NULL);
        json_box(j, "box", lat, &s->box);
        json_uint(j, "cells", cm_box_cells(&s->box));
        json_uint(j, "escaping", s->escaping);
        json_uint(j, "all_escaping", s->all_escaping);
        json_uint(j, "cluster_cells", s->cluster_cells);
        json_uint(j, "new_groups", s->new_groups);
        json_uint(j, "straddling_groups", s->straddling);
        json_seconds(j, "time_s", s->seconds);
        json_object_end(j);
    }
    json_array_end(j);
    json_str(j, "stop", log->stop);
    json_object_end(j);
}

static void print_json(FILE *out, const cm_model *m, const cm_lattice *lat, const summary *sum,
                       const timing *t, const extend_log *log)
{
    json j;
    json_begin(&j, out, "solve");
    json_model(&j, m);
    json_lattice(&j, lat);
    json_box(&j, "box", lat, &sum->box);
    json_uint(&j, "box_cells", cm_box_cells(&sum->box));
    json_uint(&j, "cells", sum->cells);
    json_uint(&j, "sink_cells", sum->sink);
    json_object(&j, "time_s");
    json_seconds(&j, t->first, t->t1);
    json_seconds(&j, t->second, t->t2);
    json_seconds(&j, "attractors", sum->att_seconds);
    json_object_end(&j);
    if (log)
        print_json_extension(&j, lat, log);
    attractor_json(&j, lat, &sum->att);
    attractor_json_groups(&j, sum->groups, sum->ngroups, lat, &sum->att);
    json_end(&j);
}

/* The progress line (src/progress.h) and Ctrl-C: the callbacks below stop
 * the solve when it came. */

/* A cm_progress_fn for a solve in one region. */
static int whole_progress(void *user, const char *phase, double fraction)
{
    progress *p = user;
    char what[64];
    snprintf(what, sizeof what, "%s %.0f%%", phase, 100 * fraction);
    progress_say(p, (uint64_t)(fraction * (double)p->total), what);
    return interrupt_requested();
}

/* A cm_joined_fn for a cluster (after the join's commit): the line, and
 * Ctrl-C, which stops the solve with what is committed. */
static cm_status cluster_progress(void *user, cm_cluster *c, uint32_t box,
                                  const cm_join_stats *stats, char *msg, size_t msg_size)
{
    progress *p = user;
    (void)box, (void)stats;
    char what[64];
    snprintf(what, sizeof what, "%u region%s joined", c->nregions, c->nregions == 1 ? "" : "s");
    progress_say(p, c->cells, what);
    return interrupt_requested() ? cm_fail(CM_ECANCELED, msg, msg_size, "interrupted") : CM_OK;
}

static cm_status solve_whole(const solve_args *a, const cm_model *m, const cm_lattice *lat,
                             const cm_box *box, cm_region *r, timing *t, progress *p, char *msg,
                             size_t msg_size)
{
    /* exits recorded: their orbits are followed (cm_region_settle_exits) */
    const cm_scm_options opt = {.max_steps = a->max_steps,
                                .threads = a->threads,
                                .progress = whole_progress,
                                .user = p,
                                .record_exits = 1};
    *t = (timing){"images", "classification", 0, 0};
    cm_status st = cm_region_alloc(r, box, msg, msg_size);
    const double t0 = cm_seconds();
    if (st == CM_OK)
        st = cm_scm_images(m, lat, &opt, r, msg, msg_size);
    const double t1 = cm_seconds();
    if (st == CM_OK && interrupt_requested()) /* classification cannot stop half-way */
        st = cm_fail(CM_ECANCELED, msg, msg_size, "interrupted");
    if (st == CM_OK)
        st = cm_scm_classify(r, a->threads, msg, msg_size);
    t->t1 = t1 - t0;
    t->t2 = cm_seconds() - t1;
    return st;
}

/* --stage1: the regions of --split solved alone and taken through Stage 1
 * of their join only (thesis Fig. 4.27), flattened into r. */
static cm_status solve_stage1(const solve_args *a, const project_plan *plan, const cm_model *m,
                              const cm_lattice *lat, const cm_box *box, cm_region *r, timing *t,
                              char *msg, size_t msg_size)
{
    const cm_scm_options opt = plan->opt;
    const uint32_t n = project_split(plan, box, NULL);
    cm_box *boxes = malloc(n * sizeof *boxes);
    cm_region *parts = calloc(n, sizeof *parts);
    cm_status st =
        boxes && parts ? CM_OK : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the regions");
    *t = (timing){"regions", "stage 1", 0, 0};
    const double t0 = cm_seconds();
    if (st == CM_OK)
        project_split(plan, box, boxes);
    for (uint32_t k = 0; k < n && st == CM_OK; k++) {
        st = cm_region_alloc(&parts[k], &boxes[k], msg, msg_size);
        if (st == CM_OK)
            st = cm_scm_solve(m, lat, &opt, &parts[k], msg, msg_size);
    }
    const double t1 = cm_seconds();
    cm_stage1_stats stats;
    if (st == CM_OK)
        st = cm_join_stage1(parts, n, NULL, &stats, msg, msg_size);
    if (st == CM_OK)
        st = cm_flat_alloc(box, parts[0].ngroups, r, msg, msg_size);
    for (uint32_t k = 0; k < n && st == CM_OK; k++)
        cm_flat_copy(&parts[k], r);
    t->t1 = t1 - t0;
    t->t2 = cm_seconds() - t1;
    if (st == CM_OK && !a->json)
        fprintf(a->report, "stage 1 of the join of %u regions: of %llu sink cells, %llu now lead to groups, "
               "%llu leave every region, %llu are pending (left to Stage 2, drawn as the sink)\n",
               n, (unsigned long long)stats.sink_cells, (unsigned long long)stats.to_group,
               (unsigned long long)stats.to_sink, (unsigned long long)stats.pending);
    for (uint32_t k = 0; parts && k < n; k++)
        cm_region_free(&parts[k]);
    free(parts);
    free(boxes);
    return st;
}

/* The cluster being solved and the database it is saved to (may be NULL). */
typedef struct run {
    cm_cluster c;
    cm_store *store;
} run;

/* A project_step_fn: notes the step for the summary and says it as it ends. */
typedef struct step_report {
    const solve_args *a;
    const cm_lattice *lat;
    extend_log *log;
} step_report;

static void report_step(void *user, const project_step *s, int k)
{
    const step_report *rep = user;
    rep->log->steps[k] = *s;
    if (rep->a->json)
        return;
    char box[CM_MAX_DIM * 64];
    cm_box_text(rep->lat, &s->box, box, sizeof box);
    fprintf(rep->a->report,
            "extend %d: box %s (%llu cells): %llu of the %llu escaping sequences of %llu cells "
            "led there; %u new groups (%u across borders); %.3f s\n",
            k + 1, box, (unsigned long long)cm_box_cells(&s->box), (unsigned long long)s->escaping,
           (unsigned long long)s->all_escaping, (unsigned long long)s->cluster_cells, s->new_groups,
           s->straddling, s->seconds);
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
                          : !cm_lattice_equal(&info->lattice, f->lat) ? "lattice (--region, --cells)"
                          : strcmp(info->plan, f->plan)               ? "plan (--split, --extend, ...)"
                                                                      : NULL;
    if (differs)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "%s was made by another solve (its %s differs): resume with the options "
                       "of: %s",
                       f->db, differs, info->command);
    *model = f->m;
    return CM_OK;
}

/* --db before any work: a file to resume, or where a new one can be
 * written (an existing file there must be a cellmap database, which the
 * new one replaces once complete). */
static int check_db_arg(const solve_args *a)
{
    char why[1024];
    struct stat sb;
    if (!a->db)
        return EXIT_OK;
    if (a->resume)
        return cli_input_check("solve", a->db);
    if (stat(a->db, &sb) == 0 && S_ISREG(sb.st_mode) && cm_store_probe(a->db, why, sizeof why) != CM_OK) {
        fprintf(stderr, "cellmap solve: refusing to overwrite %s: %s; choose another --db file\n",
                a->db, why);
        return EXIT_USAGE;
    }
    return outfile_check("solve", a->db, true);
}

/* The database of --db: a new one, or (--resume) the saved cluster, which
 * must come from the same model, parameters, lattice and plan. */
static cm_status open_store(const solve_args *a, const char *command, const cm_model *m,
                            const cm_lattice *lat, const char *plan, run *rn, char *msg,
                            size_t msg_size)
{
    if (!a->resume)
    {
        const cm_model_lib *lib;
        cm_model_set_find(&a->mo.set, m->name, &lib);
        return project_create(a->db, m, lib, lat, command, plan, &rn->store, &rn->c, msg,
                              msg_size);
    }
    solve_fit fit = {m, lat, plan, a->db};
    cm_store_info info;
    int upgraded_from = 0;
    const cm_status st = project_resume(a->db, same_solve, &fit, &rn->store, &info, &rn->c,
                                        &upgraded_from, msg, msg_size);
    cli_said_upgrade("solve", a->db, upgraded_from);
    return st;
}

/* The project's plan from --split, --max-steps, --threads, --extend,
 * --escape-below and --bounds. */
static void make_plan(const solve_args *a, const cm_box *bounds, project_plan *p)
{
    memset(p, 0, sizeof *p);
    p->nsplit = a->n_split;
    memcpy(p->split, a->split, sizeof p->split);
    p->opt = (cm_scm_options){a->max_steps, a->threads, NULL, NULL, 1};
    p->extend = a->extend;
    p->escape_below = a->escape_below;
    p->bounds = a->bounds_text ? bounds : NULL;
    p->bounds_text = a->bounds_text;
}

/* --split, --extend and --db: a cluster of regions. */
static cm_status solve_cluster(const solve_args *a, const project_plan *plan, const char *command,
                               const cm_model *m, const cm_lattice *lat, const cm_box *box,
                               run *rn, timing *t, extend_log *log, char *msg, size_t msg_size)
{
    char plan_text[1024];
    project_plan_text(plan, box, plan_text, sizeof plan_text);
    cm_status st = CM_OK;
    if (a->db)
        st = open_store(a, command, m, lat, plan_text, rn, msg, msg_size);
    else
        cm_cluster_init(&rn->c, lat);
    rn->c.keep_exits = a->db != NULL; /* only a database saves them; no image is read */
    rn->c.threads = a->threads;
    rn->c.mem_budget = a->mem;
    *t = (timing){"regions and joins", "summary", 0, 0};
    const double t0 = cm_seconds();
    if (st == CM_OK)
        st = project_add_box(&rn->c, rn->store, m, plan, box, NULL, msg, msg_size);
    step_report rep = {a, lat, log};
    if (st == CM_OK && a->extend > 0)
        st = project_extend(&rn->c, rn->store, m, plan, box, report_step, &rep, &log->n,
                            log->stop, sizeof log->stop, msg, msg_size);
    t->t1 = cm_seconds() - t0;
    return st;
}

/* The summary of a cluster: from the database when there is one, else
 * from the periodic cells the cluster noted and its basin counts (no cell
 * is read either way). */
static cm_status summarise_cluster(run *rn, const cm_model *m, summary *sum,
                                   char *msg, size_t msg_size)
{
    cm_cluster *c = &rn->c;
    cm_cluster_bounds(c, &sum->box);
    sum->cells = c->cells;
    sum->ngroups = c->ngroups;
    sum->groups = calloc((size_t)c->ngroups + 1, sizeof *sum->groups);
    if (!sum->groups)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %u groups", c->ngroups);
    if (rn->store)
        return cm_store_groups(rn->store, sum->groups, c->ngroups, &sum->sink, msg, msg_size);
    sum->sink = cm_cluster_sink_cells(c);
    return cm_cluster_describe_new(c, m, sum->groups, msg, msg_size);
}

/* The figure of the cells drawn: the solved ones, or those of --view. */
static cm_status draw_cells(const solve_args *a, const cm_lattice *lat, run *rn,
                            const summary *sum, cm_region *r, basin_png *png, char *msg,
                            size_t msg_size)
{
    if (a->png.has_view) {
        cm_box box;
        view_cells(lat, a->png.lo, a->png.hi, &sum->box, &box);
        cm_region_free(r);
        memcpy(png->lo, a->png.lo, sizeof png->lo);
        memcpy(png->hi, a->png.hi, sizeof png->hi);
        cm_status st = cm_cluster_flatten(&rn->c, &box, r, msg, msg_size);
        if (st != CM_OK)
            return st;
    } else if (!r->group) {
        cm_status st = cm_cluster_flatten(&rn->c, &sum->box, r, msg, msg_size);
        if (st != CM_OK)
            return st;
    }
    if (write_basin_png("solve", png) != EXIT_OK)
        return cm_fail(CM_ERENDER, msg, msg_size, "%s was not written (see above)",
                       a->png.path ? a->png.path : a->png.svg);
    return CM_OK;
}

/* The PNG of the solved cells, or of --view (cells outside the cluster are
 * drawn as not computed). */
static cm_status draw_png(const solve_args *a, const cm_model *m, const cm_lattice *lat, run *rn,
                          const summary *sum, cm_region *r, char *msg, size_t msg_size)
{
    basin_png png = {&a->png, m,   lat, r, sum->groups, {0, 0}, {0, 0}, NULL,
                     a->png.by == BY_ATTRACTORS ? &sum->att : NULL, NULL};
    /* where the sink cells' sequences leave the cells drawn */
    cm_region_cells whole = {r, m, lat, a->max_steps};
    const cm_computed region = cm_region_computed(&whole);
    png.computed = r->group ? &region : &sum->joined.computed;
    return draw_cells(a, lat, rn, sum, r, &png, msg, msg_size);
}


static void print_database(FILE *out, const solve_args *a, const run *rn, const summary *sum)
{
    cm_store_stats ss;
    cm_store_get_stats(rn->store, &ss);
    fprintf(out, "database %s: %u region%s, %.2f bytes/cell written; paging: %llu regions read "
           "back (%.3f s), %llu changed ones saved to evict them (%.3f s); commits %.3f s\n",
           a->db, rn->c.nregions, rn->c.nregions == 1 ? "" : "s",
           (double)ss.bytes_written / (double)sum->cells, (unsigned long long)ss.regions_read,
           ss.read_seconds, (unsigned long long)ss.regions_evicted, ss.evict_seconds,
           ss.commit_seconds);
}

static cm_status finish_store(run *rn, char *msg, size_t msg_size)
{
    cm_status st = cm_store_finish(rn->store, msg, msg_size);
    rn->store = NULL;
    return st;
}

/* After Ctrl-C or a failure (why: "interrupted", or the failure's
 * message): what --db keeps and how to go on. */
static void say_kept(const solve_args *a, const char *command, const run *rn, const char *why)
{
    if (rn->store && cm_store_replacing(rn->store))
        fprintf(stderr, "cellmap solve: %s; %s is unchanged (the new cluster is discarded)\n", why,
                a->db);
    else if (rn->store)
        fprintf(stderr, "cellmap solve: %s; %s keeps the %u region%s joined so far. To finish "
                        "it%s: %s%s\n",
                why, a->db, rn->c.nregions, rn->c.nregions == 1 ? "" : "s",
                strcmp(why, "interrupted") ? " once that is fixed" : "", command,
                a->resume ? "" : " --resume");
    else
        fprintf(stderr, "cellmap solve: %s\n", why);
}

static int say_interrupted(const solve_args *a, const char *command, const run *rn)
{
    say_kept(a, command, rn, "interrupted");
    return EXIT_INTERRUPTED;
}

int cmd_solve(int argc, char **argv)
{
    cli c = {"solve", argc, argv, 0, NULL, NULL};
    solve_args a;
    memset(&a, 0, sizeof a);
    a.mo.name = "microchaos-pd";
    a.png.default_layers = all_layers; /* --png is a figure; --layers basin the bare image */
    int rc = parse_solve(&c, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;
    if ((rc = check_db_arg(&a)) != EXIT_OK)
        return rc;
    cm_model m;
    if ((rc = model_opts_build(&c, &a.mo, &m)) != EXIT_OK)
        return rc;
    cm_lattice lat;
    cm_box box, bounds;
    cm_region r;
    summary sum;
    run rn;
    char msg[1024], command[4096];
    memset(&r, 0, sizeof r);
    memset(&sum, 0, sizeof sum);
    for (int d = 0; d < CM_MAX_DIM; d++)
        sum.slow[d] = NAN; /* known for a single region only */
    memset(&rn, 0, sizeof rn);
    join_argv(argc + 1, argv - 1, command, sizeof command);
    extend_log *log = calloc(1, sizeof *log);
    if (!log) {
        fprintf(stderr, "cellmap solve: out of memory\n");
        rc = EXIT_FAIL;
        goto done;
    }
    if ((rc = make_lattice(&c, &a, &m, &lat, &box)) != EXIT_OK ||
        (rc = make_bounds(&c, &a, &lat, &box, &bounds)) != EXIT_OK ||
        ((a.png.path || a.png.svg) && (rc = check_basin_png("solve", &a.png, &m, &lat, &box)) != EXIT_OK))
        goto done;
    progress pr;
    progress_start(&pr, "solve", "cells", cm_box_cells(&box), a.quiet);
    project_plan plan;
    make_plan(&a, &bounds, &plan);
    plan.joined = cluster_progress;
    plan.joined_user = &pr;
    interrupt_catch();
    rc = EXIT_FAIL;
    timing t = {"images", "classification", 0, 0};
    cm_status st;
    if (!a.stage1 && (a.n_split || a.extend || a.db || a.png.has_view)) {
        /* a view is cut from a cluster */
        const double t0 = cm_seconds();
        st = solve_cluster(&a, &plan, command, &m, &lat, &box, &rn, &t, log, msg, sizeof msg);
        progress_end(&pr);
        if (st == CM_ECANCELED) {
            rc = say_interrupted(&a, command, &rn);
            goto done;
        }
        if (st != CM_OK || summarise_cluster(&rn, &m, &sum, msg, sizeof msg) != CM_OK)
            goto fail;
        t.t2 = cm_seconds() - t0 - t.t1;
    } else {
        st = a.stage1 ? solve_stage1(&a, &plan, &m, &lat, &box, &r, &t, msg, sizeof msg)
                      : solve_whole(&a, &m, &lat, &box, &r, &t, &pr, msg, sizeof msg);
        progress_end(&pr);
        if (st == CM_ECANCELED) {
            rc = say_interrupted(&a, command, &rn);
            goto done;
        }
        if (st != CM_OK)
            goto fail;
        if (!a.stage1 && cm_region_settle_exits(&r, a.threads, &sum.exits, msg, sizeof msg) != CM_OK)
            goto fail;
        sum.box = r.box;
        sum.cells = r.ncells;
        sum.ngroups = r.ngroups;
        if (!a.json && !a.quiet) /* only the text summary shows it */
            cm_scm_slow_share(&r, a.threads, sum.slow);
        if (cm_scm_describe(&m, &lat, &r, &sum.groups, &sum.sink, msg, sizeof msg) != CM_OK)
            goto fail;
    }
    const double ta = cm_seconds();
    a.att.threads = a.threads;
    /* the cells' groups: the region's, or the cluster's (resolved on the way) */
    cm_status found = r.group ? cm_region_attractors(&m, &lat, &r, a.max_steps, &sum.exits,
                                                     sum.groups, &a.att, &sum.att, msg, sizeof msg)
                              : cluster_ends_open(&sum.joined, &rn.c, msg, sizeof msg);
    if (found == CM_OK && !r.group)
        found = cm_cluster_attractors(&m, &sum.joined.cc, sum.groups, &a.att, &sum.att, msg,
                                      sizeof msg);
    if (found != CM_OK)
        goto fail;
    if (a.stage1) { /* its sink is Stage 1's: pending, not followed */
        sum.att.outside_steps = 0;
        sum.att.outside_cells = sum.sink;
    }
    sum.att_seconds = cm_seconds() - ta;
    cm_attractor_options used;
    cm_attractor_defaults(&m, &a.att, &used);
    used.threads = 0;
    if (rn.store && cm_store_put_attractors(rn.store, &sum.att, &used, lat.dim, msg, sizeof msg) !=
                        CM_OK)
        goto fail;
    const extend_log *shown = a.extend ? log : NULL;
    if (a.json)
        print_json(a.report, &m, &lat, &sum, &t, shown);
    else if (!a.quiet)
        print_text(a.report, &m, &lat, &sum, &t, shown);
    if (rn.store && !a.json && !a.quiet)
        print_database(a.report, &a, &rn, &sum);
    if ((a.png.path || a.png.svg) && draw_png(&a, &m, &lat, &rn, &sum, &r, msg, sizeof msg) != CM_OK)
        goto fail;
    if (rn.store && finish_store(&rn, msg, sizeof msg) != CM_OK)
        goto fail;
    rc = EXIT_OK;
    goto done;
fail:
    say_kept(&a, command, &rn, msg);
done:
    cm_store_close(rn.store, msg, sizeof msg);
    cm_cluster_free(&rn.c);
    free(log);
    free(sum.groups);
    cm_attractors_free(&sum.att);
    cm_exits_free(&sum.exits);
    cluster_ends_close(&sum.joined);
    cm_region_free(&r);
    cm_model_release(&m);
    return rc;
}
