/* Benchmark of the renderer (issues 6 and 51). Figures of the thesis'
 * 4.6.3 example (microchaos-pd, alpha = 0.078, beta = 0, P = 0.007, D =
 * 0.02 on [0, 500] x [-40, 40]), solved as 2 x 2 regions and joined:
 *   - 4096 x 4096 cells in a 4096 x 4096 figure with every layer (basin
 *     shaded by step number, attractors, overlays, axes, legend, title),
 *     GL opened for the figure as a one-off command does;
 *   - 1000 x 1000 cells in a 1000 x 1000 figure with every layer, with a
 *     kept GL context (as an explore session keeps one), and as the bare
 *     raster (--layers basin), which needs no GL.
 * Each is timed as raster (cells to colours, the overlays, the font), plot
 * (the raster drawn, and GL's lines where there are any), text (axes,
 * legend, title) and PNG encoding. Prints medians and ranges of `repeats`
 * runs and checks that one thread draws the same bytes.
 *
 * usage: bench_render [repeats (default 5)] [directory for the PNG (default /tmp)] */
#include <omp.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bench_util.h"
#include "cellmap/join.h"
#include "models/registry.h"
#include "render/figure.h"
#include "render/gl.h"
#include "render/png_out.h"

enum { MAX_REPEATS = 50 };

static void die(const char *msg)
{
    fprintf(stderr, "bench_render: %s\n", msg);
    exit(1);
}

/* The cluster, flattened, with its groups labelled. */
static void make_cells(const cm_model *m, const cm_lattice *lat, int side, cm_region *flat,
                       cm_group_info **groups)
{
    char msg[512];
    const cm_box whole = {2, {0, 0}, {side, side}};
    cm_box boxes[4];
    for (int k = 0; k < 4; k++)
        boxes[k] = (cm_box){2,
                            {(k % 2) * side / 2, (k / 2) * side / 2},
                            {(k % 2 + 1) * side / 2, (k / 2 + 1) * side / 2}};
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
    printf("cluster: %d x %d cells in 4 regions, %u groups, solved and flattened in %.2f s\n", side,
           side, flat->ngroups, now() - t0);
    cm_cluster_free(&c);
}

#define ALL_LAYERS                                                                           \
    (CM_LAYER_BASIN | CM_LAYER_STEPS | CM_LAYER_ATTRACTORS | CM_LAYER_OVERLAYS | CM_LAYER_AXES | \
     CM_LAYER_LEGEND | CM_LAYER_TITLE)

typedef struct figure_case {
    const char *name;
    int side;       /* cells and pixels a side */
    unsigned layers;
    bool keep_gl;   /* a GL context kept across the figures */
} figure_case;

static void print_times(const char *what, double *v, int n)
{
    double lo = v[0], hi = v[0];
    for (int k = 1; k < n; k++)
        lo = v[k] < lo ? v[k] : lo, hi = v[k] > hi ? v[k] : hi;
    printf("  %-10s %8.1f ms (%.1f..%.1f)\n", what, 1e3 * median(v, n), 1e3 * lo, 1e3 * hi);
}

/* Draws and encodes the case's figure `repeats` times; false when one
 * thread draws other bytes. */
static bool bench_case(const figure_case *fc, int repeats, const char *dir)
{
    char msg[512], path[4096];
    snprintf(path, sizeof path, "%s/bench-render-%ld.png", dir, (long)getpid());
    const char *texts[1] = {"alpha=0.078,beta=0,P=0.007,D=0.02"};
    cm_model m;
    if (cm_model_create("microchaos-pd", texts, 1, &m, msg, sizeof msg) != CM_OK)
        die(msg);
    const cm_lattice lat = {2, {0, -40}, {500.0 / fc->side, 80.0 / fc->side}};
    cm_region flat;
    cm_group_info *groups;
    make_cells(&m, &lat, fc->side, &flat, &groups);
    cm_render_options ro;
    memset(&ro, 0, sizeof ro);
    ro.width = ro.height = fc->side;
    ro.layers = fc->layers;
    ro.model = &m;
    ro.font_path = CELLMAP_FONT_PATH;
    if (fc->keep_gl && cm_gl_open(&ro.gl, msg, sizeof msg) != CM_OK)
        die(msg);
    const size_t bytes = (size_t)fc->side * (size_t)fc->side * 4;
    uint8_t *rgba = malloc(bytes), *again = malloc(bytes);
    if (!rgba || !again)
        die("out of memory for the images");
    double raster[MAX_REPEATS], plot[MAX_REPEATS], text[MAX_REPEATS], png[MAX_REPEATS],
        total[MAX_REPEATS];
    cm_render_info info;
    const cm_png_text chunk[] = {{"Software", "cellmap bench_render"}};
    for (int k = 0; k < repeats; k++) {
        const double t0 = now();
        if (cm_render_figure(&lat, &flat, groups, &ro, rgba, &info, msg, sizeof msg) != CM_OK)
            die(msg);
        const double t1 = now();
        if (cm_png_write(path, rgba, fc->side, fc->side, 0, chunk, 1, msg, sizeof msg) != CM_OK)
            die(msg);
        const double t2 = now();
        raster[k] = info.raster_s;
        plot[k] = info.gl_s;
        text[k] = info.text_s;
        png[k] = t2 - t1;
        total[k] = t2 - t0;
    }
    const int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    if (cm_render_figure(&lat, &flat, groups, &ro, again, &info, msg, sizeof msg) != CM_OK)
        die(msg);
    omp_set_num_threads(threads);
    const bool same = memcmp(rgba, again, bytes) == 0;
    struct stat st;
    const double mb = stat(path, &st) == 0 ? (double)st.st_size / 1e6 : -1;
    printf("%s: %dx%d figure, plot %dx%d in %d GL tile(s), %d threads; medians (ranges) of %d:\n",
           fc->name, fc->side, fc->side, info.plot_w, info.plot_h, info.tiles, threads, repeats);
    print_times("raster", raster, repeats);
    print_times("plot", plot, repeats);
    print_times("text", text, repeats);
    print_times("PNG", png, repeats);
    print_times("total", total, repeats);
    printf("  %.1f ns/cell, PNG file %.2f MB; one thread draws the same bytes: %s\n",
           1e9 * median(total, repeats) / ((double)fc->side * fc->side), mb, same ? "yes" : "NO");
    unlink(path);
    free(rgba);
    free(again);
    free(groups);
    cm_region_free(&flat);
    cm_gl_close(ro.gl);
    cm_model_release(&m);
    return same;
}

int main(int argc, char **argv)
{
    const int repeats = argc > 1 ? atoi(argv[1]) : 5;
    const char *dir = argc > 2 ? argv[2] : "/tmp";
    if (repeats < 1 || repeats > MAX_REPEATS)
        die("usage: bench_render [repeats 1..50] [directory]");
    const figure_case cases[] = {
        {"4096, every layer, GL opened for it", 4096, ALL_LAYERS, false},
        {"1000, every layer, GL kept", 1000, ALL_LAYERS, true},
        {"1000, bare raster", 1000, CM_LAYER_BASIN, false},
    };
    bool same = true;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++)
        same = bench_case(&cases[k], repeats, dir) && same;
    return same ? 0 : 1;
}
