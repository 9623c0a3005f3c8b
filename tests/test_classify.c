/* Classification of functional graphs: cm_classify_threads against the plain
 * sequential algorithm written here (one walk at a time), on graphs chosen
 * to make interleaved walks meet: random maps, random permutations (long
 * cycles shared by many walks), one cycle through every cell, chains longer
 * than the path buffers, graphs that leave the region and graphs into
 * recorded exits, on 1 to 5 threads (cells cut into as many blocks, so
 * cycles and chains run through several blocks). Results must be equal cell
 * by cell, group ids included. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/classify.h"
#include "cellmap/scm.h"
#include "check.h"

#define OUTSIDE UINT32_C(0xFFFFFFFE)

/* The textbook algorithm: walk from each unvisited cell, label the path. */
static uint32_t reference(uint32_t n, const uint32_t *image, uint32_t *group, uint32_t *step,
                          int node_refs)
{
    enum { UNSEEN = 0, ON_PATH = 1, DONE = 2 };
    uint8_t *state = calloc(n, 1);
    uint32_t *path = malloc((size_t)n * sizeof *path);
    uint32_t *pos = malloc((size_t)n * sizeof *pos);
    uint32_t ngroups = 0;
    for (uint32_t start = 0; start < n; start++) {
        uint32_t len = 0, i = start;
        while (i < n && state[i] == UNSEEN) {
            state[i] = ON_PATH;
            pos[i] = len;
            path[len++] = i;
            i = image[i];
        }
        uint32_t g = 0, cycle_at = UINT32_MAX, tail = 0;
        if (i < n && state[i] == ON_PATH) {
            g = ++ngroups;
            cycle_at = pos[i];
        } else if (i < n) {
            g = group[i];
            tail = step[i];
        } else if (node_refs && cm_image_exit_index(i) >= 0) {
            g = CM_NODE_REF | (uint32_t)cm_image_exit_index(i);
        }
        for (uint32_t p = 0; p < len; p++) {
            group[path[p]] = g;
            step[path[p]] = cycle_at == UINT32_MAX ? tail + len - p
                                                   : (p >= cycle_at ? 0 : cycle_at - p);
            state[path[p]] = DONE;
        }
    }
    free(state);
    free(path);
    free(pos);
    return ngroups;
}

static uint64_t rng_state = 0x9E3779B97F4A7C15u;
static uint32_t rnd(uint32_t bound)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (uint32_t)(rng_state % bound);
}

/* Runs cm_classify on 1 to 5 threads (cells cut into as many blocks) and
 * the reference on image[] and compares; returns the group count. */
static uint32_t compare_refs(const char *what, uint32_t n, const uint32_t *image, int node_refs)
{
    uint32_t *g1 = malloc((size_t)n * 4), *s1 = malloc((size_t)n * 4);
    uint32_t *g2 = malloc((size_t)n * 4), *s2 = malloc((size_t)n * 4);
    const uint32_t ng2 = reference(n, image, g2, s2, node_refs);
    for (int threads = 1; threads <= 5; threads++) {
        uint32_t ng1 = 0;
        char msg[128];
        /* whatever the arrays held before: every cell must be written */
        memset(g1, 0xA5, (size_t)n * 4);
        memset(s1, 0x5A, (size_t)n * 4);
        CHECK(cm_classify_threads(n, image, g1, s1, &ng1, node_refs, threads, msg, sizeof msg) ==
              CM_OK);
        CHECK_INT(ng1, ng2);
        uint32_t bad = 0;
        for (uint32_t i = 0; i < n && bad < 5; i++) {
            if (g1[i] != g2[i] || s1[i] != s2[i]) {
                fprintf(stderr, "%s, %d threads: cell %u: group %u step %u, reference %u %u\n",
                        what, threads, i, g1[i], s1[i], g2[i], s2[i]);
                bad++;
            }
        }
        CHECK_INT(bad, 0);
    }
    free(g1);
    free(s1);
    free(g2);
    free(s2);
    return ng2;
}

