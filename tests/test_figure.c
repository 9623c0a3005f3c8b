/* Figures against what is known analytically: switching lines through
 * x = m/P (docs/models.md 6.4), regular and virtual fixed points (Fig. 4.13's
 * parameters: x_3* is virtual), markers at the periodic cells, basin colours
 * cell by cell (also across GL tiles), the 1-D graph, determinism across
 * thread counts, and indexed PNGs read back with libpng. */
#include <math.h>
#include <omp.h>
#include <png.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cellmap/scm.h"
#include "check.h"
#include "models/registry.h"
#include "render/figure.h"
#include "render/palette.h"
#include "render/png_out.h"
#include "render/svg.h"

static const cm_rgb white = {255, 255, 255};

typedef struct scene {
    cm_model m;
    cm_lattice lat;
    cm_region r;
    cm_group_info *g;
    uint8_t *classes;
} scene;

/* The groups' colours as a figure of the whole region draws them with
 * `reach` cells per pixel (render/raster.h): the neighbour rule depends on
 * which basins touch at that resolution. */
static void scene_colours(scene *s, uint32_t reach)
{
    char msg[256];
    cm_slice sl;
    cm_raster ras;
    cm_slice_of(&s->lat, &s->r, NULL, 0, &sl);
    CHECK(cm_raster_build(&s->lat, &s->r, s->g, &sl, CM_RASTER_BASIN, 0, NULL, &ras, msg,
                          sizeof msg) == CM_OK);
    CHECK(cm_raster_paint(&s->lat, &s->r, s->g, reach, reach, &ras, msg, sizeof msg) == CM_OK);
    memcpy(s->classes, ras.classes + 1, s->r.ngroups);
    cm_raster_free(&ras);
}

static void solve(scene *s, const char *model, const char *params, const cm_lattice *lat,
                  const cm_box *box)
{
    char msg[256];
    const char *texts[1] = {params};
    memset(s, 0, sizeof *s);
    CHECK(cm_model_create(model, texts, 1, &s->m, msg, sizeof msg) == CM_OK);
    s->lat = *lat;
    CHECK(cm_region_alloc(&s->r, box, msg, sizeof msg) == CM_OK);
    const cm_scm_options opt = {.max_steps = 1};
    CHECK(cm_scm_solve(&s->m, lat, &opt, &s->r, msg, sizeof msg) == CM_OK);
    s->g = calloc(s->r.ngroups + 1, sizeof *s->g);
    cm_scm_groups(&s->r, lat, s->g, NULL);
    s->classes = calloc(s->r.ngroups + 1, 1);
    scene_colours(s, 1);
}

static void scene_free(scene *s)
{
    free(s->g);
    free(s->classes);
    cm_region_free(&s->r);
    cm_model_release(&s->m);
}

static cm_status draw(const scene *s, cm_render_options *ro, uint8_t **rgba, cm_render_info *info)
{
    char msg[256];
    free(*rgba);
    *rgba = calloc((size_t)ro->width * (size_t)ro->height, 4);
    ro->model = &s->m;
    ro->font_path = CELLMAP_FONT_PATH;
    const cm_status st = cm_render_figure(&s->lat, &s->r, s->g, ro, *rgba, info, msg, sizeof msg);
    if (st != CM_OK)
        fprintf(stderr, "render: %s\n", msg);
    return st;
}

static const uint8_t *at(const uint8_t *rgba, int w, int i, int j)
{
    return rgba + 4 * ((size_t)j * (size_t)w + (size_t)i);
}

static bool is(const uint8_t *p, cm_rgb c) { return p[0] == c.r && p[1] == c.g && p[2] == c.b; }

/* The pixel of state point (x, y) in the plot. */
static void pixel_of(const cm_render_info *f, double x, double y, int *i, int *j)
{
    *i = f->plot_x + (int)floor((x - f->lo[0]) / (f->hi[0] - f->lo[0]) * f->plot_w);
    *j = f->plot_y + (int)floor((f->hi[1] - y) / (f->hi[1] - f->lo[1]) * f->plot_h);
}

