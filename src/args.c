#include "src/args.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

bool cli_take_double(cli *c, const char *name, double lo, double hi, double *out, int *error)
{
    if (!cli_is(c, name, true, error))
        return false;
    if (c->value && (!parse_double(c->value, out) || !(*out >= lo && *out <= hi)))
        *error = cli_usage_error(c, "%s: '%s' must be a number in %g..%g", name, c->value, lo, hi);
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
                       const cm_model_set *models, cm_lattice *lat, cm_box *box)
{
    char msg[512];
    if (lattice_of_spec(lo, m, models, lat, box, msg, sizeof msg) == CM_OK)
        return EXIT_OK;
    return cli_usage_error(c, "%s", msg);
}

int cli_input_check(const char *cmd, const char *path)
{
    char msg[1024];
    if (project_probe(path, msg, sizeof msg) == CM_OK)
        return EXIT_OK;
    fprintf(stderr, "cellmap %s: %s\n", cmd, msg);
    return EXIT_USAGE;
}

int cli_open_read(const char *cmd, const char *path, uint64_t mem_budget, cm_store **s,
                  cm_store_info *info, cm_cluster *c)
{
    char msg[1024];
    if (project_open_cluster(path, mem_budget, s, info, c, msg, sizeof msg) == CM_OK)
        return EXIT_OK;
    fprintf(stderr, "cellmap %s: %s\n", cmd, msg);
    return EXIT_FAIL;
}

void cli_said_upgrade(const char *cmd, const char *path, int from)
{
    if (from)
        fprintf(stderr,
                "cellmap %s: upgraded %s from format version %d to %d (older cellmap versions "
                "cannot open it any more)\n",
                cmd, path, from, CM_STORE_VERSION);
}

int sweep_check(const cli *c, const model_opts *mo, const char *only, const param_axis *ax,
                int n_ax, cm_params *base)
{
    char msg[512];
    if (param_sweep_base(mo, only, ax, n_ax, base, msg, sizeof msg) == CM_OK)
        return EXIT_OK;
    return cli_usage_error(c, "%s", msg);
}

/* "P=LO:HI" into b's name, lo and hi; 0 or the usage error. */
static int parse_branch(const cli *c, branch_spec *b)
{
    const char *v = c->value, *eq = strchr(v, '='), *colon = eq ? strchr(eq + 1, ':') : NULL;
    char lo[64], hi[64];
    if (!eq || eq == v || (size_t)(eq - v) >= sizeof b->name || !colon ||
        (size_t)(colon - eq - 1) >= sizeof lo || strlen(colon + 1) >= sizeof hi)
        return cli_usage_error(c, "--branch: '%s' is not P=LO:HI (e.g. xi=0.5:15)", v);
    memcpy(b->name, v, (size_t)(eq - v));
    b->name[eq - v] = 0;
    memcpy(lo, eq + 1, (size_t)(colon - eq - 1));
    lo[colon - eq - 1] = 0;
    strcpy(hi, colon + 1);
    if (!parse_double(lo, &b->lo) || !parse_double(hi, &b->hi) || !(b->lo < b->hi))
        return cli_usage_error(c, "--branch: '%s' needs numbers LO < HI (e.g. xi=0.5:15)", v);
    return 0;
}

bool branch_opts_take(cli *c, branch_spec *b, int *error)
{
    if (cli_is(c, "--from", true, error)) {
        if (c->value && !parse_doubles(c->value, b->from, &b->n_from, CM_MAX_DIM))
            *error = cli_usage_error(c, "--from: '%s' is not a list of numbers X[,Y...]",
                                     c->value);
    } else if (cli_is(c, "--branch", true, error)) {
        if (c->value)
            *error = parse_branch(c, b);
    } else if (cli_is(c, "--direction", true, error)) {
        if (c->value && strcmp(c->value, "up") && strcmp(c->value, "down"))
            *error = cli_usage_error(c, "--direction: '%s' is not up or down", c->value);
        else if (c->value)
            b->direction = strcmp(c->value, "up") == 0 ? 1 : -1;
    } else if (cli_is(c, "--ds-max", true, error)) {
        if (c->value && (!parse_double(c->value, &b->ds_max) || !(b->ds_max > 0)))
            *error = cli_usage_error(c, "--ds-max: '%s' must be a number above 0", c->value);
    } else if (!cli_take_int(c, "--max-points", 10, 1000000, &b->max_points, error)) {
        return false;
    }
    return true;
}

int branch_opts_check(const cli *c, const branch_spec *b, bool extra, const char *extra_name)
{
    if (b->n_from == 0)
        return cli_usage_error(c, "--from X[,Y...] is required: where Newton's method starts");
    if ((extra || b->direction || b->ds_max > 0) && !b->name[0])
        return cli_usage_error(c, "%s, --direction and --ds-max need --branch P=LO:HI",
                               extra_name);
    return 0;
}
