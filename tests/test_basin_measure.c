/* Basin measures (cellmap/basin_measure) on windows whose answers are
 * known: a 4x4 window's box entropies by hand; a straight (slanted)
 * boundary between two basins, whose basin entropy falls with the box
 * (Sb ~ eps), whose boundary boxes stay under log 2, and whose uncertain
 * fraction grows as eps^1 (alpha = 1, Grebogi et al.); three sectors
 * meeting at one point (not Wada: only cells near the point see all
 * three); a window where every 3x3 block holds all three labels (Wada at
 * r = 1); uncomputed cells left out; bad requests; slabs of a window,
 * each with the rows around it, add up to the whole window's counts. */
#include <math.h>
#include <stdlib.h>

#include "cellmap/basin_measure.h"
#include "check.h"

enum { N = 400 };

static cm_label_grid grid2(int32_t *label, int64_t nx, int64_t ny, int32_t hi)
{
    return (cm_label_grid){.dim = 2, .n = {nx, ny}, .label = label, .lo = -2, .hi = hi};
}

static void test_by_hand(void)
{
    /* boxes of 2: {1,1,1,1} -> 0; {1,2,1,2} -> ln 2; {2,2,2,3} -> 0.5623;
     * {3,3,3,3} -> 0 */
    int32_t l[16] = {1, 1, 1, 2, 1, 1, 1, 2, 2, 2, 3, 3, 2, 3, 3, 3};
    const cm_label_grid g = grid2(l, 4, 4, 3);
    cm_entropy e;
    char msg[256];
    double map[4];
    CHECK(cm_basin_entropy(&g, 2, &e, map, msg, sizeof msg) == CM_OK);
    const double h3 = -(0.75 * log(0.75) + 0.25 * log(0.25));
    CHECK(map[0] == 0 && map[3] == 0); /* boxes in C order */
    CHECK_NEAR(map[1], log(2.0), 1e-15);
    CHECK_NEAR(map[2], h3, 1e-15);
    CHECK_INT(e.boxes, 4);
    CHECK_INT(e.boundary, 2);
    CHECK_NEAR(e.sb, (log(2.0) + h3) / 4, 1e-15);
    CHECK_NEAR(e.sbb, (log(2.0) + h3) / 2, 1e-15);
    /* an uncomputed cell takes its box out */
    l[0] = -1;
    CHECK(cm_basin_entropy(&g, 2, &e, map, msg, sizeof msg) == CM_OK);
    CHECK(isnan(map[0]) && map[3] == 0);
    CHECK_INT(e.boxes, 3);
    CHECK_NEAR(e.sb, (log(2.0) + h3) / 3, 1e-15);
    CHECK(cm_basin_entropy(&g, 5, &e, NULL, msg, sizeof msg) == CM_EINVAL);
}

static void test_straight_boundary(void)
{
    int32_t *l = malloc(N * N * sizeof *l);
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++)
            l[i * N + j] = i + 0.37 * j < 250.3 ? 1 : 2;
    const cm_label_grid g = grid2(l, N, N, 2);
    char msg[256];
    double last = 0;
    for (int eps = 2; eps <= 16; eps *= 2) {
        cm_entropy e;
        CHECK(cm_basin_entropy(&g, eps, &e, NULL, msg, sizeof msg) == CM_OK);
        printf("straight boundary: eps %2d Sb %.5f Sbb %.4f (%llu of %llu boxes)\n", eps, e.sb,
               e.sbb, (unsigned long long)e.boundary, (unsigned long long)e.boxes);
        CHECK(e.sb > last);   /* Sb grows with the box: it tends to 0 as they shrink */
        CHECK(e.sb < 0.02 * eps);
        CHECK(e.sbb < log(2.0));
        last = e.sb;
    }
    double lf[5], le[5];
    for (int k = 0; k < 5; k++) {
        double f;
        uint64_t counted;
        CHECK(cm_uncertain_fraction(&g, 1 << k, &f, &counted, NULL, msg, sizeof msg) == CM_OK);
        lf[k] = log(f), le[k] = log(1 << k);
    }
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int k = 0; k < 5; k++)
        sx += le[k], sy += lf[k], sxx += le[k] * le[k], sxy += le[k] * lf[k];
    const double alpha = (5 * sxy - sx * sy) / (5 * sxx - sx * sx);
    printf("straight boundary: uncertainty exponent %.4f\n", alpha);
    CHECK_NEAR(alpha, 1.0, 0.05);
    cm_wada w;
    CHECK(cm_wada_test(&g, 2, &w, msg, sizeof msg) == CM_EINVAL); /* two basins */
    free(l);
}

