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
            partition_json(&a, &r);
        else if (!a.out.quiet)
            partition_report(report_stream(a.out.csv, a.out.png, NULL), &r.p);
        st = partition_write(&a, &r, msg, sizeof msg);
    }
    return analysis_said(c.cmd, st, msg);
}

