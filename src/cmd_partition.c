/* cellmap partition: the delay micro-chaos map's proof of chaos (thesis
 * 4.4.2, App. C.3, Fig. 4.11): the partition of its attractor in domain
 * '01', the transition matrix (4.52), irreducibility and primitivity. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/partition.h"
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

/* The summary: the regions, their rows and whether the matrix is primitive. */
static void print_summary(FILE *f, const cm_delay_partition *p)
{
    char row[CM_DELAY_MAX_REGIONS + 1];
    fprintf(f, "%d regions on the branches x_j = a x_(j-1) (upper) and a x_(j-1) - b "
               "(lower), x_(j-1) in (%.9g, %.9g):\n",
            p->r, p->x_l, p->x_r);
    for (int i = 0; i < p->r; i++) {
        partition_row_text(p, i, row);
        fprintf(f, "  I_%-2d %s (%.9g, %.9g)  %s\n", i + 1, p->branch[i] ? "lower" : "upper",
                p->lo[i], p->hi[i], row);
    }
    if (p->primitive_index)
        fprintf(f, "irreducible and primitive: every entry of P^%d is positive (r^2 - r = "
                   "%d)\n",
                p->primitive_index, p->r * p->r - p->r);
    else
        fprintf(f, "%s, not primitive\n", p->irreducible ? "irreducible" : "not irreducible");
}

static void print_json(const part_args *a, const part_result *r)
{
    const cm_delay_partition *p = &r->p;
    char row[CM_DELAY_MAX_REGIONS + 1];
    json j;
    json_begin(&j, stdout, "partition");
    param_base_json(&j, a->mo.name, &r->base);
    json_nums(&j, "ends", (const double[2]){p->x_l, p->x_r}, 2);
    json_array(&j, "regions");
    for (int i = 0; i < p->r; i++) {
        partition_row_text(p, i, row);
        json_object(&j, NULL);
        json_str(&j, "branch", p->branch[i] ? "lower" : "upper");
        json_nums(&j, "range", (const double[2]){p->lo[i], p->hi[i]}, 2);
        json_str(&j, "row", row);
        json_object_end(&j);
    }
    json_array_end(&j);
    json_bool(&j, "irreducible", p->irreducible);
    json_int(&j, "primitive_index", p->primitive_index);
    json_end(&j);
}

int cmd_partition(int argc, char **argv)
{
    cli c = {"partition", argc, argv, 0, NULL, NULL};
    part_args a = partition_defaults();
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
    char msg[1024];
    part_result r;
    cm_status st = partition_compute(&a, &r, msg, sizeof msg);
    if (st == CM_OK) {
        if (a.out.json)
            print_json(&a, &r);
        else if (!a.out.quiet)
            print_summary(report_stream(a.out.csv, a.out.png, NULL), &r.p);
        st = partition_write(&a, &r, msg, sizeof msg);
    }
    return analysis_said(c.cmd, st, msg);
}

