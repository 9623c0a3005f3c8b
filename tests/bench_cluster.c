/* Benchmark of clustered SCM on the thesis' Table 4.1 experiment: two
 * neighbouring regions of the PD micro-chaos map (alpha = 0.07, beta = 0,
 * P = 0.007, D = 0.02; x in [85.4, 285.4] and [285.4, 485.4], x' in
 * [-12.5, 12.5], as in Figs. 4.26-4.28) of 0.5 to 8 million cells each.
 * Prints medians of `repeats` runs on 2 threads: SCM of one region, the join
 * of the second region into the first, the clustered total (both regions
 * solved concurrently, then joined) and SCM on the union, in ms and ns per
 * cell of the joined regions, the ratio clustered / union, and the cluster's
 * bytes per cell (cell arrays, exit tables, escape lists).
 *
 * usage: bench_cluster [repeats (default 5)] [max million cells per region (default 8)] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "cellmap/join.h"
#include "bench_util.h"
#include "models/registry.h"

static void die(const char *msg)
{
    fprintf(stderr, "bench_cluster: %s\n", msg);
    exit(1);
}

int main(int argc, char **argv)
{
    const int repeats = argc > 1 ? atoi(argv[1]) : 5;
    const double max_million = argc > 2 ? atof(argv[2]) : 8;
    if (repeats < 1 || repeats > 100)
        die("usage: bench_cluster [repeats 1..100] [max million cells per region]");
    cm_model m;
    char msg[256];
    const char *params[1] = {"alpha=0.07,beta=0,P=0.007,D=0.02"};
    if (cm_model_create("microchaos-pd", params, 1, &m, msg, sizeof msg) != CM_OK)
        die(msg);
    const double millions[] = {0.5, 1, 2, 4, 8};
    printf("%9s %9s %9s %9s %9s %9s %9s %11s %11s %6s %8s %8s\n", "cells/reg", "region_ms", "join_ms",
           "clust_ms", "union_ms", "resolved", "nodes", "join_ns/c", "clust_ns/c", "ratio", "bytes/c", "groups");
    for (int s = 0; s < 5 && millions[s] <= max_million; s++) {
        const int64_t side = (int64_t)llround(sqrt(millions[s] * 1e6));
        const cm_lattice lat = {2, {85.4, -12.5}, {200.0 / (double)side, 25.0 / (double)side}};
        const cm_box boxes[2] = {{2, {0, 0}, {side, side}}, {2, {side, 0}, {2 * side, side}}};
        const cm_box whole = {2, {0, 0}, {2 * side, side}};
        double t_region[100], t_join[100], t_clust[100], t_union[100];
        uint64_t resolved = 0, nodes = 0;
        uint32_t groups = 0;
        double bytes = 0;
        for (int k = -1; k < repeats; k++) {
            const cm_scm_options opt = {.max_steps = 1, .threads = 2, .record_exits = 1};
            const cm_scm_options plain = {.max_steps = 1, .threads = 2};
            /* one region, then the join of the second (each solved with 2 threads) */
            cm_cluster c;
            cm_region r[2];
            cm_join_stats stats;
            cm_cluster_init(&c, &lat);
            c.threads = 2;
            double t0 = now();
            for (int j = 0; j < 2; j++)
                if (cm_region_alloc(&r[j], &boxes[j], msg, sizeof msg) != CM_OK ||
                    cm_scm_solve(&m, &lat, &opt, &r[j], msg, sizeof msg) != CM_OK)
                    die(msg);
            double t1 = now();
            if (cm_cluster_join(&c, &r[0], NULL, msg, sizeof msg) != CM_OK)
                die(msg);
            double t2 = now();
            if (cm_cluster_join(&c, &r[1], &stats, msg, sizeof msg) != CM_OK)
                die(msg);
            double t3 = now();
            groups = c.ngroups;
            resolved = stats.resolved_cells;
            nodes = stats.nodes;
            bytes = (double)cm_cluster_bytes(&c);
            cm_cluster_free(&c);
            /* clustered total: regions concurrently, then joined */
            cm_cluster_init(&c, &lat);
            c.threads = 2;
            const double t4 = now();
            if (cm_cluster_solve_boxes(&c, &m, boxes, 2, &opt, NULL, NULL, NULL, msg, sizeof msg) != CM_OK)
                die(msg);
            const double t5 = now();
            cm_cluster_free(&c);
            /* SCM on the union */
            cm_region u;
            if (cm_region_alloc(&u, &whole, msg, sizeof msg) != CM_OK)
                die(msg);
            const double t6 = now();
            if (cm_scm_solve(&m, &lat, &plain, &u, msg, sizeof msg) != CM_OK)
                die(msg);
            const double t7 = now();
            if (u.ngroups != groups)
                die("the cluster and the union solve differ in their group count");
            cm_region_free(&u);
            if (k < 0)
                continue;
            t_region[k] = (t1 - t0) / 2;
            t_join[k] = (t3 - t2) + (t2 - t1);
            t_clust[k] = t5 - t4;
            t_union[k] = t7 - t6;
        }
        const double n2 = 2.0 * (double)(side * side);
        const double join = median(t_join, repeats), clust = median(t_clust, repeats),
                     uni = median(t_union, repeats);
        printf("%9lld %9.1f %9.1f %9.1f %9.1f %9llu %9llu %11.2f %11.2f %6.3f %8.2f %8u\n",
               (long long)(side * side), 1e3 * median(t_region, repeats), 1e3 * join,
               1e3 * clust, 1e3 * uni, (unsigned long long)resolved, (unsigned long long)nodes, 1e9 * join / n2,
               1e9 * clust / n2, clust / uni, bytes / n2, groups);
        fflush(stdout);
    }
    cm_model_release(&m);
    return 0;
}
