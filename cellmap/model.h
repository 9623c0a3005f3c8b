/* cellmap/model.h - the contract between the engine and a dynamical system.
 *
 * A model is a value (in the spirit of gsl_odeiv2_system): a dimension, a
 * pure step function and a context of coefficients derived once from the
 * parameters. The engine only ever calls step(); everything else here is for
 * the command line, the renderer and the analysis commands.
 *
 * Thread safety: step() and fixed_points() must be pure; the engine calls
 * step() from many threads at once on one model.
 */
#ifndef CM_MODEL_H
#define CM_MODEL_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "cellmap/lattice.h"
#include "cellmap/status.h"
#include "cellmap/numtext.h" /* models print their parameters with it */
#include "cellmap/overlay.h"

#define CM_MAX_PARAMS 24
#define CM_PARAM_MAX_VALUES 64

/* Description of one parameter. A scalar has max_count 1; a vector parameter
 * is written v1:v2:... on the command line (max_count entries at most).
 * A parameter with choices ("none|output|...") takes one of the words and
 * stores the word's index. */
typedef struct cm_param_spec {
    const char *name;
    const char *def; /* default, in command-line syntax */
    double min, max; /* inclusive range of every element */
    int max_count;
    const char *choices; /* NULL or '|'-separated words */
    const char *doc;     /* one line */
} cm_param_spec;

typedef struct cm_param_value {
    int count;
    double v[CM_PARAM_MAX_VALUES];
} cm_param_value;

/* Values of all parameters of a spec, in the spec's order. */
typedef struct cm_params {
    const cm_param_spec *spec; /* terminated by an entry with name == NULL */
    int count;
    cm_param_value value[CM_MAX_PARAMS];
} cm_params;

/* A fixed point of a quantised map for control level `level`. `band` is the
 * level actually produced at the point; the point is regular iff they agree. */
typedef struct cm_fixed_point {
    int64_t level;
    int64_t band;
    bool regular;
    double x[CM_MAX_DIM];
} cm_fixed_point;

/* step()'s return values, CM_STEP_*, are in cellmap/status.h. */

/* Marks a function whose loops the compiler vectorises (a model's step_n,
 * the engine's image loops): on x86-64 it is built three times, for
 * AVX-512, for AVX2 and for the baseline, and the processor picks at load
 * time (AVX-512's 8 doubles a vector: images 18-22 % faster than AVX2's on
 * bench_scm). Same results every way: no build contracts or reorders
 * floating-point operations (ISO C: -ffp-contract=off). */
#if defined(__x86_64__) && defined(__GNUC__) && defined(__ELF__)
#define CM_VECTOR_LOOP __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define CM_VECTOR_LOOP
#endif

/* Integrators of a flow (cm_flow.method): GSL's explicit embedded
 * Runge-Kutta pairs, the classical fourth-order method with step doubling
 * (gsl_odeiv2_step_rk8pd, _rkf45, _rkck, _rk4), and for stiff flows its
 * implicit ones, which take the field's Jacobian by central differences:
 * the variable-order BDF method, the implicit Gauss fourth-order
 * Runge-Kutta method and Bulirsch-Stoer's (_msbdf, _rk4imp, _bsimp). */
enum {
    CM_FLOW_RK8PD = 0,
    CM_FLOW_RKF45,
    CM_FLOW_RKCK,
    CM_FLOW_RK4,
    CM_FLOW_MSBDF,
    CM_FLOW_RK4IMP,
    CM_FLOW_BSIMP,
    CM_FLOW_METHODS
};

/* A map made of an ODE flow x' = f(t, x), which cellmap integrates with
 * GSL (gsl_odeiv2) from time t0: the stroboscopic map (the state at
 * t0 + period) when section is NULL and plane 0, else the Poincare map of
 * the section g(t, x) = 0 (the state where g next changes sign in
 * `direction`, located to event_tol in time). A section on a state plane
 * x_k = level of an autonomous flow (plane = k + 1) makes the map's state
 * the flow's without x_k: the model's dim is then the flow's dimension
 * less one (cm_flow_dim), its coord_names (if any) name the flow's
 * coordinates, and the map lifts a state onto the plane, integrates to the
 * next crossing and drops x_k again. A start that leaves the world box
 * (|x_d| > world), gives a non-finite value, makes field() fail, takes
 * more than CM_FLOW_MAX_STEPS steps or, for a section, does not reach it
 * before t0 + t_max has no image (the sink). Zero settings take the
 * defaults given. */
struct cm_model;
typedef struct cm_flow {
    /* dxdt = f(t, x), dim entries, for model m (its values and ctx).
     * Returns 0, or nonzero where the field is not defined. Pure and
     * thread-safe, like step(). */
    int (*field)(const struct cm_model *m, double t, const double *x, double *dxdt);
    double t0, period;
    double (*section)(const struct cm_model *m, double t, const double *x); /* NULL: stroboscopic */
    int direction;  /* +1: g from negative to >= 0; -1: the reverse; 0: either */
    int method;     /* CM_FLOW_RK8PD ... */
    double abs_tol; /* per step, default 1e-9 */
    double rel_tol; /* per step, default 1e-9 */
    double t_max;   /* a section's longest flight, default 1000 */
    double world;   /* default 1e6 */
    double event_tol; /* default 1e-12 */
    int plane;        /* 0, or k + 1: the section is the plane x_k = level */
    double level;
} cm_flow;
#define CM_FLOW_MAX_STEPS 1000000

