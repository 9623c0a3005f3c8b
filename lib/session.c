/* lib/session.c - an explore session's engine half (lib/session.h). */
#include "lib/session.h"

#include <malloc.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cellmap/clock.h"
#include "cellmap/cover.h"
#include "cellmap/extend.h"
#include "cellmap/output.h"
#include "lib/parse.h"

/* By default a call may compute at most this many new cells (12 bytes each). */
#define MAX_NEW_CELLS (UINT64_C(1) << 28)
enum { VIEW_TEXT = 512 };

/* ---- the view ------------------------------------------------------------ */

/* The cells the view touches: dimensions 0 and 1 from the view, the others
 * the session's depth. */
static void view_box(const session *s, const double *lo, const double *hi, cm_box *box)
{
    const cm_lattice *lat = &s->c.lat;
    memset(box, 0, sizeof *box);
    box->dim = s->dim;
    cm_rect_box(lat, s->view_dims, lo, hi, box);
    for (int d = s->view_dims; d < s->dim; d++) {
        box->lo[d] = s->depth_lo[d];
        box->hi[d] = s->depth_hi[d];
    }
}

void session_slice_box(const session *s, cm_box *box)
{
    box->dim = s->dim;
    for (int d = 2; d < s->dim; d++) {
        box->lo[d] = s->slice[d];
        box->hi[d] = s->slice[d] + 1;
    }
}

/* The one layer of the view's box that is drawn (the slice). */
static void shown_box(const session *s, cm_box *box)
{
    view_box(s, s->lo, s->hi, box);
    session_slice_box(s, box);
}

static void format_view(const session *s, char *out, size_t size)
{
    size_t used = 0;
    out[0] = 0;
    for (int d = 0; d < s->view_dims && used < size; d++)
        used += (size_t)snprintf(out + used, size - used, "%s%.9g:%.9g", d ? " " : "", s->lo[d],
                                 s->hi[d]);
    for (int d = 2; d < s->dim && used < size; d++)
        used +=
            (size_t)snprintf(out + used, size - used, "%s%.9g", d == 2 ? " at " : ",",
                             s->c.lat.origin[d] + ((double)s->slice[d] + 0.5) * s->c.lat.width[d]);
}

/* A view must be finite, inside the world and at least a cell wide. */
static cm_status check_view(const session *s, const double *lo, const double *hi, const char *verb,
                            char *msg, size_t msg_size)
{
    const cm_lattice *lat = &s->c.lat;
    for (int d = 0; d < s->view_dims; d++) {
        const double cells = (hi[d] - lo[d]) / lat->width[d];
        const double far = fmax(fabs(lo[d] - lat->origin[d]), fabs(hi[d] - lat->origin[d]));
        if (!isfinite(lo[d]) || !isfinite(hi[d]) || !(lo[d] < hi[d]))
            return cm_fail(CM_EINVAL, msg, msg_size, "%s: the view needs LO < HI, both finite",
                           verb);
        if (far / lat->width[d] > (double)CM_WORLD_LIMIT / 2)
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "%s: the view would leave the world (more than 2^39 cells from the "
                           "origin in %s)",
                           verb, cm_model_coord_name(&s->model, d));
        if (cells < 1.0)
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "%s: the view would be %.3g cells wide in %s, below the lattice's "
                           "resolution (cells %.6g wide); stay at least one cell wide",
                           verb, cells, cm_model_coord_name(&s->model, d), lat->width[d]);
    }
    return CM_OK;
}


/* ---- computing what the view uncovers -------------------------------------- */

/* Solves the boxes as new regions and joins them, one commit per join. */
static cm_status compute_boxes(session *s, const cm_box *boxes, uint32_t n, session_work *done,
                               char *msg, size_t msg_size)
{
    const cm_scm_options opt = {.max_steps = s->max_steps,
                                .threads = s->threads,
                                .record_exits = 1};
    cm_join_stats stats;
    const double t0 = cm_seconds();
    cm_status st = project_solve_boxes(&s->c, s->store, &s->model, &opt, boxes, n, NULL, NULL,
                                       &stats, msg, msg_size);
    done->seconds += cm_seconds() - t0;
    s->grew |= n > 0;
    if (st != CM_OK)
        return st;
    done->cells += cm_boxes_cells(boxes, n);
    done->regions += n;
    done->new_groups += stats.new_groups;
    done->straddling += stats.straddling_groups;
    done->affected += stats.affected_regions;
    return CM_OK;
}

/* Computes the cells of `box` the cluster lacks. */
static cm_status cover_box(session *s, const cm_box *box, const char *verb, session_work *done,
                           char *msg, size_t msg_size)
{
    cm_box *boxes = NULL;
    uint32_t n = 0;
    cm_status st = cm_cluster_uncovered(&s->c, box, &boxes, &n, msg, msg_size);
    const uint64_t cells = cm_boxes_cells(boxes, n);
    if (st == CM_OK && cells > s->max_new_cells)
        st = cm_fail(CM_ETOOBIG, msg, msg_size,
                     "%s would compute %llu new cells, more than %llu at once%s; zoom or pan in "
                     "smaller steps%s",
                     verb, (unsigned long long)cells, (unsigned long long)s->max_new_cells,
                     s->mem_given ? " (what the memory budget holds, 12 bytes a cell)" : "",
                     s->mem_given ? ", or give a larger memory budget" : "");
    if (st == CM_OK && n > 0)
        st = compute_boxes(s, boxes, n, done, msg, msg_size);
    free(boxes);
    return st;
}

