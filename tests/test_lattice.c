#include <stdint.h>
#include <string.h>

#include "cellmap/lattice.h"
#include "cellmap/idmap.h"
#include "check.h"

static void point_cell_round_trip(void)
{
    const cm_lattice lat = {2, {-3.0, 10.0}, {0.25, 0.5}};
    for (int64_t cx = -50; cx <= 50; cx += 7)
        for (int64_t cy = -50; cy <= 50; cy += 9) {
            const int64_t c[2] = {cx, cy};
            double x[2];
            int64_t back[2] = {0, 0};
            cm_lattice_centre(&lat, c, x);
            CHECK(cm_lattice_cell(&lat, x, back));
            CHECK_INT(back[0], cx);
            CHECK_INT(back[1], cy);
        }
}

static void edges(void)
{
    const cm_lattice lat = {1, {0.0}, {1.0}};
    int64_t c = 99;
    double x = -0.5; /* negative coordinates floor, never truncate toward 0 */
    CHECK(cm_lattice_cell(&lat, &x, &c));
    CHECK_INT(c, -1);
    x = 0.0;
    CHECK(cm_lattice_cell(&lat, &x, &c));
    CHECK_INT(c, 0);
    x = -1.0; /* a lower cell boundary belongs to the cell above it */
    CHECK(cm_lattice_cell(&lat, &x, &c));
    CHECK_INT(c, -1);
    c = 99;
    x = NAN;
    CHECK(!cm_lattice_cell(&lat, &x, &c));
    CHECK_INT(c, 99); /* untouched */
    x = INFINITY;
    CHECK(!cm_lattice_cell(&lat, &x, &c));
    x = -INFINITY;
    CHECK(!cm_lattice_cell(&lat, &x, &c));
    x = 1e300;
    CHECK(!cm_lattice_cell(&lat, &x, &c));
    x = (double)CM_WORLD_LIMIT; /* the first cell beyond the world */
    CHECK(!cm_lattice_cell(&lat, &x, &c));
    x = (double)CM_WORLD_LIMIT - 1.0;
    CHECK(cm_lattice_cell(&lat, &x, &c));
    CHECK_INT(c, CM_WORLD_LIMIT - 1);
    x = -(double)CM_WORLD_LIMIT;
    CHECK(cm_lattice_cell(&lat, &x, &c));
    CHECK_INT(c, -CM_WORLD_LIMIT);
    x = -(double)CM_WORLD_LIMIT - 1.0;
    CHECK(!cm_lattice_cell(&lat, &x, &c));
    /* in 2-D one bad coordinate is enough */
    const cm_lattice lat2 = {2, {0, 0}, {1, 1}};
    int64_t c2[2] = {5, 5};
    const double p[2] = {1.0, NAN};
    CHECK(!cm_lattice_cell(&lat2, p, c2));
    CHECK_INT(c2[0], 5);
}

static void checks(void)
{
    char msg[128];
    cm_lattice bad = {0, {0}, {1}};
    CHECK(cm_lattice_check(&bad, msg, sizeof msg) == CM_EINVAL);
    bad.dim = 7;
    CHECK(cm_lattice_check(&bad, msg, sizeof msg) == CM_EINVAL);
    cm_lattice zero = {1, {0}, {0.0}};
    CHECK(cm_lattice_check(&zero, msg, sizeof msg) == CM_EINVAL);
    CHECK(strstr(msg, "width") != NULL);
    const cm_lattice six = {6, {0, 0, 0, 0, 0, 0}, {1, 1, 1, 1, 1, 1}};
    CHECK(cm_lattice_check(&six, msg, sizeof msg) == CM_OK);
    cm_box empty = {2, {0, 0}, {0, 5}};
    CHECK(cm_box_check(&empty, msg, sizeof msg) == CM_EINVAL);
    cm_box big = {1, {-CM_WORLD_LIMIT - 1}, {0}};
    CHECK(cm_box_check(&big, msg, sizeof msg) == CM_ERANGE);
}

