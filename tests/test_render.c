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

int main(void)
{
    check_ticks();
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
    uint8_t *classes = calloc(r.ngroups, 1);
    cm_palette_classes(NULL, g, r.ngroups, &lat, NULL, 0, classes);
    for (uint32_t k = 0; k < r.ngroups; k++)
        colours[k] = cm_class_colour(NULL, classes[k]);
    cm_render_info ri;

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
    CHECK(cm_png_write(path, a, W, H, texts, 2, msg, sizeof msg) == CM_OK);
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
    CHECK(cm_png_write("/nonexistent-dir/x.png", a, W, H, texts, 2, msg, sizeof msg) == CM_EINVAL);
    unlink(path);
    CHECK(rmdir(dir) == 0); /* empty: no temporary file left behind */

    free(a);
    free(b);
    free(g);
    free(colours);
    free(classes);
    cm_region_free(&r);
    CHECK_DONE();
}
