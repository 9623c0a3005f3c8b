/* Maps of ODE flows (models/ode_flow): stroboscopic and Poincare maps of
 * flows with known solutions, the sink cases, step_n against step, and the
 * forced Duffing oscillator's basins against long simulations. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/scm.h"
#include "check.h"
#include "models/map_lyapunov.h"
#include "models/ode_flow.h"
#include "models/params.h"
#include "models/registry.h"


#define RES 600 /* cells per side of -2.5:2.5 */
#define TWO_PI 6.283185307179586476925286766559

/* x'' + 2 zeta x' + x = 0; zeta is the context. */
static int damped_field(const cm_model *m, double t, const double *x, double *f)
{
    (void)t;
    const double zeta = *(const double *)m->ctx;
    f[0] = x[1];
    f[1] = -2 * zeta * x[1] - x[0];
    return 0;
}

static double section_x(const cm_model *m, double t, const double *x)
{
    (void)m, (void)t;
    return x[0];
}

/* x' = x^2: blows up at t = 1/x0. */
static int blowup_field(const cm_model *m, double t, const double *x, double *f)
{
    (void)m, (void)t;
    f[0] = x[0] * x[0];
    return 0;
}

/* Defined for x < 1 only. */
static int partial_field(const cm_model *m, double t, const double *x, double *f)
{
    (void)m, (void)t;
    f[0] = 1;
    return x[0] < 1 ? 0 : 1;
}

/* y' = 1 - e^(1000 (y - 5)): rises at rate 1 to a stiff wall at y = 5,
 * where it stops. A step that the error control grows on the flat part
 * overshoots the wall so far that the exponential overflows. */
static int wall_field(const cm_model *m, double t, const double *x, double *f)
{
    (void)m, (void)t;
    f[0] = 1 - exp(1000 * (x[0] - 5));
    return 0;
}

/* The rotation, recording the time of the first field evaluation after
 * the start (the first trial step's second stage). */
typedef struct first_probe {
    double t0, first;
} first_probe;

static int probed_rotation(const cm_model *m, double t, const double *x, double *f)
{
    first_probe *p = m->ctx;
    if (t > p->t0 && p->first == 0)
        p->first = t - p->t0;
    f[0] = x[1];
    f[1] = -x[0];
    return 0;
}

static cm_model flow_model(int dim, cm_flow f, void *ctx)
{
    cm_model m;
    memset(&m, 0, sizeof m);
    m.name = "test-flow";
    m.dim = dim;
    m.ctx = ctx;
    m.flow = f;
    char msg[256];
    const cm_status st = cm_flow_attach(&m, msg, sizeof msg);
    if (st != CM_OK)
        fprintf(stderr, "%s\n", msg);
    CHECK(st == CM_OK);
    return m;
}

/* The undamped oscillator over a period T rotates the state by T; with
 * damping the crossings of x = 0 upwards are 2 pi/omega_d apart and v
 * shrinks by exp(-zeta 2 pi/omega_d) between them. */
