/* Simple cell mapping reproduces the thesis' published pictures (docs/models.md
 * 6.7): where the attractors are, and how many. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/scm.h"
#include "check.h"
#include "models/registry.h"

typedef struct solved {
    cm_region r;
    cm_group_info *g;
} solved;

static solved run_model(const char *model, const char *params, double x0, double x1, double v0,
                        double v1, int64_t nx, int64_t nv, int max_steps)
{
    cm_model m;
    char msg[256];
    const char *texts[1] = {params};
    solved s;
    memset(&s, 0, sizeof s);
    if (cm_model_create(model, texts, 1, &m, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "%s\n", msg);
        exit(1);
    }
    const cm_lattice lat = {2, {x0, v0}, {(x1 - x0) / (double)nx, (v1 - v0) / (double)nv}};
    const cm_box box = {2, {0, 0}, {nx, nv}};
    const cm_scm_options opt = {.max_steps = max_steps};
    CHECK(cm_region_alloc(&s.r, &box, msg, sizeof msg) == CM_OK);
    CHECK(cm_scm_solve(&m, &lat, &opt, &s.r, msg, sizeof msg) == CM_OK);
    CHECK(cm_scm_describe(&m, &lat, &s.r, &s.g, NULL, msg, sizeof msg) == CM_OK);
    cm_model_release(&m);
    return s;
}

static solved run(const char *params, double x0, double x1, double v0, double v1, int64_t nx,
                  int64_t nv, int max_steps)
{
    return run_model("microchaos-pd", params, x0, x1, v0, v1, nx, nv, max_steps);
}

static void release(solved *s)
{
    cm_region_free(&s->r);
    free(s->g);
}

/* Cells of all groups whose periodic cells lie within the x-interval. */
static uint64_t basin_between(const solved *s, double lo, double hi, uint64_t min_basin)
{
    uint64_t cells = 0;
    for (uint32_t k = 0; k < s->r.ngroups; k++)
        if (s->g[k].basin_cells >= min_basin && s->g[k].lo[0] > lo && s->g[k].hi[0] < hi)
            cells += s->g[k].basin_cells;
    return cells;
}

/* The next of a fixed sequence of random cells of an nx x nv lattice over
 * box: its index, and its centre in at. */
static uint64_t random_cell(uint64_t *seed, const double box[4], int64_t nx, int64_t nv,
                            double at[2])
{
    *seed = *seed * 6364136223846793005ULL + 1442695040888963407ULL;
    const uint64_t i = (*seed >> 33) % (uint64_t)(nx * nv);
    at[0] = box[0] + ((double)(i % (uint64_t)nx) + 0.5) * (box[1] - box[0]) / (double)nx;
    at[1] = box[2] + ((double)(i / (uint64_t)nx) + 0.5) * (box[3] - box[2]) / (double)nv;
    return i;
}

/* The sink cells of an nx x nv lattice over box (into *sink), and how many
 * of them lie in the corners where x and v have one sign or in the top and
 * bottom rows (|v| > 300), where Figs. 4.21 and 4.30 put the sink. */
static uint64_t sink_in_corners(const solved *s, const double box[4], int64_t nx, int64_t nv,
                                uint64_t *sink)
{
    const double wx = (box[1] - box[0]) / (double)nx, wv = (box[3] - box[2]) / (double)nv;
    uint64_t corners = 0;
    for (uint64_t i = 0; i < s->r.ncells; i++) {
        if (s->r.group[i] != 0)
            continue;
        const double x = box[0] + ((double)(i % (uint64_t)nx) + 0.5) * wx,
                     v = box[2] + ((double)(i / (uint64_t)nx) + 0.5) * wv;
        ++*sink;
        corners += x * v > 0 || fabs(v) > 300;
    }
    return corners;
}

/* Sec. 4.6.3 (alpha = 0.078, beta = 0, P = 0.007, D = 0.02), the left region
 * of the C-SCM example: the small chaotic attractors at the crossings of
 * SW_1, SW_2, SW_3 with the x-axis (x = m/P), and nothing else of size. */
