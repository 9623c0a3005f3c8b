/* lib/sweep.c - a parameter swept (lib/sweep.h). */
#include "lib/sweep.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "lib/param_grid.h"
#include "lib/solve.h"
#include "lib/work.h"

/* Whether an attractor or group centred there lies in the window. */
static bool in_window(const sweep_args *a, const double *centre)
{
    for (int d = 0; d < a->n_near; d++)
        if (!(centre[d] >= a->near_lo[d] && centre[d] <= a->near_hi[d]))
            return false;
    return true;
}

/* What tracking keeps of an attractor (its id and basin set by the caller). */
static sweep_attractor tracked_of(const cm_attractor *at)
{
    sweep_attractor t = {.kind = at->kind, .period = at->period};
    memcpy(t.centre, at->centre, sizeof t.centre);
    memcpy(t.lo, at->lo, sizeof t.lo);
    memcpy(t.hi, at->hi, sizeof t.hi);
    memcpy(t.anchor, at->anchor, sizeof t.anchor);
    return t;
}

/* The system's attractors (cellmap/attractors.h) in the window, each
 * kept for tracking (pt->att): sticking zones are kept as cell mapping
 * gives them, counted only. */
static cm_status count_attractors(const sweep_args *a, const cm_attractor_set *s,
                                  uint32_t ngroups, sweep_point *pt)
{
    pt->groups = ngroups;
    pt->diverged_cells = s->diverged_cells + s->sink_diverged_cells;
    pt->outside_cells = s->outside_cells, pt->undecided_cells = s->unresolved_cells;
    pt->att = calloc((size_t)s->n + 1, sizeof *pt->att);
    if (!pt->att)
        return CM_ENOMEM;
    for (uint32_t k = 0; k < s->n; k++) {
        const cm_attractor *at = &s->a[k];
        if (!in_window(a, at->centre)) {
            pt->elsewhere_cells += at->basin_cells;
        } else if (at->kind == CM_ATTRACTOR_STICKING) {
            pt->sticking++;
            pt->sticking_cells += at->basin_cells;
        } else {
            sweep_attractor *t = &pt->att[pt->attractors++];
            *t = tracked_of(at);
            t->basin_cells = at->basin_cells;
            pt->attractor_cells += at->basin_cells;
        }
    }
    return CM_OK;
}

static void count_groups(const sweep_args *a, const cm_group_info *groups, uint32_t n,
                         sweep_point *pt)
{
    pt->groups = n;
    for (uint32_t k = 0; k < n; k++) {
        if (!in_window(a, groups[k].centre))
            continue;
        if (groups[k].kind == CM_GROUP_STICKING) {
            pt->sticking++;
            pt->sticking_cells += groups[k].basin_cells;
        } else {
            pt->attractors++;
            pt->attractor_cells += groups[k].basin_cells;
        }
    }
}

/* The cells solved in one region in memory, its groups (into *groups) and
 * the system's attractors (into att, by attractors). */
static cm_status solve_in_memory(const sweep_args *a, const cm_lattice *lat, const cm_box *box,
                                 const cm_model *m, sweep_point *pt, cm_group_info **groups,
                                 uint32_t *ngroups, cm_attractor_set *att, char *msg,
                                 size_t msg_size)
{
    const cm_scm_options opt = {.max_steps = a->max_steps,
                                .threads = a->threads,
                                .record_exits = 1}; /* exits followed */
    cm_region r;
    memset(&r, 0, sizeof r);
    cm_exits exits = {0};
    cm_status st = cm_region_alloc(&r, box, msg, msg_size);
    if (st == CM_OK)
        st = cm_scm_solve(m, lat, &opt, &r, msg, msg_size);
    if (st == CM_OK)
        st = cm_region_settle_exits(&r, a->threads, &exits, msg, msg_size);
    if (st == CM_OK)
        st = cm_scm_describe(m, lat, &r, groups, &pt->sink_cells, msg, msg_size);
    *ngroups = r.ngroups;
    if (st == CM_OK && a->by == BY_ATTRACTORS) {
        cm_attractor_options o = a->att;
        o.threads = a->threads;
        st = cm_region_attractors(m, lat, &r, a->max_steps, &exits, *groups, &o, att, msg,
                                  msg_size);
    }
    cm_exits_free(&exits);
    cm_region_free(&r);
    return st;
}

