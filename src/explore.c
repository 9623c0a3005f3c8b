#include "src/explore.h"

#include "cellmap/clock.h"
#include "lib/json.h"

#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "cellmap/cover.h"
#include "cellmap/extend.h"
#include "cellmap/output.h"
#include "models/registry.h"
#include "render/figure.h"
#include "lib/attractor_report.h"
#include "src/figure_opts.h"
#include "src/commands.h"
#include "lib/project.h"

const char session_help[] =
    "  view X0:X1 [Y0:Y1] [at Z[,W...]]   look at this box of state space (and, for\n"
    "                                     models of more than two dimensions, the slice\n"
    "                                     through Z, W, ...); X0:X1,Y0:Y1 as --region\n"
    "                                     writes it works too\n"
    "  pan left|right|up|down AMOUNT      move the view by 25% (of the view), 120c (cells)\n"
    "                                     or a length in state coordinates\n"
    "  zoom FACTOR                        2: twice as close, 0.5: twice as far (about the\n"
    "                                     centre)\n"
    "  goto X [Y]                         centre the view on a point\n"
    "  extend auto [N]                    N times (default 1), add the tile of the view's\n"
    "                                     size where the most sequences escape (4.6.4)\n"
    "  render FILE.png|FILE.svg [WxH]     the view as a basin image (default: a pixel\n"
    "                                     per cell, at most 4096); --layers, --png-mode,\n"
    "                                     --palette, --labels, --min-basin, --legend\n"
    "                                     as `cellmap render` takes them\n"
    "  stats [--json]                     groups and attractors in view, cells, memory, disk\n"
    "  export --groups|--cells|--flat ... as `cellmap export` (--window: the view)\n"
    "  save                               save the view (joins are saved as they happen)\n"
    "  quit                               end the session\n"
    "  help                               this list\n";

/* By default a command may compute at most this many new cells (12 bytes each). */
#define MAX_NEW_CELLS (UINT64_C(1) << 28)
enum { MAX_TOKENS = 24, VIEW_TEXT = 512 };

/* ---- the view ------------------------------------------------------------ */

/* The cells the view touches: dimensions 0 and 1 from the view, the others
 * the session's depth. */
static void view_box(const session *s, const double *lo, const double *hi, cm_box *box)
{
    const cm_lattice *lat = &s->c.lat;
    memset(box, 0, sizeof *box);
    box->dim = s->dim;
    for (int d = 0; d < s->dim; d++) {
        if (d < s->view_dims) {
            box->lo[d] = cm_lattice_border(lat, d, lo[d], 0);
            box->hi[d] = cm_lattice_border(lat, d, hi[d], 1);
        } else {
            box->lo[d] = s->depth_lo[d];
            box->hi[d] = s->depth_hi[d];
        }
    }
}

/* The one layer of the view's box that is drawn (the slice). */
static void shown_box(const session *s, cm_box *box)
{
    view_box(s, s->lo, s->hi, box);
    for (int d = 2; d < s->dim; d++) {
        box->lo[d] = s->slice[d];
        box->hi[d] = s->slice[d] + 1;
    }
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

typedef struct computed {
    uint64_t cells;
    uint32_t regions, new_groups, straddling, affected;
    double seconds;
} computed;

/* Solves the boxes as new regions and joins them, one commit per join. */
static cm_status compute_boxes(session *s, const cm_box *boxes, uint32_t n, computed *done,
                               char *msg, size_t msg_size)
{
    const cm_scm_options opt = {.max_steps = s->max_steps,
                                .threads = s->threads,
                                .record_exits = 1};
    cm_join_stats stats;
    const double t0 = cm_seconds();
    cm_status st = cm_cluster_solve_boxes(&s->c, &s->model, boxes, n, &opt, cm_store_commit_join,
                                          s->store, &stats, msg, msg_size);
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
static cm_status cover_box(session *s, const cm_box *box, const char *verb, computed *done,
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
                     s->mem_given ? " (what --mem holds, 12 bytes a cell)" : "",
                     s->mem_given ? ", or give a larger --mem" : "");
    if (st == CM_OK && n > 0)
        st = compute_boxes(s, boxes, n, done, msg, msg_size);
    free(boxes);
    return st;
}

/* Writes the view to the file if it changed since it was last written. A
 * file found damaged is never written again. */
static cm_status save_view(session *s, char *msg, size_t msg_size)
{
    char text[VIEW_TEXT];
    if (!s->have_view || !s->view_unsaved || s->damaged)
        return CM_OK;
    format_view(s, text, sizeof text);
    const cm_status st = cm_store_set_note(s->store, "note.explore.view", text, msg, msg_size);
    s->view_unsaved = st != CM_OK;
    return st;
}

static void report(const session *s, const char *what, const computed *done)
{
    if (!s->out)
        return;
    char view[VIEW_TEXT];
    format_view(s, view, sizeof view);
    fprintf(s->out, "%s: view %s; ", what, view);
    if (done->regions == 0)
        fprintf(s->out, "nothing new to compute\n");
    else
        fprintf(s->out,
                "computed %llu cells in %u new region%s, joined (%u region%s resolved again), "
                "%u new group%s (%u across borders); %.1f ms\n",
                (unsigned long long)done->cells, done->regions, done->regions == 1 ? "" : "s",
                done->affected, done->affected == 1 ? "" : "s", done->new_groups,
                done->new_groups == 1 ? "" : "s", done->straddling, 1e3 * done->seconds);
    fflush(s->out);
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

/* Moves the view to lo..hi and computes what it uncovers. */
static cm_status move_view(session *s, const double *given_lo, const double *given_hi,
                           const char *what, char *msg, size_t msg_size)
{
    double lo[2] = {given_lo[0], s->view_dims > 1 ? given_lo[1] : 0};
    double hi[2] = {given_hi[0], s->view_dims > 1 ? given_hi[1] : 0};
    cm_status st = within_periods(s, lo, hi, what, msg, msg_size);
    if (st == CM_OK)
        st = check_view(s, lo, hi, what, msg, msg_size);
    cm_box box;
    computed done = {0};
    if (st != CM_OK)
        return st;
    view_box(s, lo, hi, &box);
    st = cover_box(s, &box, what, &done, msg, msg_size);
    if (st != CM_OK)
        return st;
    memcpy(s->lo, lo, sizeof s->lo);
    memcpy(s->hi, hi, sizeof s->hi);
    s->have_view = 1;
    s->view_unsaved = 1;
    /* with the cells it computed (written already), else when the session
     * ends: a file is not written before its cells have been read */
    st = done.regions ? save_view(s, msg, msg_size) : CM_OK;
    if (st == CM_OK)
        report(s, what, &done);
    return st;
}

/* ---- parsing --------------------------------------------------------------- */

/* Splits a line into words ("double quotes" keep spaces); drops a # comment. */
static int tokenize(char *line, char **tokens, int max, char *msg, size_t msg_size)
{
    int n = 0;
    char *p = line;
    for (;;) {
        while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')
            p++;
        if (!*p || *p == '#')
            return n;
        if (n == max) {
            cm_fail(CM_EINVAL, msg, msg_size, "too many words (at most %d)", max);
            return -1;
        }
        if (*p == '"') {
            tokens[n++] = ++p;
            while (*p && *p != '"')
                p++;
            if (!*p) {
                cm_fail(CM_EINVAL, msg, msg_size, "a \" is not closed");
                return -1;
            }
        } else {
            tokens[n++] = p;
            while (*p && *p != ' ' && *p != '\t' && *p != '\r' && *p != '\n')
                p++;
        }
        if (*p)
            *p++ = 0;
    }
}

static cm_status need_view(const session *s, const char *verb, char *msg, size_t msg_size)
{
    return s->have_view ? CM_OK
                        : cm_fail(CM_EINVAL, msg, msg_size,
                                  "%s: there is no view yet; start with `view X0:X1%s`", verb,
                                  s->view_dims > 1 ? " Y0:Y1" : "");
}

static cm_status words(int n, int lo, int hi, const char *usage, char *msg, size_t msg_size)
{
    return n >= lo && n <= hi ? CM_OK : cm_fail(CM_EINVAL, msg, msg_size, "usage: %s", usage);
}

/* "at Z,W,..." of a view: the slice, in cells, inside the depth. */
static cm_status parse_slice(session *s, const char *text, int64_t *slice, char *msg,
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
                           "view: %s = %s is outside the session's depth (--depth)", cm_model_coord_name(&s->model, d),
                           CM_NUM(v[d - 2]));
        slice[d] = (int64_t)c;
    }
    return CM_OK;
}