static void test_known_flows(void)
{
    double zeta = 0;
    cm_model rot = flow_model(2, (cm_flow){.field = damped_field, .period = 1.3}, &zeta);
    const double x[2] = {0.7, -0.2};
    double y[2];
    CHECK_INT(rot.step(&rot, x, y), CM_STEP_OK);
    CHECK_NEAR(y[0], x[0] * cos(1.3) + x[1] * sin(1.3), 1e-8);
    CHECK_NEAR(y[1], -x[0] * sin(1.3) + x[1] * cos(1.3), 1e-8);

    double zeta2 = 0.1;
    const double wd = sqrt(1 - zeta2 * zeta2), Td = TWO_PI / wd;
    cm_model up = flow_model(
        2, (cm_flow){.field = damped_field, .section = section_x, .direction = 1}, &zeta2);
    const double start[2] = {0, 1};
    double t_end;
    long steps;
    CHECK_INT(cm_flow_map(&up, start, y, &t_end, &steps), CM_STEP_OK);
    CHECK_NEAR(t_end, Td, 1e-9);
    CHECK(fabs(y[0]) < 1e-9);
    CHECK_NEAR(y[1], exp(-zeta2 * Td), 1e-8);
    CHECK(steps > 0);
    cm_model down = flow_model(
        2, (cm_flow){.field = damped_field, .section = section_x, .direction = -1}, &zeta2);
    CHECK_INT(cm_flow_map(&down, start, y, &t_end, NULL), CM_STEP_OK);
    CHECK_NEAR(t_end, Td / 2, 1e-9);
    CHECK_NEAR(y[1], -exp(-zeta2 * Td / 2), 1e-8);
    cm_model either = flow_model(
        2, (cm_flow){.field = damped_field, .section = section_x, .direction = 0}, &zeta2);
    CHECK_INT(cm_flow_map(&either, start, y, &t_end, NULL), CM_STEP_OK);
    CHECK_NEAR(t_end, Td / 2, 1e-9);
    /* a section the flow never reaches in t_max: no image */
    const double far[2] = {0, 0};
    CHECK_INT(cm_flow_map(&up, far, y, NULL, NULL), CM_STEP_NO_IMAGE);

    /* the section's settings as parameters: t_max = 5 stops short of the
     * crossing at 2 pi/omega_d; a coarse event_tol moves the crossing */
    static const cm_param_spec spec[] = {CM_FLOW_PARAM_SPECS, CM_FLOW_SECTION_PARAM_SPECS,
                                         {NULL, NULL, 0, 0, 0, NULL, NULL}};
    char msg[256];
    cm_model short_flight;
    memset(&short_flight, 0, sizeof short_flight);
    short_flight.name = "short";
    short_flight.dim = 2;
    short_flight.ctx = &zeta2;
    short_flight.flow = (cm_flow){.field = damped_field, .section = section_x, .direction = 1};
    CHECK(cm_params_defaults(spec, &short_flight.values, msg, sizeof msg) == CM_OK);
    CHECK(cm_params_set(&short_flight.values, "t_max=5,method=rkf45", msg, sizeof msg) == CM_OK);
    CHECK(cm_flow_attach(&short_flight, msg, sizeof msg) == CM_OK);
    CHECK(short_flight.flow.t_max == 5 && short_flight.flow.method == CM_FLOW_RKF45);
    CHECK_INT(cm_flow_map(&short_flight, start, y, NULL, NULL), CM_STEP_NO_IMAGE);
}

static void test_step_n(const cm_model *m);

/* The damped oscillator in (x, v) beside z' = -z: a third coordinate
 * that decays on its own. */
static int damped_and_decay(const cm_model *m, double t, const double *x, double *f)
{
    damped_field(m, t, x, f);
    f[2] = -x[2];
    return 0;
}

/* A section on a state plane: the map's state drops the plane's
 * coordinate, its names skip it, the return time is the flight, and the
 * settings come as parameters (section, level, crossing). */
static void test_plane_sections(void)
{
    static const char *const names[] = {"x", "v", "z"};
    double zeta = 0.1;
    const double wd = sqrt(1 - zeta * zeta), Td = TWO_PI / wd;
    cm_model up = flow_model(2, (cm_flow){.field = damped_and_decay, .plane = 1, .direction = 1},
                             &zeta);
    up.coord_names = names;
    CHECK_INT(cm_flow_dim(&up), 3);
    CHECK(strcmp(cm_model_coord_name(&up, 0), "v") == 0);
    CHECK(strcmp(cm_model_coord_name(&up, 1), "z") == 0);
    CHECK(strcmp(cm_flow_coord_name(&up, 0), "x") == 0);
    const double start[2] = {1, 0.5}; /* x = 0 (the plane), v = 1, z = 0.5 */
    double y[2], t_end;
    CHECK_INT(cm_flow_map(&up, start, y, &t_end, NULL), CM_STEP_OK);
    CHECK_NEAR(t_end, Td, 1e-9);
    CHECK_NEAR(y[0], exp(-zeta * Td), 1e-8);
    CHECK_NEAR(y[1], 0.5 * exp(-Td), 1e-8);
    CHECK_INT(up.step(&up, start, y), CM_STEP_OK); /* the engine's step agrees */
    CHECK_NEAR(y[0], exp(-zeta * Td), 1e-8);
    test_step_n(&up);

    /* as parameters: the plane v = 0 crossed downwards (x at its maximum,
     * a quarter period in for x = 0, v = 1 ... but the start is on v = 0) */
    static const cm_param_spec spec[] = {CM_FLOW_PLANE_PARAM_SPECS("x|v|z", "x", "0", "up"),
                                         CM_FLOW_SECTION_PARAM_SPECS, CM_FLOW_PARAM_SPECS,
                                         {NULL, NULL, 0, 0, 0, NULL, NULL}};
    char msg[256];
    cm_model down;
    memset(&down, 0, sizeof down);
    down.name = "down";
    down.dim = 2;
    down.ctx = &zeta;
    down.flow.field = damped_and_decay;
    CHECK(cm_params_defaults(spec, &down.values, msg, sizeof msg) == CM_OK);
    CHECK(cm_params_set(&down.values, "section=v,level=0,crossing=down", msg, sizeof msg) == CM_OK);
    CHECK(cm_flow_attach(&down, msg, sizeof msg) == CM_OK);
    CHECK(down.flow.plane == 2 && down.flow.direction == -1);
    /* from x = 1, v = 0 the velocity goes negative at once, so the next
     * downward crossing of v = 0 is a full period later: x shrinks by
     * exp(-zeta Td) */
    const double at_max[2] = {1, 0.25};
    CHECK_INT(cm_flow_map(&down, at_max, y, &t_end, NULL), CM_STEP_OK);
    CHECK_NEAR(t_end, Td, 1e-9);
    CHECK_NEAR(y[0], exp(-zeta * Td), 1e-8);
    CHECK_NEAR(y[1], 0.25 * exp(-Td), 1e-8);

    /* refused: a plane beyond the flow's coordinates, a plane and a
     * section function both */
    cm_model bad;
    memset(&bad, 0, sizeof bad);
    bad.name = "bad";
    bad.dim = 2;
    bad.flow = (cm_flow){.field = damped_and_decay, .plane = 4};
    CHECK(cm_flow_attach(&bad, msg, sizeof msg) == CM_EINVAL);
    CHECK(strstr(msg, "plane") != NULL);
    bad.flow = (cm_flow){.field = damped_and_decay, .plane = 1, .section = section_x};
    CHECK(cm_flow_attach(&bad, msg, sizeof msg) == CM_EINVAL);
    CHECK(strstr(msg, "both") != NULL);
}

