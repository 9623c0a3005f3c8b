#include "src/args.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/output.h"
#include "cellmap/scm.h"
#include "models/registry.h"

int cli_usage_error(const cli *c, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "cellmap %s: ", c->cmd);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, "\n(see `cellmap %s --help`)\n", c->cmd);
    return EXIT_USAGE;
}

int cli_stray(const cli *c)
{
    if (c->opt[0] == '-' && c->opt[1])
        return cli_usage_error(c, "unknown option '%s'", c->opt);
    return cli_usage_error(c, "unexpected argument '%s'", c->opt);
}

bool cli_next(cli *c)
{
    c->i++;
    c->opt = c->i < c->argc ? c->argv[c->i] : NULL;
    c->value = NULL;
    return c->opt != NULL;
}

bool cli_is(cli *c, const char *name, bool needs_value, int *error)
{
    const size_t n = strlen(name);
    if (strncmp(c->opt, name, n) != 0 || (c->opt[n] != '\0' && c->opt[n] != '='))
        return false;
    if (!needs_value) {
        if (c->opt[n] == '=')
            *error = cli_usage_error(c, "%s takes no value", name);
        return true;
    }
    if (c->opt[n] == '=') {
        c->value = c->opt + n + 1;
    } else if (c->i + 1 < c->argc) {
        c->value = c->argv[++c->i];
    } else {
        *error = cli_usage_error(c, "%s needs a value", name);
    }
    return true;
}

bool parse_int64(const char *s, int64_t *out)
{
    char *end = NULL;
    errno = 0;
    const long long v = strtoll(s, &end, 10);
    if (end == s || *end != '\0' || errno == ERANGE)
        return false;
    *out = v;
    return true;
}

bool parse_bytes(const char *s, uint64_t *out)
{
    char *end = NULL;
    errno = 0;
    const unsigned long long v = strtoull(s, &end, 10);
    if (end == s || *s == '-' || errno == ERANGE)
        return false;
    const char units[] = "KMG";
    const char *u = *end ? strchr(units, *end) : NULL;
    if (*end && (!u || end[1] != '\0'))
        return false;
    const int shift = u ? 10 * (int)(u - units + 1) : 0;
    if (v > (UINT64_MAX >> shift))
        return false;
    *out = (uint64_t)v << shift;
    return true;
}

bool cli_take_mem(cli *c, uint64_t *mem, int *error)
{
    if (!cli_is(c, "--mem", true, error))
        return false;
    if (c->value && (!parse_bytes(c->value, mem) || *mem < (1u << 20)))
        *error = cli_usage_error(c, "--mem: '%s' must be a size of at least 1M, as BYTES[K|M|G]",
                                 c->value);
    return true;
}

bool cli_take_int(cli *c, const char *name, int lo, int hi, int *out, int *error)
{
    int64_t v = 0;
    if (!cli_is(c, name, true, error))
        return false;
    if (c->value && (!parse_int64(c->value, &v) || v < lo || v > hi))
        *error =
            cli_usage_error(c, "%s: '%s' must be an integer in %d..%d", name, c->value, lo, hi);
    else if (c->value)
        *out = (int)v;
    return true;
}

bool cli_take_size(cli *c, int min_w, int min_h, int max_side, int *w, int *h, int *error)
{
    int64_t wh[2];
    int n = 0;
    if (!cli_is(c, "--size", true, error))
        return false;
    if (c->value && (!parse_counts(c->value, wh, &n, 2) || n != 2 || wh[0] < min_w ||
                     wh[1] < min_h || wh[0] > max_side || wh[1] > max_side))
        *error = cli_usage_error(c, "--size: '%s' must be WxH within %dx%d..%dx%d", c->value, min_w,
                                 min_h, max_side, max_side);
    else if (c->value) {
        *w = (int)wh[0];
        *h = (int)wh[1];
    }
    return true;
}

bool parse_double(const char *s, double *out)
{
    char *end = NULL;
    errno = 0;
    const double v = strtod(s, &end);
    if (end == s || *end != '\0' || errno == ERANGE || !isfinite(v))
        return false;
    *out = v;
    return true;
}

