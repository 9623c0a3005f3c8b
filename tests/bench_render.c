/* Benchmark of the renderer (issue 6): a 4096x4096 figure of a 16 M-cell
 * cluster with every layer (basin shaded by step number, attractors,
 * overlays, axes, legend, title), timed as raster (cells to colours, the
 * overlays, the font), GL (OSMesa tiles), text (axes, legend, title) and
 * PNG encoding. The cluster is the thesis' 4.6.3 example (microchaos-pd,
 * alpha = 0.078, beta = 0, P = 0.007, D = 0.02 on [0, 500] x [-40, 40]) on
 * 4096 x 4096 cells, solved as 2 x 2 regions and joined. Prints medians of
 * `repeats` runs and checks that one thread draws the same bytes.
 *
 * usage: bench_render [repeats (default 5)] [directory for the PNG (default /tmp)] */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bench_util.h"
#include "cellmap/join.h"
#include "models/registry.h"
#include "render/figure.h"
#include "render/png_out.h"

enum { SIDE = 4096, MAX_REPEATS = 50 };

static void die(const char *msg)
{
    fprintf(stderr, "bench_render: %s\n", msg);
    exit(1);
}

/* The cluster, flattened, with its groups labelled. */
static void make_cells(const cm_model *m, const cm_lattice *lat, cm_region *flat,
                       cm_group_info **groups)
{
    char msg[512];
    const cm_box whole = {2, {0, 0}, {SIDE, SIDE}};
    cm_box boxes[4];
    for (int k = 0; k < 4; k++)
        boxes[k] = (cm_box){2,
                            {(k % 2) * SIDE / 2, (k / 2) * SIDE / 2},
                            {(k % 2 + 1) * SIDE / 2, (k / 2 + 1) * SIDE / 2}};
    cm_cluster c;
    cm_cluster_init(&c, lat);
    c.threads = 2;
    const cm_scm_options opt = {.max_steps = 1};
    const double t0 = now();
    if (cm_cluster_solve_boxes(&c, m, boxes, 4, &opt, NULL, NULL, NULL, msg, sizeof msg) != CM_OK ||
        cm_cluster_flatten(&c, &whole, flat, msg, sizeof msg) != CM_OK)
        die(msg);
    *groups = calloc((size_t)flat->ngroups + 1, sizeof **groups);
    if (!*groups)
        die("out of memory for groups");
    cm_scm_groups(flat, lat, *groups, NULL);
    if (cm_scm_label_groups(m, lat, flat, *groups, flat->ngroups, msg, sizeof msg) != CM_OK)
        die(msg);
    printf("cluster: %d x %d cells in 4 regions, %u groups, solved and flattened in %.2f s\n", SIDE,
           SIDE, flat->ngroups, now() - t0);
    cm_cluster_free(&c);
}

int main(int argc, char **argv)
{
    const int repeats = argc > 1 ? atoi(argv[1]) : 5;
    const char *dir = argc > 2 ? argv[2] : "/tmp";
    if (repeats < 1 || repeats > MAX_REPEATS)
        die("usage: bench_render [repeats 1..50] [directory]");
    char msg[512], path[4096];
    snprintf(path, sizeof path, "%s/bench-render-%ld.png", dir, (long)getpid());
    const char *texts[1] = {"alpha=0.078,beta=0,P=0.007,D=0.02"};
    cm_model m;
    if (cm_model_create("microchaos-pd", texts, 1, &m, msg, sizeof msg) != CM_OK)
        die(msg);
    const cm_lattice lat = {2, {0, -40}, {500.0 / SIDE, 80.0 / SIDE}};
    cm_region flat;
    cm_group_info *groups;
    make_cells(&m, &lat, &flat, &groups);

    cm_render_options ro;
    memset(&ro, 0, sizeof ro);
    ro.width = ro.height = SIDE;
    ro.layers = CM_LAYER_BASIN | CM_LAYER_STEPS | CM_LAYER_ATTRACTORS | CM_LAYER_OVERLAYS |
                CM_LAYER_AXES | CM_LAYER_LEGEND | CM_LAYER_TITLE;
    ro.model = &m;
    ro.font_path = CELLMAP_FONT_PATH;
    const size_t bytes = (size_t)SIDE * SIDE * 4;
    uint8_t *rgba = malloc(bytes), *again = malloc(bytes);
    if (!rgba || !again)
        die("out of memory for the images");
    double raster[MAX_REPEATS], gl[MAX_REPEATS], text[MAX_REPEATS], png[MAX_REPEATS],
        total[MAX_REPEATS];
    cm_render_info info;
    const cm_png_text chunk[] = {{"Software", "cellmap bench_render"}};
    for (int k = 0; k < repeats; k++) {
        const double t0 = now();
        if (cm_render_figure(&lat, &flat, groups, &ro, rgba, &info, msg, sizeof msg) != CM_OK)
            die(msg);
        const double t1 = now();
        if (cm_png_write(path, rgba, SIDE, SIDE, 0, chunk, 1, msg, sizeof msg) != CM_OK)
            die(msg);
        const double t2 = now();
        raster[k] = info.raster_s;
        gl[k] = info.gl_s;
        text[k] = info.text_s;
        png[k] = t2 - t1;
        total[k] = t2 - t0;
    }
    omp_set_num_threads(1);
    if (cm_render_figure(&lat, &flat, groups, &ro, again, &info, msg, sizeof msg) != CM_OK)
        die(msg);
    const int same = memcmp(rgba, again, bytes) == 0;
    const double cells = (double)SIDE * SIDE, t = median(total, repeats);
    printf("figure %dx%d, every layer, plot %dx%d in %d GL tile(s), %d threads; medians of %d:\n",
           SIDE, SIDE, info.plot_w, info.plot_h, info.tiles, omp_get_num_procs(), repeats);
    printf("  raster %.3f s, GL %.3f s, text %.3f s, PNG encode %.3f s; total %.3f s\n",
           median(raster, repeats), median(gl, repeats), median(text, repeats),
           median(png, repeats), t);
    struct stat st;
    const double mb = stat(path, &st) == 0 ? (double)st.st_size / 1e6 : -1;
    printf("  %.1f ns/cell; memory: raster 3 B/cell + figure 4 B/pixel; PNG file %.1f MB\n",
           1e9 * t / cells, mb);
    printf("  one thread draws the same bytes: %s\n", same ? "yes" : "NO");
    unlink(path);
    free(rgba);
    free(again);
    free(groups);
    cm_region_free(&flat);
    cm_model_release(&m);
    return same ? 0 : 1;
}