/* y' = A y with A's eigenvalues -1 and -1000 (eigenvectors (1, 1) and
 * (1, -1)): from (2, 0), y = e^-t (1, 1) + e^-1000t (1, -1). */
static int stiff_field(const cm_model *m, double t, const double *x, double *f)
{
    (void)m, (void)t;
    f[0] = -500.5 * x[0] + 499.5 * x[1];
    f[1] = 499.5 * x[0] - 500.5 * x[1];
    return 0;
}

/* Every integrator meets the stiff system's solution at t = 1 and 20; over
 * the long run the implicit ones in fewer steps than the explicit pair,
 * whose step the eigenvalue -1000 bounds. */
static void test_stiff_methods(void)
{
    const char *const names[] = {"rk8pd", "rkf45", "rkck", "rk4", "msbdf", "rk4imp", "bsimp"};
    long steps[CM_FLOW_METHODS];
    for (int k = 0; k < CM_FLOW_METHODS; k++)
        for (double T = 1; T <= 20; T += 19) {
            cm_model m = flow_model(
                2, (cm_flow){.field = stiff_field, .period = T, .method = k, .abs_tol = 1e-10,
                             .rel_tol = 1e-10},
                NULL);
            const double start[2] = {2, 0};
            double y[2];
            CHECK_INT(cm_flow_map(&m, start, y, NULL, &steps[k]), CM_STEP_OK);
            printf("stiff y' = A y to t = %2g: %-6s %5ld steps, error %.1e\n", T, names[k],
                   steps[k], fmax(fabs(y[0] - exp(-T)), fabs(y[1] - exp(-T))));
            CHECK_NEAR(y[0], exp(-T), 1e-8);
            CHECK_NEAR(y[1], exp(-T), 1e-8);
        }
    CHECK(steps[CM_FLOW_MSBDF] < steps[CM_FLOW_RK8PD]);
    CHECK(steps[CM_FLOW_BSIMP] < steps[CM_FLOW_RK8PD]);
}

typedef struct followed {
    int samples, crossings;
    double last_t, worst, zeta, wd;
    double cross_t[4], cross_v[4];
} followed;

static int observe(void *user, int kind, double t, const double *y)
{
    followed *f = user;
    CHECK(t >= f->last_t);
    f->last_t = t;
    if (kind == CM_FLOW_SAMPLE) {
        f->samples++;
        const double exact = exp(-f->zeta * t) * sin(f->wd * t) / f->wd;
        f->worst = fmax(f->worst, fabs(y[0] - exact));
    } else if (f->crossings < 4) {
        f->cross_t[f->crossings] = t;
        f->cross_v[f->crossings++] = y[1];
    }
    return 0;
}