/* Copies the piece of s up to sep (or the end) into piece, at most 255
 * characters; returns where the next piece starts, s's end if this was
 * the last, or NULL for an empty or too long piece. */
static const char *take_piece(const char *s, char sep, char piece[256])
{
    const char *end = strchr(s, sep);
    const size_t len = end ? (size_t)(end - s) : strlen(s);
    if (len == 0 || len >= 256)
        return NULL;
    memcpy(piece, s, len);
    piece[len] = '\0';
    return end ? end + 1 : s + len;
}

/* Calls parse_one on each piece of s between seps, at most max pieces; the
 * count, or -1 if a piece is malformed, empty or one too many. */
static int parse_pieces(const char *s, char sep, int max, void *out,
                        bool (*parse_one)(char *piece, void *out, int index))
{
    char piece[256];
    int n = 0;
    for (const char *p = s; p && *p; n++) {
        if (n == max || !(p = take_piece(p, sep, piece)) || !parse_one(piece, out, n))
            return -1;
        if (p[-1] == sep && *p == '\0')
            return -1; /* a trailing separator */
    }
    return n > 0 ? n : -1;
}

typedef struct ranges_out {
    double *lo, *hi;
} ranges_out;

static bool parse_range(char *piece, void *out, int d)
{
    ranges_out *r = out;
    char *colon = strchr(piece, ':');
    if (!colon)
        return false;
    *colon = '\0';
    return parse_double(piece, &r->lo[d]) && parse_double(colon + 1, &r->hi[d]) &&
           r->lo[d] < r->hi[d];
}

static bool parse_count(char *piece, void *out, int d)
{
    int64_t *v = out;
    return parse_int64(piece, &v[d]) && v[d] >= 1;
}

static bool parse_one_double(char *piece, void *out, int d)
{
    return parse_double(piece, (double *)out + d);
}

bool parse_ranges(const char *s, double *lo, double *hi, int *count, int max)
{
    ranges_out r = {lo, hi};
    const int n = parse_pieces(s, ',', max, &r, parse_range);
    if (n > 0)
        *count = n;
    return n > 0;
}

bool parse_counts(const char *s, int64_t *v, int *count, int max)
{
    const int n = parse_pieces(s, 'x', max, v, parse_count);
    if (n > 0)
        *count = n;
    return n > 0;
}

bool chart_outputs_take(cli *c, chart_outputs *o, int min_w, int min_h, int *error)
{
    if (cli_is(c, "--csv", true, error))
        o->csv = c->value;
    else if (cli_is(c, "--png", true, error))
        o->png = c->value;
    else if (cli_is(c, "--json", false, error))
        o->json = true;
    else if (cli_is(c, "--quiet", false, error))
        o->quiet = true;
    else
        return cli_take_size(c, min_w, min_h, 4096, &o->width, &o->height, error);
    return true;
}

int chart_outputs_check(const cli *c, const chart_outputs *o)
{
    if (o->json && (cm_output_names_stdout(o->csv) || cm_output_names_stdout(o->png)))
        return cli_usage_error(c, "--json and an output to standard output: choose one");
    if (cm_output_names_stdout(o->csv) && cm_output_names_stdout(o->png))
        return cli_usage_error(c, "--csv - and --png -: only one can go to standard output");
    return 0;
}

bool parse_doubles(const char *s, double *v, int *count, int max)
{
    const int n = parse_pieces(s, ',', max, v, parse_one_double);
    if (n > 0)
        *count = n;
    return n > 0;
}

FILE *report_stream(const char *out1, const char *out2, const char *out3)
{
    const char *const outs[3] = {out1, out2, out3};
    for (int k = 0; k < 3; k++)
        if (outs[k] && cm_output_names_stdout(outs[k]))
            return stderr;
    return stdout;
}

