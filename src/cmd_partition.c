/* cellmap partition: the delay micro-chaos map's proof of chaos (thesis
 * 4.4.2, App. C.3, Fig. 4.11): the partition of its attractor in domain
 * '01', the transition matrix (4.52), irreducibility and primitivity. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "models/delay_partition.h"
#include "models/params.h"
#include "src/args.h"
#include "src/figure_opts.h"
#include "src/commands.h"
#include "lib/json.h"
#include "src/outfile.h"
#include "lib/param_grid.h"

static const char partition_help[] =
    "usage: cellmap partition [--model microchaos-delay] [--param k=v[,k=v]] [--csv FILE|-]\n"
    "                         [--png FILE] [--size WxH] [--json] [--quiet]\n\n"
    "The proof of chaos for the delay micro-chaos map x_(j+1) = a x_j - b Int(x_(j-1))\n"
    "(thesis 4.4.2, App. C.3, docs/models.md 5.3), in the parameter domain '01' where\n"
    "its attractor is two truncated branches, on U_1 (lower) and U_0 (upper): the\n"
    "partition of Fig. 4.11 (the basic regions B^L = (a - b, 1), B^U = (1, a) and their\n"
    "pre-images), the transition matrix (4.52), P_ij = 1 where the closure of f(I_i)\n"
    "covers I_j, and whether it is irreducible and primitive (the smallest N with\n"
    "every entry of P^N positive). Fig. 4.11: --param a=1.3,b=0.66.\n\n"
    "  --csv FILE|-        the regions: index, branch, x_(j-1) range, and the matrix's row\n"
    "  --png FILE          the attractor in (x_(j-1), x_j), its regions in alternating\n"
    "                      colours, with the lines x_(j-1) = 1 (Fig. 4.11)\n"
    "  --size WxH          image size (default 900x700)\n"
    "  --json              the partition as JSON on standard output\n"
    "  --quiet             no summary\n";

typedef struct part_args {
    model_opts mo;
    chart_outputs out;
} part_args;

static int parse_args(cli *c, part_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(partition_help, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (chart_outputs_take(c, &a->out, 300, 200, &err)) {
        } else {
            err = cli_stray(c);
        }
    }
    if (!err)
        err = chart_outputs_check(c, &a->out);
    return err;
}

static void row_text(const cm_delay_partition *p, int i, char *out)
{
    for (int j = 0; j < p->r; j++)
        out[j] = (char)('0' + p->P[i][j]);
    out[p->r] = '\0';
}

static bool write_csv(const part_args *a, const cm_delay_partition *p)
{
    outfile o;
    if (!outfile_open("partition", a->out.csv, &o))
        return false;
    fprintf(o.f, "region,branch,lo,hi,row\n");
    char row[CM_DELAY_MAX_REGIONS + 1];
    for (int i = 0; i < p->r; i++) {
        row_text(p, i, row);
        fprintf(o.f, "%d,%s,%.17g,%.17g,%s\n", i + 1, p->branch[i] ? "lower" : "upper", p->lo[i],
                p->hi[i], row);
    }
    return outfile_close("partition", &o, true);
}

static bool write_png(const part_args *a, const cm_delay_partition *p, const char *params)
{
    double x[2][2 * CM_DELAY_MAX_REGIONS], y[2][2 * CM_DELAY_MAX_REGIONS];
    size_t n[2] = {0, 0};
    double top = 0, bottom = 0;
    for (int i = 0; i < p->r; i++) {
        const int c = i % 2, k = p->branch[i];
        for (int e = 0; e < 2; e++) {
            const double s = e ? p->hi[i] : p->lo[i];
            x[c][n[c]] = s;
            y[c][n[c]++] = p->a * s - p->b * k;
            top = fmax(top, p->a * s - p->b * k);
            bottom = fmin(bottom, p->a * s - p->b * k);
        }
    }
    const double one_x[2] = {1, 1}, one_y[2] = {bottom - 0.1, top + 0.1};
    const cm_rgb red = {215, 48, 39}, blue = {69, 117, 180}, grey = {150, 150, 150};
    const cm_series series[] = {
        {CM_SERIES_SEGMENTS, one_x, one_y, 2, grey, 1},
        {CM_SERIES_SEGMENTS, x[0], y[0], n[0], red, 4},
        {CM_SERIES_SEGMENTS, x[1], y[1], n[1], blue, 4},
    };
    char title[600];
    snprintf(title, sizeof title,
             "partition I_1..I_%d (alternating colours), x_(j-1) = 1 grey; %s",
             p->r, params);
    const cm_chart chart = {a->out.width,
                            a->out.height,
                            {p->x_l - 0.1, bottom - 0.1},
                            {p->x_r + 0.1, top + 0.1},
                            "x_(j-1)",
                            "x_j",
                            title,
                            NULL,
                            series,
                            3,
                            figure_font(),
                            0,
                            NULL,
                            0};
    const cm_png_text texts[] = {{"Model", a->mo.name}, {"Parameters", params}};
    return write_chart_png("partition", a->out.png, &chart, 1, texts, 2);
}

int cmd_partition(int argc, char **argv)
{
    cli c = {"partition", argc, argv, 0, NULL, NULL};
    part_args a = {.mo = {.name = "microchaos-delay"}, .out = {.width = 900, .height = 700}};
    const int perr = parse_args(&c, &a);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    const int werr = chart_outputs_writable(&c, &a.out);
    if (werr != EXIT_OK)
        return werr;
    cm_params base;
    const int verr = sweep_check(&c, &a.mo, "microchaos-delay", NULL, 0, &base);
    if (verr)
        return verr;
    cm_delay_partition p;
    char why[300];
    if (!cm_delay_partition_01(cm_params_get(&base, "a"), cm_params_get(&base, "b"), &p, why,
                               sizeof why)) {
        fprintf(stderr, "cellmap partition: %s; e.g. --param a=1.3,b=0.66 (Fig. 4.11)\n", why);
        return EXIT_USAGE;
    }
    char params[400], row[CM_DELAY_MAX_REGIONS + 1];
    cm_params_format(&base, params, sizeof params);
    if (a.out.json) {
        json j;
        json_begin(&j, stdout, "partition");
        param_base_json(&j, a.mo.name, &base);
        json_nums(&j, "ends", (const double[2]){p.x_l, p.x_r}, 2);
        json_array(&j, "regions");
        for (int i = 0; i < p.r; i++) {
            row_text(&p, i, row);
            json_object(&j, NULL);
            json_str(&j, "branch", p.branch[i] ? "lower" : "upper");
            json_nums(&j, "range", (const double[2]){p.lo[i], p.hi[i]}, 2);
            json_str(&j, "row", row);
            json_object_end(&j);
        }
        json_array_end(&j);
        json_bool(&j, "irreducible", p.irreducible);
        json_int(&j, "primitive_index", p.primitive_index);
        json_end(&j);
    } else if (!a.out.quiet) {
        FILE *f = report_stream(a.out.csv, a.out.png, NULL);
        fprintf(f, "%d regions on the branches x_j = a x_(j-1) (upper) and a x_(j-1) - b "
                   "(lower), x_(j-1) in (%.9g, %.9g):\n",
                p.r, p.x_l, p.x_r);
        for (int i = 0; i < p.r; i++) {
            row_text(&p, i, row);
            fprintf(f, "  I_%-2d %s (%.9g, %.9g)  %s\n", i + 1, p.branch[i] ? "lower" : "upper",
                    p.lo[i], p.hi[i], row);
        }
        if (p.primitive_index)
            fprintf(f, "irreducible and primitive: every entry of P^%d is positive (r^2 - r = "
                       "%d)\n",
                    p.primitive_index, p.r * p.r - p.r);
        else
            fprintf(f, "%s, not primitive\n", p.irreducible ? "irreducible" : "not irreducible");
    }
    bool ok = true;
    if (a.out.csv)
        ok = write_csv(&a, &p);
    if (ok && a.out.png)
        ok = write_png(&a, &p, params);
    return ok ? EXIT_OK : EXIT_FAIL;
}