/* A run followed through time: samples every dt on the known solution,
 * the section's crossings where the map puts them, in time order. */
static void test_follow(void)
{
    double zeta = 0.1;
    const double wd = sqrt(1 - zeta * zeta), Td = TWO_PI / wd;
    cm_model up = flow_model(
        2, (cm_flow){.field = damped_field, .section = section_x, .direction = 1}, &zeta);
    const double start[2] = {0, 1};
    followed f = {0, 0, 0, 0, zeta, wd, {0}, {0}};
    double reached;
    CHECK_INT(cm_flow_follow(&up, start, 0, 2.5 * Td, 0.1, observe, &f, &reached), CM_STEP_OK);
    CHECK_NEAR(reached, 2.5 * Td, 1e-12);
    CHECK_INT(f.samples, (int)ceil(2.5 * Td / 0.1) + 1);
    CHECK(f.worst < 1e-8);
    CHECK_INT(f.crossings, 2);
    CHECK_NEAR(f.cross_t[0], Td, 1e-9);
    CHECK_NEAR(f.cross_t[1], 2 * Td, 1e-9);
    CHECK_NEAR(f.cross_v[1], exp(-2 * zeta * Td), 1e-8);
    /* an orbit that blows up is lost, and says when */
    cm_model blow = flow_model(1, (cm_flow){.field = blowup_field, .period = 2}, NULL);
    const double fast[1] = {1.0};
    followed g = {0, 0, 0, 0, 0, 1, {0}, {0}};
    CHECK_INT(cm_flow_follow(&blow, fast, 0, 5, 0.25, observe, &g, &reached), CM_STEP_NO_IMAGE);
    CHECK(reached < 1.0);
}

static void test_sinks(void)
{
    cm_model blow = flow_model(1, (cm_flow){.field = blowup_field, .period = 2}, NULL);
    double y[1];
    const double slow[1] = {0.1}, fast[1] = {1.0}, nan_start[1] = {NAN};
    CHECK_INT(blow.step(&blow, slow, y), CM_STEP_OK); /* blows up at t = 10 */
    CHECK_NEAR(y[0], 0.1 / (1 - 0.2), 1e-8);
    CHECK_INT(blow.step(&blow, fast, y), CM_STEP_NO_IMAGE); /* at t = 1 */
    CHECK_INT(blow.step(&blow, nan_start, y), CM_STEP_NO_IMAGE);
    cm_model part = flow_model(1, (cm_flow){.field = partial_field, .period = 1}, NULL);
    const double inside[1] = {-0.5}, leaves[1] = {0.5};
    CHECK_INT(part.step(&part, inside, y), CM_STEP_OK);
    CHECK_NEAR(y[0], 0.5, 1e-12);
    CHECK_INT(part.step(&part, leaves, y), CM_STEP_NO_IMAGE);
    /* a flow with nothing to integrate is refused */
    cm_model bad;
    memset(&bad, 0, sizeof bad);
    bad.name = "bad";
    bad.dim = 1;
    bad.flow.field = blowup_field; /* no period, no section */
    char msg[256];
    CHECK(cm_flow_attach(&bad, msg, sizeof msg) == CM_EINVAL);
    CHECK(strstr(msg, "period") != NULL);
}

/* The integrator's two guards against a step it cannot take (issue 45,
 * item 4): the first trial step is at most a hundredth of the time the
 * field takes to change the state by its size (|y| + 1), whatever the
 * period; a step accepted with a non-finite state (its error estimate
 * NaN) is taken back and tried shorter, so an orbit that never blows up
 * is not called one. */
static void test_step_guards(void)
{
    first_probe probe = {0, 0};
    cm_model rot = flow_model(2, (cm_flow){.field = probed_rotation, .period = 640}, &probe);
    const double start[2] = {1, 0};
    double y[2];
    CHECK_INT(rot.step(&rot, start, y), CM_STEP_OK);
    /* scale |y| + 1 = 2, rate 1: a first step of at most 0.02 (period/64 is 10) */
    CHECK(probe.first > 0 && probe.first <= 0.02);
    CHECK_NEAR(y[0], cos(640), 1e-6);
    cm_model wall = flow_model(1, (cm_flow){.field = wall_field, .period = 20}, NULL);
    const double low[1] = {0};
    CHECK_INT(wall.step(&wall, low, y), CM_STEP_OK);
    CHECK_NEAR(y[0], 5, 1e-6);
}

