#include "cellmap/attractors.h"

#include <math.h>
#include <stdio.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

const char *cm_attractor_kind_name(int kind)
{
    return kind == CM_ATTRACTOR_APERIODIC ? "aperiodic"
           : kind == CM_ATTRACTOR_STICKING ? "sticking"
                                           : "periodic";
}

void cm_attractor_defaults(const cm_model *m, const cm_attractor_options *in,
                           cm_attractor_options *out)
{
    static const cm_attractor_options none;
    *out = in ? *in : none;
    if (!out->transient)
        out->transient = CM_ATTRACTOR_TRANSIENT;
    if (!out->record)
        out->record = CM_ATTRACTOR_RECORD;
    if (!out->max_steps)
        out->max_steps = m && m->flow.field ? CM_ATTRACTOR_MAX_STEPS_FLOW : CM_ATTRACTOR_MAX_STEPS;
    if (out->tol == 0)
        out->tol = CM_ATTRACTOR_TOL;
    if (out->match == 0)
        out->match = CM_ATTRACTOR_MATCH;
    if (!out->outside)
        out->outside = CM_OUTSIDE_STEPS;
}

cm_status cm_attractor_check(const cm_attractor_options *o, char *msg, size_t msg_size)
{
    if (!(o->tol > 0 && isfinite(o->tol) && o->tol < 1))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the recurrence tolerance %g must be above 0 and below 1 cell width",
                       o->tol);
    if (!(o->match >= o->tol && isfinite(o->match) && o->match <= 1))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the matching tolerance %g must be between the recurrence tolerance (%g) "
                       "and 1 cell width",
                       o->match, o->tol);
    if (o->record < 8 || (uint64_t)o->transient + o->record > o->max_steps)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the attractor budget of %u steps must hold the transient (%u) and a "
                       "record of at least 8 steps (%u)",
                       o->max_steps, o->transient, o->record);
    if (o->outside > CM_OUTSIDE_MAX_STEPS && o->outside != CM_OUTSIDE_OFF)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "orbits that leave the computed cells are followed at most %u steps, "
                       "not %u", CM_OUTSIDE_MAX_STEPS, o->outside);
    return CM_OK;
}

/* ---- one group's true orbit ------------------------------------------- */

/* A group's orbit: decided by itself, or (ORBIT_INHERITS) by the group its
 * true orbit leads to. */
enum {
    ORBIT_PERIODIC,
    ORBIT_APERIODIC,
    ORBIT_DIVERGED,
    ORBIT_UNRESOLVED,
    ORBIT_STICKING,
    ORBIT_INHERITS
};

/* The cells whose groups a probe counts, after its transient. */
#define LABEL_WINDOW 16

/* The share of new cells in a record's second half below which it has settled. */
#define SETTLED_NEW 0.05

/* A cell with its unused coordinates 0, so that comparisons need no
 * dimension (qsort has no user pointer). */
typedef struct cell_key {
    int64_t c[CM_MAX_DIM];
} cell_key;

typedef struct orbit {
    int fate;
    uint32_t period;
    double *cycle;   /* period * dim states, the last cycle recorded */
    cell_key *cells; /* its footprint: distinct cells, in box order */
    uint64_t ncells;
    uint64_t steps;
} orbit;

typedef struct follow_ctx {
    const cm_model *m;
    const cm_lattice *lat;
    const cm_attractor_options *o;
    double tol_abs[CM_MAX_DIM];
} follow_ctx;

/* Box order (cm_cell_less), for qsort. */
static int key_compare(const void *a, const void *b)
{
    const int64_t *x = ((const cell_key *)a)->c, *y = ((const cell_key *)b)->c;
    return cm_cell_less(x, y, CM_MAX_DIM) ? -1 : cm_cell_less(y, x, CM_MAX_DIM);
}

/* Sorts n cells into box order and drops repeats; returns how many remain. */
static uint64_t unique_cells(cell_key *cells, uint64_t n)
{
    if (n == 0)
        return 0;
    qsort(cells, n, sizeof *cells, key_compare);
    uint64_t k = 1;
    for (uint64_t i = 1; i < n; i++)
        if (key_compare(&cells[i], &cells[k - 1]) != 0)
            cells[k++] = cells[i];
    return k;
}

static cell_key key_of(const cm_lattice *lat, const double *x)
{
    cell_key k;
    memset(&k, 0, sizeof k);
    cm_lattice_cell(lat, x, k.c);
    return k;
}

/* Whether a and b are within tol in every coordinate (the shortest way
 * round a periodic one: period[d] > 0). */
static bool close_states(const double *a, const double *b, int dim, const double *tol,
                         const double *period)
{
    for (int d = 0; d < dim; d++)
        if (!(fabs(cm_period_diff(period, d, a[d], b[d])) <= tol[d]))
            return false;
    return true;
}

/* The smallest p whose cycle the record's second half repeats, or 0:
 * there (at least two cycles of it) every state is within tol of the one
 * p before it, and every state in the last one's phase within tol of it
 * (converged, not creeping). One window for every p: judged each on its
 * own stretch, a fixed point still converging at the record's start would
 * fail p = 1 and pass as a longer cycle whose sparser checks start later
 * (a period-1 point of chip-4d's section map, multiplier -0.83, came out
 * as period 18). */
static uint32_t recurrence(const double *s, uint64_t n, int dim, const double *tol,
                           const double *period)
{
    const double *last = s + (n - 1) * dim;
    const uint64_t w = n / 2; /* the window: s[w .. n - 1] */
    for (uint64_t p = 1; w + 2 * p <= n; p++) {
        if (!close_states(last, last - p * dim, dim, tol, period))
            continue;
        uint64_t i = w + p;
        while (i < n && close_states(s + i * dim, s + (i - p) * dim, dim, tol, period))
            i++;
        uint64_t j = p;
        while (i == n && j <= n - 1 - w && close_states(last, last - j * dim, dim, tol, period))
            j += p;
        if (i == n && j > n - 1 - w)
            return (uint32_t)p;
    }
    return 0;
}

/* One step of the true map; false when the orbit diverges (no image, a
 * state that is not finite or beyond the world). */
static bool true_step(const follow_ctx *f, double *x, cell_key *k)
{
    double y[CM_MAX_DIM];
    if (f->m->step(f->m, x, y) != CM_STEP_OK || !cm_lattice_cell(f->lat, y, k->c))
        return false;
    for (int d = 0; d < f->lat->dim; d++)
        x[d] = y[d];
    return true;
}