/* The view's ranges from words t[0..]: "X0:X1 Y0:Y1", or as --region
 * gives them, "X0:X1,Y0:Y1". *used receives the words taken. */
static cm_status parse_view_ranges(const session *s, char **t, int n, double *lo, double *hi,
                                   int *used, char *msg, size_t msg_size)
{
    const int ranges = s->view_dims;
    int count = 0;
    if (ranges > 1 && n >= 1 && strchr(t[0], ',')) {
        *used = 1;
        if (!parse_ranges(t[0], lo, hi, &count, ranges) || count != ranges)
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "view: '%s' is not X0:X1,Y0:Y1 with X0 < X1, Y0 < Y1", t[0]);
        return CM_OK;
    }
    *used = ranges;
    if (n < ranges)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "usage: view X0:X1 Y0:Y1 (or X0:X1,Y0:Y1): a range per dimension");
    for (int d = 0; d < ranges; d++)
        if (!parse_ranges(t[d], &lo[d], &hi[d], &count, 1) || count != 1)
            return cm_fail(CM_EINVAL, msg, msg_size, "view: '%s' is not LO:HI with LO < HI", t[d]);
    return CM_OK;
}

static cm_status cmd_view(session *s, char **t, int n, char *msg, size_t msg_size)
{
    const char *usage = s->view_dims > 1 ? "view X0:X1 Y0:Y1 (or X0:X1,Y0:Y1)" : "view X0:X1";
    double lo[2] = {0, 0}, hi[2] = {0, 0};
    int64_t slice[CM_MAX_DIM];
    memcpy(slice, s->slice, sizeof slice);
    int used = 0;
    cm_status st = words(n, 2, 2 + s->view_dims + 2, usage, msg, msg_size);
    if (st == CM_OK)
        st = parse_view_ranges(s, t + 1, n - 1, lo, hi, &used, msg, msg_size);
    if (st == CM_OK && n != 1 + used && (n != 3 + used || strcmp(t[1 + used], "at") != 0))
        st = cm_fail(CM_EINVAL, msg, msg_size, "usage: %s [at Z,...]", usage);
    if (st == CM_OK && n == 3 + used)
        st = parse_slice(s, t[2 + used], slice, msg, msg_size);
    if (st != CM_OK)
        return st;
    memcpy(s->slice, slice, sizeof slice);
    return move_view(s, lo, hi, "view", msg, msg_size);
}

/* AMOUNT of a pan along dimension d: "25%", "120c" or a length. */
static cm_status parse_amount(const session *s, const char *text, int d, double *out, char *msg,
                              size_t msg_size)
{
    char number[64];
    const size_t len = strlen(text);
    double v = 0, unit = 1;
    if (len >= sizeof number)
        return cm_fail(CM_EINVAL, msg, msg_size, "pan: the amount '%.32s...' is too long", text);
    snprintf(number, sizeof number, "%s", text);
    if (len > 1 && text[len - 1] == '%') {
        number[len - 1] = 0;
        unit = (s->hi[d] - s->lo[d]) / 100;
    } else if (len > 1 && text[len - 1] == 'c') {
        number[len - 1] = 0;
        unit = s->c.lat.width[d];
    }
    if (!parse_double(number, &v) || !(v > 0) || !isfinite(v * unit))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "pan: '%s' is not a positive amount: 25%% (of the view), 120c (cells) or "
                       "a length",
                       text);
    *out = v * unit;
    return CM_OK;
}

static cm_status cmd_pan(session *s, char **t, int n, char *msg, size_t msg_size)
{
    static const char *const dirs[] = {"left", "right", "down", "up"};
    cm_status st = words(n, 3, 3, "pan left|right|up|down AMOUNT", msg, msg_size);
    int dir = -1;
    for (int k = 0; k < 4 && st == CM_OK; k++)
        if (strcmp(t[1], dirs[k]) == 0)
            dir = k;
    if (st == CM_OK && dir < 0)
        st = cm_fail(CM_EINVAL, msg, msg_size, "pan: '%s' is not left, right, up or down", t[1]);
    if (st == CM_OK && dir >= 2 && s->view_dims < 2)
        st = cm_fail(CM_EINVAL, msg, msg_size, "pan %s: a one-dimensional view pans left or right",
                     t[1]);
    if (st == CM_OK)
        st = need_view(s, "pan", msg, msg_size);
    const int d = dir / 2;
    double amount = 0;
    if (st == CM_OK)
        st = parse_amount(s, t[2], d, &amount, msg, msg_size);
    if (st != CM_OK)
        return st;
    double lo[2], hi[2];
    memcpy(lo, s->lo, sizeof lo);
    memcpy(hi, s->hi, sizeof hi);
    const double shift = dir % 2 ? amount : -amount;
    lo[d] += shift;
    hi[d] += shift;
    char what[96];
    snprintf(what, sizeof what, "pan %s %s", t[1], t[2]);
    return move_view(s, lo, hi, what, msg, msg_size);
}