/* Whether a pixel within r of (i, j) has colour c. */
static bool near(const uint8_t *rgba, int w, int h, int i, int j, int r, cm_rgb c)
{
    for (int y = j - r; y <= j + r; y++)
        for (int x = i - r; x <= i + r; x++)
            if (x >= 0 && y >= 0 && x < w && y < h && is(at(rgba, w, x, y), c))
                return true;
    return false;
}

static cm_rgb cell_colour(const scene *s, uint64_t k)
{
    const uint32_t grp = s->r.group[k];
    return grp == 0 ? cm_colour_sink : cm_class_colour(NULL, s->classes[grp - 1]);
}

/* Every pixel whose centre is not within `margin` pixels of a cell border
 * has its cell's colour (the plot shows the region's box exactly). */
static int wrong_pixels(const scene *s, const uint8_t *rgba, int w, int h, double margin)
{
    const uint64_t nx = (uint64_t)(s->r.box.hi[0] - s->r.box.lo[0]);
    const uint64_t ny = (uint64_t)(s->r.box.hi[1] - s->r.box.lo[1]);
    int wrong = 0;
    for (int j = 0; j < h; j++) {
        const double cy = (h - j - 0.5) * (double)ny / h; /* in cells, from the bottom */
        if (fabs(cy - round(cy)) * h / (double)ny < margin)
            continue;
        for (int i = 0; i < w; i++) {
            const double cx = (i + 0.5) * (double)nx / w;
            if (fabs(cx - round(cx)) * w / (double)nx < margin)
                continue;
            const uint64_t k = (uint64_t)cy * nx + (uint64_t)cx;
            wrong += !is(at(rgba, w, i, j), cell_colour(s, k));
        }
    }
    return wrong;
}