/* The footprint of a cycle: the cells of its states. */
static cm_status cycle_result(orbit *r, const double *s, uint64_t n, uint32_t p, int dim,
                              const cm_lattice *lat)
{
    r->fate = ORBIT_PERIODIC;
    r->period = p;
    r->cycle = malloc((size_t)p * dim * sizeof *r->cycle);
    r->cells = malloc((size_t)p * sizeof *r->cells);
    if (!r->cycle || !r->cells)
        return CM_ENOMEM;
    memcpy(r->cycle, s + (n - p) * dim, (size_t)p * dim * sizeof *s);
    for (uint32_t i = 0; i < p; i++)
        r->cells[i] = key_of(lat, r->cycle + (size_t)i * dim);
    r->ncells = unique_cells(r->cells, p);
    return CM_OK;
}

/* A set of cells, each with an owner: an open-addressing table. */
typedef struct cell_owner {
    cell_key *cells;
    uint32_t *owner; /* UINT32_MAX: an empty slot */
    uint64_t mask, used;
    int dim;
} cell_owner;

static uint64_t cell_hash(const cell_key *k, int dim)
{
    uint64_t h = 0x9E3779B97F4A7C15u;
    for (int d = 0; d < dim; d++) {
        h ^= (uint64_t)k->c[d] + 0x9E3779B97F4A7C15u + (h << 6) + (h >> 2);
        h *= 0xBF58476D1CE4E5B9u;
    }
    return h ^ (h >> 31);
}

static bool same_cell(const cell_key *a, const cell_key *b, int dim)
{
    for (int d = 0; d < dim; d++)
        if (a->c[d] != b->c[d])
            return false;
    return true;
}

/* The slot of cell k (hash h = cell_hash(k)): its own, or the empty one
 * it would take. */
static uint64_t owner_slot_hashed(const cell_owner *t, const cell_key *k, uint64_t h)
{
    uint64_t i = h & t->mask;
    while (t->owner[i] != UINT32_MAX && !same_cell(&t->cells[i], k, t->dim))
        i = (i + 1) & t->mask;
    return i;
}

static uint64_t owner_slot(const cell_owner *t, const cell_key *k)
{
    return owner_slot_hashed(t, k, cell_hash(k, t->dim));
}

static cm_status owner_init(cell_owner *t, uint64_t cells, int dim)
{
    t->dim = dim;
    uint64_t cap = 16;
    while (cap < 2 * cells + 2)
        cap *= 2;
    t->mask = cap - 1;
    t->used = 0;
    t->cells = malloc((size_t)cap * sizeof *t->cells);
    t->owner = malloc((size_t)cap * sizeof *t->owner);
    if (!t->cells || !t->owner)
        return CM_ENOMEM;
    memset(t->owner, 0xFF, (size_t)cap * sizeof *t->owner);
    return CM_OK;
}

static void owner_free(cell_owner *t)
{
    free(t->cells);
    free(t->owner);
}

/* Gives cell k to owner o unless it has one; returns its owner before
 * (UINT32_MAX: none). Grows the table at half load. */
static cm_status owner_claim_hashed(cell_owner *t, const cell_key *k, uint64_t h, uint32_t o,
                                    uint32_t *before)
{
    if (2 * (t->used + 1) > t->mask + 1) {
        cell_owner bigger;
        if (owner_init(&bigger, t->mask + 1, t->dim) != CM_OK) {
            owner_free(&bigger);
            return CM_ENOMEM;
        }
        for (uint64_t i = 0; i <= t->mask; i++)
            if (t->owner[i] != UINT32_MAX) {
                const uint64_t j = owner_slot(&bigger, &t->cells[i]);
                bigger.cells[j] = t->cells[i];
                bigger.owner[j] = t->owner[i];
            }
        bigger.used = t->used;
        owner_free(t);
        *t = bigger;
    }
    const uint64_t i = owner_slot_hashed(t, k, h);
    *before = t->owner[i];
    if (*before == UINT32_MAX) {
        t->cells[i] = *k;
        t->owner[i] = o;
        t->used++;
    }
    return CM_OK;
}

static cm_status owner_claim(cell_owner *t, const cell_key *k, uint32_t o, uint32_t *before)
{
    return owner_claim_hashed(t, k, cell_hash(k, t->dim), o, before);
}

/* Consecutive moves from cell to cell inside the footprint of one
 * attractor found before after which an orbit is taken to be on it (moves,
 * not steps: a map that moves less than a cell a step stays in a cell for
 * many steps wherever it is). */
#define KNOWN_RUN 8

/* The known footprint the last `run` moves of a walk stayed on. */
typedef struct known_walk {
    cell_key at; /* the cell of the last move */
    uint32_t owner, run;
} known_walk;

/* Notes the walk's cell k (hash h): true once KNOWN_RUN moves from cell to
 * cell stayed on one footprint of known (walk->owner). */
static bool known_move(const cell_owner *known, known_walk *w, const cell_key *k, uint64_t h,
                       int dim)
{
    if (same_cell(k, &w->at, dim))
        return false;
    w->at = *k;
    const uint32_t j = known->owner[owner_slot_hashed(known, k, h)];
    w->run = j != UINT32_MAX && j == w->owner ? w->run + 1 : j != UINT32_MAX;
    w->owner = j;
    return w->run >= KNOWN_RUN;
}

/* The states a record keeps, its last ones: periods up to a third of them
 * are found (RING / 3 = 1024); longer cycles are aperiodic here. */
#define RING 3072

/* One record of len steps from x: the last states in ring (the state of
 * step i at i % RING), and the cells in t (of the first half FIRST, of the
 * second half seen in the first SEEN_AGAIN, else FRESH). Stops early when
 * the orbit diverges (*done < len) or makes KNOWN_RUN moves on one known
 * footprint (*owner). */
enum { FIRST, SEEN_AGAIN, FRESH };

typedef struct record {
    double *ring;       /* min(len, RING) states */
    uint64_t ring_cap;  /* states it holds */
    cell_owner t;
    uint64_t done, again, fresh;
    known_walk walk; /* on the known footprints */
    double origin[CM_MAX_DIM]; /* the state before the record: sums are taken from it */
    double sum[2][CM_MAX_DIM], squares[CM_MAX_DIM]; /* of each half, and of both */
} record;