static void box_index_round_trip(void)
{
    const cm_box box = {3, {-2, 5, -7}, {3, 9, -4}};
    CHECK_INT(cm_box_cells(&box), 5 * 4 * 3);
    for (uint64_t i = 0; i < cm_box_cells(&box); i++) {
        int64_t c[3];
        cm_box_cell(&box, i, c);
        CHECK(cm_box_contains(&box, c));
        CHECK_INT(cm_box_index(&box, c), i);
    }
    const int64_t first[3] = {-2, 5, -7};
    CHECK_INT(cm_box_index(&box, first), 0);
    const int64_t next_x[3] = {-1, 5, -7}; /* dimension 0 is the fastest */
    CHECK_INT(cm_box_index(&box, next_x), 1);
    const int64_t outside[3] = {3, 5, -7};
    CHECK(!cm_box_contains(&box, outside));
    CHECK(strcmp(cm_strerror(CM_EINVAL), "invalid argument") == 0);
    CHECK(strcmp(cm_status_name(CM_EDB), "CM_EDB") == 0);
}

/* The id map against a plain array, through random puts, gets and
 * removals dense enough to wrap probe runs around the table. */
static void test_idmap(void)
{
    enum { KEYS = 3000 };
    static uint64_t ref[KEYS];
    static bool in[KEYS];
    cm_idmap m;
    memset(&m, 0, sizeof m);
    uint64_t state = 12345, count = 0;
    for (int op = 0; op < 200000; op++) {
        state = state * UINT64_C(6364136223846793005) + 1442695040888963407u;
        const uint32_t key = (uint32_t)((state >> 33) % KEYS);
        const int what = (int)((state >> 20) % 3);
        uint64_t v = 0;
        if (what == 0) {
            CHECK(cm_idmap_put(&m, key * 977u, state) == CM_OK);
            count += !in[key];
            in[key] = true;
            ref[key] = state;
        } else if (what == 1) {
            const bool had = cm_idmap_remove(&m, key * 977u, &v);
            CHECK(had == in[key]);
            if (had)
                CHECK(v == ref[key]);
            count -= in[key];
            in[key] = false;
        } else {
            const bool has = cm_idmap_get(&m, key * 977u, &v);
            CHECK(has == in[key]);
            if (has)
                CHECK(v == ref[key]);
        }
    }
    CHECK_INT(m.count, count);
    for (uint32_t k = 0; k < KEYS; k++)
        CHECK(cm_idmap_get(&m, k * 977u, NULL) == in[k]);
    CHECK(cm_idmap_put(&m, UINT32_MAX, 1) == CM_EINVAL);
    cm_idmap_free(&m);
}

/* The one rule between rectangles and boxes: an edge within a billionth
 * of a cell (relative) of a border is on it, near the origin and far from
 * it alike; otherwise the box holds every cell the rectangle meets; a
 * box's rectangle gives the box back. */
static void rectangle_box_rule(void)
{
    const cm_lattice lat = {2, {-3.0, 100.0}, {0.25, 0.1}};
    CHECK_INT(cm_lattice_border(&lat, 0, -3.0 + 4 * 0.25, 0), 4);
    CHECK_INT(cm_lattice_border(&lat, 0, -3.0 + 4 * 0.25, 1), 4);
    CHECK_INT(cm_lattice_border(&lat, 0, -2.1, 0), 3); /* c = 3.6 */
    CHECK_INT(cm_lattice_border(&lat, 0, -2.1, 1), 4);
    /* 10^7 cells out: 0.1 + 10^7 * 0.1 is not exactly representable */
    const double far = 100.0 + 1e7 * 0.1;
    CHECK_INT(cm_lattice_border(&lat, 1, far, 0), 10000000);
    CHECK_INT(cm_lattice_border(&lat, 1, far, 1), 10000000);
    CHECK_INT(cm_lattice_border(&lat, 1, far - 0.05, 0), 9999999);
    CHECK_INT(cm_lattice_border(&lat, 1, far - 0.05, 1), 10000000);
    CHECK_INT(cm_lattice_border(&lat, 0, 1e300, 1), CM_WORLD_LIMIT);
    CHECK_INT(cm_lattice_border(&lat, 0, -1e300, 0), -CM_WORLD_LIMIT);
    const cm_box box = {2, {-7, 9999990}, {12, 10000003}};
    double lo[2], hi[2];
    cm_box_rect(&lat, &box, 2, lo, hi);
    for (int d = 0; d < 2; d++) {
        CHECK_INT(cm_lattice_border(&lat, d, lo[d], 0), box.lo[d]);
        CHECK_INT(cm_lattice_border(&lat, d, hi[d], 1), box.hi[d]);
        CHECK(lo[d] == cm_lattice_edge(&lat, d, box.lo[d]));
    }
}

int main(void)
{
    rectangle_box_rule();
    test_idmap();
    point_cell_round_trip();
    edges();
    checks();
    box_index_round_trip();
    CHECK_DONE();
}