static void test_pd_figure(void)
{
    /* Fig. 4.13's parameters on -8..8 x -4..4, 0.02 per cell */
    scene s;
    const cm_lattice lat = {2, {-8, -4}, {0.02, 0.02}};
    const cm_box box = {2, {0, 0}, {800, 400}};
    solve(&s, "microchaos-pd", "alpha=0.8,beta=0.3,P=0.9,D=0.4", &lat, &box);
    uint8_t *a = NULL, *b = NULL;
    cm_render_info fa, fb;
    cm_render_options ro;
    memset(&ro, 0, sizeof ro);
    ro.width = 800;
    ro.height = 400;

    /* basin layer: every pixel is its cell's colour */
    ro.layers = CM_LAYER_BASIN;
    CHECK(draw(&s, &ro, &a, &fa) == CM_OK);
    CHECK_INT(wrong_pixels(&s, a, 800, 400, 0.0), 0);
    CHECK_INT(fa.plot_w, 800);

    /* switching lines: white through x = m/P on x' = 0, and through
     * x = (m - D x')/P above and below; not white halfway between */
    ro.layers = CM_LAYER_BASIN | CM_LAYER_OVERLAYS;
    CHECK(draw(&s, &ro, &a, &fa) == CM_OK);
    for (int m = -6; m <= 6; m++) {
        if (m == 0)
            continue;
        int i, j;
        for (double y = -3; y <= 3; y += 1.5) {
            pixel_of(&fa, (m - 0.4 * y) / 0.9, y, &i, &j);
            CHECK(near(a, 800, 400, i, j, 1, white));
            pixel_of(&fa, (m + 0.5 - 0.4 * y) / 0.9, y, &i, &j);
            CHECK(!is(at(a, 800, i, j), white));
        }
    }
    /* fixed points x_m* = m/alpha^2: x_1* regular (a white disc), x_3*
     * virtual (a ring: its centre keeps the basin's colour) */
    int i, j;
    pixel_of(&fa, 1 / 0.64, 0, &i, &j);
    CHECK(is(at(a, 800, i, j), white));
    CHECK(near(a, 800, 400, i, j, 5, cm_colour_marker));
    pixel_of(&fa, 3 / 0.64, 0, &i, &j);
    CHECK(is(at(a, 800, i, j), cell_colour(&s, (uint64_t)(399 - j) * 800 + (uint64_t)i)));
    CHECK(near(a, 800, 400, i, j, 5, cm_colour_marker));

    /* attractor markers: the pixel of every periodic cell is black */
    ro.layers = CM_LAYER_BASIN | CM_LAYER_ATTRACTORS;
    CHECK(draw(&s, &ro, &a, &fa) == CM_OK);
    int periodic = 0, unmarked = 0;
    for (uint64_t k = 0; k < s.r.ncells; k++)
        if (cm_is_periodic(&s.r, k)) {
            periodic++;
            pixel_of(&fa, -8 + 0.02 * ((double)(k % 800) + 0.5),
                     -4 + 0.02 * ((double)(k / 800) + 0.5), &i, &j);
            unmarked += !is(at(a, 800, i, j), cm_colour_marker);
        }
    CHECK(periodic > 0);
    CHECK_INT(unmarked, 0);
    /* zoomed out 4x, a one-cell attractor still shows */
    ro.lo[0] = -32, ro.hi[0] = 32, ro.lo[1] = -16, ro.hi[1] = 16;
    CHECK(draw(&s, &ro, &a, &fa) == CM_OK);
    unmarked = 0;
    for (uint64_t k = 0; k < s.r.ncells; k++)
        if (cm_is_periodic(&s.r, k)) {
            pixel_of(&fa, -8 + 0.02 * ((double)(k % 800) + 0.5),
                     -4 + 0.02 * ((double)(k / 800) + 0.5), &i, &j);
            unmarked += !is(at(a, 800, i, j), cm_colour_marker);
        }
    CHECK_INT(unmarked, 0);
    memset(ro.lo, 0, sizeof ro.lo);
    memset(ro.hi, 0, sizeof ro.hi);

    /* shading: periodic cells (step 0) keep their colour; steps only: grey */
    ro.layers = CM_LAYER_BASIN | CM_LAYER_STEPS;
    CHECK(draw(&s, &ro, &a, &fa) == CM_OK);
    ro.layers = CM_LAYER_STEPS;
    CHECK(draw(&s, &ro, &b, &fb) == CM_OK);
    int darker = 0, checked = 0;
    for (uint64_t k = 0; k < s.r.ncells; k++) {
        pixel_of(&fa, -8 + 0.02 * ((double)(k % 800) + 0.5), -4 + 0.02 * ((double)(k / 800) + 0.5),
                 &i, &j);
        const uint8_t *p = at(a, 800, i, j), *q = at(b, 800, i, j);
        const cm_rgb c = cell_colour(&s, k);
        CHECK(q[0] == q[1] && q[1] == q[2]);
        if (s.r.step[k] == 0 && s.r.group[k] != 0) {
            CHECK(is(p, c));
            CHECK_INT(q[0], 235);
        } else if (s.r.step[k] > 3) {
            darker += p[0] <= c.r && p[1] <= c.g && p[2] <= c.b && !is(p, c);
            checked++;
        }
    }
    CHECK(checked > 0);
    CHECK_INT(darker, checked);

    /* all layers: axes, legend and title leave the plot smaller, framed */
    ro.layers = CM_LAYER_BASIN | CM_LAYER_ATTRACTORS | CM_LAYER_OVERLAYS | CM_LAYER_AXES |
                CM_LAYER_LEGEND | CM_LAYER_TITLE;
    ro.width = 1200;
    ro.height = 700;
    CHECK(draw(&s, &ro, &a, &fa) == CM_OK);
    CHECK(fa.plot_x > 20 && fa.plot_y > 10 && fa.plot_w < 1100 && fa.plot_h < 680);
    CHECK(is(at(a, 1200, fa.plot_x - 1, fa.plot_y + fa.plot_h / 2), cm_colour_marker));
    CHECK(is(at(a, 1200, fa.plot_x + fa.plot_w / 3, fa.plot_y + fa.plot_h), cm_colour_marker));
    pixel_of(&fa, 2 / 0.9, 0, &i, &j); /* still a switching line at x = 2/P */
    CHECK(near(a, 1200, 700, i, j, 1, white));
    int sink_swatch = 0, title_ink = 0;
    for (int y = fa.plot_y; y < fa.plot_y + fa.plot_h; y++)
        for (int x = fa.plot_x + fa.plot_w + 2; x < 1200; x++)
            sink_swatch += is(at(a, 1200, x, y), cm_colour_sink);
    for (int y = 0; y < fa.plot_y - 2; y++)
        for (int x = 0; x < 600; x++)
            title_ink += at(a, 1200, x, y)[0] < 128;
    CHECK(sink_swatch >= 16); /* the legend's sink entry */
    CHECK(title_ink > 50);

    /* deterministic, and the same with one thread as with two */
    omp_set_num_threads(1);
    CHECK(draw(&s, &ro, &b, &fb) == CM_OK);
    omp_set_num_threads(2);
    CHECK(memcmp(a, b, 1200 * 700 * 4) == 0);
    CHECK(draw(&s, &ro, &b, &fb) == CM_OK);
    CHECK(memcmp(a, b, 1200 * 700 * 4) == 0);

    /* too small for the text: a clear error, not a broken picture */
    ro.width = 60;
    ro.height = 40;
    CHECK(draw(&s, &ro, &a, &fa) == CM_EINVAL);

    /* larger than a GL tile: the bare raster needs no GL, every pixel its
     * cell's; with the overlays GL draws the lines in 2 x 2 tiles, laid
     * over the same raster (a few pixels of lines) */
    ro.layers = CM_LAYER_BASIN;
    ro.width = CM_PLOT_TILE + 100;
    ro.height = CM_PLOT_TILE + 60;
    CHECK(draw(&s, &ro, &a, &fa) == CM_OK);
    CHECK_INT(fa.tiles, 0);
    CHECK_INT(wrong_pixels(&s, a, ro.width, ro.height, 0.5), 0);
    ro.layers = CM_LAYER_BASIN | CM_LAYER_OVERLAYS;
    CHECK(draw(&s, &ro, &b, &fb) == CM_OK);
    CHECK_INT(fb.tiles, 4);
    const size_t pixels = (size_t)ro.width * (size_t)ro.height;
    size_t lines = 0;
    for (size_t k = 0; k < pixels; k++)
        lines += memcmp(a + 4 * k, b + 4 * k, 4) != 0;
    CHECK(lines > 0 && lines < pixels / 50);

    /* the largest size the issue asks for, 8192 x 8192: still every pixel its cell's */
    ro.layers = CM_LAYER_BASIN;
    ro.width = ro.height = 8192;
    CHECK(draw(&s, &ro, &a, &fa) == CM_OK);
    CHECK_INT(fa.tiles, 0);
    CHECK_INT(wrong_pixels(&s, a, ro.width, ro.height, 0.5), 0);
    free(a);
    free(b);
    scene_free(&s);
}