static cm_status cmd_zoom(session *s, char **t, int n, char *msg, size_t msg_size)
{
    double factor = 0;
    cm_status st = words(n, 2, 2, "zoom FACTOR (2: closer, 0.5: farther)", msg, msg_size);
    if (st == CM_OK && (!parse_double(t[1], &factor) || !(factor > 0) || !isfinite(factor)))
        st = cm_fail(CM_EINVAL, msg, msg_size, "zoom: '%s' is not a positive factor", t[1]);
    if (st == CM_OK)
        st = need_view(s, "zoom", msg, msg_size);
    if (st != CM_OK)
        return st;
    double lo[2] = {0, 0}, hi[2] = {0, 0};
    for (int d = 0; d < s->view_dims; d++) {
        const double mid = 0.5 * (s->lo[d] + s->hi[d]), half = 0.5 * (s->hi[d] - s->lo[d]) / factor;
        lo[d] = mid - half;
        hi[d] = mid + half;
    }
    char what[96];
    snprintf(what, sizeof what, "zoom %s", t[1]);
    return move_view(s, lo, hi, what, msg, msg_size);
}

static cm_status cmd_goto(session *s, char **t, int n, char *msg, size_t msg_size)
{
    const char *usage = s->view_dims > 1 ? "goto X Y" : "goto X";
    cm_status st = words(n, 1 + s->view_dims, 1 + s->view_dims, usage, msg, msg_size);
    if (st == CM_OK)
        st = need_view(s, "goto", msg, msg_size);
    double lo[2] = {0, 0}, hi[2] = {0, 0};
    for (int d = 0; d < s->view_dims && st == CM_OK; d++) {
        double x;
        if (!parse_double(t[1 + d], &x) || !isfinite(x)) {
            st = cm_fail(CM_EINVAL, msg, msg_size, "goto: '%s' is not a number", t[1 + d]);
            break;
        }
        const double half = 0.5 * (s->hi[d] - s->lo[d]);
        lo[d] = x - half;
        hi[d] = x + half;
    }
    return st == CM_OK ? move_view(s, lo, hi, "goto", msg, msg_size) : st;
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
    if (s->out) {
        if (s->resume_step)
            fprintf(s->out, "resuming this script's run that stopped in line %ld (extend auto, "
                            "step %d): extensions done before are not repeated\n",
                    s->resume_line, s->resume_step);
        else
            fprintf(s->out, "resuming this script's run that stopped after line %ld: "
                            "extensions done before are not repeated\n",
                    s->resume_line);
    }
    return CM_OK;
}

cm_status session_journal_end(session *s, char *msg, size_t msg_size)
{
    return journal_write(s, "complete", msg, msg_size);
}

/* One step: the tile the cluster's escaping sequences lead to most
 * (given: a resumed step's recorded tile), journaled, then computed. */
static cm_status extend_step(session *s, const cm_box *tile, int step, const cm_box *given,
                             char *msg, size_t msg_size)
{
    cm_extend_choice choice;
    memset(&choice, 0, sizeof choice);
    computed done = {0};
    const double t0 = cm_seconds();
    cm_status st = CM_OK;
    if (given)
        choice.box = *given;
    else
        st = cm_extend_choose(&s->c, tile, NULL, &choice, msg, msg_size);
    if (st == CM_OK)
        st = journal_step(s, step, &choice.box, msg, msg_size);
    if (st == CM_OK)
        st = cover_box(s, &choice.box, "extend auto", &done, msg, msg_size);
    if (st != CM_OK)
        return st;
    if (s->out) {
        char box[CM_MAX_DIM * 64], where[128] = "recorded before the interruption";
        cm_box_text(&s->c.lat, &choice.box, box, sizeof box);
        if (!given)
            snprintf(where, sizeof where, "where %llu of the %llu escaping sequences go",
                     (unsigned long long)choice.escaping, (unsigned long long)choice.all_escaping);
        fprintf(s->out,
                "extend auto %d: tile %s, %s; computed %llu cells in %u new region%s, %u new "
                "group%s (%u across borders); %.1f ms\n",
                step, box, where, (unsigned long long)done.cells, done.regions,
                done.regions == 1 ? "" : "s", done.new_groups, done.new_groups == 1 ? "" : "s",
                done.straddling, 1e3 * (cm_seconds() - t0));
        fflush(s->out);
    }
    return CM_OK;
}

static cm_status cmd_extend(session *s, char **t, int n, char *msg, size_t msg_size)
{
    int64_t steps = 1;
    cm_status st = words(n, 2, 3, "extend auto [N]", msg, msg_size);
    if (st == CM_OK && strcmp(t[1], "auto") != 0)
        st = cm_fail(CM_EINVAL, msg, msg_size, "usage: extend auto [N] (not '%s')", t[1]);
    if (st == CM_OK && n == 3 && (!parse_int64(t[2], &steps) || steps < 1 || steps > 1000))
        st = cm_fail(CM_EINVAL, msg, msg_size, "extend auto: '%s' must be an integer in 1..1000",
                     t[2]);
    if (st == CM_OK)
        st = need_view(s, "extend", msg, msg_size);
    if (st != CM_OK)
        return st;
    /* a resumed run: the extend lines before the one that stopped are done,
     * and that one goes on from its recorded step, whose tile it completes */
    const bool here = s->script_hash && s->line == s->resume_line;
    if (s->script_hash && (s->line < s->resume_line || (here && !s->resume_step))) {
        if (s->out)
            fprintf(s->out, "extend auto: done in the run that stopped; not repeated\n");
        return CM_OK;
    }
    const int64_t first = here ? s->resume_step : 1;
    s->resume_step = 0; /* resumed once */
    cm_box tile;
    view_box(s, s->lo, s->hi, &tile);
    for (int64_t k = first; k <= steps && st == CM_OK; k++) {
        const cm_box *given = here && k == first ? &s->resume_tile : NULL;
        st = extend_step(s, &tile, (int)k, given, msg, msg_size);
        if (st == CM_ENOTFOUND) { /* nothing escapes next to the cluster: done, not an error */
            if (s->out)
                fprintf(s->out, "extend auto: stopped, %s\n", msg);
            st = CM_OK;
            break;
        }
    }
    if (st == CM_OK) {
        char state[48];
        snprintf(state, sizeof state, "line %ld done", s->line);
        st = journal_write(s, state, msg, msg_size);
    }
    return st;
}

/* ---- render, stats, export, save --------------------------------------------- */