static cm_status take_record(const follow_ctx *f, double *x, uint64_t len, const cell_owner *known,
                             record *rec)
{
    const int dim = f->lat->dim;
    cm_status st = owner_init(&rec->t, 32, dim);
    const uint64_t need = len < RING ? len : RING;
    if (st == CM_OK && rec->ring_cap < need) {
        double *ring = realloc(rec->ring, (size_t)need * dim * sizeof *ring);
        if (!ring)
            return CM_ENOMEM;
        rec->ring = ring;
        rec->ring_cap = need;
    }
    rec->done = rec->again = rec->fresh = 0;
    memcpy(rec->origin, x, (size_t)dim * sizeof *x);
    memset(rec->sum, 0, sizeof rec->sum);
    memset(rec->squares, 0, sizeof rec->squares);
    cell_key k;
    memset(&k, 0, sizeof k);
    bool on_known = false;
    for (uint64_t i = 0; st == CM_OK && i < len && !on_known; i++) {
        if (!true_step(f, x, &k))
            return CM_OK;
        rec->done++;
        double *kept = rec->ring + (i % RING) * dim;
        for (int d = 0; d < dim; d++) {
            kept[d] = x[d];
            const double u = cm_model_diff(f->m, d, x[d], rec->origin[d]);
            rec->sum[i >= len / 2][d] += u;
            rec->squares[d] += u * u;
        }
        const uint64_t h = cell_hash(&k, dim);
        uint64_t slot = owner_slot_hashed(&rec->t, &k, h);
        uint32_t before;
        if (i < len / 2) {
            if (rec->t.owner[slot] == UINT32_MAX)
                st = owner_claim_hashed(&rec->t, &k, h, FIRST, &before);
        } else if (rec->t.owner[slot] == FIRST) {
            rec->t.owner[slot] = SEEN_AGAIN;
            rec->again++;
        } else if (rec->t.owner[slot] == UINT32_MAX) {
            st = owner_claim_hashed(&rec->t, &k, h, FRESH, &before);
            rec->fresh++;
        }
        on_known = known && known_move(known, &rec->walk, &k, h, dim);
    }
    return st;
}

/* Whether the record is stationary, not creeping: in every coordinate the
 * means of its halves differ by less than half the record's spread (a
 * steady drift differs by about 1.7 times its spread; an orbit on an
 * attractor by ever less as the record grows). */
static bool stationary(const record *rec, uint64_t len, int dim)
{
    const double h1 = (double)(len / 2), h2 = (double)(len - len / 2), n = (double)len;
    for (int d = 0; d < dim; d++) {
        const double m1 = rec->sum[0][d] / h1, m2 = rec->sum[1][d] / h2;
        const double mean = (rec->sum[0][d] + rec->sum[1][d]) / n;
        const double var = fmax(rec->squares[d] / n - mean * mean, 0);
        if (fabs(m2 - m1) > 0.5 * sqrt(var))
            return false;
    }
    return true;
}

/* The record's last min(len, RING) states in order into s. */
static uint64_t ring_states(const record *rec, uint64_t len, int dim, double *s)
{
    const uint64_t n = len < RING ? len : RING;
    for (uint64_t i = 0; i < n; i++)
        memcpy(s + i * dim, rec->ring + ((len - n + i) % RING) * dim, (size_t)dim * sizeof *s);
    return n;
}

/* The record's cells, distinct and in box order, as r's footprint. */
static cm_status footprint_of(const record *rec, orbit *r)
{
    r->cells = malloc((size_t)(rec->t.used + 1) * sizeof *r->cells);
    if (!r->cells)
        return CM_ENOMEM;
    r->ncells = 0;
    for (uint64_t i = 0; i <= rec->t.mask; i++)
        if (rec->t.owner[i] != UINT32_MAX)
            r->cells[r->ncells++] = rec->t.cells[i];
    r->ncells = unique_cells(r->cells, r->ncells);
    return CM_OK;
}

/* Before any record: up to `steps` steps that only look for KNOWN_RUN
 * moves on one known footprint (most orbits of a cluster end on the
 * attractors its largest basins hold). 1: on footprint *owner; -1: the
 * orbit diverged; 0: neither. */
static int onto_known(const follow_ctx *f, double *x, uint64_t steps, const cell_owner *known,
                      uint32_t *owner, uint64_t *done)
{
    cell_key k;
    known_walk w;
    memset(&k, 0, sizeof k);
    memset(&w, 0, sizeof w);
    w.owner = UINT32_MAX;
    for (uint64_t i = 0; i < steps; i++) {
        if (!true_step(f, x, &k))
            return -1;
        ++*done;
        if (known_move(known, &w, &k, cell_hash(&k, f->lat->dim), f->lat->dim)) {
            *owner = w.owner;
            return 1;
        }
    }
    return 0;
}

/* Follows the true orbit on from x (steps taken so far in r->steps):
 * records that double until the orbit recurs, settles (the record is
 * stationary, and its second half visits almost no cell that its first
 * half did not: at most SETTLED_NEW of them) or diverges, or the budget is spent, or (known not
 * NULL) it makes KNOWN_RUN moves in the footprint of one earlier orbit
 * (r->fate ORBIT_INHERITS, *from its owner), which it first looks for
 * alone for a record's length. */
static cm_status follow(const follow_ctx *f, double *x, const cell_owner *known, orbit *r,
                        uint32_t *from)
{
    const int dim = f->lat->dim;
    const cm_attractor_options *o = f->o;
    uint64_t len = o->record;
    if (known) {
        const uint64_t room = r->steps < o->max_steps ? o->max_steps - r->steps : 0;
        const int on = onto_known(f, x, len < room ? len : room, known, from, &r->steps);
        if (on) {
            r->fate = on > 0 ? ORBIT_INHERITS : ORBIT_DIVERGED;
            return CM_OK;
        }
    }
    record *rec = calloc(1, sizeof *rec);
    double *s = NULL;
    uint64_t s_cap = 0;
    cm_status st = rec ? CM_OK : CM_ENOMEM;
    if (rec)
        rec->walk.owner = UINT32_MAX;
    r->fate = ORBIT_UNRESOLVED;
    while (st == CM_OK && r->fate == ORBIT_UNRESOLVED) {
        const bool last = r->steps + 2 * len > o->max_steps;
        if (r->steps + len > o->max_steps)
            len = o->max_steps - r->steps;
        st = take_record(f, x, len, known, rec);
        r->steps += rec->done;
        if (st != CM_OK)
            break;
        if (rec->walk.run >= KNOWN_RUN) {
            r->fate = ORBIT_INHERITS;
            *from = rec->walk.owner;
        } else if (rec->done < len) {
            r->fate = ORBIT_DIVERGED;
        } else {
            if (s_cap < rec->ring_cap) {
                double *grown = realloc(s, (size_t)rec->ring_cap * dim * sizeof *s);
                if (!grown) {
                    st = CM_ENOMEM;
                    break;
                }
                s = grown;
                s_cap = rec->ring_cap;
            }
            const uint64_t n = ring_states(rec, len, dim, s);
            const uint32_t p = recurrence(s, n, dim, f->tol_abs, f->m->period);
            const bool calm = !p && stationary(rec, len, dim) &&
                              (double)rec->fresh <= SETTLED_NEW * (double)(rec->again + rec->fresh);
            if (p)
                st = cycle_result(r, s, n, p, dim, f->lat);
            else if (calm) {
                r->fate = ORBIT_APERIODIC;
                st = footprint_of(rec, r);
            } else if (last || len < 8)
                break; /* unresolved */
            else
                len *= 2; /* this record becomes transient */
        }
        owner_free(&rec->t);
        memset(&rec->t, 0, sizeof rec->t);
    }
    if (rec) {
        owner_free(&rec->t);
        free(rec->ring);
    }
    free(rec);
    free(s);
    return st;
}