static void test_1d_graph(void)
{
    /* Fig. 4.2: x -> 3.5 x - 2.8 Int(x) on -10..10 */
    scene s;
    const cm_lattice lat = {1, {-10}, {0.02}};
    const cm_box box = {1, {0}, {1000}};
    solve(&s, "microchaos-1d", "a=3.5,b=2.8", &lat, &box);
    uint8_t *a = NULL;
    cm_render_info f;
    cm_render_options ro;
    memset(&ro, 0, sizeof ro);
    ro.width = 600;
    ro.height = 600;
    ro.layers = CM_LAYER_BASIN | CM_LAYER_OVERLAYS;
    CHECK(draw(&s, &ro, &a, &f) == CM_OK);
    CHECK(f.graph_w == 600 && f.graph_h > 400 && f.plot_y > f.graph_y + f.graph_h);
    /* the graph passes through (x, f(x)); x_1* = b/(a-1) = 1.12 is regular */
    const double xs[] = {0.3, -0.7, 1.5, 4.2};
    for (int k = 0; k < 4; k++) {
        const double x = xs[k], y = 3.5 * x - 2.8 * trunc(x);
        const int i = f.graph_x + (int)floor((x + 10) / 20 * f.graph_w);
        const int j = f.graph_y + (int)floor((10 - y) / 20 * f.graph_h);
        CHECK(near(a, 600, 600, i, j, 1, cm_colour_marker));
    }
    const int i = f.graph_x + (int)floor((1.12 + 10) / 20 * f.graph_w);
    const int j = f.graph_y + (int)floor((10 - 1.12) / 20 * f.graph_h);
    CHECK(is(at(a, 600, i, j), white));
    /* the strip below: the colour of the cell under each column (1000
     * cells on 600 pixels: those two apart count as touching) */
    scene_colours(&s, 2);
    int wrong = 0;
    for (int x = 0; x < 600; x++) {
        const uint64_t k = (uint64_t)((x + 0.5) * 1000 / 600);
        wrong += !is(at(a, 600, x, f.plot_y + f.plot_h / 2), cell_colour(&s, k));
    }
    CHECK_INT(wrong, 0);
    free(a);
    scene_free(&s);
}

