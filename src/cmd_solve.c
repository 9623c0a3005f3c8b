/* cellmap solve: simple cell mapping of one region, with a summary, a basin
 * PNG and a .cmdb database. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "lib/json.h"
#include "lib/solve.h"
#include "src/args.h"
#include "src/attractor_opts.h"
#include "src/commands.h"
#include "src/figure_opts.h"
#include "src/interrupt.h"
#include "src/outfile.h"
#include "src/progress.h"

static const char solve_help[] =
    "usage: cellmap solve [--model NAME] [--param k=v[,k=v]] [--region LO:HI[,LO:HI...]]\n"
    "                     [--cells N[xM...]] [--split K[xL...]] [--max-steps K]\n"
    "                     [--extend N [--escape-below F] [--bounds LO:HI[,LO:HI...]]]\n"
    "                     [--threads T]\n"
    "                     [--png FILE] [--svg|--pdf FILE] [--size WxH] [--layers L,...] [--png-mode rgb|indexed]\n"
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
    "  --threads T         OpenMP threads for the images (default: all cores; one for\n"
    "                      fewer than 32768 cells without --extend)\n"
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
    "                      --db FILE (same results); default: an eighth of the\n"
    "                      machine's memory, 16M..128M\n"
    "  --json              print the summary as JSON\n"
    "  --quiet             no progress line and no summary (--json still prints)\n"
    "  --stage1            stop the join of the --split regions after Stage 1 (thesis\n"
    "                      Alg. C.5, Fig. 4.27): sink cells leading into another region's\n"
    "                      groups take their group; those leading into its sink domain\n"
    "                      (pending, left to Stage 2) stay in the sink\n";

/* Most regions --split may cut the box into; most --extend steps. */
enum { MAX_SPLIT = 4096, MAX_EXTEND = SOLVE_MAX_EXTEND };

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

/* A share of slow cells (cm_scm_slow_share) above which the summary says so. */
#define SLOW_SHARE 0.25

