#include <omp.h>
#include <png.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cellmap/scm.h"
#include "check.h"
#include "render/axes.h"
#include "render/figure.h"
#include "render/palette.h"
#include "render/png_out.h"
#include "render/raster.h"
#include "render/touching.h"

/* Ticks at both ends of a range whose ends are multiples of the step that
 * floating point does not hit exactly. */
static void check_ticks(void)
{
    cm_ticks t;
    cm_make_ticks(-0.3, 0.3, &t); /* step 0.1: -0.3 / 0.1 and 3 * 0.1 both round */
    CHECK_INT(t.n, 7);
    CHECK(strcmp(t.label[0], "-0.3") == 0 && strcmp(t.label[6], "0.3") == 0);
    CHECK(strcmp(t.label[3], "0.0") == 0);
    cm_make_ticks(0.1, 0.7, &t); /* step 0.1: 0.7 / 0.1 = 6.999999999999999 */
    CHECK_INT(t.n, 7);
    CHECK(strcmp(t.label[0], "0.1") == 0 && strcmp(t.label[6], "0.7") == 0);
    cm_make_ticks(0.05, 0.95, &t); /* step 0.2: both ends between ticks */
    CHECK_INT(t.n, 4);
    CHECK(strcmp(t.label[0], "0.2") == 0 && strcmp(t.label[3], "0.8") == 0);
    cm_make_ticks(-3, 3, &t); /* step 1: exact */
    CHECK_INT(t.n, 7);
    cm_make_ticks(1, 1, &t); /* an empty range has none */
    CHECK_INT(t.n, 0);
}

/* Upper half (y > 0.5) has no image (the sink); the lower half: every cell
 * is fixed, except x > 0.75, which moves to the fixed cell (1, 1). */
static int half_sink(const cm_model *m, const double *x, double *y)
{
    (void)m;
    if (x[1] > 0.5)
        return CM_STEP_NO_IMAGE;
    y[0] = x[0] > 0.75 ? 0.15 : x[0];
    y[1] = x[0] > 0.75 ? 0.15 : x[1];
    return 0;
}

static const uint8_t *pixel(const uint8_t *rgba, int w, int px, int py)
{
    return rgba + 4 * ((size_t)py * (size_t)w + (size_t)px);
}

static int same_rgb(const uint8_t *p, cm_rgb c) { return p[0] == c.r && p[1] == c.g && p[2] == c.b; }

/* The pairs of labels side by side in a grid, and those up to two cells
 * apart (a figure of two cells per pixel). */
static void check_touching(void)
{
    const uint32_t N = CM_GROUP_NONE;
    const uint32_t grid[3][4] = {{1, 1, 2, 2}, {1, 3, 3, 2}, {4, 4, 4, N}};
    const uint64_t near[] = {(uint64_t)1 << 32 | 2, (uint64_t)1 << 32 | 3, (uint64_t)1 << 32 | 4,
                             (uint64_t)2 << 32 | 3, (uint64_t)2 << 32 | N, (uint64_t)3 << 32 | 4,
                             (uint64_t)4 << 32 | N};
    cm_touching t;
    char msg[128];
    CHECK(cm_touching_collect(&grid[0][0], 4, 3, 4, 1, 1, &t, msg, sizeof msg) == CM_OK);
    CHECK_INT(t.n, 7);
    CHECK(t.n == 7 && memcmp(t.pair, near, sizeof near) == 0);
    cm_touching_free(&t);
    /* two rows apart, 2 (top right) and 4 (bottom) meet as well */
    CHECK(cm_touching_collect(&grid[0][0], 4, 3, 4, 2, 2, &t, msg, sizeof msg) == CM_OK);
    CHECK_INT(t.n, 8);
    CHECK(t.n == 8 && t.pair[4] == ((uint64_t)2 << 32 | 4));
    cm_touching_free(&t);
    CHECK_INT(cm_touching_reach(1000, 400), 3);
    CHECK_INT(cm_touching_reach(400, 1000), 1);
}

/* Two touching groups whose palette holds two near-identical colours and
 * one far from both: they never get the close pair; with only the close
 * pair, they still get different colours; without neighbours the colours
 * are those of the anchors' hashes, as with no pairs. */