static void test_indexed_png(void)
{
    char dir[] = "/tmp/cellmap-figure-XXXXXX", path[256], msg[256];
    CHECK(mkdtemp(dir) != NULL);
    snprintf(path, sizeof path, "%s/i.png", dir);
    const uint8_t index[6] = {0, 1, 2, 5, 6, 4};
    uint8_t palette[3 * 8];
    for (int k = 0; k < 8; k++) {
        const cm_rgb c = cm_class_colour(NULL, k);
        memcpy(palette + 3 * k, (uint8_t[3]){c.r, c.g, c.b}, 3);
    }
    const cm_png_text texts[] = {{"Software", "cellmap test"}};
    CHECK(cm_png_write_indexed(path, index, 3, 2, 0, palette, 8, texts, 1, msg, sizeof msg) == CM_OK);
    CHECK(cm_png_write_indexed(path, index, 3, 2, 0, palette, 300, texts, 1, msg, sizeof msg) ==
          CM_EINVAL);
    FILE *f = fopen(path, "rb");
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png_create_info_struct(png);
    if (f && !setjmp(png_jmpbuf(png))) {
        png_init_io(png, f);
        png_read_png(png, info, PNG_TRANSFORM_IDENTITY, NULL);
        CHECK_INT(png_get_color_type(png, info), PNG_COLOR_TYPE_PALETTE);
        png_colorp pal = NULL;
        int n = 0;
        png_get_PLTE(png, info, &pal, &n);
        CHECK_INT(n, 8);
        CHECK(n == 8 && pal[1].red == cm_colour_sink.r && pal[1].green == cm_colour_sink.g);
        png_bytepp rows = png_get_rows(png, info);
        CHECK(memcmp(rows[0], index, 3) == 0 && memcmp(rows[1], index + 3, 3) == 0);
    } else {
        CHECK(!"libpng failed to read the indexed file back");
    }
    png_destroy_read_struct(&png, &info, NULL);
    if (f)
        fclose(f);
    unlink(path);
    CHECK(rmdir(dir) == 0);
}

/* The SVG's one <image>: its rectangle into box[4] and its PNG, decoded
 * from base64, into *png (malloc'd) and *n. */
static bool svg_image(const char *svg, double box[4], uint8_t **png, size_t *n)
{
    const char *img = strstr(svg, "<image ");
    if (!img || strstr(img + 1, "<image ") ||
        sscanf(img, "<image x=\"%lf\" y=\"%lf\" width=\"%lf\" height=\"%lf\"", &box[0], &box[1],
               &box[2], &box[3]) != 4)
        return false;
    const char *b64 = strstr(img, "base64,"), *end = b64 ? strchr(b64, '"') : NULL;
    if (!end)
        return false;
    b64 += 7;
    static const char digits[] =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    *png = malloc((size_t)(end - b64));
    *n = 0;
    uint32_t acc = 0;
    int bits = 0;
    for (const char *p = b64; p < end && *p != '='; p++) {
        const char *d = strchr(digits, *p);
        if (!d || !*p)
            return false;
        acc = acc << 6 | (uint32_t)(d - digits);
        if ((bits += 6) >= 8)
            (*png)[(*n)++] = (uint8_t)(acc >> (bits -= 8));
    }
    return true;
}