static void orbit_free(orbit *r)
{
    free(r->cycle);
    free(r->cells);
    memset(r, 0, sizeof *r);
}

/* ---- groups into attractors --------------------------------------------- */

static uint32_t find_root(uint32_t *parent, uint32_t i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
    return i;
}

/* Unites two classes under the one whose group has the smaller anchor
 * (the order does not change which groups end up together). */
static void unite(uint32_t *parent, uint32_t a, uint32_t b)
{
    a = find_root(parent, a);
    b = find_root(parent, b);
    if (a != b)
        parent[a > b ? a : b] = a < b ? a : b;
}

/* A point of a cycle, for matching cycles by their first coordinate. */
typedef struct cycle_point {
    double x0;
    uint32_t group; /* index into the order of groups by anchor */
    uint32_t i;     /* the point's index in its cycle */
} cycle_point;

static int by_x0(const void *a, const void *b)
{
    const cycle_point *p = a, *q = b;
    if (p->x0 != q->x0)
        return p->x0 < q->x0 ? -1 : 1;
    return p->group != q->group ? (p->group < q->group ? -1 : 1) : (p->i > q->i) - (p->i < q->i);
}

/* Unites periodic orbits whose cycles are one: equal periods, and the first
 * state of one within match of a state of the other. */
static cm_status match_cycles(const orbit *r, uint32_t n, int dim, const double *match,
                              const double *period, uint32_t *parent)
{
    uint64_t points = 0;
    for (uint32_t k = 0; k < n; k++)
        points += r[k].fate == ORBIT_PERIODIC ? r[k].period : 0;
    cycle_point *pt = malloc((points + 1) * sizeof *pt);
    if (!pt)
        return CM_ENOMEM;
    uint64_t m = 0;
    for (uint32_t k = 0; k < n; k++)
        for (uint32_t i = 0; r[k].fate == ORBIT_PERIODIC && i < r[k].period; i++)
            pt[m++] = (cycle_point){r[k].cycle[(size_t)i * dim], k, i};
    qsort(pt, m, sizeof *pt, by_x0);
    for (uint32_t k = 0; k < n; k++) {
        if (r[k].fate != ORBIT_PERIODIC)
            continue;
        const double *a = r[k].cycle;
        uint64_t lo = 0, hi = m; /* the first point with x0 >= a[0] - match[0] */
        while (lo < hi) {
            const uint64_t mid = lo + (hi - lo) / 2;
            if (pt[mid].x0 < a[0] - match[0])
                lo = mid + 1;
            else
                hi = mid;
        }
        for (uint64_t j = lo; j < m && pt[j].x0 <= a[0] + match[0]; j++) {
            const orbit *b = &r[pt[j].group];
            if (pt[j].group != k && b->period == r[k].period &&
                close_states(a, b->cycle + (size_t)pt[j].i * dim, dim, match, period))
                unite(parent, k, pt[j].group);
        }
    }
    free(pt);
    return CM_OK;
}

/* Unites orbits whose footprints (a cycle's cells, or the cells an
 * aperiodic orbit visits) share at least a quarter of the smaller one's
 * cells: at the lattice's resolution they are one attractor. Orbits come
 * in anchor order; each counts its cells that an earlier one claimed
 * first, by that one. */
static bool has_footprint(int fate) { return fate == ORBIT_APERIODIC || fate == ORBIT_PERIODIC; }

static cm_status match_footprints(const orbit *r, uint32_t n, uint32_t *parent)
{
    uint64_t all = 0;
    uint32_t with = 0;
    for (uint32_t k = 0; k < n; k++)
        if (has_footprint(r[k].fate)) {
            all += r[k].ncells;
            with++;
        }
    if (with < 2)
        return CM_OK;
    cell_owner t;
    uint64_t *shared = calloc(n, sizeof *shared);
    uint32_t *hit = malloc((size_t)n * sizeof *hit);
    cm_status st = owner_init(&t, all, CM_MAX_DIM);
    if (!shared || !hit)
        st = CM_ENOMEM;
    for (uint32_t k = 0; st == CM_OK && k < n; k++) {
        if (!has_footprint(r[k].fate))
            continue;
        uint32_t nhit = 0;
        for (uint64_t i = 0; i < r[k].ncells; i++) {
            const uint64_t slot = owner_slot(&t, &r[k].cells[i]);
            const uint32_t j = t.owner[slot];
            if (j == UINT32_MAX) {
                t.owner[slot] = k;
                t.cells[slot] = r[k].cells[i];
            } else if (shared[j]++ == 0) {
                hit[nhit++] = j;
            }
        }
        for (uint32_t h = 0; h < nhit; h++) {
            const uint32_t j = hit[h];
            const uint64_t smaller = r[k].ncells < r[j].ncells ? r[k].ncells : r[j].ncells;
            if (4 * shared[j] >= smaller)
                unite(parent, j, k);
            shared[j] = 0;
        }
    }
    free(t.cells);
    free(t.owner);
    free(shared);
    free(hit);
    return st;
}

/* ---- the set ------------------------------------------------------------- */

/* A group's place in the anchor order. */
typedef struct anchored {
    cell_key anchor;
    uint32_t index; /* into the groups array */
} anchored;

static int by_anchor(const void *a, const void *b)
{
    const anchored *p = a, *q = b;
    const int c = key_compare(&p->anchor, &q->anchor);
    return c ? c : (p->index > q->index) - (p->index < q->index);
}

/* Members of the classes, class by class: members[at[a]..at[a+1]) are
 * attractor a's groups in anchor order (representatives and those that
 * inherit from them); fate[k] is what group k's class came to. */