/* The cells solved as `solve --db a->keep/NAME=VALUE.cmdb` would (one
 * region, its attractors found and stored, the file completed): the
 * groups and attractors taken from the solve. */
static cm_status solve_kept(const sweep_args *a, const cm_lattice *lat, const cm_box *box,
                            const cm_model *m, double value, sweep_point *pt,
                            cm_group_info **groups, uint32_t *ngroups, cm_attractor_set *att,
                            char *msg, size_t msg_size)
{
    char path[4096], command[4200];
    if (snprintf(path, sizeof path, "%s/%s=%s.cmdb", a->keep, a->name, CM_NUM(value)) >=
        (int)sizeof path)
        return cm_fail(CM_EINVAL, msg, msg_size, "the directory's path is too long: %s", a->keep);
    snprintf(command, sizeof command, "%s (%s = %s)", a->command ? a->command : "cellmap sweep",
             a->name, CM_NUM(value));
    solve_request q;
    memset(&q, 0, sizeof q);
    q.model = m, q.lib = model_spec_lib(&a->mo, m->name);
    q.lat = *lat, q.box = *box;
    q.plan.opt = (cm_scm_options){.max_steps = a->max_steps, .threads = a->threads,
                                  .record_exits = 1};
    q.cluster = true, q.db = path, q.command = command;
    q.att = a->att;
    q.att.threads = a->threads;
    solve_result *r = malloc(sizeof *r);
    if (!r)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a solve");
    cm_status st = solve_run(&q, r, msg, msg_size);
    if (st == CM_OK)
        st = solve_finish(r, msg, msg_size);
    if (st == CM_OK) { /* taken over from the solve */
        pt->sink_cells = r->sink;
        *ngroups = r->ngroups, *groups = r->groups, *att = r->att;
        r->groups = NULL;
        memset(&r->att, 0, sizeof r->att);
    }
    solve_result_free(r);
    free(r);
    return st;
}

cm_status sweep_solve_at(const sweep_args *a, const cm_lattice *lat, const cm_box *box,
                         double value, sweep_point *pt, char *msg, size_t msg_size)
{
    memset(pt, 0, sizeof *pt);
    pt->value = value, pt->cells = cm_box_cells(box);
    const double t0 = cm_seconds();
    cm_model m;
    const char *name = a->name;
    if (!model_with_values(&a->mo, &name, &value, 1, &m, msg, msg_size))
        return CM_EINVAL;
    cm_group_info *groups = NULL;
    uint32_t ngroups = 0;
    cm_attractor_set att;
    memset(&att, 0, sizeof att);
    cm_status st = a->keep ? solve_kept(a, lat, box, &m, value, pt, &groups, &ngroups, &att, msg,
                                        msg_size)
                           : solve_in_memory(a, lat, box, &m, pt, &groups, &ngroups, &att, msg,
                                             msg_size);
    if (st == CM_OK && a->by == BY_ATTRACTORS) {
        if (count_attractors(a, &att, ngroups, pt) != CM_OK)
            st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %u attractors", att.n);
    } else if (st == CM_OK) {
        count_groups(a, groups, ngroups, pt);
    }
    cm_attractors_free(&att);
    if (st != CM_OK) {
        free(pt->att);
        pt->att = NULL;
    }
    free(groups);
    cm_model_release(&m);
    pt->seconds = cm_seconds() - t0;
    return st;
}

bool sweep_write_csv(const sweep_args *a, const sweep_point *pts, int n, char *msg, size_t msg_size)
{
    outfile o;
    if (outfile_begin(a->csv, &o, msg, msg_size) != CM_OK)
        return false;
    fprintf(o.f,
            "%s,attractors,sticking,attractor_cells,sticking_cells,groups,sink_cells,seconds\n",
            a->name);
    for (int k = 0; k < n; k++)
        fprintf(o.f, "%.17g,%u,%u,%llu,%llu,%u,%llu,%.3f\n", pts[k].value, pts[k].attractors,
                pts[k].sticking, (unsigned long long)pts[k].attractor_cells,
                (unsigned long long)pts[k].sticking_cells, pts[k].groups,
                (unsigned long long)pts[k].sink_cells, pts[k].seconds);
    return (outfile_end(&o, true, msg, msg_size) == CM_OK);
}

/* The directory of the kept files, made when it does not exist (its
 * parent must). */