/* The SVG's embedded raster is the PNG figure's plot, pixel for pixel:
 * the <image> sits on the PNG's plot rectangle, holds one pixel per cell
 * in its cell's colour (row 0 the highest cells), and every pixel of the
 * PNG's plot shows the raster pixel of its cell. */
static void test_svg_raster(void)
{
    scene s;
    const cm_lattice lat = {2, {-8, -4}, {0.04, 0.04}};
    const cm_box box = {2, {0, 0}, {400, 200}};
    solve(&s, "microchaos-pd", "alpha=0.8,beta=0.3,P=0.9,D=0.4", &lat, &box);
    cm_render_options ro;
    memset(&ro, 0, sizeof ro);
    ro.width = 1000;
    ro.height = 620;
    ro.layers = CM_LAYER_BASIN | CM_LAYER_AXES | CM_LAYER_LEGEND | CM_LAYER_TITLE;
    uint8_t *fig = NULL;
    cm_render_info fi;
    CHECK(draw(&s, &ro, &fig, &fi) == CM_OK);
    char *svg = NULL, msg[256];
    size_t svg_size = 0;
    FILE *f = open_memstream(&svg, &svg_size);
    CHECK(cm_render_svg(&s.lat, &s.r, s.g, &ro, f, msg, sizeof msg) == CM_OK);
    fclose(f);
    double rect[4];
    uint8_t *png = NULL;
    size_t n = 0;
    const bool found = svg_image(svg, rect, &png, &n);
    CHECK(found);
    CHECK_NEAR(rect[0], fi.plot_x, 1e-9);
    CHECK_NEAR(rect[1], fi.plot_y, 1e-9);
    CHECK_NEAR(rect[2], fi.plot_w, 1e-9);
    CHECK_NEAR(rect[3], fi.plot_h, 1e-9);
    png_image im;
    memset(&im, 0, sizeof im);
    im.version = PNG_IMAGE_VERSION;
    uint8_t *ras = NULL;
    if (found && png_image_begin_read_from_memory(&im, png, n)) {
        im.format = PNG_FORMAT_RGBA;
        ras = malloc(PNG_IMAGE_SIZE(im));
        CHECK(png_image_finish_read(&im, NULL, ras, 0, NULL) != 0);
    }
    CHECK(ras != NULL);
    CHECK_INT(im.width, 400);
    CHECK_INT(im.height, 200);
    int wrong_cells = 0, wrong_plot = 0, compared = 0;
    for (int j = 0; ras && im.width == 400 && im.height == 200 && j < 200; j++)
        for (int i = 0; i < 400; i++)
            wrong_cells += !is(at(ras, 400, i, j), cell_colour(&s, (uint64_t)(199 - j) * 400 + (uint64_t)i));
    for (int y = fi.plot_y; ras && wrong_cells == 0 && y < fi.plot_y + fi.plot_h; y++) {
        const double cy = (y - fi.plot_y + 0.5) * 200.0 / fi.plot_h; /* raster rows, from the top */
        if (fabs(cy - round(cy)) * fi.plot_h / 200.0 < 0.5)
            continue; /* within half a pixel of a cell border */
        for (int x = fi.plot_x; x < fi.plot_x + fi.plot_w; x++) {
            const double cx = (x - fi.plot_x + 0.5) * 400.0 / fi.plot_w;
            if (fabs(cx - round(cx)) * fi.plot_w / 400.0 < 0.5)
                continue;
            compared++;
            wrong_plot += memcmp(at(fig, ro.width, x, y), at(ras, 400, (int)cx, (int)cy), 3) != 0;
        }
    }
    CHECK_INT(wrong_cells, 0);
    CHECK_INT(wrong_plot, 0);
    CHECK(compared > fi.plot_w * fi.plot_h / 4);
    free(ras);
    free(png);
    free(svg);
    free(fig);
    scene_free(&s);
}

