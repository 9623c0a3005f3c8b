/* src/explore.c - the explore session language (src/explore.h): words
 * read into the calls of lib/session.h, and what they did printed. */
#include "src/explore.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lib/figure_args.h"
#include "lib/json.h"
#include "lib/parse.h"
#include "lib/stats_report.h"
#include "lib/work.h"
#include "src/commands.h"
#include "src/figure_opts.h"


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
    "  render FILE.png|.svg|.pdf [WxH]    the view as a basin image (default: a pixel\n"
    "                                     per cell, at most 4096); `cellmap render`'s\n"
    "                                     figure options but --view\n"
    "  stats [--json]                     groups and attractors in view, cells, memory, disk\n"
    "  export --groups|--cells|--flat ... as `cellmap export` (--window: the view)\n"
    "  save                               save the view (joins are saved as they happen)\n"
    "  quit                               end the session\n"
    "  help                               this list\n";


enum { MAX_TOKENS = 24, VIEW_TEXT = 512 };

/* ---- what the session did ---------------------------------------------- */

static void report(const explore *e, const char *what, const session_work *done)
{
    if (!e->out)
        return;
    char view[VIEW_TEXT];
    session_view_text(&e->s, view, sizeof view);
    fprintf(e->out, "%s: view %s; ", what, view);
    if (done->regions == 0)
        fprintf(e->out, "nothing new to compute\n");
    else
        fprintf(e->out,
                "computed %llu cells in %u new region%s, joined (%u region%s resolved again), "
                "%u new group%s (%u across borders); %.1f ms\n",
                (unsigned long long)done->cells, done->regions, done->regions == 1 ? "" : "s",
                done->affected, done->affected == 1 ? "" : "s", done->new_groups,
                done->new_groups == 1 ? "" : "s", done->straddling, 1e3 * done->seconds);
    fflush(e->out);
}

/* Moves the view and says what it computed. */
static cm_status move(explore *e, const double *lo, const double *hi, const int64_t *slice,
                      const char *what, char *msg, size_t msg_size)
{
    session_work done;
    const cm_status st = session_move(&e->s, lo, hi, slice, what, &done, msg, msg_size);
    if (st == CM_OK)
        report(e, what, &done);
    return st;
}

/* ---- parsing --------------------------------------------------------------- */