/* The integrator settings a flow model takes as parameters, spelt the
 * same for built-in models and plugins: put CM_FLOW_PARAM_SPECS at the end
 * of a spec (before its terminator) and cellmap reads them. */
#define CM_FLOW_PARAM_SPECS                                                                    \
    {"method", "rk8pd", 0, CM_FLOW_METHODS - 1, 1, "rk8pd|rkf45|rkck|rk4|msbdf|rk4imp|bsimp",    \
     "integrator: GSL's Runge-Kutta Prince-Dormand 8(9), Fehlberg 4(5), Cash-Karp 4(5), RK4; "  \
     "for stiff flows BDF, implicit Gauss RK4, Bulirsch-Stoer"},                                 \
        {"abs_tol", "1e-9", 1e-15, 1e-2, 1, NULL, "absolute error per integration step"},       \
        {"rel_tol", "1e-9", 0, 1e-2, 1, NULL, "relative error per integration step"},           \
        {"world", "1e6", 1e-6, 1e300, 1, NULL, "|x_i| beyond this: the orbit has no image"}
/* And, for a Poincare map, the section's settings (cm_flow.t_max, event_tol). */
#define CM_FLOW_SECTION_PARAM_SPECS                                                            \
    {"t_max", "1000", 1e-6, 1e12, 1, NULL, "the longest flight to the section (else no image)"}, \
        {"event_tol", "1e-12", 1e-15, 1, 1, NULL, "the section's crossing time to this"}

/* And, for a section on a state plane of an autonomous flow, its
 * settings: the coordinate (one of coords, '|'-separated, the flow's
 * coordinate names in order), its level and the crossing's direction
 * (up, down or either), the defaults given. */
#define CM_FLOW_PLANE_PARAM_SPECS(coords, coord, level, crossing)                                \
    {"section", coord, 0, CM_MAX_DIM - 1, 1, coords, "the section is the plane SECTION = level"}, \
        {"level", level, -1e300, 1e300, 1, NULL, "the level of the section's plane"},            \
        {"crossing", crossing, 0, 2, 1, "up|down|either",                                      \
         "the crossings the map takes: upwards (increasing), downwards or either"}

typedef struct cm_model {
    const char *name;
    int dim;
    const cm_param_spec *params;
    cm_params values; /* the parameters the model was built from */
    void *ctx;        /* derived coefficients; owned by the model */
    /* 0: image in y; >0: no image (the sink); <0: abort the run. A model
     * of a flow leaves step NULL and fills `flow`: cellmap gives it step
     * and step_n. */
    int (*step)(const struct cm_model *m, const double *x, double *y);
    /* Optional: step for n points at once, in arrays by coordinate (point
     * i is x[0][i], x[1][i], ...; its image goes to y[d][i], its status to
     * rc[i]), so that a loop the compiler vectorises does the work. Gives,
     * point by point and bit for bit, what step gives. Pure, like step(). */
    void (*step_n)(const struct cm_model *m, size_t n, const double *const *x, double *const *y,
                   int *rc);
    /* Optional. Fixed points for levels m0..m1 into out (cap entries);
     * *count receives how many were written. Returns 0, or -1 when the model
     * has no enumerable fixed points (a message then goes to msg). */
    int (*fixed_points)(const struct cm_model *m, int64_t m0, int64_t m1, cm_fixed_point *out,
                        size_t cap, size_t *count, char *msg, size_t msg_size);
    /* Optional, for models with dry friction. Whether y is a rest state held
     * by static friction (step(y) = y because the system sticks): groups
     * whose periodic cells map to rest states are sticking zones, not
     * attractors of the motion. Pure, like step(). */
    bool (*at_rest)(const struct cm_model *m, const double *y);
    /* Optional. Appends what the renderer should draw over the basins in the
     * view rectangle lo..hi (dimensions 0 and 1; for 1-D models the plane of
     * the map's graph): switching lines, fixed points, manifolds, sticking
     * zones. Pure, like step(). */
    void (*overlays)(const struct cm_model *m, const double lo[2], const double hi[2],
                     cm_overlay_list *out);
    /* Optional. Names of the state coordinates (dim entries; for a section
     * on a state plane, the flow's: dim + 1) for axis labels; NULL: x0,
     * x1, ... */
    const char *const *coord_names;
    void (*destroy)(void *ctx);
    cm_flow flow; /* flow.field NULL: a map given by step */
    /* Optional: angles and phases. period[d] > 0 makes coordinate d
     * periodic: cellmap takes every state step() gives modulo period[d]
     * into [period_lo[d], period_lo[d] + period[d]) (a pendulum's angle:
     * 2 pi from -pi), so cells, regions and their joins, attractors,
     * figures and exports see one period, and a rotation is no exit.
     * 0: not periodic. Boxes must lie within that period. */
    double period[CM_MAX_DIM];
    double period_lo[CM_MAX_DIM];
    /* Optional (plugin ABI 5): 1 when state coordinates 0 and 1 share a unit
     * (nondimensional x and x', the complex plane): figures then draw a
     * square of state space square unless asked otherwise (--aspect) */
    int equal_axes;
    /* private: the model's own step functions, which cm_model_wrap_periods
     * wraps */
    int (*own_step)(const struct cm_model *m, const double *x, double *y);
    void (*own_step_n)(const struct cm_model *m, size_t n, const double *const *x,
                       double *const *y, int *rc);
} cm_model;