typedef struct classes {
    uint32_t n;
    uint32_t *of;      /* orbit -> class, UINT32_MAX: diverged or unresolved */
    uint8_t *fate;     /* orbit -> its class's fate (ORBIT_*) */
    uint32_t *members; /* orbits */
    uint32_t *at;      /* n + 1 offsets */
} classes;

static bool is_attractor(int fate)
{
    return fate == ORBIT_PERIODIC || fate == ORBIT_APERIODIC || fate == ORBIT_STICKING;
}

static cm_status make_classes(const orbit *r, uint32_t n, uint32_t *parent, classes *c)
{
    c->n = 0;
    c->of = malloc(((size_t)n + 1) * sizeof *c->of);
    c->fate = malloc((size_t)n + 1);
    c->members = malloc(((size_t)n + 1) * sizeof *c->members);
    c->at = calloc((size_t)n + 2, sizeof *c->at);
    uint32_t *of_root = malloc(((size_t)n + 1) * sizeof *of_root);
    uint8_t *root_fate = malloc((size_t)n + 1);
    if (!c->of || !c->fate || !c->members || !c->at || !of_root || !root_fate) {
        free(of_root);
        free(root_fate);
        return CM_ENOMEM;
    }
    for (uint32_t k = 0; k < n; k++) {
        of_root[k] = UINT32_MAX;
        root_fate[k] = ORBIT_UNRESOLVED;
    }
    for (uint32_t k = 0; k < n; k++) /* a class's representatives decide its fate */
        if (r[k].fate != ORBIT_INHERITS)
            root_fate[find_root(parent, k)] = (uint8_t)r[k].fate;
    for (uint32_t k = 0; k < n; k++) {
        const uint32_t root = find_root(parent, k);
        c->fate[k] = root_fate[root];
        c->of[k] = UINT32_MAX;
        if (!is_attractor(root_fate[root]))
            continue;
        if (of_root[root] == UINT32_MAX)
            of_root[root] = c->n++;
        c->of[k] = of_root[root];
        c->at[c->of[k] + 1]++;
    }
    for (uint32_t a = 0; a < c->n; a++)
        c->at[a + 1] += c->at[a];
    uint32_t *fill = of_root; /* reused: the next free slot of each class */
    for (uint32_t a = 0; a < c->n; a++)
        fill[a] = c->at[a];
    for (uint32_t k = 0; k < n; k++)
        if (c->of[k] != UINT32_MAX)
            c->members[fill[c->of[k]]++] = k;
    free(of_root);
    free(root_fate);
    return CM_OK;
}

static void classes_free(classes *c)
{
    free(c->of);
    free(c->fate);
    free(c->members);
    free(c->at);
}

/* Attractor a of class members: kind and period of its first member (the
 * smallest anchor), its footprint (the members' cells, distinct, into fp
 * from fp[0]; returns how many), basin, centre and bounds (the first
 * member's cycle, else the footprint cells' centres). */
static uint64_t describe(const cm_model *m, const cm_lattice *lat, const cm_group_info *groups,
                         const anchored *order, const orbit *r, const uint32_t *members,
                         uint32_t count, cm_attractor *at, cell_key *fp)
{
    const int dim = lat->dim;
    /* a converged cycle speaks for the class, else its first representative */
    const orbit *first = NULL;
    for (uint32_t i = 0; i < count && !first; i++)
        if (r[members[i]].fate == ORBIT_PERIODIC)
            first = &r[members[i]];
    for (uint32_t i = 0; i < count && !first; i++)
        if (r[members[i]].fate != ORBIT_INHERITS)
            first = &r[members[i]];
    at->kind = first->fate == ORBIT_PERIODIC   ? CM_ATTRACTOR_PERIODIC
               : first->fate == ORBIT_STICKING ? CM_ATTRACTOR_STICKING
                                               : CM_ATTRACTOR_APERIODIC;
    at->period = first->fate == ORBIT_APERIODIC ? 0 : first->period;
    at->groups = count;
    uint64_t used = 0;
    for (uint32_t i = 0; i < count; i++) {
        const orbit *o = &r[members[i]];
        at->basin_cells += groups[order[members[i]].index].basin_cells;
        if (o->ncells) /* those that inherit have no footprint of their own */
            memcpy(fp + used, o->cells, (size_t)o->ncells * sizeof *fp);
        used += o->ncells;
    }
    used = unique_cells(fp, used);
    at->footprint_cells = used;
    memcpy(at->anchor, fp[0].c, (size_t)dim * sizeof *at->anchor);
    double sum[CM_MAX_DIM] = {0};
    for (int d = 0; d < dim; d++) {
        at->lo[d] = INFINITY;
        at->hi[d] = -INFINITY;
    }
    const uint64_t points = first->cycle ? first->period : used;
    double ref[CM_MAX_DIM]; /* periodic coordinates are taken the shortest way from here */
    for (uint64_t i = 0; i < points; i++) {
        double x[CM_MAX_DIM];
        if (first->cycle)
            memcpy(x, first->cycle + i * dim, (size_t)dim * sizeof *x);
        else
            cm_lattice_centre(lat, fp[i].c, x);
        if (i == 0)
            memcpy(ref, x, (size_t)dim * sizeof *x);
        for (int d = 0; d < dim; d++) {
            x[d] = ref[d] + cm_model_diff(m, d, x[d], ref[d]);
            sum[d] += x[d];
            at->lo[d] = fmin(at->lo[d], x[d]);
            at->hi[d] = fmax(at->hi[d], x[d]);
        }
    }
    for (int d = 0; d < dim; d++)
        at->centre[d] = cm_model_wrap(m, d, sum[d] / (double)points);
    return used;
}

/* The classes as attractors numbered 1..n in the box order of their
 * anchors (the smallest cells of their footprints), and the groups' fates. */