static bool keep_directory(const char *dir, char *msg, size_t msg_size)
{
    struct stat st;
    if (stat(dir, &st) == 0 && !S_ISDIR(st.st_mode))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "--keep %s: not a directory; name a directory for the files of the "
                       "values", dir) == CM_OK;
    if (stat(dir, &st) != 0 && mkdir(dir, 0777) != 0)
        return cm_fail(CM_EINVAL, msg, msg_size, "--keep %s: cannot make the directory (%s)",
                       dir, strerror(errno)) == CM_OK;
    return true;
}

cm_status sweep_check_setup(const sweep_args *a, sweep_result *r, char *msg, size_t msg_size)
{
    *r = (sweep_result){0};
    if (a->n_values < 2 || a->n_values > MAX_VALUES || a->refine < 0 || a->refine > MAX_REFINE ||
        a->max_steps < 0 || a->max_steps > PROJECT_MAX_STEPS)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "%d values, refine %d, max steps %d: need 2..%d values, 0..%d bisections "
                       "and 0..%d steps",
                       a->n_values, a->refine, a->max_steps, MAX_VALUES, MAX_REFINE,
                       PROJECT_MAX_STEPS);
    for (int k = 1; k < a->n_values; k++)
        if (!(a->values[k] > a->values[k - 1]))
            return cm_fail(CM_EINVAL, msg, msg_size, "the values must increase");
    if ((a->fractions || a->png) && a->by != BY_ATTRACTORS)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "basin shares are the tracked attractors': not with --by groups");
    if (!(a->match >= 0 && a->match <= 1))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the matching distance %g: give a share of the region, 0 .. 1", a->match);
    for (int d = 0; d < a->n_near; d++)
        if (!(a->near_lo[d] < a->near_hi[d]))
            return cm_fail(CM_EINVAL, msg, msg_size, "the window needs LO < HI in each dimension");
    cm_model m;
    cm_status st = model_spec_build(&a->mo, &m, msg, msg_size);
    if (st != CM_OK)
        return st;
    memcpy(r->period, m.period, sizeof r->period);
    if (cm_params_find(&m.values, a->name) < 0)
        st = cm_fail(CM_EINVAL, msg, msg_size, "'%s' is not a parameter of %s (`cellmap models`)",
                     a->name, m.name);
    else if (a->n_near > m.dim)
        st = cm_fail(CM_EINVAL, msg, msg_size,
                     "the window has %d range(s) but model %s has dimension %d", a->n_near,
                     m.name, m.dim);
    else
        st = lattice_of_spec(&a->lat, &m, &a->mo.set, &r->lat, &r->box, msg, msg_size);
    cm_model_release(&m);
    for (int k = 0; k < a->n_values && st == CM_OK; k++) {
        const char *name = a->name;
        char why[256];
        if (!model_with_values(&a->mo, &name, &a->values[k], 1, &m, why, sizeof why))
            st = cm_fail(CM_EINVAL, msg, msg_size, "%s = %s: %s", a->name, CM_NUM(a->values[k]),
                         why);
        else
            cm_model_release(&m);
    }
    if (st == CM_OK && a->keep && !keep_directory(a->keep, msg, msg_size))
        st = CM_EINVAL;
    return st;
}

/* ---- attractors tracked across values ---- */

/* The region's extent along dimension k, in state units. */
static double extent(const sweep_result *r, int k)
{
    return r->lat.width[k] * (double)(r->box.hi[k] - r->box.lo[k]);
}

/* The matching distance asked for, or its default. */
static double match_within(const sweep_args *a) { return a->match > 0 ? a->match : SWEEP_MATCH; }

double sweep_distance(const sweep_result *r, const sweep_attractor *x, const sweep_attractor *y)
{
    double d = 0;
    for (int k = 0; k < r->lat.dim; k++) {
        const double apart = fabs(cm_period_diff(r->period, k, x->centre[k], y->centre[k]));
        d = fmax(d, apart / extent(r, k));
    }
    return d;
}

typedef struct pairing {
    double d;
    uint32_t i, j;
} pairing;

static int by_distance(const void *x, const void *y)
{
    const pairing *u = x, *v = y;
    if (u->d != v->d)
        return (u->d > v->d) - (u->d < v->d);
    if (u->i != v->i)
        return (u->i > v->i) - (u->i < v->i);
    return (u->j > v->j) - (u->j < v->j);
}