static void check_neighbour_rule(void)
{
    const cm_lattice lat = {2, {0, 0}, {0.1, 0.1}};
    cm_group_info g[2];
    memset(g, 0, sizeof g);
    g[0] = (cm_group_info){.id = 1, .period = 1, .basin_cells = 10, .anchor = {0, 0}};
    g[1] = (cm_group_info){.id = 2, .period = 1, .basin_cells = 5, .anchor = {5, 5}};
    const cm_rgb a = {0x44, 0x77, 0xaa}, close_to_a = {0x4a, 0x7a, 0xaa}, far = {0xcc, 0xbb, 0x44};
    CHECK(cm_colour_distance(a, close_to_a) < 5 && cm_colour_distance(a, far) > 60);
    CHECK(cm_delta_e(a, far) >= cm_colour_distance(a, far));
    uint64_t pair = (uint64_t)1 << 32 | 2;
    const cm_touching touching = {&pair, 1}, none = {&pair, 0};
    for (int order = 0; order < 6; order++) { /* every order of the three colours */
        const cm_rgb three[3] = {a, close_to_a, far};
        cm_palette p = {"test", 3, {{0}}};
        for (int k = 0; k < 3; k++)
            p.colour[k] = three[(k + order) % 3];
        if (order >= 3) {
            const cm_rgb kept = p.colour[0];
            p.colour[0] = p.colour[1], p.colour[1] = kept;
        }
        uint8_t cls[2], plain[2], empty[2];
        cm_palette_classes(&p, g, 2, &lat, NULL, 0, &touching, cls);
        CHECK(cm_colour_distance(cm_class_colour(&p, cls[0]), cm_class_colour(&p, cls[1])) >=
              CM_NEIGHBOUR_DISTANCE);
        cm_palette_classes(&p, g, 2, &lat, NULL, 0, NULL, plain);
        cm_palette_classes(&p, g, 2, &lat, NULL, 0, &none, empty);
        CHECK(memcmp(plain, empty, 2) == 0);
        CHECK(cls[0] == plain[0]); /* the larger keeps its colour */
        p.n = 2; /* only the close pair: the best there is */
        cm_palette_classes(&p, g, 2, &lat, NULL, 0, &touching, cls);
        CHECK(cls[0] != cls[1]);
    }
}

/* Every pixel of a basin raster shows the cell its centre lies in (the
 * CPU draws it, render/quads.h), ties included: at 3 pixels for 2 cells
 * and at 177 for 150 (Fig. 4.13's zoom) some centres lie exactly on cell
 * edges, and show the cell above the edge (cells are half-open). The
 * reference is the figure of one pixel per cell, whose centres are the
 * cells' centres; the views are the region's, so the cells' colours are
 * the same in all of them (the neighbour rule's reach stays 1). */
static void check_pixel_centres(const cm_lattice *lat, const cm_region *r, const cm_group_info *g)
{
    const int nx = (int)(r->box.hi[0] - r->box.lo[0]), ny = (int)(r->box.hi[1] - r->box.lo[1]);
    const int sizes[][2] = {{15, 15}, {20, 10}, {177, 59}, {59, 177}, {10, 10}};
    char msg[256];
    cm_render_options ro;
    memset(&ro, 0, sizeof ro);
    ro.layers = CM_LAYER_BASIN;
    ro.width = nx, ro.height = ny;
    uint8_t *one = calloc((size_t)nx * (size_t)ny, 4);
    cm_render_info ri;
    CHECK(cm_render_figure(lat, r, g, &ro, one, &ri, msg, sizeof msg) == CM_OK);
    for (size_t v = 0; v < sizeof sizes / sizeof sizes[0]; v++) {
        const int W = sizes[v][0], H = sizes[v][1];
        uint8_t *img = calloc((size_t)W * (size_t)H, 4);
        ro.width = W, ro.height = H;
        CHECK(cm_render_figure(lat, r, g, &ro, img, &ri, msg, sizeof msg) == CM_OK);
        int wrong = 0;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) { /* the cell of the centre, in integers */
                const int i = (2 * x + 1) * nx / (2 * W), b = H - 1 - y;
                const int j = (2 * b + 1) * ny / (2 * H);
                wrong += memcmp(pixel(img, W, x, y), pixel(one, nx, i, ny - 1 - j), 4) != 0;
            }
        CHECK(wrong == 0);
        free(img);
    }
    free(one);
}

/* An RGBA image of w x h: noise (no two rows alike, nothing to compress)
 * or flat bands with noise in every 97th row, so that matches cross the
 * PNG's deflate segments. */
static uint8_t *test_image(int w, int h, bool noise)
{
    uint8_t *a = malloc(4 * (size_t)w * (size_t)h);
    uint64_t x = 0x9E3779B97F4A7C15u;
    for (size_t k = 0; a && k < 4 * (size_t)w * (size_t)h; k++) {
        x ^= x << 13, x ^= x >> 7, x ^= x << 17;
        const size_t y = k / (4 * (size_t)w);
        a[k] = noise || y % 97 == 0 ? (uint8_t)x : (uint8_t)(y / 50 * 40 + k % 4);
    }
    return a;
}