/* A region of 5 x 3 cells whose groups 1, 2, 3 have n - 1, n and n + 1
 * cells (n = 5; each group's first cell periodic), and its group infos. */
static void boundary_scene(scene *s)
{
    char msg[256];
    memset(s, 0, sizeof *s);
    s->lat = (cm_lattice){2, {0, 0}, {1, 1}};
    const cm_box box = {2, {0, 0}, {5, 3}};
    CHECK(cm_region_alloc(&s->r, &box, msg, sizeof msg) == CM_OK);
    s->r.ngroups = 3;
    s->g = calloc(4, sizeof *s->g);
    const uint32_t first[4] = {0, 4, 9, 15}; /* group k's cells: first[k-1] .. first[k]-1 */
    for (uint32_t k = 1; k <= 3; k++) {
        s->g[k - 1] = (cm_group_info){.id = k, .period = 1, .basin_cells = first[k] - first[k - 1]};
        s->g[k - 1].anchor[0] = first[k - 1] % 5;
        s->g[k - 1].anchor[1] = first[k - 1] / 5;
        for (uint32_t i = first[k - 1]; i < first[k]; i++) {
            s->r.group[i] = k;
            s->r.step[i] = i != first[k - 1];
            s->r.image[i] = first[k - 1];
        }
    }
}

/* The text of the SVG legend's "other" line of a figure with min_basin. */
static bool svg_has_text(const scene *s, uint64_t min_basin, const char *text)
{
    cm_render_options ro;
    memset(&ro, 0, sizeof ro);
    ro.width = 900;
    ro.height = 500;
    ro.layers = CM_LAYER_BASIN | CM_LAYER_LEGEND;
    ro.min_basin = min_basin;
    ro.font_path = CELLMAP_FONT_PATH;
    char *svg = NULL, msg[256];
    size_t n = 0;
    FILE *f = open_memstream(&svg, &n);
    const cm_status st = cm_render_svg(&s->lat, &s->r, s->g, &ro, f, msg, sizeof msg);
    fclose(f);
    if (st != CM_OK)
        fprintf(stderr, "cm_render_svg: %s\n", msg);
    CHECK(st == CM_OK);
    const bool found = st == CM_OK && strstr(svg, text) != NULL;
    free(svg);
    return found;
}

/* --min-basin N folds groups of fewer than N cells, and only those, into
 * "other": groups of N - 1, N and N + 1 cells; the raster's count and the
 * legend's line say how many were folded. */
static void test_min_basin_boundary(void)
{
    scene s;
    boundary_scene(&s);
    cm_slice sl;
    cm_slice_of(&s.lat, &s.r, NULL, 0, &sl);
    const uint64_t rules[3] = {5, 6, 7}; /* N: groups 1; 1, 2; 1, 2, 3 folded */
    const uint64_t folded_cells[3] = {4, 9, 15};
    for (int t = 0; t < 3; t++) {
        cm_raster ras;
        char msg[256];
        CHECK(cm_raster_build(&s.lat, &s.r, s.g, &sl, CM_RASTER_BASIN, rules[t], NULL, &ras, msg,
                              sizeof msg) == CM_OK);
        CHECK(cm_raster_paint(&s.lat, &s.r, s.g, 1, 1, &ras, msg, sizeof msg) == CM_OK);
        CHECK_INT(ras.other_groups, t + 1);
        CHECK_INT(ras.other_cells, folded_cells[t]);
        for (uint32_t k = 1; k <= 3; k++)
            CHECK_INT(ras.classes[k] == CM_CLASS_OTHER, (int)k <= t + 1);
        int wrong = 0;
        for (uint64_t i = 0; i < 15; i++)
            wrong += !is(ras.pixels + 3 * i, cm_colour_other) != (s.r.group[i] > (uint32_t)t + 1);
        CHECK_INT(wrong, 0);
        cm_raster_free(&ras);
    }
    CHECK(svg_has_text(&s, 5, ">1 groups &lt; 5 cells  27%<"));
    CHECK(svg_has_text(&s, 6, ">2 groups &lt; 6 cells  60%<"));
    CHECK(!svg_has_text(&s, 4, "groups &lt;"));
    cm_region_free(&s.r);
    free(s.g);
}

