/* Tracking a sweep's attractors (lib/sweep.h): matching by the distance
 * between centres, nearest pairs first, within the share of the region
 * asked; on a periodic coordinate (a pendulum's angle on -pi:pi) the
 * distance goes the shorter way round, so an attractor that crosses the
 * cut at +-pi keeps its match instead of vanishing and appearing. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "lib/sweep.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static sweep_point point_of(sweep_attractor *att, uint32_t n)
{
    sweep_point p;
    memset(&p, 0, sizeof p);
    p.att = att, p.attractors = n;
    return p;
}

int main(void)
{
    sweep_args a;
    memset(&a, 0, sizeof a);
    a.match = 0.05;
    sweep_result r;
    memset(&r, 0, sizeof r);
    r.lat = (cm_lattice){2, {-M_PI, -4}, {2 * M_PI / 100, 8.0 / 100}};
    r.box = (cm_box){2, {0, 0}, {100, 100}};
    /* at one value, near +pi and near 0; at the next, past the cut and near 0 */
    sweep_attractor p_att[2] = {{.centre = {3.10, 1.0}}, {.centre = {0.05, 0.0}}};
    sweep_attractor q_att[2] = {{.centre = {0.06, 0.01}}, {.centre = {-3.12, 1.02}}};
    const sweep_point p = point_of(p_att, 2), q = point_of(q_att, 2);
    int pair[2];
    uint32_t matched;

    /* not periodic: 6.22 apart of 6.28, no match across the cut */
    CHECK(fabs(sweep_distance(&r, &p_att[0], &q_att[1]) - 6.22 / (2 * M_PI)) < 1e-12);
    CHECK(sweep_match(&a, &r, &p, &q, pair, &matched) == CM_OK);
    CHECK_INT(matched, 1);
    CHECK_INT(pair[0], 1);
    CHECK_INT(pair[1], -1);

    /* the angle periodic: 0.0632 apart the short way, both matched */
    r.period[0] = 2 * M_PI;
    CHECK(fabs(sweep_distance(&r, &p_att[0], &q_att[1]) - (2 * M_PI - 6.22) / (2 * M_PI)) <
          1e-12);
    CHECK(sweep_match(&a, &r, &p, &q, pair, &matched) == CM_OK);
    CHECK_INT(matched, 2);
    CHECK_INT(pair[0], 1);
    CHECK_INT(pair[1], 0);

    /* beyond the distance asked: no match, periodic or not */
    a.match = 0.005;
    CHECK(sweep_match(&a, &r, &p, &q, pair, &matched) == CM_OK);
    CHECK_INT(matched, 1);
    CHECK_INT(pair[1], -1);
    CHECK_DONE();
}