static void cscm_example(void)
{
    solved s = run("alpha=0.078,beta=0,P=0.007,D=0.02", 0, 500, -40, 40, 1000, 1000, 1);
    uint64_t near_switching_lines = 0, large = 0;
    for (int m = 1; m <= 3; m++) {
        const double x = m / 0.007;
        const uint64_t b = basin_between(&s, x - 2.5, x + 2.5, 5000);
        fprintf(stderr, "4.6.3: basin of the attractor at SW_%d (x = %.2f): %llu cells\n", m, x,
                (unsigned long long)b);
        CHECK(b > 20000);
        near_switching_lines += b;
    }
    for (uint32_t k = 0; k < s.r.ngroups; k++) {
        if (s.g[k].basin_cells >= 5000) {
            large += s.g[k].basin_cells;
            CHECK(fabs(s.g[k].centre[1]) < 1.0); /* on the x-axis */
        }
    }
    CHECK_INT(large, near_switching_lines);
    release(&s);
}

/* Fig. 4.16 (0.8, 0.3, P = 0.7, D = 0.6): two attractors at SW_5 and SW_6,
 * between the fixed points x_4*, x_5*, x_6* (x_m* = m/alpha^2); the objects
 * at SW_4 and SW_7 are repellers, so little can settle there. */
static void fig_4_16(void)
{
    solved s = run("alpha=0.8,beta=0.3,P=0.7,D=0.6", -13, 13, -4, 4, 1300, 400, 1);
    const double xs = 1 / 0.64; /* x_m* = m xs */
    const uint64_t total = s.r.ncells;
    const uint64_t sw4 = basin_between(&s, 3 * xs, 4 * xs, 1);
    const uint64_t sw5 = basin_between(&s, 4 * xs, 5 * xs, 1);
    const uint64_t sw6 = basin_between(&s, 5 * xs, 6 * xs, 1);
    const uint64_t sw7 = basin_between(&s, 6 * xs, 7 * xs, 1);
    fprintf(stderr, "Fig 4.16 basin shares: SW4 %.3f SW5 %.3f SW6 %.3f SW7 %.3f\n",
            (double)sw4 / total, (double)sw5 / total, (double)sw6 / total, (double)sw7 / total);
    CHECK(sw5 > total / 10);
    CHECK(sw6 > total / 10);
    CHECK(sw4 < total / 20);
    CHECK(sw7 < total / 20);
    /* the mirror image on the negative side */
    CHECK_INT(basin_between(&s, -5 * xs, -4 * xs, 1), sw5);
    /* At SW_7 cell mapping finds cycles on the repeller (a period-25 group
     * on these cells) whose cells' true orbits leave for SW_6; their basins
     * shrink with the cells: 2.9 % here, 0.1 % on cells half as large. */
    CHECK(sw7 > total / 50);
    cm_model m;
    char msg[256];
    const char *texts[1] = {"alpha=0.8,beta=0.3,P=0.7,D=0.6"};
    CHECK(cm_model_create("microchaos-pd", texts, 1, &m, msg, sizeof msg) == CM_OK);
    for (uint32_t k = 0; k < s.r.ngroups; k++) {
        if (!(s.g[k].lo[0] > 6 * xs && s.g[k].hi[0] < 7 * xs && s.g[k].basin_cells > total / 100))
            continue;
        double x[2] = {s.g[k].centre[0], s.g[k].centre[1]}, y[2];
        for (int t = 0; t < 5000; t++) {
            CHECK_INT(m.step(&m, x, y), CM_STEP_OK);
            x[0] = y[0], x[1] = y[1];
        }
        CHECK(x[0] > 5 * xs && x[0] < 6 * xs); /* at SW_6 */
    }
    cm_model_release(&m);
    release(&s);
    solved fine = run("alpha=0.8,beta=0.3,P=0.7,D=0.6", -13, 13, -4, 4, 2600, 800, 1);
    const uint64_t sw7_fine = basin_between(&fine, 6 * xs, 7 * xs, 1);
    fprintf(stderr, "Fig 4.16 on cells of 0.01: SW7 %.4f\n", (double)sw7_fine / fine.r.ncells);
    CHECK(sw7_fine < fine.r.ncells / 500);
    release(&fine);
}