static void print_text(FILE *out, const cm_model *m, const cm_lattice *lat,
                       const solve_result *sum, bool extended)
{
    char params[2048];
    cm_params_json(&m->values, params, sizeof params);
    const uint64_t cells = sum->cells, box_cells = cm_box_cells(&sum->box), sink = sum->sink;
    const cm_group_info *g = sum->groups;
    const uint32_t ngroups = sum->ngroups;
    if (extended)
        fprintf(out, "extension stopped: %s\n", sum->stop);
    fprintf(out, "model %s %s\n", m->name, params);
    fprintf(out, "cells %llu", (unsigned long long)cells);
    if (cells != box_cells)
        fprintf(out, " (of %llu in the bounding box; the others not computed)",
               (unsigned long long)box_cells);
    fprintf(out, "\n");
    fprintf(out, "time: %s %.3f s, %s %.3f s (%.1f ns/cell), attractors %.3f s (%llu steps)\n",
            sum->first, sum->t1, sum->second, sum->t2, 1e9 * (sum->t1 + sum->t2) / (double)cells,
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

static void print_json_extension(json *j, const cm_lattice *lat, const solve_result *log)
{
    json_object(j, "extension");
    json_array(j, "steps");
    for (int k = 0; k < log->nsteps; k++) {
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

static void print_json(FILE *out, const cm_model *m, const cm_lattice *lat,
                       const solve_result *sum, bool extended)
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
    json_seconds(&j, sum->first, sum->t1);
    json_seconds(&j, sum->second, sum->t2);
    if (strcmp(sum->first, "regions and joins") == 0) /* of them, on the joining thread */
        json_seconds(&j, "joins", sum->join_seconds);
    json_seconds(&j, "attractors", sum->att_seconds);
    json_object_end(&j);
    solve_json_ranks(&j, sum);
    if (extended)
        print_json_extension(&j, lat, sum);
    attractor_json(&j, lat, &sum->att);
    attractor_json_groups(&j, sum->groups, sum->ngroups, lat, &sum->att);
    json_end(&j);
}

/* A project_step_fn: says the extension's step as it ends. */
typedef struct step_report {
    const solve_args *a;
    const cm_lattice *lat;
    solve_result *log;
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
    if (stat(a->db, &sb) == 0 && S_ISREG(sb.st_mode) && project_probe(a->db, why, sizeof why) != CM_OK) {
        fprintf(stderr, "cellmap solve: refusing to overwrite %s: %s; choose another --db file\n",
                a->db, why);
        return EXIT_USAGE;
    }
    return outfile_check("solve", a->db, true);
}

/* The project's plan from --split, --max-steps, --threads, --extend,
 * --escape-below and --bounds. */
static void make_plan(const solve_args *a, const cm_box *bounds, project_plan *p)
{
    memset(p, 0, sizeof *p);
    p->nsplit = a->n_split;
    memcpy(p->split, a->split, sizeof p->split);
    p->opt = (cm_scm_options){.max_steps = a->max_steps, .threads = a->threads, .record_exits = 1};
    p->extend = a->extend;
    p->escape_below = a->escape_below;
    p->bounds = a->bounds_text ? bounds : NULL;
    p->bounds_text = a->bounds_text;
}

static void print_database(FILE *out, const solve_args *a, const solve_result *r)
{
    cm_store_stats ss;
    solve_store_stats(r, &ss);
    fprintf(out, "database %s: %u region%s, %.2f bytes/cell written; paging: %llu regions read "
           "back (%.3f s), %llu changed ones saved to evict them (%.3f s); commits %.3f s\n",
           a->db, r->c.nregions, r->c.nregions == 1 ? "" : "s",
           (double)ss.bytes_written / (double)r->cells, (unsigned long long)ss.regions_read,
           ss.read_seconds, (unsigned long long)ss.regions_evicted, ss.evict_seconds,
           ss.commit_seconds);
}

/* After Ctrl-C or a failure (why: "interrupted", or the failure's
 * message): what --db keeps and how to go on. */
static void say_kept(const solve_args *a, const char *command, const solve_result *rn,
                     const char *why)
{
    if (solve_replacing(rn))
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

static int say_interrupted(const solve_args *a, const char *command, const solve_result *rn)
{
    say_kept(a, command, rn, "interrupted");
    return EXIT_INTERRUPTED;
}

int cmd_solve(int argc, char **argv) { return cmd_solve_on(argc, argv, NULL); }

int cmd_solve_on(int argc, char **argv, solve_ranks *ranks)
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
    solve_request q;
    memset(&q, 0, sizeof q);
    char msg[1024], command[4096];
    join_argv(argc + 1, argv - 1, command, sizeof command);
    solve_result *r = malloc(sizeof *r);
    cm_box bounds;
    rc = EXIT_FAIL;
    if (!r) {
        fprintf(stderr, "cellmap solve: out of memory\n");
        goto done;
    }
    memset(r, 0, sizeof *r);
    if ((rc = make_lattice(&c, &a, &m, &q.lat, &q.box)) != EXIT_OK ||
        (rc = make_bounds(&c, &a, &q.lat, &q.box, &bounds)) != EXIT_OK ||
        (png_opts_draws(&a.png) &&
         (rc = check_basin_png("solve", &a.png, &m, &q.lat, &q.box)) != EXIT_OK))
        goto done;
    if (!a.threads && solve_small(cm_box_cells(&q.box), a.extend))
        omp_set_num_threads(1);
    progress pr;
    progress_start(&pr, "solve", "cells", cm_box_cells(&q.box), a.quiet);
    const work_hooks hooks = progress_hooks(&pr);
    q.model = &m;
    q.lib = model_spec_lib(&a.mo, m.name);
    make_plan(&a, &bounds, &q.plan);
    /* a view is cut from a cluster */
    q.cluster = a.n_split || a.extend || a.db || a.png.has_view;
    q.stage1 = a.stage1;
    q.db = a.db;
    q.resume = a.resume;
    q.command = command;
    q.mem = a.mem;
    q.att = a.att;
    q.slow_share = !a.json && !a.quiet; /* only the text summary shows it */
    q.hooks = &hooks;
    q.ranks = ranks;
    step_report rep = {&a, &q.lat, r};
    q.step_done = report_step;
    q.step_user = &rep;
    interrupt_catch();
    const cm_status st = solve_run(&q, r, msg, sizeof msg);
    progress_end(&pr);
    rc = r->worker && st == CM_OK ? EXIT_OK : EXIT_FAIL;
    if (r->worker) /* rank 0 reports */
        goto done;
    cli_said_upgrade("solve", a.db, r->upgraded_from);
    if (st == CM_ECANCELED) {
        rc = say_interrupted(&a, command, r);
        goto done;
    }
    if (st != CM_OK)
        goto fail;
    if (a.stage1 && !a.json)
        fprintf(a.report, "stage 1 of the join of %u regions: of %llu sink cells, %llu now lead to groups, "
               "%llu leave every region, %llu are pending (left to Stage 2, drawn as the sink)\n",
               r->stage1_regions, (unsigned long long)r->stage1.sink_cells,
               (unsigned long long)r->stage1.to_group, (unsigned long long)r->stage1.to_sink,
               (unsigned long long)r->stage1.pending);
    if (a.json)
        print_json(a.report, &m, &q.lat, r, a.extend > 0);
    else if (!a.quiet)
        print_text(a.report, &m, &q.lat, r, a.extend > 0);
    if (r->store && !a.json && !a.quiet)
        print_database(a.report, &a, r);
    if (png_opts_draws(&a.png) && solve_draw(&q, r, &a.png, msg, sizeof msg) != CM_OK)
        goto fail;
    if (solve_finish(r, msg, sizeof msg) != CM_OK)
        goto fail;
    rc = EXIT_OK;
    goto done;
fail:
    say_kept(&a, command, r, msg);
done:
    if (r)
        solve_result_free(r);
    free(r);
    cm_model_release(&m);
    return rc;
}
