#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "models/registry.h"
#include "src/args.h"
#include "src/commands.h"

static const char fp_help[] =
    "usage: cellmap fixed-points --model NAME [--param k=v[,k=v]] [--range M0:M1]\n\n"
    "Prints, for every control level m in M0..M1 (default -10:10), the candidate\n"
    "fixed point x_m* as CSV: level,band,kind,x0,x1,... where band is the level\n"
    "actually produced at the point and kind is 'regular' (band = level) or\n"
    "'virtual' (thesis (4.16)-(4.17), docs/models.md 2.4).\n";

int cmd_fixed_points(int argc, char **argv)
{
    cli c = {"fixed-points", argc, argv, 0, NULL, NULL};
    model_opts mo = {"microchaos-pd", {0}, 0};
    int64_t m0 = -10, m1 = 10;
    int err = 0;
    while (cli_next(&c) && !err) {
        if (strcmp(c.opt, "--help") == 0) {
            fputs(fp_help, stdout);
            return EXIT_OK;
        } else if (model_opts_take(&c, &mo, &err)) {
        } else if (cli_is(&c, "--range", true, &err)) {
            const char *colon = c.value ? strchr(c.value, ':') : NULL;
            char lo[64];
            if (c.value && (!colon || (size_t)(colon - c.value) >= sizeof lo))
                err = cli_usage_error(&c, "--range: '%s' is not M0:M1", c.value);
            else if (c.value) {
                snprintf(lo, sizeof lo, "%.*s", (int)(colon - c.value), c.value);
                if (!parse_int64(lo, &m0) || !parse_int64(colon + 1, &m1) || m0 > m1 ||
                    m0 < -(INT64_C(1) << 50) || m1 > (INT64_C(1) << 50) || m1 - m0 > 1000000)
                    err = cli_usage_error(
                        &c, "--range: '%s' must be integers M0 <= M1, at most 1e6 levels", c.value);
            }
        } else {
            err = cli_usage_error(&c, "unknown option '%s'", c.opt);
        }
    }
    if (err)
        return err;
    cm_model m;
    if ((err = model_opts_build(&c, &mo, &m)) != EXIT_OK)
        return err;
    if (!m.fixed_points) {
        fprintf(stderr, "cellmap fixed-points: model %s has no fixed-point formula\n", m.name);
        cm_model_release(&m);
        return EXIT_FAIL;
    }
    const size_t cap = (size_t)(m1 - m0 + 1) * 3; /* friction models list up to 3 per level */
    cm_fixed_point *fps = malloc(cap * sizeof *fps);
    size_t n = 0;
    char msg[512] = "";
    int status = EXIT_OK;
    if (!fps) {
        fprintf(stderr, "cellmap fixed-points: out of memory\n");
        status = EXIT_FAIL;
    } else if (m.fixed_points(&m, m0, m1, fps, cap, &n, msg, sizeof msg) != 0) {
        fprintf(stderr, "cellmap fixed-points: %s\n", msg);
        status = EXIT_FAIL;
    } else {
        printf("level,band,kind");
        for (int d = 0; d < m.dim; d++)
            printf(",x%d", d);
        printf("\n");
        for (size_t i = 0; i < n; i++) {
            printf("%lld,%lld,%s", (long long)fps[i].level, (long long)fps[i].band,
                   fps[i].regular ? "regular" : "virtual");
            for (int d = 0; d < m.dim; d++)
                printf(",%.17g", fps[i].x[d]);
            printf("\n");
        }
    }
    free(fps);
    cm_model_release(&m);
    return status;
}