/* Fig. 4.21 (alpha = 6.8511e-3, beta = 0, P = 5.4997e-5, D = 2.5665e-3):
 * twelve tiny attractors, one at each SW_m, 1 <= |m| <= m_max = 6, i.e. one
 * between each pair of neighbouring fixed points x_{m-1}*, x_m* (x_m* =
 * m/alpha^2), the interval SW_m crosses. The sampling step is short compared
 * with the cells, so images are re-stepped. */
static void fig_4_21(void)
{
    const double P = 5.4997e-5, a2 = 6.8511e-3 * 6.8511e-3;
    solved s = run("alpha=6.8511e-3,beta=0,P=5.4997e-5,D=2.5665e-3", -125000, 125000, -600, 600,
                   1000, 400, 100000);
    int found = 0, large = 0;
    for (uint32_t k = 0; k < s.r.ngroups; k++)
        large += s.g[k].basin_cells >= s.r.ncells / 200;
    for (int m = -6; m <= 6; m++) {
        if (m == 0)
            continue;
        const double lo = (m > 0 ? m - 1 : m) / a2, hi = (m > 0 ? m : m + 1) / a2;
        CHECK(lo < m / P && m / P < hi);
        found += basin_between(&s, lo, hi, s.r.ncells / 200) > 0;
    }
    fprintf(stderr, "Fig 4.21: %d of 12 attractors found, %d large groups\n", found, large);
    CHECK_INT(found, 12);
    CHECK_INT(large, 12);
    release(&s);
}

/* Where the true orbit from (x, v) goes: 0 if it leaves the box within
 * `steps` steps, else the switching line m (x near m/P) it ends near. */
static int orbit_fate(const cm_model *m, double P, const double s0[2], const double box[4],
                      int steps)
{
    double s[2] = {s0[0], s0[1]}, y[2];
    for (int k = 0; k < steps; k++) {
        if (m->step(m, s, y) != 0 || y[0] < box[0] || y[0] >= box[1] || y[1] < box[2] ||
            y[1] >= box[3])
            return 0;
        s[0] = y[0], s[1] = y[1];
    }
    return (int)lround(s[0] * P);
}

/* The slow v of Figs. 4.21 and 4.30 (max-steps 100000 on both lattices):
 * on the coarse lattice more than 80 % of the moving cells stay in their v
 * row; on the fine one, returned solved with that share in *fine_share,
 * under a quarter do. */
static solved slow_rows_then_fine(const char *model, const char *params, const double box[4],
                                  const int64_t coarse[2], const int64_t fine[2],
                                  double *fine_share)
{
    double share[CM_MAX_DIM];
    solved c = run_model(model, params, box[0], box[1], box[2], box[3], coarse[0], coarse[1],
                         100000);
    cm_scm_slow_share(&c.r, 0, share);
    CHECK(share[1] > 0.8);
    release(&c);
    solved s = run_model(model, params, box[0], box[1], box[2], box[3], fine[0], fine[1], 100000);
    cm_scm_slow_share(&s.r, 0, share);
    CHECK(share[1] < 0.25);
    *fine_share = share[1];
    return s;
}

/* Fig. 4.21 as the thesis draws it. On the 1000 x 400 lattice of the
 * figure above, cells are 3 units tall in v while v changes by less than
 * 1.5 per step: 85 % of the cells that move stay in their v row, cell
 * mapping cannot follow v's decay, and 80 % of the box goes to the sink.
 * On 4000 x 3200 cells the v row holds under 25 %; the sink is the two
 * corners where the orbits leave (x and v of one sign, or |v| > 300), a
 * third of the box; every switching line keeps its attractor; and 1000
 * random cells go where their true orbits go (the sink, or the same
 * switching line) to 95 %. */