/* The shown layer of the view, flattened, and the cluster's groups. */
static cm_status shown_cells(session *s, cm_region *flat, cm_group_info **groups, char *msg,
                             size_t msg_size)
{
    cm_box box;
    uint64_t sink = 0;
    shown_box(s, &box);
    *groups = calloc((size_t)s->c.ngroups + 1, sizeof **groups);
    if (!*groups)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %u groups", s->c.ngroups);
    cm_status st = cm_store_groups(s->store, *groups, s->c.ngroups, &sink, msg, msg_size);
    if (st == CM_OK)
        st = cm_cluster_flatten(&s->c, &box, flat, msg, msg_size);
    return st;
}

/* The words after "render FILE.png": [WIDTHxHEIGHT] [--layers L,...]
 * [--png-mode rgb|indexed], as solve's options. */
static cm_status render_words(char **t, int n, png_opts *po, char *msg, size_t msg_size)
{
    for (int k = 2; k < n; k++) {
        int64_t wh[2];
        int count = 0;
        char bad[64];
        const bool has_value = k + 1 < n;
        if (strcmp(t[k], "--layers") == 0 && has_value) {
            if (!parse_layers(t[++k], &po->layers, bad, sizeof bad))
                return cm_fail(CM_EINVAL, msg, msg_size,
                               "render: unknown layer '%s' (use basin, steps, attractors, "
                               "overlays, axes, legend, title or all)",
                               bad);
        } else if (strcmp(t[k], "--png-mode") == 0 && has_value) {
            if (!parse_png_mode(t[++k], &po->indexed))
                return cm_fail(CM_EINVAL, msg, msg_size, "render: '%s' must be rgb or indexed",
                               t[k]);
        } else if (strcmp(t[k], "--by") == 0 && has_value) {
            const char *by = t[++k];
            if (strcmp(by, "groups") != 0 && strcmp(by, "attractors") != 0)
                return cm_fail(CM_EINVAL, msg, msg_size,
                               "render: --by '%s' must be attractors or groups", by);
            po->by = strcmp(by, "groups") == 0 ? BY_GROUPS : BY_ATTRACTORS;
        } else if (strcmp(t[k], "--palette") == 0 && has_value) {
            char why[400];
            if (!png_opts_palette(t[++k], po, why, sizeof why))
                return cm_fail(CM_EINVAL, msg, msg_size, "render: --palette: %s", why);
        } else if (strcmp(t[k], "--labels") == 0 && has_value) {
            char why[400];
            if (!png_opts_labels(t[++k], po, why, sizeof why))
                return cm_fail(CM_EINVAL, msg, msg_size, "render: --labels: %s", why);
        } else if ((strcmp(t[k], "--min-basin") == 0 || strcmp(t[k], "--legend") == 0) &&
                   has_value) {
            const bool legend = strcmp(t[k], "--legend") == 0;
            int64_t v = 0;
            if (!parse_int64(t[++k], &v) || v < 1 || (legend && v > 200))
                return cm_fail(CM_EINVAL, msg, msg_size, "render: %s takes %s, not '%s'",
                               t[k - 1], legend ? "1..200" : "a whole number of cells, 1 or more",
                               t[k]);
            if (legend)
                po->legend_groups = (int)v;
            else
                po->min_basin = (uint64_t)v;
        } else if (k == 2 && parse_counts(t[k], wh, &count, 2) && count == 2 &&
                   wh[0] <= CM_RENDER_MAX_SIDE && wh[1] <= CM_RENDER_MAX_SIDE) {
            po->width = (int)wh[0];
            po->height = (int)wh[1];
        } else {
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "render: '%s' is not WIDTHxHEIGHT (each 1..%d), --layers L,... or "
                           "--png-mode MODE",
                           t[k], CM_RENDER_MAX_SIDE);
        }
    }
    if (po->indexed && (po->width || po->layers))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "render: an indexed image has one pixel per cell; leave out the size and "
                       "--layers");
    return CM_OK;
}

static cm_status session_render(session *s, char **t, int n, char *msg, size_t msg_size)
{
    png_opts po;
    memset(&po, 0, sizeof po);
    const size_t len = n > 1 ? strlen(t[1]) : 0;
    const bool svg = len > 4 && strcmp(t[1] + len - 4, ".svg") == 0; /* FILE.svg: as SVG */
    *(svg ? &po.svg : &po.path) = n > 1 ? t[1] : NULL;
    cm_status st = words(n, 2, 17, "render FILE.png|FILE.svg [WIDTHxHEIGHT] [--layers L,...] "
                         "[--png-mode M] [--palette P] [--labels FILE] [--min-basin N] [--legend K] "
                         "[--by attractors|groups]",
                         msg, msg_size);
    if (st == CM_OK)
        st = render_words(t, n, &po, msg, msg_size);
    const cm_file_use files[] = {{s->path, "the session's database", true, true},
                                 {n > 1 ? t[1] : NULL, "render", true, false},
                                 {po.palette_file, "--palette", false, false},
                                 {po.labels_file, "--labels", false, false}};
    if (st == CM_OK)
        st = cm_files_apart(files, sizeof files / sizeof *files, msg, msg_size);
    if (st == CM_OK)
        st = need_view(s, "render", msg, msg_size);
    if (st != CM_OK)
        return st;
    const double t0 = cm_seconds();
    cm_region flat;
    cm_group_info *groups = NULL;
    memset(&flat, 0, sizeof flat);
    st = shown_cells(s, &flat, &groups, msg, msg_size);
    cm_attractor_set att;
    memset(&att, 0, sizeof att);
    cluster_ends ends;
    memset(&ends, 0, sizeof ends);
    if (st == CM_OK && po.by == BY_ATTRACTORS)
        st = cluster_ends_open(&ends, &s->c, msg, msg_size);
    if (st == CM_OK && po.by == BY_ATTRACTORS)
        st = cm_cluster_attractors(&s->model, &ends.cc, groups, NULL, &att, msg, msg_size);
    if (st == CM_OK && !s->gl && !po.indexed && !svg)
        st = cm_gl_open(&s->gl, msg, msg_size);
    const basin_png png = {&po,
                           &s->model,
                           &s->c.lat,
                           &flat,
                           groups,
                           {s->lo[0], s->lo[1]},
                           {s->hi[0], s->hi[1]},
                           s->gl,
                           po.by == BY_ATTRACTORS ? &att : NULL,
                           &ends.computed};
    if (st == CM_OK && write_basin_png("explore", &png) != EXIT_OK)
        st = cm_fail(CM_ERENDER, msg, msg_size, "render: %s was not written (see above)", t[1]);
    if (st == CM_OK && s->out) {
        fprintf(s->out, "render %s: %.1f ms\n", t[1], 1e3 * (cm_seconds() - t0));
        fflush(s->out);
    }
    cm_region_free(&flat);
    cluster_ends_close(&ends);
    cm_attractors_free(&att);
    free(groups);
    return st;
}

/* Most attractors `stats` lists (those with the most cells in view). */
enum { STATS_GROUPS = 20 };