static void test_wada(void)
{
    int32_t *l = malloc(N * N * sizeof *l);
    /* three sectors about the centre: every boundary is between two */
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++) {
            const double a = atan2(i - N / 2 + 0.5, j - N / 2 + 0.5);
            l[i * N + j] = a < -1 ? 1 : a < 1.5 ? 2 : 3;
        }
    cm_label_grid g = grid2(l, N, N, 3);
    cm_wada w;
    char msg[256];
    CHECK(cm_wada_test(&g, 3, &w, msg, sizeof msg) == CM_OK);
    printf("three sectors: %d basins, %llu boundary cells, seeing all: %.4f %.4f %.4f\n",
           w.basins, (unsigned long long)w.boundary, w.fraction[0], w.fraction[1], w.fraction[2]);
    CHECK_INT(w.basins, 3);
    CHECK(w.boundary > 3 * N / 2 && w.boundary < 3 * N * 2);
    CHECK(w.fraction[2] < 0.05 && w.fraction[0] <= w.fraction[2]);
    /* stripes 1, 2, 3, 1, 2, 3, ...: every boundary cell sees all three
     * within one cell but those of the window's edge columns */
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++)
            l[i * N + j] = 1 + j % 3;
    CHECK(cm_wada_test(&g, 1, &w, msg, sizeof msg) == CM_OK);
    CHECK_INT(w.boundary, N * N);
    CHECK_NEAR(w.fraction[0], (double)(N - 2) / N, 1e-12);
    /* the diverged (0) and outside (-2) labels are basins too */
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++)
            l[i * N + j] = (int32_t[]){-2, 0, 1}[j % 3];
    g.hi = 1;
    CHECK(cm_wada_test(&g, 1, &w, msg, sizeof msg) == CM_OK);
    CHECK_INT(w.basins, 3);
    CHECK(cm_wada_test(&g, 0, &w, msg, sizeof msg) == CM_EINVAL);
    free(l);
}

/* A window of three sectors with wiggly boundaries and a few uncomputed
 * cells, measured whole and as slabs of 7 rows with 5 rows around them. */
static void test_slabs(void)
{
    enum { NX = 61, NY = 45, CORE = 7, HALO = 5 };
    int32_t *l = malloc(NX * NY * sizeof *l);
    for (int i = 0; i < NX; i++)
        for (int j = 0; j < NY; j++) {
            const double turn = atan2(j - NY / 2.0, i - NX / 2.0) / (2 * 3.141592653589793) + 1.5;
            const int sector = (int)floor(3 * turn + 0.4 * sin(0.9 * i) * cos(0.7 * j)) % 3;
            l[i * NY + j] = (i * 3 + j) % 23 == 0 ? -1 : sector + 1;
        }
    const cm_label_grid whole = grid2(l, NX, NY, 3);
    char msg[256];
    cm_entropy e_whole[2], e_sum[2] = {{0}};
    uint64_t counted_whole[3], uncertain_whole[3], counted_sum[3] = {0}, uncertain_sum[3] = {0};
    cm_wada w_whole, w;
    uint64_t boundary = 0, seeing[3] = {0};
    const int boxes[2] = {3, 4}, eps[3] = {1, 2, 5};
    double f;
    for (int k = 0; k < 2; k++)
        CHECK(cm_basin_entropy(&whole, boxes[k], &e_whole[k], NULL, msg, sizeof msg) == CM_OK);
    for (int k = 0; k < 3; k++)
        CHECK(cm_uncertain_fraction(&whole, eps[k], &f, &counted_whole[k], &uncertain_whole[k],
                                    msg, sizeof msg) == CM_OK);
    CHECK(cm_wada_test(&whole, 3, &w_whole, msg, sizeof msg) == CM_OK);
    for (int c0 = 0; c0 < NX; c0 += CORE) {
        const int lo = c0 - HALO < 0 ? 0 : c0 - HALO;
        const int c1 = c0 + CORE < NX ? c0 + CORE : NX;
        const int hi = c1 + HALO < NX ? c1 + HALO : NX;
        cm_label_grid g = grid2(l + lo * NY, hi - lo, NY, 3);
        g.row0 = lo, g.window_rows = NX, g.core_lo = c0 - lo, g.core_hi = c1 - lo;
        g.basins = w_whole.basins;
        for (int k = 0; k < 2; k++) {
            cm_entropy e;
            CHECK(cm_basin_entropy(&g, boxes[k], &e, NULL, msg, sizeof msg) == CM_OK);
            e_sum[k].boxes += e.boxes, e_sum[k].boundary += e.boundary;
            e_sum[k].sum += e.sum, e_sum[k].sum_boundary += e.sum_boundary;
        }
        for (int k = 0; k < 3; k++) {
            uint64_t counted, uncertain;
            CHECK(cm_uncertain_fraction(&g, eps[k], &f, &counted, &uncertain, msg,
                                        sizeof msg) == CM_OK);
            counted_sum[k] += counted, uncertain_sum[k] += uncertain;
        }
        CHECK(cm_wada_test(&g, 3, &w, msg, sizeof msg) == CM_OK);
        boundary += w.boundary;
        for (int r = 0; r < 3; r++)
            seeing[r] += w.seeing[r];
    }
    for (int k = 0; k < 2; k++) {
        CHECK(e_sum[k].boxes == e_whole[k].boxes && e_sum[k].boundary == e_whole[k].boundary);
        CHECK(e_whole[k].boundary > 10 && e_whole[k].boxes > e_whole[k].boundary);
        CHECK(fabs(e_sum[k].sum - e_whole[k].sum) < 1e-9 * e_whole[k].sum);
        CHECK(fabs(e_sum[k].sum_boundary - e_whole[k].sum_boundary) < 1e-9 * e_whole[k].sum);
    }
    for (int k = 0; k < 3; k++)
        CHECK(counted_sum[k] == counted_whole[k] && uncertain_sum[k] == uncertain_whole[k] &&
              uncertain_whole[k] > 0 && uncertain_whole[k] < counted_whole[k]);
    CHECK(boundary == w_whole.boundary && boundary > 100);
    for (int r = 0; r < 3; r++)
        CHECK(seeing[r] == w_whole.seeing[r]);
    CHECK(w_whole.seeing[0] < w_whole.seeing[2]);
    free(l);
}

int main(void)
{
    test_by_hand();
    test_straight_boundary();
    test_wada();
    test_slabs();
    CHECK_DONE();
}