static void fig_4_21_fine(void)
{
    const char *params = "alpha=6.8511e-3,beta=0,P=5.4997e-5,D=2.5665e-3";
    const double P = 5.4997e-5, a2 = 6.8511e-3 * 6.8511e-3, box[4] = {-125000, 125000, -600, 600};
    const int64_t nx = 4000, nv = 3200;
    double share;
    solved s = slow_rows_then_fine("microchaos-pd", params, box, (const int64_t[2]){1000, 400},
                                   (const int64_t[2]){nx, nv}, &share);
    uint64_t sink = 0;
    const uint64_t corners = sink_in_corners(&s, box, nx, nv, &sink);
    CHECK((double)sink <= 0.35 * (double)s.r.ncells);
    CHECK(corners == sink);
    int lines = 0;
    for (int m = -6; m <= 6; m++)
        if (m != 0)
            lines += basin_between(&s, (m > 0 ? m - 1 : m) / a2, (m > 0 ? m : m + 1) / a2,
                                   s.r.ncells / 1000) > 0;
    CHECK_INT(lines, 12);
    cm_model m;
    char msg[256];
    const char *texts[1] = {params};
    CHECK(cm_model_create("microchaos-pd", texts, 1, &m, msg, sizeof msg) == CM_OK);
    int agree = 0;
    uint64_t seed = 12345;
    for (int k = 0; k < 1000; k++) {
        double at[2];
        const uint64_t i = random_cell(&seed, box, nx, nv, at);
        const uint32_t g = s.r.group[i];
        const int cell_fate = g == 0 ? 0 : (int)lround(s.g[g - 1].centre[0] * P);
        agree += cell_fate == orbit_fate(&m, P, at, box, 20000);
    }
    fprintf(stderr, "Fig 4.21 on 4000 x 3200 cells: sink %.1f %%, %d of 1000 cells as their "
                    "orbits, %.0f %% of moving cells in their v row\n",
            100.0 * (double)sink / (double)s.r.ncells, agree, 100 * share);
    CHECK(agree >= 950);
    cm_model_release(&m);
    release(&s);
}

/* Where the true orbit of the hybrid map from (x, v) goes: 0 if it leaves
 * the box within `steps` steps; 1000 + m if it comes to rest in the sticking
 * zone about x_m* = m/alpha^2; else the switching line m (x near m/P) it ends
 * near. */
static int friction_fate(const cm_model *m, double P, double a2, const double s0[2],
                         const double box[4], int steps)
{
    double s[2] = {s0[0], s0[1]}, y[2];
    for (int k = 0; k < steps; k++) {
        if (m->step(m, s, y) != 0 || y[0] < box[0] || y[0] >= box[1] || y[1] < box[2] ||
            y[1] >= box[3])
            return 0;
        if (y[0] == s[0] && y[1] == s[1] && y[1] == 0)
            return 1000 + (int)lround(y[0] * a2);
        s[0] = y[0], s[1] = y[1];
    }
    return (int)lround(s[0] * P);
}

static int friction_cell_fate(const solved *s, uint64_t i, double P, double a2)
{
    const uint32_t g = s->r.group[i];
    if (g == 0)
        return 0;
    const cm_group_info *gi = &s->g[g - 1];
    return gi->kind == CM_GROUP_STICKING ? 1000 + (int)lround(gi->centre[0] * a2)
                                         : (int)lround(gi->centre[0] * P);
}

/* Fig. 4.30 (alpha = 6.53e-3, beta = 0, P = 5.5e-5, D = 2.5e-3, mu = 0.095)
 * has Fig. 4.21's slow v: on the 3-unit rows of an 800 x 201 lattice over
 * -301.5:301.5 in v, 83 % of the moving cells stay in their row and 59 % of
 * the box goes to the sink. On 3200 x 1609 cells (0.375 tall, a row on the
 * rest states v = 0) the sink is the two corners where x and v have one
 * sign (and the outermost rows), and 1000 random cells go where their true
 * orbits go: into the sink or not to 99 %; to the same switching line or
 * sticking zone to 85 % (orbits next to the outer sticking zones come to
 * rest there late, which the cells' cycles at the switching line do not
 * show). */