cm_status session_save(session *s, char *msg, size_t msg_size)
{
    char text[VIEW_TEXT];
    if (!s->have_view || !s->view_unsaved || s->damaged)
        return CM_OK;
    format_view(s, text, sizeof text);
    const cm_status st = cm_store_set_note(s->store, "note.explore.view", text, msg, msg_size);
    s->view_unsaved = st != CM_OK;
    return st;
}

/* A view kept within the periods of periodic coordinates: one wider than
 * a period is refused, one across the seam moved back inside (a pan stops
 * there: one period is the whole circle). */
static cm_status within_periods(const session *s, double *lo, double *hi, const char *verb,
                                char *msg, size_t msg_size)
{
    const cm_model *m = &s->model;
    for (int d = 0; d < s->view_dims; d++) {
        if (!cm_model_periodic(m, d))
            continue;
        const double from = m->period_lo[d], to = from + m->period[d];
        if (hi[d] - lo[d] > m->period[d] * (1 + 1e-12))
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "%s: the view would be %.9g wide in %s, more than its period %.9g "
                           "(%s is periodic, %.9g:%.9g): view at most one period",
                           verb, hi[d] - lo[d], cm_model_coord_name(m, d), m->period[d],
                           cm_model_coord_name(m, d), from, to);
        const double shift = lo[d] < from ? from - lo[d] : hi[d] > to ? to - hi[d] : 0;
        lo[d] += shift;
        hi[d] += shift;
    }
    return CM_OK;
}

cm_status session_move(session *s, const double *given_lo, const double *given_hi,
                       const int64_t *slice, const char *verb, session_work *done, char *msg,
                       size_t msg_size)
{
    double lo[2] = {given_lo[0], s->view_dims > 1 ? given_lo[1] : 0};
    double hi[2] = {given_hi[0], s->view_dims > 1 ? given_hi[1] : 0};
    memset(done, 0, sizeof *done);
    cm_status st = within_periods(s, lo, hi, verb, msg, msg_size);
    if (st == CM_OK)
        st = check_view(s, lo, hi, verb, msg, msg_size);
    if (st != CM_OK)
        return st;
    int64_t kept[CM_MAX_DIM];
    memcpy(kept, s->slice, sizeof kept);
    if (slice)
        memcpy(s->slice, slice, sizeof s->slice);
    cm_box box;
    view_box(s, lo, hi, &box);
    st = cover_box(s, &box, verb, done, msg, msg_size);
    if (st != CM_OK) {
        memcpy(s->slice, kept, sizeof kept);
        return st;
    }
    memcpy(s->lo, lo, sizeof s->lo);
    memcpy(s->hi, hi, sizeof s->hi);
    s->have_view = 1;
    s->view_unsaved = 1;
    /* with the cells it computed (written already), else when the session
     * ends: a file is not written before its cells have been read */
    return done->regions ? session_save(s, msg, msg_size) : CM_OK;
}

cm_status session_rect_box(const session *s, const double *lo, const double *hi, cm_box *box,
                           char *msg, size_t msg_size)
{
    memset(box, 0, sizeof *box);
    box->dim = s->dim;
    for (int d = 0; d < s->dim; d++)
        if (!(lo[d] < hi[d]) || !isfinite(lo[d]) || !isfinite(hi[d]))
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "the box needs finite LO < HI in each of the %d dimensions", s->dim);
    cm_rect_box(&s->c.lat, s->dim, lo, hi, box);
    return CM_OK;
}

cm_status session_add_box(session *s, const cm_box *box, session_work *done, char *msg,
                          size_t msg_size)
{
    memset(done, 0, sizeof *done);
    const cm_status st = cover_box(s, box, "add", done, msg, msg_size);
    return st == CM_OK && done->regions ? session_save(s, msg, msg_size) : st;
}

cm_status session_need_view(const session *s, const char *verb, char *msg, size_t msg_size)
{
    return s->have_view ? CM_OK
                        : cm_fail(CM_EINVAL, msg, msg_size,
                                  "%s: there is no view yet; start with `view X0:X1%s`", verb,
                                  s->view_dims > 1 ? " Y0:Y1" : "");
}

/* "at Z,W,..." of a view: the slice, in cells, inside the depth. */
cm_status session_slice(const session *s, const char *text, int64_t *slice, char *msg,
                        size_t msg_size)
{
    double v[CM_MAX_DIM];
    int n = 0;
    if (s->dim <= 2)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "view: `at` chooses a slice of models of more than two dimensions");
    if (!parse_doubles(text, v, &n, CM_MAX_DIM) || n != s->dim - 2)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "view: `at %s` needs %d number(s), one per "
                       "dimension from the third on",
                       text, s->dim - 2);
    for (int d = 2; d < s->dim; d++) {
        const double c = floor((v[d - 2] - s->c.lat.origin[d]) / s->c.lat.width[d]);
        if (!(c >= (double)s->depth_lo[d] && c < (double)s->depth_hi[d]))
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "view: %s = %s is outside the session's depth", cm_model_coord_name(&s->model, d),
                           CM_NUM(v[d - 2]));
        slice[d] = (int64_t)c;
    }
    return CM_OK;
}


/* ---- extend auto, and the journal of a script's run ------------------------ */

#define JOURNAL_NOTE "note.explore.journal"