typedef struct group_count {
    uint64_t cells;
    uint32_t id;
} group_count;

static int more_in_view(const void *a, const void *b)
{
    const group_count *x = a, *y = b;
    if (x->cells != y->cells)
        return x->cells > y->cells ? -1 : 1;
    return (x->id > y->id) - (x->id < y->id);
}

/* The groups with cells in view, the most first. */
static void print_groups(const session *s, uint32_t ngroups, const cm_group_info *g,
                         const uint64_t *in_view)
{
    group_count *ids = malloc(((size_t)ngroups + 1) * sizeof *ids);
    uint32_t n = 0;
    if (!ids)
        return;
    for (uint32_t k = 1; k <= ngroups; k++)
        if (in_view[k])
            ids[n++] = (group_count){in_view[k], k};
    qsort(ids, n, sizeof *ids, more_in_view);
    fprintf(s->out, "%6s %8s %12s %12s  %s\n", "group", "period", "in view", "basin", "centre");
    for (uint32_t k = 0; k < n && k < STATS_GROUPS; k++) {
        const cm_group_info *gi = &g[ids[k].id - 1];
        char centre[CM_MAX_DIM * CM_NUM_TEXT];
        cm_point_text(&s->c.lat, gi->centre, ", ", centre, sizeof centre);
        fprintf(s->out, "%6u %8u %12llu %12llu  (%s)\n", gi->id, gi->period,
                (unsigned long long)ids[k].cells, (unsigned long long)gi->basin_cells, centre);
    }
    if (n > STATS_GROUPS)
        fprintf(s->out, "... and %u groups with fewer cells in view\n", n - STATS_GROUPS);
    free(ids);
}

/* What `stats` counts in the view. */
typedef struct view_counts {
    uint64_t cells, missing, groups_in_view, cluster_cells, file_bytes;
    const uint64_t *in_view; /* cells per group id; [0]: the sink's domain */
    const cm_attractor_set *att; /* the system's attractors */
    const uint64_t *by_label;    /* cells per attractor label, at label + 2 (-2 and -1 first) */
} view_counts;

/* The view's cells by attractor label (cm_attractor_cell_labels), the
 * attractors found first (as render finds them). */
static cm_status count_by_attractors(session *s, const cm_region *flat, const cm_group_info *groups,
                                     cm_attractor_set *att, uint64_t **by_label, char *msg,
                                     size_t msg_size)
{
    cluster_ends ends;
    memset(&ends, 0, sizeof ends);
    int32_t *label = malloc((flat->ncells + 1) * sizeof *label);
    cm_status st = label ? cluster_ends_open(&ends, &s->c, msg, msg_size)
                         : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the labels");
    if (st == CM_OK)
        st = cm_cluster_attractors(&s->model, &ends.cc, groups, NULL, att, msg, msg_size);
    if (st == CM_OK)
        st = cm_attractor_cell_labels(att, flat, &ends.computed, label, msg, msg_size);
    *by_label = st == CM_OK ? calloc((size_t)att->n + 3, sizeof **by_label) : NULL;
    if (st == CM_OK && !*by_label)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the attractors in view");
    for (uint64_t i = 0; st == CM_OK && i < flat->ncells; i++)
        (*by_label)[label[i] + 2]++;
    cluster_ends_close(&ends);
    free(label);
    return st;
}

/* The attractors with cells in view, the most first, and the cells that
 * diverge or stay outside. */
static void print_attractors(const session *s, const view_counts *v)
{
    const cm_attractor_set *att = v->att;
    group_count *ids = malloc(((size_t)att->n + 1) * sizeof *ids);
    uint32_t n = 0;
    if (!ids)
        return;
    for (uint32_t a = 1; a <= att->n; a++)
        if (v->by_label[a + 2])
            ids[n++] = (group_count){v->by_label[a + 2], a};
    qsort(ids, n, sizeof *ids, more_in_view);
    fprintf(s->out, "attractors in view %u; diverged %llu cells, outside or undecided %llu\n", n,
            (unsigned long long)v->by_label[CM_LABEL_DIVERGED + 2],
            (unsigned long long)v->by_label[CM_LABEL_OUTSIDE + 2]);
    fprintf(s->out, "%6s  %-9s %6s %12s %12s  %s\n", "attr.", "kind", "period", "in view",
            "basin", "centre");
    for (uint32_t k = 0; k < n && k < STATS_GROUPS; k++) {
        const cm_attractor *a = &att->a[ids[k].id - 1];
        char centre[CM_MAX_DIM * CM_NUM_TEXT], period[16];
        cm_point_text(&s->c.lat, a->centre, ", ", centre, sizeof centre);
        snprintf(period, sizeof period, a->kind == CM_ATTRACTOR_APERIODIC ? "-" : "%u", a->period);
        fprintf(s->out, "%6u  %-9s %6s %12llu %12llu  (%s)\n", a->id,
                cm_attractor_kind_name(a->kind), period, (unsigned long long)ids[k].cells,
                (unsigned long long)a->basin_cells, centre);
    }
    if (n > STATS_GROUPS)
        fprintf(s->out, "... and %u attractors with fewer cells in view\n", n - STATS_GROUPS);
    free(ids);
}

static void print_stats_text(const session *s, const view_counts *v, const cm_region *flat,
                             const cm_group_info *groups)
{
    char view[VIEW_TEXT];
    format_view(s, view, sizeof view);
    fprintf(s->out,
            "view %s: %llu cells, %llu not computed, %llu in the sink's domain, %llu groups\n",
            view, (unsigned long long)v->cells, (unsigned long long)v->missing,
            (unsigned long long)v->in_view[0], (unsigned long long)v->groups_in_view);
    print_groups(s, flat->ngroups, groups, v->in_view);
    print_attractors(s, v);
    fprintf(s->out,
            "cluster: %u regions, %llu cells, %u groups; memory %.1f MiB (cell arrays "
            "resident %.1f MiB%s); disk %.1f MiB (%.2f bytes/cell)\n",
            s->c.nregions, (unsigned long long)v->cluster_cells, s->c.ngroups,
            (double)cm_cluster_bytes(&s->c) / 1048576.0,
            (double)cm_cluster_resident_bytes(&s->c) / 1048576.0,
            s->c.mem_budget ? ", within --mem" : "", (double)v->file_bytes / 1048576.0,
            v->cluster_cells ? (double)v->file_bytes / (double)v->cluster_cells : 0.0);
}

/* The same as one JSON document (docs/cellmap.schema.json), every group
 * in view in id order. */