/* The SVG of a scene drawn with ro (the caller frees it). */
static char *svg_of(const scene *s, const cm_render_options *ro)
{
    char *svg = NULL, msg[256];
    size_t n = 0;
    FILE *f = open_memstream(&svg, &n);
    const cm_status st = cm_render_svg(&s->lat, &s->r, s->g, ro, f, msg, sizeof msg);
    fclose(f);
    if (st != CM_OK)
        fprintf(stderr, "cm_render_svg: %s\n", msg);
    CHECK(st == CM_OK);
    return svg;
}

/* Legend shares with two significant digits, "< 0.01%" below; a title
 * wrapped at spaces onto lines that fit the image, every word kept. */
static void test_legend_shares_and_title(void)
{
    char msg[256];
    scene s;
    memset(&s, 0, sizeof s);
    s.lat = (cm_lattice){2, {0, 0}, {1, 1}};
    const cm_box box = {2, {0, 0}, {200, 100}}; /* 20 000 cells */
    CHECK(cm_region_alloc(&s.r, &box, msg, sizeof msg) == CM_OK);
    s.r.ngroups = 4;
    s.g = calloc(5, sizeof *s.g);
    const uint32_t first[5] = {0, 1, 6, 306, 20000}; /* 1, 5, 300 and 19 694 cells */
    for (uint32_t k = 1; k <= 4; k++) {
        s.g[k - 1] = (cm_group_info){.id = k, .period = 1, .basin_cells = first[k] - first[k - 1]};
        s.g[k - 1].anchor[0] = first[k - 1] % 200;
        s.g[k - 1].anchor[1] = first[k - 1] / 200;
        for (uint32_t i = first[k - 1]; i < first[k]; i++) {
            s.r.group[i] = k;
            s.r.step[i] = i != first[k - 1];
            s.r.image[i] = first[k - 1];
        }
    }
    cm_render_options ro;
    memset(&ro, 0, sizeof ro);
    ro.width = 900;
    ro.height = 500;
    ro.layers = CM_LAYER_BASIN | CM_LAYER_LEGEND;
    ro.min_basin = 1;
    ro.font_path = CELLMAP_FONT_PATH;
    char *svg = svg_of(&s, &ro);
    CHECK(strstr(svg, "p=1  &lt; 0.01%<") && strstr(svg, "p=1  0.025%<") &&
          strstr(svg, "p=1  1.5%<") && strstr(svg, "p=1  98%<"));
    free(svg);

    const char *title = "Basins of a system drawn to show that a long title wraps onto several "
                        "lines at spaces and loses none of its words on the way";
    ro.layers = CM_LAYER_BASIN | CM_LAYER_TITLE; /* its lines are the only texts */
    ro.title = title;
    ro.width = 400;
    svg = svg_of(&s, &ro);
    char joined[1024] = "";
    int lines = 0;
    for (const char *t = strstr(svg, "<text "); t; t = strstr(t + 1, "<text ")) {
        const char *from = strchr(t, '>') + 1, *to = strstr(from, "</text>");
        snprintf(joined + strlen(joined), sizeof joined - strlen(joined), "%s%.*s",
                 lines++ ? " " : "", (int)(to - from), from);
    }
    CHECK(lines >= 2 && lines <= 4);
    CHECK(strcmp(joined, title) == 0);
    free(svg);
    cm_region_free(&s.r);
    free(s.g);
}

int main(void)
{
    test_legend_shares_and_title();
    test_pd_figure();
    test_min_basin_boundary();
    test_svg_raster();
    test_1d_graph();
    test_indexed_png();
    CHECK_DONE();
}