/* Writes the journal's state: "script H line K step J tile LO:HI,..." (a
 * step's tile, before it is computed), "script H line K done" or "script
 * H complete". Nothing without a journal. */
static cm_status journal_write(session *s, const char *state, char *msg, size_t msg_size)
{
    char text[96 + CM_MAX_DIM * 48];
    if (!s->script_hash || s->damaged)
        return CM_OK;
    snprintf(text, sizeof text, "script %016llx %s", (unsigned long long)s->script_hash, state);
    return cm_store_set_note(s->store, JOURNAL_NOTE, text, msg, msg_size);
}

static cm_status journal_step(session *s, int step, const cm_box *tile, char *msg, size_t msg_size)
{
    char state[48 + CM_MAX_DIM * 48];
    size_t used = (size_t)snprintf(state, sizeof state, "line %ld step %d tile ", s->line, step);
    for (int d = 0; d < tile->dim && used < sizeof state; d++)
        used += (size_t)snprintf(state + used, sizeof state - used, "%s%lld:%lld", d ? "," : "",
                                 (long long)tile->lo[d], (long long)tile->hi[d]);
    return journal_write(s, state, msg, msg_size);
}

cm_status session_journal_begin(session *s, uint64_t script_hash, char *msg, size_t msg_size)
{
    char text[512], ignored[64];
    s->script_hash = script_hash;
    s->resume_line = 0;
    s->resume_step = 0;
    if (cm_store_get_note(s->store, JOURNAL_NOTE, text, sizeof text, ignored, sizeof ignored) !=
        CM_OK)
        return CM_OK; /* no run journaled yet */
    unsigned long long hash;
    long line;
    int step, at = 0;
    if (sscanf(text, "script %llx line %ld %n", &hash, &line, &at) != 2 || hash != script_hash ||
        line < 1)
        return CM_OK; /* another script, or this one's run went to its end */
    const char *rest = text + at;
    s->resume_line = line;
    if (sscanf(rest, "step %d tile %n", &step, &at) == 1 && step >= 1) {
        cm_box *b = &s->resume_tile;
        b->dim = s->c.lat.dim;
        const char *p = rest + at;
        for (int d = 0; d < b->dim; d++) {
            long long lo, hi;
            int used = 0;
            if (sscanf(p, "%lld:%lld%n", &lo, &hi, &used) != 2 || lo >= hi)
                return cm_fail(CM_EFORMAT, msg, msg_size,
                               "%s is damaged: its journal of explore runs says '%s'", s->path,
                               text);
            b->lo[d] = lo;
            b->hi[d] = hi;
            p += used + (p[used] == ',');
        }
        s->resume_step = step;
    }
    return CM_OK;
}

cm_status session_journal_end(session *s, char *msg, size_t msg_size)
{
    return journal_write(s, "complete", msg, msg_size);
}

/* A session's extension step: the tile journaled, then its uncovered
 * cells computed, and said. */
typedef struct session_extension {
    session *s;
    session_step_fn step_done;
    void *user;
} session_extension;

static cm_status session_tile(void *user, int k, const cm_extend_choice *choice, bool recorded,
                              double started, char *msg, size_t msg_size)
{
    const session_extension *x = user;
    session_step done;
    memset(&done, 0, sizeof done);
    cm_status st = journal_step(x->s, k, &choice->box, msg, msg_size);
    if (st == CM_OK)
        st = cover_box(x->s, &choice->box, "extend auto", &done.work, msg, msg_size);
    if (st != CM_OK)
        return st;
    done.step = k;
    done.tile = choice->box;
    done.recorded = recorded;
    done.escaping = choice->escaping;
    done.all_escaping = choice->all_escaping;
    done.work.seconds = cm_seconds() - started;
    if (x->step_done)
        x->step_done(x->user, &done);
    return CM_OK;
}

cm_status session_extend(session *s, const cm_box *tile, int steps, session_step_fn step_done,
                         void *user, session_extended *out, char *msg, size_t msg_size)
{
    memset(out, 0, sizeof *out);
    if (steps < 1 || steps > 1000)
        return cm_fail(CM_EINVAL, msg, msg_size, "extend auto: %d steps is not in 1..1000",
                       steps);
    cm_status st = tile ? CM_OK : session_need_view(s, "extend", msg, msg_size);
    if (st != CM_OK)
        return st;
    /* a resumed run: the extend lines before the one that stopped are done,
     * and that one goes on from its recorded step, whose tile it completes */
    const bool here = s->script_hash && s->line == s->resume_line;
    if (s->script_hash && (s->line < s->resume_line || (here && !s->resume_step))) {
        out->repeated = true;
        return CM_OK;
    }
    const int first = here ? s->resume_step : 1;
    s->resume_step = 0; /* resumed once */
    cm_box view;
    if (!tile)
        view_box(s, s->lo, s->hi, &view);
    const session_extension x = {s, step_done, user};
    int done = 0;
    out->stop[0] = '\0';
    st = project_extend_tiles(&s->c, tile ? tile : &view, NULL, first, steps, here ? &s->resume_tile : NULL,
                              session_tile, (void *)&x, &done, out->stop, sizeof out->stop, msg,
                              msg_size);
    out->stopped = out->stop[0] != '\0';
    if (st == CM_OK) {
        char state[48];
        snprintf(state, sizeof state, "line %ld done", s->line);
        st = journal_write(s, state, msg, msg_size);
    }
    return st;
}