static void print_stats_json(const session *s, const view_counts *v, const cm_region *flat,
                             const cm_group_info *groups)
{
    json j;
    json_begin(&j, s->out, "stats");
    json_model(&j, &s->model);
    json_lattice(&j, &s->c.lat);
    json_box(&j, "box", &s->c.lat, &flat->box);
    json_uint(&j, "cells", v->cells);
    json_uint(&j, "not_computed", v->missing);
    json_uint(&j, "sink_cells", v->in_view[0]);
    json_array(&j, "groups");
    for (uint32_t k = 1; k <= flat->ngroups; k++) {
        if (!v->in_view[k])
            continue;
        const cm_group_info *g = &groups[k - 1];
        json_object(&j, NULL);
        json_group_fields(&j, g, &s->c.lat);
        json_uint(&j, "in_view", v->in_view[k]);
        json_object_end(&j);
    }
    json_array_end(&j);
    json_array(&j, "attractors");
    for (uint32_t k = 0; k < v->att->n; k++) {
        const cm_attractor *a = &v->att->a[k];
        if (!v->by_label[a->id + 2])
            continue;
        json_object(&j, NULL);
        json_attractor_fields(&j, a, &s->c.lat);
        json_uint(&j, "in_view", v->by_label[a->id + 2]);
        json_object_end(&j);
    }
    json_array_end(&j);
    json_uint(&j, "diverged_cells", v->by_label[CM_LABEL_DIVERGED + 2]);
    json_uint(&j, "outside_cells", v->by_label[CM_LABEL_OUTSIDE + 2]);
    json_object(&j, "cluster");
    json_uint(&j, "regions", s->c.nregions);
    json_uint(&j, "cells", v->cluster_cells);
    json_uint(&j, "groups", s->c.ngroups);
    json_uint(&j, "memory_bytes", cm_cluster_bytes(&s->c));
    json_uint(&j, "resident_bytes", cm_cluster_resident_bytes(&s->c));
    json_uint(&j, "file_bytes", v->file_bytes);
    json_object_end(&j);
    json_end(&j);
}

static cm_status cmd_stats(session *s, char **t, int n, char *msg, size_t msg_size)
{
    const bool as_json = n == 2 && strcmp(t[1], "--json") == 0;
    cm_status st = n == 2 && !as_json ? cm_fail(CM_EINVAL, msg, msg_size, "usage: stats [--json]")
                                      : words(n, 1, 2, "stats [--json]", msg, msg_size);
    if (st == CM_OK)
        st = need_view(s, "stats", msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_region flat;
    cm_group_info *groups = NULL;
    memset(&flat, 0, sizeof flat);
    st = shown_cells(s, &flat, &groups, msg, msg_size);
    uint64_t *in_view = st == CM_OK ? calloc((size_t)flat.ngroups + 2, sizeof *in_view) : NULL;
    if (st == CM_OK && !in_view)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the groups in view");
    cm_attractor_set att;
    memset(&att, 0, sizeof att);
    uint64_t *by_label = NULL;
    if (st == CM_OK && s->out)
        st = count_by_attractors(s, &flat, groups, &att, &by_label, msg, msg_size);
    if (st == CM_OK && s->out) {
        view_counts v = {flat.ncells, 0, 0, 0, 0, in_view, &att, by_label};
        for (uint64_t i = 0; i < flat.ncells; i++) {
            if (flat.group[i] == CM_GROUP_NONE)
                v.missing++;
            else
                v.groups_in_view += in_view[flat.group[i]]++ == 0 && flat.group[i] != 0;
        }
        for (uint32_t k = 0; k < s->c.nregions; k++)
            v.cluster_cells += s->c.regions[k].r.ncells;
        cm_store_info info;
        if (cm_store_read_info(s->store, &info, msg, msg_size) == CM_OK)
            v.file_bytes = info.file_bytes;
        if (as_json)
            print_stats_json(s, &v, &flat, groups);
        else
            print_stats_text(s, &v, &flat, groups);
        fflush(s->out);
    }
    free(in_view);
    free(by_label);
    cm_attractors_free(&att);
    cm_region_free(&flat);
    free(groups);
    return st;
}

/* `export ...` runs `cellmap export FILE ...` on the saved cluster; cells
 * default to the view's. */
static cm_status cmd_export_view(session *s, char **t, int n, char *msg, size_t msg_size)
{
    char *argv[MAX_TOKENS + 4], window[CM_MAX_DIM * 64];
    int argc = 0, has_window = 0, has_cells = 0;
    argv[argc++] = "export";
    argv[argc++] = (char *)s->path;
    for (int k = 1; k < n; k++) {
        has_window |= strcmp(t[k], "--window") == 0 || strncmp(t[k], "--window=", 9) == 0;
        has_cells |= strncmp(t[k], "--cells", 7) == 0 || strncmp(t[k], "--flat", 6) == 0;
        argv[argc++] = t[k];
    }
    if (has_cells && !has_window && s->have_view) {
        cm_box box;
        view_box(s, s->lo, s->hi, &box);
        cm_box_text(&s->c.lat, &box, window, sizeof window);
        argv[argc++] = "--window";
        argv[argc++] = window;
    }
    argv[argc] = NULL;
    if (s->out)
        fflush(s->out); /* status lines before export's own output */
    const int rc = cmd_export(argc, argv);
    return rc == EXIT_OK ? CM_OK : cm_fail(CM_EINVAL, msg, msg_size, "export failed (see above)");
}

static cm_status cmd_save(session *s, char **t, int n, char *msg, size_t msg_size)
{
    (void)t;
    cm_status st = words(n, 1, 1, "save", msg, msg_size);
    if (st == CM_OK)
        st = save_view(s, msg, msg_size);
    if (st == CM_OK && s->out) {
        fprintf(s->out, "saved %s: %u regions, %u groups\n", s->path, s->c.nregions, s->c.ngroups);
        fflush(s->out);
    }
    return st;
}

static cm_status cmd_quit(session *s, char **t, int n, char *msg, size_t msg_size)
{
    s->quit = 1;
    return words(n, 1, 1, t[0], msg, msg_size);
}

static cm_status cmd_help(session *s, char **t, int n, char *msg, size_t msg_size)
{
    (void)t;
    (void)n;
    (void)msg;
    (void)msg_size;
    if (s->out)
        fputs(session_help, s->out);
    return CM_OK;
}

static const struct {
    const char *name;
    cm_status (*run)(session *s, char **t, int n, char *msg, size_t msg_size);
} commands[] = {
    {"view", cmd_view},     {"pan", cmd_pan},
    {"zoom", cmd_zoom},     {"goto", cmd_goto},
    {"extend", cmd_extend}, {"render", session_render},
    {"stats", cmd_stats},   {"export", cmd_export_view},
    {"save", cmd_save},     {"quit", cmd_quit},
    {"exit", cmd_quit},     {"help", cmd_help},
};

cm_status session_exec(session *s, const char *line, char *msg, size_t msg_size)
{
    char copy[4096], *t[MAX_TOKENS];
    if (strlen(line) >= sizeof copy)
        return cm_fail(CM_EINVAL, msg, msg_size, "the line is longer than %zu characters",
                       sizeof copy - 1);
    snprintf(copy, sizeof copy, "%s", line);
    const int n = tokenize(copy, t, MAX_TOKENS, msg, msg_size);
    if (n < 0)
        return CM_EINVAL;
    if (n == 0)
        return CM_OK;
    for (size_t k = 0; k < sizeof commands / sizeof commands[0]; k++)
        if (strcmp(t[0], commands[k].name) == 0) {
            const cm_status st = commands[k].run(s, t, n, msg, msg_size);
            s->damaged |= st == CM_EFORMAT;
            return st;
        }
    char names[256];
    size_t used = 0;
    for (size_t k = 0; k < sizeof commands / sizeof commands[0] && used < sizeof names; k++)
        used += (size_t)snprintf(names + used, sizeof names - used, "%s%s", k ? ", " : "",
                                 commands[k].name);
    return cm_fail(CM_EINVAL, msg, msg_size, "unknown command '%s' (commands: %s)", t[0], names);
}

/* ---- opening and closing ------------------------------------------------------ */

static int open_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

static int open_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "cellmap explore: ");
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    return EXIT_FAIL;
}