static uint32_t compare(const char *what, uint32_t n, const uint32_t *image)
{
    return compare_refs(what, n, image, 0);
}

static void test_random_maps(void)
{
    for (uint32_t n = 1; n <= 5000; n = n * 3 + 1) {
        uint32_t *image = malloc((size_t)n * 4);
        for (int trial = 0; trial < 20; trial++) {
            const uint32_t leave_one_in = 2 + (uint32_t)trial * 7;
            for (uint32_t i = 0; i < n; i++)
                image[i] = rnd(leave_one_in) == 0 ? OUTSIDE : rnd(n);
            compare("random map", n, image);
        }
        free(image);
    }
}

/* Maps into a few cells near each cell: long trees, local cycles. */
static void test_local_maps(void)
{
    const uint32_t n = 200000;
    uint32_t *image = malloc((size_t)n * 4);
    for (uint32_t i = 0; i < n; i++) {
        const uint32_t j = i + rnd(64);
        image[i] = j >= 32 && j - 32 < n ? j - 32 : OUTSIDE;
    }
    CHECK(compare("local map", n, image) > 0);
    free(image);
}

static void test_permutations(void)
{
    for (uint32_t n = 2; n <= 300000; n *= 7) {
        uint32_t *image = malloc((size_t)n * 4);
        for (uint32_t i = 0; i < n; i++)
            image[i] = i;
        for (uint32_t i = n - 1; i > 0; i--) {
            const uint32_t j = rnd(i + 1), t = image[i];
            image[i] = image[j];
            image[j] = t;
        }
        compare("permutation", n, image);
        free(image);
    }
}

/* Every walk starts on the same cycle: walks meet at every step. */
static void test_one_cycle(void)
{
    for (uint32_t n = 1; n <= 100000; n = n * 10 + 3) {
        uint32_t *image = malloc((size_t)n * 4);
        for (uint32_t i = 0; i < n; i++)
            image[i] = (i + 1) % n;
        CHECK_INT(compare("one cycle (forward)", n, image), 1);
        for (uint32_t i = 0; i < n; i++)
            image[i] = (i + n - 1) % n;
        CHECK_INT(compare("one cycle (backward)", n, image), 1);
        free(image);
    }
}

/* Chains far longer than the path buffers: i -> i+1, leaving at the end,
 * and a chain ending in a cycle of two at its far end. */
static void test_long_chains(void)
{
    const uint32_t n = 300000;
    uint32_t *image = malloc((size_t)n * 4);
    for (uint32_t i = 0; i < n; i++)
        image[i] = i + 1 < n ? i + 1 : OUTSIDE;
    CHECK_INT(compare("chain to the outside", n, image), 0);
    image[n - 1] = n - 2;
    CHECK_INT(compare("chain to a cycle", n, image), 1);
    for (uint32_t i = 0; i < n; i++) /* the chain runs downwards, entered from above */
        image[i] = i > 0 ? i - 1 : 0;
    CHECK_INT(compare("descending chain", n, image), 1);
    free(image);
}

/* Chains into recorded exits (images CM_IMAGE_EXIT_BASE + k) take
 * CM_NODE_REF | k, through any number of blocks. */
static void test_node_refs(void)
{
    for (uint32_t n = 2; n <= 200000; n = n * 5 + 3) {
        uint32_t *image = malloc((size_t)n * 4);
        for (int trial = 0; trial < 4; trial++) {
            for (uint32_t i = 0; i < n; i++)
                image[i] = rnd(8) == 0 ? CM_IMAGE_EXIT_BASE + rnd(1000)
                           : rnd(8) == 0 ? OUTSIDE
                                          : rnd(n);
            compare_refs("exits", n, image, 1);
        }
        free(image);
    }
}

int main(void)
{
    test_random_maps();
    test_local_maps();
    test_permutations();
    test_one_cycle();
    test_long_chains();
    test_node_refs();
    CHECK_DONE();
}