/* ---- render, stats ------------------------------------------------------------ */

/* The cluster's groups (ids 1..ngroups) into a new *groups, the caller's
 * to free (also on failure). */
static cm_status read_groups(session *s, cm_group_info **groups, char *msg, size_t msg_size)
{
    uint64_t sink = 0;
    *groups = calloc((size_t)s->c.ngroups + 1, sizeof **groups);
    return *groups ? cm_store_groups(s->store, *groups, s->c.ngroups, &sink, msg, msg_size)
                   : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %u groups",
                             s->c.ngroups);
}

/* The cells of box, flattened, and the cluster's groups; with open
 * non-NULL, also the cells' open nodes (cm_cluster_flatten_open) into a
 * new *open, the caller's to free. */
static cm_status box_cells(session *s, const cm_box *box, cm_region *flat, uint32_t **open,
                           cm_group_info **groups, char *msg, size_t msg_size)
{
    cm_status st = read_groups(s, groups, msg, msg_size);
    if (st != CM_OK)
        return st;
    if (!s->resolve_cache)
        s->resolve_cache = cm_resolve_cache_new(); /* NULL: every node resolved */
    if (open) {
        *open = cm_cells_array((cm_box_cells(box) + 1) * sizeof **open);
        if (!*open)
            return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the view's cells");
    }
    return cm_cluster_flatten_cached(&s->c, box, s->resolve_cache, flat, open ? *open : NULL, msg,
                                     msg_size);
}

/* The shown layer of the view, as box_cells gives it. */
static cm_status shown_cells(session *s, cm_region *flat, uint32_t **open, cm_group_info **groups,
                             char *msg, size_t msg_size)
{
    cm_box box;
    shown_box(s, &box);
    return box_cells(s, &box, flat, open, groups, msg, msg_size);
}

cm_status session_labels(session *s, const cm_box *box, cm_region *flat, int32_t **labels,
                         cm_attractor_set *att, char *msg, size_t msg_size)
{
    memset(flat, 0, sizeof *flat);
    memset(att, 0, sizeof *att);
    *labels = NULL;
    cm_group_info *groups = NULL;
    uint32_t *open = NULL;
    cm_status st = box->dim == s->dim ? CM_OK
                                      : cm_fail(CM_EINVAL, msg, msg_size,
                                                "a box of %d dimensions for a model of %d",
                                                box->dim, s->dim);
    if (st == CM_OK)
        st = box_cells(s, box, flat, &open, &groups, msg, msg_size);
    if (st == CM_OK && !s->exit_memo)
        s->exit_memo = cm_exit_memo_new(); /* NULL: labels without it */
    if (st == CM_OK)
        st = part_labels(&s->model, &s->c, flat, open, groups, false, s->exit_memo, att, labels,
                         msg, msg_size);
    free(open);
    free(groups);
    if (st != CM_OK) {
        cm_region_free(flat);
        cm_attractors_free(att);
    }
    return st;
}

/* The shown cells, their groups and, by attractors, their labels
 * (part_labels; the exits met kept for the next render). */
static cm_status view_labels(session *s, bool by_attractors, cm_region *flat,
                             cm_group_info **groups, cm_attractor_set *att, int32_t **labels,
                             char *msg, size_t msg_size)
{
    uint32_t *open = NULL;
    cm_status st = shown_cells(s, flat, by_attractors ? &open : NULL, groups, msg, msg_size);
    if (st == CM_OK && by_attractors && !s->exit_memo)
        s->exit_memo = cm_exit_memo_new(); /* NULL: labels without it */
    if (st == CM_OK && by_attractors)
        st = part_labels(&s->model, &s->c, flat, open, *groups, false, s->exit_memo, att, labels,
                         msg, msg_size);
    free(open);
    return st;
}

/* Whether the view's labels can be kept between renders (cellmap/view_keep.h);
 * the keep, and the resolve cache it flattens through, made when first
 * needed. */
static bool kept_view_works(session *s)
{
    if (!s->c.keep_exits || s->c.resolved_cells || s->c.open_released)
        return false;
    if (!s->view_keep)
        s->view_keep = cm_view_keep_new(); /* NULL: labels afresh */
    if (!s->resolve_cache)
        s->resolve_cache = cm_resolve_cache_new(); /* NULL: every node resolved */
    return s->view_keep != NULL;
}

/* view_labels by attractors, from what the last render kept: flat gets
 * what the figure reads of the cells besides their labels; both are the
 * keep's (cm_view_keep_labels). */
static cm_status kept_view_labels(session *s, cm_region *flat, cm_group_info **groups,
                                  cm_attractor_set *att, int32_t **labels, char *msg,
                                  size_t msg_size)
{
    cm_box box;
    shown_box(s, &box);
    cm_status st = read_groups(s, groups, msg, msg_size);
    if (st == CM_OK)
        st = cm_attractors_find(&s->model, &s->c.lat, *groups, s->c.ngroups,
                                cm_cluster_cells_group, &s->c, NULL, att, msg, msg_size);
    if (st == CM_OK)
        st = cm_view_keep_labels(s->view_keep, &s->model, &s->c, s->resolve_cache, &box, NULL,
                                 att, labels, flat, msg, msg_size);
    return st;
}