/* The file's model, rebuilt from its name and parameters. */
static int model_of_file(session *s, const session_options *o, const cm_store_info *info)
{
    char msg[2048];
    s->models = o->mo.set; /* --model-lib's, and the file's own plugin */
    if (model_of_store(info, &s->models, &s->model, msg, sizeof msg) != CM_OK)
        return open_error("%s: %s", s->path, msg);
    s->have_model = 1;
    return EXIT_OK;
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
static int restore_depth(session *s)
{
    char text[512], msg[256];
    if (s->dim <= 2)
        return EXIT_OK;
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
        return open_error("%s has no depth for dimensions 3.. (it was not made by explore)",
                          s->path);
    }
    for (int d = 2; d < s->dim; d++) {
        if (s->depth_lo[d] >= s->depth_hi[d] || s->depth_lo[d] < -CM_WORLD_LIMIT ||
            s->depth_hi[d] > CM_WORLD_LIMIT)
            return open_error("%s is damaged: its depth note '%s' is not LO:HI,... cells of "
                              "the world",
                              s->path, text);
        s->slice[d] = s->depth_lo[d] + (s->depth_hi[d] - s->depth_lo[d]) / 2;
    }
    return EXIT_OK;
}

/* The view saved by the last session, or the cluster's bounding box. */
static int restore_view(session *s)
{
    char msg[256], slice[VIEW_TEXT];
    double lo[2], hi[2];
    const cm_status noted = project_view_note(s->store, s->view_dims, lo, hi, slice, sizeof slice);
    if (noted == CM_EFORMAT)
        return open_error("%s is damaged: its view note is not a view", s->path);
    if (noted == CM_OK) {
        if (check_view(s, lo, hi, "the view note", msg, sizeof msg) != CM_OK)
            return open_error("%s is damaged: %s", s->path, msg);
        memcpy(s->lo, lo, sizeof lo);
        memcpy(s->hi, hi, sizeof hi);
        if (slice[0] && parse_slice(s, slice, s->slice, msg, sizeof msg) != CM_OK)
            return open_error("%s is damaged: its view note: %s", s->path, msg);
        s->have_view = 1;
    } else if (s->c.nregions > 0) {
        cm_box b;
        cm_cluster_bounds(&s->c, &b);
        cm_box_rect(&s->c.lat, &b, s->view_dims, s->lo, s->hi);
        s->have_view = 1;
    }
    return EXIT_OK;
}

/* The lattice of the options (--cell-size, --origin) for a model. */
static int options_lattice(const session_options *o, int dim, cm_lattice *lat)
{
    char msg[256];
    memset(lat, 0, sizeof *lat);
    lat->dim = dim;
    if (o->n_cell_size != dim) {
        fprintf(stderr,
                "cellmap explore: --cell-size needs %d width(s) DX[,DY...] for this model\n", dim);
        return EXIT_USAGE;
    }
    if (o->n_origin && o->n_origin != dim) {
        fprintf(stderr, "cellmap explore: --origin needs %d coordinate(s) for this model\n", dim);
        return EXIT_USAGE;
    }
    for (int d = 0; d < dim; d++) {
        lat->width[d] = o->cell_size[d];
        lat->origin[d] = o->n_origin ? o->origin[d] : 0.0;
    }
    if (cm_lattice_check(lat, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "cellmap explore: --cell-size/--origin: %s\n", msg);
        return EXIT_USAGE;
    }
    return EXIT_OK;
}

/* Options given for an existing file must describe it. */
static int check_same(const session *s, const session_options *o, const cm_store_info *info)
{
    cm_model m;
    char msg[512], params[4096];
    if (o->mo.name) {
        if (cm_model_set_create(&o->mo.set, o->mo.name, o->mo.texts, o->mo.n_texts, &m, msg, sizeof msg) != CM_OK)
            return open_error("%s", msg);
        cm_params_json(&m.values, params, sizeof params);
        const int differs = strcmp(m.name, info->model) != 0 || strcmp(params, info->params) != 0;
        cm_model_release(&m);
        if (differs)
            return open_error("%s holds model %s; drop --model/--param to go on with it, or "
                              "choose another file",
                              s->path, info->model);
    }
    cm_lattice lat;
    if (o->n_cell_size && (options_lattice(o, info->lattice.dim, &lat) != EXIT_OK ||
                           !cm_lattice_equal(&lat, &info->lattice)))
        return open_error("%s has another lattice; drop --cell-size/--origin to go on with "
                          "it",
                          s->path);
    if (o->max_steps && o->max_steps != s->max_steps)
        return open_error("%s was computed with another --max-steps; drop it to go on with "
                          "the file's",
                          s->path);
    return EXIT_OK;
}

/* What project_resume asks explore (fits_session). */
typedef struct explore_fit {
    session *s;
    const session_options *o;
    int rc; /* a refusal already reported */
} explore_fit;

/* A project_fits_fn: the file's model rebuilds, and the options agree with it. */
static cm_status fits_session(void *user, const cm_store_info *info, const cm_model **model,
                              char *msg, size_t msg_size)
{
    explore_fit *f = user;
    f->s->max_steps = 1; /* a plan without max-steps; 0 (a solve's default) is 1 too */
    if (project_plan_int(info->plan, "max-steps", 0, MAX_STEPS_LIMIT, &f->s->max_steps) ==
        CM_EFORMAT) {
        f->rc = open_error("%s is damaged: its plan '%s' has no valid max-steps", f->s->path,
                           info->plan);
        return cm_fail(CM_EINVAL, msg, msg_size, "refused"); /* reported */
    }
    if (f->s->max_steps < 1)
        f->s->max_steps = 1;
    f->rc = model_of_file(f->s, f->o, info);
    if (f->rc == EXIT_OK)
        f->rc = check_same(f->s, f->o, info);
    if (f->rc != EXIT_OK)
        return cm_fail(CM_EINVAL, msg, msg_size, "refused"); /* reported */
    *model = &f->s->model;
    return CM_OK;
}