static cm_status words(int n, int lo, int hi, const char *usage, char *msg, size_t msg_size)
{
    return n >= lo && n <= hi ? CM_OK : cm_fail(CM_EINVAL, msg, msg_size, "usage: %s", usage);
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

static cm_status cmd_view(explore *e, char **t, int n, char *msg, size_t msg_size)
{
    const session *s = &e->s;
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
        st = session_slice(s, t[2 + used], slice, msg, msg_size);
    return st == CM_OK ? move(e, lo, hi, slice, "view", msg, msg_size) : st;
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

static cm_status cmd_pan(explore *e, char **t, int n, char *msg, size_t msg_size)
{
    const session *s = &e->s;
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
        st = session_need_view(s, "pan", msg, msg_size);
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
    return move(e, lo, hi, NULL, what, msg, msg_size);
}

static cm_status cmd_zoom(explore *e, char **t, int n, char *msg, size_t msg_size)
{
    const session *s = &e->s;
    double factor = 0;
    cm_status st = words(n, 2, 2, "zoom FACTOR (2: closer, 0.5: farther)", msg, msg_size);
    if (st == CM_OK && (!parse_double(t[1], &factor) || !(factor > 0) || !isfinite(factor)))
        st = cm_fail(CM_EINVAL, msg, msg_size, "zoom: '%s' is not a positive factor", t[1]);
    if (st == CM_OK)
        st = session_need_view(s, "zoom", msg, msg_size);
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
    return move(e, lo, hi, NULL, what, msg, msg_size);
}

static cm_status cmd_goto(explore *e, char **t, int n, char *msg, size_t msg_size)
{
    const session *s = &e->s;
    const char *usage = s->view_dims > 1 ? "goto X Y" : "goto X";
    cm_status st = words(n, 1 + s->view_dims, 1 + s->view_dims, usage, msg, msg_size);
    if (st == CM_OK)
        st = session_need_view(s, "goto", msg, msg_size);
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
    return st == CM_OK ? move(e, lo, hi, NULL, "goto", msg, msg_size) : st;
}

/* ---- extend auto ------------------------------------------------------------ */

static void said_step(void *user, const session_step *step)
{
    const explore *e = user;
    if (!e->out)
        return;
    char box[CM_MAX_DIM * 64], where[128] = "recorded before the interruption";
    cm_box_text(&e->s.c.lat, &step->tile, box, sizeof box);
    if (!step->recorded)
        snprintf(where, sizeof where, "where %llu of the %llu escaping sequences go",
                 (unsigned long long)step->escaping, (unsigned long long)step->all_escaping);
    const session_work *done = &step->work;
    fprintf(e->out,
            "extend auto %d: tile %s, %s; computed %llu cells in %u new region%s, %u new "
            "group%s (%u across borders); %.1f ms\n",
            step->step, box, where, (unsigned long long)done->cells, done->regions,
            done->regions == 1 ? "" : "s", done->new_groups, done->new_groups == 1 ? "" : "s",
            done->straddling, 1e3 * done->seconds);
    fflush(e->out);
}

static cm_status cmd_extend(explore *e, char **t, int n, char *msg, size_t msg_size)
{
    int64_t steps = 1;
    cm_status st = words(n, 2, 3, "extend auto [N]", msg, msg_size);
    if (st == CM_OK && strcmp(t[1], "auto") != 0)
        st = cm_fail(CM_EINVAL, msg, msg_size, "usage: extend auto [N] (not '%s')", t[1]);
    if (st == CM_OK && n == 3 && (!parse_int64(t[2], &steps) || steps < 1 || steps > 1000))
        st = cm_fail(CM_EINVAL, msg, msg_size, "extend auto: '%s' must be an integer in 1..1000",
                     t[2]);
    if (st != CM_OK)
        return st;
    session_extended how;
    st = session_extend(&e->s, NULL, (int)steps, said_step, e, &how, msg, msg_size);
    if (st == CM_OK && e->out && how.repeated)
        fprintf(e->out, "extend auto: done in the run that stopped; not repeated\n");
    if (st == CM_OK && e->out && how.stopped)
        fprintf(e->out, "extend auto: stopped, %s\n", how.stop);
    return st;
}

/* ---- render, stats, export, save --------------------------------------------- */

/* The words after "render FILE.png": [WIDTHxHEIGHT] and the figure options
 * `cellmap render` takes (lib/figure_args.h); the view is the session's. */
static cm_status render_words(char **t, int n, png_opts *po, char *msg, size_t msg_size)
{
    for (int k = 2; k < n; k++) {
        int64_t wh[2];
        int count = 0;
        const bool has_value = k + 1 < n;
        bool figure_option = false;
        for (const char *const *name = png_value_options; *name && !figure_option; name++)
            figure_option = strcmp(t[k], *name) == 0 && strcmp(*name, "--view") != 0;
        if (figure_option && has_value) {
            char why[1024];
            if (!png_opts_value(po, t[k], t[k + 1], why, sizeof why))
                return cm_fail(CM_EINVAL, msg, msg_size, "render: %s", why);
            k++;
        } else if (strcmp(t[k], "--by") == 0 && has_value) {
            const char *by = t[++k];
            if (strcmp(by, "groups") != 0 && strcmp(by, "attractors") != 0)
                return cm_fail(CM_EINVAL, msg, msg_size,
                               "render: --by '%s' must be attractors or groups", by);
            po->by = strcmp(by, "groups") == 0 ? BY_GROUPS : BY_ATTRACTORS;
        } else if (strcmp(t[k], "--legend") == 0 && has_value) {
            int64_t v = 0;
            if (!parse_int64(t[++k], &v) || v < 1 || v > 200)
                return cm_fail(CM_EINVAL, msg, msg_size, "render: --legend takes 1..200, not '%s'",
                               t[k]);
            po->legend_groups = (int)v;
        } else if (k == 2 && parse_counts(t[k], wh, &count, 2) && count == 2 &&
                   wh[0] <= CM_RENDER_MAX_SIDE && wh[1] <= CM_RENDER_MAX_SIDE) {
            po->width = (int)wh[0];
            po->height = (int)wh[1];
        } else {
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "render: '%s' is not WIDTHxHEIGHT (each 1..%d) or an option of "
                           "`cellmap render` with its value",
                           t[k], CM_RENDER_MAX_SIDE);
        }
    }
    if (po->indexed && (po->width || po->layers))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "render: an indexed image has one pixel per cell; leave out the size and "
                       "--layers");
    return CM_OK;
}