static void fig_4_30_fine(void)
{
    const char *params = "alpha=6.53e-3,beta=0,P=5.5e-5,D=2.5e-3,mu=0.095";
    const double P = 5.5e-5, a2 = 6.53e-3 * 6.53e-3, box[4] = {-100000, 100000, -301.5, 301.5};
    const int64_t nx = 3200, nv = 1609;
    double share;
    solved s = slow_rows_then_fine("microchaos-pd-friction", params, box,
                                   (const int64_t[2]){800, 201}, (const int64_t[2]){nx, nv},
                                   &share);
    uint64_t sink = 0;
    const uint64_t corners = sink_in_corners(&s, box, nx, nv, &sink);
    CHECK((double)sink <= 0.1 * (double)s.r.ncells);
    CHECK(corners == sink);
    cm_model m;
    char msg[256];
    const char *texts[1] = {params};
    CHECK(cm_model_create("microchaos-pd-friction", texts, 1, &m, msg, sizeof msg) == CM_OK);
    int agree = 0, sink_agree = 0;
    uint64_t seed = 12345;
    for (int k = 0; k < 1000; k++) {
        double at[2];
        const uint64_t i = random_cell(&seed, box, nx, nv, at);
        const int cell = friction_cell_fate(&s, i, P, a2),
                  orbit = friction_fate(&m, P, a2, at, box, 20000);
        agree += cell == orbit;
        sink_agree += (cell == 0) == (orbit == 0);
    }
    fprintf(stderr, "Fig 4.30 on 3200 x 1609 cells: sink %.1f %%, %d of 1000 cells as their "
                    "orbits (%d sink or not), %.0f %% of moving cells in their v row\n",
            100.0 * (double)sink / (double)s.r.ncells, agree, sink_agree, 100 * share);
    CHECK(sink_agree >= 990);
    CHECK(agree >= 850);
    cm_model_release(&m);
    release(&s);
}

/* With the printed parameters of Fig. 4.30 the sticking zone of level 3
 * absorbs the attractor at SW_4 (x = 4/P = 72727) near mu = alpha^2 m_max / P
 * - (m_max - 1) = 0.10116, not at the printed 0.095: the true orbit from
 * (73062.5, -7.5) still moves near SW_4 after 300000 steps at mu = 0.095 and
 * 0.101, and comes to rest in the zone about x_3* at 0.1012. */
static void fig_4_30_absorption(void)
{
    const double P = 5.5e-5, a2 = 6.53e-3 * 6.53e-3, box[4] = {-1e6, 1e6, -1e6, 1e6};
    const char *params[3] = {"alpha=6.53e-3,beta=0,P=5.5e-5,D=2.5e-3,mu=0.095",
                             "alpha=6.53e-3,beta=0,P=5.5e-5,D=2.5e-3,mu=0.101",
                             "alpha=6.53e-3,beta=0,P=5.5e-5,D=2.5e-3,mu=0.1012"};
    const int fate[3] = {4, 4, 1003};
    CHECK(fabs(a2 * 4 / P - 3 - 0.10116) < 1e-5);
    for (int k = 0; k < 3; k++) {
        cm_model m;
        char msg[256];
        CHECK(cm_model_create("microchaos-pd-friction", &params[k], 1, &m, msg, sizeof msg) ==
              CM_OK);
        const double at[2] = {73062.5, -7.5};
        CHECK_INT(friction_fate(&m, P, a2, at, box, 300000), fate[k]);
        cm_model_release(&m);
    }
}

int main(void)
{
    cscm_example();
    fig_4_16();
    fig_4_21();
    fig_4_21_fine();
    fig_4_30_fine();
    fig_4_30_absorption();
    CHECK_DONE();
}