/* step_n gives what step gives, bit for bit. */
static void test_step_n(const cm_model *m)
{
    enum { N = 64 };
    double x0[N], x1[N], y0[N], y1[N];
    int rc[N];
    for (int i = 0; i < N; i++) {
        x0[i] = -2.5 + 5.0 * i / N;
        x1[i] = 2.0 - 4.0 * ((i * 37) % N) / N;
    }
    const double *xs[2] = {x0, x1};
    double *ys[2] = {y0, y1};
    m->step_n(m, N, xs, ys, rc);
    int same = 0;
    for (int i = 0; i < N; i++) {
        const double x[2] = {x0[i], x1[i]};
        double y[2];
        const int r = m->step(m, x, y);
        /* the images where there are images (no image: y is not written) */
        same += r == rc[i] &&
                (r != CM_STEP_OK || memcmp(y, (double[2]){y0[i], y1[i]}, sizeof y) == 0);
    }
    CHECK_INT(same, N);
}

/* ---- Duffing: SCM against simulation ---- */

enum { MAX_ATTRACTORS = 32, CYCLE = 8, TRANSIENT = 300 };
typedef struct attractor {
    double p[CYCLE][2];
} attractor;

static double dist(const double *a, const double *b) { return hypot(a[0] - b[0], a[1] - b[1]); }

/* The attractor a long simulation from x settles on, among found[0..*n)
 * (appended when new); -1 if the orbit was lost. */
static int settle(const cm_model *m, const double *x0, attractor *found, int *n)
{
    double x[2] = {x0[0], x0[1]}, y[2];
    attractor a;
    for (int k = 0; k < TRANSIENT + CYCLE; k++) {
        if (m->step(m, x, y) != CM_STEP_OK)
            return -1;
        x[0] = y[0], x[1] = y[1];
        if (k >= TRANSIENT)
            memcpy(a.p[k - TRANSIENT], x, sizeof x);
    }
    for (int i = 0; i < *n; i++)
        for (int j = 0; j < CYCLE; j++)
            if (dist(found[i].p[j], x) < 1e-4)
                return i;
    if (*n == MAX_ATTRACTORS)
        return -1;
    found[*n] = a;
    return (*n)++;
}

/* Chebyshev distance in cells from point p to the nearest periodic cell
 * of group g. */
static double cells_to_group(const cm_region *r, const cm_lattice *lat, uint32_t g, const double *p)
{
    double best = INFINITY;
    for (uint64_t i = 0; i < r->ncells; i++) {
        if (!cm_is_periodic(r, i) || r->group[i] != g)
            continue;
        int64_t cell[2];
        double c[2];
        cm_box_cell(&r->box, i, cell);
        cm_lattice_centre(lat, cell, c);
        const double d = fmax(fabs(c[0] - p[0]) / lat->width[0], fabs(c[1] - p[1]) / lat->width[1]);
        best = fmin(best, d);
    }
    return best;
}