/* The dimension of m's flow: its map's, or one more for a section on a
 * state plane. */
static inline int cm_flow_dim(const cm_model *m) { return m->dim + (m->flow.plane ? 1 : 0); }

/* Whether coordinate d of m is periodic (cm_model.period). */
static inline bool cm_model_periodic(const cm_model *m, int d) { return m->period[d] > 0; }

/* Checks a model's periods (each 0, or above 0 and finite with a finite
 * period_lo) and, when one is set (or check_status: a plugin's model),
 * wraps step and step_n: states taken into the periods, and a status
 * other than CM_STEP_OK, CM_STEP_NO_IMAGE and CM_STEP_ABORT made
 * CM_STEP_ABORT (it stops the run instead of passing for the sink).
 * CM_EINVAL naming the coordinate. Called once, when the model is made
 * (cm_model_set_create). */
cm_status cm_model_wrap_periods(cm_model *m, bool check_status, char *msg, size_t msg_size);

/* x (coordinate d) taken into the model's period, or as it is. */
double cm_model_wrap(const cm_model *m, int d, double x);

/* a - b in coordinate d, for a periodic one the shortest way round (in
 * [-period/2, period/2)). */
double cm_model_diff(const cm_model *m, int d, double a, double b);

/* The same for a bare array of periods (period[d] 0: not periodic). */
double cm_period_diff(const double *period, int d, double a, double b);

/* Whether box (cells of lat) lies within every periodic coordinate's
 * period (at most one period wide): CM_EINVAL naming the coordinate and
 * the period otherwise. */
cm_status cm_model_check_box(const cm_model *m, const cm_lattice *lat, const cm_box *box,
                             char *msg, size_t msg_size);

/* Whether lat's cells tile every periodic coordinate's period (a whole
 * number of cells from period_lo to its end), as views that pan across
 * the seam need: CM_EINVAL naming the coordinate otherwise. */
cm_status cm_model_check_lattice(const cm_model *m, const cm_lattice *lat, char *msg,
                                 size_t msg_size);

/* The name of state coordinate d: the model's own (coord_names, d < dim),
 * else x0, x1, ... (d < CM_MAX_DIM). The same names head CSV columns, JSON
 * arrays and SQL columns. */
const char *cm_model_coord_name(const cm_model *m, int d);

/* The name of coordinate d of m's flow (d < cm_flow_dim(m)): the same as
 * cm_model_coord_name's but for a section on a state plane, whose
 * coordinate the map's state drops. */
const char *cm_flow_coord_name(const cm_model *m, int d);

/* Word k of a parameter's '|'-separated choices into buf (k itself, as a
 * number, past the last word). */
void cm_param_choice_name(const char *choices, int k, char *buf, size_t size);

/* Releases the model's context; NULL-safe; leaves the struct zeroed. */
void cm_model_release(cm_model *m);

/* Integer part rounding toward zero, as the thesis' Int (docs/models.md 1.1).
 * Returns false for NaN, infinities and |z| >= 2^62, where no level exists. */
static inline bool cm_int_part(double z, double *level)
{
    if (!(z > -4611686018427387904.0 && z < 4611686018427387904.0))
        return false;
    *level = (double)(int64_t)z; /* conversion truncates toward zero */
    return true;
}

/* What cm_int_part gives z, for |z| < 2^62, and whether z is in that range,
 * in double arithmetic only, for step_n loops (SSE2 and AVX2 convert no
 * 64-bit integer): below 2^52, adding and taking away 2^52 rounds |z| to an
 * integer and stepping down where that went up truncates; from 2^52 on
 * every double is an integer. Adding 0 turns -0 into the +0 the conversion
 * gives. */
static inline double cm_int_part_value(double z)
{
    const double a = fabs(z), big = 0x1p52;
    double t = (a + big) - big;
    t -= t > a ? 1.0 : 0.0;
    return copysign(a < big ? t : a, z) + 0.0;
}

static inline int cm_int_part_status(double z)
{
    return z > -4611686018427387904.0 && z < 4611686018427387904.0 ? CM_STEP_OK
                                                                   : CM_STEP_NO_IMAGE;
}

#endif