static cm_status build_set(const cm_model *m, const cm_lattice *lat, const cm_group_info *groups,
                           const anchored *order, const orbit *r, uint32_t n, const classes *c,
                           cm_attractor_set *out)
{
    const int dim = lat->dim;
    uint64_t total = 0;
    for (uint32_t k = 0; k < n; k++)
        total += r[k].ncells;
    cell_key *fp = malloc(((size_t)total + 1) * sizeof *fp);
    cm_attractor *a = calloc((size_t)c->n + 1, sizeof *a);
    uint64_t *fp_at = calloc((size_t)c->n + 2, sizeof *fp_at);
    anchored *rank = malloc(((size_t)c->n + 1) * sizeof *rank);
    uint32_t *id_of = malloc(((size_t)c->n + 1) * sizeof *id_of);
    out->footprint = malloc(((size_t)total + 1) * dim * sizeof *out->footprint);
    out->a = calloc((size_t)c->n + 1, sizeof *out->a);
    out->footprint_at = calloc((size_t)c->n + 2, sizeof *out->footprint_at);
    cm_status st = fp && a && fp_at && rank && id_of && out->footprint && out->a &&
                           out->footprint_at
                       ? CM_OK
                       : CM_ENOMEM;
    for (uint32_t k = 0; st == CM_OK && k < c->n; k++) {
        const uint32_t from = c->at[k], count = c->at[k + 1] - from;
        fp_at[k + 1] = fp_at[k] + describe(m, lat, groups, order, r, c->members + from, count,
                                           &a[k], fp + fp_at[k]);
        rank[k] = (anchored){fp[fp_at[k]], k};
    }
    if (st == CM_OK) {
        qsort(rank, c->n, sizeof *rank, by_anchor);
        out->n = c->n;
        for (uint32_t i = 0; i < c->n; i++) {
            const uint32_t k = rank[i].index;
            id_of[k] = i + 1;
            out->a[i] = a[k];
            out->a[i].id = i + 1;
            out->footprint_at[i + 1] = out->footprint_at[i] + a[k].footprint_cells;
            for (uint64_t j = 0; j < a[k].footprint_cells; j++)
                memcpy(out->footprint + (out->footprint_at[i] + j) * dim, fp[fp_at[k] + j].c,
                       (size_t)dim * sizeof *out->footprint);
            out->merged += a[k].groups - 1;
        }
        out->of_group[0] = CM_FATE_DIVERGED;
        for (uint32_t k = 0; k < n; k++) {
            const cm_group_info *g = &groups[order[k].index];
            const int fate = c->fate[k];
            out->of_group[g->id] = fate == ORBIT_DIVERGED     ? CM_FATE_DIVERGED
                                   : fate == ORBIT_UNRESOLVED ? CM_FATE_UNRESOLVED
                                                              : id_of[c->of[k]];
            out->diverged_groups += fate == ORBIT_DIVERGED;
            out->unresolved_groups += fate == ORBIT_UNRESOLVED;
            out->unresolved_cells += fate == ORBIT_UNRESOLVED ? g->basin_cells : 0;
            out->diverged_cells += fate == ORBIT_DIVERGED ? g->basin_cells : 0;
        }
    }
    free(fp);
    free(a);
    free(fp_at);
    free(rank);
    free(id_of);
    return st;
}

/* ---- the probe: where each group's true orbit goes ------------------------ */

/* The cells of a probe's window, packed (dim coordinates each). */
typedef struct probe {
    double x[CM_MAX_DIM]; /* the state after the probe */
    bool diverged;
} probe;

/* Follows group k's orbit from its anchor's centre through the transient
 * and the window, whose cells go to window[k * WINDOW * dim ..]. */
static void run_probe(const follow_ctx *f, const int64_t *anchor, probe *p, int64_t *window,
                      uint64_t *steps)
{
    const int dim = f->lat->dim;
    cm_lattice_centre(f->lat, anchor, p->x);
    p->diverged = false;
    cell_key k;
    for (uint32_t i = 0; i < f->o->transient + LABEL_WINDOW; i++, ++*steps) {
        if (!true_step(f, p->x, &k)) {
            p->diverged = true;
            return;
        }
        if (i >= f->o->transient)
            memcpy(window + (size_t)(i - f->o->transient) * dim, k.c, (size_t)dim * sizeof *k.c);
    }
}

/* The group index (in anchor order) that group k's window mostly lands in
 * among the groups not known to diverge, from the window cells' groups
 * (window_group[0..LABEL_WINDOW)): k itself when its own basin is among
 * the most, or when no cell of the window has such a group (the sink,
 * cells not computed). */
static void successor(const uint32_t *window_group, uint32_t k, const uint32_t *index_of,
                      uint32_t ngroups, const probe *p, uint32_t *next)
{
    uint32_t seen[LABEL_WINDOW], count[LABEL_WINDOW], n = 0;
    for (int i = 0; i < LABEL_WINDOW; i++) {
        const uint32_t g = window_group[i];
        if (g == 0 || g > ngroups)
            continue; /* the sink, or no cell computed there */
        const uint32_t j = index_of[g];
        if (p[j].diverged)
            continue;
        uint32_t m = 0;
        while (m < n && seen[m] != j)
            m++;
        if (m == n) {
            seen[n] = j;
            count[n++] = 0;
        }
        count[m]++;
    }
    *next = k;
    uint32_t best = 0;
    for (uint32_t m = 0; m < n; m++)
        if (count[m] > best || (count[m] == best && (seen[m] == k || (*next != k && seen[m] < *next)))) {
            best = count[m];
            *next = seen[m];
        }
    for (uint32_t m = 0; m < n; m++) /* its own basin among the most: it stays */
        if (seen[m] == k && count[m] == best)
            *next = k;
}

/* Whether group k's window is looked up (successor). */
static bool has_successor(const cm_group_info *g, const probe *p)
{
    return g->kind != CM_GROUP_STICKING && !p->diverged;
}

/* The groups of the windows of the groups that have successors, into
 * *out (LABEL_WINDOW entries per group, in anchor order; the others'
 * entries CM_GROUP_NONE): one lookup for them all. */
static cm_status window_groups(const cm_group_info *groups, const anchored *order, uint32_t n,
                               const probe *p, const int64_t *window, int dim,
                               cm_cells_group_fn label, void *user, uint32_t **out, char *msg,
                               size_t msg_size)
{
    const size_t per = (size_t)LABEL_WINDOW * (size_t)dim;
    uint64_t asked = 0;
    for (uint32_t k = 0; k < n; k++)
        asked += has_successor(&groups[order[k].index], &p[k]);
    int64_t *cells = malloc((asked * per + 1) * sizeof *cells);
    uint32_t *found = malloc((asked * LABEL_WINDOW + 1) * sizeof *found);
    *out = malloc(((size_t)n * LABEL_WINDOW + 1) * sizeof **out);
    cm_status st = cells && found && *out
                       ? CM_OK
                       : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory following %u groups", n);
    uint64_t j = 0;
    for (uint32_t k = 0; st == CM_OK && k < n; k++)
        if (has_successor(&groups[order[k].index], &p[k]))
            memcpy(cells + (j++) * per, window + (size_t)k * per, per * sizeof *cells);
    if (st == CM_OK)
        st = label(user, cells, asked * LABEL_WINDOW, found, msg, msg_size);
    j = 0;
    for (uint32_t k = 0; st == CM_OK && k < n; k++) {
        uint32_t *w = *out + (size_t)k * LABEL_WINDOW;
        if (has_successor(&groups[order[k].index], &p[k]))
            memcpy(w, found + (j++) * LABEL_WINDOW, LABEL_WINDOW * sizeof *w);
        else
            for (int i = 0; i < LABEL_WINDOW; i++)
                w[i] = CM_GROUP_NONE;
    }
    free(cells);
    free(found);
    if (st != CM_OK) {
        free(*out);
        *out = NULL;
    }
    return st;
}

