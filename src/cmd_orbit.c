/* cellmap orbit: x_0 .. x_N of a model, at full precision. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/project.h"
#include "src/args.h"
#include "src/commands.h"
#include "lib/json.h"
#include "src/outfile.h"

static const char orbit_help[] =
    "usage: cellmap orbit --model NAME [--model-lib P.so] [--param k=v[,k=v]] --from X[,Y...]\n"
    "                     --steps N [--csv FILE|-] [--json]\n\n"
    "Prints the orbit x_0 .. x_N as CSV (j and the state's coordinates, named as\n"
    "`cellmap models` gives them) with %.17g, so any implementation can be checked\n"
    "against it: to standard output, or to FILE with --csv. --json prints one JSON\n"
    "document instead (\"points\", and \"end\": \"steps\" or \"sink\"). Stops early\n"
    "(exit 0) when the map has no image (the sink); the CSV's last line then says\n"
    "so in a comment. For the map of an ODE flow a column t (JSON: \"t\") gives the\n"
    "flow's time at each point: the sum of the periods, or of the return times to\n"
    "a Poincare map's section.\n";

typedef struct orbit_args {
    model_opts mo;
    double from[CM_MAX_DIM];
    int n_from;
    int64_t steps;
    const char *csv;
    bool json;
} orbit_args;

/* 0: go on; -1: --help was printed; else the usage error. */
static int parse_args(cli *c, orbit_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(orbit_help, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (cli_is(c, "--from", true, &err)) {
            if (c->value && !parse_doubles(c->value, a->from, &a->n_from, CM_MAX_DIM))
                err = cli_usage_error(c, "--from: '%s' is not a list of numbers X[,Y...]",
                                      c->value);
        } else if (cli_is(c, "--steps", true, &err)) {
            if (c->value &&
                (!parse_int64(c->value, &a->steps) || a->steps < 0 || a->steps > 100000000))
                err = cli_usage_error(c, "--steps: '%s' must be an integer in 0..1e8", c->value);
        } else if (cli_is(c, "--csv", true, &err)) {
            a->csv = c->value;
        } else if (cli_is(c, "--json", false, &err)) {
            a->json = true;
        } else {
            err = cli_stray(c);
        }
    }
    if (!err && (a->n_from == 0 || a->steps < 0))
        err = cli_usage_error(c, "--from and --steps are required");
    if (!err && a->json && a->csv)
        err = cli_usage_error(c, "--json and --csv: choose one");
    return err;
}

/* Follows the orbit, writing CSV to f or JSON points to j. */
static int follow(const orbit_args *a, const cm_model *m, FILE *f, json *j)
{
    double x[CM_MAX_DIM], y[CM_MAX_DIM], t = 0, flight;
    double *times = NULL; /* JSON: the flow's times, after the points */
    const bool flow = m->flow.field != NULL;
    memcpy(x, a->from, sizeof x);
    if (f) {
        fprintf(f, "j");
        for (int d = 0; d < m->dim; d++)
            fprintf(f, ",%s", cm_model_coord_name(m, d));
        fprintf(f, flow ? ",t\n" : "\n");
    } else {
        json_array(j, "points");
        if (flow && !(times = malloc(((size_t)a->steps + 1) * sizeof *times))) {
            fprintf(stderr, "cellmap orbit: out of memory for %lld times\n",
                    (long long)a->steps + 1);
            return EXIT_FAIL;
        }
    }
    const char *end = "steps";
    int status = EXIT_OK;
    int64_t step;
    for (step = 0; step <= a->steps; step++) {
        if (f) {
            fprintf(f, "%lld", (long long)step);
            for (int d = 0; d < m->dim; d++)
                fprintf(f, ",%.17g", x[d]);
            if (flow)
                fprintf(f, ",%.17g", t);
            fprintf(f, "\n");
        } else {
            json_nums(j, NULL, x, m->dim);
            if (times)
                times[step] = t;
        }
        if (step == a->steps)
            break;
        const int rc = model_image(m, x, y, &flight);
        if (rc > 0 && step == 0 && flow && flight >= m->flow.t_max &&
            (m->flow.section || m->flow.plane)) {
            fprintf(stderr,
                    "cellmap orbit: the flow from --from does not reach the model's section "
                    "within t_max = %g time units: start elsewhere, choose a section the orbit "
                    "crosses (section, level, crossing) or raise t_max\n",
                    m->flow.t_max);
            status = EXIT_FAIL;
            break;
        }
        t += flight;
        if (rc > 0) {
            end = "sink";
            if (f)
                fprintf(f, "# no image after step %lld (the sink)\n", (long long)step);
            break;
        }
        if (rc < 0) {
            fprintf(stderr, "cellmap orbit: the model aborted at step %lld\n", (long long)step);
            status = EXIT_FAIL;
            break;
        }
        memcpy(x, y, sizeof x);
    }
    if (j) {
        json_array_end(j);
        if (times)
            json_nums(j, "t", times, (int)step + 1); /* the points written */
        json_str(j, "end", end);
    }
    free(times);
    return status;
}

int cmd_orbit(int argc, char **argv)
{
    cli c = {"orbit", argc, argv, 0, NULL, NULL};
    orbit_args a;
    memset(&a, 0, sizeof a);
    a.mo.name = "microchaos-pd";
    a.steps = -1;
    int err = parse_args(&c, &a);
    if (err)
        return err < 0 ? EXIT_OK : err;
    const int werr = outfile_check("orbit", a.csv, false);
    if (werr != EXIT_OK)
        return werr;
    cm_model m;
    if ((err = model_opts_build(&c, &a.mo, &m)) != EXIT_OK)
        return err;
    if (a.n_from != m.dim) {
        err = cli_usage_error(&c, "--from has %d value(s) but model %s has dimension %d",
                              a.n_from, m.name, m.dim);
        cm_model_release(&m);
        return err;
    }
    int status;
    if (a.json) {
        json j;
        json_begin(&j, stdout, "orbit");
        json_model(&j, &m);
        json_nums(&j, "from", a.from, m.dim);
        json_int(&j, "steps", a.steps);
        status = follow(&a, &m, NULL, &j);
        json_end(&j);
    } else if (!a.csv) {
        status = follow(&a, &m, stdout, NULL);
    } else {
        outfile o;
        status = EXIT_FAIL;
        if (outfile_open("orbit", a.csv, &o)) {
            status = follow(&a, &m, o.f, NULL);
            if (!outfile_close("orbit", &o, status == EXIT_OK))
                status = EXIT_FAIL;
        }
    }
    cm_model_release(&m);
    return status;
}