bool model_opts_take(cli *c, model_opts *mo, int *error)
{
    if (cli_is(c, "--model", true, error)) {
        mo->name = c->value;
        return true;
    }
    if (cli_is(c, "--model-lib", true, error)) {
        char msg[1400];
        if (c->value && cm_model_set_load(&mo->set, c->value, msg, sizeof msg) != CM_OK)
            *error = cli_usage_error(c, "--model-lib: %s", msg);
        return true;
    }
    if (cli_is(c, "--param", true, error)) {
        if (c->value && mo->n_texts == MAX_PARAM_TEXTS)
            *error = cli_usage_error(c, "too many --param options (at most %d)", MAX_PARAM_TEXTS);
        else if (c->value)
            mo->texts[mo->n_texts++] = c->value;
        return true;
    }
    return false;
}

int model_opts_build(const cli *c, const model_opts *mo, cm_model *m)
{
    char msg[512];
    if (cm_model_set_create(&mo->set, mo->name, mo->texts, mo->n_texts, m, msg, sizeof msg) !=
        CM_OK)
        return cli_usage_error(c, "%s", msg);
    return EXIT_OK;
}

void join_argv(int argc, char **argv, char *buf, size_t size)
{
    size_t used = 0;
    buf[0] = '\0';
    for (int i = 0; i < argc && used + 1 < size; i++)
        used += (size_t)snprintf(buf + used, size - used, "%s%s", i ? " " : "", argv[i]);
}

bool lattice_opts_take(cli *c, lattice_opts *lo, int *error)
{
    if (cli_is(c, "--region", true, error)) {
        lo->region_text = c->value;
    } else if (cli_is(c, "--cells", true, error)) {
        if (c->value && !parse_counts(c->value, lo->cells, &lo->n_cells, CM_MAX_DIM))
            *error = cli_usage_error(c, "--cells: '%s' is not N[xM...] with positive integers",
                                     c->value);
    } else {
        return false;
    }
    return true;
}

int lattice_opts_build(const cli *c, const lattice_opts *lo, const cm_model *m,
                       const cm_model_set *models, cm_lattice *lat,
                       cm_box *box)
{
    const cm_model_entry *e = cm_model_set_find(models, m->name, NULL);
    const char *text = lo->region_text ? lo->region_text : e ? e->region : NULL;
    double low[CM_MAX_DIM], high[CM_MAX_DIM];
    int n = 0;
    if (!text)
        return cli_usage_error(c, "--region is required for model %s (one LO:HI per dimension)",
                               m->name);
    if (!parse_ranges(text, low, high, &n, CM_MAX_DIM))
        return cli_usage_error(c, "--region: '%s' is not LO:HI[,LO:HI...] with LO < HI", text);
    if (n != m->dim)
        return cli_usage_error(c, "--region has %d range(s) but model %s has dimension %d", n,
                               m->name, m->dim);
    if (lo->n_cells && lo->n_cells != m->dim)
        return cli_usage_error(c, "--cells has %d count(s) but model %s has dimension %d",
                               lo->n_cells, m->name, m->dim);
    memset(lat, 0, sizeof *lat);
    memset(box, 0, sizeof *box);
    lat->dim = box->dim = m->dim;
    double total = 1.0;
    for (int d = 0; d < m->dim; d++) {
        const int64_t cells = lo->n_cells ? lo->cells[d] : (m->dim <= 2 ? 1000 : 100);
        lat->origin[d] = low[d];
        lat->width[d] = (high[d] - low[d]) / (double)cells;
        box->hi[d] = cells;
        total *= (double)cells;
    }
    if (total > (double)CM_REGION_MAX_CELLS)
        return cli_usage_error(c, "--cells asks for %.0f cells; one region holds at most %llu",
                               total, (unsigned long long)CM_REGION_MAX_CELLS);
    char msg[512];
    if (cm_lattice_check(lat, msg, sizeof msg) != CM_OK ||
        cm_model_check_box(m, lat, box, msg, sizeof msg) != CM_OK)
        return cli_usage_error(c, "%s", msg);
    return EXIT_OK;
}
