#include <stdio.h>
#include <string.h>

#include "models/registry.h"
#include "src/args.h"
#include "src/commands.h"

static const char orbit_help[] =
    "usage: cellmap orbit --model NAME [--param k=v[,k=v]] --from X[,Y...] --steps N\n\n"
    "Prints the orbit x_0 .. x_N as CSV (j,x0,x1,...) with %.17g, so any\n"
    "implementation can be checked against it. Stops early (exit 0) when the\n"
    "map has no image (the sink); the last line then says so in a comment.\n";

int cmd_orbit(int argc, char **argv)
{
    cli c = {"orbit", argc, argv, 0, NULL, NULL};
    model_opts mo = {"microchaos-pd", {0}, 0};
    double from[CM_MAX_DIM];
    int n_from = 0, err = 0;
    int64_t steps = -1;
    while (cli_next(&c) && !err) {
        if (strcmp(c.opt, "--help") == 0) {
            fputs(orbit_help, stdout);
            return EXIT_OK;
        } else if (model_opts_take(&c, &mo, &err)) {
        } else if (cli_is(&c, "--from", true, &err)) {
            if (c.value && !parse_doubles(c.value, from, &n_from, CM_MAX_DIM))
                err =
                    cli_usage_error(&c, "--from: '%s' is not a list of numbers X[,Y...]", c.value);
        } else if (cli_is(&c, "--steps", true, &err)) {
            if (c.value && (!parse_int64(c.value, &steps) || steps < 0 || steps > 100000000))
                err = cli_usage_error(&c, "--steps: '%s' must be an integer in 0..1e8", c.value);
        } else {
            err = cli_usage_error(&c, "unknown option '%s'", c.opt);
        }
    }
    if (err)
        return err;
    if (n_from == 0 || steps < 0)
        return cli_usage_error(&c, "--from and --steps are required");
    cm_model m;
    if ((err = model_opts_build(&c, &mo, &m)) != EXIT_OK)
        return err;
    if (n_from != m.dim) {
        cm_model_release(&m);
        return cli_usage_error(&c, "--from has %d value(s) but model %s has dimension %d", n_from,
                               m.name ? m.name : mo.name, m.dim);
    }
    double x[CM_MAX_DIM], y[CM_MAX_DIM];
    memcpy(x, from, sizeof x);
    printf("j");
    for (int d = 0; d < m.dim; d++)
        printf(",x%d", d);
    printf("\n");
    int status = EXIT_OK;
    for (int64_t j = 0; j <= steps; j++) {
        printf("%lld", (long long)j);
        for (int d = 0; d < m.dim; d++)
            printf(",%.17g", x[d]);
        printf("\n");
        if (j == steps)
            break;
        const int rc = m.step(&m, x, y);
        if (rc > 0) {
            printf("# no image after step %lld (the sink)\n", (long long)j);
            break;
        }
        if (rc < 0) {
            fprintf(stderr, "cellmap orbit: the model aborted at step %lld\n", (long long)j);
            status = EXIT_FAIL;
            break;
        }
        memcpy(x, y, sizeof x);
    }
    cm_model_release(&m);
    return status;
}