/* cm_png_encode against libpng's reader: every pixel back, the same bytes
 * on one thread as on two, for images of one segment, many, and scanlines
 * longer than a segment (render/png_out.c cuts the image data in pieces
 * of 256 KiB deflated apart). */
static void check_png_segments(void)
{
    const struct {
        int w, h;
        bool noise;
    } cases[] = {{1, 1, true},      {1200, 700, true}, {2000, 2000, false},
                 {90000, 3, true},  {300, 1, false},   {7, 5000, false}};
    char msg[256];
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        const int w = cases[c].w, h = cases[c].h;
        uint8_t *a = test_image(w, h, cases[c].noise), *back = malloc(3 * (size_t)w * (size_t)h);
        uint8_t *png2 = NULL, *png1 = NULL;
        size_t n2 = 0, n1 = 0;
        CHECK(a && back);
        omp_set_num_threads(2);
        CHECK(cm_png_encode(a, w, h, &png2, &n2, msg, sizeof msg) == CM_OK);
        omp_set_num_threads(1);
        CHECK(cm_png_encode(a, w, h, &png1, &n1, msg, sizeof msg) == CM_OK);
        omp_set_num_threads(2);
        CHECK(n1 == n2 && png1 && png2 && memcmp(png1, png2, n1) == 0);
        png_image im;
        memset(&im, 0, sizeof im);
        im.version = PNG_IMAGE_VERSION;
        CHECK(png_image_begin_read_from_memory(&im, png2, n2) != 0);
        im.format = PNG_FORMAT_RGB;
        CHECK(png_image_finish_read(&im, NULL, back, 0, NULL) != 0);
        CHECK_INT(im.width, w);
        CHECK_INT(im.height, h);
        size_t wrong = 0;
        for (size_t k = 0; k < (size_t)w * (size_t)h; k++)
            wrong += memcmp(back + 3 * k, a + 4 * k, 3) != 0;
        CHECK_INT(wrong, 0);
        png_image_free(&im);
        free(a);
        free(back);
        free(png1);
        free(png2);
    }
}