/* The groups on cycles of the successor graph (each cycle's first in
 * anchor order, its representative, gets rep[k] = true); every group is
 * united with its successor. */
static void cycles_of(const uint32_t *next, uint32_t n, uint32_t *parent, bool *rep)
{
    uint8_t *mark = calloc(n ? n : 1, 1); /* 0 new, 1 on the walk, 2 done */
    for (uint32_t k = 0; k < n; k++) {
        rep[k] = false;
        unite(parent, k, next[k]);
    }
    for (uint32_t k = 0; mark && k < n; k++) {
        uint32_t j = k;
        while (mark[j] == 0) {
            mark[j] = 1;
            j = next[j];
        }
        if (mark[j] == 1) { /* a new cycle through j: its smallest index speaks */
            uint32_t first = j, i = next[j];
            while (i != j) {
                first = i < first ? i : first;
                i = next[i];
            }
            rep[first] = true;
        }
        for (j = k; mark[j] == 1; j = next[j])
            mark[j] = 2;
    }
    if (!mark) /* out of memory: every group checks itself */
        for (uint32_t k = 0; k < n; k++)
            rep[k] = true;
    free(mark);
}

/* Representatives are checked in batches, each against the footprints of
 * the batches before: the first of CHECK_BATCH, then twice as many each
 * time up to CHECK_BATCH_MAX (once the largest basins' attractors are
 * known, most orbits end on them at once). Fixed sizes, so that what is
 * known when a group is checked never depends on the thread count. */
#define CHECK_BATCH 8
#define CHECK_BATCH_MAX 256

/* A representative's place in the checking order: the largest basins
 * first (the likely attractors, whose footprints then catch the orbits of
 * the groups drifting onto them), then anchor order. */
typedef struct ranked_rep {
    uint64_t basin;
    uint32_t k;
} ranked_rep;

static int larger_first(const void *a, const void *b)
{
    const ranked_rep *p = a, *q = b;
    if (p->basin != q->basin)
        return p->basin > q->basin ? -1 : 1;
    return (p->k > q->k) - (p->k < q->k);
}

/* The full check of the representatives still unresolved (r[k].fate), in
 * batches; an orbit that stays on the footprint of one checked before is
 * united with it. */
static cm_status check_representatives(const follow_ctx *f, const cm_group_info *groups,
                                       const anchored *order, uint32_t n, probe *p,
                                       uint32_t *parent, orbit *r, uint64_t *taken, char *msg,
                                       size_t msg_size)
{
    const int threads = f->o->threads > 0 ? f->o->threads : omp_get_max_threads();
    ranked_rep *todo = malloc(((size_t)n + 1) * sizeof *todo);
    uint32_t *from = malloc(((size_t)n + 1) * sizeof *from);
    cell_owner known;
    cm_status st = owner_init(&known, 64, f->lat->dim);
    uint32_t m = 0;
    for (uint32_t k = 0; todo && k < n; k++)
        if (r[k].fate == ORBIT_UNRESOLVED)
            todo[m++] = (ranked_rep){groups[order[k].index].basin_cells, k};
    if (!todo || !from)
        st = CM_ENOMEM;
    if (st == CM_OK)
        qsort(todo, m, sizeof *todo, larger_first);
    uint32_t size = CHECK_BATCH;
    for (uint32_t b = 0, end; st == CM_OK && b < m; b = end) {
        end = b + size < m ? b + size : m;
        size = 2 * size < CHECK_BATCH_MAX ? 2 * size : CHECK_BATCH_MAX;
        int failed = 0;
        uint64_t steps = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) reduction(| : failed) \
    reduction(+ : steps) if (end - b > 1)
        for (int64_t i = b; i < (int64_t)end; i++) {
            const uint32_t k = todo[i].k;
            const uint64_t before = r[k].steps;
            failed |= follow(f, p[k].x, known.used ? &known : NULL, &r[k], &from[k]) != CM_OK;
            steps += r[k].steps - before;
        }
        *taken += steps;
        if (failed)
            st = CM_ENOMEM;
        for (uint32_t i = b; st == CM_OK && i < end; i++) {
            const uint32_t k = todo[i].k;
            if (r[k].fate == ORBIT_INHERITS)
                unite(parent, from[k], k);
            for (uint64_t c = 0; st == CM_OK && c < r[k].ncells; c++) {
                uint32_t before;
                st = owner_claim(&known, &r[k].cells[c], k, &before);
            }
        }
    }
    owner_free(&known);
    free(todo);
    free(from);
    return st == CM_OK ? CM_OK
                       : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory following %u groups", n);
}

/* Follows the orbits of the groups in anchor order: the probe on every
 * group, then the full check on the representatives of the successor
 * graph's cycles, on the threads asked for; sticking zones are taken as
 * they are. */
