/* cellmap fixed-points: the regular and virtual fixed points of a
 * micro-chaos map, level by level. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/project.h"
#include "src/args.h"
#include "src/commands.h"
#include "lib/json.h"
#include "src/outfile.h"

static const char fp_help[] =
    "usage: cellmap fixed-points --model NAME [--model-lib P.so] [--param k=v[,k=v]]\n"
    "                            [--range M0:M1] [--csv FILE|-] [--json]\n\n"
    "Lists, for every control level m in M0..M1 (default -10:10), the candidate\n"
    "fixed point x_m* as CSV: level,band,kind and the state's coordinates (their\n"
    "names as `cellmap models` gives them), where band is the level actually\n"
    "produced at the point and kind is 'regular' (band = level) or 'virtual'\n"
    "(thesis (4.16)-(4.17), docs/models.md 2.4). The CSV goes to standard output,\n"
    "or to FILE with --csv; --json prints the same as one JSON document instead.\n";

typedef struct fp_args {
    model_opts mo;
    int64_t m0, m1;
    const char *csv;
    bool json;
} fp_args;

static int parse_range(cli *c, fp_args *a)
{
    const char *colon = strchr(c->value, ':');
    char lo[64];
    if (!colon || (size_t)(colon - c->value) >= sizeof lo)
        return cli_usage_error(c, "--range: '%s' is not M0:M1", c->value);
    snprintf(lo, sizeof lo, "%.*s", (int)(colon - c->value), c->value);
    if (!parse_int64(lo, &a->m0) || !parse_int64(colon + 1, &a->m1) || a->m0 > a->m1 ||
        a->m0 < -(INT64_C(1) << 50) || a->m1 > (INT64_C(1) << 50) || a->m1 - a->m0 > 1000000)
        return cli_usage_error(c, "--range: '%s' must be integers M0 <= M1, at most 1e6 levels",
                               c->value);
    return EXIT_OK;
}

/* 0: go on; -1: --help was printed; else the usage error. */
static int parse_args(cli *c, fp_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(fp_help, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (cli_is(c, "--range", true, &err)) {
            if (c->value)
                err = parse_range(c, a);
        } else if (cli_is(c, "--csv", true, &err)) {
            a->csv = c->value;
        } else if (cli_is(c, "--json", false, &err)) {
            a->json = true;
        } else {
            err = cli_stray(c);
        }
    }
    if (!err && a->json && a->csv)
        err = cli_usage_error(c, "--json and --csv: choose one");
    return err;
}

static void write_csv(FILE *f, const cm_model *m, const cm_fixed_point *fps, size_t n)
{
    fprintf(f, "level,band,kind");
    for (int d = 0; d < m->dim; d++)
        fprintf(f, ",%s", cm_model_coord_name(m, d));
    fprintf(f, "\n");
    for (size_t i = 0; i < n; i++) {
        fprintf(f, "%lld,%lld,%s", (long long)fps[i].level, (long long)fps[i].band,
                fps[i].regular ? "regular" : "virtual");
        for (int d = 0; d < m->dim; d++)
            fprintf(f, ",%.17g", fps[i].x[d]);
        fprintf(f, "\n");
    }
}

static void write_json(const cm_model *m, const cm_fixed_point *fps, size_t n)
{
    json j;
    json_begin(&j, stdout, "fixed-points");
    json_model(&j, m);
    json_array(&j, "fixed_points");
    for (size_t i = 0; i < n; i++) {
        json_object(&j, NULL);
        json_int(&j, "level", fps[i].level);
        json_int(&j, "band", fps[i].band);
        json_str(&j, "kind", fps[i].regular ? "regular" : "virtual");
        json_nums(&j, "x", fps[i].x, m->dim);
        json_object_end(&j);
    }
    json_array_end(&j);
    json_end(&j);
}

static bool write_results(const fp_args *a, const cm_model *m, const cm_fixed_point *fps,
                          size_t n)
{
    if (a->json) {
        write_json(m, fps, n);
        return true;
    }
    if (!a->csv) {
        write_csv(stdout, m, fps, n);
        return true;
    }
    outfile o;
    if (!outfile_open("fixed-points", a->csv, &o))
        return false;
    write_csv(o.f, m, fps, n);
    return outfile_close("fixed-points", &o, true);
}

int cmd_fixed_points(int argc, char **argv)
{
    cli c = {"fixed-points", argc, argv, 0, NULL, NULL};
    fp_args a = {.mo = {.name = "microchaos-pd"}, .m0 = -10, .m1 = 10};
    int err = parse_args(&c, &a);
    if (err)
        return err < 0 ? EXIT_OK : err;
    const int werr = outfile_check("fixed-points", a.csv, false);
    if (werr != EXIT_OK)
        return werr;
    cm_model m;
    if ((err = model_opts_build(&c, &a.mo, &m)) != EXIT_OK)
        return err;
    if (!m.fixed_points) {
        fprintf(stderr, "cellmap fixed-points: model %s has no fixed-point formula\n", m.name);
        cm_model_release(&m);
        return EXIT_FAIL;
    }
    const size_t cap = (size_t)(a.m1 - a.m0 + 1) * 3; /* friction models list up to 3 per level */
    cm_fixed_point *fps = malloc(cap * sizeof *fps);
    size_t n = 0;
    char msg[512] = "";
    int status = EXIT_FAIL;
    if (!fps)
        fprintf(stderr, "cellmap fixed-points: out of memory\n");
    else if (m.fixed_points(&m, a.m0, a.m1, fps, cap, &n, msg, sizeof msg) != 0)
        fprintf(stderr, "cellmap fixed-points: %s\n", msg);
    else if (write_results(&a, &m, fps, n))
        status = EXIT_OK;
    free(fps);
    cm_model_release(&m);
    return status;
}