static cm_status cmd_render_view(explore *e, char **t, int n, char *msg, size_t msg_size)
{
    png_opts po;
    memset(&po, 0, sizeof po);
    const size_t len = n > 1 ? strlen(t[1]) : 0;
    const char *ext = len > 4 ? t[1] + len - 4 : ""; /* FILE.svg, FILE.pdf: as SVG, PDF */
    *(strcmp(ext, ".svg") == 0 ? &po.svg : strcmp(ext, ".pdf") == 0 ? &po.pdf : &po.path) =
        n > 1 ? t[1] : NULL;
    cm_status st = words(n, 2, 23, "render FILE.png|.svg|.pdf [WIDTHxHEIGHT] [--layers L,...] "
                         "[--png-mode M] [--palette P] [--labels FILE] [--min-basin N] [--legend K] "
                         "[--by attractors|groups] [--title T] [--aspect A] [--font-size PT] "
                         "[--dpi N]",
                         msg, msg_size);
    if (st == CM_OK)
        st = render_words(t, n, &po, msg, msg_size);
    if (st != CM_OK)
        return st;
    const double t0 = cm_seconds();
    st = session_render(&e->s, &po, msg, msg_size);
    if (st == CM_OK && e->out) {
        fprintf(e->out, "render %s: %.1f ms\n", t[1], 1e3 * (cm_seconds() - t0));
        fflush(e->out);
    }
    return st;
}

static cm_status cmd_stats(explore *e, char **t, int n, char *msg, size_t msg_size)
{
    const bool as_json = n == 2 && strcmp(t[1], "--json") == 0;
    cm_status st = n == 2 && !as_json ? cm_fail(CM_EINVAL, msg, msg_size, "usage: stats [--json]")
                                      : words(n, 1, 2, "stats [--json]", msg, msg_size);
    if (st == CM_OK)
        st = session_need_view(&e->s, "stats", msg, msg_size);
    if (st != CM_OK || !e->out)
        return st;
    session_stats v;
    st = session_count(&e->s, &v, msg, msg_size);
    if (st == CM_OK) {
        if (as_json)
            stats_json(e->out, &e->s, &v);
        else
            stats_report(e->out, &e->s, &v);
        fflush(e->out);
    }
    session_stats_free(&v);
    return st;
}

/* `export ...` runs `cellmap export FILE ...` over the session's cluster;
 * cells default to the view's. */
static cm_status cmd_export_view(explore *e, char **t, int n, char *msg, size_t msg_size)
{
    session *s = &e->s;
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
        session_view_cells(s, &box);
        cm_box_text(&s->c.lat, &box, window, sizeof window);
        argv[argc++] = "--window";
        argv[argc++] = window;
    }
    argv[argc] = NULL;
    if (e->out)
        fflush(e->out); /* status lines before export's own output */
    const int rc = cmd_export_in(argc, argv, s);
    return rc == EXIT_OK ? CM_OK : cm_fail(CM_EINVAL, msg, msg_size, "export failed (see above)");
}

static cm_status cmd_save(explore *e, char **t, int n, char *msg, size_t msg_size)
{
    session *s = &e->s;
    (void)t;
    cm_status st = words(n, 1, 1, "save", msg, msg_size);
    if (st == CM_OK)
        st = session_save(s, msg, msg_size);
    if (st == CM_OK && e->out) {
        fprintf(e->out, "saved %s: %u regions, %u groups\n", s->path, s->c.nregions, s->c.ngroups);
        fflush(e->out);
    }
    return st;
}

static cm_status cmd_quit(explore *e, char **t, int n, char *msg, size_t msg_size)
{
    e->quit = 1;
    return words(n, 1, 1, t[0], msg, msg_size);
}