cm_status sweep_match(const sweep_args *a, const sweep_result *r, const sweep_point *p,
                      const sweep_point *q, int *pair, uint32_t *matched)
{
    const double within = match_within(a);
    pairing *cand = malloc(((size_t)p->attractors * q->attractors + 1) * sizeof *cand);
    bool *taken = calloc((size_t)p->attractors + 1, sizeof *taken);
    if (!cand || !taken) {
        free(cand);
        free(taken);
        return CM_ENOMEM;
    }
    size_t n = 0;
    for (uint32_t i = 0; i < p->attractors; i++)
        for (uint32_t j = 0; j < q->attractors; j++) {
            const double d = sweep_distance(r, &p->att[i], &q->att[j]);
            if (d <= within)
                cand[n++] = (pairing){d, i, j};
        }
    qsort(cand, n, sizeof *cand, by_distance);
    for (uint32_t j = 0; j < q->attractors; j++)
        pair[j] = -1;
    *matched = 0;
    for (size_t k = 0; k < n; k++)
        if (!taken[cand[k].i] && pair[cand[k].j] < 0) {
            taken[cand[k].i] = true, pair[cand[k].j] = (int)cand[k].i;
            ++*matched;
        }
    free(cand);
    free(taken);
    return CM_OK;
}

/* Whether attractor x's basin collapses into y's: to less than half its
 * cells (as when a sticking zone absorbs the attractor and a rest state
 * too close to tell apart on the lattice is left). A seeded attractor's
 * basin is not measured: no collapse to or from it. */
static bool collapses(const sweep_attractor *x, const sweep_attractor *y)
{
    return !x->seeded && !y->seeded && 2 * y->basin_cells < x->basin_cells;
}

/* Whether two points have the same attractors: by attractors, each of
 * either matched to one of the other (*lost, *gained: those without a
 * match) and no basin collapsing; by groups, as many of them. */
static cm_status same_points(const sweep_args *a, const sweep_result *r, const sweep_point *x,
                             const sweep_point *y, bool *same, uint32_t *lost, uint32_t *gained)
{
    uint32_t matched = x->attractors < y->attractors ? x->attractors : y->attractors;
    int *pair = a->by == BY_ATTRACTORS ? malloc(((size_t)y->attractors + 1) * sizeof *pair)
                                       : NULL;
    if (a->by == BY_ATTRACTORS && (!pair || sweep_match(a, r, x, y, pair, &matched) != CM_OK)) {
        free(pair);
        return CM_ENOMEM;
    }
    bool collapse = false;
    for (uint32_t j = 0; pair && j < y->attractors; j++)
        collapse = collapse || (pair[j] >= 0 && collapses(&x->att[pair[j]], &y->att[j]));
    free(pair);
    *lost = x->attractors - matched, *gained = y->attractors - matched;
    *same = !*lost && !*gained && !collapse;
    return CM_OK;
}

/* ---- seeds: attractors the lattice misses, from a neighbouring value's ---- */

/* Whether t lies within the matching distance of one of p's attractors. */
static bool near_one_of(const sweep_args *a, const sweep_result *r, const sweep_point *p,
                        const sweep_attractor *t)
{
    for (uint32_t j = 0; j < p->attractors; j++)
        if (sweep_distance(r, &p->att[j], t) <= match_within(a))
            return true;
    return false;
}

/* Appends to `to` the attractor found from seed x (at->anchor, at to's
 * value) when it lies within the matching distance of x, in the window,
 * and near none of to's attractors: the lattice lost it there. */
static cm_status add_seeded(const sweep_args *a, const sweep_result *r, const sweep_attractor *x,
                            const cm_attractor *at, sweep_point *to)
{
    sweep_attractor t = tracked_of(at);
    t.seeded = true;
    if (at->kind == CM_ATTRACTOR_STICKING || sweep_distance(r, x, &t) > match_within(a) ||
        !in_window(a, at->centre) || near_one_of(a, r, to, &t))
        return CM_OK;
    sweep_attractor *grown = realloc(to->att, ((size_t)to->attractors + 1) * sizeof *grown);
    if (!grown)
        return CM_ENOMEM;
    to->att = grown;
    to->att[to->attractors++] = t;
    return CM_OK;
}

/* The attractors of `from` that no attractor of `to` matches, followed by
 * the true map at to's value from their anchor cells (as cm_attractors_find
 * checks a group): those that persist nearby are added to `to`, seeded. A
 * lattice too coarse for an attractor's basin near a fold (a newborn one,
 * or one about to die) then does not move the fold: births and deaths are
 * where the true orbits say. */
