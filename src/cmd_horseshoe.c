/* cellmap horseshoe: the Smale horseshoes of the PD-controlled micro-chaos
 * map at its switching lines (thesis 4.5.3, Figs. 4.15-4.19): the
 * trapezoids L and R, the four escape conditions of a full binary shift,
 * attractor or repeller, and the periodic points of the restricted maps,
 * whose growth bounds the topological entropy from below; at one parameter
 * point or along a sweep of P (Fig. 4.17). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/horseshoe.h"
#include "src/args.h"
#include "src/figure_opts.h"
#include "src/commands.h"
#include "src/outfile.h"
#include "lib/param_grid.h"

static const char horseshoe_help[] =
    "usage: cellmap horseshoe [--model microchaos-pd] [--param k=v[,k=v]] [--m M0:M1]\n"
    "                         [--periods N] [--sweep P=LO:HI:K [--crisis]] [--images K]\n"
    "                         [--preimages K] [--plane D=LO:HI:K] [--csv FILE|-]\n"
    "                         [--png FILE] [--size WxH] [--json] [--quiet]\n\n"
    "The horseshoes of the PD micro-chaos map (thesis 4.5.3, docs/models.md 6.6): at\n"
    "each switching line SW_m the parallelogram Q_m between the fixed points x_(m-1)*\n"
    "and x_m*, bounded by their stable and unstable manifolds and cut by SW_m into\n"
    "the trapezoids L and R; the four escape conditions (f_l of the corners LUSW and\n"
    "RUSW right of W_R^S, f_r of them left of W_L^S): any of them, and an image leaves\n"
    "Q_m (a repeller; none: an attractor); all four, and the map on Q_m is conjugate\n"
    "to a full binary shift. N_n, the points of period n whose orbits follow their\n"
    "symbols (the band left or right of SW_m) inside Q_m, gives the lower estimate\n"
    "log(N_n)/n of the topological entropy: log 2 on a full horseshoe.\n\n"
    "  --m M0:M1           the switching lines, 1 <= M0 <= M1 (default 1 to m_max, 4.76)\n"
    "  --periods N         the period of the estimate, 1..20 (default 12)\n"
    "  --sweep P=LO:HI:K   the entropy estimate against P (Fig. 4.17), at each m\n"
    "  --crisis            with --sweep: the PNG is the crisis chart of Fig. 4.20 instead:\n"
    "                      at each P and SW_m, an attractor (green), or a repeller whose\n"
    "                      orbits escape away from the origin (Out: red), towards it (In:\n"
    "                      blue) or both (purple); beyond m_max (4.76) nothing (grey)\n"
    "  --csv FILE|-        per m (and P): the corners, the escape conditions, attractor\n"
    "                      or repeller, full shift, N_n and the entropy estimate\n"
    "  --png FILE          one point: L and R (red, blue), their images f_l(L), f_r(R)\n"
    "                      and the switching lines (Figs. 4.15, 4.16); a sweep: the\n"
    "                      entropy estimate against P per m (Fig. 4.17)\n"
    "  --plane D=LO:HI:K   with --sweep: the PNG is the P-D plane instead, where each SW_m\n"
    "                      is a full binary shift and its escape conditions' lines\n"
    "                      (Fig. 4.19; the CSV and JSON stay the sweep's)\n"
    "  --images K          one point: draw the K-th images of L and R instead, 1..6:\n"
    "                      f applied to the parts of the previous ones in Q_m\n"
    "  --preimages K       one point: also the points of Q_m that reach L (dark red) or\n"
    "                      R (dark blue) in K steps inside Q_m, 0..6 (Fig. 4.18: 3, 2)\n"
    "  --size WxH          image size (default 1000x600)\n"
    "  --json              the summary as JSON on standard output\n"
    "  --quiet             no summary\n";

static int parse_args(cli *c, hs_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(horseshoe_help, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (cli_is(c, "--m", true, &err)) {
            long long lo, hi;
            char tail;
            if (c->value && (sscanf(c->value, "%lld:%lld%c", &lo, &hi, &tail) != 2 || lo < 1 ||
                             hi < lo || hi - lo > 1000))
                err = cli_usage_error(c, "--m: '%s' is not M0:M1 with 1 <= M0 <= M1 <= M0 + 1000",
                                      c->value);
            else if (c->value)
                a->m0 = lo, a->m1 = hi;
            a->has_m = 1;
        } else if (cli_take_int(c, "--periods", 1, 20, &a->periods, &err)) {
        } else if (cli_take_int(c, "--images", 1, CM_STRIP_MAX_STEPS, &a->images, &err)) {
        } else if (cli_take_int(c, "--preimages", 0, CM_STRIP_MAX_STEPS, &a->preimages, &err)) {
        } else if (cli_is(c, "--crisis", false, &err)) {
            a->crisis = 1;
        } else if (cli_is(c, "--sweep", true, &err)) {
            if (c->value && (!param_axis_parse(c->value, strlen(c->value), &a->sweep) ||
                             strcmp(a->sweep.name, "P") != 0 || a->sweep.n > 10000 ||
                             !param_axis_even(&a->sweep)))
                err = cli_usage_error(c, "--sweep: '%s' is not P=LO:HI:K with LO < HI and "
                                         "1 <= K <= 10000",
                                      c->value);
            a->has_sweep = 1;
        } else if (cli_is(c, "--plane", true, &err)) {
            if (c->value && (!param_axis_parse(c->value, strlen(c->value), &a->plane) ||
                             strcmp(a->plane.name, "D") != 0 || a->plane.n > 10000 ||
                             a->plane.n < 2 || !param_axis_even(&a->plane)))
                err = cli_usage_error(c, "--plane: '%s' is not D=LO:HI:K with LO < HI and "
                                         "2 <= K <= 10000", c->value);
            a->has_plane = 1;
        } else if (chart_outputs_take(c, &a->out, 300, 200, &err)) {
        } else {
            err = cli_stray(c);
        }
    }
    if (!err)
        err = chart_outputs_check(c, &a->out);
    if (!err && a->has_plane && (!a->has_sweep || a->crisis))
        err = cli_usage_error(c, "--plane charts the P-D plane: give --sweep P=LO:HI:K too, "
                                 "without --crisis");
    if (!err && a->crisis && !a->has_sweep)
        err = cli_usage_error(c, "--crisis charts a sweep: give --sweep P=LO:HI:K too");
    return err;
}

int cmd_horseshoe(int argc, char **argv)
{
    cli c = {"horseshoe", argc, argv, 0, NULL, NULL};
    hs_args a = horseshoe_defaults();
    const int perr = parse_args(&c, &a);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    const int werr = chart_outputs_writable(&c, &a.out);
    if (werr != EXIT_OK)
        return werr;
    cm_params base;
    const int verr =
        sweep_check(&c, &a.mo, "microchaos-pd", a.has_sweep ? &a.sweep : NULL, a.has_sweep, &base);
    if (verr)
        return verr;
    char msg[1024];
    hs_result r;
    cm_status st = horseshoe_compute(&a, &r, msg, sizeof msg);
    if (st == CM_OK) {
        if (a.out.json) {
            horseshoe_json(&a, &r);
        } else if (!a.out.quiet) {
            FILE *f = report_stream(a.out.csv, a.out.png, NULL);
            if (a.has_sweep)
                fprintf(f, "%d values of P at SW_%lld..%lld\n", a.sweep.n, (long long)a.m0,
                        (long long)a.m1);
            else
                for (int i = 0; i < r.count; i++)
                    horseshoe_report_item(f, &a, &r.items[i]);
        }
        st = horseshoe_write(&a, &r, msg, sizeof msg);
    }
    horseshoe_result_free(&r);
    return analysis_said(c.cmd, st, msg);
}