static cm_status cmd_help(explore *e, char **t, int n, char *msg, size_t msg_size)
{
    (void)t;
    (void)n;
    (void)msg;
    (void)msg_size;
    if (e->out)
        fputs(session_help, e->out);
    return CM_OK;
}

static const struct {
    const char *name;
    cm_status (*run)(explore *e, char **t, int n, char *msg, size_t msg_size);
} commands[] = {
    {"view", cmd_view},     {"pan", cmd_pan},
    {"zoom", cmd_zoom},     {"goto", cmd_goto},
    {"extend", cmd_extend}, {"render", cmd_render_view},
    {"stats", cmd_stats},   {"export", cmd_export_view},
    {"save", cmd_save},     {"quit", cmd_quit},
    {"exit", cmd_quit},     {"help", cmd_help},
};

cm_status explore_exec(explore *e, const char *line, char *msg, size_t msg_size)
{
    char copy[4096], *t[MAX_TOKENS];
    if (strlen(line) >= sizeof copy)
        return cm_fail(CM_EINVAL, msg, msg_size, "the line is longer than %zu characters",
                       sizeof copy - 1);
    snprintf(copy, sizeof copy, "%s", line);
    const int n = parse_words(copy, t, MAX_TOKENS, msg, msg_size);
    if (n < 0)
        return CM_EINVAL;
    if (n == 0)
        return CM_OK;
    for (size_t k = 0; k < sizeof commands / sizeof commands[0]; k++)
        if (strcmp(t[0], commands[k].name) == 0) {
            const cm_status st = commands[k].run(e, t, n, msg, msg_size);
            e->s.damaged |= st == CM_EFORMAT;
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

bool session_opts_take(cli *c, session_options *o, int *err)
{
    if (model_opts_take(c, &o->mo, err) ||
        cli_take_int(c, "--max-steps", 1, MAX_STEPS_LIMIT, &o->max_steps, err) ||
        cli_take_int(c, "--threads", 1, THREADS_LIMIT, &o->threads, err) ||
        cli_take_mem(c, &o->mem, err))
        return true;
    if (cli_is(c, "--cell-size", true, err)) {
        if (c->value && !parse_doubles(c->value, o->cell_size, &o->n_cell_size, CM_MAX_DIM))
            *err = cli_usage_error(c, "--cell-size: '%s' is not DX[,DY...]", c->value);
    } else if (cli_is(c, "--origin", true, err)) {
        if (c->value && !parse_doubles(c->value, o->origin, &o->n_origin, CM_MAX_DIM))
            *err = cli_usage_error(c, "--origin: '%s' is not X[,Y...]", c->value);
    } else if (cli_is(c, "--depth", true, err)) {
        o->depth_text = c->value;
    } else {
        return false;
    }
    return true;
}

int explore_open(explore *e, const session_options *o, FILE *out)
{
    char msg[2048];
    session_opened opened;
    memset(e, 0, sizeof *e);
    e->out = out;
    const cm_status st = session_open(&e->s, o, &opened, msg, sizeof msg);
    cli_said_upgrade("explore", o->path, opened.upgraded_from);
    if (st == CM_OK)
        return EXIT_OK;
    fprintf(stderr, "cellmap explore: %s\n", msg);
    return opened.bad_options ? EXIT_USAGE : EXIT_FAIL;
}

cm_status explore_journal_begin(explore *e, uint64_t script_hash, char *msg, size_t msg_size)
{
    const session *s = &e->s;
    const cm_status st = session_journal_begin(&e->s, script_hash, msg, msg_size);
    if (st != CM_OK || !e->out || !s->resume_line)
        return st;
    if (s->resume_step)
        fprintf(e->out, "resuming this script's run that stopped in line %ld (extend auto, "
                        "step %d): extensions done before are not repeated\n",
                s->resume_line, s->resume_step);
    else
        fprintf(e->out, "resuming this script's run that stopped after line %ld: "
                        "extensions done before are not repeated\n",
                s->resume_line);
    return st;
}

cm_status explore_close(explore *e, char *msg, size_t msg_size)
{
    return session_close(&e->s, msg, msg_size);
}