static cm_status seed_point(const sweep_args *a, const sweep_result *r, const sweep_point *from,
                            sweep_point *to, char *msg, size_t msg_size)
{
    if (a->no_seeds || a->by != BY_ATTRACTORS || !from->attractors)
        return CM_OK;
    int *pair = malloc(((size_t)to->attractors + 1) * sizeof *pair);
    bool *matched = calloc((size_t)from->attractors, sizeof *matched);
    cm_group_info *seeds = calloc((size_t)from->attractors, sizeof *seeds);
    uint32_t *seed_of = malloc((size_t)from->attractors * sizeof *seed_of), n = 0, pairs;
    cm_status st = pair && matched && seeds && seed_of ? sweep_match(a, r, from, to, pair, &pairs)
                                                       : CM_ENOMEM;
    for (uint32_t j = 0; st == CM_OK && j < to->attractors; j++)
        if (pair[j] >= 0)
            matched[pair[j]] = true;
    for (uint32_t i = 0; st == CM_OK && i < from->attractors; i++)
        if (!matched[i]) {
            seeds[n] = (cm_group_info){.id = n + 1, .period = 1, .basin_cells = 1,
                                       .kind = CM_GROUP_ATTRACTOR};
            memcpy(seeds[n].anchor, from->att[i].anchor, sizeof seeds[n].anchor);
            seed_of[n++] = i;
        }
    if (st == CM_ENOMEM)
        cm_fail(st, msg, msg_size, "out of memory for the seeds");
    cm_model m;
    const char *name = a->name;
    if (st == CM_OK && n && !model_with_values(&a->mo, &name, &to->value, 1, &m, msg, msg_size))
        st = CM_EINVAL;
    else if (st == CM_OK && n) {
        cm_attractor_options o = a->att;
        o.threads = a->threads;
        o.outside = CM_OUTSIDE_OFF; /* no cells to return to */
        cm_attractor_set set;
        st = cm_attractors_find(&m, &r->lat, seeds, n, NULL, NULL, &o, &set, msg, msg_size);
        for (uint32_t k = 0; st == CM_OK && k < n; k++) {
            const uint32_t id = set.of_group[k + 1];
            if (id != CM_FATE_DIVERGED && id != CM_FATE_UNRESOLVED &&
                add_seeded(a, r, &from->att[seed_of[k]], &set.a[id - 1], to) != CM_OK)
                st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for seeded attractors");
        }
        cm_attractors_free(&set);
        cm_model_release(&m);
    }
    free(pair);
    free(matched);
    free(seeds);
    free(seed_of);
    return st;
}

/* Solves value into the next point of r (r->failed_value on failure). */
static cm_status solve_next(const sweep_args *a, const work_hooks *h, sweep_result *r,
                            double value, char *msg, size_t msg_size)
{
    const cm_status stopped = work_check(h, msg, msg_size);
    if (stopped != CM_OK)
        return stopped;
    r->failed_value = value;
    const cm_status st = sweep_solve_at(a, &r->lat, &r->box, value, &r->pts[r->n], msg, msg_size);
    r->n += st == CM_OK;
    return st;
}

/* Bisects between ch->lo and ch->hi (whose counts differ) a->refine times;
 * the solved midpoints are appended to r's points. */
static cm_status refine_change(const sweep_args *a, const work_hooks *h, sweep_result *r,
                               sweep_change *ch, char *msg, size_t msg_size)
{
    sweep_point lo = ch->lo, hi = ch->hi;
    for (int k = 0; k < a->refine; k++) {
        cm_status st = solve_next(a, h, r, 0.5 * (lo.value + hi.value), msg, msg_size);
        sweep_point *mid = &r->pts[r->n - 1];
        if (st == CM_OK)
            st = seed_point(a, r, &lo, mid, msg, msg_size);
        if (st == CM_OK)
            st = seed_point(a, r, &hi, mid, msg, msg_size);
        if (st != CM_OK)
            return st;
        bool same;
        uint32_t lost, gained;
        if (same_points(a, r, &lo, mid, &same, &lost, &gained) != CM_OK)
            return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory matching attractors");
        if (same)
            lo = *mid;
        else
            hi = *mid;
    }
    ch->lo = lo;
    ch->hi = hi;
    return CM_OK;
}

/* A vanished attractor x merges into y of the next value when y is
 * aperiodic (a chaotic attractor grown over it, as in a merging crisis)
 * and x's centre lies within y's bounds widened by the matching distance. */