static void test_duffing_basins(void)
{
    cm_model m;
    char msg[256];
    const char *params[1] = {"delta=0.15,gamma=0.1,omega=1"};
    CHECK(cm_model_create("duffing", params, 1, &m, msg, sizeof msg) == CM_OK);
    test_step_n(&m);
    /* -2.5:2.5 squared, RES x RES cells */
    const cm_lattice lat = {2, {-2.5, -2.5}, {5.0 / RES, 5.0 / RES}};
    const cm_box box = {2, {0, 0}, {RES, RES}};
    cm_region r;
    const cm_scm_options opt = {.max_steps = 50, .threads = 2};
    CHECK(cm_region_alloc(&r, &box, msg, sizeof msg) == CM_OK);
    CHECK(cm_scm_solve(&m, &lat, &opt, &r, msg, sizeof msg) == CM_OK);

    /* 1000 random starts, simulated to their attractors */
    attractor found[MAX_ATTRACTORS];
    int nfound = 0, lost = 0;
    srand(12345);
    for (int s = 0; s < 1000; s++) {
        const double x[2] = {-2.5 + 5.0 * rand() / RAND_MAX, -2.5 + 5.0 * rand() / RAND_MAX};
        lost += settle(&m, x, found, &nfound) < 0;
    }
    CHECK_INT(lost, 0);
    CHECK_INT(nfound, 4); /* the four period-1 attractors of docs/models.md 11.2 */
    printf("duffing: %d attractors from 1000 starts, SCM: %u groups\n", nfound, r.ngroups);

    /* every simulated attractor lies on (or next to) the periodic cells of
     * an SCM group, and every SCM group on (or next to) one of them */
    uint32_t owner[MAX_ATTRACTORS + 1];
    int group_attractor[64];
    CHECK(r.ngroups < 64);
    for (int a = 0; a < nfound; a++) {
        owner[a] = 0;
        for (uint32_t g = 1; g <= r.ngroups && g < 64; g++)
            if (cells_to_group(&r, &lat, g, found[a].p[0]) <= 2)
                owner[a] = g;
        CHECK(owner[a] != 0);
    }
    for (uint32_t g = 1; g <= r.ngroups && g < 64; g++) {
        group_attractor[g] = -1;
        double best = INFINITY;
        for (int a = 0; a < nfound; a++) {
            const double d = cells_to_group(&r, &lat, g, found[a].p[0]);
            if (d < best)
                best = d, group_attractor[g] = a;
        }
        if (!(best <= 3))
            fprintf(stderr, "SCM group %u is %.1f cells from every simulated attractor\n", g, best);
        CHECK(best <= 3);
    }

    /* labels: the SCM group's attractor against a simulation from the
     * centre of 1000 random cells */
    int agree = 0;
    for (int s = 0; s < 1000; s++) {
        const uint64_t i = (uint64_t)rand() % r.ncells;
        int64_t cell[2];
        double c[2];
        cm_box_cell(&box, i, cell);
        cm_lattice_centre(&lat, cell, c);
        const int sim = settle(&m, c, found, &nfound);
        const uint32_t g = r.group[i];
        agree += g >= 1 && g < 64 && group_attractor[g] == sim;
    }
    printf("duffing: SCM labels agree with simulation for %d of 1000 random cells\n", agree);
    CHECK(agree >= 950);

    /* the integrator's error: images at the default tolerances (1e-9)
     * against 1e-12 stay far below a cell (5/400) */
    cm_model tight;
    const char *tight_params[2] = {params[0], "abs_tol=1e-12,rel_tol=1e-12"};
    CHECK(cm_model_create("duffing", tight_params, 2, &tight, msg, sizeof msg) == CM_OK);
    double worst = 0;
    for (int s = 0; s < 200; s++) {
        const double x[2] = {-2.5 + 5.0 * rand() / RAND_MAX, -2.5 + 5.0 * rand() / RAND_MAX};
        double y[2], z[2];
        CHECK(m.step(&m, x, y) == CM_STEP_OK && tight.step(&tight, x, z) == CM_STEP_OK);
        worst = fmax(worst, dist(y, z));
    }
    printf("duffing: largest image difference, tolerance 1e-9 against 1e-12: %.2e\n", worst);
    CHECK(worst < 1e-6);
    cm_model_release(&tight);
    cm_region_free(&r);
    cm_model_release(&m);
}

/* Finite-difference exponents against exact ones: on a stable focus of
 * Duffing's stroboscopic map both exponents of the flow are -delta/2 (their
 * sum is the field's divergence, -delta); the 1-D micro-chaos map
 * x' = a x - b Int(x) stretches by a everywhere, so its exponent is ln a. */
static void test_lyapunov(void)
{
    cm_model m;
    char msg[256];
    CHECK(cm_model_create("duffing", NULL, 0, &m, msg, sizeof msg) == CM_OK);
    double lambda = 0;
    const double well[2] = {-0.9, 0.0};
    CHECK(cm_map_lyapunov(&m, well, 1e-8, 300, &lambda));
    CHECK_NEAR(lambda, -0.15 / 2, 1e-3);
    cm_model_release(&m);
    const char *params[1] = {"a=1.6,b=1"};
    CHECK(cm_model_create("microchaos-1d", params, 1, &m, msg, sizeof msg) == CM_OK);
    const double x0[1] = {2.345};
    CHECK(cm_map_lyapunov(&m, x0, 1e-9, 20000, &lambda));
    CHECK_NEAR(lambda, log(1.6), 1e-3);
    cm_model_release(&m);
}

int main(void)
{
    test_lyapunov();
    test_known_flows();
    test_plane_sections();
    test_stiff_methods();
    test_follow();
    test_sinks();
    test_step_guards();
    test_duffing_basins();
    CHECK_DONE();
}