static cm_status follow_groups(const follow_ctx *f, const cm_group_info *groups,
                               const anchored *order, uint32_t n, cm_cells_group_fn label,
                               void *user, uint32_t *parent, orbit *r, uint64_t *steps,
                               char *msg, size_t msg_size)
{
    const int dim = f->lat->dim, threads = f->o->threads > 0 ? f->o->threads : omp_get_max_threads();
    probe *p = calloc((size_t)n + 1, sizeof *p);
    int64_t *window = malloc(((size_t)n + 1) * LABEL_WINDOW * dim * sizeof *window);
    uint32_t *next = malloc(((size_t)n + 1) * sizeof *next);
    uint32_t *index_of = calloc((size_t)n + 2, sizeof *index_of);
    bool *rep = calloc((size_t)n + 1, sizeof *rep);
    if (!p || !window || !next || !index_of || !rep) {
        free(p), free(window), free(next), free(index_of), free(rep);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory following %u groups", n);
    }
    uint64_t taken = 0;
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads) reduction(+ : taken) if (n > 1)
    for (int64_t k = 0; k < (int64_t)n; k++)
        if (groups[order[k].index].kind != CM_GROUP_STICKING)
            run_probe(f, groups[order[k].index].anchor, &p[k], window + k * LABEL_WINDOW * dim,
                      &taken);
    cm_status st = CM_OK;
    for (uint32_t k = 0; k < n; k++)
        if (groups[order[k].index].id <= n)
            index_of[groups[order[k].index].id] = k;
    uint32_t *window_group = NULL;
    if (label)
        st = window_groups(groups, order, n, p, window, dim, label, user, &window_group, msg,
                           msg_size);
    for (uint32_t k = 0; k < n && st == CM_OK; k++) {
        next[k] = k;
        if (label && has_successor(&groups[order[k].index], &p[k]))
            successor(window_group + (size_t)k * LABEL_WINDOW, k, index_of, n, p, &next[k]);
        if (next[k] != k && groups[order[next[k]].index].kind == CM_GROUP_STICKING)
            next[k] = k; /* rest states are not an orbit's fate here */
    }
    free(window_group);
    if (st == CM_OK)
        cycles_of(next, n, parent, rep);
    for (uint32_t k = 0; st == CM_OK && k < n; k++) {
        const cm_group_info *g = &groups[order[k].index];
        r[k].steps = f->o->transient + LABEL_WINDOW;
        r[k].fate = !rep[k] ? ORBIT_INHERITS : p[k].diverged ? ORBIT_DIVERGED : ORBIT_UNRESOLVED;
        if (rep[k] && g->kind == CM_GROUP_STICKING) {
            r[k].fate = ORBIT_STICKING;
            r[k].period = g->period;
            r[k].cells = malloc(sizeof *r[k].cells);
            if (!r[k].cells)
                st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory following %u groups", n);
            else
                r[k].cells[0] = order[k].anchor;
            r[k].ncells = 1;
        }
    }
    if (st == CM_OK)
        st = check_representatives(f, groups, order, n, p, parent, r, &taken, msg, msg_size);
    *steps = taken;
    free(p), free(window), free(next), free(index_of), free(rep);
    return st;
}

cm_status cm_region_cells_group(void *region, const int64_t *cells, uint64_t n, uint32_t *group,
                                char *msg, size_t msg_size)
{
    (void)msg, (void)msg_size;
    const cm_region *r = region;
    for (uint64_t i = 0; i < n; i++) {
        const int64_t *cell = cells + i * (uint64_t)r->box.dim;
        group[i] =
            cm_box_contains(&r->box, cell) ? r->group[cm_box_index(&r->box, cell)] : CM_GROUP_NONE;
    }
    return CM_OK;
}

cm_status cm_attractors_find(const cm_model *m, const cm_lattice *lat,
                             const cm_group_info *groups, uint32_t ngroups,
                             cm_cells_group_fn label, void *label_user,
                             const cm_attractor_options *opt, cm_attractor_set *out, char *msg,
                             size_t msg_size)
{
    memset(out, 0, sizeof *out);
    cm_attractor_options o;
    cm_attractor_defaults(m, opt, &o);
    cm_status st = cm_attractor_check(&o, msg, msg_size);
    if (st != CM_OK)
        return st;
    const int dim = lat->dim;
    follow_ctx f = {m, lat, &o, {0}};
    double match[CM_MAX_DIM];
    for (int d = 0; d < dim; d++) {
        f.tol_abs[d] = o.tol * lat->width[d];
        match[d] = o.match * lat->width[d];
    }
    out->ngroups = ngroups;
    out->of_group = calloc((size_t)ngroups + 1, sizeof *out->of_group);
    anchored *order = malloc(((size_t)ngroups + 1) * sizeof *order);
    uint32_t *parent = malloc(((size_t)ngroups + 1) * sizeof *parent);
    orbit *r = calloc((size_t)ngroups + 1, sizeof *r);
    classes c = {0, NULL, NULL, NULL, NULL};
    if (!out->of_group || !order || !parent || !r)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the attractors of %u groups",
                     ngroups);
    for (uint32_t k = 0; st == CM_OK && k < ngroups; k++) {
        memset(&order[k], 0, sizeof order[k]);
        memcpy(order[k].anchor.c, groups[k].anchor, (size_t)dim * sizeof *groups[k].anchor);
        order[k].index = k;
        parent[k] = k;
    }
    if (st == CM_OK) { /* anchors, not ids, decide: the same in any split */
        qsort(order, ngroups, sizeof *order, by_anchor);
        st = follow_groups(&f, groups, order, ngroups, label, label_user, parent, r, &out->steps,
                           msg, msg_size);
    }
    cm_status mem = CM_OK;
    if (st == CM_OK)
        mem = match_cycles(r, ngroups, dim, match, m->period, parent);
    if (st == CM_OK && mem == CM_OK)
        mem = match_footprints(r, ngroups, parent);
    if (st == CM_OK && mem == CM_OK)
        mem = make_classes(r, ngroups, parent, &c);
    if (st == CM_OK && mem == CM_OK)
        mem = build_set(m, lat, groups, order, r, ngroups, &c, out);
    if (st == CM_OK && mem != CM_OK)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the attractors of %u groups",
                     ngroups);
    classes_free(&c);
    for (uint32_t k = 0; r && k < ngroups; k++)
        orbit_free(&r[k]);
    free(r);
    free(order);
    free(parent);
    return st;
}

int32_t cm_attractor_label(const cm_attractor_set *s, uint32_t g)
{
    if (g == CM_GROUP_NONE)
        return CM_LABEL_UNCOMPUTED;
    const uint32_t a = g == 0 || g > s->ngroups ? CM_FATE_UNRESOLVED : s->of_group[g];
    return a == CM_FATE_UNRESOLVED ? CM_LABEL_OUTSIDE : (int32_t)a;
}

int32_t cm_attractor_exit_label(const cm_attractor_set *s, int dim, const int64_t *cell)
{
    const uint64_t k = cm_cell_search(s->exit_cell, s->nexits, dim, cell);
    return k == UINT64_MAX ? CM_LABEL_OUTSIDE : s->exit_label[k];
}

int64_t cm_attractor_fate(const cm_attractor_set *s, uint32_t g)
{
    const uint32_t a = s->of_group[g];
    return a == CM_FATE_UNRESOLVED ? -1 : (int64_t)a;
}

void cm_attractors_free(cm_attractor_set *s)
{
    if (!s)
        return;
    free(s->a);
    free(s->of_group);
    free(s->footprint);
    free(s->footprint_at);
    free(s->exit_cell);
    free(s->exit_label);
    memset(s, 0, sizeof *s);
}