cm_status session_render(session *s, png_opts *po, char *msg, size_t msg_size)
{
    const cm_file_use files[] = {{s->path, "the session's database", true, true},
                                 {po->path ? po->path : po->svg ? po->svg : po->pdf, "render",
                                  true, false},
                                 {po->palette_file, "the palette", false, false},
                                 {po->labels_file, "the labels file", false, false}};
    cm_status st = cm_files_apart(files, sizeof files / sizeof *files, msg, msg_size);
    if (st == CM_OK)
        st = session_need_view(s, "render", msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_region flat;
    cm_group_info *groups = NULL;
    memset(&flat, 0, sizeof flat);
    cm_attractor_set att;
    memset(&att, 0, sizeof att);
    int32_t *labels = NULL;
    const bool by_attractors = po->by == BY_ATTRACTORS;
    const bool kept = by_attractors && !figure_draws_steps(po) && kept_view_works(s);
    st = kept ? kept_view_labels(s, &flat, &groups, &att, &labels, msg, msg_size)
              : view_labels(s, by_attractors, &flat, &groups, &att, &labels, msg, msg_size);
    if (st == CM_OK && !s->gl && figure_needs_gl(po, &s->model))
        st = cm_gl_open(&s->gl, msg, msg_size);
    const basin_png png = {po,
                           &s->model,
                           &s->c.lat,
                           &flat,
                           groups,
                           {s->lo[0], s->lo[1]},
                           {s->hi[0], s->hi[1]},
                           s->gl,
                           po->by == BY_ATTRACTORS ? &att : NULL,
                           NULL,
                           labels,
                           &flat}; /* freed (or the keep's) after the figure */
    if (st == CM_OK)
        st = figure_write(&png, msg, msg_size);
    if (!kept) {
        cm_region_free(&flat);
        free(labels);
    }
    cm_attractors_free(&att);
    free(groups);
    return st;
}

cm_status session_figure(session *s, const png_opts *po, const double lo[2], const double hi[2],
                         char *msg, size_t msg_size)
{
    cm_store_info info;
    cm_box box;
    cm_status st = check_view(s, lo, hi, "figure", msg, msg_size);
    if (st == CM_OK)
        st = cm_store_read_info(s->store, &info, msg, msg_size);
    if (st != CM_OK)
        return st;
    view_box(s, lo, hi, &box);
    session_slice_box(s, &box);
    st = figure_check(po, &s->model, &s->c.lat, &box, msg, msg_size);
    return st == CM_OK ? figure_of_file(s->store, &info, &s->c, s->path, po, &box, lo, hi, NULL,
                                        NULL, msg, msg_size)
                       : st;
}

/* The view's cells by attractor label (cm_attractor_cell_labels, the same
 * labels render finds), the attractors found with every exit followed, so
 * that their basins are the cluster's. */
static cm_status count_by_attractors(session *s, const cm_region *flat, const cm_group_info *groups,
                                     cm_attractor_set *att, uint64_t **by_label, char *msg,
                                     size_t msg_size)
{
    int32_t *label = NULL;
    cm_status st =
        part_labels(&s->model, &s->c, flat, NULL, groups, true, NULL, att, &label, msg, msg_size);
    *by_label = st == CM_OK ? calloc((size_t)att->n + 3, sizeof **by_label) : NULL;
    if (st == CM_OK && !*by_label)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the attractors in view");
    for (uint64_t i = 0; st == CM_OK && i < flat->ncells; i++)
        (*by_label)[label[i] + 2]++;
    free(label);
    return st;
}

cm_status session_count(session *s, session_stats *v, char *msg, size_t msg_size)
{
    memset(v, 0, sizeof *v);
    cm_status st = session_need_view(s, "stats", msg, msg_size);
    if (st != CM_OK)
        return st;
    st = shown_cells(s, &v->flat, NULL, &v->groups, msg, msg_size);
    const cm_region *flat = &v->flat;
    v->in_view = st == CM_OK ? calloc((size_t)flat->ngroups + 2, sizeof *v->in_view) : NULL;
    if (st == CM_OK && !v->in_view)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the groups in view");
    if (st == CM_OK)
        st = count_by_attractors(s, flat, v->groups, &v->att, &v->by_label, msg, msg_size);
    if (st != CM_OK)
        return st;
    v->cells = flat->ncells;
    for (uint64_t i = 0; i < flat->ncells; i++) {
        if (flat->group[i] == CM_GROUP_NONE)
            v->missing++;
        else
            v->groups_in_view += v->in_view[flat->group[i]]++ == 0 && flat->group[i] != 0;
    }
    for (uint32_t k = 0; k < s->c.nregions; k++)
        v->cluster_cells += s->c.regions[k].r.ncells;
    cm_store_info info;
    if (cm_store_read_info(s->store, &info, msg, msg_size) == CM_OK)
        v->file_bytes = info.file_bytes;
    v->memory_bytes = cm_cluster_bytes(&s->c);
    v->resident_bytes = cm_cluster_resident_bytes(&s->c);
    v->view_bytes = cm_view_keep_bytes(s->view_keep) + cm_exit_memo_bytes(s->exit_memo) +
                    cm_resolve_cache_bytes(s->resolve_cache);
    return CM_OK;
}

void session_stats_free(session_stats *v)
{
    free(v->in_view);
    free(v->by_label);
    cm_attractors_free(&v->att);
    cm_region_free(&v->flat);
    free(v->groups);
    memset(v, 0, sizeof *v);
}

cm_status session_records(session *s, cm_store_info *info, char *msg, size_t msg_size)
{
    return cm_store_read_info(s->store, info, msg, msg_size);
}

void session_view_text(const session *s, char *out, size_t size) { format_view(s, out, size); }

void session_view_cells(const session *s, cm_box *box) { view_box(s, s->lo, s->hi, box); }

void session_shown_cells(const session *s, cm_box *box) { shown_box(s, box); }


/* ---- opening and closing ------------------------------------------------------ */

/* What opening a session works with, and how it reports a refusal. */
typedef struct opening {
    session *s;
    const session_options *o;
    session_opened *r;
    char *msg;
    size_t msg_size;
} opening;

static cm_status refuse(const opening *op, cm_status st, bool bad_options, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

static cm_status refuse(const opening *op, cm_status st, bool bad_options, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(op->msg, op->msg_size, fmt, ap);
    va_end(ap);
    op->r->bad_options = bad_options;
    return st;
}

/* The file's model, rebuilt from its name and parameters. */
static cm_status model_of_file(const opening *op, const cm_store_info *info)
{
    session *s = op->s;
    char msg[2048];
    s->models = op->o->mo.set; /* --model-lib's, and the file's own plugin */
    const cm_status st = model_of_store(info, &s->models, &s->model, msg, sizeof msg);
    if (st != CM_OK)
        return refuse(op, st, false, "%s: %s", s->path, msg);
    s->have_model = 1;
    return CM_OK;
}

static void format_depth(const session *s, char *out, size_t size)
{
    size_t used = 0;
    out[0] = 0;
    for (int d = 2; d < s->dim && used < size; d++)
        used += (size_t)snprintf(out + used, size - used, "%s%lld:%lld", d > 2 ? "," : "",
                                 (long long)s->depth_lo[d], (long long)s->depth_hi[d]);
}

/* The depth (cells of dimensions 3..) from the file's note, or the
 * cluster's bounds; the slice in its middle. */
static cm_status restore_depth(const opening *op)
{
    session *s = op->s;
    char text[512], msg[256];
    if (s->dim <= 2)
        return CM_OK;
    if (cm_store_get_note(s->store, "note.explore.depth", text, sizeof text, msg, sizeof msg) ==
        CM_OK) {
        char *p = text;
        for (int d = 2; d < s->dim; d++) {
            char *end;
            s->depth_lo[d] = strtoll(p, &end, 10);
            s->depth_hi[d] = *end == ':' ? strtoll(end + 1, &end, 10) : s->depth_lo[d];
            p = *end == ',' ? end + 1 : end;
        }
    } else if (s->c.nregions > 0) {
        cm_box bounds;
        cm_cluster_bounds(&s->c, &bounds);
        memcpy(s->depth_lo, bounds.lo, sizeof bounds.lo);
        memcpy(s->depth_hi, bounds.hi, sizeof bounds.hi);
    } else {
        return refuse(op, CM_EFORMAT, false,
                      "%s has no depth for dimensions 3.. (it was not made by explore)", s->path);
    }
    for (int d = 2; d < s->dim; d++) {
        if (s->depth_lo[d] >= s->depth_hi[d] || s->depth_lo[d] < -CM_WORLD_LIMIT ||
            s->depth_hi[d] > CM_WORLD_LIMIT)
            return refuse(op, CM_EFORMAT, false,
                          "%s is damaged: its depth note '%s' is not LO:HI,... cells of the world",
                          s->path, text);
        s->slice[d] = s->depth_lo[d] + (s->depth_hi[d] - s->depth_lo[d]) / 2;
    }
    return CM_OK;
}

/* The view saved by the last session, or the cluster's bounding box. */
static cm_status restore_view(const opening *op)
{
    session *s = op->s;
    char msg[256], slice[VIEW_TEXT];
    double lo[2], hi[2];
    const cm_status noted = project_view_note(s->store, s->view_dims, lo, hi, slice, sizeof slice);
    if (noted == CM_EFORMAT)
        return refuse(op, CM_EFORMAT, false, "%s is damaged: its view note is not a view",
                      s->path);
    if (noted == CM_OK) {
        if (check_view(s, lo, hi, "the view note", msg, sizeof msg) != CM_OK)
            return refuse(op, CM_EFORMAT, false, "%s is damaged: %s", s->path, msg);
        memcpy(s->lo, lo, sizeof lo);
        memcpy(s->hi, hi, sizeof hi);
        if (slice[0] && session_slice(s, slice, s->slice, msg, sizeof msg) != CM_OK)
            return refuse(op, CM_EFORMAT, false, "%s is damaged: its view note: %s", s->path,
                          msg);
        s->have_view = 1;
    } else if (s->c.nregions > 0) {
        cm_box b;
        cm_cluster_bounds(&s->c, &b);
        cm_box_rect(&s->c.lat, &b, s->view_dims, s->lo, s->hi);
        s->have_view = 1;
    }
    return CM_OK;
}

/* The lattice of the options (--cell-size, --origin) for a model. */
static cm_status options_lattice(const opening *op, int dim, cm_lattice *lat)
{
    const session_options *o = op->o;
    char msg[256];
    memset(lat, 0, sizeof *lat);
    lat->dim = dim;
    if (o->n_cell_size != dim)
        return refuse(op, CM_EINVAL, true, "the cell size needs %d width(s) DX[,DY...] for this "
                      "model", dim);
    if (o->n_origin && o->n_origin != dim)
        return refuse(op, CM_EINVAL, true, "the origin needs %d coordinate(s) for this model", dim);
    for (int d = 0; d < dim; d++) {
        lat->width[d] = o->cell_size[d];
        lat->origin[d] = o->n_origin ? o->origin[d] : 0.0;
    }
    if (cm_lattice_check(lat, msg, sizeof msg) != CM_OK)
        return refuse(op, CM_EINVAL, true, "the cell size or origin: %s", msg);
    return CM_OK;
}

/* Options given for an existing file must describe it. */
static cm_status check_same(const opening *op, const cm_store_info *info)
{
    const session *s = op->s;
    const session_options *o = op->o;
    cm_model m;
    char msg[512], params[4096];
    if (o->mo.name) {
        const cm_status st = model_spec_build(&o->mo, &m, msg, sizeof msg);
        if (st != CM_OK)
            return refuse(op, st, false, "%s", msg);
        cm_params_json(&m.values, params, sizeof params);
        const int differs = strcmp(m.name, info->model) != 0 || strcmp(params, info->params) != 0;
        cm_model_release(&m);
        if (differs)
            return refuse(op, CM_EINVAL, false,
                          "%s holds model %s; give no model or parameters to go on with it, or choose "
                          "another file",
                          s->path, info->model);
    }
    cm_lattice lat;
    if (o->n_cell_size && (options_lattice(op, info->lattice.dim, &lat) != CM_OK ||
                           !cm_lattice_equal(&lat, &info->lattice)))
        return refuse(op, CM_EINVAL, false,
                      "%s has another lattice; give no cell size or origin to go on with it",
                      s->path);
    if (o->max_steps && o->max_steps != s->max_steps)
        return refuse(op, CM_EINVAL, false,
                      "%s was computed with other max steps; give none to go on with the "
                      "file's",
                      s->path);
    return CM_OK;
}

/* What project_resume asks a session (fits_session). */
typedef struct session_fit {
    const opening *op;
    cm_status refused; /* a refusal already said in op->msg */
} session_fit;

/* A project_fits_fn: the file's model rebuilds, and the options agree with it. */
static cm_status fits_session(void *user, const cm_store_info *info, const cm_model **model,
                              char *msg, size_t msg_size)
{
    session_fit *f = user;
    session *s = f->op->s;
    s->max_steps = 1; /* a plan without max-steps; 0 (a solve's default) is 1 too */
    if (project_plan_int(info->plan, "max-steps", 0, PROJECT_MAX_STEPS, &s->max_steps) ==
        CM_EFORMAT)
        f->refused = refuse(f->op, CM_EFORMAT, false,
                            "%s is damaged: its plan '%s' has no valid max-steps", s->path,
                            info->plan);
    if (s->max_steps < 1)
        s->max_steps = 1;
    if (f->refused == CM_OK)
        f->refused = model_of_file(f->op, info);
    if (f->refused == CM_OK)
        f->refused = check_same(f->op, info);
    if (f->refused != CM_OK)
        return cm_fail(f->refused, msg, msg_size, "refused"); /* said in op->msg */
    *model = &s->model;
    return CM_OK;
}

static cm_status open_existing(const opening *op)
{
    session *s = op->s;
    char msg[1024];
    cm_store_info info;
    session_fit fit = {op, CM_OK};
    const cm_status st = project_resume(s->path, fits_session, &fit, &s->store, &info, &s->c,
                                        &op->r->upgraded_from, msg, sizeof msg);
    if (st != CM_OK)
        return fit.refused != CM_OK ? fit.refused : refuse(op, st, false, "%s", msg);
    s->dim = info.lattice.dim;
    s->view_dims = s->dim < 2 ? s->dim : 2;
    const cm_status depth = restore_depth(op);
    return depth != CM_OK ? depth : restore_view(op);
}

/* The depth of a new file's models of more than two dimensions: --depth
 * or the model's example region. */
static cm_status new_depth(const opening *op)
{
    session *s = op->s;
    const session_options *o = op->o;
    const cm_model_entry *e = cm_model_set_find(&o->mo.set, s->model.name, NULL);
    const char *text = o->depth_text;
    double lo[CM_MAX_DIM], hi[CM_MAX_DIM];
    int n = 0;
    if (s->dim <= 2)
        return CM_OK;
    if (!text && e && e->region) {
        if (!parse_ranges(e->region, lo, hi, &n, CM_MAX_DIM) || n != s->dim)
            return refuse(op, CM_EINVAL, false, "model %s: bad example region %s",
                          s->model.name, e->region);
    } else if (!text || !parse_ranges(text, lo + 2, hi + 2, &n, CM_MAX_DIM - 2) ||
               n != s->dim - 2) {
        return refuse(op, CM_EINVAL, true,
                      "model %s has %d dimensions: the depth LO:HI,... gives the ranges of "
                      "dimensions 3..%d that every view computes",
                      s->model.name, s->dim, s->dim);
    }
    for (int d = 2; d < s->dim; d++) {
        s->depth_lo[d] = cm_lattice_border(&s->c.lat, d, lo[d], 0);
        s->depth_hi[d] = cm_lattice_border(&s->c.lat, d, hi[d], 1);
        s->slice[d] = s->depth_lo[d] + (s->depth_hi[d] - s->depth_lo[d]) / 2;
    }
    char depth[512], msg[512];
    format_depth(s, depth, sizeof depth);
    const cm_status st = cm_store_set_note(s->store, "note.explore.depth", depth, msg, sizeof msg);
    return st == CM_OK ? CM_OK : refuse(op, st, false, "%s", msg);
}

static cm_status create_new(const opening *op)
{
    session *s = op->s;
    const session_options *o = op->o;
    char msg[1024];
    cm_lattice lat;
    if (!o->mo.name)
        return refuse(op, CM_EINVAL, true,
                      "%s does not exist; a new file needs a model (and its parameters) and "
                      "the size of its cells (and their origin)",
                      s->path);
    cm_status st = model_spec_build(&o->mo, &s->model, msg, sizeof msg);
    if (st != CM_OK)
        return refuse(op, st, true, "%s", msg);
    s->have_model = 1;
    s->dim = s->model.dim;
    s->view_dims = s->dim < 2 ? s->dim : 2;
    s->max_steps = o->max_steps ? o->max_steps : 1;
    if ((st = options_lattice(op, s->dim, &lat)) != CM_OK)
        return st;
    if ((st = cm_model_check_lattice(&s->model, &lat, msg, sizeof msg)) != CM_OK)
        return refuse(op, st, true, "the cell size or origin: %s", msg);
    char plan[64];
    snprintf(plan, sizeof plan, "explore max-steps %d", s->max_steps);
    const cm_model_lib *lib = model_spec_lib(&o->mo, s->model.name);
    st = project_create(s->path, &s->model, lib, &lat, o->command, plan, &s->store, &s->c, msg,
                        sizeof msg);
    if (st != CM_OK)
        return refuse(op, st, false, "%s", msg);
    return new_depth(op);
}

void session_keep_freed(void)
{
    (void)mallopt(M_MMAP_THRESHOLD, 32 << 20);
    (void)mallopt(M_TRIM_THRESHOLD, 64 << 20);
}

cm_status session_open(session *s, const session_options *o, session_opened *opened, char *msg,
                       size_t msg_size)
{
    struct stat sb;
    memset(s, 0, sizeof *s);
    memset(opened, 0, sizeof *opened);
    s->path = o->path;
    s->threads = o->threads;
    s->max_new_cells = o->max_new_cells ? o->max_new_cells : MAX_NEW_CELLS;
    /* under --mem, one step computes no more than its cell arrays (12 bytes
     * a cell) hold: a region being solved is resident whole (the default
     * budget bounds what is kept, not what one step may compute) */
    if (o->mem && o->mem / 12 < s->max_new_cells)
        s->max_new_cells = o->mem / 12 > 4096 ? o->mem / 12 : 4096;
    s->mem_given = o->mem != 0;
    const opening op = {s, o, opened, msg, msg_size};
    const cm_status st = stat(o->path, &sb) == 0 ? open_existing(&op) : create_new(&op);
    if (st != CM_OK)
        return st;
    s->c.threads = o->threads;
    s->c.mem_budget = o->mem ? o->mem : project_default_mem();
    return CM_OK;
}

/* The system's attractors of the cluster into the file, when it grew (or
 * holds none: a file of an older format, a killed session). */
static cm_status save_attractors(session *s, char *msg, size_t msg_size)
{
    cm_attractor_set att;
    const int dim = s->c.lat.dim;
    if (s->damaged || s->c.nregions == 0)
        return CM_OK;
    if (!s->grew) { /* the file's own groups: what it stores is current, or damaged */
        const cm_status stored =
            cm_store_check_attractors(s->store, dim, s->c.ngroups, msg, msg_size);
        if (stored == CM_EFORMAT)
            s->damaged = 1; /* not written again */
        if (stored != CM_ENOTFOUND)
            return stored;
    }
    cm_group_info *groups = NULL;
    cm_status st = read_groups(s, &groups, msg, msg_size);
    memset(&att, 0, sizeof att);
    cm_attractor_options used;
    cm_attractor_defaults(&s->model, NULL, &used);
    cluster_ends ends;
    memset(&ends, 0, sizeof ends);
    if (st == CM_OK)
        st = cluster_ends_open(&ends, &s->c, msg, msg_size);
    ends.cc.spent = &ends.exits; /* nothing reads them after: the set takes their cells */
    if (st == CM_OK)
        st = cm_cluster_attractors(&s->model, &ends.cc, groups, NULL, &att, msg, msg_size);
    if (st == CM_OK)
        st = cm_store_put_attractors(s->store, &att, &used, dim, msg, msg_size);
    s->grew = st != CM_OK;
    cluster_ends_close(&ends);
    cm_attractors_free(&att);
    free(groups);
    return st;
}

cm_status session_close(session *s, char *msg, size_t msg_size)
{
    cm_status st = s->store ? save_attractors(s, msg, msg_size) : CM_OK;
    if (st == CM_OK && s->store)
        st = session_save(s, msg, msg_size);
    const cm_status closed = cm_store_close(s->store, msg, msg_size);
    s->store = NULL;
    cm_cluster_free(&s->c);
    cm_gl_close(s->gl);
    s->gl = NULL;
    cm_exit_memo_free(s->exit_memo);
    s->exit_memo = NULL;
    cm_resolve_cache_free(s->resolve_cache);
    s->resolve_cache = NULL;
    cm_view_keep_free(s->view_keep);
    s->view_keep = NULL;
    if (s->have_model)
        cm_model_release(&s->model);
    s->have_model = 0;
    return st != CM_OK ? st : closed;
}