static int open_existing(session *s, const session_options *o)
{
    char msg[1024];
    cm_store_info info;
    explore_fit fit = {s, o, EXIT_OK};
    int upgraded_from = 0;
    const cm_status st = project_resume(s->path, fits_session, &fit, &s->store, &info, &s->c,
                                        &upgraded_from, msg, sizeof msg);
    cli_said_upgrade("explore", s->path, upgraded_from);
    if (st != CM_OK)
        return fit.rc != EXIT_OK ? fit.rc : open_error("%s", msg);
    int rc;
    s->dim = info.lattice.dim;
    s->view_dims = s->dim < 2 ? s->dim : 2;
    if ((rc = restore_depth(s)) != EXIT_OK)
        return rc;
    return restore_view(s);
}

/* The depth of a new file's models of more than two dimensions: --depth
 * or the model's example region. */
static int new_depth(session *s, const session_options *o)
{
    const cm_model_entry *e = cm_model_set_find(&o->mo.set, s->model.name, NULL);
    const char *text = o->depth_text;
    double lo[CM_MAX_DIM], hi[CM_MAX_DIM];
    int n = 0;
    if (s->dim <= 2)
        return EXIT_OK;
    if (!text && e && e->region) {
        if (!parse_ranges(e->region, lo, hi, &n, CM_MAX_DIM) || n != s->dim)
            return open_error("model %s: bad example region %s", s->model.name, e->region);
    } else if (!text || !parse_ranges(text, lo + 2, hi + 2, &n, CM_MAX_DIM - 2) ||
               n != s->dim - 2) {
        fprintf(stderr,
                "cellmap explore: model %s has %d dimensions: --depth LO:HI,... gives the "
                "ranges of dimensions 3..%d that every view computes\n",
                s->model.name, s->dim, s->dim);
        return EXIT_USAGE;
    }
    for (int d = 2; d < s->dim; d++) {
        s->depth_lo[d] = cm_lattice_border(&s->c.lat, d, lo[d], 0);
        s->depth_hi[d] = cm_lattice_border(&s->c.lat, d, hi[d], 1);
        s->slice[d] = s->depth_lo[d] + (s->depth_hi[d] - s->depth_lo[d]) / 2;
    }
    char depth[512], msg[512];
    format_depth(s, depth, sizeof depth);
    if (cm_store_set_note(s->store, "note.explore.depth", depth, msg, sizeof msg) != CM_OK)
        return open_error("%s", msg);
    return EXIT_OK;
}

static int create_new(session *s, const session_options *o)
{
    char msg[1024];
    cm_lattice lat;
    if (!o->mo.name) {
        fprintf(stderr,
                "cellmap explore: %s does not exist; create it with --model NAME "
                "[--param k=v,...] --cell-size DX[,DY...] [--origin X,Y...]\n",
                s->path);
        return EXIT_USAGE;
    }
    if (cm_model_set_create(&o->mo.set, o->mo.name, o->mo.texts, o->mo.n_texts, &s->model, msg, sizeof msg) !=
        CM_OK) {
        fprintf(stderr, "cellmap explore: %s\n", msg);
        return EXIT_USAGE;
    }
    s->have_model = 1;
    s->dim = s->model.dim;
    s->view_dims = s->dim < 2 ? s->dim : 2;
    s->max_steps = o->max_steps ? o->max_steps : 1;
    int rc = options_lattice(o, s->dim, &lat);
    if (rc != EXIT_OK)
        return rc;
    if (cm_model_check_lattice(&s->model, &lat, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "cellmap explore: --cell-size/--origin: %s\n", msg);
        return EXIT_USAGE;
    }
    char plan[64];
    snprintf(plan, sizeof plan, "explore max-steps %d", s->max_steps);
    const cm_model_lib *lib;
    cm_model_set_find(&o->mo.set, s->model.name, &lib);
    if (project_create(s->path, &s->model, lib, &lat, o->command, plan, &s->store, &s->c, msg,
                       sizeof msg) != CM_OK)
        return open_error("%s", msg);
    return new_depth(s, o);
}

int session_open(session *s, const session_options *o)
{
    struct stat sb;
    memset(s, 0, sizeof *s);
    s->path = o->path;
    s->out = o->out;
    s->threads = o->threads;
    s->max_new_cells = o->max_new_cells ? o->max_new_cells : MAX_NEW_CELLS;
    /* under --mem, one step computes no more than its cell arrays (12 bytes
     * a cell) hold: a region being solved is resident whole */
    if (o->mem && o->mem / 12 < s->max_new_cells)
        s->max_new_cells = o->mem / 12 > 4096 ? o->mem / 12 : 4096;
    s->mem_given = o->mem != 0;
    const int rc = stat(o->path, &sb) == 0 ? open_existing(s, o) : create_new(s, o);
    if (rc != EXIT_OK)
        return rc;
    s->c.threads = o->threads;
    s->c.mem_budget = o->mem;
    return EXIT_OK;
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
            cm_store_get_attractors(s->store, dim, s->c.ngroups, &att, NULL, msg, msg_size);
        if (stored == CM_OK)
            cm_attractors_free(&att);
        if (stored == CM_EFORMAT)
            s->damaged = 1; /* not written again */
        if (stored != CM_ENOTFOUND)
            return stored;
    }
    cm_group_info *groups = calloc((size_t)s->c.ngroups + 1, sizeof *groups);
    uint64_t sink = 0;
    cm_status st = groups ? cm_store_groups(s->store, groups, s->c.ngroups, &sink, msg, msg_size)
                          : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the groups");
    memset(&att, 0, sizeof att);
    cm_attractor_options used;
    cm_attractor_defaults(&s->model, NULL, &used);
    cluster_ends ends;
    memset(&ends, 0, sizeof ends);
    if (st == CM_OK)
        st = cluster_ends_open(&ends, &s->c, msg, msg_size);
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
        st = save_view(s, msg, msg_size);
    const cm_status closed = cm_store_close(s->store, msg, msg_size);
    s->store = NULL;
    cm_cluster_free(&s->c);
    cm_gl_close(s->gl);
    s->gl = NULL;
    if (s->have_model)
        cm_model_release(&s->model);
    s->have_model = 0;
    return st != CM_OK ? st : closed;
}