int main(void)
{
    check_ticks();
    check_png_segments();
    check_touching();
    check_neighbour_rule();
    cm_model m;
    memset(&m, 0, sizeof m);
    m.name = "test";
    m.dim = 2;
    m.step = half_sink;
    const cm_lattice lat = {2, {0, 0}, {0.1, 0.1}};
    const cm_box box = {2, {0, 0}, {10, 10}};
    cm_region r;
    char msg[256];
    CHECK(cm_region_alloc(&r, &box, msg, sizeof msg) == CM_OK);
    const cm_scm_options opt = {.max_steps = 1, .threads = 1};
    CHECK(cm_scm_solve(&m, &lat, &opt, &r, msg, sizeof msg) == CM_OK);
    cm_group_info *g = calloc(r.ngroups, sizeof *g);
    cm_scm_groups(&r, &lat, g, NULL);
    cm_rgb *colours = calloc(r.ngroups, sizeof *colours);
    /* the groups' colours in this view: most cells are fixed, single-cell
     * groups side by side, so the neighbour rule moves many (reach 1: the
     * figure has more pixels than cells) */
    cm_slice slice;
    cm_slice_of(&lat, &r, NULL, 0, &slice);
    cm_raster ras;
    CHECK(cm_raster_build(&lat, &r, g, &slice, CM_RASTER_BASIN, 0, NULL, &ras, msg, sizeof msg) ==
          CM_OK);
    CHECK(cm_raster_paint(&lat, &r, g, 1, 1, &ras, msg, sizeof msg) == CM_OK);
    for (uint32_t k = 0; k < r.ngroups; k++)
        colours[k] = cm_class_colour(NULL, ras.classes[k + 1]);
    cm_raster_free(&ras);
    cm_render_info ri;
    check_pixel_centres(&lat, &r, g);

    enum { W = 200, H = 100 };
    uint8_t *a = calloc(W * H, 4), *b = calloc(W * H, 4);
    cm_render_options ro;
    memset(&ro, 0, sizeof ro);
    ro.width = W;
    ro.height = H;
    ro.layers = CM_LAYER_BASIN;
    CHECK(cm_render_figure(&lat, &r, g, &ro, a, &ri, msg, sizeof msg) == CM_OK);
    /* Row 0 is the top: high y, the sink. Pixels are 0.005 x 0.01 of state. */
    CHECK(same_rgb(pixel(a, W, 10, 5), cm_colour_sink));
    CHECK(!same_rgb(pixel(a, W, 10, 95), cm_colour_sink));
    /* (x, y) = (0.05, 0.05) is cell (0, 0): its group's colour */
    const uint32_t g00 = r.group[0];
    CHECK(g00 > 0);
    CHECK(same_rgb(pixel(a, W, 10, 95), colours[g00 - 1]));
    /* x > 0.75 drains into cell (1, 1): same colour as (0.15, 0.15) */
    const uint32_t g11 = r.group[1 + 10 * 1];
    CHECK(same_rgb(pixel(a, W, 190, 85), colours[g11 - 1]));
    CHECK(same_rgb(pixel(a, W, 30, 85), colours[g11 - 1]));

    /* markers: the fixed cell (0.35, 0.25) becomes black */
    ro.layers = CM_LAYER_BASIN | CM_LAYER_ATTRACTORS;
    CHECK(cm_render_figure(&lat, &r, g, &ro, b, &ri, msg, sizeof msg) == CM_OK);
    CHECK(same_rgb(pixel(b, W, 70, 75), cm_colour_marker));
    CHECK(same_rgb(pixel(b, W, 70, 5), cm_colour_sink)); /* no marker in the sink */
    /* a sub-pixel cell still gets a visible marker: a view 50x wider */
    ro.lo[0] = -10;
    ro.hi[0] = 10;
    ro.lo[1] = -5;
    ro.hi[1] = 5;
    CHECK(cm_render_figure(&lat, &r, g, &ro, b, &ri, msg, sizeof msg) == CM_OK);
    CHECK(same_rgb(pixel(b, W, 101, 49), cm_colour_marker)); /* (0.15, 0.15) is a fixed cell */
    CHECK(same_rgb(pixel(b, W, 2, 2), cm_colour_not_computed));

    /* cells not computed (outside a cluster's regions, CM_GROUP_NONE, step
     * 0 as flattening leaves them) are drawn as such, without markers */
    ro.lo[0] = ro.hi[0] = ro.lo[1] = ro.hi[1] = 0;
    const uint32_t kept_group = r.group[0], kept_step = r.step[0];
    r.group[0] = CM_GROUP_NONE;
    r.step[0] = 0;
    CHECK(cm_render_figure(&lat, &r, g, &ro, b, &ri, msg, sizeof msg) == CM_OK);
    CHECK(same_rgb(pixel(b, W, 10, 95), cm_colour_not_computed));
    CHECK(same_rgb(pixel(b, W, 30, 95), cm_colour_marker)); /* its neighbour, fixed */
    r.group[0] = kept_group;
    r.step[0] = kept_step;
    ro.layers = CM_LAYER_BASIN;

    /* deterministic */
    CHECK(cm_render_figure(&lat, &r, g, &ro, a, &ri, msg, sizeof msg) == CM_OK);
    CHECK(cm_render_figure(&lat, &r, g, &ro, b, &ri, msg, sizeof msg) == CM_OK);
    CHECK(memcmp(a, b, (size_t)W * H * 4) == 0);

    /* PNG: decoded back with libpng, with our text chunks; no temp left */
    char dir[] = "/tmp/cellmap-render-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char path[256];
    snprintf(path, sizeof path, "%s/basin.png", dir);
    const cm_png_text texts[] = {{"Software", "cellmap test"}, {"Model", "half-sink"}};
    CHECK(cm_png_write(path, a, W, H, 0, texts, 2, msg, sizeof msg) == CM_OK);
    FILE *f = fopen(path, "rb");
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png_create_info_struct(png);
    if (!setjmp(png_jmpbuf(png))) {
        png_init_io(png, f);
        png_read_png(png, info, PNG_TRANSFORM_IDENTITY, NULL);
        CHECK_INT(png_get_image_width(png, info), W);
        CHECK_INT(png_get_image_height(png, info), H);
        png_textp t = NULL;
        int nt = 0;
        png_get_text(png, info, &t, &nt);
        CHECK_INT(nt, 2);
        CHECK(nt == 2 && strcmp(t[1].key, "Model") == 0 && strcmp(t[1].text, "half-sink") == 0);
        png_bytepp rows = png_get_rows(png, info);
        CHECK(memcmp(rows[95] + 3 * 10, pixel(a, W, 10, 95), 3) == 0);
    } else {
        CHECK(!"libpng failed to read the file back");
    }
    png_destroy_read_struct(&png, &info, NULL);
    fclose(f);
    /* writing into a missing directory fails cleanly */
    CHECK(cm_png_write("/nonexistent-dir/x.png", a, W, H, 0, texts, 2, msg, sizeof msg) == CM_EINVAL);
    unlink(path);
    CHECK(rmdir(dir) == 0); /* empty: no temporary file left behind */

    free(a);
    free(b);
    free(g);
    free(colours);
    cm_region_free(&r);
    CHECK_DONE();
}