static bool merges_into(const sweep_args *a, const sweep_result *r, const sweep_attractor *x,
                        const sweep_attractor *y)
{
    if (y->kind != CM_ATTRACTOR_APERIODIC)
        return false;
    const double within = match_within(a);
    for (int k = 0; k < r->lat.dim; k++) {
        const double pad = within * extent(r, k);
        if (!(x->centre[k] >= y->lo[k] - pad && x->centre[k] <= y->hi[k] + pad))
            return false;
    }
    return true;
}

/* The events between points p and q (q's ids set, pair from sweep_match);
 * p's attractors that end there join gone[] (*n_gone of them). */
static void note_events(const sweep_args *a, sweep_result *r, const sweep_point *p,
                        const sweep_point *q, const int *pair, bool *kept, sweep_attractor *gone,
                        size_t *n_gone)
{
    for (uint32_t i = 0; i < p->attractors; i++)
        kept[i] = false;
    for (uint32_t j = 0; j < q->attractors; j++)
        if (pair[j] >= 0 && collapses(&p->att[pair[j]], &q->att[j]))
            r->events[r->n_events++] = (sweep_event){SWEEP_COLLAPSES, q->att[j].id, 0, p->value,
                                                     q->value};
    for (uint32_t j = 0; j < q->attractors; j++)
        if (pair[j] >= 0)
            kept[pair[j]] = true;
        else
            r->events[r->n_events++] = (sweep_event){SWEEP_APPEARS, q->att[j].id, 0, p->value,
                                                     q->value};
    for (uint32_t i = 0; i < p->attractors; i++) {
        if (kept[i])
            continue;
        sweep_event e = {SWEEP_VANISHES, p->att[i].id, 0, p->value, q->value};
        gone[(*n_gone)++] = p->att[i];
        double best = INFINITY;
        for (uint32_t j = 0; j < q->attractors; j++) {
            const double d = sweep_distance(r, &p->att[i], &q->att[j]);
            if (d < best && merges_into(a, r, &p->att[i], &q->att[j]))
                best = d, e.kind = SWEEP_MERGES, e.into = q->att[j].id;
        }
        r->events[r->n_events++] = e;
    }
}

static int by_id(const void *x, const void *y)
{
    const uint32_t u = ((const sweep_attractor *)x)->id, v = ((const sweep_attractor *)y)->id;
    return (u > v) - (u < v);
}

/* The id of q's unmatched attractor t: that of the nearest attractor that
 * ended before, as it was last seen, within the matching distance (taken
 * out of gone[]: a lattice too coarse for an attractor at one value loses
 * it there), else the next new one. */
static uint32_t id_of_new(const sweep_args *a, sweep_result *r, const sweep_attractor *t,
                          sweep_attractor *gone, size_t *n_gone)
{
    const double within = match_within(a);
    size_t best = SIZE_MAX;
    double d_best = INFINITY;
    for (size_t i = 0; i < *n_gone; i++) {
        const double d = sweep_distance(r, &gone[i], t);
        if (d <= within && d < d_best)
            d_best = d, best = i;
    }
    if (best == SIZE_MAX)
        return ++r->tracked;
    const uint32_t id = gone[best].id;
    gone[best] = gone[--*n_gone];
    return id;
}

/* Ids over the points in value order: an attractor matched to one of the
 * value before keeps its id, any other takes that of one that ended
 * before (id_of_new) or the next; the events where attractors begin and
 * end; each point's attractors then in id order. */
static cm_status track(const sweep_args *a, sweep_result *r, char *msg, size_t msg_size)
{
    size_t total = 0, most = 1;
    for (int k = 0; k < r->n; k++) {
        total += r->pts[k].attractors;
        most = r->pts[k].attractors > most ? r->pts[k].attractors : most;
    }
    int *pair = malloc(most * sizeof *pair);
    bool *kept = malloc(most * sizeof *kept);
    sweep_attractor *gone = malloc((total + 1) * sizeof *gone);
    size_t n_gone = 0;
    r->events = malloc((3 * total + 1) * sizeof *r->events);
    cm_status st = pair && kept && gone && r->events ? CM_OK : CM_ENOMEM;
    for (uint32_t j = 0; st == CM_OK && r->n && j < r->pts[0].attractors; j++)
        r->pts[0].att[j].id = ++r->tracked;
    for (int k = 1; st == CM_OK && k < r->n; k++) {
        const sweep_point *p = &r->pts[k - 1];
        sweep_point *q = &r->pts[k];
        uint32_t matched;
        st = sweep_match(a, r, p, q, pair, &matched);
        for (uint32_t j = 0; st == CM_OK && j < q->attractors; j++)
            q->att[j].id = pair[j] >= 0 ? p->att[pair[j]].id
                                        : id_of_new(a, r, &q->att[j], gone, &n_gone);
        if (st == CM_OK)
            note_events(a, r, p, q, pair, kept, gone, &n_gone);
    }
    for (int k = 0; st == CM_OK && k < r->n; k++)
        qsort(r->pts[k].att, r->pts[k].attractors, sizeof *r->pts[k].att, by_id);
    free(pair);
    free(kept);
    free(gone);
    return st == CM_OK ? CM_OK : cm_fail(st, msg, msg_size, "out of memory tracking attractors");
}

/* The changes between listed values k - 1 and k: with a->refine, each
 * bisected to the first change after its lower end, then the rest of the
 * interval searched again, up to SWEEP_CHANGES changes. */
static cm_status find_changes(const sweep_args *a, const work_hooks *h, const sweep_report *rep,
                              sweep_result *r, int k, char *msg, size_t msg_size)
{
    sweep_point lo = r->pts[k - 1];
    const sweep_point hi = r->pts[k];
    for (int round = 0; round < (a->refine ? SWEEP_CHANGES : 1); round++) {
        bool same;
        uint32_t lost, gained;
        if (same_points(a, r, &lo, &hi, &same, &lost, &gained) != CM_OK)
            return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory matching attractors");
        if (same)
            return CM_OK;
        sweep_change *ch = &r->changes[r->n_changes++];
        ch->lo = lo, ch->hi = hi;
        const cm_status st = a->refine ? refine_change(a, h, r, ch, msg, msg_size) : CM_OK;
        if (st != CM_OK)
            return st;
        if (same_points(a, r, &ch->lo, &ch->hi, &same, &lost, &gained) != CM_OK)
            return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory matching attractors");
        ch->several = lost > 1 || gained > 1;
        if (a->refine && rep && rep->change)
            rep->change(rep->user, a, ch);
        lo = ch->hi;
    }
    return CM_OK;
}

static int by_value(const void *x, const void *y)
{
    const double u = ((const sweep_point *)x)->value, v = ((const sweep_point *)y)->value;
    return (u > v) - (u < v);
}

cm_status sweep_compute(const sweep_args *a, const work_hooks *h, const sweep_report *rep,
                        sweep_result *r, char *msg, size_t msg_size)
{
    cm_status st = CM_OK;
    r->pts = malloc((size_t)a->n_values * (1 + (size_t)a->refine * SWEEP_CHANGES) * sizeof *r->pts);
    r->changes = malloc((size_t)a->n_values * SWEEP_CHANGES * sizeof *r->changes);
    if (!r->pts || !r->changes)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory");
    for (int k = 0; k < a->n_values && st == CM_OK; k++) {
        st = solve_next(a, h, r, a->values[k], msg, msg_size);
        if (st == CM_OK && k > 0) /* seeds forward as the values come */
            st = seed_point(a, r, &r->pts[k - 1], &r->pts[k], msg, msg_size);
        if (st == CM_OK && rep && rep->point)
            rep->point(rep->user, a, &r->pts[r->n - 1]);
        work_progress(h, (uint64_t)r->n, NULL);
    }
    for (int k = a->n_values - 2; k >= 0 && st == CM_OK; k--) /* and back */
        st = seed_point(a, r, &r->pts[k + 1], &r->pts[k], msg, msg_size);
    /* the listed values are pts[0 .. n_values-1]; refinements follow them */
    for (int k = 1; k < a->n_values && st == CM_OK; k++)
        st = find_changes(a, h, rep, r, k, msg, msg_size);
    if (st == CM_OK)
        qsort(r->pts, (size_t)r->n, sizeof *r->pts, by_value);
    if (st == CM_OK && a->by == BY_ATTRACTORS)
        st = track(a, r, msg, msg_size);
    return st;
}

void sweep_result_free(sweep_result *r)
{
    for (int k = 0; r->pts && k < r->n; k++)
        free(r->pts[k].att);
    free(r->pts);
    free(r->changes);
    free(r->events);
    r->pts = NULL, r->changes = NULL, r->events = NULL;
}
